//! Conditional events (`when`, issue 53): a condition acts where its variable crosses its value,
//! checked against the surge tank's balance. With its level loop in manual and the inflow raised
//! from 100 to 500 kmol/h at 1 min, the level rises at `ΔF/(ρA)`: it crosses `h` at
//! `t = 60 s + ρA (h − h0)/ΔF`, where `ρA = M0/h0` is the holdup per metre of the steady state.
//! Then a trip, an interlock that cuts the feed and gives it back later, a condition holding at
//! the start, an event that no longer fits, snapshots across a pending event, and input errors.

use plantwide::solve::dynamic::{Progress, Snapshot, Start};

use crate::dynamics::{column, converged, run_from};
use crate::harness::{plantwide, value};

/// The scenario: loop in manual, inflow to 500 kmol/h at 1 min, and `when` (the JSON list).
fn scenario(when: &str, extra: &str) -> String {
    format!(
        r#"{{"format_version": 1, "duration": "60 min",
 "events": [{{"type": "mode", "at": "0 min", "controller": "level_control", "mode": "manual"}},
            {{"type": "step", "at": "1 min", "path": "inflow_rate", "to": "500 kmol/h"}}],
 "when": {when},
 "record": {{"interval": "1 min", "paths": ["tank.level", "inflow.F", "tank.M"]}}{extra}}}"#
    )
}

/// Holdup per metre [mol/m] and the holdup at the start [mol].
fn tank_figures(plant: &plantwide::flowsheet::Plant, x0: &[f64]) -> (f64, f64) {
    let m0 = value(plant, x0, "tank.M");
    (m0 / value(plant, x0, "tank.level"), m0)
}

const DF: f64 = 400.0 / 3.6; // mol/s
const F_OUT: f64 = 100.0 / 3.6; // mol/s, held by the loop in manual
/// The integrator's relative tolerance (the scenario's default).
const RTOL: f64 = 1e-6;

/// A high-level interlock cuts the feed at 3 m, at the time the balance gives (to 1e-6 s: the
/// crossing is located on the integrator's polynomial), and the tank then drains at the held
/// outflow: the final holdup is the balance's to 1e-9.
#[test]
fn an_interlock_acts_where_the_level_crosses_its_value() {
    let (plant, x0) = converged("surge_tank.json", &[]);
    let (rho_a, m0) = tank_figures(&plant, &x0);
    let when =
        r#"[{"path": "tank.level", "above": "3 m", "then": [{"type": "feed_lost", "at": "0 s", "unit": "inflow"}]}]"#;
    let res = run_from(&plant, &scenario(when, ""), Start::Steady(&x0), &mut |_| {});
    let expected = 60.0 + rho_a * 1.0 / DF;
    let acted: Vec<&(f64, String)> = res.events.iter().filter(|(_, o)| o.starts_with("when[0]")).collect();
    assert_eq!(acted.len(), 2, "{:?}", res.events);
    assert_eq!(acted[0].1, "when[0] (`tank.level` above 3 m)");
    assert_eq!(acted[1].1, "when[0].then[0]");
    let t_star = acted[0].0;
    // The balance within what the integrator's tolerance allows the holdup, as a time; the
    // crossing itself is located to rounding: the level there is 3 m.
    let allowed = RTOL * (m0 + DF * (expected - 60.0)) / DF;
    assert!(
        (t_star - expected).abs() <= allowed,
        "crossing at {t_star} s, the balance gives {expected} s ± {allowed:.1e}"
    );
    let at_crossing = res.times.iter().position(|&t| t == t_star).expect("a row at the crossing");
    let level = column(&res, "tank.level")[at_crossing];
    assert!((level - 3.0).abs() <= 1e-9, "level at the crossing {level}");
    assert_eq!(acted[1].0, t_star);
    assert!(res.tripped.is_none());
    let (f, m) = (column(&res, "inflow.F"), column(&res, "tank.M"));
    for (k, t) in res.times.iter().enumerate().filter(|&(_, t)| *t > t_star) {
        assert_eq!(f[k], 0.0, "the feed is lost from the crossing on (t = {t})");
    }
    let m_end = m0 + DF * (expected - 60.0) - F_OUT * (3600.0 - expected);
    let got = *m.last().unwrap();
    assert!((got - m_end).abs() <= RTOL * m_end, "final holdup {got}, the balance gives {m_end}");
    assert!(res.conservation.worst() <= 1e-12);
}

