//! Closed forms of surge sizing for a step disturbance.
//!
//! A vessel of cross-section `A` \[m²\] passes a liquid whose inflow steps by `ΔQ` \[m³/s\]; its
//! level controller moves the outflow, and the design asks that the level stay within `±Δh` \[m\]
//! of its setpoint and that the outflow never change faster than `r_Q` \[m³/s²\]. In deviation
//! variables `A dh/dt = Q_in − Q_out`. For each controller the largest level deviation and the
//! largest rate of the outflow are (derived here, the linear results also in
//! `crate::tune::averaging`):
//! - **P only**, `Q_out = K_c h`, `|K_c| = ΔQ/Δh`: the outflow is the inflow through the filter
//!   `1/(τ_F s + 1)`, `τ_F = A/K_c = A Δh/ΔQ`; the level creeps to `Δh`, the rate is largest at the
//!   step, `ΔQ/τ_F = ΔQ²/(A Δh)`. So `A = ΔQ²/(r_Q Δh)`.
//! - **PI, critically damped**, `ω_n = ΔQ/(e A Δh)`: `Q_out/Q_in = (2ω_n s + ω_n²)/(s + ω_n)²`, a
//!   step response `ΔQ (1 − e^(−ω_n t) + ω_n t e^(−ω_n t))` whose slope `ΔQ ω_n e^(−ω_n t)(2 − ω_n t)`
//!   is largest at `t = 0`, `2 ω_n ΔQ = 2ΔQ²/(e A Δh)`; the level peaks at `Δh` at `t = 1/ω_n`.
//!   So `A = 2ΔQ²/(e r_Q Δh)`.
//! - **Optimal** (McDonald, McAvoy & Tits 1986, *AIChE J.* 32, 75): the outflow ramps at the
//!   constant rate `r_Q` until it meets the inflow at `t* = ΔQ/r_Q`, by which time the level has
//!   risen `∫₀^t* (ΔQ − r_Q t) dt / A = ΔQ²/(2 r_Q A)`; that is the least band any controller can
//!   keep for a rate `r_Q` (a slower start can only be made up by a faster rate later). So
//!   `A = ΔQ²/(2 r_Q Δh)`.
//!
//! All three are `A = c ΔQ²/(r_Q Δh)`: `c` = 1 (P), `2/e` ≈ 0.736 (PI), 1/2 (optimal); the band
//! volume `A Δh = c ΔQ²/r_Q` does not depend on the band. With molar flows `Δu` \[mol/s\] and
//! `r` \[mol/s²\] and the liquid's molar volume `v_L` \[m³/mol\]: `ΔQ = v_L Δu`, `r_Q = v_L r`.

use serde::Serialize;

/// One of the three level controllers the sizing designs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LevelDesign {
    /// Proportional only.
    P,
    /// Critically damped PI.
    Pi,
    /// McDonald, McAvoy & Tits' optimal averaging (a constant-rate ramp).
    Optimal,
}

impl LevelDesign {
    /// The three, in the order reported.
    pub const ALL: [LevelDesign; 3] = [LevelDesign::P, LevelDesign::Pi, LevelDesign::Optimal];

    /// `c` of `A = c ΔQ²/(r_Q Δh)`.
    pub fn coefficient(self) -> f64 {
        match self {
            LevelDesign::P => 1.0,
            LevelDesign::Pi => 2.0 / std::f64::consts::E,
            LevelDesign::Optimal => 0.5,
        }
    }

    /// The cross-section \[m²\] for a step `dq` \[m³/s\], a rate limit `rq` \[m³/s²\] and a band
    /// `band` \[m\].
    pub fn area(self, dq: f64, rq: f64, band: f64) -> f64 {
        self.coefficient() * dq * dq / (rq * band)
    }

    /// The largest rate of the outflow \[m³/s²\] after a step `dq` in a vessel of cross-section
    /// `area` designed for the band `band` (the inverse of [`LevelDesign::area`]).
    pub fn rate(self, dq: f64, area: f64, band: f64) -> f64 {
        self.coefficient() * dq * dq / (area * band)
    }

    /// The attenuation closed forms, for a sinusoidal inflow of amplitude `dq` \[m³/s\] at `omega`
    /// \[rad/s\] whose outflow may swing at most `a·dq` (`0 < a < 1`) with the level within `band`
    /// \[m\], in the periodic steady state: `(area, T)`, `T` the filter time `τ_F` (P) or `1/ω_n`
    /// (PI); `None` for the optimal law, which is no linear filter.
    /// - P: `|1/(1 + jωτ)| = a` gives `ωτ = √(1/a² − 1)`; the level `q/(A s + K_c)`, `K_c = A/τ`,
    ///   swings `dq/(A √(ω² + 1/τ²))`, so `A = dq √(1 − a²)/(ω Δh)`.
    /// - PI: `|T(jω)|² = (u⁴ + 4u²)/(u² + 1)²`, `u = ω_n/ω`, rises from 0 to 1.25 at `u = 1`: for
    ///   `a < 1` the root of `(1 − a²) w² + (4 − 2a²) w − a² = 0`, `w = u²`; the level
    ///   `s q/(A (s + ω_n)²)` swings `ω dq/(A (ω² + ω_n²))`, so `A = ω dq/(Δh (ω² + ω_n²))`.
    pub fn for_attenuation(self, dq: f64, a: f64, omega: f64, band: f64) -> Option<(f64, f64)> {
        match self {
            LevelDesign::P => {
                let tau = (1.0 / (a * a) - 1.0).sqrt() / omega;
                Some((dq * (1.0 - a * a).sqrt() / (omega * band), tau))
            }
            LevelDesign::Pi => {
                let (q2, q1, q0) = (1.0 - a * a, 4.0 - 2.0 * a * a, -a * a);
                let w = (-q1 + (q1 * q1 - 4.0 * q2 * q0).sqrt()) / (2.0 * q2);
                let wn = omega * w.sqrt();
                Some((omega * dq / (band * (omega * omega + wn * wn)), 1.0 / wn))
            }
            LevelDesign::Optimal => None,
        }
    }

