//! Bubble and dew points. All VLE models are handled through `K_i = Φ_i(T, x) / P`
//! (see `ThermoPackage::ln_phi`), so that
//!
//! * bubble pressure: `P = Σ x_i Φ_i(T, x)` (direct), `y_i = x_i Φ_i / P`;
//! * bubble temperature: the root of `ln Σ x_i Φ_i(T, x) − ln P = 0` (1-D, `x` is fixed);
//! * dew pressure/temperature: `1 = P Σ y_i / Φ_i(T, x)` with the incipient liquid
//!   `x_i = P y_i / Φ_i(T, x)`, solved by successive substitution on `x` followed by Newton's method
//!   on `(ln K, ln P)` or `(ln K, ln T)` with an exact dual-number Jacobian.

use num_dual::{Dual64, DualNum};

use super::input::{self, conditions};
use crate::solve1d::{T_MAX, T_MIN, solve_increasing};
use crate::{SaturationPoint, Scalar, ThermoError, ThermoPackage};

/// Successive-substitution iterations before the Newton polish.
const SS_MAX: usize = 200;
/// Successive substitution hands over to Newton below this change in mole fractions.
const SS_TOL: f64 = 1e-10;
/// Newton iterations of the polish.
const NEWTON_MAX: usize = 50;

/// `ln Σ_{w_i > 0} w_i exp(sign · v_i)`, shifted by the largest exponent for range safety.
pub(crate) fn log_sum_exp<S: Scalar>(w: &[f64], v: &[S], sign: f64) -> S {
    let m =
        w.iter().zip(v).filter(|(wi, _)| **wi > 0.0).map(|(_, vi)| sign * vi.re()).fold(f64::NEG_INFINITY, f64::max);
    if !m.is_finite() {
        return S::from(m);
    }
    let mut s = S::from(0.0);
    for (wi, vi) in w.iter().zip(v) {
        if *wi > 0.0 {
            s += (*vi * sign - m).exp() * *wi;
        }
    }
    s.ln() + m
}

/// A first temperature guess [K] for a mixture at pressure `p`: the mole-fraction average of the
/// normal boiling points, shifted with Trouton's rule (ΔS_vap ≈ 10.6 R).
pub(crate) fn t_guess(pkg: &ThermoPackage, p: f64, z: &[f64]) -> f64 {
    let mut tb = 0.0;
    let mut w = 0.0;
    for (zi, c) in z.iter().zip(&pkg.components) {
        if c.tb.is_finite() && c.tb > 0.0 {
            tb += zi * c.tb;
            w += zi;
        }
    }
    let tb = if w > 0.0 { tb / w } else { 300.0 };
    let den = 1.0 - (p / 101_325.0).ln() / 10.6;
    let t = if den > 0.1 { tb / den } else { tb * 10.0 };
    t.clamp(20.0, 5000.0)
}

fn ln_phi_f64(pkg: &ThermoPackage, t: f64, x: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; pkg.n()];
    pkg.ln_phi(t, x, &mut out);
    out
}

fn not_finite(routine: &'static str, cond: String) -> ThermoError {
    ThermoError::BadInput {
        routine,
        reason: format!("K-values are not finite at {cond} (check the vapour-pressure data)"),
    }
}

pub(crate) fn bubble_p(pkg: &ThermoPackage, t: f64, x: &[f64]) -> Result<SaturationPoint, ThermoError> {
    const R: &str = "bubble_p";
    input::temperature(R, t)?;
    let x = input::composition(R, pkg.n(), x)?;
    let lp = ln_phi_f64(pkg, t, &x);
    let ln_p = log_sum_exp(&x, &lp, 1.0);
    let mut y: Vec<f64> =
        x.iter().zip(&lp).map(|(xi, l)| if *xi > 0.0 { xi * (l - ln_p).exp() } else { 0.0 }).collect();
    super::rachford_rice::normalise(&mut y);
    let p = ln_p.exp();
    if !(p.is_finite() && p > 0.0 && y.iter().all(|v| v.is_finite())) {
        return Err(not_finite(R, conditions(Some(t), None, None, "x", &x)));
    }
    Ok(SaturationPoint { t, p, incipient: y, iterations: 1 })
}

