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

/// One step of the march up the frequency grid: from `ω0` (response `l0`, unwrapped phase `p0`
/// \[rad\]) to `ω1` (`l1`, `p1`).
#[derive(Debug, Clone, Copy)]
struct Step {
    w0: f64,
    l0: c64,
    p0: f64,
    w1: f64,
    l1: c64,
    p1: f64,
}

impl Step {
    /// The phase at `w` in `[ω0, ω1]` unwrapped as the march unwraps it (the step turns it by
    /// less than π/16).
    fn unwrapped(&self, lw: c64) -> f64 {
        self.p0 + (lw / self.l0).arg()
    }
}

/// March `l` up a log-spaced grid from `omega_lo` to `omega_hi` \[rad/s\] (ratio ≤ 1.1, shrunk so
/// that no step turns the phase by more than π/16, so a dead time cannot alias), the phase
/// unwrapped from the lowest frequency, handing each step to `visit` until it returns false. No
/// step is made where `L(omega_lo)` is zero or not finite.
fn march(l: &impl Fn(f64) -> c64, omega_lo: f64, omega_hi: f64, mut visit: impl FnMut(Step) -> bool) {
    let (mut w, mut lw) = (omega_lo, l(omega_lo));
    if !(lw.norm().is_finite() && lw.norm() > 0.0) {
        return;
    }
    let mut phase = lw.arg();
    let mut ratio: f64 = 1.1;
    while w < omega_hi {
        let w_next = (w * ratio).min(omega_hi);
        let l_next = l(w_next);
        let step = (l_next / lw).arg();
        if !step.is_finite() {
            return;
        }
        if step.abs() > MAX_PHASE_STEP && ratio > 1.0 + 1e-9 {
            ratio = 1.0 + 0.5 * (ratio - 1.0);
            continue;
        }
        let s = Step { w0: w, l0: lw, p0: phase, w1: w_next, l1: l_next, p1: phase + step };
        if !visit(s) {
            return;
        }
        (w, lw, phase) = (w_next, l_next, s.p1);
        ratio = 1.1;
    }
}

/// The margins of the loop `l` searched between `omega_lo` and `omega_hi` \[rad/s\]: a march up a
/// log-spaced grid ([`march`]), each crossover bracketed on it and solved to 1e-12 in ω.
pub fn margins(l: impl Fn(f64) -> c64, omega_lo: f64, omega_hi: f64) -> Margins {
    let pi = std::f64::consts::PI;
    let mut m = Margins { gain_margin: None, phase_crossover: None, phase_margin: None, gain_crossover: None };
    march(&l, omega_lo, omega_hi, |s| {
        let unwrapped = |x: f64| s.unwrapped(l(x));
        if m.gain_crossover.is_none() && s.l0.norm() >= 1.0 && s.l1.norm() < 1.0 {
            let wc = root_bracketed(|x| l(x).norm().ln(), s.w0, s.w1, 1e-12 * s.w1);
            m.gain_crossover = Some(wc);
            m.phase_margin = Some(wrap_degrees(180.0 + unwrapped(wc).to_degrees()));
        }
        // The −180° line (modulo 360°) the phase passes between the two frequencies, if any.
        let line = -pi - 2.0 * pi * ((-pi - s.p0.min(s.p1)) / (2.0 * pi)).floor();
        if m.phase_crossover.is_none() && (s.p0 - line) * (s.p1 - line) <= 0.0 && s.p0 != s.p1 {
            let w180 = root_bracketed(|x| unwrapped(x) - line, s.w0, s.w1, 1e-12 * s.w1);
            let gain = l(w180).norm();
            if gain < 1.0 {
                m.phase_crossover = Some(w180);
                m.gain_margin = Some(1.0 / gain);
            }
        }
        m.gain_crossover.is_none() || m.phase_crossover.is_none()
    });
    m
}

