//! Equipment faults in scenarios (issue 54): a valve stuck or failed to a position and repaired, a
//! feed lost and restored (also one a controller drives: the fault overrides the controller, which
//! winds up against it), an analyzer frozen and repaired; and the refusals of faults out of order.

use approx::abs_diff_eq;

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
    assert!(
        abs_diff_eq!(repaired[2], repaired[3], epsilon = 1e-12 * repaired[3].abs()),
        "the repaired pump takes the controller's output: {repaired:?}"
    );
    let lost = at(&rows, 1000.0)[1];
    assert_eq!(lost[4], 0.0);
    assert!(rows.iter().filter(|r| r[0] > 1000.0 && r[0] < 1100.0).all(|r| r[4] == 0.0));
    assert_eq!(at(&rows, 1100.0)[1][4], 50.0, "restored to its flow before the loss");
    let end = rows.last().unwrap();
    assert!((end[1] - 1.0).abs() < 1e-3 && (end[2] - 50.0).abs() < 0.1, "back on setpoint: {end:?}");
}

/// Found by the soak: a sinusoid after a feed was lost and restored was refused ("takes
/// `inflow.F` out of its range: -5 mol/s"), its centre taken as the lost feed's zero. The feed is
/// back at its 50 mol/s, so the sinusoid swings about that: 50 ± 5 mol/s at the quarter periods.
#[test]
fn a_sinusoid_after_a_restored_feed_swings_about_its_restored_flow() {
    let scenario = r#"{"format_version": 1, "duration": "1000 s",
      "record": {"interval": "25 s", "time_unit": "s", "paths": ["inflow.F"]},
      "events": [{"type": "feed_lost", "at": "100 s", "unit": "inflow"},
                 {"type": "feed_restored", "at": "200 s", "unit": "inflow"},
                 {"type": "sinusoid", "at": "300 s", "path": "inflow.F", "amplitude": "5 mol/s", "period": "400 s"}]}"#;
    let (_, rows) = run("surge_tank_pi.json", "sine_after_restore", scenario);
    let f = |t: f64| at(&rows, t).last().unwrap()[1];
    assert!((f(400.0) - 55.0).abs() < 1e-9 && (f(600.0) - 45.0).abs() < 1e-9, "{} {}", f(400.0), f(600.0));
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

/// Found by the soak: composition steps at different times whose fractions together pass 1 (z[B]
/// raised at 1 h, z[R] at 2 h, neither lowering the other) left the last component a negative
/// fraction and stopped the run hours later in consistent initialization. Refused at once, naming
/// the event and the sum.
#[test]
fn composition_steps_that_sum_above_one_are_refused_naming_the_event() {
    let dir = scratch("z_sum");
    let scenario = dir.join("s.json");
    std::fs::write(
        &scenario,
        r#"{"format_version": 1, "duration": "3 h",
          "events": [{"type": "step", "at": "1 h", "path": "fresh_A.z[A]", "to": 0.99},
                     {"type": "step", "at": "1 h", "path": "fresh_A.z[B]", "to": 0.01},
                     {"type": "step", "at": "2 h", "path": "fresh_A.z[R]", "to": 0.01}]}"#,
    )
    .unwrap();
    let out = harness::plantwide(&[
        "run",
        &harness::flowsheet("two_column_plant.json"),
        "--scenario",
        scenario.to_str().unwrap(),
        "--csv",
        dir.join("o.csv").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("events[2]") && err.contains("sum to 1.01"), "{err}");
}

/// `run` with `--json` on `flowsheet` through the scenario file `scenario`, into `dir`: the
/// summary and the CSV's last time.
fn run_json(flowsheet: &str, scenario: &str, dir: &std::path::Path, extra: &[&str]) -> (serde_json::Value, String) {
    let csv = dir.join("o.csv");
    let mut args = vec!["run", flowsheet, "--scenario", scenario, "--csv", csv.to_str().unwrap(), "--json"];
    args.extend_from_slice(extra);
    let out = harness::plantwide(&args);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    (serde_json::from_slice(&out.stdout).unwrap(), std::fs::read_to_string(csv).unwrap())
}