pub(crate) fn bubble_t(pkg: &ThermoPackage, p: f64, x: &[f64]) -> Result<SaturationPoint, ThermoError> {
    const R: &str = "bubble_t";
    input::pressure(R, p)?;
    let x = input::composition(R, pkg.n(), x)?;
    let ln_p = p.ln();
    let xd: Vec<Dual64> = x.iter().map(|&v| Dual64::from(v)).collect();
    let mut lp = vec![Dual64::from(0.0); pkg.n()];
    let f = |t: f64| {
        pkg.ln_phi(Dual64::new(t, 1.0), &xd, &mut lp);
        let g = log_sum_exp(&x, &lp, 1.0) - ln_p;
        (g.re, g.eps)
    };
    let (t, iterations) =
        solve_increasing(f, t_guess(pkg, p, &x), T_MIN, T_MAX).map_err(|it| ThermoError::NoConvergence {
            routine: R,
            iterations: it,
            residual: f64::NAN,
            conditions: conditions(None, Some(p), None, "x", &x),
        })?;
    let sp = bubble_p(pkg, t, &x)?;
    Ok(SaturationPoint { t, p, incipient: sp.incipient, iterations })
}

/// Incipient liquid `x_i ∝ y_i / Φ_i(T, x)` and `ln(Σ y_i / Φ_i)` for the current `x`.
fn dew_update(pkg: &ThermoPackage, t: f64, y: &[f64], x: &[f64]) -> (Vec<f64>, f64) {
    let lp = ln_phi_f64(pkg, t, x);
    let ls = log_sum_exp(y, &lp, -1.0);
    let xn: Vec<f64> = y.iter().zip(&lp).map(|(yi, l)| if *yi > 0.0 { yi * (-l - ls).exp() } else { 0.0 }).collect();
    (xn, ls)
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (u, v)| m.max((u - v).abs()))
}

/// Newton polish of a dew point. Unknowns `u = (ln K_1 … ln K_n, ln s)` with `s = P` (fixed `T`)
/// or `s = T` (fixed `P`); residuals `ln K_i − ln Φ_i(T, x̂) + ln P` and `ln Σ x_i`, where
/// `x_i = y_i / K_i` and `x̂ = x / Σ x`.
fn dew_newton(pkg: &ThermoPackage, y: &[f64], u: &mut [f64], fixed: f64, t_unknown: bool) -> Result<usize, f64> {
    let n = pkg.n();
    let mut lp = vec![Dual64::from(0.0); n];
    let res = |v: &[Dual64]| {
        let mut x: Vec<Dual64> = y.iter().zip(v).map(|(yi, lk)| (-*lk).exp() * *yi).collect();
        let sx: Dual64 = x.iter().copied().sum();
        x.iter_mut().for_each(|xi| *xi /= sx);
        let (t, ln_p) = if t_unknown { (v[n].exp(), Dual64::from(fixed.ln())) } else { (Dual64::from(fixed), v[n]) };
        pkg.ln_phi(t, &x, &mut lp);
        let mut r: Vec<Dual64> = (0..n).map(|i| v[i] - lp[i] + ln_p).collect();
        r.push(sx.ln());
        r.iter().all(|ri| ri.re.is_finite()).then_some(r)
    };
    crate::newton::newton(u, res, NEWTON_MAX)
}

