//! Relay-feedback (autotune variation, ATV) test on a linear SISO element.
//!
//! Åström & Hägglund (1984), "Automatic tuning of simple regulators with specifications on phase
//! and amplitude margins", Automatica 20, 645; Luyben (1987), Ind. Eng. Chem. Res. 26, 2490.
//! An ideal relay of amplitude `h` (with optional hysteresis `ε`) closes the loop,
//! `u = −sgn(K) h` once `y > ε` and `+sgn(K) h` once `y < −ε`. The loop settles into a limit cycle
//! of amplitude `a` and period `P`; the describing function of the relay, `N(a) = 4h/(πa)`, gives
//! the estimates `K_u ≈ sgn(K) 4h/(πa)` and `P_u ≈ P`.
//! The describing function assumes a sinusoidal output; its error grows as the output departs from
//! a sine (for `K e^{−θs}/(τs+1)` the exact cycle is `a = |K| h (1 − e^{−θ/τ})`,
//! `P = 2θ + 2τ ln(2 − e^{−θ/τ})`, which puts `K_u` about 11 % low at θ = τ).
//!
//! The element `K Π(τ_lead s + 1)/Π(τ_lag s + 1) e^{−θs}` is simulated as a chain of first-order
//! sections (a lead paired with a lag is `r + (1 − r)/(τ_lag s + 1)`, `r = τ_lead/τ_lag`), RK4 on
//! a fixed step, split at the instants where the delayed relay output switches (the input is
//! constant on every sub-step); relay switching instants are located by bisection on re-integrated
//! sub-steps to 1e-12 of the step.

use plantwide_analysis::tf::Element;
use serde::Serialize;

use crate::TuneError;

/// Settings of a relay test.
#[derive(Debug, Clone, PartialEq)]
pub struct RelaySettings {
    /// Relay amplitude `h` in input units (default: 1; the element is linear, so K_u does not
    /// depend on it).
    pub amplitude: f64,
    /// Hysteresis `ε` in output units (default: 0, an ideal relay).
    pub hysteresis: f64,
    /// Cycles measured after the transient (default: 4).
    pub n_cycles: usize,
    /// Steps per fastest time constant of the element (default: 400).
    pub steps_per_time_constant: usize,
    /// Largest number of relay switches before giving up (default: 200).
    pub max_switches: usize,
}

impl Default for RelaySettings {
    fn default() -> Self {
        RelaySettings { amplitude: 1.0, hysteresis: 0.0, n_cycles: 4, steps_per_time_constant: 400, max_switches: 200 }
    }
}

/// Outcome of a relay test.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RelayReport {
    /// Describing-function ultimate gain `sgn(K) 4h/(πa)`.
    pub ku: f64,
    /// Period of the cycle \[s\].
    pub pu: f64,
    /// Amplitude `a` of the output cycle (half of peak to peak).
    pub amplitude: f64,
    /// Cycles measured.
    pub n_cycles: usize,
    /// Largest relative deviation of a measured period from their mean.
    pub period_spread: f64,
}

/// The element as a chain of sections `(τ_lag, r)`: `w = r v + (1 − r) x`, `τ_lag ẋ = v − x`.
fn sections(e: &Element) -> Result<Vec<(f64, f64)>, TuneError> {
    if e.leads.len() > e.lags.len() {
        return Err(TuneError::ImproperElement { leads: e.leads.len(), lags: e.lags.len() });
    }
    Ok(e.lags.iter().enumerate().map(|(k, &t)| (t, e.leads.get(k).map_or(0.0, |l| l / t))).collect())
}

/// `ẋ` of the chain for input `v`; the output is `K` times the last section's output.
fn chain_rate(sec: &[(f64, f64)], x: &[f64], v: f64, dx: &mut [f64]) {
    let mut w = v;
    for (k, &(tau, r)) in sec.iter().enumerate() {
        dx[k] = (w - x[k]) / tau;
        w = r * w + (1.0 - r) * x[k];
    }
}

fn chain_output(sec: &[(f64, f64)], x: &[f64], v: f64, gain: f64) -> f64 {
    gain * sec.iter().zip(x).fold(v, |w, (&(_, r), &xk)| r * w + (1.0 - r) * xk)
}

/// One RK4 step of length `h` with constant input `v`.
fn rk4(sec: &[(f64, f64)], x: &[f64], v: f64, h: f64) -> Vec<f64> {
    let n = x.len();
    let (mut k1, mut k2, mut k3, mut k4) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let shift = |k: &[f64], c: f64| -> Vec<f64> { x.iter().zip(k).map(|(a, b)| a + c * b).collect() };
    chain_rate(sec, x, v, &mut k1);
    chain_rate(sec, &shift(&k1, 0.5 * h), v, &mut k2);
    chain_rate(sec, &shift(&k2, 0.5 * h), v, &mut k3);
    chain_rate(sec, &shift(&k3, h), v, &mut k4);
    (0..n).map(|i| x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])).collect()
}

