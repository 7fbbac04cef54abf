//! FIR / step-response estimation (Eq 7-32) by least squares, optionally ridge-regularised
//! (Eq 7-51), solved by QR of the stacked matrix [X; √c I] — not by the normal equations
//! (Eq 7-50), which are ill-conditioned for FIR models (§2.4).

use crate::StepResponse;
use crate::data::{MAX_DELAY, MAX_FIR, check_len, check_miso, check_rows};
use crate::error::IdentError;
use crate::linalg::{covariance, qr_lstsq};
use faer::Mat;
use serde::{Deserialize, Serialize};

/// A MISO FIR model y(t) = Σ_j Σ_k h_j(k) u_j(t − k) + e(t).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FirModel {
    /// Impulse response per input, h_j(k) for k = 0..delay+n_coef−1 (the first `delay`
    /// entries are zero).
    pub impulse: Vec<Vec<f64>>,
    /// Step response per input, s_j(k) = Σ_{i≤k} h_j(i).
    pub step: Vec<Vec<f64>>,
    /// Steady-state gain per input, Σ_k h_j(k).
    pub gain: Vec<f64>,
    /// Residual variance λ̂ = Σ e²/(rows − d) (data rows only, not the ridge rows).
    pub residual_variance: f64,
    /// Standard error of every estimated coefficient, per input (length n_coef), from
    /// λ̂ (XᵀX + cI)⁻¹ (for c > 0 this ignores the ridge bias).
    pub std_errors: Vec<Vec<f64>>,
    /// Number of estimated coefficients per input.
    pub n_coef: usize,
    /// Common delay (samples) before the first estimated coefficient.
    pub delay: usize,
    /// Ridge parameter c (Eq 7-51).
    pub ridge: f64,
    /// Number of regression rows used.
    pub rows: usize,
}

/// Fits a MISO FIR model with `n_coef` coefficients per input (1..=500) starting at lag
/// `delay` (≤ 1000): y(t) = Σ_j Σ_{k=0..n_coef−1} h_j(delay+k) u_j(t−delay−k) + e(t).
///
/// Solves min ‖Xθ − y‖² + c‖θ‖², i.e. θ̂ = (XᵀX + cI)⁻¹Xᵀy (Eq 7-51; c = `ridge` ≥ 0, c = 0
/// gives Eq 7-50), by Householder QR of [X; √c I] against [y; 0]. Rows t = delay+n_coef−1..N−1
/// (no pre-sample values are assumed). Data must be deviation variables (see `detrend`).
pub fn fir(u: &[Vec<f64>], y: &[f64], n_coef: usize, delay: usize, ridge: f64) -> Result<FirModel, IdentError> {
    let n = check_miso(u, y)?;
    if n_coef == 0 || n_coef > MAX_FIR {
        return Err(IdentError::BadOrder { field: "n_coef".into(), value: n_coef, reason: "must be 1..=500" });
    }
    if delay > MAX_DELAY {
        return Err(IdentError::BadOrder { field: "delay".into(), value: delay, reason: "must be <= 1000" });
    }
    if !(ridge.is_finite() && ridge >= 0.0) {
        return Err(IdentError::BadDesign { field: "ridge", value: ridge, reason: "must be finite and >= 0" });
    }
    let nu = u.len();
    let d = nu * n_coef;
    let t0 = delay + n_coef - 1;
    let rows = n.saturating_sub(t0);
    check_rows("FIR model", rows, d)?;
    let extra = if ridge > 0.0 { d } else { 0 };
    let sc = ridge.sqrt();
    let x = Mat::<f64>::from_fn(rows + extra, d, |r, c| {
        if r < rows {
            let (j, k) = (c / n_coef, c % n_coef);
            u[j][r + t0 - delay - k]
        } else if r - rows == c {
            sc
        } else {
            0.0
        }
    });
    let mut rhs: Vec<f64> = y[t0..].to_vec();
    rhs.resize(rows + extra, 0.0);
    let sol = qr_lstsq(&x, &rhs).map_err(|c| IdentError::RankDeficient {
        column: c,
        name: format!("h[{}][{}]", c / n_coef, delay + c % n_coef),
    })?;
    let rss: f64 = (0..rows)
        .map(|r| {
            let yhat: f64 = (0..d).map(|c| x[(r, c)] * sol.theta[c]).sum();
            (rhs[r] - yhat).powi(2)
        })
        .sum();
    let lambda = rss / (rows - d) as f64;
    let p = covariance(&sol.rinv, lambda);
    let mut impulse = vec![vec![0.0; delay + n_coef]; nu];
    for (c, th) in sol.theta.iter().enumerate() {
        impulse[c / n_coef][delay + c % n_coef] = *th;
    }
    let step: Vec<Vec<f64>> = impulse.iter().map(|h| cumsum(h)).collect();
    Ok(FirModel {
        gain: impulse.iter().map(|h| h.iter().sum()).collect(),
        std_errors: (0..nu).map(|j| (0..n_coef).map(|k| p[j * n_coef + k][j * n_coef + k].sqrt()).collect()).collect(),
        impulse,
        step,
        residual_variance: lambda,
        n_coef,
        delay,
        ridge,
        rows,
    })
}

