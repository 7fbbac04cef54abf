//! Recycle plants: tear sets, the sequential-modular pass (direct substitution, Wegstein, Broyden)
//! and the whole-plant Newton, on Luyben's snowball plant under both control structures and on a
//! flash loop with a vapour and a liquid recycle.

use crate::harness::{component_balance_error, flowsheet, plantwide, value};
use plantwide::flowsheet::tears::{ConnectionKind, decompose};
use plantwide::flowsheet::{Plant, load_file, load_str};
use plantwide::solve::sequential::{
    Accelerator, Method, SmError, SmSettings, StrategySettings, plan, solve_sequential, steady_state_by,
};
use plantwide::solve::{NewtonSettings, steady_state};

/// One lbmol/h in mol/s.
const LBMOL_H: f64 = 453.592_37 / 3600.0;

fn load(name: &str) -> Plant {
    load_file(std::path::Path::new(&flowsheet(name))).unwrap_or_else(|e| panic!("{e}"))
}

fn sm(accelerator: Accelerator, tol: f64) -> SmSettings {
    SmSettings { accelerator, tol, ..SmSettings::default() }
}

/// Inputs of `plant` with `path` set to `value` (SI).
fn inputs_with(plant: &Plant, sets: &[(&str, f64)]) -> Vec<f64> {
    let mut u = plant.input_values();
    for (path, v) in sets {
        u[plant.input(path).unwrap_or_else(|| panic!("no input {path}"))] = *v;
    }
    u
}

/// Names of the torn connections of every recycle in the sequential-modular plan.
fn tears(plant: &Plant) -> Vec<Vec<String>> {
    let u = plant.input_values();
    let p = plan(plant, &u, &plant.initial_guess_at(&u));
    p.recycles().map(|s| p.tear_names(plant, s)).collect()
}

/// Largest relative difference between two solutions over the stream variables (a floor of 1e-3
/// of each variable's nominal value for quantities near zero).
fn stream_difference(plant: &Plant, a: &[f64], b: &[f64]) -> f64 {
    let n = plant.stream_layout().len();
    plant
        .streams()
        .iter()
        .flat_map(|s| s.offset..s.offset + n)
        .map(|i| (a[i] - b[i]).abs() / a[i].abs().max(1e-3 * plant.vars()[i].spec.nominal))
        .fold(0.0, f64::max)
}

// ---------------------------------------------------------------------------------------------
// Tear sets of textbook flowsheets, against hand-derived minimum sets.

/// A flowsheet of the given units and streams (`(name, from, to)`), binary constant-α.
fn sketch(units: &str, streams: &[(&str, &str, &str)]) -> Plant {
    let streams: Vec<String> =
        streams.iter().map(|(n, f, t)| format!(r#""{n}": {{"from": "{f}", "to": "{t}"}}"#)).collect();
    let text = format!(
        r#"{{"format_version": 1, "name": "sketch",
        "components": [{{"name": "a", "hypothetical": {{"alpha": 2, "mw": "50 kg/kmol", "hvap": "30 kJ/mol"}}}},
                       {{"name": "b", "hypothetical": {{"alpha": 1, "mw": "50 kg/kmol", "hvap": "30 kJ/mol"}}}}],
        "thermo": {{"vle": "constant_alpha"}},
        "units": {{{units}}},
        "streams": {{{}}}}}"#,
        streams.join(", ")
    );
    load_str(&text, "sketch").unwrap_or_else(|e| panic!("{e}"))
}

const FEED: &str = r#""type": "feed", "F": "1 kmol/h", "T": "300 K", "P": "1 atm", "z": {"a": 0.5, "b": 0.5}"#;