/// `stop` ends the run at the crossing: its time, the level there, and the reason.
#[test]
fn a_stop_condition_ends_the_run_at_its_crossing() {
    let (plant, x0) = converged("surge_tank.json", &[]);
    let (rho_a, _) = tank_figures(&plant, &x0);
    let when = r#"[{"path": "tank.level", "above": "3.5 m", "stop": true}]"#;
    let res = run_from(&plant, &scenario(when, ""), Start::Steady(&x0), &mut |_| {});
    let expected = 60.0 + rho_a * 1.5 / DF;
    let allowed = RTOL * value(&plant, &res.x, "tank.M") / DF;
    assert!(
        (res.t - expected).abs() <= allowed,
        "ended at {} s, the balance gives {expected} s ± {allowed:.1e}",
        res.t
    );
    let why = res.tripped.as_deref().expect("the run says why it ended");
    assert!(why.contains("`tank.level` above 3.5 m") && why.contains("when[0]"), "{why}");
    assert_eq!(*res.times.last().unwrap(), res.t, "the last row is the crossing");
    let level = *column(&res, "tank.level").last().unwrap();
    assert!((level - 3.5).abs() <= 1e-9, "level at the stop {level}");
}

/// A condition that holds at the start acts there; its events come their delay later; a feed
/// restored after the interlock's loss gives back the flow before it.
#[test]
fn a_condition_holding_at_the_start_acts_there_and_delays_count_from_it() {
    let (plant, x0) = converged("surge_tank.json", &[]);
    let when = r#"[{"path": "tank.level", "below": "2.5 m",
                    "then": [{"type": "feed_lost", "at": "5 min", "unit": "inflow"},
                             {"type": "feed_restored", "at": "7 min", "unit": "inflow"}]}]"#;
    let res = run_from(&plant, &scenario(when, ""), Start::Steady(&x0), &mut |_| {});
    let at = |o: &str| res.events.iter().find(|(_, e)| e == o).map(|(t, _)| *t);
    assert_eq!(at("when[0] (`tank.level` below 2.5 m)"), Some(0.0), "{:?}", res.events);
    assert_eq!(at("when[0].then[0]"), Some(300.0));
    assert_eq!(at("when[0].then[1]"), Some(420.0));
    let f = column(&res, "inflow.F");
    let row = |t: f64| res.times.iter().rposition(|&u| u == t).unwrap();
    assert_eq!(f[row(360.0)], 0.0);
    assert_eq!(f[row(480.0)], 500.0 / 3.6, "restored to the flow before the loss");
}

/// An event that no longer fits when its condition acts (the repair of a feed that was never
/// lost) is skipped and listed as skipped, not applied.
#[test]
fn an_event_that_no_longer_fits_is_skipped_and_says_so() {
    let (plant, x0) = converged("surge_tank.json", &[]);
    let when = r#"[{"path": "tank.level", "above": "3 m", "then": [{"type": "feed_restored", "at": "0 s", "unit": "inflow"}]}]"#;
    let res = run_from(&plant, &scenario(when, ""), Start::Steady(&x0), &mut |_| {});
    let skipped = res.events.iter().find(|(_, o)| o.starts_with("when[0].then[0]")).expect("listed");
    assert_eq!(skipped.1, "when[0].then[0] skipped: `inflow.F` has no fault to repair");
}