/// A plant running down after a lost feed keeps running (issue 54): the two-column plant's fresh
/// A lost for 4 h, then restored. The run stopped at 6.48 h ("step size too small (1.8e-11 s)")
/// when the column's bottoms controller left its lower limit: the integrator retried ever shorter
/// steps on one Jacobian taken across that kink. Independent checks: while the feed is lost the
/// reactor's level controller closes its outlet (its output at the 0 limit) and the level falls;
/// after the restoration the integral actions bring the reactor level and its B fraction back to
/// their setpoints; the component and mass balances close.
#[test]
fn a_plant_running_down_after_a_lost_feed_keeps_running_and_recovers() {
    let dir = scratch("rundown");
    let scenario = dir.join("s.json");
    std::fs::write(
        &scenario,
        r#"{"format_version": 1, "duration": "40 h", "record": {"interval": "10 min", "time_unit": "h",
            "paths": ["reactor.level", "reactor_level.op", "effluent.x[B]", "column1_bottom_T.op"]},
          "events": [{"type": "feed_lost", "at": "2 h", "unit": "fresh_A"},
                     {"type": "feed_restored", "at": "6 h", "unit": "fresh_A"}]}"#,
    )
    .unwrap();
    let (summary, csv) = run_json(&harness::flowsheet("two_column_plant.json"), scenario.to_str().unwrap(), &dir, &[]);
    let rows: Vec<Vec<f64>> = csv.lines().skip(1).map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    let during: Vec<&Vec<f64>> = rows.iter().filter(|r| r[0] > 4.0 && r[0] < 6.0).collect();
    assert!(during.iter().all(|r| r[2] == 0.0 && r[1] < 2.0), "outlet closed, level falling: {during:?}");
    let end = rows.last().unwrap();
    assert_eq!(end[0], 40.0);
    assert!((end[1] - 2.5).abs() < 1e-3 && (end[3] - 0.35).abs() < 1e-4, "back on setpoints: {end:?}");
    let error = summary["conservation"]["max_relative_error"].as_f64().unwrap();
    assert!(error < 1e-12, "conservation {error:e}");
}

/// Every inflow of the two-column plant's mixer stopped (fresh B lost, the recycle's distillate
/// valve failed closed, then fresh A lost) and fresh A restored: at zero flow the mixer's
/// balances read 0 = 0 and the run stopped ("iteration matrix singular"; soak seed 2 stopped the
/// same way on restoring fresh A). Independent checks: a stopped mixer carries the unweighted
/// mean of its inlets (its documented stopped-flow rule, to the solver's tolerance); once fresh A flows alone, the reactor
/// feed is fresh A (its flow and pure A); the balances close.
#[test]
fn a_mixer_whose_inflows_all_stop_carries_its_inlets_mean_and_takes_a_restored_feed() {
    let dir = scratch("stopped_mixer");
    let scenario = dir.join("s.json");
    std::fs::write(
        &scenario,
        r#"{"format_version": 1, "duration": "2 h", "record": {"interval": "1 min", "time_unit": "h",
            "paths": ["reactor_feed.F", "reactor_feed.x[A]", "recycle.x[A]", "feed_B.x[A]", "feed_A.F"]},
          "events": [{"type": "valve_stuck", "at": "0.5 h", "path": "column1.distillate", "to": "0 kmol/h"},
                     {"type": "feed_lost", "at": "0.5 h", "unit": "fresh_B"},
                     {"type": "feed_lost", "at": "0.6 h", "unit": "fresh_A"},
                     {"type": "feed_restored", "at": "0.8 h", "unit": "fresh_A"},
                     {"type": "feed_restored", "at": "0.9 h", "unit": "fresh_B"},
                     {"type": "valve_repaired", "at": "1 h", "path": "column1.distillate"}]}"#,
    )
    .unwrap();
    let (summary, csv) = run_json(&harness::flowsheet("two_column_plant.json"), scenario.to_str().unwrap(), &dir, &[]);
    let rows: Vec<Vec<f64>> = csv.lines().skip(1).map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    let stopped: Vec<&Vec<f64>> = rows.iter().filter(|r| r[0] > 0.61 && r[0] < 0.79).collect();
    assert!(stopped.len() > 5 && stopped.iter().all(|r| r[1] == 0.0), "no inflow: {stopped:?}");
    for r in &stopped {
        let mean = (1.0 + r[4] + r[3]) / 3.0;
        assert!((r[2] - mean).abs() < 1e-8, "x[A] {} against the inlets' mean {mean}", r[2]);
    }
    let alone: Vec<&Vec<f64>> = rows.iter().filter(|r| r[0] > 0.81 && r[0] < 0.89).collect();
    let fresh_a = 100.0 / 3.6;
    for r in &alone {
        assert!((r[1] - fresh_a).abs() < 1e-9 * fresh_a && (r[2] - 1.0).abs() < 1e-12, "fresh A alone: {r:?}");
    }
    assert_eq!(rows.last().unwrap()[0], 2.0);
    let error = summary["conservation"]["max_relative_error"].as_f64().unwrap();
    assert!(error < 1e-12, "conservation {error:e}");
}

