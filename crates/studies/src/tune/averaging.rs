//! Averaging level control: a level loop tuned to use the vessel as surge capacity, so that the
//! manipulated flow changes as slowly as the allowed level band permits (Buckley's averaging level
//! control, *Practical Distillation Control* ch. 2; the plantwide surge rule R4.1 of ch. 1).
//!
//! The level integrates the flow imbalance: `dh/dt = k (u − u₀) + d`, with `k` the integrating
//! gain of the level per unit of the manipulated input [level unit/(input unit · s)], and a step
//! disturbance `d = −k Δu` that the input must eventually move by `Δu` to balance. With the
//! controller `u − u₀ = K_c (e + (1/τ_I) ∫e dt)`, `e = sp − h` (`K_c` of the sign of `k`), and the
//! allowed level deviation `Δh` (derived here from the linear closed loop):
//! - **P only**: `h − sp → −Δu/K_c` with time constant `τ_F = 1/(k K_c)`; the deviation reaches
//!   `Δh` exactly when `|K_c| = Δu/Δh`, so `τ_F = Δh/(|k| Δu)` is the slowest filter the band
//!   allows (the flow passed downstream is the disturbance filtered by `1/(τ_F s + 1)`).
//! - **PI, critically damped**: `s² + k K_c s + k K_c/τ_I = 0` with `ζ = 1` has the double pole
//!   `−ω_n`; the level deviation is `(Δu |k|) t e^(−ω_n t)`, largest at `t = 1/ω_n` where it is
//!   `|k| Δu/(e ω_n)`. Setting it to `Δh`: `ω_n = |k| Δu/(e Δh)`, `|K_c| = 2 Δu/(e Δh)`,
//!   `τ_I = 2/ω_n = 2 e Δh/(|k| Δu)`; the level returns to its setpoint.

use serde::{Deserialize, Serialize};

/// P-only or critically damped PI.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AveragingForm {
    /// Proportional only: the level settles off its setpoint, the flow is filtered to first order.
    P,
    /// Proportional-integral with ζ = 1: the level returns to its setpoint.
    Pi,
}

/// Averaging-level settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AveragingSettings {
    /// Form.
    pub form: AveragingForm,
    /// Controller gain (input units per level unit; the sign of `k`).
    pub kc: f64,
    /// Reset time \[s\] (PI only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tau_i: Option<f64>,
    /// P: the first-order filter time of the flow `τ_F`; PI: the time of the largest level
    /// deviation `1/ω_n` \[s\].
    pub time: f64,
    /// The largest level deviation after the design disturbance (= the band asked for).
    pub band: f64,
    /// The default band (a quarter of the holdup) this one replaced, where other loops move the
    /// level at the default's time scale ([`crate::tune::flowsheet::averaging_loop`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub band_narrowed_from: Option<f64>,
}

/// Why averaging settings cannot be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AveragingError {
    /// A quantity is zero, negative or not finite.
    #[error("averaging level: {what} = {} must be {fix}", plantwide_model::limits::number(*.value))]
    Bad {
        /// The quantity.
        what: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        fix: &'static str,
    },
}

/// Averaging settings for a level with integrating gain `k`, a disturbance that the input must
/// move by `du` to balance, and an allowed level deviation `band`.
///
/// # Errors
/// [`AveragingError::Bad`] for a zero or non-finite gain, or a non-positive `du` or `band`.
pub fn averaging(k: f64, du: f64, band: f64, form: AveragingForm) -> Result<AveragingSettings, AveragingError> {
    if !(k.is_finite() && k != 0.0) {
        return Err(AveragingError::Bad { what: "the level's integrating gain", value: k, fix: "nonzero and finite" });
    }
    check_swing(du, band)?;
    let sign = k.signum();
    Ok(match form {
        AveragingForm::P => AveragingSettings {
            form,
            kc: sign * du / band,
            tau_i: None,
            time: band / (k.abs() * du),
            band,
            band_narrowed_from: None,
        },
        AveragingForm::Pi => {
            let e = std::f64::consts::E;
            let wn = k.abs() * du / (e * band);
            AveragingSettings {
                form,
                kc: sign * 2.0 * du / (e * band),
                tau_i: Some(2.0 / wn),
                time: 1.0 / wn,
                band,
                band_narrowed_from: None,
            }
        }
    })
}

