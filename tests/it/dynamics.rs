//! Dynamic simulation against closed forms and steady states: the surge tank's PI (second-order)
//! and P-only (first-order) level responses, column A's response to a feed step (final state =
//! the new steady state, time constant, conservation, step count), event timing, controller
//! mode switches and failures, sampled controllers and analyzers, and snapshot → resume.

use approx::abs_diff_eq;
use plantwide::flowsheet::overrides::{set_field, set_input};
use plantwide::flowsheet::scenario::{parse_scenario, resolve};
use plantwide::flowsheet::{FlowsheetSpec, Plant, assemble, parse_spec};
use plantwide::solve::dynamic::{Progress, SimulationResult, Snapshot, Start, simulate};
use plantwide::solve::{NewtonSettings, steady_state};

use crate::harness::{self, flowsheet};

/// Load a shipped flowsheet with `--set`-style field overrides, converge it, run `scenario`.
fn run(name: &str, fields: &[(&str, &str)], scenario: &str) -> (Plant, Vec<f64>, SimulationResult) {
    let (plant, x0) = converged(name, fields);
    let res = run_from(&plant, scenario, Start::Steady(&x0), &mut |_| {});
    (plant, x0, res)
}

pub(crate) fn converged(name: &str, fields: &[(&str, &str)]) -> (Plant, Vec<f64>) {
    let path = flowsheet(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut spec: FlowsheetSpec = parse_spec(&text, &path).unwrap();
    for (p, v) in fields {
        set_field(&mut spec, p, v).unwrap();
    }
    let plant = assemble(&spec, &path).unwrap();
    let ss = steady_state(&plant, &plant.input_values(), None, &NewtonSettings::default()).unwrap();
    (plant, ss.x)
}

pub(crate) fn run_from(
    plant: &Plant,
    scenario: &str,
    start: Start<'_>,
    observer: &mut dyn FnMut(Progress<'_>),
) -> SimulationResult {
    let spec = parse_scenario(scenario, "scenario.json").unwrap_or_else(|e| panic!("{e}"));
    let sc = resolve(&spec, plant, "scenario.json").unwrap_or_else(|e| panic!("{e}"));
    simulate(plant, &sc, start, "test", observer).unwrap_or_else(|e| panic!("{e}"))
}

pub(crate) fn column(res: &SimulationResult, path: &str) -> Vec<f64> {
    let k = res.columns.iter().position(|c| c.path == path).unwrap_or_else(|| panic!("no column {path}"));
    res.rows.iter().map(|r| r[k]).collect()
}

/// Surge tank, level loop, step of the inflow by dF at t_s: deviation of level and outflow.
/// `v = v_L/A` [m/mol] is the level per mole; `kc` [mol/s/m]; `tau_i` [s] (None: P only).
fn tank_closed_form(t: f64, v: f64, kc: f64, tau_i: Option<f64>, df: f64) -> (f64, f64) {
    let a = v * kc;
    match tau_i {
        // h' = v(dF − Kc h): h = dF/Kc (1 − e^{−a t}), F_out − F0 = dF (1 − e^{−a t}).
        None => (df / kc * (1.0 - (-a * t).exp()), df * (1.0 - (-a * t).exp())),
        // h'' + a h' + (a/τ_I) h = 0, h(0) = 0, h'(0) = v dF (underdamped here):
        // h = (v dF/ω) e^{−σt} sin ωt; F_out = F_in − h'/v.
        Some(ti) => {
            let (sigma, omega) = (a / 2.0, (a / ti - a * a / 4.0).sqrt());
            assert!(omega.is_finite() && omega > 0.0, "the test case is underdamped");
            let e = (-sigma * t).exp();
            let h = v * df / omega * e * (omega * t).sin();
            let dh = v * df * e * ((omega * t).cos() - sigma / omega * (omega * t).sin());
            (h, df - dh / v)
        }
    }
}

const TANK_STEP: &str = r#"{"format_version": 1, "duration": "2500 s",
    "integrator": {"rtol": 1e-10, "atol": 1e-12},
    "events": [{"type": "step", "at": "100 s", "path": "F_in", "to": "60 mol/s"}],
    "record": {"interval": "5 s", "time_unit": "s", "paths": ["tank.level", "out.F", "tank.M", "tank.outflow"]}}"#;

fn check_tank(fields: &[(&str, &str)], tau_i: Option<f64>) {
    let (plant, x0, res) = run("surge_tank_pi.json", fields, TANK_STEP);
    let (kc, df, t_s) = (50.0, 10.0, 100.0);
    // Level per mole from the model's own liquid volume at the (constant) tank temperature.
    let v = harness::value(&plant, &x0, "tank.level") / harness::value(&plant, &x0, "tank.M");
    let (level, out) = (column(&res, "tank.level"), column(&res, "out.F"));
    // The pump's flow setpoint, an input driven by the level controller, is recorded as the
    // controller's output: the flow the tank delivers, not the flowsheet's initial value.
    let setpoint = column(&res, "tank.outflow");
    let err_sp = setpoint.iter().zip(&out).map(|(s, f)| (s - f).abs()).fold(0.0, f64::max);
    assert!(err_sp < 1e-9 * 50.0, "recorded tank.outflow differs from out.F by {err_sp} mol/s");
    let (mut err_h, mut err_f): (f64, f64) = (0.0, 0.0);
    for (i, &t) in res.times.iter().enumerate() {
        let (h, f) = if t < t_s || (t == t_s && i + 1 < res.times.len() && res.times[i + 1] == t_s) {
            (0.0, 0.0)
        } else {
            tank_closed_form(t - t_s, v, kc, tau_i, df)
        };
        err_h = err_h.max((level[i] - 1.0 - h).abs());
        err_f = err_f.max((out[i] - 50.0 - f).abs());
    }
    eprintln!("tank τ_I = {tau_i:?}: max |Δlevel| {err_h:.2e} m, max |Δoutflow| {err_f:.2e} mol/s; {:?}", res.stats);
    // 1e-6 of the response's own scale: dF/Kc = 0.2 m of level, dF = 10 mol/s of outflow.
    assert!(err_h < 1e-6 * df / kc, "level error {err_h}");
    assert!(err_f < 1e-6 * df, "outflow error {err_f}");
}

#[test]
fn surge_tank_pi_level_follows_the_second_order_closed_form() {
    check_tank(&[], Some(200.0));
}

#[test]
fn surge_tank_p_only_level_follows_the_first_order_closed_form() {
    check_tank(&[("lc.tau_i", "null")], None);
}

#[test]
fn events_land_exactly_on_their_times() {
    let (_, _, res) = run(
        "surge_tank_pi.json",
        &[],
        r#"{"format_version": 1, "duration": "1000 s",
        "events": [{"type": "step", "at": "100.3 s", "path": "F_in", "by": "5 mol/s"},
                   {"type": "pulse", "at": "1.7 min", "path": "lc.sp", "by": "0.1 m", "width": "33.3 s"},
                   {"type": "ramp", "at": "400 s", "path": "F_in", "to": "40 mol/s", "duration": "77.7 s"}],
        "record": {"interval": "50 s", "time_unit": "s", "paths": ["tank.level", "F_in", "lc.sp"]}}"#,
    );
    let want = [100.3, 102.0, 102.0 + 33.3, 400.0, 400.0 + 77.7];
    let got: Vec<f64> = res.events.iter().map(|e| e.0).collect();
    assert_eq!(got, want, "event times are hit exactly");
    // A row just before and just after each scenario event, at exactly its time.
    for t in want {
        assert_eq!(res.times.iter().filter(|&&r| r == t).count(), 2, "rows at {t}");
    }
    let f_in = column(&res, "F_in");
    let k = res.times.iter().rposition(|&t| t == 400.0 + 77.7).unwrap();
    assert_eq!(f_in[k], 40.0, "the ramp ends on its target");
}