/// A step listed after a pulse, at the pulse's end: the end acts first, then the step (file
/// order), and the step holds. A live run's journal has this whenever a command arrives at the
/// sync point where a pulse ends; it was refused as ambiguous, so the journal of a 1114-command
/// serve soak did not replay.
#[test]
fn a_step_where_an_earlier_pulse_ends_acts_after_the_end() {
    let scenario = r#"{"format_version": 1, "duration": "600 s",
      "record": {"interval": "30 s", "time_unit": "s", "paths": ["inflow.F"]},
      "events": [{"type": "pulse", "at": "60 s", "path": "F_in", "by": "5 mol/s", "width": "60 s"},
                 {"type": "step", "at": "120 s", "path": "F_in", "to": "70 mol/s"}]}"#;
    let (_, rows) = run("surge_tank_pi.json", "pulse_then_step", scenario);
    let flow = |t: f64| at(&rows, t).last().map(|r| r[1]).unwrap_or_else(|| panic!("no row at {t} s"));
    assert_eq!((flow(90.0), flow(150.0), flow(600.0)), (55.0, 70.0, 70.0), "{rows:?}");
}

/// Changes of a feed while it is lost go on behind the loss, as a setpoint moved at a dead valve:
/// a pulse that ends during the loss and a step during it leave the feed at zero (each made the
/// lost feed flow again: a serve soak's pulse on a lost feed jumped its flow into a mixer with
/// nothing else flowing and stopped the run), and the repair gives back where the scenario has
/// it by then: the pulse's base (50 mol/s), not its top; the stepped 70 mol/s.
#[test]
fn changes_of_a_lost_feed_go_on_behind_the_loss_and_the_repair_gives_them_back() {
    let scenario = r#"{"format_version": 1, "duration": "600 s",
      "record": {"interval": "30 s", "time_unit": "s", "paths": ["inflow.F"]},
      "events": [{"type": "pulse", "at": "60 s", "path": "F_in", "to": "60 mol/s", "width": "120 s"},
                 {"type": "feed_lost", "at": "100 s", "unit": "inflow"},
                 {"type": "feed_restored", "at": "300 s", "unit": "inflow"}]}"#;
    let (_, rows) = run("surge_tank_pi.json", "pulse_in_fault", scenario);
    let flow = |t: f64| at(&rows, t).last().map(|r| r[1]).unwrap_or_else(|| panic!("no row at {t} s"));
    assert_eq!(
        (flow(90.0), flow(150.0), flow(210.0), flow(270.0), flow(330.0)),
        (60.0, 0.0, 0.0, 0.0, 50.0),
        "{rows:?}"
    );
    let scenario = r#"{"format_version": 1, "duration": "600 s",
      "record": {"interval": "30 s", "time_unit": "s", "paths": ["inflow.F"]},
      "events": [{"type": "feed_lost", "at": "100 s", "unit": "inflow"},
                 {"type": "step", "at": "150 s", "path": "F_in", "to": "70 mol/s"},
                 {"type": "feed_restored", "at": "300 s", "unit": "inflow"}]}"#;
    let (_, rows) = run("surge_tank_pi.json", "step_in_fault", scenario);
    let flow = |t: f64| at(&rows, t).last().map(|r| r[1]).unwrap_or_else(|| panic!("no row at {t} s"));
    assert_eq!((flow(90.0), flow(150.0), flow(270.0), flow(330.0)), (50.0, 0.0, 0.0, 70.0), "{rows:?}");
}

