//! ARX estimation (Eq 7-31, 7-36 to 7-38) by QR least squares, order selection by AIC
//! (§2.8), simulation and one-step prediction.

use crate::StepResponse;
use crate::data::{check_len, check_miso, check_nk, check_order, check_rows};
use crate::error::IdentError;
use crate::linalg::{covariance, qr_lstsq, step_bf};
use crate::validate::fit_percent;
use faer::Mat;
use serde::{Deserialize, Serialize};

/// MISO ARX model A(q) y(t) = Σ_j B_j(q) u_j(t − nk_j) + e(t) (Eq 7-31),
/// A = 1 + a₁q⁻¹ + … + a_na q⁻ⁿᵃ, B_j = b_j1 + b_j2 q⁻¹ + … + b_j,nb q⁻ⁿᵇ⁺¹ (Eq 7-27).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ArxModel {
    /// Order of A.
    pub na: usize,
    /// Number of B coefficients per input.
    pub nb: usize,
    /// Delay per input (samples).
    pub nk: Vec<usize>,
    /// a₁..a_na (the leading 1 is implicit).
    pub a: Vec<f64>,
    /// b_j1..b_j,nb per input.
    pub b: Vec<Vec<f64>>,
    /// Steady-state gain per input, B_j(1)/A(1).
    pub gain: Vec<f64>,
    /// Criterion V = (1/N)Σ ½ e²(t) over the regression rows (Eq 7-35).
    pub loss: f64,
    /// Noise variance estimate λ̂ = Σ e²/(N − d).
    pub noise_variance: f64,
    /// Covariance of θ = [a; b_1; …; b_nu], λ̂ (ΦᵀΦ)⁻¹ (row-major d × d).
    pub covariance: Vec<Vec<f64>>,
    /// Standard errors √diag(P), same order as θ.
    pub std_errors: Vec<f64>,
    /// Akaike criterion ln((1/N)Σe²) + 2d/N (§2.8, toolbox definition).
    pub aic: f64,
    /// Number of regression rows N.
    pub rows: usize,
}

/// One candidate of [`arx_select`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OrderScore {
    /// na = nb = order.
    pub order: usize,
    /// AIC on the estimation data.
    pub aic: f64,
    /// Loss V (Eq 7-35) on the estimation data.
    pub loss: f64,
    /// One-step prediction loss V = (1/N)Σ½e² on the validation data.
    pub val_loss: f64,
    /// Simulation fit (%) on the validation data.
    pub val_fit_percent: f64,
}

fn start_row(na: usize, nb: usize, nk: &[usize]) -> usize {
    nk.iter().map(|&d| d + nb - 1).max().unwrap_or(0).max(na)
}

/// Fits an ARX model by linear least squares (Eq 7-38, θ̂ = [Σφφᵀ]⁻¹Σφy) computed by QR of
/// the regressor matrix (§2.4: QR rather than normal equations). Regressor (Eq 7-37):
/// φ(t) = [−y(t−1)…−y(t−na), u_j(t−nk_j)…u_j(t−nk_j−nb+1) for each j].
///
/// `na` ∈ 0..=50, `nb` ∈ 1..=50, `nk` one delay per input (≤ 1000). Rows start where all
/// regressors are available (no pre-sample values are assumed).
pub fn arx(u: &[Vec<f64>], y: &[f64], na: usize, nb: usize, nk: &[usize]) -> Result<ArxModel, IdentError> {
    let n = check_miso(u, y)?;
    check_order("na", na, false)?;
    check_order("nb", nb, true)?;
    check_nk(nk, u.len())?;
    let nu = u.len();
    let d = na + nu * nb;
    let t0 = start_row(na, nb, nk);
    let rows = n.saturating_sub(t0);
    check_rows("ARX model", rows, d)?;
    let x = Mat::<f64>::from_fn(rows, d, |r, c| {
        let t = r + t0;
        if c < na {
            -y[t - c - 1]
        } else {
            let (j, k) = ((c - na) / nb, (c - na) % nb);
            u[j][t - nk[j] - k]
        }
    });
    let sol =
        qr_lstsq(&x, &y[t0..]).map_err(|c| IdentError::RankDeficient { column: c, name: param_name(c, na, nb) })?;
    let rss: f64 = (0..rows).map(|r| (y[r + t0] - (0..d).map(|c| x[(r, c)] * sol.theta[c]).sum::<f64>()).powi(2)).sum();
    let lambda = rss / (rows - d) as f64;
    let covariance = covariance(&sol.rinv, lambda);
    let a = sol.theta[..na].to_vec();
    let b: Vec<Vec<f64>> = (0..nu).map(|j| sol.theta[na + j * nb..na + (j + 1) * nb].to_vec()).collect();
    let a1 = 1.0 + a.iter().sum::<f64>();
    let mean_sq = rss / rows as f64;
    Ok(ArxModel {
        na,
        nb,
        nk: nk.to_vec(),
        gain: b.iter().map(|bj| bj.iter().sum::<f64>() / a1).collect(),
        a,
        b,
        loss: 0.5 * mean_sq,
        noise_variance: lambda,
        std_errors: (0..d).map(|i| covariance[i][i].sqrt()).collect(),
        covariance,
        aic: mean_sq.ln() + 2.0 * d as f64 / rows as f64,
        rows,
    })
}