const COLUMN_A_STEP: &str = r#"{"format_version": 1, "duration": "2000 min",
    "events": [{"type": "step", "at": "0 min", "path": "feed_source.F", "to": "1.01 kmol/min"}],
    "record": {"interval": "1 min", "paths": ["bottoms.x[light]", "distillate.x[light]", "column.M[1]", "column.M[41]"],
               "totals": ["feed", "distillate", "bottoms"]}}"#;

/// Column A (S&P 2005 §12.4), LV with P level loops, feed 1 → 1.01 kmol/min at t = 0.
/// A run on a thread that has run before (its integrator recycled, `Bdf::recycle`) is the run
/// a new integrator makes, bit for bit: after another plant (the sparse LU's pattern rebuilt),
/// after the same plant (its live matrix, analysis and binding kept), and for the same plant
/// recording other paths (another history kept) or at another tolerance (both bound anew). The
/// references run on threads of their own, which have no integrator to recycle.
#[test]
fn a_run_after_runs_on_the_same_thread_is_bit_for_bit_a_fresh_run() {
    fn bits(scenario: &str) -> (Vec<u64>, Vec<u64>, String) {
        let res = run("column_a.json", &[], scenario).2;
        let rows: Vec<u64> = res.rows.iter().flat_map(|r| r.iter().map(|v| v.to_bits())).collect();
        (res.x.iter().map(|v| v.to_bits()).collect(), rows, format!("{:?}", res.stats))
    }
    let recording = COLUMN_A_STEP.replace(r#""column.M[1]", "column.M[41]""#, r#""column.M[20]""#);
    let tolerance = COLUMN_A_STEP.replace(r#""duration""#, r#""integrator": {"atol": 1e-6}, "duration""#);
    let scenarios = [COLUMN_A_STEP.to_string(), recording, tolerance];
    let fresh: Vec<_> = scenarios
        .iter()
        .map(|sc| {
            let sc = sc.clone();
            std::thread::spawn(move || bits(&sc)).join().unwrap()
        })
        .collect();
    assert!(fresh[1] != fresh[0] && fresh[2] != fresh[0], "the variants are other runs");
    run("surge_tank_pi.json", &[], TANK_STEP);
    for (k, what) in
        [(0, "after another plant"), (0, "after the same plant"), (1, "another recording"), (0, "after it")]
            .into_iter()
            .chain([(2, "another tolerance"), (0, "after it")])
    {
        assert!(bits(&scenarios[k]) == fresh[k], "{what}");
    }
}

#[test]
fn column_a_feed_step_settles_on_the_new_steady_state_with_a_200_min_time_constant() {
    let (plant, x0, res) = run("column_a.json", &[], COLUMN_A_STEP);
    // The steady state at F = 1.01 kmol/min, as `plantwide steady --set feed_source.F=1.01kmol/min`.
    let mut u = plant.input_values();
    assert!(set_input(&plant, &mut u, "feed_source.F", "1.01 kmol/min").unwrap());
    let ss = steady_state(&plant, &u, Some(&x0), &NewtonSettings::default()).unwrap();
    let xb = column(&res, "bottoms.x[light]");
    let yd = column(&res, "distillate.x[light]");
    let (xb_ss, yd_ss) =
        (harness::value(&plant, &ss.x, "bottoms.x[light]"), harness::value(&plant, &ss.x, "distillate.x[light]"));
    let (xb_end, yd_end) = (*xb.last().unwrap(), *yd.last().unwrap());
    eprintln!("xB {xb_end:.9} vs {xb_ss:.9}, yD {yd_end:.9} vs {yd_ss:.9}; {:?}", res.stats);
    assert!((xb_end - xb_ss).abs() < 1e-6 && (yd_end - yd_ss).abs() < 1e-6);
    // First-order-like: 63.2 % of the change at τ, 86.5 % at 2τ, and τ near 200 min (S&P: 194 min).
    let xb0 = xb[0];
    let reach = |frac: f64| {
        let target = xb0 + frac * (xb_end - xb0);
        let i = (1..xb.len()).find(|&i| (xb[i] - target) * (xb_end - xb0) >= 0.0).unwrap();
        let (t0, t1) = (res.times[i - 1], res.times[i]);
        (t0 + (t1 - t0) * (target - xb[i - 1]) / (xb[i] - xb[i - 1])) / 60.0
    };
    let (tau, t86) = (reach(1.0 - (-1.0f64).exp()), reach(1.0 - (-2.0f64).exp()));
    eprintln!("xB: 63 % at {tau:.1} min, 86 % at {t86:.1} min (2τ = {:.1})", 2.0 * tau);
    assert!((170.0..230.0).contains(&tau), "time constant {tau} min");
    assert!((t86 / (2.0 * tau) - 1.0).abs() < 0.1, "first-order-like: 86 % at {t86} min vs 2τ = {}", 2.0 * tau);
    // The stiff case (τL = 0.063 min against a 200 min composition mode) in few steps.
    assert!(res.stats.n_steps < 2000, "{:?}", res.stats);
}

/// Column A's tray temperatures are output-only (constant α: no balance reads them), so the
/// integrator leaves them out and solves them at the end: every final `T` is the bubble point of
/// its stage's liquid (the thermo package's own `bubble_t`, an independent solver) to 1e-9, the
/// outlets' temperature and enthalpy follow from it; recording one makes it a variable the
/// integrator carries, and its recorded end value agrees with the solve.
#[test]
fn column_a_output_temperatures_are_the_final_bubble_points() {
    let (plant, _, res) = run("column_a.json", &[], COLUMN_A_STEP);
    let thermo = plant.thermo();
    let value = |path: &str| harness::value(&plant, &res.x, path);
    let mut worst = 0.0f64;
    for s in 1..=41 {
        let x = [value(&format!("column.x[{s}][light]")), value(&format!("column.x[{s}][heavy]"))];
        let bubble = thermo.bubble_t(101_325.0, &x).unwrap().t;
        worst = worst.max((value(&format!("column.T[{s}]")) - bubble).abs() / bubble);
    }
    eprintln!("final T against bubble_t: worst relative {worst:.1e}");
    assert!(worst < 1e-9, "{worst}");
    let (t41, x41) = (value("column.T[41]"), [value("column.x[41][light]"), value("column.x[41][heavy]")]);
    assert_eq!(value("distillate.T"), t41);
    assert_eq!(value("distillate.h"), thermo.h_liq(t41, &x41));
    let recorded = COLUMN_A_STEP.replace(r#""column.M[41]"]"#, r#""column.M[41]", "column.T[21]"]"#);
    let (_, _, carried) = run("column_a.json", &[], &recorded);
    let t21 = *column(&carried, "column.T[21]").last().unwrap();
    eprintln!("T[21]: carried {t21:.9} K, solved at the end {:.9} K", value("column.T[21]"));
    assert!((t21 - value("column.T[21]")).abs() < 1e-6, "{t21} vs {}", value("column.T[21]"));
}

/// Component inventories: Δ(Σ stage holdups) = ∫(feed − distillate − bottoms) dt, the integrals
/// taken by the integrator's own BDF formula as quadratures.
#[test]
fn column_a_conserves_component_inventories() {
    let (plant, x0, res) = run("column_a.json", &[], COLUMN_A_STEP);
    let x = &res.x;
    for c in ["light", "heavy"] {
        let holdup =
            |x: &[f64]| (1..=41).map(|s| harness::value(&plant, x, &format!("column.n[{s}][{c}]"))).sum::<f64>();
        let total = |s: &str| *column(&res, &format!("{s}.total[{c}]")).last().unwrap();
        let net = total("feed") - total("distillate") - total("bottoms");
        let change = holdup(x) - holdup(&x0);
        let rel = (change - net).abs() / total("feed");
        eprintln!(
            "{c}: Δholdup {change:.6} mol, ∫(in − out) {net:.6} mol, fed {:.1} mol: relative gap {rel:.1e}",
            total("feed")
        );
        assert!(rel < 1e-8 && (change - net).abs() < 1e-8 * change.abs().max(1.0), "{c}: {change} vs {net}");
    }
}

/// The end-of-run check (`SimulationResult::conservation`): on every shipped scenario the units'
/// holdups change by what the boundary streams brought in and took out, to round-off (the
/// invariant is linear, so BDF and its Newton iteration keep it; measured 7e-16 … 3e-14), and
/// its boundary integrals are the ones `record.totals` integrates.
#[test]
fn shipped_scenarios_conserve_moles_to_round_off() {
    for (fs, sc) in [
        ("column_a.json", "column_a_feed_step.json"),
        ("surge_tank_pi.json", "surge_tank_inflow_step.json"),
        ("surge_tank_pi.json", "surge_tank_upsets.json"),
    ] {
        let text = std::fs::read_to_string(flowsheet(&format!("scenarios/{sc}"))).unwrap();
        let (_, _, res) = run(fs, &[], &text);
        let c = &res.conservation;
        eprintln!("{sc}: {} basis, largest relative error {:.1e}", c.basis, c.worst());
        assert_eq!(c.basis, "moles");
        assert!(c.worst() < 1e-12, "{sc}: {c:?}");
        assert!(c.balances.iter().all(|b| b.fed > 0.0 && b.removed > 0.0), "{sc}: {c:?}");
    }
    // The boundary integrals equal the recorded totals of the same streams.
    let (_, _, res) = run("column_a.json", &[], COLUMN_A_STEP);
    for (b, c) in res.conservation.balances.iter().zip(["light", "heavy"]) {
        let last = |s: &str| *column(&res, &format!("{s}.total[{c}]")).last().unwrap();
        assert_eq!(b.name, c);
        assert!((b.fed - last("feed")).abs() <= 1e-12 * b.fed, "{b:?}");
        assert!((b.removed - last("distillate") - last("bottoms")).abs() <= 1e-12 * b.removed, "{b:?}");
    }
}

/// Plants with a CSTR (A → B in the jacketed reactor; A → B with a column and recycle) are
/// checked on mass, which the reactions conserve, while the moles of A are consumed.
#[test]
fn reactor_plants_conserve_mass_to_round_off() {
    for (fs, feed) in [("cstr_multiplicity.json", "fresh.F"), ("reactor_column_recycle.json", "fresh.F")] {
        let scenario = format!(
            r#"{{"format_version": 1, "duration": "2 h",
            "events": [{{"type": "step", "at": "5 min", "path": "{feed}", "by": "1 kmol/h"}}],
            "record": {{"totals": ["feed"]}}}}"#
        );
        let (plant, x0, res) = run(fs, &[], &scenario);
        let c = &res.conservation;
        eprintln!("{fs}: {} basis, relative error {:.1e}, {:?}", c.basis, c.worst(), c.balances[0]);
        assert_eq!((c.basis, c.balances.len(), c.balances[0].unit), ("mass", 1, "kg"));
        assert!(c.worst() < 1e-12, "{fs}: {c:?}");
        // A is fed and reacts: its moles are not conserved.
        let a_fed = *column(&res, "feed.total[A]").last().unwrap();
        let a_held = |x: &[f64]| harness::value(&plant, x, "reactor.N[A]");
        assert!(a_fed > a_held(&res.x) - a_held(&x0) + 1.0, "{fs}: A reacted");
    }
}

/// Column A's feed step run for 1200 min with a snapshot at 700 min: the plant, its steady state,
/// the scenario, the run and the snapshot (through its JSON, as a file holds it).
fn column_a_snapshot_at_700_min() -> (Plant, Vec<f64>, String, SimulationResult, Snapshot) {
    let scenario = COLUMN_A_STEP.replace(
        r#""duration": "2000 min","#,
        r#""duration": "1200 min", "snapshots": [{"at": "700 min", "file": "snap.json"}],"#,
    );
    let (plant, x0) = converged("column_a.json", &[]);
    let mut saved = None;
    let full = run_from(&plant, &scenario, Start::Steady(&x0), &mut |p| {
        if let Progress::Snapshot { file, snapshot } = p {
            assert_eq!(file, "snap.json");
            saved = Some(serde_json::to_string(snapshot).unwrap());
        }
    });
    let snap: Snapshot = serde_json::from_str(&saved.expect("snapshot taken")).unwrap();
    (plant, x0, scenario, full, snap)
}

/// Snapshot at 700 min → JSON → resume: the same trajectory as the uninterrupted run (bit for
/// bit: the snapshot holds the BDF history and Jacobian). A resume with a retuned level loop
/// (changed fingerprint) restarts from the same state and settles on the same compositions.
#[test]
fn snapshot_and_resume_continue_the_uninterrupted_trajectory() {
    let (_, _, scenario, full, snap) = column_a_snapshot_at_700_min();
    assert!(snap.t >= 700.0 * 60.0 && snap.t < 800.0 * 60.0, "{}", snap.t);
    let (plant2, _) = converged("column_a.json", &[]);
    let resumed = run_from(&plant2, &scenario, Start::Snapshot(&snap), &mut |_| {});
    let mut compared = 0;
    let mut worst: f64 = 0.0;
    for (i, t) in resumed.times.iter().enumerate() {
        let j = full.times.iter().position(|u| u == t).unwrap_or_else(|| panic!("time {t} not in the full run"));
        for (a, b) in resumed.rows[i].iter().zip(&full.rows[j]) {
            worst = worst.max((a - b).abs() / b.abs().max(1e-3));
        }
        compared += 1;
    }
    eprintln!("resumed at {:.3} min: {compared} rows, largest relative difference {worst:.1e}", snap.t / 60.0);
    assert!(compared > 400 && worst <= 1e-10, "{compared} rows, {worst}");
    // Retuned: Kc of the reboiler level loop doubled for the rest of the run.
    let (plant3, _) = converged("column_a.json", &[("reboiler_level.kc", "\"20 kmol/min/kmol\"")]);
    let spec = parse_scenario(&scenario, "s.json").unwrap();
    let sc = resolve(&spec, &plant3, "s.json").unwrap();
    let retuned = simulate(&plant3, &sc, Start::Snapshot(&snap), "retuned", &mut |_| {}).unwrap();
    assert!(retuned.stats.n_restarts >= 1);
    let xb = column(&retuned, "bottoms.x[light]");
    let xb_full = column(&full, "bottoms.x[light]");
    let diff = (xb.last().unwrap() - xb_full.last().unwrap()).abs();
    eprintln!("retuned resume: xB(end) differs by {diff:.2e}");
    assert!(diff < 1e-6, "level tuning does not move the compositions' steady state: {diff}");
}

/// A snapshot resumed with *another* scenario (what-if runs from one saved state): its events
/// are the new scenario's from the snapshot's time on, its rows the new interval's after it. The
/// saved counters meant other instants: the next event index (1 in the old scenario) skipped the
/// new one, and the next recording (k = 700 of 1 min) fell at 2100 s of a 3 s interval, rows
/// extrapolated 11 hours backwards (exit 0; soak seed 2). The check is the continuous run with
/// both events and the same snapshot: after it, it is the resumed run (same history, same stops).
#[test]
fn a_snapshot_resumed_with_another_scenario_runs_that_scenario_from_its_time() {
    let (plant, x0, _, _, snap) = column_a_snapshot_at_700_min();
    let what_if = |events: &str| {
        format!(
            r#"{{"format_version": 1, "duration": "1000 min", "events": [{events}
                {{"type": "step", "at": "900 min", "path": "feed_source.F", "to": "0.95 kmol/min"}}],
            "record": {{"interval": "3 min", "paths": ["bottoms.x[light]", "feed_source.F"],
                        "totals": ["feed", "distillate", "bottoms"]}}}}"#
        )
    };
    let resumed = run_from(&plant, &what_if(""), Start::Snapshot(&snap), &mut |_| {});
    let both = r#"{"type": "step", "at": "0 min", "path": "feed_source.F", "to": "1.01 kmol/min"},"#;
    // The continuous run takes the same snapshot (and so goes on from the state it saved) and
    // records the same totals (integrator states).
    let with_snapshot =
        what_if(both).replace(r#""events""#, r#""snapshots": [{"at": "700 min", "file": "s"}], "events""#);
    let continuous = run_from(&plant, &with_snapshot, Start::Steady(&x0), &mut |_| {});
    assert!(resumed.times[0] > snap.t && resumed.times[0] <= snap.t + 180.0, "first row at {} s", resumed.times[0]);
    let feed = column(&resumed, "feed_source.F");
    let (stepped, restored) = (1.01e3 / 60.0, 0.95e3 / 60.0);
    assert!(
        abs_diff_eq!(feed[0], stepped, epsilon = 1e-12 * stepped)
            && abs_diff_eq!(*feed.last().unwrap(), restored, epsilon = 1e-12 * restored),
        "the new step acted: {feed:?}"
    );
    let (xb, xb_full) = (column(&resumed, "bottoms.x[light]"), column(&continuous, "bottoms.x[light]"));
    let mut worst: f64 = 0.0;
    for (i, t) in resumed.times.iter().enumerate() {
        let j = continuous
            .times
            .iter()
            .position(|u| u == t)
            .unwrap_or_else(|| panic!("time {t} not in the continuous run"));
        worst = worst.max((xb[i] - xb_full[j]).abs());
    }
    eprintln!("resumed with another scenario: {} rows, largest difference in xB {worst:.1e}", resumed.times.len());
    assert!(worst < 1e-9, "{worst}");
    // A duration that ends before the snapshot's time has nothing to run: refused, by name.
    let spec =
        parse_scenario(&what_if("").replace("1000 min", "500 min").replace("900 min", "400 min"), "s.json").unwrap();
    let sc = resolve(&spec, &plant, "s.json").unwrap();
    let e = simulate(&plant, &sc, Start::Snapshot(&snap), "test", &mut |_| {}).unwrap_err();
    assert!(e.is_user_error() && e.to_string().contains("the duration must reach past it"), "{e}");
}

