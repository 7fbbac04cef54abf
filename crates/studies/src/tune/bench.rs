//! Plant tests run the way they are run on a plant: a loop in manual, its output moved by a test
//! signal (a relay, a step) at a fixed scan interval, its measurement sampled — on any
//! [`Bench`]: the nonlinear dynamic model of a flowsheet, or a closed-form element in tests.
//!
//! **Sampled relay** (the relay of *Practical Distillation Control* ch. 7, Fig. 7-2; Åström &
//! Hägglund 1984): every scan `Δ` the relay compares the measurement `y` with its steady value `y₀`
//! and sets `u = u₀ + s h` when `y − y₀ < −ε`, `u = u₀ − s h` when `y − y₀ > ε` (`s` the sign of
//! the process gain, `ε` the hysteresis), holding `u` between scans. After the start-up switches
//! the last `n` cycles must agree (period and amplitude spread below `tolerance`); then
//! `K_u = s 4h/(π a)` with `a` half the peak-to-peak of `y`, and `P_u` the mean period. The scan
//! adds a delay of about `Δ/2` to the loop, so `P_u` is good to `O(Δ/P_u)`.
//!
//! **Step test**: `u = u₀ + Δu` from `t = 0`; `y − y₀` sampled every `Δ` until it has settled
//! (over the last third of the record it moved less than `settle` of its total change) or the
//! duration limit — which is all an integrating response (a level) ever reaches.

use serde::Serialize;

/// A plant under test.
pub trait Bench {
    /// Why the plant could not be advanced.
    type Error: std::error::Error;
    /// The current time \[s\].
    fn time(&self) -> f64;
    /// The current measurement.
    fn measurement(&self) -> f64;
    /// Hold the loop's output at `u` from now on.
    fn set_output(&mut self, u: f64);
    /// Integrate to time `t` \[s\].
    fn advance_to(&mut self, t: f64) -> Result<(), Self::Error>;
}

/// Settings of a sampled relay test.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledRelay {
    /// Relay amplitude `h` (output units).
    pub amplitude: f64,
    /// Hysteresis `ε` (measurement units).
    pub hysteresis: f64,
    /// Scan interval `Δ` \[s\].
    pub scan: f64,
    /// Sign of the process gain (+1 or −1).
    pub sign: f64,
    /// Cycles that must agree (default 3).
    pub n_cycles: usize,
    /// Largest relative spread of their periods and amplitudes (default 1 %).
    pub tolerance: f64,
    /// Relay switches before giving up (default 60).
    pub max_switches: usize,
    /// Scans without a switch before giving up (a measurement that does not come back).
    pub max_quiet_scans: usize,
}

/// A sustained relay cycle.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RelayCycle {
    /// Describing-function ultimate gain `s 4h/(π a)` (output units per measurement unit).
    pub ku: f64,
    /// Ultimate period: the mean period of the measured cycles \[s\].
    pub pu: f64,
    /// Amplitude `a` of the measurement's cycle.
    pub amplitude: f64,
    /// Cycles measured.
    pub cycles: usize,
    /// Largest relative deviation of a measured period from their mean.
    pub period_spread: f64,
    /// Largest relative deviation of a measured amplitude from their mean.
    pub amplitude_spread: f64,
    /// Time above the steady value over the period, in (0, 1): 0.5 for a symmetric cycle; far from
    /// it, the plant is nonlinear over the relay's amplitude (reduce it) or not at steady state.
    pub duty: f64,
    /// Relay switches taken.
    pub switches: usize,
    /// The relay's amplitude `h` (output units).
    pub relay_amplitude: f64,
    /// The flow whose room shrank the default amplitude, if one did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limited_by: Option<String>,
}