#[test]
fn single_loop_is_torn_at_its_recycle() {
    // feed → mix → split → {mix (recycle), product}: one cycle of two streams; the recycle is the
    // back edge of the flow order.
    let units = format!(
        r#""feed": {{{FEED}}}, "mix": {{"type": "mixer"}}, "split": {{"type": "splitter", "fractions": [0.5]}}, "out": {{"type": "product"}}"#
    );
    let p = sketch(
        &units,
        &[
            ("s1", "feed", "mix.in1"),
            ("s2", "mix", "split"),
            ("recycle", "split.out1", "mix.in2"),
            ("s3", "split.out2", "out"),
        ],
    );
    assert_eq!(tears(&p), vec![vec!["recycle"]]);
}

#[test]
fn two_nested_loops_are_torn_once_where_they_overlap() {
    // Inner loop m2 → split2 → m2, outer loop m1 → m2 → split2 → split1 → m1. Both run through
    // the stream m2 → split2, so one tear breaks both (the two recycles would be two tears).
    let units = format!(
        r#""feed": {{{FEED}}}, "m1": {{"type": "mixer"}}, "m2": {{"type": "mixer"}},
        "split2": {{"type": "splitter", "fractions": [0.4]}}, "split1": {{"type": "splitter", "fractions": [0.3]}},
        "out": {{"type": "product"}}"#
    );
    let p = sketch(
        &units,
        &[
            ("s1", "feed", "m1.in1"),
            ("s2", "m1", "m2.in1"),
            ("shared", "m2", "split2"),
            ("inner", "split2.out1", "m2.in2"),
            ("s3", "split2.out2", "split1"),
            ("outer", "split1.out1", "m1.in2"),
            ("s4", "split1.out2", "out"),
        ],
    );
    assert_eq!(tears(&p), vec![vec!["shared"]]);
    let u = p.input_values();
    let plan = plan(&p, &u, &p.initial_guess_at(&u));
    let scc = plan.recycles().next().unwrap();
    assert_eq!((scc.n_cycles, scc.redundancy, scc.exact), (Some(2), Some(0), true));
}

/// Feed–effluent heat exchanger: a hot loop and a cold loop through the two sides of one unit.
const TWO_LOOPS_ONE_EXCHANGER: &str = r#"{"format_version": 1, "name": "two_loops_one_exchanger",
    "components": ["benzene", "toluene"], "thermo": {"vle": "ideal"},
    "units": {
      "hot_feed": {"type": "feed", "F": "10 kmol/h", "T": "380 K", "P": "3 atm", "z": {"benzene": 0.5, "toluene": 0.5}},
      "cold_feed": {"type": "feed", "F": "12 kmol/h", "T": "300 K", "P": "3 atm", "z": {"benzene": 0.3, "toluene": 0.7}},
      "hot_mix": {"type": "mixer"}, "cold_mix": {"type": "mixer"},
      "hx": {"type": "heat_exchanger", "ua": "2 kW/K"},
      "hot_split": {"type": "splitter", "fractions": [0.6]}, "cold_split": {"type": "splitter", "fractions": [0.5]},
      "hot_out": {"type": "product"}, "cold_out": {"type": "product"}
    },
    "streams": {
      "h1": {"from": "hot_feed", "to": "hot_mix.in1"}, "h2": {"from": "hot_mix", "to": "hx.hot_in"},
      "h3": {"from": "hx.hot_out", "to": "hot_split"}, "hot_recycle": {"from": "hot_split.out1", "to": "hot_mix.in2"},
      "h4": {"from": "hot_split.out2", "to": "hot_out"},
      "c1": {"from": "cold_feed", "to": "cold_mix.in1"}, "c2": {"from": "cold_mix", "to": "hx.cold_in"},
      "c3": {"from": "hx.cold_out", "to": "cold_split"}, "cold_recycle": {"from": "cold_split.out1", "to": "cold_mix.in2"},
      "c4": {"from": "cold_split.out2", "to": "cold_out"}
    }}"#;