/// Level per mole `v` of the surge tank and its initial state.
fn tank(fields: &[(&str, &str)]) -> (Plant, Vec<f64>, f64) {
    let (plant, x0) = converged("surge_tank_pi.json", fields);
    let v = harness::value(&plant, &x0, "tank.level") / harness::value(&plant, &x0, "tank.M");
    (plant, x0, v)
}

/// Manual at 100 s (bumpless), inflow +10 mol/s at 200 s: the level ramps at v·10 m/s exactly;
/// back to auto at 500 s, the PI loop returns the level to its setpoint (the integral tracked the
/// manual output with lag τ_I, so the return bumps by about τ_I·Kc·de/dt while the level ramps).
#[test]
fn manual_mode_holds_the_output_and_auto_returns_to_setpoint() {
    let (plant, x0, v) = tank(&[]);
    let res = run_from(
        &plant,
        r#"{"format_version": 1, "duration": "3000 s", "integrator": {"rtol": 1e-9},
        "events": [{"type": "mode", "at": "100 s", "controller": "lc", "mode": "manual"},
                   {"type": "step", "at": "200 s", "path": "F_in", "to": "60 mol/s"},
                   {"type": "mode", "at": "500 s", "controller": "lc", "mode": "auto"}],
        "record": {"interval": "10 s", "time_unit": "s", "paths": ["tank.level", "out.F", "lc.op"]}}"#,
        Start::Steady(&x0),
        &mut |_| {},
    );
    let (level, out) = (column(&res, "tank.level"), column(&res, "out.F"));
    let mut worst: f64 = 0.0;
    for (i, &t) in res.times.iter().enumerate().filter(|(_, t)| (100.0..500.0).contains(*t)) {
        assert!((out[i] - 50.0).abs() < 1e-9, "manual output held at {t}: {}", out[i]);
        worst = worst.max((level[i] - (1.0 + v * 10.0 * (t - 200.0).max(0.0))).abs());
    }
    assert!(worst < 1e-9, "level ramp {worst}");
    assert!((level.last().unwrap() - 1.0).abs() < 1e-3 && (out.last().unwrap() - 60.0).abs() < 1e-2);
}

