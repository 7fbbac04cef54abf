//! First-order-plus-dead-time (FOPTD) fits per input: OE with nb = nf = 1 (Eq 7-66) and the
//! delay scanned for least loss. The discrete model is the exact zero-order-hold sampling of
//! K e^(−θs)/(τs + 1) with θ = d·T_s:
//! y(t) = [b q⁻¹/(1 − a q⁻¹)] u(t − d), a = e^(−T_s/τ), b = K(1 − a), i.e. nk = d + 1.

use crate::data::check_len;
use crate::error::IdentError;
use crate::linalg::step_bf;
use crate::oe::{OeModel, oe};
use serde::{Deserialize, Serialize};

/// Largest dead time (samples) scanned by [`foptd`].
pub const MAX_FOPTD_DELAY: usize = 200;

/// FOPTD model of one input: K e^(−θs)/(τs + 1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Foptd {
    /// Input index.
    pub input: usize,
    /// Steady-state gain K = b/(1 + f₁).
    pub gain: f64,
    /// Time constant τ = −T_s/ln(a), a = −f₁ ∈ (0, 1) (time units of `ts`).
    pub tau: f64,
    /// Dead time θ = d·T_s = (nk − 1)·T_s (time units of `ts`).
    pub delay: f64,
    /// Dead time d in samples.
    pub delay_samples: usize,
    /// OE delay nk = d + 1 (the ZOH adds one sample).
    pub nk: usize,
    /// Discrete pole a = −f₁.
    pub pole: f64,
    /// Discrete numerator b = b₁.
    pub b: f64,
    /// Sampling period T_s.
    pub ts: f64,
    /// Loss V (Eq 7-35) of the whole MISO fit at the chosen delays.
    pub loss: f64,
    /// LM convergence flag of the final fit.
    pub converged: bool,
}

impl Foptd {
    /// Sampled unit-step response over n samples (exact at the sampling instants).
    pub fn step_response(&self, n: usize) -> Result<Vec<f64>, IdentError> {
        check_len(n)?;
        Ok(step_bf(&[self.b], &[-self.pole], self.nk, n))
    }
}

fn fit(u: &[Vec<f64>], y: &[f64], nk: &[usize]) -> Result<OeModel, IdentError> {
    oe(u, y, 1, 1, nk, None)
}

/// Fits a FOPTD model to every input of MISO data (deviation variables): OE with nb = nf = 1
/// per input, each input's dead time d ∈ 0..=`max_delay_samples` (≤ 200) chosen for the least
/// loss V. One input: exhaustive scan. Several inputs: coordinate-wise scans (each input's
/// delay with the others fixed, starting from d = 0), repeated until no delay changes (at most
/// 4 sweeps) — a local search, not an exhaustive (max_delay+1)^nu grid. Candidate delays whose
/// OE fit fails (e.g. unstable ARX start) are skipped. `ts` > 0 is the sampling period.
pub fn foptd(u: &[Vec<f64>], y: &[f64], ts: f64, max_delay_samples: usize) -> Result<Vec<Foptd>, IdentError> {
    if !(ts.is_finite() && ts > 0.0) {
        return Err(IdentError::BadDesign { field: "ts", value: ts, reason: "must be finite and > 0" });
    }
    if max_delay_samples > MAX_FOPTD_DELAY {
        return Err(IdentError::BadOrder {
            field: "max_delay_samples".into(),
            value: max_delay_samples,
            reason: "must be <= 200",
        });
    }
    let nu = u.len();
    crate::data::check_miso(u, y)?;
    let mut nk = vec![1usize; nu];
    let mut best: Option<OeModel> = None;
    let mut last_err = None;
    for _sweep in 0..4 {
        let mut changed = false;
        for j in 0..nu {
            for cand in 1..=max_delay_samples + 1 {
                let mut trial = nk.clone();
                trial[j] = cand;
                match fit(u, y, &trial) {
                    Ok(m) => {
                        if best.as_ref().is_none_or(|b| m.loss < b.loss) {
                            changed |= trial != nk;
                            nk = trial;
                            best = Some(m);
                        }
                    }
                    Err(e) => last_err = Some(e),
                }
            }
        }
        if !changed || nu == 1 {
            break;
        }
    }
    let m = best.ok_or_else(|| last_err.unwrap_or(IdentError::Numerical("FOPTD scan")))?;
    to_foptd(&m, ts)
}