fn param_name(c: usize, na: usize, nb: usize) -> String {
    if c < na {
        format!("a[{}]", c + 1)
    } else {
        format!("b[{}][{}] (input u[{}])", (c - na) / nb, (c - na) % nb + 1, (c - na) / nb)
    }
}

fn check_model_inputs(nk: &[usize], u: &[Vec<f64>]) -> Result<usize, IdentError> {
    if u.len() != nk.len() {
        return Err(IdentError::LengthMismatch {
            name: "u (number of inputs)".into(),
            expected: nk.len(),
            got: u.len(),
        });
    }
    let n = u.first().map_or(0, |s| s.len());
    for (j, uj) in u.iter().enumerate() {
        if uj.len() != n {
            return Err(IdentError::LengthMismatch { name: format!("u[{j}]"), expected: n, got: uj.len() });
        }
    }
    Ok(n)
}

/// Pure simulation of an ARX model (no measured-output feedback), zero initial conditions:
/// ŷ(t) = −Σ a_k ŷ(t−k) + Σ_j Σ_i b_ji u_j(t−nk_j−i+1).
pub fn simulate_arx(model: &ArxModel, u: &[Vec<f64>]) -> Result<Vec<f64>, IdentError> {
    let n = check_model_inputs(&model.nk, u)?;
    let mut y = vec![0.0; n];
    for (j, uj) in u.iter().enumerate() {
        let w = crate::linalg::filter_bf(&model.b[j], &model.a, model.nk[j], uj);
        y.iter_mut().zip(w).for_each(|(s, v)| *s += v);
    }
    Ok(y)
}

/// One-step-ahead prediction ŷ(t) = B(q)u(t) + (1 − A(q))y(t) (Eq 7-36); pre-sample values
/// are taken as zero.
pub fn predict_arx(model: &ArxModel, u: &[Vec<f64>], y: &[f64]) -> Result<Vec<f64>, IdentError> {
    let n = check_model_inputs(&model.nk, u)?;
    if y.len() != n {
        return Err(IdentError::LengthMismatch { name: "y".into(), expected: n, got: y.len() });
    }
    Ok((0..n)
        .map(|t| {
            let ar: f64 = (0..model.na).filter(|k| t > *k).map(|k| -model.a[k] * y[t - k - 1]).sum();
            let ex: f64 = (0..u.len())
                .map(|j| {
                    (0..model.nb)
                        .filter_map(|i| t.checked_sub(model.nk[j] + i).map(|s| model.b[j][i] * u[j][s]))
                        .sum::<f64>()
                })
                .sum();
            ar + ex
        })
        .collect())
}

/// Order selection: fits na = nb = n for n = 1..=`max_order` (≤ 50) on the estimation data
/// and returns the model with the least AIC = ln V + 2d/N (§2.8) together with every
/// candidate's score, including its validation one-step loss and simulation fit.
pub fn arx_select(
    est: (&[Vec<f64>], &[f64]),
    val: (&[Vec<f64>], &[f64]),
    max_order: usize,
    nk: &[usize],
) -> Result<(ArxModel, Vec<OrderScore>), IdentError> {
    check_order("max_order", max_order, true)?;
    check_miso(val.0, val.1)?;
    let nval = val.1.len();
    let mut best: Option<ArxModel> = None;
    let mut scores = Vec::with_capacity(max_order);
    for order in 1..=max_order {
        let m = arx(est.0, est.1, order, order, nk)?;
        let t0 = start_row(order, order, nk).min(nval);
        let pred = predict_arx(&m, val.0, val.1)?;
        let val_loss = 0.5 * (t0..nval).map(|t| (val.1[t] - pred[t]).powi(2)).sum::<f64>() / (nval - t0).max(1) as f64;
        let sim = simulate_arx(&m, val.0)?;
        scores.push(OrderScore {
            order,
            aic: m.aic,
            loss: m.loss,
            val_loss,
            val_fit_percent: fit_percent(val.1, &sim)?,
        });
        if best.as_ref().is_none_or(|b| m.aic < b.aic) {
            best = Some(m);
        }
    }
    best.map(|b| (b, scores)).ok_or(IdentError::BadOrder {
        field: "max_order".into(),
        value: max_order,
        reason: "no candidate",
    })
}

