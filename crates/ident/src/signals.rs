//! Test signals (§2.1, book §7-2-2): PRBS design (Eq 7-5 to 7-10), Fibonacci-LFSR PRBS,
//! generalized binary noise, white noise, and the Koung & MacGregor (1991) directional design
//! for ill-conditioned plants.

use crate::data::{MAX_INPUTS, MAX_LEN, check_len};
use crate::error::IdentError;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Smallest and largest number of shift registers supported by [`prbs`].
pub const REGISTERS: std::ops::RangeInclusive<usize> = 2..=16;
/// Largest clock period in samples.
pub const MAX_CLOCK_SAMPLES: usize = 1_000_000;

/// Feedback taps of the Fibonacci LFSR for n = 2..=16 (spec table §2.1; each gives period
/// 2ⁿ − 1, verified by the tests).
const TAPS: [&[usize]; 15] = [
    &[2, 1],
    &[3, 2],
    &[4, 3],
    &[5, 3],
    &[6, 5],
    &[7, 6],
    &[8, 6, 5, 4],
    &[9, 5],
    &[10, 7],
    &[11, 9],
    &[12, 6, 4, 1],
    &[13, 4, 3, 1],
    &[14, 5, 3, 1],
    &[15, 14],
    &[16, 15, 13, 4],
];

/// A PRBS design from the "proposed design algorithm" of §2.1.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PrbsDesign {
    /// Sampling period T_s (time units of the inputs).
    pub ts: f64,
    /// Clock period T_cl = `clock_samples`·T_s (Eq 7-8, rounded down to a multiple of T_s).
    pub clock_period: f64,
    /// Clock period in samples.
    pub clock_samples: usize,
    /// Number of shift registers n.
    pub registers: usize,
    /// Period N = 2ⁿ − 1 in clock periods.
    pub period: usize,
    /// Useful excitation band [2π/(N T_cl), 2.8/T_cl] in rad/time (Eq 7-6).
    pub band: (f64, f64),
    /// Delay D between the inputs' copies in samples, ⌊N·T_cl/(p·T_s)⌋ (Eq 7-10).
    pub shift_samples: usize,
    /// Number of inputs p.
    pub n_inputs: usize,
    /// Samples in one period, N·T_cl/T_s. The total test length is (periods)·`samples`.
    pub samples: usize,
}

fn positive(field: &'static str, v: f64) -> Result<f64, IdentError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(IdentError::BadDesign { field, value: v, reason: "must be finite and > 0" })
    }
}

fn non_negative(field: &'static str, v: f64) -> Result<f64, IdentError> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(IdentError::BadDesign { field, value: v, reason: "must be finite and >= 0" })
    }
}