    /// Name in reports and JSON.
    pub fn name(self) -> &'static str {
        match self {
            LevelDesign::P => "p",
            LevelDesign::Pi => "pi",
            LevelDesign::Optimal => "optimal",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tune::averaging::{AveragingForm, averaging};

    /// `A dh/dt = dq − q_out` with the linear controller `q_out = K_c (h + I/τ_I)`, `dI/dt = h`,
    /// from rest, by RK4 with step `dt`: (largest |h|, largest |dq_out/dt|).
    fn linear(area: f64, kc: f64, ti: f64, dq: f64, dt: f64, t_end: f64) -> (f64, f64) {
        let f = |x: [f64; 2]| [(dq - kc * (x[0] + x[1] / ti)) / area, x[0]];
        let (mut x, mut peak, mut rate) = ([0.0f64; 2], 0.0f64, 0.0f64);
        let mut q = 0.0;
        for _ in 0..(t_end / dt).round() as usize {
            x = crate::numeric::rk4(f, x, dt);
            let q_new = kc * (x[0] + x[1] / ti);
            rate = rate.max((q_new - q).abs() / dt);
            q = q_new;
            peak = peak.max(x[0].abs());
        }
        (peak, rate)
    }

    #[test]
    fn linear_designs_meet_band_and_rate_exactly() {
        let (dq, rq, band) = (0.01, 2e-5, 0.3);
        for (design, form) in [(LevelDesign::P, AveragingForm::P), (LevelDesign::Pi, AveragingForm::Pi)] {
            let area = design.area(dq, rq, band);
            // The controller of `tune::averaging` for this vessel: k = 1/A per m³/s of outflow.
            let s = averaging(1.0 / area, dq, band, form).unwrap();
            let ti = s.tau_i.unwrap_or(f64::INFINITY);
            let t = s.time;
            let (peak, rate) = linear(area, s.kc, ti, dq, t * 1e-4, 30.0 * t);
            assert!((peak / band - 1.0).abs() < 1e-6, "{design:?}: {peak}");
            // The rate is largest in the first step, where the RK4 difference quotient is short of
            // the slope at t = 0 by ~dt/(2 τ): 5e-5 of it.
            assert!(rate <= rq * (1.0 + 1e-9) && rate > rq * (1.0 - 1e-4), "{design:?}: {rate} vs {rq}");
            assert!((design.rate(dq, area, band) / rq - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn attenuation_designs_give_the_asked_amplitude_ratio_and_level_swing() {
        let (dq, a, omega, band) = (0.01, 0.3, 2.0 * std::f64::consts::PI / 3600.0, 0.3);
        // P: the filter 1/(1 + jωτ); the level q/(A jω + K_c).
        let (area, tau) = LevelDesign::P.for_attenuation(dq, a, omega, band).unwrap();
        let g = 1.0 / (1.0 + (omega * tau).powi(2)).sqrt();
        let kc = area / tau;
        let level = dq / ((area * omega).powi(2) + kc * kc).sqrt();
        assert!((g - a).abs() < 1e-12 && (level / band - 1.0).abs() < 1e-12, "{g} {level}");
        // PI: T = (2ω_n s + ω_n²)/(s + ω_n)², the level s q/(A (s + ω_n)²), by complex arithmetic.
        let (area, t) = LevelDesign::Pi.for_attenuation(dq, a, omega, band).unwrap();
        let wn = 1.0 / t;
        let (re, im) = (wn * wn - omega * omega, 2.0 * wn * omega); // (jω + ω_n)²
        let den = (re * re + im * im).sqrt();
        let t_mag = (wn.powi(4) + 4.0 * wn * wn * omega * omega).sqrt() / den;
        let level = omega * dq / (area * den);
        assert!((t_mag - a).abs() < 1e-12 && (level / band - 1.0).abs() < 1e-12, "{t_mag} {level}");
        assert!(LevelDesign::Optimal.for_attenuation(dq, a, omega, band).is_none());
    }

    #[test]
    fn the_optimal_ramp_meets_both_at_half_the_p_area() {
        let (dq, rq, band) = (0.01, 2e-5, 0.3);
        let area = LevelDesign::Optimal.area(dq, rq, band);
        // The ramp q_out = r t to t* = dq/r: the level rises ∫(dq − r t)/A dt.
        let t_star = dq / rq;
        let n = 100_000;
        let dt = t_star / n as f64;
        let rise: f64 = (0..n).map(|i| (dq - rq * (i as f64 + 0.5) * dt) / area * dt).sum();
        assert!((rise / band - 1.0).abs() < 1e-9, "{rise}");
        assert!((LevelDesign::P.area(dq, rq, band) / area - 2.0).abs() < 1e-12);
        assert!((LevelDesign::Pi.area(dq, rq, band) / area - 4.0 / std::f64::consts::E).abs() < 1e-12);
    }
}
