//! The built-in CSTR of `flowsheets/cstr_multiplicity.json` and the same reactor written as an
//! `equations` unit (`tests/data/cstr_equations.json`, issue 57) reach the same steady state.

use std::path::Path;

use plantwide_flowsheet::load_file;
use plantwide_solve::{NewtonSettings, steady_state};

fn solve(rel: &str) -> (plantwide_flowsheet::Plant, Vec<f64>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(rel);
    let plant = load_file(&path).unwrap_or_else(|e| panic!("{rel}: {e}"));
    let ss = steady_state(&plant, &plant.input_values(), None, &NewtonSettings::default())
        .unwrap_or_else(|e| panic!("{rel}: {e}"));
    (plant, ss.x)
}

#[test]
fn cstr_as_equations_has_the_built_in_steady_state() {
    let (builtin, xb) = solve("flowsheets/cstr_multiplicity.json");
    let (eqs, xe) = solve("tests/data/cstr_equations.json");
    let pairs = [
        ("effluent.F", "effluent.F"),
        ("effluent.T", "effluent.T"),
        ("effluent.P", "effluent.P"),
        ("effluent.h", "effluent.h"),
        ("effluent.x[A]", "effluent.x[A]"),
        ("reactor.N[A]", "reactor.NA"),
        ("reactor.N[B]", "reactor.NB"),
        ("reactor.U", "reactor.U"),
        ("reactor.Tj", "reactor.Tj"),
        ("reactor.M", "reactor.M"),
        ("reactor.level", "reactor.level"),
        ("reactor.V", "reactor.V"),
        ("reactor.Q", "reactor.Q"),
    ];
    let mut worst: f64 = 0.0;
    for (b, e) in pairs {
        let ib = builtin.var(b).unwrap_or_else(|| panic!("built-in has no `{b}`"));
        let ie = eqs.var(e).unwrap_or_else(|| panic!("equations unit has no `{e}`"));
        let d = (xb[ib] - xe[ie]).abs() / xb[ib].abs().max(1e-300);
        eprintln!("{b:>14} {:>22.15e} {e:>14} {:>22.15e}  rel {d:.1e}", xb[ib], xe[ie]);
        worst = worst.max(d);
    }
    assert!(worst < 1e-10, "worst relative difference {worst:.2e}");
}

/// A 20 % cut of the coolant flow at 1 min, run for 30 min from each steady state: the recorded
/// trajectories agree.
#[test]
fn cstr_as_equations_follows_the_built_in_trajectory() {
    use plantwide_flowsheet::scenario::{parse_scenario, resolve};
    use plantwide_solve::dynamic::{Start, simulate};
    let scenario = r#"{"format_version": 1, "name": "coolant cut", "duration": "30 min",
        "integrator": {"rtol": 1e-12, "atol": 1e-12},
        "events": [{"type": "step", "at": "1 min", "path": "reactor.coolant_flow", "to": "4 kg/s"}],
        "record": {"interval": "1 min", "paths": [{"path": "effluent.T"}, {"path": "reactor.Tj"},
            {"path": "reactor.level"}, {"path": "effluent.x[A]"}, {"path": "reactor.Q"}]}}"#;
    let run = |rel: &str| {
        let (plant, x) = solve(rel);
        let spec = parse_scenario(scenario, "coolant_cut.json").unwrap();
        let sc = resolve(&spec, &plant, "coolant_cut.json").unwrap_or_else(|e| panic!("{rel}: {e}"));
        simulate(&plant, &sc, Start::Steady(&x), "", &mut |_| {}).unwrap_or_else(|e| panic!("{rel}: {e}"))
    };
    let (b, e) = (run("flowsheets/cstr_multiplicity.json"), run("tests/data/cstr_equations.json"));
    assert_eq!(b.times, e.times);
    let mut worst: f64 = 0.0;
    for (rb, re) in b.rows.iter().zip(e.rows.iter()) {
        for (k, (vb, ve)) in rb.iter().zip(re).enumerate() {
            let d = (vb - ve).abs() / vb.abs().max(1e-300);
            worst = worst.max(d);
            if d > 1e-8 {
                eprintln!("column {k}: {vb} vs {ve} ({d:.1e})");
            }
        }
    }
    let last = b.rows.last().unwrap();
    eprintln!("final {last:?}; worst relative difference {worst:.1e}");
    assert!(worst < 1e-8, "worst relative difference {worst:.2e}");
}

