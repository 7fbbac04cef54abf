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
