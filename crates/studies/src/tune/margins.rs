//! Gain and phase margins of a tuned loop, `L(jω) = g(jω) c(jω)` with the ideal PID
//! `c(jω) = K_c (1 + 1/(jω τ_I) + jω τ_D)` (Seborg, Edgar & Mellichamp, *Process Dynamics and
//! Control*, ch. 14; the quantities python-control's `stability_margins` returns).
//!
//! - Gain crossover ω_c: the lowest frequency where `|L|` falls through 1; phase margin
//!   `PM = 180° + ∠L(jω_c)` (the phase unwrapped from the lowest frequency).
//! - Phase crossover ω_180: the lowest frequency where the unwrapped phase crosses `−180°`
//!   (modulo 360°) with `|L| < 1`; gain margin `GM = 1/|L(jω_180)|` (crossings where `|L| > 1`,
//!   an integrating process under PI at low frequency, are not where the loop goes unstable when
//!   its gain grows).
//!
//! `K_c` carries the sign of the process gain (the controller's action), so `L` is a loop of
//! negative feedback with a positive low-frequency gain.

use faer::c64;
use serde::Serialize;

use crate::numeric::root_bracketed;

/// The margins of one loop (`None` where the crossover does not occur in the range searched).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Margins {
    /// Gain margin `1/|L(jω_180)|` (a factor, not dB).
    pub gain_margin: Option<f64>,
    /// Phase crossover ω_180 \[rad per time unit of the tuning\].
    pub phase_crossover: Option<f64>,
    /// Phase margin \[deg\].
    pub phase_margin: Option<f64>,
    /// Gain crossover ω_c \[rad per time unit of the tuning\].
    pub gain_crossover: Option<f64>,
}

impl Margins {
    /// The frequencies in rad per time unit of `seconds` s (from rad/s).
    pub fn in_time_unit(self, seconds: f64) -> Margins {
        Margins {
            phase_crossover: self.phase_crossover.map(|w| w * seconds),
            gain_crossover: self.gain_crossover.map(|w| w * seconds),
            ..self
        }
    }
}

/// The ideal-form PID `K_c (1 + 1/(jω τ_I) + jω τ_D)` (`τ_I = None`: no reset).
pub fn pid(kc: f64, tau_i: Option<f64>, tau_d: Option<f64>, omega: f64) -> c64 {
    let s = c64::new(0.0, omega);
    let reset = tau_i.map_or(c64::new(0.0, 0.0), |t| (s * t).inv());
    (c64::new(1.0, 0.0) + reset + s * tau_d.unwrap_or(0.0)) * kc
}

/// Largest phase change between two frequencies of the march (keeps the unwrapping exact).
const MAX_PHASE_STEP: f64 = std::f64::consts::PI / 16.0;

/// The margins of the loop `l` searched between `omega_lo` and `omega_hi` \[rad/s\]: a march up a
/// log-spaced grid (ratio ≤ 1.1, shrunk so that no step turns the phase by more than π/16, so a
/// dead time cannot alias), each crossover bracketed on it and solved to 1e-12 in ω.
pub fn margins(l: impl Fn(f64) -> c64, omega_lo: f64, omega_hi: f64) -> Margins {
    let pi = std::f64::consts::PI;
    let mut m = Margins { gain_margin: None, phase_crossover: None, phase_margin: None, gain_crossover: None };
    let (mut w, mut lw) = (omega_lo, l(omega_lo));
    if !(lw.norm().is_finite() && lw.norm() > 0.0) {
        return m;
    }
    let mut phase = lw.arg();
    let mut ratio: f64 = 1.1;
    while w < omega_hi && (m.gain_crossover.is_none() || m.phase_crossover.is_none()) {
        let w_next = (w * ratio).min(omega_hi);
        let l_next = l(w_next);
        let step = (l_next / lw).arg();
        if !step.is_finite() {
            break;
        }
        if step.abs() > MAX_PHASE_STEP && ratio > 1.0 + 1e-9 {
            ratio = 1.0 + 0.5 * (ratio - 1.0);
            continue;
        }
        let phase_next = phase + step;
        let (w0, l0, p0) = (w, lw, phase);
        let unwrapped = |x: f64| p0 + (l(x) / l0).arg();
        if m.gain_crossover.is_none() && lw.norm() >= 1.0 && l_next.norm() < 1.0 {
            let wc = root_bracketed(|x| l(x).norm().ln(), w0, w_next, 1e-12 * w_next);
            m.gain_crossover = Some(wc);
            m.phase_margin = Some(wrap_degrees(180.0 + unwrapped(wc).to_degrees()));
        }
        // The −180° line (modulo 360°) the phase passes between the two frequencies, if any.
        let line = -pi - 2.0 * pi * ((-pi - phase.min(phase_next)) / (2.0 * pi)).floor();
        if m.phase_crossover.is_none() && (phase - line) * (phase_next - line) <= 0.0 && phase != phase_next {
            let w180 = root_bracketed(|x| unwrapped(x) - line, w0, w_next, 1e-12 * w_next);
            let gain = l(w180).norm();
            if gain < 1.0 {
                m.phase_crossover = Some(w180);
                m.gain_margin = Some(1.0 / gain);
            }
        }
        (w, lw, phase) = (w_next, l_next, phase_next);
        ratio = 1.1;
    }
    m
}