/// Why a relay test found no usable cycle.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RelayError<E: std::error::Error> {
    /// The plant could not be integrated.
    #[error(transparent)]
    Bench(E),
    /// The relay switches at nearly every scan: the loop has no phase crossover of its own.
    #[error(
        "the relay switches every {scans} scans ({period:.4e} s cycle at a {scan:.4e} s scan): the loop's phase never \
         reaches −180° of its own (too little dead time or lag); give the measurement's dead time, or tune it another way"
    )]
    Chatter {
        /// Mean scans per half cycle.
        scans: f64,
        /// The cycle's period \[s\].
        period: f64,
        /// The scan \[s\].
        scan: f64,
    },
    /// The measurement stopped crossing its steady value: no switch for many scans.
    #[error(
        "no relay switch for {scans} scans (to t = {t:.4e} s): the measurement does not come back across its \
         steady value — the loop integrates, saturates at the relay's amplitude, or its scan is far too long; \
         try a smaller amplitude or give `scan`"
    )]
    NoSwitch {
        /// Scans since the last switch.
        scans: usize,
        /// Time reached \[s\].
        t: f64,
    },
    /// The cycles did not settle.
    #[error(
        "no sustained cycle after {switches} relay switches (spread of the last periods {spread:.2} %, of \
         their amplitudes {amplitude_spread:.2} %): the loop may be integrating, or saturating at the relay \
         amplitude; try a smaller amplitude or more switches"
    )]
    NotSustained {
        /// Switches taken.
        switches: usize,
        /// Spread of the last periods \[%\].
        spread: f64,
        /// Spread of the last amplitudes \[%\].
        amplitude_spread: f64,
    },
}

/// Run a sampled relay test on `bench` from its steady state (`u0`, and the measurement now as `y₀`).
///
/// # Errors
/// [`RelayError`]: the bench failed, the relay chatters, or no cycle settles.
pub fn relay<B: Bench>(bench: &mut B, u0: f64, s: &SampledRelay) -> Result<RelayCycle, RelayError<B::Error>> {
    let y0 = bench.measurement();
    let mut high = true; // start by pushing the measurement up
    bench.set_output(u0 + s.sign * s.amplitude);
    let (mut switches, mut extremes): (Vec<f64>, Vec<(f64, f64)>) = (Vec::new(), Vec::new());
    let (mut lo, mut hi, mut above) = (f64::MAX, f64::MIN, 0.0);
    let mut above_per_half: Vec<f64> = Vec::new();
    let mut since_switch = 0;
    while switches.len() < s.max_switches {
        let t = bench.time() + s.scan;
        bench.advance_to(t).map_err(RelayError::Bench)?;
        since_switch += 1;
        if since_switch > s.max_quiet_scans {
            return Err(RelayError::NoSwitch { scans: since_switch - 1, t });
        }
        let e = bench.measurement() - y0;
        (lo, hi) = (lo.min(e), hi.max(e));
        if e > 0.0 {
            above += s.scan;
        }
        let trip = if high { e > s.hysteresis } else { e < -s.hysteresis };
        if !trip {
            continue;
        }
        high = !high;
        since_switch = 0;
        bench.set_output(u0 + if high { s.sign } else { -s.sign } * s.amplitude);
        switches.push(t);
        extremes.push((lo, hi));
        above_per_half.push(above);
        (lo, hi, above) = (f64::MAX, f64::MIN, 0.0);
        if let Some(c) = cycle(&switches, &extremes, &above_per_half, s)? {
            return Ok(c);
        }
    }
    let spread = spread_of(&periods(&switches, s.n_cycles)).0 * 100.0;
    let amplitude_spread = spread_of(&amplitudes(&extremes, s.n_cycles)).0 * 100.0;
    Err(RelayError::NotSustained { switches: switches.len(), spread, amplitude_spread })
}

/// The periods of the last `n` cycles (a cycle is two switches).
fn periods(switches: &[f64], n: usize) -> Vec<f64> {
    if switches.len() < 2 * n + 1 {
        return Vec::new();
    }
    let t = &switches[switches.len() - 2 * n - 1..];
    (0..n).map(|k| t[2 * k + 2] - t[2 * k]).collect()
}

