//! Ultimate gain and period of a SISO element from its frequency response.
//!
//! The ultimate frequency ω_u is the first (lowest) phase crossover, where the unwrapped phase of
//! `g(jω)` reaches −π; the ultimate gain is the proportional gain that puts the loop on the edge
//! of stability, `K_u = 1/|g(jω_u)|`, and the ultimate period `P_u = 2π/ω_u`
//! (Ziegler & Nichols 1942; Seborg, Edgar, Mellichamp, *Process Dynamics and Control*, ch. 12).
//! A process with a negative gain is handled as `−g`: its ultimate gain carries the sign of the
//! process gain, as its controller's gain does.

use faer::c64;
use plantwide_analysis::tf::Element;
use serde::Serialize;

use crate::numeric::root_bracketed;

/// Ultimate gain and frequency of a loop.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Ultimate {
    /// Ultimate gain `K_u` (input units per output unit), with the sign of the process gain.
    pub ku: f64,
    /// Ultimate (phase-crossover) frequency ω_u \[rad/s\].
    pub omega_u: f64,
    /// Ultimate period `P_u = 2π/ω_u` \[s\].
    pub pu: f64,
}

/// Largest phase change allowed between two frequencies of the march (keeps the unwrapping exact).
const MAX_PHASE_STEP: f64 = std::f64::consts::PI / 16.0;

/// The first phase crossover of `g` between `omega_lo` and `omega_hi` \[rad/s\], or `None`.
///
/// The phase is unwrapped by marching up a log-spaced grid (ratio ≤ 1.1, shrunk so that no step
/// turns the phase by more than π/16, so dead time cannot alias), starting from `arg(±g(jω_lo))`,
/// the sign chosen so that the low-frequency phase lies in (−π/2, π/2]. The crossover is bracketed
/// on that grid and solved to a relative width of 1e-12 in ω.
pub fn ultimate(g: impl Fn(f64) -> c64, omega_lo: f64, omega_hi: f64) -> Option<Ultimate> {
    let g_lo = g(omega_lo);
    if !(g_lo.norm() > 0.0 && g_lo.norm().is_finite()) {
        return None;
    }
    let sign = if g_lo.re >= 0.0 { 1.0 } else { -1.0 };
    let h = |w: f64| g(w) * sign;
    let pi = std::f64::consts::PI;
    let (mut w, mut hw, mut phase) = (omega_lo, h(omega_lo), h(omega_lo).arg());
    let mut ratio: f64 = 1.1;
    while w < omega_hi {
        let w_next = (w * ratio).min(omega_hi);
        let h_next = h(w_next);
        let step = (h_next / hw).arg();
        if step.abs() > MAX_PHASE_STEP && ratio > 1.0 + 1e-9 {
            ratio = 1.0 + 0.5 * (ratio - 1.0);
            continue;
        }
        let phase_next = phase + step;
        if phase > -pi && phase_next <= -pi {
            let (w0, h0, p0) = (w, hw, phase);
            let wu = root_bracketed(|x| p0 + (h(x) / h0).arg() + pi, w0, w_next, 1e-12);
            let ku = sign / h(wu).norm();
            return Some(Ultimate { ku, omega_u: wu, pu: 2.0 * pi / wu });
        }
        (w, hw, phase) = (w_next, h_next, phase_next);
        ratio = (1.0 + 2.0 * (ratio - 1.0)).min(1.1);
    }
    None
}

/// The frequency range searched for an element's crossover: from 1e-3 over its slowest time
/// constant (lag, lead or dead time) to 1e4 over its fastest \[rad/s\]; `None` for a pure gain.
pub fn element_frequency_range(e: &Element) -> Option<(f64, f64)> {
    let times: Vec<f64> =
        e.lags.iter().chain(&e.leads).map(|t| t.abs()).chain([e.dead_time]).filter(|t| *t > 0.0).collect();
    let slow = times.iter().cloned().fold(0.0, f64::max);
    let fast = times.iter().cloned().fold(f64::INFINITY, f64::min);
    (slow > 0.0).then(|| (1e-3 / slow, 1e4 / fast))
}

