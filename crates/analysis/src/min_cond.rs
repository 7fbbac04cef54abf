//! Minimized (optimally scaled) condition number `γ*(G) = min over diagonal D₁, D₂ > 0 of
//! γ(D₁ G D₂)` of a square gain matrix — the condition number that no choice of units can improve.
//!
//! For 2 × 2 matrices it has the closed form (Grosdidier, Morari & Holt 1985)
//! `γ* = ‖Λ‖₁ + sqrt(‖Λ‖₁² − 1)`, `‖Λ‖₁` the induced 1-norm (largest column sum of `|λ_ij|`).
//!
//! For n × n it is a convex problem: with `M = [[0, G⁻¹], [G, 0]]` and `D = diag(e^t)`,
//! `σ̄(D M D⁻¹) = max(σ̄(K), σ̄(K⁻¹))` for `K = D₂ G D₁⁻¹`, and its minimum over `t` is `sqrt(γ*)`
//! (the balance `σ̄(K) = σ̄(K⁻¹)` is reached by scaling `D₂`). `t ↦ σ̄(e^T M e^{−T})` is convex
//! (Sezginer & Overton 1990), non-smooth where `σ̄` is repeated — which is where the minimum
//! usually is. It is minimized by BFGS with a weak-Wolfe line search, which converges on such
//! non-smooth convex functions (Lewis & Overton 2013); the gradient where `σ̄` is simple is
//! `∂ ln σ̄ / ∂t_k = u_k² − v_k²` (`u`, `v` the singular vectors of `σ̄`).
//!
//! # References
//! - P. Grosdidier, M. Morari, B. R. Holt, Ind. Eng. Chem. Fundam. 24 (1985) 221–235.
//! - R. S. Sezginer, M. L. Overton, *The largest singular value of e^X A e^{−X} is convex on
//!   convex sets of commuting matrices*, IEEE TAC 35 (1990) 229–230.
//! - A. S. Lewis, M. L. Overton, *Nonsmooth optimization via quasi-Newton methods*, Math.
//!   Program. 141 (2013) 135–163.
//! - R. D. Braatz, M. Morari, *Minimizing the Euclidean condition number*, SIAM J. Control Optim.
//!   32 (1994) 1763–1768.

use faer::linalg::solvers::DenseSolveCore;
use faer::{Mat, MatRef};

use crate::error::AnalysisError;
use crate::measures::{rga, svd};

/// Minimized condition number of a square matrix: the closed form for 2 × 2, the convex
/// minimization otherwise.
pub fn minimized_condition_number(g: MatRef<'_, f64>) -> Result<f64, AnalysisError> {
    if g.nrows() != g.ncols() {
        return Err(AnalysisError::Request(format!(
            "the minimized condition number needs a square gain matrix (got {}×{})",
            g.nrows(),
            g.ncols()
        )));
    }
    // γ* does not depend on the units of the signals; the equilibrated matrix keeps the
    // minimization (and its singularity test) away from entries 1e13 apart.
    let e = crate::measures::equilibrated(g);
    match g.nrows() {
        1 => Ok(1.0),
        2 => minimized_condition_number_2x2(e.as_ref()),
        _ => minimized_condition_number_convex(e.as_ref()),
    }
}

/// `γ* = ‖Λ‖₁ + sqrt(‖Λ‖₁² − 1)` for a 2 × 2 matrix.
pub fn minimized_condition_number_2x2(g: MatRef<'_, f64>) -> Result<f64, AnalysisError> {
    let l = rga(g)?;
    let norm1 = (0..2).map(|j| l[(0, j)].abs() + l[(1, j)].abs()).fold(0.0, f64::max);
    Ok(norm1 + (norm1 * norm1 - 1.0).max(0.0).sqrt())
}