pub(crate) fn dew_p(pkg: &ThermoPackage, t: f64, y: &[f64]) -> Result<SaturationPoint, ThermoError> {
    const R: &str = "dew_p";
    input::temperature(R, t)?;
    let y = input::composition(R, pkg.n(), y)?;
    let cond = || conditions(Some(t), None, None, "y", &y);
    let mut x = y.clone();
    let mut ss = 0;
    for it in 1..=SS_MAX {
        ss = it;
        let (xn, _) = dew_update(pkg, t, &y, &x);
        if !xn.iter().all(|v| v.is_finite()) {
            return Err(not_finite(R, cond()));
        }
        let d = max_diff(&xn, &x);
        x = xn;
        if d < SS_TOL {
            break;
        }
    }
    let lp = ln_phi_f64(pkg, t, &x);
    let ln_p = -log_sum_exp(&y, &lp, -1.0);
    let mut u: Vec<f64> = lp.iter().map(|l| l - ln_p).collect();
    u.push(ln_p);
    let it = dew_newton(pkg, &y, &mut u, t, false).map_err(|r| ThermoError::NoConvergence {
        routine: R,
        iterations: ss + NEWTON_MAX,
        residual: r,
        conditions: cond(),
    })?;
    let n = pkg.n();
    let mut x: Vec<f64> = y.iter().zip(&u).map(|(yi, lk)| yi * (-lk).exp()).collect();
    super::rachford_rice::normalise(&mut x);
    let p = u[n].exp();
    if !(p.is_finite() && p > 0.0) {
        return Err(not_finite(R, cond()));
    }
    Ok(SaturationPoint { t, p, incipient: x, iterations: ss + it })
}

pub(crate) fn dew_t(pkg: &ThermoPackage, p: f64, y: &[f64]) -> Result<SaturationPoint, ThermoError> {
    const R: &str = "dew_t";
    input::pressure(R, p)?;
    let y = input::composition(R, pkg.n(), y)?;
    let cond = || conditions(None, Some(p), None, "y", &y);
    let ln_p = p.ln();
    let n = pkg.n();
    let mut x = y.clone();
    let mut t = t_guess(pkg, p, &y);
    let mut ss = 0;
    let mut lp = vec![Dual64::from(0.0); n];
    for it in 1..=SS_MAX {
        ss = it;
        // Dew temperature for the current incipient-liquid estimate: Σ y_i/Φ_i(T, x) = 1/P.
        let xd: Vec<Dual64> = x.iter().map(|&v| Dual64::from(v)).collect();
        let f = |tt: f64| {
            pkg.ln_phi(Dual64::new(tt, 1.0), &xd, &mut lp);
            let g = -(log_sum_exp(&y, &lp, -1.0) + ln_p);
            (g.re, g.eps)
        };
        t = solve_increasing(f, t, T_MIN, T_MAX)
            .map_err(|e| ThermoError::NoConvergence {
                routine: R,
                iterations: it + e,
                residual: f64::NAN,
                conditions: cond(),
            })?
            .0;
        let (xn, _) = dew_update(pkg, t, &y, &x);
        if !xn.iter().all(|v| v.is_finite()) {
            return Err(not_finite(R, cond()));
        }
        let d = max_diff(&xn, &x);
        x = xn;
        if d < SS_TOL {
            break;
        }
    }
    let lpf = ln_phi_f64(pkg, t, &x);
    let mut u: Vec<f64> = lpf.iter().map(|l| l - ln_p).collect();
    u.push(t.ln());
    let it = dew_newton(pkg, &y, &mut u, p, true).map_err(|r| ThermoError::NoConvergence {
        routine: R,
        iterations: ss + NEWTON_MAX,
        residual: r,
        conditions: cond(),
    })?;
    let mut x: Vec<f64> = y.iter().zip(&u).map(|(yi, lk)| yi * (-lk).exp()).collect();
    super::rachford_rice::normalise(&mut x);
    let t = u[n].exp();
    if !(t.is_finite() && t > 0.0) {
        return Err(not_finite(R, cond()));
    }
    Ok(SaturationPoint { t, p, incipient: x, iterations: ss + it })
}