/// Each recorded path measured by a controller carries its setpoint, the value the scenario gave
/// it at each recorded time (a step at 100 s, recorded in two rows at 100 s: before and after
/// it); a path no controller measures, and a total, carry none.
#[test]
fn a_measured_path_records_its_setpoint_and_others_none() {
    let (plant, x0, _) = tank(&[]);
    let res = run_from(
        &plant,
        r#"{"format_version": 1, "duration": "300 s",
        "events": [{"type": "step", "at": "100 s", "path": "lc.sp", "to": "1.2 m"}],
        "record": {"interval": "10 s", "time_unit": "s", "paths": ["out.F", "tank.level"], "totals": ["out"]}}"#,
        Start::Steady(&x0),
        &mut |_| {},
    );
    assert_eq!(res.references.len(), res.columns.len());
    let level = res.columns.iter().position(|c| c.path == "tank.level").unwrap();
    for (k, r) in res.references.iter().enumerate() {
        assert_eq!(r.is_some(), k == level, "reference of {}", res.columns[k].path);
    }
    let sp = res.references[level].as_ref().unwrap();
    assert_eq!(sp.len(), res.times.len());
    let mut at_step = Vec::new();
    for (&t, &v) in res.times.iter().zip(sp) {
        if t == 100.0 {
            at_step.push(v);
        } else {
            assert_eq!(v, if t < 100.0 { 1.0 } else { 1.2 }, "setpoint at {t} s");
        }
    }
    assert_eq!(at_step, [1.0, 1.2]);
}

