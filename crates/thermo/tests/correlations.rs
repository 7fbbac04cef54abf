//! Pure-component correlations: published reference values, closed forms, and exact dual-number
//! derivatives checked against finite differences.
#![allow(clippy::needless_range_loop)] // index loops over components read like the equations

mod common;

use common::*;
use num_dual::Dual64;
use plantwide_thermo::{Component, CpIdealGas, HeatOfVaporization, T_REF};

/// Dual-number derivative of `f` at `x` vs a Richardson-extrapolated central difference.
fn check_derivative(name: &str, f: impl Fn(Dual64) -> Dual64, x: f64) {
    let d = f(Dual64::new(x, 1.0));
    let fd = central_diff(|v| f(Dual64::from(v)).re, x, 1e-4 * x.abs().max(1e-3));
    let tol = 1e-7 * d.eps.abs().max(1e-9 * d.re.abs().max(1.0));
    assert!((d.eps - fd).abs() <= tol, "{name}: dual {} vs finite difference {fd} at {x}", d.eps);
    assert_eq!(d.re, f(Dual64::from(x)).re, "{name}: value part differs from plain evaluation");
}

fn all_components() -> Vec<Component> {
    vec![
        water_dippr(),
        water_other_forms(),
        benzene_antoine(),
        Component::hypothetical("h", 2.0, 0.05, 30_000.0, 350.0, 120.0, 1e-4),
    ]
}

#[test]
fn derivatives_of_every_correlation() {
    for c in all_components() {
        for &t in &[280.0, 330.0, 373.15, 450.0, 600.0] {
            let n = |s: &str| format!("{} {s} at {t}", c.name);
            check_derivative(&n("psat"), |t| c.psat(t), t);
            check_derivative(&n("h_ig"), |t| c.h_ig(t), t);
            check_derivative(&n("cp_gas"), |t| c.cp_gas(t), t);
            check_derivative(&n("dh_vap"), |t| c.dh_vap(t), t);
            check_derivative(&n("h_liq"), |t| c.h_liq(t), t);
            check_derivative(&n("cp_liquid"), |t| c.cp_liquid(t), t);
            check_derivative(&n("v_liq"), |t| c.v_liq(t), t);
        }
    }
}

#[test]
fn h_ig_derivative_is_cp() {
    for c in all_components() {
        for &t in &[250.0, 298.15, 400.0, 800.0] {
            let d = c.h_ig(Dual64::new(t, 1.0));
            let cp = c.cp_gas(t);
            assert!((d.eps - cp).abs() <= 1e-12 * cp, "{}: dh/dT {} vs cp {cp}", c.name, d.eps);
        }
        assert_eq!(c.h_ig(T_REF), 0.0, "{}: h_ig(298.15 K) must be the datum", c.name);
    }
}

/// Composite Gauss–Legendre (5 points) quadrature.
fn gauss_legendre(f: impl Fn(f64) -> f64, a: f64, b: f64, panels: usize) -> f64 {
    let nodes = [0.0, 0.538_469_310_105_683_1, -0.538_469_310_105_683_1, 0.906_179_845_938_664, -0.906_179_845_938_664];
    let weights = [
        0.568_888_888_888_888_9,
        0.478_628_670_499_366_5,
        0.478_628_670_499_366_5,
        0.236_926_885_056_189_1,
        0.236_926_885_056_189_1,
    ];
    let h = (b - a) / panels as f64;
    (0..panels)
        .map(|k| {
            let m = a + (k as f64 + 0.5) * h;
            nodes.iter().zip(&weights).map(|(x, w)| w * f(m + 0.5 * h * x)).sum::<f64>() * 0.5 * h
        })
        .sum()
}

#[test]
fn dippr107_closed_form_integral_matches_quadrature() {
    let forms = [
        CpIdealGas::Dippr107 { c: [33.363, 26.79, 2610.5, 8.896, 1169.0] }, // water, Perry's 2-156
        CpIdealGas::Dippr107 { c: [44.767, 230.85, 1479.2, 168.36, 677.66] }, // benzene, Perry's 2-156
        CpIdealGas::Dippr107 { c: [29.1, 0.0, 0.0, 8.0, 0.0] },             // degenerate c2 = c4 = 0
        CpIdealGas::Polynomial { c: [32.24, 1.924e-3, 1.055e-5, -3.596e-9] },
    ];
    for f in &forms {
        for &t in &[150.0, 298.15, 350.0, 700.0, 1500.0] {
            let quad = gauss_legendre(|x| f.cp(x), T_REF, t, 400);
            let closed: f64 = f.h(t);
            assert!(
                (closed - quad).abs() <= 1e-9 * quad.abs().max(1.0),
                "{f:?} at {t}: closed {closed} vs quadrature {quad}"
            );
        }
    }
}