/// The amplitudes of the last `n` cycles: half each cycle's peak-to-peak over its two halves
/// (none before `n` cycles).
fn amplitudes(extremes: &[(f64, f64)], n: usize) -> Vec<f64> {
    if extremes.len() < 2 * n {
        return Vec::new();
    }
    let last = &extremes[extremes.len() - 2 * n..];
    (0..n)
        .map(|k| {
            let (a, b) = (last[2 * k], last[2 * k + 1]);
            0.5 * (a.1.max(b.1) - a.0.min(b.0))
        })
        .collect()
}

/// `(largest relative deviation from the mean, mean)`.
fn spread_of(v: &[f64]) -> (f64, f64) {
    if v.is_empty() {
        return (f64::INFINITY, f64::NAN);
    }
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    (v.iter().map(|p| (p - mean).abs() / mean.abs()).fold(0.0, f64::max), mean)
}

/// The cycle once the last `n` cycles (after at least two start-up switches) agree; `None` before.
fn cycle<E: std::error::Error>(
    switches: &[f64],
    extremes: &[(f64, f64)],
    above: &[f64],
    s: &SampledRelay,
) -> Result<Option<RelayCycle>, RelayError<E>> {
    let n = s.n_cycles;
    if switches.len() < 2 * n + 3 {
        return Ok(None);
    }
    let (p_spread, pu) = spread_of(&periods(switches, n));
    let (a_spread, a) = spread_of(&amplitudes(extremes, n));
    if pu < 8.0 * s.scan {
        return Err(RelayError::Chatter { scans: 0.5 * pu / s.scan, period: pu, scan: s.scan });
    }
    // Switches fall on the scan's grid, so a sustained cycle's periods jitter by a scan each way
    // and its amplitudes with them (its half cycles are a scan longer or shorter): a spread of up
    // to four scans in the period is that quantization, not a cycle still growing (generated
    // plants 0x25299ef6fed046a2, 0x856e864a5c8f51ba: 0.3–1.2 % at P_u/200, never settling in 200
    // switches against 1 %).
    let allowed = s.tolerance.max(4.0 * s.scan / pu);
    if p_spread > allowed || a_spread > allowed {
        return Ok(None);
    }
    let duty = above[above.len() - 2 * n..].iter().sum::<f64>() / (n as f64 * pu);
    Ok(Some(RelayCycle {
        ku: s.sign * 4.0 * s.amplitude / (std::f64::consts::PI * a),
        pu,
        amplitude: a,
        cycles: n,
        period_spread: p_spread,
        amplitude_spread: a_spread,
        duty,
        switches: switches.len(),
        relay_amplitude: s.amplitude,
        limited_by: None,
    }))
}

/// Settings of a step test.
#[derive(Debug, Clone, PartialEq)]
pub struct StepTest {
    /// Output step `Δu` (output units).
    pub step: f64,
    /// Sampling interval `Δ` \[s\].
    pub scan: f64,
    /// Longest test \[s\].
    pub max_duration: f64,
    /// Settled when the last third of the record moved less than this fraction of the total
    /// change (default 0.2 %).
    pub settle: f64,
    /// A finer sampling `(interval, until)` \[s\] for the response's start, before `scan` takes
    /// over: a lag-dominant element's initial response (its effective dead time) at the loop's
    /// own time scale, its slow approach at its own.
    pub fine: Option<(f64, f64)>,
}

impl StepTest {
    /// Samples taken at the finer interval.
    pub fn fine_samples(&self) -> usize {
        self.fine.map_or(0, |(f, until)| (until / f).ceil() as usize)
    }

    /// Time of sample `i` since the step (sample 0 at the step).
    fn sample_time(&self, i: usize) -> f64 {
        let n = self.fine_samples();
        match self.fine {
            Some((f, _)) if i <= n => i as f64 * f,
            Some((f, _)) => n as f64 * f + (i - n) as f64 * self.scan,
            None => i as f64 * self.scan,
        }
    }
}

