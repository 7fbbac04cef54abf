//! Adiabatic (PH) flash.

use num_dual::Dual64;

use super::input::{self, conditions};
use super::saturation::{bubble_t, dew_t};
use super::tp::{flash_tp, single_phase};
use crate::solve1d::{T_MAX, T_MIN, brent, solve_increasing};
use crate::{FlashResult, PhaseState, R_GAS, ThermoError, ThermoPackage};

/// PH flash: the temperature at which the equilibrium state of feed `z` at `p` has molar enthalpy
/// `h`. With the bubble and dew temperatures `T_b`, `T_d` of the feed:
///
/// * `h ≤ h_L(T_b, z)`: liquid; `h_L(T, z) = h` by bracketed Newton below `T_b`;
/// * `h ≥ h_V(T_d, z)`: vapour; `h_V(T, z) = h` by bracketed Newton above `T_d`;
/// * otherwise two phases: Brent's method on `H_TP(T) − h` over `[T_b, T_d]`, where `H_TP` is the
///   enthalpy of the TP flash (continuous and increasing), converged to a bracket of a few ulps.
///   When `T_d − T_b ≤ 1e-12 T_b` (a pure component or an azeotrope) the temperature is `T_b` and β
///   follows from the lever rule `β = (h − h_L)/(h_V − h_L)`.
pub(crate) fn flash_ph(pkg: &ThermoPackage, p: f64, h: f64, z: &[f64]) -> Result<FlashResult, ThermoError> {
    const R: &str = "flash_ph";
    input::pressure(R, p)?;
    if !h.is_finite() {
        return Err(ThermoError::BadInput {
            routine: R,
            reason: format!("enthalpy must be finite, got h = {h} J/mol"),
        });
    }
    let z = input::composition(R, pkg.n(), z)?;
    let cond = || conditions(None, Some(p), Some(h), "z", &z);
    let bub = bubble_t(pkg, p, &z)?;
    let dew = dew_t(pkg, p, &z)?;
    let (tb, td) = (bub.t, dew.t.max(bub.t));
    // Single-phase enthalpies minus h, with dT derivatives. The phase decision uses the same
    // (dual-number) evaluation as the root finder so that the two agree to the last bit.
    let zd: Vec<Dual64> = z.iter().map(|&v| Dual64::from(v)).collect();
    let f_liq = |t: f64| {
        let v = pkg.h_liq(Dual64::new(t, 1.0), &zd) - h;
        (v.re, v.eps)
    };
    let f_vap = |t: f64| {
        let v = pkg.h_vap(Dual64::new(t, 1.0), &zd) - h;
        (v.re, v.eps)
    };
    let (dl, dv) = (f_liq(tb).0, f_vap(td).0);
    let base_it = bub.iterations + dew.iterations;
    let no_conv =
        |it: usize, r: f64| ThermoError::NoConvergence { routine: R, iterations: it, residual: r, conditions: cond() };
    if dl >= 0.0 {
        let (t, it) = if dl == 0.0 {
            (tb, 0)
        } else {
            solve_increasing(f_liq, tb, T_MIN, tb).map_err(|it| no_conv(base_it + it, dl))?
        };
        return Ok(single_phase(pkg, t, p, &z, PhaseState::Liquid, base_it + it));
    }
    if dv <= 0.0 {
        let (t, it) = if dv == 0.0 {
            (td, 0)
        } else {
            solve_increasing(f_vap, td, td, T_MAX).map_err(|it| no_conv(base_it + it, dv))?
        };
        return Ok(single_phase(pkg, t, p, &z, PhaseState::Vapour, base_it + it));
    }
    let (hl, hv) = (dl + h, dv + h);
    if td - tb <= 1e-12 * tb {
        // Pure component or azeotrope: one saturation temperature, lever rule on the enthalpy.
        let y = bub.incipient;
        let hv = pkg.h_vap(tb, &y);
        let beta = ((h - hl) / (hv - hl)).clamp(0.0, 1.0);
        return Ok(FlashResult {
            t: tb,
            p,
            beta,
            x: z.clone(),
            y,
            h,
            phase: PhaseState::TwoPhase,
            iterations: base_it,
        });
    }
    let scale = (hv - hl).abs().max(R_GAS * td).max(h.abs());
    let f = |t: f64| flash_tp(pkg, t, p, &z).map(|r| r.h - h);
    let (t, _, it) = brent(f, tb, td, hl - h, hv - h, 1e-15 * scale)
        .map_err(|(it, e)| e.unwrap_or_else(|| no_conv(base_it + it, f64::NAN)))?;
    let mut r = flash_tp(pkg, t, p, &z)?;
    r.iterations = base_it + it;
    Ok(r)
}