/// `ln σ̄(D M D⁻¹)` and its gradient in `t` (`D = diag(e^t)`).
fn objective(m: MatRef<'_, f64>, t: &[f64]) -> Result<(f64, Vec<f64>), AnalysisError> {
    let n = t.len();
    let scaled = Mat::from_fn(n, n, |i, j| m[(i, j)] * (t[i] - t[j]).exp());
    let s = svd(scaled.as_ref())?;
    let grad = (0..n).map(|k| s.u[(k, 0)].powi(2) - s.v[(k, 0)].powi(2)).collect();
    Ok((s.singular_values[0].ln(), grad))
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `γ*` by BFGS on the convex function `ln σ̄(e^T M e^{−T})`; any size.
pub fn minimized_condition_number_convex(g: MatRef<'_, f64>) -> Result<f64, AnalysisError> {
    let n = g.nrows();
    let s = svd(g)?;
    let (smax, smin) = (s.singular_values[0], s.singular_values[n - 1]);
    if smin.is_nan() || smin <= crate::measures::SINGULAR_RATIO * smax {
        return Err(AnalysisError::Singular(
            "the gain matrix is singular: its minimized condition number is infinite".into(),
        ));
    }
    let inv = g.partial_piv_lu().inverse();
    let m = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
        (true, false) => inv[(i, j - n)],
        (false, true) => g[(i - n, j)],
        _ => 0.0,
    });
    let dim = 2 * n;
    let mut t = vec![0.0; dim];
    let (mut f, mut grad) = objective(m.as_ref(), &t)?;
    let mut h = Mat::<f64>::identity(dim, dim);
    for _ in 0..400 {
        let d: Vec<f64> = (0..dim).map(|i| -(0..dim).map(|j| h[(i, j)] * grad[j]).sum::<f64>()).collect();
        let slope = dot(&grad, &d);
        if slope >= 0.0 || slope.abs() < 1e-15 {
            break;
        }
        // Weak Wolfe line search by bracketing (Lewis & Overton 2013, §4.2).
        let (mut lo, mut hi, mut alpha) = (0.0, f64::INFINITY, 1.0);
        let mut accepted = None;
        for _ in 0..60 {
            let trial: Vec<f64> = t.iter().zip(&d).map(|(ti, di)| ti + alpha * di).collect();
            let (ft, gt) = objective(m.as_ref(), &trial)?;
            if ft > f + 1e-4 * alpha * slope {
                hi = alpha;
            } else if dot(&gt, &d) < 0.9 * slope {
                lo = alpha;
            } else {
                accepted = Some((trial, ft, gt));
                break;
            }
            alpha = if hi.is_finite() { 0.5 * (lo + hi) } else { 2.0 * lo.max(alpha) };
        }
        let Some((t_new, f_new, g_new)) = accepted else { break };
        let sv: Vec<f64> = t_new.iter().zip(&t).map(|(a, b)| a - b).collect();
        let yv: Vec<f64> = g_new.iter().zip(&grad).map(|(a, b)| a - b).collect();
        let sy = dot(&sv, &yv);
        let decrease = f - f_new;
        (t, f, grad) = (t_new, f_new, g_new);
        if sy > 1e-300 {
            // H ← (I − ρ s yᵀ) H (I − ρ y sᵀ) + ρ s sᵀ.
            let rho = 1.0 / sy;
            let hy: Vec<f64> = (0..dim).map(|i| (0..dim).map(|j| h[(i, j)] * yv[j]).sum()).collect();
            let yhy = dot(&yv, &hy);
            h = Mat::from_fn(dim, dim, |i, j| {
                h[(i, j)] - rho * (hy[i] * sv[j] + sv[i] * hy[j]) + (rho * rho * yhy + rho) * sv[i] * sv[j]
            });
        }
        if decrease < 1e-15 * f.abs().max(1.0) {
            break;
        }
    }
    Ok((2.0 * f).exp())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measures::tests::Rng;
    use crate::measures::{condition_number, from_rows};

    #[test]
    fn published_lv_model_has_min_condition_number_138_3() {
        // S&P (2005) §3.6: G = [87.8 −86.4; 108.2 −109.6], γ* = 138.268.
        let g = from_rows(&[vec![87.8, -86.4], vec![108.2, -109.6]]);
        let closed = minimized_condition_number_2x2(g.as_ref()).unwrap();
        assert!((closed - 138.268).abs() < 2e-3, "{closed}");
    }

    #[test]
    fn convex_method_agrees_with_the_2x2_closed_form() {
        let mut rng = Rng::new(31);
        for _ in 0..25 {
            let g = rng.matrix(2, 2);
            let closed = minimized_condition_number_2x2(g.as_ref()).unwrap();
            let convex = minimized_condition_number_convex(g.as_ref()).unwrap();
            assert!((convex - closed).abs() < 1e-6 * closed, "convex {convex} vs closed form {closed}");
        }
    }

    #[test]
    fn convex_method_is_scale_invariant_and_below_the_plain_condition_number() {
        let mut rng = Rng::new(41);
        for n in [3, 4, 5] {
            let g = rng.matrix(n, n);
            let gamma_star = minimized_condition_number(g.as_ref()).unwrap();
            let d1: Vec<f64> = (0..n).map(|_| 10f64.powf(1.5 * rng.next())).collect();
            let d2: Vec<f64> = (0..n).map(|_| 10f64.powf(1.5 * rng.next())).collect();
            let gs = Mat::from_fn(n, n, |i, j| d1[i] * g[(i, j)] * d2[j]);
            let again = minimized_condition_number(gs.as_ref()).unwrap();
            assert!((again - gamma_star).abs() < 1e-5 * gamma_star, "n = {n}: {gamma_star} vs {again}");
            let plain = condition_number(&svd(g.as_ref()).unwrap().singular_values);
            assert!(gamma_star <= plain * (1.0 + 1e-9) && gamma_star >= 1.0);
            // A lower bound: ‖Λ‖_m − 1/γ* ≤ γ* with ‖Λ‖_m = 2 max(‖Λ‖₁, ‖Λ‖_∞) (S&P 2005, eq. A.80).
            let l = rga(g.as_ref()).unwrap();
            let n1 = (0..n).map(|j| (0..n).map(|i| l[(i, j)].abs()).sum::<f64>()).fold(0.0, f64::max);
            let ninf = (0..n).map(|i| (0..n).map(|j| l[(i, j)].abs()).sum::<f64>()).fold(0.0, f64::max);
            assert!(2.0 * n1.max(ninf) - 1.0 / gamma_star <= gamma_star * (1.0 + 1e-6), "n = {n}");
        }
    }

    #[test]
    fn a_scaled_orthogonal_matrix_has_min_condition_number_one() {
        // Q orthogonal (a rotation in the 0–2 plane and a reflection), scaled badly on both sides.
        let (c, s) = (0.6, 0.8);
        let q = from_rows(&[vec![c, 0.0, -s], vec![0.0, -1.0, 0.0], vec![s, 0.0, c]]);
        let g = Mat::from_fn(3, 3, |i, j| [100.0, 1.0, 0.01][i] * q[(i, j)] * [0.1, 10.0, 3.0][j]);
        assert!(condition_number(&svd(g.as_ref()).unwrap().singular_values) > 1e3);
        let gamma_star = minimized_condition_number(g.as_ref()).unwrap();
        assert!((gamma_star - 1.0).abs() < 1e-6, "{gamma_star}");
    }
}