/// The outflow's flow setpoint sticks at 200 s; the inflow then rises: the level ramps exactly
/// while the controller's output (driving nothing any more) winds up.
#[test]
fn stuck_valve_freezes_the_input_and_the_controller_winds_up() {
    // Continuous, and scanned every 5 s (the scan must not move a stuck input either).
    for sampling in ["{}", r#"{"lc": "5 s"}"#] {
        let (plant, x0, v) = tank(&[]);
        let scenario = r#"{"format_version": 1, "duration": "600 s", "integrator": {"rtol": 1e-9},
            "events": [{"type": "valve_stuck", "at": "100 s", "path": "tank.outflow"},
                       {"type": "step", "at": "200 s", "path": "F_in", "to": "60 mol/s"}],
            "sampling": SAMPLING,
            "record": {"interval": "10 s", "time_unit": "s", "paths": ["tank.level", "out.F", "lc.op"]}}"#;
        let res = run_from(&plant, &scenario.replace("SAMPLING", sampling), Start::Steady(&x0), &mut |_| {});
        let (level, out, op) = (column(&res, "tank.level"), column(&res, "out.F"), column(&res, "lc.op"));
        let n = level.len() - 1;
        assert!(out.iter().all(|f| (f - 50.0).abs() < 1e-9), "outflow frozen ({sampling})");
        assert!((level[n] - (1.0 + v * 10.0 * 400.0)).abs() < 1e-9, "{}", level[n]);
        assert!(op[n] > 60.0, "the PI output keeps rising: {}", op[n]);
    }
}

/// Feed lost at 100 s with a P-only loop: the first-order closed form with dF = −50 mol/s.
#[test]
fn feed_lost_drains_the_tank_along_the_first_order_closed_form() {
    let (plant, x0, v) = tank(&[("lc.tau_i", "null")]);
    let res = run_from(
        &plant,
        r#"{"format_version": 1, "duration": "1000 s", "integrator": {"rtol": 1e-10, "atol": 1e-12},
        "events": [{"type": "feed_lost", "at": "100 s", "unit": "inflow"}],
        "record": {"interval": "10 s", "time_unit": "s", "paths": ["tank.level", "feed.F"]}}"#,
        Start::Steady(&x0),
        &mut |_| {},
    );
    let level = column(&res, "tank.level");
    let n = level.len() - 1;
    let (h, _) = tank_closed_form(900.0, v, 50.0, None, -50.0);
    assert!((level[n] - 1.0 - h).abs() < 1e-7, "{} vs {}", level[n], 1.0 + h);
    assert!(column(&res, "feed.F").last().unwrap().abs() < 1e-12);
}

/// P-only loop scanned every 10 s: the pump setpoint is held between scans, so the level is
/// piecewise linear: h_{k+1} = h_k + v T (F_in − F0 − Kc (h_k − sp)) (exact recurrence).
#[test]
fn sampled_controller_holds_its_output_between_scans() {
    let (plant, x0, v) = tank(&[("lc.tau_i", "null")]);
    let res = run_from(
        &plant,
        r#"{"format_version": 1, "duration": "600 s", "integrator": {"rtol": 1e-10, "atol": 1e-12},
        "events": [{"type": "step", "at": "0 s", "path": "F_in", "to": "60 mol/s"}],
        "sampling": {"lc": "10 s"},
        "record": {"interval": "10 s", "time_unit": "s", "paths": ["tank.level", "out.F"]}}"#,
        Start::Steady(&x0),
        &mut |_| {},
    );
    let level = column(&res, "tank.level");
    let mut h = 1.0;
    let mut worst: f64 = 0.0;
    for (i, &t) in res.times.iter().enumerate().skip(2) {
        let k = (t / 10.0).round();
        assert_eq!(t, k * 10.0);
        h += v * 10.0 * (10.0 - 50.0 * (h - 1.0));
        worst = worst.max((level[i] - h).abs());
    }
    assert!(worst < 1e-9, "{worst}");
}

/// Analyzer on the level (sample 20 s, dead time 30 s) with a P-only loop: the controller acts on
/// h(kT) from kT + 30 s on; the level is piecewise linear between releases (exact recurrence).
#[test]
fn analyzer_samples_and_delays_the_measurement() {
    let (plant, x0, v) = tank(&[("lc.tau_i", "null")]);
    let res = run_from(
        &plant,
        r#"{"format_version": 1, "duration": "400 s", "integrator": {"rtol": 1e-10, "atol": 1e-12},
        "events": [{"type": "step", "at": "0 s", "path": "F_in", "to": "60 mol/s"}],
        "analyzers": {"lc": {"sample_time": "20 s", "dead_time": "30 s"}},
        "record": {"interval": "10 s", "time_unit": "s", "paths": ["tank.level", "out.F"]}}"#,
        Start::Steady(&x0),
        &mut |_| {},
    );
    // Exact piecewise-linear solution on a 10 s grid (all sample and release times are on it).
    let (mut h, mut held, mut queue) = (1.0, 1.0, Vec::new());
    let mut exact = vec![(0.0, h)];
    for k in 0..40 {
        let t = k as f64 * 10.0;
        if k % 2 == 0 {
            queue.push((t + 30.0, h));
        }
        if let Some(p) = queue.iter().position(|&(r, _)| r <= t) {
            held = queue.remove(p).1;
        }
        h += v * 10.0 * (10.0 - 50.0 * (held - 1.0));
        exact.push((t + 10.0, h));
    }
    let level = column(&res, "tank.level");
    let mut worst: f64 = 0.0;
    for (i, &t) in res.times.iter().enumerate() {
        if let Some(&(_, h)) = exact.iter().find(|(te, _)| *te == t) {
            worst = worst.max((level[i] - h).abs());
        }
    }
    assert!(worst < 1e-9, "{worst}");
}