#[test]
fn two_loops_sharing_a_unit_need_a_tear_each_and_converge_together() {
    // No stream lies on both loops: two tears, one SCC (the exchanger couples them), converged by
    // one Broyden matrix; the result is the whole-plant Newton's.
    let p = load_str(TWO_LOOPS_ONE_EXCHANGER, "two_loops_one_exchanger").unwrap();
    assert_eq!(tears(&p), vec![vec!["cold_recycle", "hot_recycle"]]);
    let u = p.input_values();
    let eo = steady_state(&p, &u, None, &NewtonSettings::default()).unwrap_or_else(|e| panic!("{e}"));
    for m in [Accelerator::Auto, Accelerator::Direct, Accelerator::Wegstein] {
        let sol = solve_sequential(&p, &u, None, &sm(m, 1e-11)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(sol.report.sccs[0].accelerator, if m == Accelerator::Auto { Accelerator::Broyden } else { m });
        assert!(stream_difference(&p, &eo.x, &sol.x) < 1e-9, "{m:?}");
    }
}

/// A recycle through a tank with a `free` outflow and the valve that sets it.
const TANK_VALVE_LOOP: &str = r#"{"format_version": 1, "name": "tank_valve_loop",
    "components": ["benzene", "toluene"], "thermo": {"vle": "ideal"},
    "units": {
      "feed": {"type": "feed", "F": "10 kmol/h", "T": "300 K", "P": "2 bar", "z": {"benzene": 0.4, "toluene": 0.6}},
      "mix": {"type": "mixer"},
      "tank": {"type": "tank", "diameter": "1 m", "height": "4 m", "P": "1.5 bar", "outflow": {"type": "free"}},
      "valve": {"type": "valve", "mode": {"type": "pressure_drop", "cv": "2e-4 m2", "opening": 0.5}, "p_out": "1.45 bar"},
      "split": {"type": "splitter", "fractions": [0.5]},
      "out": {"type": "product"}
    },
    "streams": {
      "s1": {"from": "feed", "to": "mix.in1"}, "s2": {"from": "mix", "to": "tank"}, "s3": {"from": "tank", "to": "valve"},
      "s4": {"from": "valve", "to": "split"}, "recycle": {"from": "split.out1", "to": "mix.in2"},
      "s5": {"from": "split.out2", "to": "out"}
    }}"#;

#[test]
fn free_outflow_vessel_and_its_valve_are_one_solve_block() {
    // The tank owns its outflow without an equation for it; the valve writes that equation (one
    // more than it owns). Alone neither is square: they are solved together.
    let p = load_str(TANK_VALVE_LOOP, "tank_valve_loop").unwrap();
    let u = p.input_values();
    let plan = plan(&p, &u, &p.initial_guess_at(&u));
    let merged: Vec<_> = plan.groups.iter().filter(|g| g.blocks.len() > 1).collect();
    assert_eq!(merged.len(), 1);
    assert_eq!(merged[0].name(&p), "tank+valve");
    assert_eq!(merged[0].reasons, vec!["`valve` writes the equation for the outflow of `tank`"]);
    let sol = solve_sequential(&p, &u, None, &sm(Accelerator::Auto, 1e-10)).unwrap_or_else(|e| panic!("{e}"));
    let eo = steady_state(&p, &u, None, &NewtonSettings::default()).unwrap_or_else(|e| panic!("{e}"));
    assert!(stream_difference(&p, &eo.x, &sol.x) < 1e-9);
    // Closed form: the loop carries F = F_feed / (1 − 0.5); the valve passes it at the level where
    // Cv·op·√(ΔP/ρ)·ρ/M = F, ΔP = P + ρ g L − p_out (liquid of the feed composition, at its T).
    let f = 2.0 * 10.0 / 3.6;
    let z = [0.4, 0.6];
    let t = value(&p, &sol.x, "s3.T");
    let (mw, v) = (p.thermo().mw(&z), p.thermo().v_liq(t, &z));
    let rho = mw / v;
    let dp = rho * (f * mw / (2e-4 * 0.5 * rho)).powi(2);
    let level = (dp - (1.5e5 - 1.45e5)) / (rho * 9.80665);
    assert!((value(&p, &sol.x, "s3.F") / f - 1.0).abs() < 1e-9);
    assert!(
        (value(&p, &sol.x, "tank.level") / level - 1.0).abs() < 1e-8,
        "{} vs {level}",
        value(&p, &sol.x, "tank.level")
    );
}