#[test]
fn published_values_of_water_and_benzene() {
    let w = water_dippr();
    // Normal boiling point 373.124 K (IAPWS-95): P_sat = 101 325 Pa within 0.3 %.
    let p: f64 = w.psat(373.124);
    assert!((p / 101_325.0 - 1.0).abs() < 3e-3, "water psat(Tb) = {p}");
    // Steam tables: ΔH_vap(373.15 K) = 40.657 kJ/mol; liquid volume at 298.15 K 18.069 cm³/mol;
    // ideal-gas cp at 298.15 K 33.58 J/(mol K); liquid cp at 298.15 K 75.3 J/(mol K).
    let dh: f64 = w.dh_vap(373.15);
    assert!((dh / 40_657.0 - 1.0).abs() < 0.01, "water ΔHvap = {dh}");
    let v: f64 = w.v_liq(298.15);
    assert!((v / 18.069e-6 - 1.0).abs() < 0.01, "water V_L = {v}");
    let cp: f64 = w.cp_gas(298.15);
    assert!((cp / 33.58 - 1.0).abs() < 0.005, "water cp_ig = {cp}");
    let cpl: f64 = w.cp_liquid(298.15);
    assert!((cpl / 75.3 - 1.0).abs() < 0.01, "water cp_L = {cpl}");
    // Extended Antoine with the same coefficients is the same function.
    let wb = water_other_forms();
    for t in [300.0, 373.15, 500.0] {
        let (a, b): (f64, f64) = (w.psat(t), wb.psat(t));
        assert!((a / b - 1.0).abs() < 1e-14);
    }
    // Benzene normal boiling point 353.24 K from the NIST Antoine equation: within 0.1 K.
    let tb = benzene_antoine().tsat(101_325.0).unwrap();
    assert!((tb - 353.24).abs() < 0.1, "benzene Tb = {tb}");
}

#[test]
fn watson_and_dippr106_vanish_at_and_above_tc() {
    let w = water_dippr();
    let wb = water_other_forms();
    for c in [&w, &wb] {
        for t in [647.096, 650.0, 900.0] {
            let d = c.dh_vap(Dual64::new(t, 1.0));
            assert_eq!((d.re, d.eps), (0.0, 0.0), "{} at {t}", c.name);
            let v = c.v_liq(Dual64::new(t, 1.0));
            assert!(v.re.is_finite() && v.eps.is_finite());
        }
        // Just below tc: finite, positive and decreasing.
        let d = c.dh_vap(Dual64::new(646.0, 1.0));
        assert!(d.re > 0.0 && d.eps < 0.0 && d.eps.is_finite());
    }
    // Watson reproduces its reference value exactly.
    let h = HeatOfVaporization::Watson { h_ref: 40_656.0, t_ref: 373.15, tc: 647.096, n: 0.38 };
    assert_eq!(h.eval(373.15), 40_656.0);
}

#[test]
fn hypothetical_component_closed_forms() {
    // Clausius–Clapeyron: tb from 1/tb = 1/t_ref + R ln(alpha)/hvap; psat(tb) = 1 atm exactly.
    let c = Component::hypothetical("x", 2.5, 0.06, 32_000.0, 360.0, 140.0, 1.1e-4);
    let tb = 1.0 / (1.0 / 360.0 + plantwide_thermo::R_GAS * 2.5f64.ln() / 32_000.0);
    assert!((c.tb - tb).abs() < 1e-12 * tb);
    let p: f64 = c.psat(c.tb);
    assert!((p / 101_325.0 - 1.0).abs() < 1e-13);
    let p_ref: f64 = c.psat(360.0);
    assert!((p_ref / (2.5 * 101_325.0) - 1.0).abs() < 1e-14);
    // Constant ΔHvap and equal heat capacities.
    for t in [300.0, 400.0] {
        assert_eq!(c.dh_vap(t), 32_000.0);
        let hl: f64 = c.h_liq(t);
        assert!((hl - (140.0 * (t - T_REF) - 32_000.0)).abs() < 1e-9);
    }
    assert_eq!(c.source, "hypothetical");
    assert!(c.tc.is_none() && c.pc.is_none() && c.omega.is_none());
}