/// Run the relay test on `e` (times in seconds).
///
/// # Errors
/// [`TuneError::NoCycle`] when the loop does not settle into a cycle (no phase crossover: a lag
/// of order ≤ 2 without dead time chatters at the step size), [`TuneError::ImproperElement`]
/// when the element has more leads than lags.
pub fn relay_test(e: &Element, settings: &RelaySettings) -> Result<RelayReport, TuneError> {
    let no_cycle = |why: String| TuneError::NoCycle { why };
    let sec = sections(e)?;
    let fastest =
        e.lags.iter().map(|t| t.abs()).chain([e.dead_time]).filter(|t| *t > 0.0).fold(f64::INFINITY, f64::min);
    if !fastest.is_finite() || e.gain == 0.0 {
        return Err(no_cycle("the element is a pure gain".into()));
    }
    let dt = fastest / settings.steps_per_time_constant as f64;
    let (h, eps, s) = (settings.amplitude, settings.hysteresis, e.gain.signum());
    // Relay output history: (switch time, new value); the process sees it θ later.
    let mut relay: Vec<(f64, f64)> = vec![(0.0, s * h)];
    let delayed = |relay: &[(f64, f64)], t: f64| {
        relay.iter().rev().find(|(ts, _)| ts + e.dead_time <= t + 1e-15 * t.abs()).map_or(0.0, |(_, v)| *v)
    };
    let (mut t, mut x) = (0.0, vec![0.0; sec.len()]);
    let mut peaks: Vec<(f64, f64)> = Vec::new(); // (max y, min y) over each half cycle
    let (mut y_max, mut y_min) = (f64::MIN, f64::MAX);
    while relay.len() < settings.max_switches {
        // Next instant: a step, or earlier the next delayed switch.
        let next_switch = relay.iter().map(|(ts, _)| ts + e.dead_time).find(|&ts| ts > t + 1e-12 * dt);
        let t_next = next_switch.map_or(t + dt, |ts| ts.min(t + dt));
        let v = delayed(&relay, t + 0.5 * (t_next - t));
        let x_next = rk4(&sec, &x, v, t_next - t);
        let y_next = chain_output(&sec, &x_next, v, e.gain);
        let u_now = relay.last().unwrap().1;
        // The loop starts on the switching surface (y = 0): the first switch waits for the output
        // to leave it by 1 % of |K| h, so that it is a genuine crossing.
        let eps = if relay.len() == 1 { eps.max(1e-2 * e.gain.abs() * h) } else { eps };
        let trips = if u_now * s > 0.0 { y_next > eps } else { y_next < -eps };
        if !trips {
            (t, x) = (t_next, x_next);
            (y_max, y_min) = (y_max.max(y_next), y_min.min(y_next));
            continue;
        }
        // Locate the crossing of ±ε within the sub-step by bisection on its length.
        let level = if u_now * s > 0.0 { eps } else { -eps };
        let (mut lo, mut hi) = (0.0, t_next - t);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            let ym = chain_output(&sec, &rk4(&sec, &x, v, mid), v, e.gain);
            if (ym - level) * (y_next - level) > 0.0 { hi = mid } else { lo = mid }
        }
        (t, x) = (t + hi, rk4(&sec, &x, v, hi));
        if relay.len() > 1 && t - relay.last().unwrap().0 < 4.0 * dt {
            return Err(no_cycle(format!(
                "the relay chatters (switches {:.3e} s apart, the step is {dt:.3e} s): the element's phase never \
                 reaches −180°; add its dead time or lags, or hysteresis",
                t - relay.last().unwrap().0
            )));
        }
        relay.push((t, -u_now));
        peaks.push((y_max, y_min));
        (y_max, y_min) = (f64::MIN, f64::MAX);
        if let Some(r) = measure(&relay, &peaks, settings, s) {
            return Ok(r);
        }
    }
    Err(no_cycle(format!("no steady cycle after {} relay switches", settings.max_switches)))
}

/// The cycle once the last `n_cycles` periods agree to 1e-6; `None` before.
fn measure(relay: &[(f64, f64)], peaks: &[(f64, f64)], settings: &RelaySettings, s: f64) -> Option<RelayReport> {
    let n = settings.n_cycles;
    // Skip the first switches (the start-up transient); a cycle is two switches.
    if relay.len() < 2 * n + 5 {
        return None;
    }
    let times: Vec<f64> = relay[relay.len() - 2 * n - 1..].iter().map(|(t, _)| *t).collect();
    let periods: Vec<f64> = (0..n).map(|k| times[2 * k + 2] - times[2 * k]).collect();
    let mean = periods.iter().sum::<f64>() / n as f64;
    let spread = periods.iter().map(|p| (p - mean).abs() / mean).fold(0.0, f64::max);
    if spread > 1e-6 {
        return None;
    }
    let last = &peaks[peaks.len() - 2 * n..];
    let y_max = last.iter().map(|p| p.0).fold(f64::MIN, f64::max);
    let y_min = last.iter().map(|p| p.1).fold(f64::MAX, f64::min);
    let a = 0.5 * (y_max - y_min);
    Some(RelayReport {
        ku: s * 4.0 * settings.amplitude / (std::f64::consts::PI * a),
        pu: mean,
        amplitude: a,
        n_cycles: n,
        period_spread: spread,
    })
}
