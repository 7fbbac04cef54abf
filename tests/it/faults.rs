//! Equipment faults in scenarios (issue 54): a valve stuck or failed to a position and repaired, a
//! feed lost and restored (also one a controller drives: the fault overrides the controller, which
//! winds up against it), an analyzer frozen and repaired; and the refusals of faults out of order.

use crate::harness;

/// A scratch folder of this test process.
fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("plantwide_it_faults_{name}_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Run `flowsheet` through the scenario `text`; the CSV's header and rows.
fn run(flowsheet: &str, name: &str, text: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let dir = scratch(name);
    let (scenario, csv) = (dir.join("s.json"), dir.join("o.csv"));
    std::fs::write(&scenario, text).unwrap();
    let out = harness::plantwide(&[
        "run",
        &harness::flowsheet(flowsheet),
        "--scenario",
        scenario.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(str::to_string).collect();
    let rows = lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    (header, rows)
}

/// The rows at time `t` (a fault's time has two: before and after it).
fn at(rows: &[Vec<f64>], t: f64) -> Vec<&Vec<f64>> {
    rows.iter().filter(|r| r[0] == t).collect()
}

/// The surge tank's outflow pump fails to 40 mol/s at 100 s (its level controller `lc` drives it)
/// and is repaired at 300 s; the inflow is lost at 1000 s and restored at 1100 s.
///
/// Independent checks: while the pump is stuck the tank gains exactly (50 − 40) mol/s × 200 s =
/// 2000 mol; the PI controller, acting on nothing, winds up along the level ramp it sees,
/// `op = 50 + Kc (e + ∫e dt/τ_I)` with `e = s (t − 100)`, i.e. `50 + 50 · e(300) · 1.5` at 300 s;
/// at the repair the pump takes that output at once; a lost feed gives 0 and its restoration the
/// 50 mol/s it had; the loop brings the level back to its setpoint.
#[test]
fn a_stuck_pump_and_a_lost_feed_fail_and_are_repaired() {
    let scenario = r#"{"format_version": 1, "duration": "3000 s",
      "record": {"interval": "10 s", "time_unit": "s", "paths": ["tank.level", "out.F", "lc.op", "inflow.F", "tank.M"]},
      "events": [{"type": "valve_stuck", "at": "100 s", "path": "tank.outflow", "to": "40 mol/s"},
                 {"type": "valve_repaired", "at": "300 s", "path": "tank.outflow"},
                 {"type": "feed_lost", "at": "1000 s", "unit": "inflow"},
                 {"type": "feed_restored", "at": "1100 s", "unit": "inflow"}]}"#;
    let (header, rows) = run("surge_tank_pi.json", "stuck", scenario);
    assert_eq!(header[1..], ["tank.level [m]", "out.F [mol/s]", "lc.op [mol/s]", "inflow.F [mol/s]", "tank.M [mol]"]);
    let (start, stuck_end) = (at(&rows, 100.0), at(&rows, 300.0));
    let (before, after) = (start[1], stuck_end[0]);
    assert_eq!(before[2], 40.0, "failed to 40 mol/s: {before:?}");
    assert!(rows.iter().filter(|r| r[0] > 100.0 && r[0] < 300.0).all(|r| r[2] == 40.0));
    assert!((after[5] - before[5] - 2000.0).abs() < 1e-6, "holdup gained {}", after[5] - before[5]);
    let e = after[1] - 1.0;
    let wound = 50.0 + 50.0 * e * 1.5;
    assert!((after[3] - wound).abs() < 1e-6 * wound, "lc.op {} against the wound-up {wound}", after[3]);
    let repaired = stuck_end[1];
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
    assert!(close(repaired[2], repaired[3]), "the repaired pump takes the controller's output: {repaired:?}");
    let lost = at(&rows, 1000.0)[1];
    assert_eq!(lost[4], 0.0);
    assert!(rows.iter().filter(|r| r[0] > 1000.0 && r[0] < 1100.0).all(|r| r[4] == 0.0));
    assert_eq!(at(&rows, 1100.0)[1][4], 50.0, "restored to its flow before the loss");
    let end = rows.last().unwrap();
    assert!((end[1] - 1.0).abs() < 1e-3 && (end[2] - 50.0).abs() < 0.1, "back on setpoint: {end:?}");
}

/// A feed a controller drives is lost (a supply failure overrides its controller) and restored to
/// that controller: the two-column plant's fresh B, on the reactor's composition loop.
#[test]
fn a_feed_a_controller_drives_is_lost_and_given_back_to_it() {
    let scenario = r#"{"format_version": 1, "duration": "3 h",
      "record": {"interval": "5 min", "time_unit": "h", "paths": ["fresh_B.F", "reactor_B.op", "effluent.x[B]"]},
      "events": [{"type": "feed_lost", "at": "1 h", "unit": "fresh_B"},
                 {"type": "feed_restored", "at": "1.5 h", "unit": "fresh_B"}]}"#;
    let (_, rows) = run("two_column_plant.json", "driven_feed", scenario);
    let during: Vec<&Vec<f64>> = rows.iter().filter(|r| r[0] > 1.0 && r[0] < 1.5).collect();
    assert!(!during.is_empty() && during.iter().all(|r| r[1] == 0.0), "lost: {during:?}");
    assert!(during.last().unwrap()[2] > during[0][2], "the composition loop winds up against the loss: {during:?}");
    assert!(rows.iter().filter(|r| r[0] > 1.5).all(|r| r[1] == r[2]), "given back to reactor_B");
}

/// A frozen analyzer holds its last result: its PI controller sees a constant error, so its output
/// moves as a straight line in time (the integral of a constant) until the repair, while the
/// composition itself moves; after the repair the samples move the output off that line.
#[test]
fn a_frozen_analyzer_holds_its_last_result_until_repaired() {
    let scenario = r#"{"format_version": 1, "duration": "300 min",
      "analyzers": {"top_composition": {"sample_time": "5 min", "dead_time": "5 min"}},
      "record": {"interval": "1 min", "paths": ["top_composition.op", "distillate.x[light]"]},
      "events": [{"type": "step", "at": "10 min", "path": "feed_source.F", "to": "1.1 kmol/min"},
                 {"type": "analyzer_frozen", "at": "30 min", "controller": "top_composition"},
                 {"type": "analyzer_repaired", "at": "120 min", "controller": "top_composition"}]}"#;
    let (_, rows) = run("column_a_lv.json", "analyzer", scenario);
    let curvature = |from: f64, to: f64| {
        let op: Vec<f64> = rows.iter().filter(|r| r[0] > from && r[0] < to).map(|r| r[1]).collect();
        let slope = (op[1] - op[0]).abs().max(f64::MIN_POSITIVE);
        op.windows(3).map(|w| (w[2] - 2.0 * w[1] + w[0]).abs() / slope).fold(0.0, f64::max)
    };
    let frozen = curvature(30.0, 120.0);
    assert!(frozen < 1e-6, "a straight line while frozen: relative curvature {frozen:e}");
    let x: Vec<f64> = rows.iter().filter(|r| r[0] > 30.0 && r[0] < 120.0).map(|r| r[2]).collect();
    assert!((x[x.len() - 1] - x[0]).abs() > 1e-6, "the composition itself moved meanwhile");
    let sampled = curvature(125.0, 200.0);
    assert!(sampled > 1e-3, "off the line once it samples again: relative curvature {sampled:e}");
}