/// The soak's seed-11 week (`tests/data/soak`, from `../shared/cases/soak`): a random event every
/// 2 h, a stuck valve, a pulse, a sinusoid and the fresh-A feed lost at 151 h. It stopped at
/// 155.09 h on too small a step; it now runs its seven days with the balances closed.
#[test]
fn the_seed_11_week_with_a_lost_feed_runs_to_its_end() {
    let dir = scratch("seed11");
    let scenario = format!("{}/tests/data/soak/two_column_feed_lost_seed11.json", env!("CARGO_MANIFEST_DIR"));
    let (summary, csv) = run_json(&harness::flowsheet("two_column_plant.json"), &scenario, &dir, &[]);
    let last: f64 = csv.lines().last().unwrap().split(',').next().unwrap().parse().unwrap();
    assert!((last - 168.0).abs() < 1e-9, "ends at {last} h");
    let error = summary["conservation"]["max_relative_error"].as_f64().unwrap();
    assert!(error < 1e-9, "conservation {error:e}");
}

/// The soak's seed-2 week (`tests/data/soak`): fresh A lost at 145.715 h while every inflow of the
/// mixer dies away, restored at 147.021 h, where the run stopped in consistent initialization
/// (the stopped mixer's singular balances). It now takes the feed back, and ends where the plant
/// does: column 2's drum, its level valve stuck at 147.467 h while the plant recovers, runs dry
/// (an honest `stopped:`, exit 2, naming the vessel; the soak's ridable faults no longer stick
/// level valves).
#[test]
fn the_seed_2_week_takes_the_restored_feed_and_stops_where_a_stuck_level_valve_drains_a_drum() {
    let scenario = format!("{}/tests/data/soak/two_column_restore_seed2.json", env!("CARGO_MANIFEST_DIR"));
    let csv = scratch("seed2").join("o.csv");
    let flowsheet = harness::flowsheet("two_column_plant.json");
    let out = harness::plantwide(&["run", &flowsheet, "--scenario", &scenario, "--csv", csv.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    let at = err.split("stopped: `column2.M[32]` ran dry at t = ").nth(1).unwrap_or_else(|| panic!("{err}"));
    let t: f64 = at.split(' ').next().unwrap().parse().unwrap();
    assert!(t > 147.467 * 3600.0 && t < 148.0 * 3600.0, "stopped at {} h: {err}", t / 3600.0);
}

/// A resume is the continuous run bit for bit also where nothing happens at the snapshot: the
/// snowball plant without analyzers, snapshots at whole hours between events. The resumed runs
/// differed in the last digit from the second row on: the continuous run kept its LU factors
/// across the snapshot while the resume refactorized. The continuous run now goes on from the
/// snapshot as a resume does.
#[test]
fn a_resume_between_events_is_the_continuous_run_bit_for_bit() {
    let dir = scratch("resume_between");
    let snaps = dir.join("snaps");
    std::fs::create_dir_all(&snaps).unwrap();
    let scenario = dir.join("s.json");
    let snapshot = |h: u32| format!(r#"{{"at": "{h} h", "file": "{}/s{h}.json"}}"#, snaps.display());
    std::fs::write(
        &scenario,
        format!(
            r#"{{"format_version": 1, "duration": "8 h", "record": {{"interval": "10 min", "time_unit": "h"}},
              "snapshots": [{}],
              "events": [{{"type": "ramp", "at": "1.5 h", "path": "fresh.F", "to": "250 lbmol/h", "duration": "50 min"}},
                         {{"type": "step", "at": "4.7 h", "path": "xd_control.sp", "to": 0.94}}]}}"#,
            (2..7).map(snapshot).collect::<Vec<_>>().join(", ")
        ),
    )
    .unwrap();
    let fs = harness::flowsheet("reactor_column_recycle.json");
    let (_, full) = run_json(&fs, scenario.to_str().unwrap(), &dir, &[]);
    // Kept first: each resumed run writes the later snapshots again.
    for h in 2..7 {
        std::fs::copy(snaps.join(format!("s{h}.json")), snaps.join(format!("kept{h}.json"))).unwrap();
    }
    for h in 2..7 {
        let kept = snaps.join(format!("kept{h}.json"));
        let (_, resumed) = run_json(&fs, scenario.to_str().unwrap(), &dir, &["--resume", kept.to_str().unwrap()]);
        let tail: Vec<&str> = resumed.lines().skip(1).collect();
        assert!(tail.len() > 10 && full.lines().collect::<Vec<_>>().ends_with(&tail), "resume from {h} h");
    }
}