pub(crate) fn cumsum(h: &[f64]) -> Vec<f64> {
    h.iter()
        .scan(0.0, |s, v| {
            *s += v;
            Some(*s)
        })
        .collect()
}

impl FirModel {
    /// Simulated output ŷ(t) = Σ_j Σ_k h_j(k) u_j(t−k) (zero pre-sample inputs).
    pub fn simulate(&self, u: &[Vec<f64>]) -> Result<Vec<f64>, IdentError> {
        if u.len() != self.impulse.len() {
            return Err(IdentError::LengthMismatch {
                name: "u (number of inputs)".into(),
                expected: self.impulse.len(),
                got: u.len(),
            });
        }
        let n = u.first().map_or(0, |s| s.len());
        let f = vec![];
        let mut yhat = vec![0.0; n];
        for (j, uj) in u.iter().enumerate() {
            if uj.len() != n {
                return Err(IdentError::LengthMismatch { name: format!("u[{j}]"), expected: n, got: uj.len() });
            }
            let w = crate::linalg::filter_bf(&self.impulse[j], &f, 0, uj);
            yhat.iter_mut().zip(w).for_each(|(a, b)| *a += b);
        }
        Ok(yhat)
    }
}

impl StepResponse for FirModel {
    /// Step response; beyond the FIR length it stays at the gain.
    fn step_response(&self, n: usize) -> Result<Vec<Vec<f64>>, IdentError> {
        check_len(n)?;
        Ok(self.step.iter().map(|s| (0..n).map(|k| s[k.min(s.len() - 1)]).collect()).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::signals::{prbs, white_noise};

    /// y(t) = a y(t−1) + b u(t−1) + v(t): impulse h(k) = b a^(k−1), k ≥ 1.
    fn first_order(u: &[f64], a: f64, b: f64, noise: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; u.len()];
        let mut x = 0.0;
        for t in 0..u.len() {
            y[t] = x + noise[t];
            x = a * x + b * u[t];
        }
        y
    }

    #[test]
    fn fir_step_matches_exact_first_order_step() {
        let (a, b) = (0.8, 0.5);
        let n = 2000;
        let u = prbs(8, 2, n, 0).unwrap();
        let y = first_order(&u, a, b, &white_noise(n, 0.05, 11).unwrap());
        let m = fir(&[u], &y, 40, 1, 0.0).unwrap();
        let gain = b / (1.0 - a);
        for k in 0..41 {
            let exact = if k == 0 { 0.0 } else { gain * (1.0 - a.powi(k as i32)) };
            assert!((m.step[0][k] - exact).abs() < 0.03 * gain, "k={k}: {} vs {exact}", m.step[0][k]);
        }
        assert!((m.gain[0] - gain).abs() < 0.03 * gain);
        assert_eq!(m.impulse[0][0], 0.0);
        // Residual variance ≈ σ² = 0.0025.
        assert!((m.residual_variance / 0.0025 - 1.0).abs() < 0.15);
    }

    #[test]
    fn ridge_reduces_coefficient_variance() {
        let (a, b) = (0.8, 0.5);
        let n = 300;
        let u = prbs(7, 1, n, 0).unwrap();
        let fits = |c: f64| -> Vec<Vec<f64>> {
            (0..2)
                .map(|seed| {
                    let y = first_order(&u, a, b, &white_noise(n, 0.5, seed).unwrap());
                    fir(std::slice::from_ref(&u), &y, 40, 1, c).unwrap().impulse[0].clone()
                })
                .collect()
        };
        let spread = |h: &[Vec<f64>]| -> f64 { h[0].iter().zip(&h[1]).map(|(x, y)| (x - y).powi(2)).sum() };
        let (s0, s1) = (spread(&fits(0.0)), spread(&fits(30.0)));
        assert!(s1 < s0, "ridge {s1} vs ls {s0}");
    }

    #[test]
    fn fir_errors() {
        let u = prbs(6, 1, 200, 0).unwrap();
        let y = vec![0.0; 200];
        let e = fir(&[u.clone(), vec![1.0; 200]], &y, 10, 0, 0.0).unwrap_err();
        assert_eq!(e, IdentError::ConstantInput { input: 1 });
        let e = fir(std::slice::from_ref(&u), &y[..150], 10, 0, 0.0).unwrap_err();
        assert!(matches!(e, IdentError::LengthMismatch { expected: 150, got: 200, .. }));
        let e = fir(&[u[..30].to_vec()], &y[..30], 20, 0, 0.0).unwrap_err();
        assert!(matches!(e, IdentError::TooShort { needed: 40, got: 11, .. }));
        assert!(fir(std::slice::from_ref(&u), &y, 0, 0, 0.0).is_err());
        assert!(fir(&[u], &y, 5, 0, -1.0).is_err());
    }
}