/// A snapshot taken after the interlock acted, before the feed it cut comes back: resumed with
/// the same scenario it is the continuous run; with another scenario (no conditions), the
/// pending return of the feed is the old scenario's and is dropped.
#[test]
fn a_snapshot_keeps_what_the_conditions_have_done_and_will_do() {
    let (plant, x0) = converged("surge_tank.json", &[]);
    let when = r#"[{"path": "tank.level", "above": "3 m",
                    "then": [{"type": "feed_lost", "at": "0 s", "unit": "inflow"},
                             {"type": "feed_restored", "at": "20 min", "unit": "inflow"}]}]"#;
    let text = scenario(when, r#", "snapshots": [{"at": "20 min", "file": "s.json"}]"#);
    let mut saved = None;
    let full = run_from(&plant, &text, Start::Steady(&x0), &mut |p| {
        if let Progress::Snapshot { snapshot, .. } = p {
            saved = Some(serde_json::to_string(snapshot).unwrap());
        }
    });
    let snap: Snapshot = serde_json::from_str(&saved.expect("taken")).unwrap();
    assert_eq!(snap.driver.fired.len(), 1);
    assert_eq!(snap.driver.triggered.len(), 1, "the return of the feed is pending");
    let resumed = run_from(&plant, &text, Start::Snapshot(&snap), &mut |_| {});
    // Rows in order (an event's time has two: before and after it).
    let first = full.times.iter().position(|&u| u == resumed.times[0]).expect("the resumed rows are the full run's");
    assert_eq!(full.times[first..], resumed.times[..], "the same recording times");
    let compared = resumed.rows.iter().zip(full.rows.iter().skip(first)).filter(|(a, b)| a == b).count();
    assert_eq!(compared, resumed.times.len(), "rows equal bit for bit");
    assert!(compared >= 40, "{compared}");
    let restored = full.events.iter().find(|(_, o)| o == "when[0].then[1]").unwrap().0;
    assert!(resumed.events.iter().any(|(t, o)| o == "when[0].then[1]" && *t == restored));
    let what_if = scenario("[]", "");
    let other = run_from(&plant, &what_if, Start::Snapshot(&snap), &mut |_| {});
    assert_eq!(*column(&other, "inflow.F").last().unwrap(), 0.0, "no return of the feed: {:?}", other.events);
}

/// Files that cannot mean a condition are refused with exit 1, naming the field; a stop is an
/// answer (exit 0) that says where the run ended.
#[test]
fn the_command_line_refuses_bad_conditions_and_reports_a_stop() {
    let dir = std::env::temp_dir().join(format!("plantwide_it_conditions_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let sheet = crate::harness::flowsheet("surge_tank.json");
    let run = |when: &str| {
        let file = dir.join("s.json");
        std::fs::write(&file, scenario(when, "")).unwrap();
        let csv = dir.join("s.csv");
        plantwide(&["run", &sheet, "--scenario", file.to_str().unwrap(), "--csv", csv.to_str().unwrap()])
    };
    for (when, says) in [
        (
            r#"[{"path": "tank.level", "above": "3 m", "below": "1 m", "stop": true}]"#,
            "when[0]: give exactly one of `above` and `below`",
        ),
        (r#"[{"path": "tank.level", "above": "3 m"}]"#, "when[0]: give `then`"),
        (
            r#"[{"path": "tank.level", "above": "3 m", "stop": true, "then": [{"type": "feed_lost", "at": "0 s", "unit": "inflow"}]}]"#,
            "when[0]: give `then`",
        ),
        (
            r#"[{"path": "inflow_rate", "above": "3 mol/s", "stop": true}]"#,
            "when[0].path: `inflow_rate` is an input no controller drives",
        ),
        (r#"[{"path": "tank.levle", "above": "3 m", "stop": true}]"#, "did you mean `tank.level`"),
        (r#"[{"path": "tank.level", "above": "3 kg", "stop": true}]"#, "when[0].above"),
        (
            r#"[{"path": "tank.level", "above": "3 m", "then": [{"type": "feed_lost", "at": "-1 s", "unit": "inflow"}]}]"#,
            "when[0].then[0].at",
        ),
    ] {
        let out = run(when);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{when}: {err}");
        assert!(err.contains(says), "{when}: expected `{says}` in: {err}");
    }
    let out = run(r#"[{"path": "tank.level", "above": "3.5 m", "stop": true}]"#);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("stopped by the scenario: `tank.level` above 3.5 m at t = 1377.6"), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}