/// A run rewires a copy of the plant, never the caller's: after a run with an analyzer, a sampled
/// controller and a stuck valve the plant has the same inputs and reads, and a second run on it
/// repeats the first exactly.
#[test]
fn a_run_leaves_the_callers_plant_as_it_was() {
    let (plant, x0, _) = tank(&[("lc.tau_i", "null")]);
    let reads: Vec<_> = plant.blocks().iter().map(|b| b.reads.clone()).collect();
    let driven: Vec<_> = plant.inputs().iter().map(|i| (i.path.clone(), i.driven_by)).collect();
    let scenario = r#"{"format_version": 1, "duration": "300 s",
        "events": [{"type": "step", "at": "0 s", "path": "F_in", "to": "60 mol/s"},
                   {"type": "valve_stuck", "at": "200 s", "path": "tank.outflow"}],
        "analyzers": {"lc": {"sample_time": "20 s", "dead_time": "30 s"}},
        "sampling": {"lc": "10 s"},
        "record": {"interval": "10 s", "time_unit": "s", "paths": ["tank.level", "out.F"]}}"#;
    let first = run_from(&plant, scenario, Start::Steady(&x0), &mut |_| {});
    assert!(plant.blocks().iter().map(|b| &b.reads).eq(&reads), "reads rewired");
    assert!(plant.inputs().iter().map(|i| (i.path.clone(), i.driven_by)).eq(driven), "inputs rewired");
    let second = run_from(&plant, scenario, Start::Steady(&x0), &mut |_| {});
    assert!(first.rows == second.rows && first.stats == second.stats, "the second run differs");
}

/// The surge tank with extra controllers (JSON object of name → description) added to the file.
fn tank_with(controllers: serde_json::Value) -> (Plant, Vec<f64>) {
    let path = flowsheet("surge_tank_pi.json");
    let mut doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let map = doc["controllers"].as_object_mut().unwrap();
    for (k, v) in controllers.as_object().unwrap() {
        map.insert(k.clone(), v.clone());
    }
    let spec = parse_spec(&doc.to_string(), &path).unwrap_or_else(|e| panic!("{e}"));
    let plant = assemble(&spec, &path).unwrap_or_else(|e| panic!("{e}"));
    let ss = steady_state(&plant, &plant.input_values(), None, &NewtonSettings::default()).unwrap();
    (plant, ss.x)
}

/// A first-order lag on the inflow, with and without a rate limit, after a step of 10 mol/s:
/// `op = u − Δ e^{−t/τ}`; rate-limited at r, it ramps at r until `u − op = rτ`, then lags.
#[test]
fn lag_and_rate_limit_follow_their_closed_forms() {
    let (plant, x0) = tank_with(serde_json::json!({
        "lag": {"type": "lag", "pv": "feed.F", "tau": "20 s"},
        "slow": {"type": "lag", "pv": "feed.F", "tau": "20 s", "rate_limit": "0.1 mol/s/s"}
    }));
    let res = run_from(
        &plant,
        r#"{"format_version": 1, "duration": "300 s", "integrator": {"rtol": 1e-10, "atol": 1e-12},
        "events": [{"type": "step", "at": "0 s", "path": "F_in", "by": "10 mol/s"}],
        "record": {"interval": "1 s", "time_unit": "s", "paths": ["lag.op", "slow.op"]}}"#,
        Start::Steady(&x0),
        &mut |_| {},
    );
    let (lag, slow) = (column(&res, "lag.op"), column(&res, "slow.op"));
    let (tau, r, du) = (20.0, 0.1, 10.0);
    let t1 = (du - r * tau) / r;
    let (mut e_lag, mut e_slow): (f64, f64) = (0.0, 0.0);
    for (i, &t) in res.times.iter().enumerate().skip(2) {
        e_lag = e_lag.max((lag[i] - (60.0 - du * (-t / tau).exp())).abs());
        let want = if t <= t1 { 50.0 + r * t } else { 60.0 - r * tau * (-(t - t1) / tau).exp() };
        e_slow = e_slow.max((slow[i] - want).abs());
    }
    eprintln!("lag error {e_lag:.1e}, rate-limited lag error {e_slow:.1e} mol/s");
    assert!(e_lag < 1e-6 && e_slow < 1e-6, "{e_lag} {e_slow}");
}

/// Padé (4,4) dead time of 30 s on the inflow, driven by a sinusoid of period 600 s (ωθ = 0.31):
/// once the filter's own transient has died out, the output is the input 30 s earlier (Padé
/// phase error ~ (ωθ)⁹/(8! 9!), far below the integration tolerance; all-pass gain 1).
#[test]
fn pade_delay_delays_a_sinusoid_by_its_dead_time() {
    let (plant, x0) =
        tank_with(serde_json::json!({"dly": {"type": "delay", "pv": "feed.F", "delay": "30 s", "order": 4}}));
    let res = run_from(
        &plant,
        r#"{"format_version": 1, "duration": "3000 s", "integrator": {"rtol": 1e-9, "atol": 1e-12},
        "events": [{"type": "sinusoid", "at": "0 s", "path": "F_in", "amplitude": "5 mol/s", "period": "600 s"}],
        "record": {"interval": "5 s", "time_unit": "s", "paths": ["dly.op"]}}"#,
        Start::Steady(&x0),
        &mut |_| {},
    );
    let out = column(&res, "dly.op");
    let w = std::f64::consts::TAU / 600.0;
    let worst = res
        .times
        .iter()
        .zip(&out)
        .filter(|(t, _)| **t >= 1000.0)
        .map(|(t, y)| (y - (50.0 + 5.0 * (w * (t - 30.0)).sin())).abs())
        .fold(0.0, f64::max);
    eprintln!("Padé-4 delay: largest error {worst:.1e} mol/s on a 5 mol/s sinusoid");
    assert!(worst < 1e-5 * 5.0, "{worst}");
}