/// PRBS design (§2.1, "proposed design algorithm"):
///
/// 1. τ = τ_dom + τ_d/2 (Eq 7-7);
/// 2. T_cl = max(T_s, T_s·⌊2.8 τ / (α T_s)⌋) (Eq 7-8, used as an upper bound);
/// 3. N_min = 2πβτ/T_cl (the T_s-rounded form of Eq 7-9, N ≥ 2παβ/2.8),
///    n = max(2, ⌈log₂(N_min + 1)⌉), N = 2ⁿ − 1;
/// 4. MIMO (Eq 7-10): while D·T_s ≤ T_99%,max with D = ⌊N·T_cl/(p T_s)⌋, increment n
///    (n ≤ 16, otherwise [`IdentError::BadDesign`]). Input j is shifted by j·D samples.
///
/// Arguments: `tau_dom`, `tau_d` (dominant time constant and dead time), `alpha` (closed-loop
/// speed-up), `beta` (3, 4, 5 ≈ 95, 98, 99 % settling), `ts` (sampling period), `n_inputs`
/// (p, 1..=16), `t_settle_max` (T_99%,max, ≥ 0; the largest 99 % settling time).
pub fn design_prbs(
    tau_dom: f64,
    tau_d: f64,
    alpha: f64,
    beta: f64,
    ts: f64,
    n_inputs: usize,
    t_settle_max: f64,
) -> Result<PrbsDesign, IdentError> {
    let tau_dom = positive("tau_dom", tau_dom)?;
    let tau_d = non_negative("tau_d", tau_d)?;
    let alpha = positive("alpha", alpha)?;
    let beta = positive("beta", beta)?;
    let ts = positive("ts", ts)?;
    let t_settle_max = non_negative("t_settle_max", t_settle_max)?;
    if n_inputs == 0 || n_inputs > MAX_INPUTS {
        return Err(IdentError::BadDesign { field: "n_inputs", value: n_inputs as f64, reason: "must be 1..=16" });
    }
    let tau = tau_dom + tau_d / 2.0;
    // Eq 7-8; the 1e-9 guards against 307.99999 from floating-point division.
    let k = (2.8 * tau / (alpha * ts) + 1e-9).floor();
    if k > MAX_CLOCK_SAMPLES as f64 {
        return Err(IdentError::BadDesign { field: "ts", value: ts, reason: "clock period exceeds 1e6 samples" });
    }
    let clock_samples = (k as usize).max(1);
    let t_cl = clock_samples as f64 * ts;
    // Eq 7-9 (T_s-rounded form).
    let n_min = 2.0 * PI * beta * tau / t_cl;
    let mut n = ((n_min + 1.0).log2().ceil() as usize).max(*REGISTERS.start());
    let shift = |n: usize| ((1usize << n) - 1) * clock_samples / n_inputs;
    if n > *REGISTERS.end() {
        return Err(IdentError::BadDesign {
            field: "beta",
            value: beta,
            reason: "needs more than 16 shift registers (Eq 7-9)",
        });
    }
    // Eq 7-10.
    while shift(n) as f64 * ts <= t_settle_max {
        n += 1;
        if n > *REGISTERS.end() {
            return Err(IdentError::BadDesign {
                field: "t_settle_max",
                value: t_settle_max,
                reason: "D = N*T_cl/p cannot exceed it with n <= 16 registers (Eq 7-10)",
            });
        }
    }
    let period = (1usize << n) - 1;
    let samples = period * clock_samples;
    if samples > MAX_LEN {
        return Err(IdentError::TooLarge { what: "PRBS period in samples", limit: MAX_LEN, got: samples });
    }
    Ok(PrbsDesign {
        ts,
        clock_period: t_cl,
        clock_samples,
        registers: n,
        period,
        band: (2.0 * PI / (period as f64 * t_cl), 2.8 / t_cl),
        shift_samples: shift(n),
        n_inputs,
        samples,
    })
}

impl PrbsDesign {
    /// Period of the sequence in time units, T = N·T_cl.
    pub fn period_time(&self) -> f64 {
        self.period as f64 * self.clock_period
    }

    /// The p input sequences of `periods` periods each, input j a copy delayed by j·D
    /// (Eq 7-10), levels ±`amplitude`.
    pub fn sequences(&self, periods: usize, amplitude: f64) -> Result<Vec<Vec<f64>>, IdentError> {
        let len = self.samples.checked_mul(periods).ok_or(IdentError::TooLarge {
            what: "series length",
            limit: MAX_LEN,
            got: usize::MAX,
        })?;
        check_len(len.saturating_mul(self.n_inputs))?;
        (0..self.n_inputs)
            .map(|j| {
                let s = prbs(self.registers, self.clock_samples, len, j * self.shift_samples)?;
                Ok(s.into_iter().map(|v| v * amplitude).collect())
            })
            .collect()
    }
}

/// PRBS power spectrum, Eq 7-5 (Davies 1970):
/// S(ω) = a²(N+1)T_cl/N · [sin(ωT_cl/2)/(ωT_cl/2)]²; half power at ω ≈ 2.8/T_cl.
pub fn prbs_spectrum(amplitude: f64, period: usize, clock_period: f64, omega: f64) -> f64 {
    let n = period as f64;
    let x = omega * clock_period / 2.0;
    let sinc = if x.abs() < 1e-12 { 1.0 } else { x.sin() / x };
    amplitude * amplitude * (n + 1.0) * clock_period / n * sinc * sinc
}

