//! Model validation (§2.8, book §7-4): simulation fit, residual whiteness (Eq 7-17, 7-59) and
//! residual–input independence (Eq 7-60) with the 95 % bound ±1.96/√N.

use crate::error::IdentError;
use serde::{Deserialize, Serialize};

/// Result of [`validate`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Validation {
    /// 100(1 − ‖y − ŷ‖/‖y − ȳ‖) (%).
    pub fit_percent: f64,
    /// Residual autocorrelation ρ_e(k), k = 0..=max_lag (ρ_e(0) = 1), Eq 7-59.
    pub autocorrelation: Vec<f64>,
    /// Residual–input cross-correlation ρ_eu_j(k), k = 0..=max_lag, per input (Eq 7-60).
    pub cross_correlation: Vec<Vec<f64>>,
    /// 95 % significance bound 1.96/√N.
    pub bound: f64,
    /// Lags k = 1..=max_lag with |ρ_e(k)| > bound.
    pub whiteness_failures: usize,
    /// (input, lag) pairs, lags 0..=max_lag, with |ρ_eu(k)| > bound.
    pub cross_failures: usize,
    /// Residuals accepted as white: at most 5 % of the tested lags outside the bound.
    pub white: bool,
    /// Residuals accepted as independent of the inputs: at most 5 % of the tested
    /// (input, lag) pairs outside the bound.
    pub independent: bool,
}

fn same_len(a: &[f64], b: &[f64], name: &str) -> Result<usize, IdentError> {
    if a.len() != b.len() {
        return Err(IdentError::LengthMismatch { name: name.into(), expected: a.len(), got: b.len() });
    }
    Ok(a.len())
}

/// Simulation fit 100(1 − ‖y − ŷ‖/‖y − ȳ‖) in % (100 = exact; can be negative). If y is
/// constant the result is 100 for an exact ŷ and −∞ otherwise.
pub fn fit_percent(y: &[f64], yhat: &[f64]) -> Result<f64, IdentError> {
    let n = same_len(y, yhat, "yhat")?;
    if n == 0 {
        return Err(IdentError::TooShort { what: "fit_percent", needed: 1, got: 0 });
    }
    let mean = y.iter().sum::<f64>() / n as f64;
    let num = y.iter().zip(yhat).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
    let den = y.iter().map(|a| (a - mean).powi(2)).sum::<f64>().sqrt();
    Ok(if den > 0.0 {
        100.0 * (1.0 - num / den)
    } else if num == 0.0 {
        100.0
    } else {
        f64::NEG_INFINITY
    })
}

fn demean(x: &[f64]) -> Vec<f64> {
    crate::data::detrend(x)
}

fn check_lag(max_lag: usize, n: usize) -> Result<(), IdentError> {
    if n < 2 || max_lag >= n {
        return Err(IdentError::TooShort {
            what: "correlation (N must exceed max_lag)",
            needed: max_lag.max(1) + 1,
            got: n,
        });
    }
    Ok(())
}

/// Autocorrelation ρ(k) = c(k)/c(0), c(k) = (1/N)Σ_{i=1}^{N−k} e(i)e(i+k) (Eq 7-17, 7-59),
/// k = 0..=`max_lag` (< N), computed on the mean-removed series. A zero series gives ρ = 0.
pub fn autocorrelation(e: &[f64], max_lag: usize) -> Result<Vec<f64>, IdentError> {
    check_lag(max_lag, e.len())?;
    let x = demean(e);
    let n = x.len() as f64;
    let c = |k: usize| x.iter().zip(&x[k..]).map(|(a, b)| a * b).sum::<f64>() / n;
    let c0 = c(0);
    Ok((0..=max_lag).map(|k| if c0 > 0.0 { c(k) / c0 } else { 0.0 }).collect())
}

/// Cross-correlation ρ_eu(k) = c_eu(k)/(σ_e σ_u), c_eu(k) = (1/N)Σ_{i=1}^{N−k} u(i)e(i+k)
/// (Eq 7-60: residual lagging the input, the causal direction that reveals missing b terms),
/// k = 0..=`max_lag` (< N), on mean-removed series.
pub fn cross_correlation(e: &[f64], u: &[f64], max_lag: usize) -> Result<Vec<f64>, IdentError> {
    let n = same_len(e, u, "u")?;
    check_lag(max_lag, n)?;
    let (x, v) = (demean(e), demean(u));
    let nf = n as f64;
    let se = (x.iter().map(|a| a * a).sum::<f64>() / nf).sqrt();
    let su = (v.iter().map(|a| a * a).sum::<f64>() / nf).sqrt();
    Ok((0..=max_lag)
        .map(|k| {
            let c = v.iter().zip(&x[k..]).map(|(a, b)| a * b).sum::<f64>() / nf;
            if se > 0.0 && su > 0.0 { c / (se * su) } else { 0.0 }
        })
        .collect())
}