#[test]
fn snowball_block_graph_has_controller_loops_inside_the_material_loop() {
    // Blocks as nodes, streams and signals as edges: the material loop mixer → reactor → column →
    // mixer contains five two-node loops (each controller measures and drives its unit). Every
    // two-node loop needs one of its two edges and the material loop one of its three streams,
    // none shared: the minimum is 6 tears, each loop torn once; the marked recycle is one of them.
    let p = load("reactor_column_recycle.json");
    let g = p.block_graph();
    let sccs = decompose(&g);
    let rec: Vec<_> = sccs.iter().filter(|s| s.is_recycle()).collect();
    assert_eq!(rec.len(), 1);
    let scc = rec[0];
    assert_eq!(scc.order.len(), 8);
    assert_eq!((scc.n_cycles, scc.redundancy, scc.exact), (Some(6), Some(0), true));
    assert_eq!(scc.tears.len(), 6);
    let streams: Vec<&str> = scc
        .tears
        .iter()
        .filter_map(|&e| match g[e].kind {
            ConnectionKind::Stream(s) => Some(p.streams()[s].name.as_str()),
            ConnectionKind::Signal(_) => None,
        })
        .collect();
    assert_eq!(streams, vec!["recycle"]);
    // Solve groups absorb the controller loops: one tear is left, the recycle.
    assert_eq!(tears(&p), vec![vec!["recycle"]]);
}

// ---------------------------------------------------------------------------------------------
// Luyben's snowball plant (validation-cases.md §4).

/// Closed form of the model at fresh feed `f0` [mol/s], structure 1: reactor holdup `M` at its
/// level setpoint, first order `k`, so `z = F0 (1 − xB)/(k M)`; column `D = F0 (z − xB)/(xD − z)`.
fn snowball_closed_form(f0: f64) -> (f64, f64) {
    let (xd, xb) = (0.95, 0.0105);
    let m = 20.0 * 3.0 / 1e-4; // area 20 m², level 3 m, 1e-4 m³/mol [mol]
    let k = 0.358_315_7 / 3600.0; // [1/s]
    let z = f0 * (1.0 - xb) / (k * m);
    let d = f0 * (z - xb) / (xd - z);
    (z, d)
}

#[test]
fn snowball_design_point_by_newton_sequential_modular_and_auto() {
    let p = load("reactor_column_recycle.json");
    let u = p.input_values();
    let (_, d_model) = snowball_closed_form(239.5 * LBMOL_H);
    for method in [Method::Eo, Method::Sm, Method::Auto] {
        let settings = StrategySettings { method, ..StrategySettings::default() };
        let sol = steady_state_by(&p, &u, &settings, &mut |_| {}).unwrap_or_else(|e| panic!("{method:?}: {e}"));
        assert_eq!(sol.sm.is_some(), method != Method::Eo);
        assert_eq!(sol.newton.is_some(), method != Method::Sm);
        let (d, f) = (value(&p, &sol.x, "recycle.F") / LBMOL_H, value(&p, &sol.x, "effluent.F") / LBMOL_H);
        // Published: D = 260.5, F = 500 lbmol/h (Luyben 1994), to 0.1 %.
        assert!((d / 260.5 - 1.0).abs() < 1e-3 && (f / 500.0 - 1.0).abs() < 1e-3, "{method:?}: D = {d}, F = {f}");
        // The model's own closed form: to the solver's accuracy (tear tolerance 1e-8 for SM).
        let tol = if method == Method::Sm { 1e-7 } else { 1e-9 };
        assert!((d * LBMOL_H / d_model - 1.0).abs() < tol, "{method:?}: D = {d} vs {}", d_model / LBMOL_H);
        assert!((value(&p, &sol.x, "recycle.x[A]") - 0.95).abs() < 1e-9);
        assert!((value(&p, &sol.x, "bottoms.x[A]") - 0.0105).abs() < 1e-9);
        assert!((value(&p, &sol.x, "reactor.level") - 3.0).abs() < 1e-9);
        // Reaction conserves moles: the product leaves at the fresh-feed rate.
        assert!((value(&p, &sol.x, "bottoms.F") / value(&p, &sol.x, "feed.F") - 1.0).abs() < tol);
        assert!(component_balance_error(&p, &sol.x, &["reactor"]) < tol);
    }
}