fn to_foptd(m: &OeModel, ts: f64) -> Result<Vec<Foptd>, IdentError> {
    (0..m.b.len())
        .map(|j| {
            let a = -m.f[j][0];
            if !(a > 0.0 && a < 1.0) {
                return Err(IdentError::NotFirstOrderLag { input: j, pole: a });
            }
            Ok(Foptd {
                input: j,
                gain: m.gain[j],
                tau: -ts / a.ln(),
                delay: (m.nk[j] - 1) as f64 * ts,
                delay_samples: m.nk[j] - 1,
                nk: m.nk[j],
                pole: a,
                b: m.b[j][0],
                ts,
                loss: m.loss,
                converged: m.converged,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::signals::gbn;

    /// Exact ZOH sampling of K e^(−θs)/(τs+1), θ = d·ts: x(t+1) = a x(t) + b u(t−d), y = x.
    fn zoh_foptd(u: &[f64], k: f64, tau: f64, d: usize, ts: f64) -> Vec<f64> {
        let a = (-ts / tau).exp();
        let b = k * (1.0 - a);
        let mut y = vec![0.0; u.len()];
        for t in 1..u.len() {
            let ud = if t > d { u[t - 1 - d] } else { 0.0 };
            y[t] = a * y[t - 1] + b * ud;
        }
        y
    }

    #[test]
    fn foptd_recovers_single_input_noise_free() {
        let (ts, n) = (1.0, 1000);
        let u = gbn(n, 15.0, 5).unwrap();
        let y = zoh_foptd(&u, 2.0, 10.0, 3, ts);
        let m = foptd(&[u], &y, ts, 8).unwrap();
        assert_eq!(m.len(), 1);
        assert!((m[0].gain - 2.0).abs() < 1e-6, "K {}", m[0].gain);
        assert!((m[0].tau - 10.0).abs() < 1e-6, "tau {}", m[0].tau);
        assert!((m[0].delay - 3.0).abs() < 1e-12);
        assert_eq!((m[0].delay_samples, m[0].nk), (3, 4));
        // Step response equals K(1 − e^(−(t−θ)/τ)) at the samples.
        let st = m[0].step_response(60).unwrap();
        for (t, s) in st.iter().enumerate() {
            let tt = t as f64 * ts - 3.0;
            let exact = if tt > 0.0 { 2.0 * (1.0 - (-tt / 10.0).exp()) } else { 0.0 };
            assert!((s - exact).abs() < 1e-6, "t {t}: {s} vs {exact}");
        }
    }

    #[test]
    fn foptd_two_inputs_different_delays() {
        let (ts, n) = (0.5, 1500);
        let u = vec![gbn(n, 12.0, 8).unwrap(), gbn(n, 12.0, 9).unwrap()];
        let y1 = zoh_foptd(&u[0], 2.0, 10.0, 2, ts);
        let y2 = zoh_foptd(&u[1], -1.5, 4.0, 6, ts);
        let y: Vec<f64> = y1.iter().zip(&y2).map(|(a, b)| a + b).collect();
        let m = foptd(&u, &y, ts, 8).unwrap();
        for (fit, (k, tau, d)) in m.iter().zip([(2.0, 10.0, 2usize), (-1.5, 4.0, 6)]) {
            assert_eq!(fit.delay_samples, d);
            assert!((fit.gain - k).abs() < 1e-6 && (fit.tau - tau).abs() < 1e-6, "{fit:?}");
            assert!((fit.delay - d as f64 * ts).abs() < 1e-12);
        }
    }

    #[test]
    fn foptd_rejects_bad_arguments() {
        let u = vec![gbn(100, 5.0, 1).unwrap()];
        let y = vec![0.0; 100];
        assert!(matches!(foptd(&u, &y, 0.0, 3), Err(IdentError::BadDesign { field: "ts", .. })));
        assert!(matches!(foptd(&u, &y, 1.0, 201), Err(IdentError::BadOrder { .. })));
        assert!(matches!(foptd(&u, &y[..50], 1.0, 3), Err(IdentError::LengthMismatch { .. })));
    }
}
