//! Units written as equations (issue 57) seen by the studies as any other unit: the CSTR and the
//! surge tank of `tests/data/{cstr,surge_tank}_equations.json` give the built-in units' numbers
//! in `gains`, `tune` and `serve`'s first state. (`steady`, `run` and the Jacobians are compared in
//! `crates/solve/tests/equations_unit.rs`; Python in `crates/python/tests/test_steady.py`.)

use crate::harness::{fixture, flowsheet, plantwide};

fn json(args: &[&str]) -> serde_json::Value {
    let out = plantwide(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("--json prints JSON")
}

/// Largest relative difference between two arrays of numbers (nested one level).
fn max_rel(a: &serde_json::Value, b: &serde_json::Value) -> f64 {
    let flat = |v: &serde_json::Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .flat_map(|r| {
                r.as_array()
                    .map_or_else(|| vec![r.as_f64().unwrap()], |r| r.iter().map(|x| x.as_f64().unwrap()).collect())
            })
            .collect()
    };
    let (a, b) = (flat(a), flat(b));
    assert_eq!(a.len(), b.len());
    a.iter().zip(&b).map(|(x, y)| (x - y).abs() / x.abs().max(y.abs()).max(1e-300)).fold(0.0, f64::max)
}

#[test]
fn the_equations_cstr_has_the_built_in_cstrs_steady_state_gains() {
    let args = |f: String| {
        json(&[
            "gains",
            &f,
            "--inputs",
            "reactor.coolant_flow,reactor.coolant_T,fresh.F",
            "--outputs",
            "effluent.T,effluent.x[A]",
            "--json",
        ])
    };
    let (builtin, eq) = (args(flowsheet("cstr_multiplicity.json")), args(fixture("data/cstr_equations.json")));
    let d = max_rel(&builtin["gain"], &eq["gain"]);
    eprintln!("gains: largest relative difference {d:.2e}");
    assert!(d < 1e-9, "{d:e}\n{}\n{}", builtin["gain"], eq["gain"]);
}

#[test]
fn the_equations_surge_tank_gets_the_built_in_tanks_averaging_level_tuning() {
    let args = |f: String| {
        json(&[
            "tune",
            &f,
            "--loop",
            "lc",
            "--method",
            "averaging",
            "--level-band",
            "0.2 m",
            "--flow-change",
            "5 mol/s",
            "--json",
        ])
    };
    let (builtin, eq) = (args(flowsheet("surge_tank_pi.json")), args(fixture("data/surge_tank_equations.json")));
    let (a, b) = (&builtin["loops"][0]["averaging"], &eq["loops"][0]["averaging"]);
    for k in ["kc", "time", "band"] {
        let (x, y) = (a[k].as_f64().unwrap(), b[k].as_f64().unwrap());
        assert!((x - y).abs() <= 1e-10 * x.abs(), "{k}: {x} vs {y}");
    }
    // The closed form (McDonald, McAvoy & Tits 1986, P-only): Kc = Δu/Δh = 5 mol/s / 0.2 m.
    assert!((a["kc"].as_f64().unwrap().abs() - 25.0).abs() < 1e-12);
}

/// `size` sizes the equations surge tank as it sizes the built-in one: the geometry is its
/// `area` parameter, the level, M and V its variables. The designs (closed forms of the molar
/// volume and the flow change) agree to roundoff; the verifying runs' peaks to the integrator's
/// tolerance (the two models are integrated in different coordinates, N and U against M and T:
/// measured 1.3e-7 at the default rtol 1e-6).
#[test]
fn size_designs_the_equations_surge_tank_as_the_built_in_one() {
    let args = |f: String| {
        let a = ["size", &f, "--vessel", "tank", "--disturbance", "inflow.F=+10 mol/s", "--level-band", "0.2 m"];
        json(&[&a[..], &["--max-outflow-rate", "3 mol/s/min", "--json"]].concat())
    };
    let (builtin, eq) = (args(flowsheet("surge_tank_pi.json")), args(fixture("data/surge_tank_equations.json")));
    let designs = |v: &serde_json::Value| v["designs"].as_array().unwrap().clone();
    let (a, b) = (designs(&builtin), designs(&eq));
    assert_eq!(a.len(), 3);
    for (x, y) in a.iter().zip(&b) {
        for k in ["area", "band_volume"] {
            let (p, q) = (x[k].as_f64().unwrap(), y[k].as_f64().unwrap());
            assert!((p - q).abs() <= 1e-12 * p.abs(), "{k}: {p} vs {q}");
        }
        for k in ["max_level_deviation", "max_outflow_rate"] {
            let (p, q) = (x["verified"][k].as_f64().unwrap(), y["verified"][k].as_f64().unwrap());
            assert!((p - q).abs() <= 1e-5 * p.abs(), "verified {k}: {p} vs {q}");
        }
    }
    for k in ["liquid_molar_volume", "flow_change"] {
        let (p, q) = (builtin[k].as_f64().unwrap(), eq[k].as_f64().unwrap());
        assert!((p - q).abs() <= 1e-12 * p.abs(), "{k}: {p} vs {q}");
    }
}
