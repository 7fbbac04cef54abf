//! Activity-coefficient models and package properties: limiting closed forms, Gibbs–Duhem, and
//! exact derivatives.
#![allow(clippy::needless_range_loop)] // index loops over components read like the equations

mod common;

use common::*;
use num_dual::Dual64;
use plantwide_thermo::{ActivityModel, ThermoPackage, VleModel};

fn nrtl3() -> ActivityModel {
    // Arbitrary but typical magnitudes (a dimensionless, b in K).
    ActivityModel::Nrtl {
        a: vec![vec![0.0, -0.8, 0.3], vec![3.4, 0.0, -0.2], vec![0.1, 0.5, 0.0]],
        b: vec![vec![0.0, 246.0, -50.0], vec![-586.0, 0.0, 120.0], vec![80.0, -30.0, 0.0]],
        alpha: vec![vec![0.0, 0.3, 0.2], vec![0.3, 0.0, 0.47], vec![0.2, 0.47, 0.0]],
    }
}

fn wilson3() -> ActivityModel {
    ActivityModel::Wilson {
        a: vec![vec![0.0, -0.5, 0.2], vec![0.4, 0.0, -0.1], vec![0.3, 0.2, 0.0]],
        b: vec![vec![0.0, -120.0, 40.0], vec![-300.0, 0.0, 60.0], vec![-20.0, 10.0, 0.0]],
    }
}

fn ln_gamma(m: &ActivityModel, t: f64, x: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; x.len()];
    m.ln_gamma(t, x, &mut out);
    out
}

#[test]
fn pure_components_have_unit_activity_coefficients() {
    for m in [nrtl3(), wilson3()] {
        for i in 0..3 {
            let mut x = vec![0.0; 3];
            x[i] = 1.0;
            for t in [300.0, 350.0, 420.0] {
                let g = ln_gamma(&m, t, &x);
                assert!(g[i].abs() < 1e-15, "{m:?}: ln γ_{i} = {} for pure {i}", g[i]);
            }
        }
    }
}

#[test]
fn nrtl_infinite_dilution_closed_form() {
    // Binary: ln γ1∞ = τ21 + τ12 exp(−α τ12), ln γ2∞ = τ12 + τ21 exp(−α τ21).
    let (a12, a21, b12, b21, alpha) = (-0.8, 3.4, 246.0, -586.0, 0.3);
    let m = ActivityModel::Nrtl {
        a: vec![vec![0.0, a12], vec![a21, 0.0]],
        b: vec![vec![0.0, b12], vec![b21, 0.0]],
        alpha: vec![vec![0.0, alpha], vec![alpha, 0.0]],
    };
    for t in [320.0, 351.0, 380.0] {
        let (t12, t21) = (a12 + b12 / t, a21 + b21 / t);
        let g1 = ln_gamma(&m, t, &[0.0, 1.0])[0];
        let g2 = ln_gamma(&m, t, &[1.0, 0.0])[1];
        assert!((g1 - (t21 + t12 * (-alpha * t12).exp())).abs() < 1e-14);
        assert!((g2 - (t12 + t21 * (-alpha * t21).exp())).abs() < 1e-14);
    }
}

#[test]
fn wilson_infinite_dilution_closed_form() {
    // Binary: ln γ1∞ = 1 − ln Λ12 − Λ21.
    let m = ActivityModel::Wilson {
        a: vec![vec![0.0, -0.5], vec![0.4, 0.0]],
        b: vec![vec![0.0, -120.0], vec![-300.0, 0.0]],
    };
    for t in [320.0_f64, 380.0] {
        let (l12, l21) = ((-0.5 - 120.0 / t).exp(), (0.4 - 300.0 / t).exp());
        let g1 = ln_gamma(&m, t, &[0.0, 1.0])[0];
        let g2 = ln_gamma(&m, t, &[1.0, 0.0])[1];
        assert!((g1 - (1.0 - l12.ln() - l21)).abs() < 1e-14);
        assert!((g2 - (1.0 - l21.ln() - l12)).abs() < 1e-14);
    }
}

#[test]
fn gibbs_duhem_holds() {
    // Σ_i x_i ∂ln γ_i/∂x_k = Σ_i x_i ∂ln γ_i/∂x_m along the simplex (direction e_k − e_m), at fixed T.
    for m in [nrtl3(), wilson3()] {
        let x = [0.2, 0.5, 0.3];
        let xd: Vec<Dual64> = x.iter().enumerate().map(|(i, &v)| Dual64::new(v, [1.0, -1.0, 0.0][i])).collect();
        let mut out = vec![Dual64::from(0.0); 3];
        m.ln_gamma(Dual64::from(340.0), &xd, &mut out);
        let gd: f64 = x.iter().zip(&out).map(|(xi, g)| xi * g.eps).sum();
        assert!(gd.abs() < 1e-13, "{m:?}: Σ x dlnγ = {gd}");
    }
}

fn check(name: &str, f: impl Fn(Dual64) -> Dual64, x: f64) {
    let d = f(Dual64::new(x, 1.0));
    let fd = central_diff(|v| f(Dual64::from(v)).re, x, 1e-4 * x.abs().max(1e-2));
    let tol = 1e-7 * d.eps.abs().max(1e-9 * d.re.abs().max(1.0));
    assert!((d.eps - fd).abs() <= tol, "{name}: dual {} vs finite difference {fd} at {x}", d.eps);
}