/// An angle in degrees brought into (−180°, 180°].
fn wrap_degrees(a: f64) -> f64 {
    let r = a.rem_euclid(360.0);
    if r > 180.0 { r - 360.0 } else { r }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SIMC on a lag-dominant FOPTD (τ ≤ 8θ): τ_I = τ cancels the lag and the loop is
    /// `e^(−θs)/(2θ s)` whatever k and τ: |L| = 1 at ω = 1/(2θ) with phase −90° − 28.65°, so
    /// PM = 61.35°; the phase reaches −180° at ω = π/(2θ) where |L| = 1/π, so GM = π (Skogestad
    /// 2003, Table 4: GM 3.14, PM 61.4°).
    #[test]
    fn simc_on_a_foptd_has_its_published_margins() {
        let (k, tau, theta) = (2.0, 10.0, 2.0);
        let kc = tau / (k * 2.0 * theta);
        let g = |w: f64| c64::new(0.0, -w * theta).exp() * k / c64::new(1.0, w * tau);
        let m = margins(|w| g(w) * pid(kc, Some(tau), None, w), 1e-4, 1e3);
        let pi = std::f64::consts::PI;
        assert!((m.gain_margin.unwrap() - pi).abs() < 1e-9, "{m:?}");
        assert!((m.phase_crossover.unwrap() - pi / (2.0 * theta)).abs() < 1e-9, "{m:?}");
        assert!((m.gain_crossover.unwrap() - 1.0 / (2.0 * theta)).abs() < 1e-9, "{m:?}");
        assert!((m.phase_margin.unwrap() - (90.0 - 0.5f64.to_degrees())).abs() < 1e-7, "{m:?}");
    }

    /// A P-only level loop `K_c v/s`: crossover at ω = K_c v with 90° of phase margin and no
    /// phase crossover (infinite gain margin).
    #[test]
    fn a_proportional_level_loop_has_ninety_degrees_and_no_phase_crossover() {
        let (kc, v) = (4.0, 0.05);
        let m = margins(|w| pid(kc, None, None, w) * v / c64::new(0.0, w), 1e-5, 1e3);
        assert!((m.gain_crossover.unwrap() - kc * v).abs() < 1e-12 && (m.phase_margin.unwrap() - 90.0).abs() < 1e-9);
        assert_eq!((m.gain_margin, m.phase_crossover), (None, None), "{m:?}");
    }

    /// A negative process gain under a controller gain of its sign is the same loop.
    #[test]
    fn a_reverse_acting_loop_has_the_margins_of_its_mirror() {
        let g = |w: f64| c64::new(0.0, -w).exp() * 3.0 / c64::new(1.0, 5.0 * w);
        let plus = margins(|w| g(w) * pid(0.8, Some(5.0), None, w), 1e-4, 1e3);
        let minus = margins(|w| -g(w) * pid(-0.8, Some(5.0), None, w), 1e-4, 1e3);
        assert_eq!(plus, minus);
        assert!(plus.gain_margin.unwrap() > 1.0 && plus.phase_margin.unwrap() > 0.0, "{plus:?}");
    }
}