/// Checks a design swing: the input change `du` and the level band `band` positive and finite.
///
/// # Errors
/// [`AveragingError::Bad`] naming the quantity that is not.
pub fn check_swing(du: f64, band: f64) -> Result<(), AveragingError> {
    if !(du.is_finite() && du > 0.0) {
        return Err(AveragingError::Bad { what: "the input change", value: du, fix: "positive" });
    }
    if !(band.is_finite() && band > 0.0) {
        return Err(AveragingError::Bad { what: "the level band", value: band, fix: "positive" });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed loop `dh/dt = k (u − u₀) − k Δu`, `u − u₀ = K_c (−h + I/τ_I)`, `dI/dt = −h`
    /// (deviation variables, setpoint 0) integrated by classical RK4 with step `dt` to `t_end`:
    /// returns (largest |h|, time of it, final h, final u − u₀).
    fn simulate(k: f64, du: f64, s: &AveragingSettings, dt: f64, t_end: f64) -> (f64, f64, f64, f64) {
        let ti = s.tau_i.unwrap_or(f64::INFINITY);
        let u = |x: [f64; 2]| s.kc * (-x[0] + x[1] / ti);
        let f = |x: [f64; 2]| [k * u(x) - k * du, -x[0]];
        let (mut x, mut peak, mut t_peak) = ([0.0, 0.0], 0.0f64, 0.0);
        let steps = (t_end / dt).round() as usize;
        for step in 1..=steps {
            x = crate::numeric::rk4(f, x, dt);
            if x[0].abs() > peak {
                (peak, t_peak) = (x[0].abs(), step as f64 * dt);
            }
        }
        (peak, t_peak, x[0], u(x))
    }

    #[test]
    fn p_only_settles_at_the_band_edge_with_the_filter_time() {
        // An outflow valve: opening it lowers the level (k < 0).
        let (k, du, band) = (-0.02, 0.1, 0.5);
        let s = averaging(k, du, band, AveragingForm::P).unwrap();
        assert!(s.kc < 0.0 && (s.time - 250.0).abs() < 1e-12, "{s:?}");
        let (peak, _, h, u) = simulate(k, du, &s, 0.5, 20.0 * s.time);
        assert!((peak - band).abs() < 1e-6 * band && (h.abs() - band).abs() < 1e-6 * band, "{peak} {h}");
        assert!((u - du).abs() < 1e-6 * du, "{u}");
        // At one filter time the deviation is 1 − 1/e of its final value.
        let (_, _, h1, _) = simulate(k, du, &s, 0.01, s.time);
        assert!((h1.abs() / band - (1.0 - (-1.0f64).exp())).abs() < 1e-6, "{h1}");
    }

    #[test]
    fn critically_damped_pi_peaks_at_the_band_and_returns() {
        let (k, du, band) = (0.004, 2.0, 0.3);
        let s = averaging(k, du, band, AveragingForm::Pi).unwrap();
        let (peak, t_peak, h, u) = simulate(k, du, &s, 0.05, 30.0 * s.time);
        assert!((peak - band).abs() < 1e-6 * band, "{peak} vs {band}");
        assert!((t_peak - s.time).abs() < 0.1, "{t_peak} vs {}", s.time);
        assert!(h.abs() < 1e-6 * band && (u - du).abs() < 1e-6 * du, "{h} {u}");
    }

    #[test]
    fn bad_specifications_are_refused() {
        assert!(averaging(0.0, 1.0, 1.0, AveragingForm::P).is_err());
        assert!(averaging(1.0, -1.0, 1.0, AveragingForm::P).is_err());
        assert!(averaging(1.0, 1.0, f64::NAN, AveragingForm::Pi).is_err());
    }
}