#[test]
fn accelerators_pinned_passes_and_the_same_steady_state() {
    let p = load("reactor_column_recycle.json");
    let u = p.input_values();
    // Passes to the default tear tolerance (1e-8) from the cold start. Direct substitution
    // contracts by the loop gain 0.77 per pass; Wegstein and Broyden extrapolate it away.
    let mut passes = Vec::new();
    for (m, expected) in [(Accelerator::Direct, 58), (Accelerator::Wegstein, 6), (Accelerator::Broyden, 6)] {
        let sol = solve_sequential(&p, &u, None, &sm(m, 1e-8)).unwrap_or_else(|e| panic!("{m:?}: {e}"));
        let rec = &sol.report.sccs[0];
        assert!(rec.converged && rec.residual <= 1e-8);
        assert_eq!(rec.passes, expected, "{m:?}: {:?}", rec.history);
        let gain = rec.loop_gain.unwrap();
        assert!((gain - 0.767).abs() < 0.01, "{m:?}: loop gain {gain}");
        passes.push(rec.passes);
    }
    assert!(passes[1] * 5 <= passes[0] && passes[2] * 5 <= passes[0]);
    // Converged tighter, the three methods and Newton agree on every stream variable to 1e-8.
    let eo = steady_state(&p, &u, None, &NewtonSettings::default()).unwrap().x;
    for m in [Accelerator::Direct, Accelerator::Wegstein, Accelerator::Broyden] {
        let x = solve_sequential(&p, &u, None, &sm(m, 1e-10)).unwrap().x;
        let diff = stream_difference(&p, &eo, &x);
        assert!(diff < 1e-8, "{m:?}: {diff:e}");
    }
}

#[test]
fn snowball_recycle_follows_the_closed_form_as_fresh_feed_rises() {
    // Structure 1 keeps the reactor holdup constant: the recycle grows much faster than the fresh
    // feed (+20 % F0 → +86 % D) and the loop gain climbs toward 1.
    let p = load("reactor_column_recycle.json");
    let mut last_gain = 0.0;
    for factor in [0.8, 0.9, 1.0, 1.1, 1.2] {
        let f0 = factor * 239.5 * LBMOL_H;
        let u = inputs_with(&p, &[("F0", f0)]);
        let settings = StrategySettings { method: Method::Auto, ..StrategySettings::default() };
        let sol = steady_state_by(&p, &u, &settings, &mut |_| {}).unwrap_or_else(|e| panic!("F0 × {factor}: {e}"));
        let (z, d) = snowball_closed_form(f0);
        assert!((value(&p, &sol.x, "effluent.x[A]") / z - 1.0).abs() < 1e-9);
        assert!((value(&p, &sol.x, "recycle.F") / d - 1.0).abs() < 1e-9, "F0 × {factor}");
        let gain = sol.sm.unwrap().sccs[0].loop_gain.unwrap();
        assert!(gain > last_gain, "loop gain {gain} at F0 × {factor}");
        last_gain = gain;
    }
    let (_, d0) = snowball_closed_form(239.5 * LBMOL_H);
    let (_, d1) = snowball_closed_form(1.2 * 239.5 * LBMOL_H);
    assert!((d1 / d0 - 1.859).abs() < 1e-3, "D rises by {}", d1 / d0);
}