/// Run a step test on `bench` from its steady state `u0`: the record and whether it settled
/// (judged on the samples at `scan`, after any finer start).
///
/// # Errors
/// The bench's, when it cannot advance.
pub fn step<B: Bench>(bench: &mut B, u0: f64, s: &StepTest) -> Result<(super::fit::StepResponse, bool), B::Error> {
    let (t0, y0) = (bench.time(), bench.measurement());
    bench.set_output(u0 + s.step);
    let (mut t, mut y) = (vec![0.0], vec![0.0]);
    let (check_every, fine) = (50, s.fine_samples());
    loop {
        let next = t0 + s.sample_time(t.len());
        bench.advance_to(next)?;
        t.push(next - t0);
        y.push(bench.measurement() - y0);
        let done = *t.last().unwrap_or(&0.0) >= s.max_duration;
        let coarse = y.len().saturating_sub(fine + 1);
        if (coarse > 0 && coarse % check_every == 0) || done {
            let settled = settled(&y, fine + 1, s.settle);
            if settled || done {
                return Ok((super::fit::StepResponse { t, y, du: s.step }, settled));
            }
        }
    }
}

/// Whether the last third of `y[from..]` moved less than `frac` of the largest deviation.
fn settled(y: &[f64], from: usize, frac: f64) -> bool {
    let largest = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let judged = &y[from.min(y.len())..];
    let tail = &judged[2 * judged.len() / 3..];
    let (lo, hi) = tail.iter().fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    largest > 0.0 && !tail.is_empty() && hi - lo < frac * largest
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `k e^(−θs)/(τ s + 1)` with piecewise-constant input, stepped exactly: the output of a
    /// first-order lag over an interval of constant input is `y_∞ + (y − y_∞) e^(−Δt/τ)`; the
    /// delay is a queue of (time, input) changes.
    struct Foptd {
        k: f64,
        tau: f64,
        theta: f64,
        t: f64,
        x: f64,
        inputs: Vec<(f64, f64)>,
    }

    impl Foptd {
        fn delayed_at(&self, t: f64) -> f64 {
            self.inputs.iter().rev().find(|(ts, _)| ts + self.theta <= t).map_or(0.0, |(_, u)| *u)
        }
    }

    impl Bench for Foptd {
        type Error = std::convert::Infallible;
        fn time(&self) -> f64 {
            self.t
        }
        fn measurement(&self) -> f64 {
            self.x
        }
        fn set_output(&mut self, u: f64) {
            self.inputs.push((self.t, u));
        }
        fn advance_to(&mut self, t_end: f64) -> Result<(), Self::Error> {
            // Split at the instants where the delayed input changes.
            let mut cuts: Vec<f64> =
                self.inputs.iter().map(|(ts, _)| ts + self.theta).filter(|&c| c > self.t && c < t_end).collect();
            cuts.push(t_end);
            for c in cuts {
                let u = self.delayed_at(0.5 * (self.t + c));
                let y_inf = self.k * u;
                self.x = y_inf + (self.x - y_inf) * (-(c - self.t) / self.tau).exp();
                self.t = c;
            }
            Ok(())
        }
    }

    fn foptd(k: f64, tau: f64, theta: f64) -> Foptd {
        Foptd { k, tau, theta, t: 0.0, x: 0.0, inputs: vec![(-1.0, 0.0)] }
    }

    #[test]
    fn sampled_relay_on_a_foptd_reproduces_the_exact_cycle_and_the_describing_function_error() {
        // Exact relay cycle of K e^(−θs)/(τs + 1) (ideal relay, h = 1): a = K (1 − e^(−θ/τ)),
        // P = 2θ + 2τ ln(2 − e^(−θ/τ)). Exact ultimate point: ω_u solves ω_u θ + atan(ω_u τ) = π,
        // K_u = √(1 + (ω_u τ)²)/K. The describing function's estimate is 4h/(π a) of the exact
        // cycle, 16.5 % below the exact K_u at θ/τ = 0.3 (its known error for a FOPTD: the cycle is
        // far from a sine when the lag dominates).
        let (k, tau, theta) = (2.0, 10.0, 3.0);
        let scan = 1e-3;
        let settings = SampledRelay {
            amplitude: 1.0,
            hysteresis: 0.0,
            scan,
            sign: 1.0,
            n_cycles: 3,
            tolerance: 1e-4,
            max_switches: 40,
            max_quiet_scans: 100_000,
        };
        let c = relay(&mut foptd(k, tau, theta), 0.0, &settings).unwrap();
        let r = (-theta / tau).exp();
        let (a_exact, p_exact) = (k * (1.0 - r), 2.0 * theta + 2.0 * tau * (2.0 - r).ln());
        // The scan holds the relay up to one scan late: both figures good to a few scans.
        assert!((c.amplitude - a_exact).abs() < 5.0 * scan * k / tau, "{c:?} vs a = {a_exact}");
        assert!((c.pu - p_exact).abs() < 4.0 * scan, "{c:?} vs P = {p_exact}");
        assert!((c.duty - 0.5).abs() < 1e-3, "{c:?}");
        let wu =
            crate::numeric::root_bracketed(|w| w * theta + (w * tau).atan() - std::f64::consts::PI, 1e-6, 10.0, 1e-14);
        let ku_exact = (1.0 + (wu * tau).powi(2)).sqrt() / k;
        let ku_df = 4.0 / (std::f64::consts::PI * a_exact);
        assert!((c.ku / ku_df - 1.0).abs() < 1e-3, "{} vs the describing function's {ku_df}", c.ku);
        let df_error = ku_df / ku_exact - 1.0;
        assert!((df_error + 0.165).abs() < 1e-3, "describing-function error {df_error}");
        // The relay's period against the exact ultimate period: 2.0 % short here.
        let pu_error = p_exact / (2.0 * std::f64::consts::PI / wu) - 1.0;
        assert!((c.pu / p_exact - 1.0).abs() < 1e-3 && (pu_error + 0.0199).abs() < 1e-3, "period error {pu_error}");
    }

    #[test]
    fn a_measurement_that_never_comes_back_stops_the_test() {
        // The relay pushes the wrong way (sign −1 on a positive gain): the output runs away and
        // never crosses back, so the test must stop instead of integrating forever.
        let settings = SampledRelay {
            amplitude: 1.0,
            hysteresis: 0.0,
            scan: 0.1,
            sign: -1.0,
            n_cycles: 3,
            tolerance: 1e-3,
            max_switches: 40,
            max_quiet_scans: 2000,
        };
        let err = relay(&mut foptd(1.0, 5.0, 1.0), 0.0, &settings).unwrap_err();
        assert!(matches!(err, RelayError::NoSwitch { scans: 2000, .. }), "{err}");
    }

    #[test]
    fn a_lag_without_dead_time_chatters() {
        let settings = SampledRelay {
            amplitude: 1.0,
            hysteresis: 0.0,
            scan: 0.1,
            sign: 1.0,
            n_cycles: 3,
            tolerance: 1e-3,
            max_switches: 40,
            max_quiet_scans: 2000,
        };
        let err = relay(&mut foptd(1.0, 5.0, 0.0), 0.0, &settings).unwrap_err();
        assert!(matches!(err, RelayError::Chatter { .. }), "{err}");
    }

    #[test]
    fn a_step_test_records_until_the_response_settles() {
        let (record, settled) = step(
            &mut foptd(-1.5, 20.0, 4.0),
            0.0,
            &StepTest { step: 0.2, scan: 0.5, max_duration: 1e4, settle: 2e-3, fine: None },
        )
        .unwrap();
        assert!(settled);
        let fit = crate::tune::fit::fit_step(&record, crate::tune::fit::ModelOrder::Foptd).unwrap();
        let crate::tune::fit::ProcessModel::Foptd { k, tau, theta } = fit.model else { panic!() };
        assert!((k + 1.5).abs() < 1e-6 && (tau - 20.0).abs() < 1e-5 && (theta - 4.0).abs() < 1e-5, "{fit:?}");
    }
}