#[test]
fn activity_derivatives_match_finite_differences() {
    let x = [0.2, 0.5, 0.3];
    for m in [nrtl3(), wilson3()] {
        for i in 0..3 {
            let g_t = |t: Dual64| {
                let xd: Vec<Dual64> = x.iter().map(|&v| Dual64::from(v)).collect();
                let mut out = vec![Dual64::from(0.0); 3];
                m.ln_gamma(t, &xd, &mut out);
                out[i]
            };
            check(&format!("ln γ_{i} wrt T"), g_t, 345.0);
            for k in 0..3 {
                let g_x = |xk: Dual64| {
                    let mut xd: Vec<Dual64> = x.iter().map(|&v| Dual64::from(v)).collect();
                    xd[k] = xk;
                    let mut out = vec![Dual64::from(0.0); 3];
                    m.ln_gamma(Dual64::from(345.0), &xd, &mut out);
                    out[i]
                };
                check(&format!("ln γ_{i} wrt x_{k}"), g_x, x[k]);
            }
        }
    }
}

fn packages() -> Vec<ThermoPackage> {
    let comps = vec![water_dippr(), water_other_forms(), benzene_antoine()];
    vec![
        ThermoPackage { components: comps.clone(), vle: VleModel::Ideal },
        ThermoPackage { components: comps.clone(), vle: VleModel::ConstantAlpha { alpha: vec![1.0, 1.7, 3.2] } },
        ThermoPackage { components: comps.clone(), vle: VleModel::Activity(nrtl3()) },
        ThermoPackage { components: comps, vle: VleModel::Activity(wilson3()) },
    ]
}

#[test]
fn package_derivatives_match_finite_differences() {
    let x = [0.2, 0.5, 0.3];
    let xd = || x.iter().map(|&v| Dual64::from(v)).collect::<Vec<Dual64>>();
    for pkg in packages() {
        for i in 0..3 {
            let k_t = |t: Dual64| {
                let mut out = vec![Dual64::from(0.0); 3];
                pkg.k_values(t, Dual64::from(1.2e5), &xd(), &mut out);
                out[i]
            };
            check(&format!("{:?} K_{i} wrt T", pkg.vle), k_t, 360.0);
            let k_p = |p: Dual64| {
                let mut out = vec![Dual64::from(0.0); 3];
                pkg.k_values(Dual64::from(360.0), p, &xd(), &mut out);
                out[i]
            };
            check(&format!("K_{i} wrt P"), k_p, 1.2e5);
            for k in 0..3 {
                let k_x = |xk: Dual64| {
                    let mut xs = xd();
                    xs[k] = xk;
                    let mut out = vec![Dual64::from(0.0); 3];
                    pkg.k_values(Dual64::from(360.0), Dual64::from(1.2e5), &xs, &mut out);
                    out[i]
                };
                check(&format!("K_{i} wrt x_{k}"), k_x, x[k]);
            }
        }
        check("h_liq wrt T", |t| pkg.h_liq(t, &xd()), 360.0);
        check("h_vap wrt T", |t| pkg.h_vap(t, &xd()), 360.0);
        check("v_liq wrt T", |t| pkg.v_liq(t, &xd()), 360.0);
        for k in 0..3 {
            let with = |xk: Dual64| {
                let mut xs = xd();
                xs[k] = xk;
                xs
            };
            check("h_liq wrt x", |v| pkg.h_liq(Dual64::from(360.0), &with(v)), x[k]);
            check("h_vap wrt x", |v| pkg.h_vap(Dual64::from(360.0), &with(v)), x[k]);
            check("v_liq wrt x", |v| pkg.v_liq(Dual64::from(360.0), &with(v)), x[k]);
            check("mw wrt x", |v| pkg.mw(&with(v)), x[k]);
        }
    }
}

#[test]
fn k_values_follow_their_definitions() {
    let pkgs = packages();
    let x = [0.2, 0.5, 0.3];
    let (t, p) = (360.0, 1.2e5);
    let mut k = vec![0.0_f64; 3];
    // Ideal: K = psat/P.
    pkgs[0].k_values(t, p, &x, &mut k);
    for (ki, c) in k.iter().zip(&pkgs[0].components) {
        let e: f64 = c.psat(t) / p;
        assert!((ki - e).abs() <= 1e-15 * ki);
    }
    // Constant alpha: K_i = α_i / Σ α x, so Σ K x = 1 and K_i/K_j = α_i/α_j.
    pkgs[1].k_values(t, p, &x, &mut k);
    let skx: f64 = k.iter().zip(&x).map(|(a, b)| a * b).sum();
    assert!((skx - 1.0).abs() < 1e-15);
    assert!((k[2] / k[0] - 3.2).abs() < 1e-14);
    // Activity: K = γ psat / P.
    let g = ln_gamma(&nrtl3(), t, &x);
    pkgs[2].k_values(t, p, &x, &mut k);
    for i in 0..3 {
        let c = &pkgs[2].components[i];
        let e: f64 = g[i].exp() * c.psat(t) / p;
        assert!((k[i] - e).abs() <= 1e-14 * e);
    }
    // Mean molar mass.
    let mw: f64 = pkgs[0].mw(&x);
    assert!((mw - (0.2 * 0.018_015_28 + 0.5 * 0.018_015_28 + 0.3 * 0.078_112)).abs() < 1e-16);
}

#[test]
fn mismatched_parameters_give_nan_not_panic() {
    let m = ActivityModel::Wilson { a: vec![vec![0.0]], b: vec![vec![0.0]] };
    let g = ln_gamma(&m, 300.0, &[0.5, 0.5]);
    assert!(g.iter().all(|v| v.is_nan()));
    let pkg = ThermoPackage {
        components: vec![water_dippr(), benzene_antoine()],
        vle: VleModel::ConstantAlpha { alpha: vec![1.0] },
    };
    let mut k = vec![0.0_f64; 2];
    pkg.k_values(300.0, 1e5, &[0.5, 0.5], &mut k);
    assert!(k.iter().all(|v| v.is_nan()));
    assert!(pkg.bubble_t(1e5, &[0.5, 0.5]).is_err());
}