#[test]
fn fixed_effluent_structure_does_not_snowball() {
    let p = load("reactor_column_recycle_fixed_effluent.json");
    let u = p.input_values();
    let sol = solve_sequential(&p, &u, None, &SmSettings::default()).unwrap_or_else(|e| panic!("{e}"));
    let eo = steady_state(&p, &u, None, &NewtonSettings::default()).unwrap_or_else(|e| panic!("{e}"));
    // The level controller and its path (fresh → mixer → reactor) are one solve block.
    assert_eq!(tears(&p), vec![vec!["recycle"]]);
    let rec = &sol.report.sccs[0];
    assert!(rec.loop_gain.unwrap() < 0.05, "loop gain {:?}", rec.loop_gain);
    // Closed form: F fixed, M at setpoint: F0 = F xD / (F (1 − xB)/(k M) + xD − xB), D = F − F0.
    let closed = |f: f64, m: f64| {
        let (xd, xb, k) = (0.95, 0.0105, 0.358_315_7 / 3600.0);
        let f0 = f * xd / (f * (1.0 - xb) / (k * m) + xd - xb);
        (f0, f - f0)
    };
    let (f0, d) = closed(500.0 * LBMOL_H, 6e5);
    for x in [&sol.x, &eo.x] {
        assert!((value(&p, x, "feed.F") / f0 - 1.0).abs() < 1e-7);
        assert!((value(&p, x, "recycle.F") / d - 1.0).abs() < 1e-7);
        assert!((value(&p, x, "recycle.F") / LBMOL_H / 260.5 - 1.0).abs() < 1e-3);
        assert!((value(&p, x, "feed.F") / LBMOL_H / 239.5 - 1.0).abs() < 1e-3);
    }
    // +20 % throughput the structure-2 way (effluent flow and reactor level setpoint): fresh feed
    // and recycle rise by exactly 20 %.
    let u = inputs_with(&p, &[("F", 600.0 * LBMOL_H), ("reactor_level.sp", 3.6)]);
    let sol = solve_sequential(&p, &u, None, &SmSettings::default()).unwrap_or_else(|e| panic!("{e}"));
    assert!((value(&p, &sol.x, "feed.F") / (1.2 * f0) - 1.0).abs() < 1e-7);
    assert!((value(&p, &sol.x, "recycle.F") / (1.2 * d) - 1.0).abs() < 1e-7);
}

// ---------------------------------------------------------------------------------------------
// Flash loop with a vapour and a liquid recycle.

#[test]
fn flash_loop_with_two_recycles_is_torn_once_and_all_methods_agree() {
    let p = load("flash_vapour_liquid_recycle.json");
    let u = p.input_values();
    // Two cycles (through the vapour and the liquid recycle) share mixed → heater → drum: the
    // minimum tear is one stream, where the loops start.
    assert_eq!(tears(&p), vec![vec!["mixed"]]);
    let eo = steady_state(&p, &u, None, &NewtonSettings::default()).unwrap_or_else(|e| panic!("{e}")).x;
    assert!(component_balance_error(&p, &eo, &[]) < 1e-9);
    // Wegstein's per-variable secant slopes amplify rounding on variables that barely move: the
    // drum's energy balance written without the enthalpy datum (same solution, other rounding in
    // the local solves) took it from 12 passes to 13.
    for (m, passes) in [(Accelerator::Direct, 22), (Accelerator::Wegstein, 13), (Accelerator::Broyden, 10)] {
        let sol = solve_sequential(&p, &u, None, &sm(m, 1e-8)).unwrap_or_else(|e| panic!("{m:?}: {e}"));
        assert_eq!(sol.report.sccs[0].passes, passes, "{m:?}");
        let gain = sol.report.sccs[0].loop_gain.unwrap();
        assert!((gain - 0.5).abs() < 0.02, "{m:?}: loop gain {gain}");
        let tight = solve_sequential(&p, &u, None, &sm(m, 1e-11)).unwrap().x;
        assert!(stream_difference(&p, &eo, &tight) < 1e-8, "{m:?}");
    }
    // Independent check of the drum: an isobaric PH flash of the heated stream (the thermodynamic
    // package's flash, not the drum model) gives the same vapour fraction and compositions.
    let f = value(&p, &eo, "heated.F");
    let z: Vec<f64> = p.components().iter().map(|c| value(&p, &eo, &format!("heated.x[{c}]"))).collect();
    let flash = p.thermo().flash_ph(101_325.0, value(&p, &eo, "heated.h"), &z).unwrap();
    assert!(
        (flash.beta - value(&p, &eo, "vapour.F") / f).abs() < 1e-8,
        "{} vs {}",
        flash.beta,
        value(&p, &eo, "vapour.F") / f
    );
    assert!((flash.t - value(&p, &eo, "vapour.T")).abs() < 1e-6);
    // Plant balance: fresh feed = top + bottom product, per component.
    for c in p.components() {
        let n = |s: &str| value(&p, &eo, &format!("{s}.F")) * value(&p, &eo, &format!("{s}.x[{c}]"));
        let (i, o) = (n("feed"), n("top_product") + n("bottom_product"));
        assert!((i - o).abs() < 1e-9 * i, "{c}: {i} vs {o}");
    }
}