/// One period of the LFSR output (N = 2ⁿ − 1 clocks), levels ±1.
///
/// Fibonacci LFSR (§2.1): state s[1..n] = all ones; each clock the output is +1 if s[n] = 1
/// else −1, then fb = XOR of s[taps], shift right (s[i+1] ← s[i]), s[1] ← fb.
fn lfsr_period(registers: usize) -> Vec<f64> {
    let taps = TAPS[registers - 2];
    let mask = (1u32 << registers) - 1;
    let mut state: u32 = mask; // bit i-1 holds s[i]
    let n = (1usize << registers) - 1;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        out.push(if state >> (registers - 1) & 1 == 1 { 1.0 } else { -1.0 });
        let fb = taps.iter().fold(0u32, |acc, &t| acc ^ (state >> (t - 1) & 1));
        state = ((state << 1) | fb) & mask;
    }
    out
}

/// Number of clocks until the LFSR state first returns to its initial value (test helper:
/// the maximal-length property, period exactly 2ⁿ − 1).
#[cfg(test)]
pub(crate) fn lfsr_state_period(registers: usize) -> usize {
    let taps = TAPS[registers - 2];
    let mask = (1u32 << registers) - 1;
    let mut state = mask;
    for k in 1..=(1usize << registers) {
        let fb = taps.iter().fold(0u32, |acc, &t| acc ^ (state >> (t - 1) & 1));
        state = ((state << 1) | fb) & mask;
        if state == mask {
            return k;
        }
    }
    0
}

/// PRBS of `len` samples, levels ±1: the LFSR sequence with `registers` = n ∈ 2..=16 (period
/// N = 2ⁿ − 1 clocks), each level held `clock_samples` samples (T_cl/T_s), repeated
/// periodically and delayed circularly by `shift_samples`: x_D(t) = x((t − D) mod N·T_cl/T_s).
pub fn prbs(registers: usize, clock_samples: usize, len: usize, shift_samples: usize) -> Result<Vec<f64>, IdentError> {
    if !REGISTERS.contains(&registers) {
        return Err(IdentError::BadOrder { field: "registers".into(), value: registers, reason: "must be 2..=16" });
    }
    if clock_samples == 0 || clock_samples > MAX_CLOCK_SAMPLES {
        return Err(IdentError::BadOrder {
            field: "clock_samples".into(),
            value: clock_samples,
            reason: "must be 1..=1000000",
        });
    }
    check_len(len)?;
    let base = lfsr_period(registers);
    let p = base.len() * clock_samples;
    let d = shift_samples % p;
    Ok((0..len).map(|t| base[((t % p) + p - d) % p / clock_samples]).collect())
}

/// Generalized binary noise (Tulleken 1990): levels ±1, starting at a random level, switching
/// sign at each subsequent sample with probability 1/`mean_switch_samples` (≥ 1; the mean
/// time between switches in samples). Reproducible: `ChaCha8Rng::seed_from_u64(seed)`.
pub fn gbn(len: usize, mean_switch_samples: f64, seed: u64) -> Result<Vec<f64>, IdentError> {
    if !(mean_switch_samples.is_finite() && mean_switch_samples >= 1.0) {
        return Err(IdentError::BadDesign {
            field: "mean_switch_samples",
            value: mean_switch_samples,
            reason: "must be finite and >= 1",
        });
    }
    check_len(len)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let p = 1.0 / mean_switch_samples;
    let mut level = if rng.random::<bool>() { 1.0 } else { -1.0 };
    let mut out = Vec::with_capacity(len);
    for t in 0..len {
        if t > 0 && rng.random::<f64>() < p {
            level = -level;
        }
        out.push(level);
    }
    Ok(out)
}

/// Gaussian white noise N(0, σ²) of `len` samples, reproducible from `seed` (ChaCha8).
pub fn white_noise(len: usize, sigma: f64, seed: u64) -> Result<Vec<f64>, IdentError> {
    let sigma = non_negative("sigma", sigma)?;
    check_len(len)?;
    let normal = Normal::new(0.0, sigma).map_err(|_| IdentError::BadDesign {
        field: "sigma",
        value: sigma,
        reason: "invalid standard deviation",
    })?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    Ok((0..len).map(|_| normal.sample(&mut rng)).collect())
}