/// `plantwide run`: CSV with units in the header, JSON summary, SVG plot, a snapshot written by
/// the scenario and a resume from it that reproduces the rest of the CSV.
#[test]
fn cli_run_writes_csv_summary_plot_and_resumes_from_its_snapshot() {
    let dir = std::env::temp_dir().join(format!("plantwide_run_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fs = flowsheet("surge_tank_pi.json");
    let sc = flowsheet("scenarios/surge_tank_inflow_step.json");
    let run = |extra: &[&str], csv: &str| {
        let out = harness::command()
            .current_dir(&dir)
            .args(["run", &fs, "--scenario", &sc, "--csv", csv])
            .args(extra)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8(out.stdout).unwrap()
    };
    let json = run(&["--json", "--plot", "trend.svg"], "full.csv");
    let summary: serde_json::Value = serde_json::from_str(&json).unwrap();
    let level = summary["paths"].as_array().unwrap().iter().find(|p| p["path"] == "tank.level").unwrap();
    assert_eq!(level["reference"], "setpoint");
    assert!(level["iae"].as_f64().unwrap() > 0.0 && level["max_deviation"].as_f64().unwrap() > 0.0);
    assert!((summary["final_values"]["out.F"].as_f64().unwrap() - 60.0).abs() < 1e-3);
    let conservation = &summary["conservation"];
    assert_eq!(conservation["basis"], "moles");
    assert!(conservation["max_relative_error"].as_f64().unwrap() < 1e-12, "{conservation}");
    assert_eq!(conservation["balances"][0]["name"], "water");
    let full = std::fs::read_to_string(dir.join("full.csv")).unwrap();
    assert_eq!(full.lines().next().unwrap(), "time [s],tank.level [m],out.F [mol/s],lc.sp [m]");
    assert!(std::fs::read_to_string(dir.join("trend.svg")).unwrap().contains("tank.level [m]"));
    // Resume from the snapshot the scenario wrote at 1000 s.
    run(&["--resume", "surge_tank_1000s.snapshot.json"], "resumed.csv");
    let resumed = std::fs::read_to_string(dir.join("resumed.csv")).unwrap();
    let tail: Vec<&str> = resumed.lines().skip(1).collect();
    assert!(
        tail.len() > 250 && full.lines().skip(1).collect::<Vec<_>>().ends_with(&tail),
        "the resumed rows are the full run's"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn cli_run_reports_scenario_errors_with_their_json_paths() {
    let dir = std::env::temp_dir().join(format!("plantwide_run_err_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.json");
    // Run the PI surge tank through the scenario `text`: (exit code, stderr).
    let run = |text: &str| {
        std::fs::write(&bad, text).unwrap();
        let out = harness::command()
            .args(["run", &flowsheet("surge_tank_pi.json"), "--scenario"])
            .arg(&bad)
            .args(["--csv", "/dev/null"])
            .output()
            .unwrap();
        (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let (code, err) = run(r#"{"format_version": 1, "duration": "10 min",
        "events": [{"type": "step", "at": "1 min", "path": "F_inn", "to": "60 mol/s"},
                   {"type": "step", "at": "2 min", "path": "tank.outflow", "to": "60 mol/s"},
                   {"type": "ramp", "at": "3 min", "path": "lc.sp", "to": "5 kg", "duration": "1 min"}]}"#);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("events[0].path: no input `F_inn` (did you mean `F_in`?)"), "{err}");
    assert!(err.contains("events[1].path: input `tank.outflow` is driven by controller `lc`"), "{err}");
    assert!(err.contains("events[2].to: `5 kg` is a mass but a length is expected"), "{err}");
    let (code, err) = run(r#"{"format_version": 1, "duration": "10 min", "events": [{"type": "jump", "at": 0}]}"#);
    assert!(code == Some(1) && err.contains("events[0]") && err.contains("unknown variant `jump`"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The minimal flash case of the newcomer reports (`tests/data/newcomer3/min_flash_step.json`):
/// subcooled feed heated to a fixed 108 °C and flashed at 1.3 atm, its level on a PI loop.
fn min_flash() -> (Plant, Vec<f64>) {
    let path = harness::fixture("data/newcomer3/min_flash_step.json");
    let plant = plantwide::flowsheet::load_file(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
    let ss = steady_state(&plant, &plant.input_values(), None, &NewtonSettings::default()).unwrap();
    (plant, ss.x)
}

/// A +10 % feed step at 10 min into the flash, then the same change as a ramp of `ramp`.
fn min_flash_scenario(change: &str, duration: &str) -> String {
    format!(
        r#"{{"format_version": 1, "duration": "{duration}", "events": [{change}],
        "record": {{"interval": "1 min", "paths": ["flash_vapour.F", "flash_liquid.F", "flash.level"]}}}}"#
    )
}

/// A feed step into a flash drum fed at a fixed temperature restarts from a consistent state
/// (it failed at the step: the drum's energy balance dropped `h_L dM/dt`, so the vapour depended
/// on the enthalpy datum and went negative). Independent checks: just after the step the
/// composition, temperature and `L` are those before it, so the datum-free balance
/// `V = F (h_F − h_L)/(h_V − h_L)` moves `V` in proportion to `F` (×1.1); a ramp of 0.1 s ends
/// where the step does; the run conserves moles; and the drum settles on the steady state of the
/// new feed, converged on its own.
#[test]
fn flash_feed_step_restarts_consistently_and_matches_a_short_ramp() {
    let (plant, x0) = min_flash();
    let step = r#"{"type": "step", "at": "10 min", "path": "feed_source.F", "to": "181.5 kmol/h"}"#;
    let ramp =
        r#"{"type": "ramp", "at": "10 min", "path": "feed_source.F", "to": "181.5 kmol/h", "duration": "0.1 s"}"#;
    let by_step = run_from(&plant, &min_flash_scenario(step, "300 min"), Start::Steady(&x0), &mut |_| {});
    let by_ramp = run_from(&plant, &min_flash_scenario(ramp, "300 min"), Start::Steady(&x0), &mut |_| {});
    // Rows at 10 min: the one before the event and the one after it.
    let v = column(&by_step, "flash_vapour.F");
    let at = |t: f64| (0..by_step.times.len()).filter(|&k| by_step.times[k] == t).collect::<Vec<_>>();
    let rows = at(600.0);
    assert_eq!(rows.len(), 2, "{:?}", by_step.times);
    let ratio = v[rows[1]] / v[rows[0]];
    eprintln!("V before {:.12} mol/s, after {:.12} mol/s: ratio {ratio:.15}", v[rows[0]], v[rows[1]]);
    assert!((ratio - 1.1).abs() < 1e-9, "{ratio}");
    for res in [&by_step, &by_ramp] {
        assert!(res.conservation.worst() < 1e-12, "{:?}", res.conservation);
    }
    let worst = (0..plant.n_vars())
        .map(|i| (by_step.x[i] - by_ramp.x[i]).abs() / plant.vars()[i].spec.nominal.max(by_step.x[i].abs()))
        .fold(0.0, f64::max);
    eprintln!("step vs 0.1 s ramp, largest relative difference at 300 min: {worst:.1e}");
    assert!(worst < 1e-5, "{worst}");
    let mut moved = plant.clone();
    moved.set_input_value(plant.input("feed_source.F").unwrap(), 181.5 / 3.6);
    let ss = steady_state(&moved, &moved.input_values(), Some(&x0), &NewtonSettings::default()).unwrap();
    for path in ["flash_vapour.F", "flash_liquid.F", "flash_liquid.T", "flash.level"] {
        let (a, b) = (harness::value(&plant, &by_step.x, path), harness::value(&plant, &ss.x, path));
        eprintln!("{path}: run {a:.9}, steady state {b:.9}");
        assert!((a - b).abs() < 1e-5 * b.abs(), "{path}: {a} vs {b}");
    }
}

/// A failure of the consistent start names the unit, equation and variable wherever it reaches
/// the user: through a `Session` (plant tests, surge sizing) as through `simulate`, with the
/// variable it left on a bound. The flash's feed cooled to 40 K, where the K-values vanish and the
/// incipient vapour has no composition, has no consistent state after the change (a feed merely
/// below the bubble point runs the drum all liquid: the next test).
#[test]
fn a_failed_consistent_start_names_its_unit_and_variable_in_a_session() {
    use plantwide::solve::dynamic::Session;
    let (plant, x0) = min_flash();
    let mut s = Session::new(&plant, &x0).unwrap();
    s.advance_to(60.0).unwrap();
    s.set_input(plant.input("preheater.T_out").unwrap(), 40.0);
    // `in equation 24 (preheater: equation for hot.T, variable hot.T)`: which equation is worst
    // where the line search stops is Newton's business; that it is named is this test's.
    let named = |msg: &str| {
        let Some((_, rest)) = msg.split_once("in equation ") else { return false };
        let unit = rest.split_once(" (").and_then(|(_, r)| r.split_once(": equation for ")).map(|(u, _)| u);
        unit.is_some_and(|u| plant.blocks().iter().any(|b| b.name == u)) && rest.contains(", variable ")
    };
    let msg = s.advance_to(120.0).unwrap_err().to_string();
    eprintln!("{msg}");
    assert!(
        msg.contains("consistent initialization failed at t = 60 s")
            && named(&msg)
            && msg.contains("beyond the bounds of `flash_vapour.F` at its lower bound 0")
            && msg.contains("a flow reversing"),
        "{msg}"
    );
    // `simulate` says the same.
    let scenario =
        min_flash_scenario(r#"{"type": "step", "at": "1 min", "path": "preheater.T_out", "to": "40 K"}"#, "5 min");
    let spec = parse_scenario(&scenario, "scenario.json").unwrap();
    let sc = resolve(&spec, &plant, "scenario.json").unwrap();
    let msg = simulate(&plant, &sc, Start::Steady(&x0), "test", &mut |_| {}).unwrap_err().to_string();
    eprintln!("{msg}");
    assert!(named(&msg), "{msg}");
}

/// A flash drum whose feed turns subcooled runs all liquid and comes back (issue 53: the plant
/// generator's flash → tank → column trains stopped with "flash_vapour.F at its lower bound 0" when a
/// feed change took the drum below its bubble point, as the newcomer's D2 drum did). The preheater's
/// outlet falls from 108 to 90 °C (below the bubble point at 1.3 atm) for 20 min: no vapour while it
/// is cold, the liquid leaving with the feed's enthalpy, material conserved, and the first steady
/// state again once it is warm.
#[test]
fn a_flash_drum_runs_all_liquid_while_its_feed_is_subcooled_and_comes_back() {
    let (plant, x0) = min_flash();
    let scenario = r#"{"format_version": 1, "duration": "300 min",
        "events": [{"type": "step", "at": "10 min", "path": "preheater.T_out", "to": "90 degC"},
                   {"type": "step", "at": "30 min", "path": "preheater.T_out", "to": "108 degC"}],
        "record": {"interval": "1 min", "paths": ["flash_vapour.F", "flash_liquid.T", "flash_liquid.h", "hot.h"]}}"#;
    let res = run_from(&plant, scenario, Start::Steady(&x0), &mut |_| {});
    let (v, t) = (column(&res, "flash_vapour.F"), column(&res, "flash_liquid.T"));
    let (h_l, h_f) = (column(&res, "flash_liquid.h"), column(&res, "hot.h"));
    let v0 = v[0];
    let bubble = plant.thermo().bubble_t(1.3 * 101_325.0, &[0.45, 0.55]).unwrap().t;
    assert!(v0 > 1.0 && bubble > 363.15 + 5.0, "two-phase at the start: V = {v0} mol/s; bubble point {bubble} K");
    for (k, time) in res.times.iter().enumerate().filter(|(_, t)| **t > 10.0 * 60.0 && **t < 30.0 * 60.0) {
        // No vapour, so the drum's energy balance says the liquid leaves with the feed's enthalpy
        // (at a temperature near the feed's, the drum's composition lagging the feed's), below the
        // bubble point.
        assert!(v[k].abs() < 1e-6 * v0, "no vapour at t = {time} s: {}", v[k]);
        assert!((h_l[k] - h_f[k]).abs() < 1e-6 * h_f[k].abs(), "t = {time} s: h_L {} h_F {}", h_l[k], h_f[k]);
        assert!((t[k] - 363.15).abs() < 0.5 && t[k] < bubble - 3.0, "t = {time} s: {} K", t[k]);
    }
    let (v_end, t_end) = (*v.last().unwrap(), *t.last().unwrap());
    assert!(
        (v_end - v0).abs() < 1e-6 * v0 && (t_end - t[0]).abs() < 1e-6,
        "back: V {v_end} vs {v0}, T {t_end} vs {}",
        t[0]
    );
    assert!(res.conservation.worst() < 1e-9, "{}", res.conservation.worst());
}

/// A flash drum whose vapour vanishes in the middle of a smooth trajectory, not at a step (issue
/// 53: generated plant 0xd22d4145c7789247, the LV configuration `screen --column` tuned, stepped by
/// −0.038 in the feed's methanol). The preheater holds 364.89 K, and 370 s after the step the
/// drum's liquid, turning heavier, reaches its bubble point there: the vapour stops. The drum's
/// phase condition was smoothed by 1e-10, far below what the corrector resolves, so Newton cycled
/// across the corner and the step size fell to 7e-12 s. Independent checks: the run ends on the
/// steady state of the stepped plant converged on its own from the cold start (with vapour
/// again, once the drum's composition has followed its feed's); moles are conserved.
#[test]
fn a_flash_drum_whose_vapour_vanishes_mid_run_integrates_through() {
    let path = harness::fixture("data/generated/train_d22d4145_lv.json");
    let plant = plantwide::flowsheet::load_file(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
    let ss = steady_state(&plant, &plant.input_values(), None, &NewtonSettings::default()).unwrap();
    let scenario = r#"{"format_version": 1, "duration": "254976.766 s", "integrator": {"rtol": 1e-6},
        "events": [{"type": "step", "at": "5099.535 s", "path": "feed_source.z[methanol]", "by": -0.038}],
        "record": {"interval": "60 s", "paths": ["flash_vapour.F", "flash_liquid.T"]}}"#;
    let res = run_from(&plant, scenario, Start::Steady(&ss.x), &mut |_| {});
    let v = column(&res, "flash_vapour.F");
    assert!(v[0] > 0.4, "two-phase at the start: {} mol/s", v[0]);
    assert!(res.conservation.worst() < 1e-9, "{:?}", res.conservation);
    let mut moved = plant.clone();
    let z = plant.input("feed_source.z[methanol]").unwrap();
    moved.set_input_value(z, plant.input_values()[z] - 0.038);
    let cold = steady_state(&moved, &moved.input_values(), None, &NewtonSettings::default()).unwrap();
    let worst = (0..plant.n_vars())
        .map(|i| (res.x[i] - cold.x[i]).abs() / plant.vars()[i].spec.nominal.max(cold.x[i].abs()))
        .fold(0.0, f64::max);
    assert!(worst < 1e-4, "the run's end against the stepped plant's steady state: {worst:.2e}");
    // The vapour vanished for a while (the drum's liquid lagging its feed) and came back.
    let t = column(&res, "flash_liquid.T");
    let gone: Vec<usize> = (0..v.len()).filter(|&k| v[k].abs() < 1e-6 * v[0]).collect();
    assert!(!gone.is_empty(), "the vapour never vanished: least {:e} mol/s", v.iter().fold(f64::MAX, |a, b| a.min(*b)));
    let back = cold.x[moved.var("flash_vapour.F").unwrap()];
    assert!(back > 0.1 && (v[v.len() - 1] - back).abs() < 1e-4 * back, "end {} mol/s against {back}", v[v.len() - 1]);
    // While it is gone, the liquid sits below the preheater's 364.89 K bubble point no more: it
    // leaves at the preheated feed's temperature (within the drum's lag).
    for &k in &gone {
        assert!(t[k] <= 364.9, "all liquid at {} s, yet {} K", res.times[k], t[k]);
    }
}