/// Validates a model from its output ŷ (simulation or prediction) on data (u, y): residuals
/// e = y − ŷ, fit percentage, and the residual tests of §2.8 with the 95 % bound 1.96/√N.
///
/// Decision rule: `white` / `independent` are true when at most 5 % of the tested lags
/// (⌊0.05·count⌋) fall outside the bound. Note that for truly white residuals each lag exceeds
/// the bound with probability 5 %, so this rule rejects white noise fairly often (≈26 % for
/// 20 lags); treat a marginal failure as a warning, a pattern as a model inadequacy.
pub fn validate(y: &[f64], yhat: &[f64], u: &[Vec<f64>], max_lag: usize) -> Result<Validation, IdentError> {
    let n = same_len(y, yhat, "yhat")?;
    let e: Vec<f64> = y.iter().zip(yhat).map(|(a, b)| a - b).collect();
    let autocorrelation = autocorrelation(&e, max_lag)?;
    let cross_correlation = u
        .iter()
        .enumerate()
        .map(|(j, uj)| {
            cross_correlation(&e, uj, max_lag).map_err(|err| match err {
                IdentError::LengthMismatch { expected, got, .. } => {
                    IdentError::LengthMismatch { name: format!("u[{j}]"), expected, got }
                }
                other => other,
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let bound = 1.96 / (n as f64).sqrt();
    let whiteness_failures = autocorrelation[1..].iter().filter(|r| r.abs() > bound).count();
    let cross_failures = cross_correlation.iter().flatten().filter(|r| r.abs() > bound).count();
    let allowed = |count: usize| (0.05 * count as f64).floor() as usize;
    Ok(Validation {
        fit_percent: fit_percent(y, yhat)?,
        white: whiteness_failures <= allowed(max_lag),
        independent: cross_failures <= allowed(u.len() * (max_lag + 1)),
        autocorrelation,
        cross_correlation,
        bound,
        whiteness_failures,
        cross_failures,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::signals::{gbn, white_noise};

    #[test]
    fn exact_model_fits_100_percent() {
        let y = gbn(200, 3.0, 1).unwrap();
        assert_eq!(fit_percent(&y, &y).unwrap(), 100.0);
        // ŷ = ȳ gives 0 %.
        let m = y.iter().sum::<f64>() / 200.0;
        assert!(fit_percent(&y, &vec![m; 200]).unwrap().abs() < 1e-12);
        assert!(fit_percent(&y, &y[..10]).is_err());
    }

    #[test]
    fn white_noise_passes_and_ar1_fails() {
        let (n, lags) = (1000, 20);
        let mut passes = 0;
        for seed in 0..40u64 {
            let e = white_noise(n, 1.0, seed).unwrap();
            let u = gbn(n, 5.0, 1000 + seed).unwrap();
            let v = validate(&e, &vec![0.0; n], std::slice::from_ref(&u), lags).unwrap();
            assert!((v.bound - 1.96 / (n as f64).sqrt()).abs() < 1e-15);
            assert_eq!(v.autocorrelation[0], 1.0);
            if v.white {
                passes += 1;
            }
            // AR(1) residual e(t) = 0.5 e(t−1) + w(t): ρ(k) = 0.5^k ≫ bound at lags 1..4.
            let mut ar = e.clone();
            for t in 1..n {
                ar[t] += 0.5 * ar[t - 1];
            }
            let va = validate(&ar, &vec![0.0; n], &[u], lags).unwrap();
            assert!(!va.white && va.whiteness_failures >= 3, "seed {seed}");
            assert!((va.autocorrelation[1] - 0.5).abs() < 0.1);
        }
        // Binomial: P(≤1 of 20 lags exceeds) ≈ 0.74, so ≈ 29.6 of 40 expected (sd 2.8).
        assert!(passes >= 22, "{passes}/40 white-noise records passed");
    }

    #[test]
    fn residual_correlated_with_input_fails_independence() {
        let n = 2000;
        let u = gbn(n, 5.0, 4).unwrap();
        let w = white_noise(n, 0.3, 5).unwrap();
        // Missing term 0.5 u(t−2) in the model: cross-correlation peak at lag 2.
        let e: Vec<f64> = (0..n).map(|t| w[t] + if t >= 2 { 0.5 * u[t - 2] } else { 0.0 }).collect();
        let v = validate(&e, &vec![0.0; n], &[u], 10).unwrap();
        assert!(!v.independent);
        let cc = &v.cross_correlation[0];
        let kmax = (0..=10).max_by(|&a, &b| cc[a].abs().total_cmp(&cc[b].abs())).unwrap();
        assert_eq!(kmax, 2);
    }

    #[test]
    fn correlation_rejects_bad_lags() {
        assert!(autocorrelation(&[1.0, 2.0, 3.0], 3).is_err());
        assert!(cross_correlation(&[1.0, 2.0, 3.0], &[1.0, 2.0], 1).is_err());
    }
}
