//! Robustness sweeps over composition, temperature and pressure with library mixtures: every
//! flash converges, is in equilibrium, closes the mass balance, and inverts by the PH flash.
#![allow(clippy::needless_range_loop)] // index loops over components read like the equations

use approx::abs_diff_eq;
use plantwide_thermo::{BinaryPair, Library, PhaseState, ThermoPackage, VleModel};

fn package(names: &[&str], vle: &str, extra: &[BinaryPair]) -> ThermoPackage {
    let lib = Library::builtin().unwrap();
    let components = names.iter().map(|n| lib.component(n).unwrap().clone()).collect();
    let vle = match vle {
        "ideal" => VleModel::Ideal,
        kind => VleModel::Activity(lib.activity_model(kind, names, extra).unwrap()),
    };
    ThermoPackage { components, vle }
}

fn sweep(pkg: &ThermoPackage, zs: &[Vec<f64>], pressures: &[f64]) -> (usize, f64, f64) {
    let mut count = 0;
    let (mut worst_t, mut worst_eq) = (0.0_f64, 0.0_f64);
    for z in zs {
        for &p in pressures {
            let tb = pkg.bubble_t(p, z).unwrap_or_else(|e| panic!("bubble {z:?} {p}: {e}")).t;
            let td = pkg.dew_t(p, z).unwrap_or_else(|e| panic!("dew {z:?} {p}: {e}")).t;
            assert!(td >= tb - 1e-9 * tb, "dew {td} below bubble {tb} for {z:?}");
            for k in 0..=12 {
                let lo = tb - (0.5 * tb).min(20.0);
                let t = lo + (td + 20.0 - lo) * k as f64 / 12.0;
                let f = pkg.flash_tp(t, p, z).unwrap_or_else(|e| panic!("{e}"));
                count += 1;
                let expect = if t <= tb {
                    PhaseState::Liquid
                } else if t >= td {
                    PhaseState::Vapour
                } else {
                    PhaseState::TwoPhase
                };
                if (t - tb).abs() > 1e-9 && (t - td).abs() > 1e-9 {
                    assert_eq!(f.phase, expect, "{z:?} at {t} K, {p} Pa (Tb {tb}, Td {td})");
                }
                for i in 0..z.len() {
                    assert!((f.beta * f.y[i] + (1.0 - f.beta) * f.x[i] - z[i]).abs() < 1e-12);
                }
                if f.phase == PhaseState::TwoPhase {
                    let mut kv = vec![0.0; z.len()];
                    pkg.k_values(t, p, &f.x, &mut kv);
                    for i in 0..z.len() {
                        worst_eq = worst_eq.max((f.y[i] - kv[i] * f.x[i]).abs());
                    }
                }
                let g = pkg.flash_ph(p, f.h, z).unwrap_or_else(|e| panic!("PH {z:?} {p} h={}: {e}", f.h));
                worst_t = worst_t.max((g.t - t).abs() / t);
                assert!(
                    abs_diff_eq!(g.x[..], f.x[..], epsilon = 1e-8) && abs_diff_eq!(g.y[..], f.y[..], epsilon = 1e-8),
                    "{z:?} {t} {p}: {g:?} vs {f:?}"
                );
            }
        }
    }
    (count, worst_t, worst_eq)
}

fn binary_grid() -> Vec<Vec<f64>> {
    [0.0, 0.001, 0.02, 0.1, 0.25, 0.5, 0.75, 0.88, 0.9, 0.95, 0.999, 1.0].iter().map(|&x| vec![x, 1.0 - x]).collect()
}

#[test]
fn sweep_binaries() {
    let pressures = [2e4, 101_325.0, 5e5];
    for (names, model) in [
        (["ethanol", "water"], "nrtl"),
        (["ethanol", "water"], "wilson"),
        (["methanol", "water"], "nrtl"),
        (["methanol", "water"], "wilson"),
        (["acetone", "water"], "nrtl"),
        (["benzene", "toluene"], "ideal"),
        (["n-pentane", "n-decane"], "ideal"),
        (["methane", "n-hexane"], "ideal"),
    ] {
        let pkg = package(&names, model, &[]);
        let (n, wt, weq) = sweep(&pkg, &binary_grid(), &pressures);
        println!("{names:?} {model}: {n} flashes, worst PH round trip |ΔT|/T = {wt:.1e}, worst |y − K x| = {weq:.1e}");
        assert!(wt < 1e-10 && weq < 1e-12);
    }
}

#[test]
fn sweep_ternaries() {
    let zs: Vec<Vec<f64>> = vec![
        vec![0.3, 0.3, 0.4],
        vec![0.8, 0.1, 0.1],
        vec![0.05, 0.05, 0.9],
        vec![0.0, 0.5, 0.5],
        vec![0.49, 0.49, 0.02],
    ];
    for (names, vle) in [
        (["benzene", "toluene", "o-xylene"], VleModel::Ideal),
        // Light gas far above its critical point (extrapolated vapour pressure) with aromatics,
        // including states down to ~10 K where the aromatics' K-values underflow.
        (["hydrogen", "benzene", "toluene"], VleModel::Ideal),
        // Relative volatilities that do not match the vapour pressures, in a scrambled order.
        (["o-xylene", "benzene", "toluene"], VleModel::ConstantAlpha { alpha: vec![1.0, 5.0, 2.3] }),
    ] {
        let lib = Library::builtin().unwrap();
        let pkg = ThermoPackage { components: names.iter().map(|n| lib.component(n).unwrap().clone()).collect(), vle };
        let (n, wt, weq) = sweep(&pkg, &zs, &[1e3, 101_325.0, 2e6]);
        println!("{names:?}: {n} flashes, worst PH round trip {wt:.1e}, worst |y − K x| {weq:.1e}");
        assert!(wt < 1e-10, "{names:?}");
        if !matches!(pkg.vle, VleModel::ConstantAlpha { .. }) {
            assert!(weq < 1e-12, "{names:?}");
        }
    }
    // Methanol–ethanol–water with NRTL; the alcohol pair is nearly ideal (τ = 0 given inline).
    let extra = BinaryPair {
        model: "nrtl".into(),
        i: "methanol".into(),
        j: "ethanol".into(),
        a_ij: 0.0,
        a_ji: 0.0,
        b_ij: 0.0,
        b_ji: 0.0,
        alpha: 0.3,
        source: "ideal pair for the test".into(),
    };
    let pkg = package(&["methanol", "ethanol", "water"], "nrtl", &[extra]);
    let (n, wt, weq) = sweep(&pkg, &zs, &[101_325.0]);
    println!("methanol–ethanol–water: {n} flashes, {wt:.1e}, {weq:.1e}");
    assert!(wt < 1e-10 && weq < 1e-12);
}