/// The Bode diagram of a loop: `L(jω)` on the margins' own march, and the margins marked on it.
#[derive(Debug, Clone, PartialEq)]
pub struct Bode {
    /// Frequencies \[rad per time unit\], increasing; the crossovers are among them.
    pub omega: Vec<f64>,
    /// `20 log10 |L(jω)|` \[dB\].
    pub magnitude_db: Vec<f64>,
    /// `∠L(jω)` \[deg\], unwrapped from the lowest frequency searched as [`margins`] unwraps it.
    pub phase_deg: Vec<f64>,
    /// The loop's margins ([`margins`] over the same range).
    pub margins: Margins,
}

impl Bode {
    /// The frequencies in rad per time unit of `seconds` s (from rad/s).
    pub fn in_time_unit(self, seconds: f64) -> Bode {
        Bode {
            omega: self.omega.iter().map(|w| w * seconds).collect(),
            margins: self.margins.in_time_unit(seconds),
            ..self
        }
    }
}

/// The Bode diagram of the loop `l` whose margins are searched between `omega_lo` and `omega_hi`
/// \[rad/s\]: the points of the same march ([`march`]) from two decades below the lowest crossover
/// to one above the highest (the whole range when there is none), with the crossovers of
/// [`margins`] inserted, so the curves pass through 0 dB and −180° exactly where it marks them.
pub fn bode(l: impl Fn(f64) -> c64, omega_lo: f64, omega_hi: f64) -> Bode {
    let m = margins(&l, omega_lo, omega_hi);
    let mut marks: Vec<f64> = [m.gain_crossover, m.phase_crossover].into_iter().flatten().collect();
    marks.sort_by(f64::total_cmp);
    let (from, to) = match (marks.first(), marks.last()) {
        (Some(a), Some(b)) => ((a / 100.0).max(omega_lo), (b * 10.0).min(omega_hi)),
        _ => (omega_lo, omega_hi),
    };
    let mut b = Bode { omega: Vec::new(), magnitude_db: Vec::new(), phase_deg: Vec::new(), margins: m };
    let mut push = |w: f64, lw: c64, phase: f64| {
        b.omega.push(w);
        b.magnitude_db.push(20.0 * lw.norm().log10());
        b.phase_deg.push(phase.to_degrees());
    };
    let mut started = false;
    march(&l, omega_lo, to, |s| {
        if s.w1 < from {
            return true;
        }
        if !started {
            push(s.w0, s.l0, s.p0);
            started = true;
        }
        for w in marks.iter().copied().filter(|w| *w > s.w0 && *w < s.w1) {
            let lw = l(w);
            push(w, lw, s.unwrapped(lw));
        }
        push(s.w1, s.l1, s.p1);
        true
    });
    b
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

    /// The Bode diagram passes through 0 dB at the gain crossover and through −180° at the
    /// phase crossover that [`margins`] finds, and its margins are those figures.
    #[test]
    fn the_bode_diagram_passes_through_the_marked_crossovers() {
        let (k, tau, theta) = (2.0, 10.0, 2.0);
        let kc = tau / (k * 2.0 * theta);
        let l = |w: f64| c64::new(0.0, -w * theta).exp() * k / c64::new(1.0, w * tau) * pid(kc, Some(tau), None, w);
        let b = bode(l, 1e-4, 1e3);
        assert_eq!(b.margins, margins(l, 1e-4, 1e3));
        let at = |w: f64| b.omega.iter().position(|x| *x == w).expect("the crossover is a point of the diagram");
        let (wc, w180) = (b.margins.gain_crossover.unwrap(), b.margins.phase_crossover.unwrap());
        assert!(b.magnitude_db[at(wc)].abs() < 1e-9, "{}", b.magnitude_db[at(wc)]);
        assert!((b.phase_deg[at(w180)] + 180.0).abs() < 1e-7, "{}", b.phase_deg[at(w180)]);
        assert!((b.phase_deg[at(wc)] + 180.0 - b.margins.phase_margin.unwrap()).abs() < 1e-7);
        assert!(
            b.omega.windows(2).all(|w| w[0] < w[1])
                && b.omega[0] <= wc / 99.0
                && *b.omega.last().unwrap() >= 9.9 * w180
        );
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