/// The ultimate gain and frequency of one transfer-function element, or `None` when its phase
/// never reaches −180° (e.g. a first- or second-order lag without dead time).
///
/// The element's phase and magnitude are known in closed form ([`Element::phase`],
/// [`Element::log_magnitude`]), so no unwrapping is needed and nothing overflows: the first
/// crossover is bracketed on a log grid fine enough that the phase turns by at most π/16 between
/// points, and `K_u = sign(K) / (|K| e^{ln|g/K|})` is formed in logarithms (a gain of 1e308 gives
/// 1e-308, one of 5e-324 an infinite `K_u`, which the caller refuses).
pub fn element_ultimate(e: &Element) -> Option<Ultimate> {
    let (lo, hi) = element_frequency_range(e)?;
    if e.gain == 0.0 || !e.gain.is_finite() {
        return None;
    }
    let pi = std::f64::consts::PI;
    let (mut w, mut phase) = (lo, e.phase(lo));
    let mut ratio: f64 = 1.1;
    while w < hi {
        let w_next = (w * ratio).min(hi);
        let phase_next = e.phase(w_next);
        if (phase_next - phase).abs() > MAX_PHASE_STEP && ratio > 1.0 + 1e-9 {
            ratio = 1.0 + 0.5 * (ratio - 1.0);
            continue;
        }
        if phase > -pi && phase_next <= -pi {
            let wu = root_bracketed(|x| e.phase(x) + pi, w, w_next, 1e-12);
            let ku = e.gain.signum() * (-(e.gain.abs().ln() + e.log_magnitude(wu))).exp();
            return Some(Ultimate { ku, omega_u: wu, pu: 2.0 * pi / wu });
        }
        (w, phase) = (w_next, phase_next);
        ratio = (1.0 + 2.0 * (ratio - 1.0)).min(1.1);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn third_order_lag_crosses_at_sqrt3_over_tau() {
        // g = 1/(τs+1)³: phase −3 atan(τω) = −π at τω = √3, |g| = 1/8 there, so K_u = 8.
        let e = Element { gain: 1.0, lags: vec![2.0; 3], leads: vec![], dead_time: 0.0 };
        let u = element_ultimate(&e).unwrap();
        assert!((u.omega_u - 3f64.sqrt() / 2.0).abs() < 1e-12, "{u:?}");
        assert!((u.ku - 8.0).abs() < 1e-10, "{u:?}");
        let neg = Element { gain: -0.5, ..e };
        assert!((element_ultimate(&neg).unwrap().ku + 16.0).abs() < 1e-9);
    }

    #[test]
    fn lags_without_dead_time_of_order_below_three_do_not_cross() {
        let first = Element { gain: 3.0, lags: vec![10.0], leads: vec![], dead_time: 0.0 };
        assert_eq!(element_ultimate(&first), None);
        let second = Element { lags: vec![10.0, 4.0], ..first.clone() };
        assert_eq!(element_ultimate(&second), None);
        let gain_only = Element { lags: vec![], ..first };
        assert_eq!(element_ultimate(&gain_only), None);
    }

    #[test]
    fn long_dead_time_is_unwrapped() {
        // Pure dead time θ = 50 s behind a fast lag: ω_u just below π/θ; the march starts at
        // 1e-3/50 rad/s and must not alias.
        let e = Element { gain: 2.0, lags: vec![0.01], leads: vec![], dead_time: 50.0 };
        let u = element_ultimate(&e).unwrap();
        let exact =
            crate::numeric::root_bracketed(|w| -50.0 * w - (0.01 * w).atan() + std::f64::consts::PI, 1e-6, 1.0, 1e-15);
        assert!((u.omega_u - exact).abs() < 1e-12 * exact, "{u:?} vs {exact}");
    }

    /// Ninety equal lags: ω_u τ = tan(π/90), K_u = sec(π/90)⁹⁰ (the phase of each lag is π/90
    /// there); the products `Π(1 + jτω)` overflow near ω_u for τ = 1 h, the closed form does not.
    #[test]
    fn ninety_lags_of_an_hour_cross_where_each_turns_two_degrees() {
        let e = Element { gain: 1.0, lags: vec![3600.0; 90], leads: vec![], dead_time: 0.0 };
        let u = element_ultimate(&e).unwrap();
        let x = (std::f64::consts::PI / 90.0).tan();
        assert!((u.omega_u - x / 3600.0).abs() < 1e-12 * u.omega_u, "{u:?}");
        let ku = (1.0 + x * x).sqrt().powi(90);
        assert!((u.ku - ku).abs() < 1e-10 * ku, "{u:?} vs {ku}");
    }

    /// Ninety lead–lag pairs (2 h over 1 h) behind a minute of dead time: the leads lift the phase
    /// by up to 30 rad, but at high frequency each pair's phase vanishes and the dead time crosses
    /// −π; the crossover solves `90 (atan 2τω − atan τω) − θω = −π`.
    #[test]
    fn lead_lags_of_high_order_with_dead_time_cross_at_the_dead_times_frequency() {
        let e = Element { gain: 1.0, lags: vec![3600.0; 90], leads: vec![7200.0; 90], dead_time: 60.0 };
        let u = element_ultimate(&e).unwrap();
        let phase = |w: f64| 90.0 * ((7200.0 * w).atan() - (3600.0 * w).atan()) - 60.0 * w;
        assert!((phase(u.omega_u) + std::f64::consts::PI).abs() < 1e-9, "{u:?}");
        assert!(u.ku.is_finite() && u.ku > 0.0, "{u:?}");
    }

    /// The gain only scales K_u: 1e308 gives K_u(1)/1e308, not an overflow called "no crossover".
    #[test]
    fn an_extreme_gain_scales_the_ultimate_gain() {
        let one = Element { gain: 1.0, lags: vec![1002.0], leads: vec![], dead_time: 60.0 };
        let big = Element { gain: 1e308, ..one.clone() };
        let (u1, ub) = (element_ultimate(&one).unwrap(), element_ultimate(&big).unwrap());
        assert_eq!(u1.omega_u, ub.omega_u);
        assert!((ub.ku * 1e308 - u1.ku).abs() < 1e-12 * u1.ku, "{ub:?} {u1:?}");
        let tiny = Element { gain: 5e-324, ..one };
        assert!(element_ultimate(&tiny).unwrap().ku.is_infinite());
    }
}