// ---------------------------------------------------------------------------------------------
// Failures and the command line.

#[test]
fn sequential_modular_failures_name_the_place() {
    // A duty that vaporizes the whole feed: the drum has no two-phase steady state; the message
    // names the solve block and its worst equation.
    let p = load("flash_recycle.json");
    let u = inputs_with(&p, &[("heater.duty", 1.6e6)]);
    match solve_sequential(&p, &u, None, &SmSettings::default()) {
        Err(SmError::Local(f)) => {
            let msg = f.to_string();
            assert!(
                msg.contains("flash_recycle.json") && msg.contains("`drum`") && msg.contains("worst equation"),
                "{msg}"
            );
        }
        other => panic!("expected a local failure, got {other:?}"),
    }
    // Bad settings and a per-SCC choice naming no recycle are user errors naming the field.
    let p = load("reactor_column_recycle.json");
    let u = p.input_values();
    let bad = SmSettings { tol: 0.0, ..SmSettings::default() };
    assert!(matches!(solve_sequential(&p, &u, None, &bad), Err(SmError::Settings(m)) if m.field == "sm.tol"));
    let bad = SmSettings { per_scc: vec![("product".into(), Accelerator::Broyden)], ..SmSettings::default() };
    assert!(
        matches!(solve_sequential(&p, &u, None, &bad), Err(e @ SmError::NotInRecycle(_)) if e.to_string().contains("`product` is not a block of any recycle"))
    );
    // A per-SCC choice is honoured.
    let pick = SmSettings {
        accelerator: Accelerator::Direct,
        per_scc: vec![("mixer".into(), Accelerator::Broyden)],
        ..SmSettings::default()
    };
    assert_eq!(solve_sequential(&p, &u, None, &pick).unwrap().report.sccs[0].accelerator, Accelerator::Broyden);
}

#[test]
fn command_line_prints_the_plan_and_the_recycle_log() {
    let file = flowsheet("reactor_column_recycle.json");
    let out = plantwide(&["check", &file]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("recycle 1: mixer -> reactor+reactor_level -> column+"), "{text}");
    assert!(
        text.contains("tear recycle (6 variables, marked in the file); minimum, non-redundant (1 cycle)"),
        "{text}"
    );
    let out = plantwide(&["steady", &file, "--method", "sm"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("Wegstein converged in 6 passes") && text.contains("loop gain 0.76"), "{text}");
    assert!(text.contains("converged by the sequential-modular method in 6 passes"), "{text}");
    let out = plantwide(&["steady", &file, "--method", "auto", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["method"], "auto");
    assert!(v["residual"].as_f64().unwrap() < 1e-10);
    assert_eq!(v["sequential_modular"]["sccs"][0]["tears"][0], "recycle");
    let d = v["values"]["recycle.F"].as_f64().unwrap() / LBMOL_H;
    assert!((d / 260.5 - 1.0).abs() < 1e-3);
}