/// Faults out of order are refused by event: a repair with no fault before it, a second fault on
/// a failed input, a frozen analyzer the scenario does not sample.
#[test]
fn faults_out_of_order_are_refused_naming_the_event() {
    let dir = scratch("refused");
    let cases = [
        (r#"[{"type": "valve_repaired", "at": "10 s", "path": "tank.outflow"}]"#, "no fault to repair"),
        (
            r#"[{"type": "valve_stuck", "at": "10 s", "path": "tank.outflow"}, {"type": "feed_lost", "at": "20 s", "unit": "inflow"}, {"type": "valve_stuck", "at": "30 s", "path": "tank.outflow", "to": "1 mol/s"}]"#,
            "has failed already",
        ),
        (r#"[{"type": "analyzer_frozen", "at": "10 s", "controller": "lc"}]"#, "is no scenario analyzer"),
        (
            r#"[{"type": "valve_stuck", "at": "10 s", "path": "tank.outflow", "to": "-1 mol/s"}]"#,
            "must not be negative",
        ),
    ];
    for (events, fragment) in cases {
        let scenario = dir.join("s.json");
        std::fs::write(&scenario, format!(r#"{{"format_version": 1, "duration": "100 s", "events": {events}}}"#))
            .unwrap();
        let out = harness::plantwide(&[
            "run",
            &harness::flowsheet("surge_tank_pi.json"),
            "--scenario",
            scenario.to_str().unwrap(),
            "--csv",
            dir.join("o.csv").to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{events}: {stderr}");
        assert!(stderr.contains("events[") && stderr.contains(fragment), "{events}: {stderr}");
    }
}
