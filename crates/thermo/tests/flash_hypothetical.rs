//! Bubble/dew points and flashes on hypothetical Clausius–Clapeyron components, where the
//! answers have closed forms (no library needed).
#![allow(clippy::needless_range_loop)] // index loops over components read like the equations

mod common;

use approx::abs_diff_eq;
use common::*;
use plantwide_thermo::flash::rachford_rice;
use plantwide_thermo::{PhaseState, R_GAS, T_REF, ThermoError, ThermoPackage, VleModel};

const ALPHAS: [f64; 3] = [4.0, 2.0, 1.0];
const HVAP: f64 = 30_000.0;
const TREF: f64 = 350.0;
const CP: f64 = 150.0;
const P0: f64 = 101_325.0;

fn ideal() -> ThermoPackage {
    ThermoPackage { components: hypotheticals(&ALPHAS), vle: VleModel::Ideal }
}

fn const_alpha(alpha: &[f64]) -> ThermoPackage {
    ThermoPackage { components: hypotheticals(&ALPHAS), vle: VleModel::ConstantAlpha { alpha: alpha.to_vec() } }
}

/// Closed-form Raoult bubble temperature: 1/T = 1/t_ref − (R/ΔH) ln(P / (P0 Σ α_i x_i)).
fn bubble_t_exact(p: f64, x: &[f64]) -> f64 {
    let s: f64 = x.iter().zip(ALPHAS).map(|(x, a)| x * a).sum();
    1.0 / (1.0 / TREF - R_GAS / HVAP * (p / (P0 * s)).ln())
}

/// Closed-form Raoult dew temperature: 1/T = 1/t_ref − (R/ΔH) ln(P Σ (y_i/α_i) / P0).
fn dew_t_exact(p: f64, y: &[f64]) -> f64 {
    let s: f64 = y.iter().zip(ALPHAS).map(|(y, a)| y / a).sum();
    1.0 / (1.0 / TREF - R_GAS / HVAP * (p * s / P0).ln())
}

#[test]
fn common_hvap_gives_constant_relative_volatility() {
    let pkg = ideal();
    let x = [0.3, 0.3, 0.4];
    for t in [280.0, 330.0, 365.0, 420.0] {
        let mut k = [0.0; 3];
        pkg.k_values(t, 1e5, &x, &mut k);
        for i in 0..3 {
            for j in 0..3 {
                let rel = (k[i] / k[j]) / (ALPHAS[i] / ALPHAS[j]) - 1.0;
                assert!(rel.abs() < 1e-14, "K_{i}/K_{j} at {t} K off by {rel}");
            }
        }
    }
}

#[test]
fn bubble_and_dew_points_match_closed_forms() {
    let compositions = [[0.2, 0.3, 0.5], [0.9, 0.05, 0.05], [0.0, 0.5, 0.5], [1.0, 0.0, 0.0]];
    for pkg in [ideal(), const_alpha(&ALPHAS)] {
        for p in [2e4, 101_325.0, 5e5] {
            for z in &compositions {
                let b = pkg.bubble_t(p, z).unwrap();
                let tb = bubble_t_exact(p, z);
                assert!((b.t - tb).abs() <= 1e-12 * tb, "{:?}: bubble {} vs {tb}", pkg.vle, b.t);
                let s: f64 = z.iter().zip(ALPHAS).map(|(x, a)| x * a).sum();
                for i in 0..3 {
                    assert!((b.incipient[i] - ALPHAS[i] * z[i] / s).abs() < 1e-13);
                }
                let d = pkg.dew_t(p, z).unwrap();
                let td = dew_t_exact(p, z);
                assert!((d.t - td).abs() <= 1e-12 * td, "{:?}: dew {} vs {td}", pkg.vle, d.t);
                // Pressures at those temperatures.
                let bp = pkg.bubble_p(tb, z).unwrap();
                assert!((bp.p / p - 1.0).abs() < 1e-13);
                let dp = pkg.dew_p(td, z).unwrap();
                assert!((dp.p / p - 1.0).abs() < 1e-13);
            }
        }
    }
}

