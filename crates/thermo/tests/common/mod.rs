//! Shared fixtures for the integration tests: components with published coefficients that do not
//! need the built-in library.
#![allow(dead_code)]

use plantwide_thermo::{Component, CpIdealGas, CpLiquid, HeatOfVaporization, LiquidVolume, VapourPressure};

/// Water with the DIPPR coefficients printed in Perry's Chemical Engineers' Handbook, 8th ed.
/// (Tables 2-8, 2-32, 2-150, 2-153, 2-156), converted from kmol to mol.
pub fn water_dippr() -> Component {
    Component {
        name: "water".into(),
        formula: "H2O".into(),
        cas: "7732-18-5".into(),
        mw: 0.018_015_28,
        tb: 373.124,
        tc: Some(647.096),
        pc: Some(22.064e6),
        omega: Some(0.3443),
        psat: VapourPressure::Dippr101 { c: [73.649, -7258.2, -7.3037, 4.1653e-6, 2.0], tmin: 273.16, tmax: 647.096 },
        cp_ig: CpIdealGas::Dippr107 { c: [33.363, 26.79, 2610.5, 8.896, 1169.0] },
        cp_liq: CpLiquid::Dippr100 { c: [276.370, -2.0901, 8.125e-3, -1.4116e-5, 9.3701e-9] },
        hvap: HeatOfVaporization::Dippr106 { c: [52053.0, 0.3199, -0.212, 0.25795, 0.0], tc: 647.096 },
        vliq: LiquidVolume::Dippr105 { c: [5459.0, 0.30542, 647.13, 0.081] },
        source: "Perry's 8th ed.".into(),
    }
}

/// Water with the other correlation forms: the Perry DIPPR 101 vapour pressure rewritten as an
/// extended Antoine equation, the ideal-gas cp polynomial of Reid, Prausnitz & Poling (4th ed.,
/// Appendix A: 32.24 + 1.924e-3 T + 1.055e-5 T² − 3.596e-9 T³ J/(mol K)), Watson heat of
/// vaporization from 40.656 kJ/mol at 373.15 K, and the Rackett volume (Z_RA = 0.2338).
pub fn water_other_forms() -> Component {
    Component {
        name: "water-b".into(),
        formula: "H2O".into(),
        cas: String::new(),
        mw: 0.018_015_28,
        tb: 373.124,
        tc: Some(647.096),
        pc: Some(22.064e6),
        omega: Some(0.3443),
        psat: VapourPressure::ExtendedAntoine {
            c: [73.649, -7258.2, 0.0, 0.0, -7.3037, 4.1653e-6, 2.0],
            tmin: 273.16,
            tmax: 647.096,
        },
        cp_ig: CpIdealGas::Polynomial { c: [32.24, 1.924e-3, 1.055e-5, -3.596e-9] },
        cp_liq: CpLiquid::Constant { cp: 75.3 },
        hvap: HeatOfVaporization::Watson { h_ref: 40_656.0, t_ref: 373.15, tc: 647.096, n: 0.38 },
        vliq: LiquidVolume::Rackett { tc: 647.096, pc: 22.064e6, zra: 0.2338 },
        source: String::new(),
    }
}

/// Benzene with the NIST Webbook Antoine equation (Eon, Pommier & Jacques 1971, 287.7–354.07 K):
/// `log10 P[bar] = 4.01814 − 1203.835/(T − 53.226)`, i.e. `a = 9.01814` for P in Pa.
pub fn benzene_antoine() -> Component {
    Component {
        name: "benzene-antoine".into(),
        formula: "C6H6".into(),
        cas: "71-43-2".into(),
        mw: 0.078_112,
        tb: 353.24,
        tc: Some(562.05),
        pc: Some(4.895e6),
        omega: Some(0.2103),
        psat: VapourPressure::Antoine { a: 9.01814, b: 1203.835, c: -53.226, tmin: 287.7, tmax: 354.07 },
        cp_ig: CpIdealGas::Constant { cp: 82.4 },
        cp_liq: CpLiquid::Constant { cp: 136.0 },
        hvap: HeatOfVaporization::Watson { h_ref: 30_720.0, t_ref: 353.24, tc: 562.05, n: 0.38 },
        vliq: LiquidVolume::Constant { v: 8.94e-5 },
        source: String::new(),
    }
}

/// Hypothetical components A (most volatile) … with relative volatilities `alphas`, common
/// `hvap` = 30 kJ/mol, `t_ref` = 350 K, cp = 150 J/(mol K).
pub fn hypotheticals(alphas: &[f64]) -> Vec<Component> {
    alphas
        .iter()
        .enumerate()
        .map(|(i, &a)| {
            Component::hypothetical(&format!("hyp{i}"), a, 0.05 + 0.01 * i as f64, 30_000.0, 350.0, 150.0, 1e-4)
        })
        .collect()
}

/// Central finite difference with one Richardson step.
pub fn central_diff(f: impl Fn(f64) -> f64, x: f64, h: f64) -> f64 {
    let d = |h: f64| (f(x + h) - f(x - h)) / (2.0 * h);
    (4.0 * d(h / 2.0) - d(h)) / 3.0
}