impl StepResponse for ArxModel {
    fn step_response(&self, n: usize) -> Result<Vec<Vec<f64>>, IdentError> {
        check_len(n)?;
        Ok((0..self.b.len()).map(|j| step_bf(&self.b[j], &self.a, self.nk[j], n)).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::signals::{gbn, white_noise};

    /// y(t) = −a1 y(t−1) − a2 y(t−2) + Σ_j B_j u_j(t−nk_j) + e(t).
    fn simulate_true(u: &[Vec<f64>], a: &[f64], b: &[Vec<f64>], nk: &[usize], e: &[f64]) -> Vec<f64> {
        let n = e.len();
        let mut y = vec![0.0; n];
        for t in 0..n {
            let mut s = e[t];
            for (k, ak) in a.iter().enumerate() {
                if t > k {
                    s -= ak * y[t - k - 1];
                }
            }
            for j in 0..u.len() {
                for (i, bi) in b[j].iter().enumerate() {
                    if let Some(tt) = t.checked_sub(nk[j] + i) {
                        s += bi * u[j][tt];
                    }
                }
            }
            y[t] = s;
        }
        y
    }

    const A: [f64; 2] = [-1.5, 0.7];

    fn b_true() -> Vec<Vec<f64>> {
        vec![vec![1.0, 0.5], vec![-0.4, 0.3]]
    }

    #[test]
    fn arx_recovers_noise_free_two_input_system() {
        let n = 600;
        let u = vec![gbn(n, 4.0, 1).unwrap(), gbn(n, 6.0, 2).unwrap()];
        let nk = [1, 3];
        let y = simulate_true(&u, &A, &b_true(), &nk, &vec![0.0; n]);
        let m = arx(&u, &y, 2, 2, &nk).unwrap();
        for (x, t) in m.a.iter().zip(A) {
            assert!((x - t).abs() < 1e-9);
        }
        for (bj, tj) in m.b.iter().zip(b_true()) {
            for (x, t) in bj.iter().zip(tj) {
                assert!((x - t).abs() < 1e-9);
            }
        }
        // Gains B(1)/A(1), A(1) = 1 − 1.5 + 0.7 = 0.2.
        assert!((m.gain[0] - 1.5 / 0.2).abs() < 1e-8);
        assert!((m.gain[1] + 0.1 / 0.2).abs() < 1e-8);
        // Simulation reproduces the noise-free output exactly.
        let sim = simulate_arx(&m, &u).unwrap();
        assert!(sim.iter().zip(&y).all(|(a, b)| (a - b).abs() < 1e-7));
        let st = m.step_response(200).unwrap();
        assert!((st[0][199] - 7.5).abs() < 1e-6 && st[1][2] == 0.0);
    }

    #[test]
    fn arx_select_picks_true_order_on_noisy_data() {
        let nk = [1, 3];
        let mut correct = 0;
        for seed in 0..20u64 {
            let n = 1500;
            let u = vec![gbn(n, 4.0, 100 + seed).unwrap(), gbn(n, 6.0, 200 + seed).unwrap()];
            let e = white_noise(n, 0.2, 300 + seed).unwrap();
            let y = simulate_true(&u, &A, &b_true(), &nk, &e);
            let (ue, uv) = (
                vec![u[0][..1000].to_vec(), u[1][..1000].to_vec()],
                vec![u[0][1000..].to_vec(), u[1][1000..].to_vec()],
            );
            let (m, scores) = arx_select((&ue, &y[..1000]), (&uv, &y[1000..]), 5, &nk).unwrap();
            assert_eq!(scores.len(), 5);
            assert!(m.na >= 2, "seed {seed}: underfit order {}", m.na);
            // The underfit order 1 must have a clearly worse validation loss than order 2.
            assert!(scores[0].val_loss > 1.2 * scores[1].val_loss);
            if m.na == 2 {
                correct += 1;
            }
        }
        // AIC is not consistent: it overfits with probability ~P(χ²₃ > 6) ≈ 0.11 per order.
        assert!(correct >= 13, "true order chosen {correct}/20");
    }

    #[test]
    fn arx_errors_name_the_problem() {
        let n = 100;
        let u = vec![gbn(n, 4.0, 1).unwrap(), vec![0.3; n]];
        let y = gbn(n, 3.0, 9).unwrap();
        assert_eq!(arx(&u, &y, 2, 2, &[1, 1]).unwrap_err(), IdentError::ConstantInput { input: 1 });
        let u1 = vec![u[0].clone()];
        // na = nb = 2, nk = 1: rows = 15 − 2 = 13, needed d + max(d, 10) = 14.
        let e = arx(&[u[0][..15].to_vec()], &y[..15], 2, 2, &[1]).unwrap_err();
        assert_eq!(e, IdentError::TooShort { what: "ARX model", needed: 14, got: 13 });
        let e = arx(&u1, &y[..99], 2, 2, &[1]).unwrap_err();
        assert!(matches!(e, IdentError::LengthMismatch { .. }));
        let e = arx(&u1, &y, 2, 2, &[1, 2]).unwrap_err();
        assert!(matches!(e, IdentError::LengthMismatch { .. }));
        assert!(matches!(arx(&u1, &y, 51, 2, &[1]), Err(IdentError::BadOrder { .. })));
        // Two identical inputs: rank deficient, named parameter of input 1.
        let u2 = vec![u[0].clone(), u[0].clone()];
        match arx(&u2, &y, 1, 1, &[1, 1]).unwrap_err() {
            IdentError::RankDeficient { column, name } => {
                assert_eq!(column, 2);
                assert!(name.contains("u[1]"), "{name}");
            }
            e => panic!("unexpected {e}"),
        }
    }
}