/// The surge tank of `flowsheets/surge_tank_pi.json` as an equations unit: the same steady state
/// and the same response to the shipped inflow step (`surge_tank_inflow_step.json`, tightened).
#[test]
fn surge_tank_as_equations_matches_the_built_in() {
    use plantwide_flowsheet::scenario::{parse_scenario, resolve};
    use plantwide_solve::dynamic::{Start, simulate};
    let (builtin, xb) = solve("flowsheets/surge_tank_pi.json");
    let (eqs, xe) = solve("tests/data/surge_tank_equations.json");
    let mut worst: f64 = 0.0;
    for (b, e) in [
        ("out.F", "out.F"),
        ("out.T", "out.T"),
        ("out.P", "out.P"),
        ("out.h", "out.h"),
        ("tank.N[water]", "tank.N"),
        ("tank.U", "tank.U"),
        ("tank.M", "tank.M"),
        ("tank.level", "tank.level"),
        ("tank.V", "tank.V"),
    ] {
        let ib = builtin.var(b).unwrap_or_else(|| panic!("built-in has no `{b}`"));
        let ie = eqs.var(e).unwrap_or_else(|| panic!("equations unit has no `{e}`"));
        let d = (xb[ib] - xe[ie]).abs() / xb[ib].abs().max(1e-300);
        eprintln!("{b:>14} {:>22.15e} {e:>14} {:>22.15e}  rel {d:.1e}", xb[ib], xe[ie]);
        worst = worst.max(d);
    }
    assert!(worst < 1e-10, "steady state: worst relative difference {worst:.2e}");
    let scenario = r#"{"format_version": 1, "name": "inflow step", "duration": "2500 s",
        "integrator": {"rtol": 1e-12, "atol": 1e-12},
        "events": [{"type": "step", "at": "100 s", "path": "F_in", "to": "60 mol/s"}],
        "record": {"interval": "5 s", "paths": ["tank.level", "out.F", "out.T", "lc.sp"]}}"#;
    let run = |plant: &plantwide_flowsheet::Plant, x: &[f64]| {
        let spec = parse_scenario(scenario, "inflow_step.json").unwrap();
        let sc = resolve(&spec, plant, "inflow_step.json").unwrap();
        simulate(plant, &sc, Start::Steady(x), "", &mut |_| {}).unwrap()
    };
    let (b, e) = (run(&builtin, &xb), run(&eqs, &xe));
    assert_eq!(b.times, e.times);
    let mut worst: f64 = 0.0;
    for (rb, re) in b.rows.iter().zip(e.rows.iter()) {
        for (vb, ve) in rb.iter().zip(re) {
            worst = worst.max((vb - ve).abs() / vb.abs().max(1e-300));
        }
    }
    eprintln!("surge tank inflow step: final {:?}; worst relative difference {worst:.1e}", b.rows.last());
    assert!(worst < 1e-8, "trajectory: worst relative difference {worst:.2e}");
}

/// The flash drum of `flowsheets/flash_recycle.json` as an equations unit calling the thermo
/// package (`K(liquid, c, P)`, `h_V(vapour)`, the closure `liquid.h = h_L(liquid)`, `rho_L`, `mw`;
/// `tests/data/flash_recycle_thermo.json`): the whole recycle plant reaches the built-in's steady
/// state.
#[test]
fn flash_as_equations_with_thermo_functions_has_the_built_in_steady_state() {
    let (builtin, xb) = solve("flowsheets/flash_recycle.json");
    let (eqs, xe) = solve("tests/data/flash_recycle_thermo.json");
    let mut pairs: Vec<(String, String)> = ["vapour", "liquid", "recycle", "bottoms"]
        .iter()
        .flat_map(|s| ["F", "T", "P", "h", "x[benzene]", "x[toluene]", "x[o-xylene]"].map(|q| format!("{s}.{q}")))
        .map(|p| (p.clone(), p))
        .collect();
    for v in ["N[benzene]", "N[toluene]", "N[o-xylene]", "M", "level", "V"] {
        pairs.push((format!("drum.{v}"), format!("drum.{v}")));
    }
    let mut worst: f64 = 0.0;
    for (b, e) in &pairs {
        let ib = builtin.var(b).unwrap_or_else(|| panic!("built-in has no `{b}`"));
        let ie = eqs.var(e).unwrap_or_else(|| panic!("equations unit has no `{e}`"));
        let d = (xb[ib] - xe[ie]).abs() / xb[ib].abs().max(1e-300);
        eprintln!("{b:>20} {:>22.15e} {:>22.15e}  rel {d:.1e}", xb[ib], xe[ie]);
        worst = worst.max(d);
    }
    assert!(worst < 1e-10, "worst relative difference {worst:.2e}");
}