#[test]
fn rachford_rice_mass_balance_closes() {
    let cases: [(&[f64], &[f64]); 5] = [
        (&[0.3, 0.3, 0.4], &[3.1, 1.2, 0.2]),
        (&[0.01, 0.98, 0.01], &[50.0, 1.0001, 0.001]),
        (&[0.5, 0.5], &[1.0 + 1e-9, 1.0 - 1e-9]),
        (&[0.2, 0.0, 0.3, 0.5], &[8.0, 0.5, 1.5, 0.05]),
        (&[0.25, 0.25, 0.25, 0.25], &[1e6, 1e-6, 2.0, 0.5]),
    ];
    for (z, k) in cases {
        let r = rachford_rice(z, k).unwrap();
        assert!((0.0..=1.0).contains(&r.beta));
        for i in 0..z.len() {
            let mb = r.beta * r.y[i] + (1.0 - r.beta) * r.x[i];
            assert!((mb - z[i]).abs() < 1e-12, "z {z:?} K {k:?}: component {i} balance {mb} vs {}", z[i]);
            if r.beta > 0.0 && r.beta < 1.0 {
                assert!((r.y[i] - k[i] * r.x[i]).abs() < 1e-12);
            }
        }
        assert!((r.x.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        assert!((r.y.iter().sum::<f64>() - 1.0).abs() < 1e-14);
    }
    // Single-phase ends.
    assert_eq!(rachford_rice(&[0.5, 0.5], &[0.9, 0.5]).unwrap().beta, 0.0);
    assert_eq!(rachford_rice(&[0.5, 0.5], &[1.5, 1.1]).unwrap().beta, 1.0);
    assert!(matches!(rachford_rice(&[0.5, 0.5], &[-1.0, 2.0]), Err(ThermoError::BadInput { .. })));
}

#[test]
fn two_phase_flash_matches_closed_form() {
    // K_i = α_i · E(T) · P0/P: for a binary the compositions are explicit.
    let pkg = ThermoPackage { components: hypotheticals(&[3.0, 1.0]), vle: VleModel::Ideal };
    let (p, z) = (101_325.0, [0.4, 0.6]);
    let t = 0.5 * (pkg.bubble_t(p, &z).unwrap().t + pkg.dew_t(p, &z).unwrap().t);
    let e = (-HVAP / R_GAS * (1.0 / t - 1.0 / TREF)).exp();
    let (k1, k2) = (3.0 * e, e);
    let x1 = (1.0 - k2) / (k1 - k2);
    let beta = (z[0] - x1) / (k1 * x1 - x1);
    let r = pkg.flash_tp(t, p, &z).unwrap();
    assert_eq!(r.phase, PhaseState::TwoPhase);
    assert!((r.x[0] - x1).abs() < 1e-13 && (r.beta - beta).abs() < 1e-12);
    // Enthalpy: h = cp (T − T_ref) − (1 − β) ΔH_vap.
    let h = CP * (t - T_REF) - (1.0 - beta) * HVAP;
    assert!((r.h - h).abs() < 1e-8, "h {} vs {h}", r.h);
}

fn round_trips(pkg: &ThermoPackage, p: f64, x: &[f64]) {
    let b = pkg.bubble_t(p, x).unwrap();
    let d = pkg.dew_t(p, &b.incipient).unwrap();
    assert!((d.t - b.t).abs() < 1e-10 * b.t, "{:?}: dew T {} vs bubble T {}", pkg.vle, d.t, b.t);
    assert!(abs_diff_eq!(d.incipient[..], x[..], epsilon = 1e-10), "dew liquid {:?} vs {x:?}", d.incipient);
    let f = pkg.flash_tp(b.t, p, x).unwrap();
    assert!(f.beta.abs() < 1e-10, "β at bubble point {}", f.beta);
    let td = pkg.dew_t(p, x).unwrap().t;
    let cases = [
        (b.t - 5.0, PhaseState::Liquid),
        (b.t + 0.3 * (td - b.t), PhaseState::TwoPhase),
        (0.5 * (b.t + td), PhaseState::TwoPhase),
        (td + 5.0, PhaseState::Vapour),
    ];
    for (t, phase) in cases {
        let f = pkg.flash_tp(t, p, x).unwrap();
        assert_eq!(f.phase, phase, "TP flash at {t} K");
        for i in 0..x.len() {
            assert!((f.beta * f.y[i] + (1.0 - f.beta) * f.x[i] - x[i]).abs() < 1e-12);
        }
        let g = pkg.flash_ph(p, f.h, x).unwrap();
        assert!((g.t - t).abs() < 1e-10 * t, "PH flash T {} vs {t}", g.t);
        assert!((g.beta - f.beta).abs() < 1e-9, "PH β {} vs {}", g.beta, f.beta);
        assert_eq!(g.phase, f.phase);
    }
}

#[test]
fn flash_round_trips() {
    round_trips(&ideal(), 101_325.0, &[0.2, 0.3, 0.5]);
    round_trips(&ideal(), 3e5, &[0.05, 0.9, 0.05]);
    round_trips(&const_alpha(&ALPHAS), 101_325.0, &[0.2, 0.3, 0.5]);
    // Relative volatilities that disagree with the vapour pressures: still exact inverses.
    round_trips(&const_alpha(&[2.5, 1.6, 1.0]), 101_325.0, &[0.2, 0.3, 0.5]);
}

#[test]
fn pure_component_ph_flash_uses_the_lever_rule() {
    let pkg = ThermoPackage { components: hypotheticals(&[2.0]), vle: VleModel::Ideal };
    let tb = pkg.components[0].tb;
    let hl = CP * (tb - T_REF) - HVAP;
    let r = pkg.flash_ph(101_325.0, hl + 0.3 * HVAP, &[1.0]).unwrap();
    assert_eq!(r.phase, PhaseState::TwoPhase);
    assert!((r.t - tb).abs() < 1e-10 * tb && (r.beta - 0.3).abs() < 1e-10);
    // Subcooled and superheated.
    let r = pkg.flash_ph(101_325.0, hl - CP * 10.0, &[1.0]).unwrap();
    assert_eq!(r.phase, PhaseState::Liquid);
    assert!((r.t - (tb - 10.0)).abs() < 1e-9);
    let r = pkg.flash_ph(101_325.0, hl + HVAP + CP * 10.0, &[1.0]).unwrap();
    assert_eq!(r.phase, PhaseState::Vapour);
    assert!((r.t - (tb + 10.0)).abs() < 1e-9);
    // TP flash of a pure component is never two-phase.
    assert_eq!(pkg.flash_tp(tb - 1e-6, 101_325.0, &[1.0]).unwrap().phase, PhaseState::Liquid);
    assert_eq!(pkg.flash_tp(tb + 1e-6, 101_325.0, &[1.0]).unwrap().phase, PhaseState::Vapour);
}

#[test]
fn bad_inputs_are_errors() {
    let pkg = ideal();
    let bad = |r: Result<_, ThermoError>| matches!(r, Err(ThermoError::BadInput { .. }));
    assert!(bad(pkg.bubble_t(-1.0, &[0.2, 0.3, 0.5]).map(|_| ())));
    assert!(bad(pkg.bubble_t(f64::NAN, &[0.2, 0.3, 0.5]).map(|_| ())));
    assert!(bad(pkg.bubble_p(0.0, &[0.2, 0.3, 0.5]).map(|_| ())));
    assert!(bad(pkg.dew_t(1e5, &[0.2, 0.3]).map(|_| ())));
    assert!(bad(pkg.dew_p(300.0, &[0.2, 0.3, 0.6]).map(|_| ())));
    assert!(bad(pkg.flash_tp(300.0, 1e5, &[0.2, -0.1, 0.9]).map(|_| ())));
    assert!(bad(pkg.flash_tp(300.0, 1e5, &[0.2, f64::NAN, 0.8]).map(|_| ())));
    assert!(bad(pkg.flash_ph(1e5, f64::INFINITY, &[0.2, 0.3, 0.5]).map(|_| ())));
    // Normalised within 1e-8: accepted and normalised.
    let r = pkg.flash_tp(300.0, 1e5, &[0.2, 0.3, 0.5 + 5e-9]).unwrap();
    assert!((r.x.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    // Error messages name the conditions.
    let e = pkg.flash_tp(300.0, -5.0, &[0.2, 0.3, 0.5]).unwrap_err().to_string();
    assert!(e.contains("-5"), "{e}");
}