/// Directional input design for an ill-conditioned plant (Koung & MacGregor 1991, §2.1
/// "emphasise low-gain directions").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DirectionalDesign {
    /// Input sequences u_j(t), one per input (nu series).
    pub inputs: Vec<Vec<f64>>,
    /// Singular values σ_1 ≥ … ≥ σ_k of the prior gain G0, k = min(ny, nu).
    pub singular_values: Vec<f64>,
    /// Right singular vectors v_i (input directions), `v[i][j]` = component j of v_i.
    pub v: Vec<Vec<f64>>,
    /// Left singular vectors u_i (output directions), `u[i][r]` = component r of u_i.
    pub u: Vec<Vec<f64>>,
    /// Amplitude c_i of signal i along v_i, c_i = γ/σ_i.
    pub scale: Vec<f64>,
    /// Common factor γ such that max_t |u_j(t)| ≤ amplitudes[j] for every input (equality for
    /// at least one). The output moves by ±γ along every u_i.
    pub output_amplitude: f64,
    /// Condition number κ = σ_1/σ_k.
    pub condition_number: f64,
}

fn check_gain(gain: &[Vec<f64>]) -> Result<(usize, usize), IdentError> {
    let ny = gain.len();
    let nu = gain.first().map_or(0, |r| r.len());
    if ny == 0 || nu == 0 || ny > MAX_INPUTS || nu > MAX_INPUTS {
        return Err(IdentError::BadOrder {
            field: "gain (dimensions)".into(),
            value: ny.max(nu),
            reason: "gain must be ny x nu with 1..=16 rows and columns",
        });
    }
    for (i, row) in gain.iter().enumerate() {
        if row.len() != nu {
            return Err(IdentError::LengthMismatch { name: format!("gain[{i}]"), expected: nu, got: row.len() });
        }
        crate::data::check_finite(row, &format!("gain[{i}]"))?;
    }
    Ok((ny, nu))
}

/// Koung & MacGregor (1991) design: with the SVD G0 = UΣVᵀ (faer), the input is
/// u(t) = Σ_{i=1..k} v_i c_i s_i(t), c_i = γ/σ_i, so that y = G0 u = γ Σ u_i s_i(t): every
/// singular direction moves the outputs by the same amplitude γ (the low-gain direction as much
/// as the high-gain one). γ is the largest value with max_t |u_j(t)| ≤ `amplitudes[j]`.
///
/// `gain`: prior steady-state gain G0, ny × nu (square or not); `signals`: nu independent ±1
/// sequences of equal length (only the first k = min(ny, nu) are used — directions in the null
/// space of G0 do not move the outputs); `amplitudes`: max |u_j| per input (> 0).
pub fn directional(
    gain: &[Vec<f64>],
    signals: &[Vec<f64>],
    amplitudes: &[f64],
) -> Result<DirectionalDesign, IdentError> {
    let (ny, nu) = check_gain(gain)?;
    for (name, got) in [("signals", signals.len()), ("amplitudes", amplitudes.len())] {
        if got != nu {
            return Err(IdentError::LengthMismatch { name: name.into(), expected: nu, got });
        }
    }
    let len = signals[0].len();
    for (j, s) in signals.iter().enumerate() {
        if s.len() != len {
            return Err(IdentError::LengthMismatch { name: format!("signals[{j}]"), expected: len, got: s.len() });
        }
        crate::data::check_finite(s, &format!("signals[{j}]"))?;
    }
    for &a in amplitudes {
        positive("amplitudes", a)?;
    }
    let g = faer::Mat::<f64>::from_fn(ny, nu, |i, j| gain[i][j]);
    let svd = g.thin_svd().map_err(|_| IdentError::Numerical("SVD of gain"))?;
    let k = ny.min(nu);
    let sv: Vec<f64> = (0..k).map(|i| svd.S().column_vector()[i]).collect();
    if sv[k - 1].is_nan() || sv[k - 1] <= 1e-12 * sv[0] {
        return Err(IdentError::BadDesign {
            field: "gain",
            value: sv[k - 1],
            reason: "gain matrix is (numerically) rank deficient: smallest singular value ~ 0",
        });
    }
    let v: Vec<Vec<f64>> = (0..k).map(|i| (0..nu).map(|j| svd.V()[(j, i)]).collect()).collect();
    let uo: Vec<Vec<f64>> = (0..k).map(|i| (0..ny).map(|r| svd.U()[(r, i)]).collect()).collect();
    // Unscaled design (γ = 1).
    let mut inputs = vec![vec![0.0; len]; nu];
    for i in 0..k {
        let c = 1.0 / sv[i];
        for (j, uj) in inputs.iter_mut().enumerate() {
            for (t, ujt) in uj.iter_mut().enumerate() {
                *ujt += v[i][j] * c * signals[i][t];
            }
        }
    }
    let gamma = inputs
        .iter()
        .zip(amplitudes)
        .map(|(uj, &a)| {
            let m = uj.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            if m > 0.0 { a / m } else { f64::INFINITY }
        })
        .fold(f64::INFINITY, f64::min);
    if !gamma.is_finite() {
        return Err(IdentError::BadDesign { field: "signals", value: 0.0, reason: "signals are all zero" });
    }
    inputs.iter_mut().flatten().for_each(|x| *x *= gamma);
    Ok(DirectionalDesign {
        inputs,
        scale: sv.iter().map(|s| gamma / s).collect(),
        condition_number: sv[0] / sv[k - 1],
        singular_values: sv,
        v,
        u: uo,
        output_amplitude: gamma,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lfsr_state_period_is_maximal_for_all_registers() {
        for n in REGISTERS {
            assert_eq!(lfsr_state_period(n), (1 << n) - 1, "n = {n}");
        }
    }

    #[test]
    fn prbs_output_period_and_balance() {
        for n in REGISTERS {
            let big_n = (1usize << n) - 1;
            let x = prbs(n, 1, 2 * big_n, 0).unwrap();
            assert!((0..big_n).all(|t| x[t] == x[t + big_n]), "n = {n}: not periodic");
            // Minimal period divides N: no proper divisor may be a period.
            for p in (1..big_n).filter(|p| big_n.is_multiple_of(*p)) {
                assert!((0..big_n).any(|t| x[t] != x[t + p]), "n = {n}: period {p}");
            }
            let plus = x[..big_n].iter().filter(|&&v| v == 1.0).count();
            let minus = x[..big_n].iter().filter(|&&v| v == -1.0).count();
            assert_eq!(plus, minus + 1, "n = {n}: balance");
            assert_eq!(plus, 1 << (n - 1));
        }
    }

    #[test]
    fn prbs_clock_and_circular_shift() {
        let (n, cs) = (5, 3);
        let p = 31 * cs;
        let x = prbs(n, cs, 2 * p, 0).unwrap();
        // Levels held for cs samples.
        assert!((0..p).step_by(cs).all(|t| (1..cs).all(|k| x[t + k] == x[t])));
        for d in [0, 1, 7, p - 1, p + 4] {
            let xd = prbs(n, cs, 2 * p, d).unwrap();
            for t in 0..2 * p {
                assert_eq!(xd[t], x[(t + 2 * p - d % p) % p], "shift {d}, t {t}");
            }
        }
    }

    #[test]
    fn prbs_rejects_bad_arguments() {
        assert!(matches!(prbs(1, 1, 10, 0), Err(IdentError::BadOrder { .. })));
        assert!(matches!(prbs(17, 1, 10, 0), Err(IdentError::BadOrder { .. })));
        assert!(matches!(prbs(4, 0, 10, 0), Err(IdentError::BadOrder { .. })));
        assert!(matches!(prbs(4, 1, MAX_LEN + 1, 0), Err(IdentError::TooLarge { .. })));
    }

    #[test]
    fn design_reproduces_book_example() {
        // τ_dom = 100 s, τ_d = 20 s, α = 1, β = 3, T_s = 1 s: T_cl = 2.8·110 = 308 s (Eq 7-8).
        let d = design_prbs(100.0, 20.0, 1.0, 3.0, 1.0, 1, 0.0).unwrap();
        assert_eq!(d.clock_samples, 308);
        assert!((d.clock_period - 308.0).abs() < 1e-12);
        // Eq 7-9: N ≥ 2παβ/2.8 = 6.73 → n = 3, N = 7.
        let n_min = 2.0 * PI * 1.0 * 3.0 / 2.8;
        assert!((n_min - 6.7320).abs() < 1e-3);
        assert_eq!((d.registers, d.period), (3, 7));
        assert_eq!(d.samples, 7 * 308);
        // Eq 7-6 band.
        assert!((d.band.0 - 2.0 * PI / (7.0 * 308.0)).abs() < 1e-15);
        assert!((d.band.1 - 2.8 / 308.0).abs() < 1e-15);
        // Half power of Eq 7-5 at ω ≈ 2.8/T_cl.
        let s0 = prbs_spectrum(1.0, 7, 308.0, 0.0);
        let sh = prbs_spectrum(1.0, 7, 308.0, 2.783 / 308.0);
        assert!((sh / s0 - 0.5).abs() < 2e-3);
    }

    #[test]
    fn design_rounds_clock_down_to_sample_multiple() {
        // 2.8·110/1 = 308 s with T_s = 50 s → ⌊6.16⌋ = 6 samples = 300 s.
        let d = design_prbs(100.0, 20.0, 1.0, 3.0, 50.0, 1, 0.0).unwrap();
        assert_eq!(d.clock_samples, 6);
        // Fast α: clock at least one sample.
        let d = design_prbs(1.0, 0.0, 10.0, 3.0, 1.0, 1, 0.0).unwrap();
        assert_eq!(d.clock_samples, 1);
    }

    #[test]
    fn mimo_rule_increments_registers() {
        // p = 2, T_cl = 308: n = 3 gives D = 7·308/2 = 1078 s. T_99 = 2000 s needs D > 2000:
        // n = 4 gives 15·308/2 = 2310 → n = 4.
        let d = design_prbs(100.0, 20.0, 1.0, 3.0, 1.0, 2, 2000.0).unwrap();
        assert_eq!(d.registers, 4);
        assert_eq!(d.shift_samples, 15 * 308 / 2);
        assert!(d.shift_samples as f64 > 2000.0);
        let d3 = design_prbs(100.0, 20.0, 1.0, 3.0, 1.0, 2, 1000.0).unwrap();
        assert_eq!(d3.registers, 3);
        // Impossible with 16 registers.
        let e = design_prbs(100.0, 20.0, 1.0, 3.0, 1.0, 2, 1e9).unwrap_err();
        assert!(matches!(e, IdentError::BadDesign { field: "t_settle_max", .. }));
        let seqs = d.sequences(1, 2.0).unwrap();
        assert_eq!(seqs[1][d.shift_samples], seqs[0][0]);
        assert!(seqs[0].iter().all(|v| v.abs() == 2.0));
    }

    #[test]
    fn design_rejects_bad_parameters() {
        let e = design_prbs(-1.0, 0.0, 1.0, 3.0, 1.0, 1, 0.0).unwrap_err();
        assert!(matches!(e, IdentError::BadDesign { field: "tau_dom", .. }));
        let e = design_prbs(1.0, 0.0, f64::NAN, 3.0, 1.0, 1, 0.0).unwrap_err();
        assert!(matches!(e, IdentError::BadDesign { field: "alpha", .. }));
        let e = design_prbs(1.0, 0.0, 1.0, 3.0, 1.0, 0, 0.0).unwrap_err();
        assert!(matches!(e, IdentError::BadDesign { field: "n_inputs", .. }));
    }

    #[test]
    fn gbn_and_white_noise_are_reproducible() {
        let a = gbn(20_000, 8.0, 7).unwrap();
        assert_eq!(a, gbn(20_000, 8.0, 7).unwrap());
        assert_ne!(a, gbn(20_000, 8.0, 8).unwrap());
        assert!(a.iter().all(|v| v.abs() == 1.0));
        // Switch probability 1/8 per sample: expected 19999/8 = 2500 switches, sd ≈ 47.
        let switches = a.windows(2).filter(|w| w[0] != w[1]).count() as f64;
        assert!((switches - 2500.0).abs() < 5.0 * 47.0, "{switches}");
        let w = white_noise(50_000, 0.5, 3).unwrap();
        assert_eq!(w, white_noise(50_000, 0.5, 3).unwrap());
        let var = w.iter().map(|x| x * x).sum::<f64>() / w.len() as f64;
        // Sample variance of 50 000 N(0, 0.25): sd of estimate = 0.25·√(2/N) ≈ 0.0016.
        assert!((var - 0.25).abs() < 0.01);
        assert!(gbn(10, 0.5, 1).is_err());
        assert!(white_noise(10, -1.0, 1).is_err());
    }

    /// Variances of the output components along the singular output directions u_1, u_2.
    fn direction_variances(g: &[Vec<f64>], u: &[Vec<f64>], dirs: &[Vec<f64>]) -> Vec<f64> {
        let len = u[0].len();
        dirs.iter()
            .map(|d| {
                let z: Vec<f64> = (0..len)
                    .map(|t| (0..g.len()).map(|r| d[r] * (0..u.len()).map(|j| g[r][j] * u[j][t]).sum::<f64>()).sum())
                    .collect();
                let m = z.iter().sum::<f64>() / len as f64;
                z.iter().map(|x| (x - m).powi(2)).sum::<f64>() / len as f64
            })
            .collect()
    }

    #[test]
    fn directional_design_balances_output_directions() {
        let g = vec![vec![0.878, -0.864], vec![1.082, -1.096]];
        // Closed form: σ1σ2 = |det G|, σ1² + σ2² = ‖G‖_F².
        let det = (0.878f64 * -1.096 - (-0.864) * 1.082).abs();
        let fro2: f64 = g.iter().flatten().map(|x| x * x).sum();
        let disc = (fro2 * fro2 - 4.0 * det * det).sqrt();
        let (s1, s2) = (((fro2 + disc) / 2.0).sqrt(), ((fro2 - disc) / 2.0).sqrt());
        // Two practically uncorrelated ±1 PRBS: one sequence and its half-period shift.
        let n = 1023;
        let s = vec![prbs(10, 1, n, 0).unwrap(), prbs(10, 1, n, 511).unwrap()];
        let d = directional(&g, &s, &[1.0, 1.0]).unwrap();
        assert!((d.singular_values[0] - s1).abs() < 1e-12);
        assert!((d.singular_values[1] - s2).abs() < 1e-12);
        assert!((d.condition_number - s1 / s2).abs() < 1e-9);
        assert!((d.condition_number - 142.0).abs() < 1.0);
        // Amplitude limits respected, tight for one input.
        let maxabs: Vec<f64> = d.inputs.iter().map(|u| u.iter().fold(0.0f64, |m, x| m.max(x.abs()))).collect();
        assert!(maxabs.iter().all(|&m| m <= 1.0 + 1e-12));
        assert!(maxabs.iter().any(|&m| (m - 1.0).abs() < 1e-12));
        let var = direction_variances(&g, &d.inputs, &d.u);
        let ratio = var[1] / var[0];
        assert!((0.5..=2.0).contains(&ratio), "directional ratio {ratio}");
        // Independent PRBS on each input (same amplitude): ratio ≈ σ2²/σ1² = 1/κ².
        let var_ind = direction_variances(&g, &s, &d.u);
        let ratio_ind = var_ind[1] / var_ind[0];
        eprintln!("low/high output variance: directional {ratio}, independent PRBS {ratio_ind}");
        let expected = (s2 / s1).powi(2);
        assert!(ratio_ind / expected > 0.5 && ratio_ind / expected < 2.0, "{ratio_ind} vs {expected}");
        assert!(ratio_ind < 1e-3);
    }

    #[test]
    fn directional_rejects_bad_input() {
        let g = vec![vec![1.0, 2.0], vec![2.0, 4.0]];
        let s = vec![vec![1.0, -1.0], vec![-1.0, 1.0]];
        assert!(matches!(directional(&g, &s, &[1.0, 1.0]), Err(IdentError::BadDesign { field: "gain", .. })));
        let g = vec![vec![1.0, 0.0], vec![0.0, 1.0]];
        assert!(matches!(directional(&g, &s[..1], &[1.0, 1.0]), Err(IdentError::LengthMismatch { .. })));
        assert!(directional(&g, &s, &[1.0, -1.0]).is_err());
    }
}
