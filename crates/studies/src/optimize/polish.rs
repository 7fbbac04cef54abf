//! Polishing of the interior point's QP answer: with the active rows it identifies held as
//! equalities, the equality-constrained QP is one dense KKT solve, exact to rounding (the idea of
//! OSQP's solution polishing, Stellato et al. 2020, §5). Near the optimum the QP's objective falls
//! below any interior-point tolerance (`gᵀd ~ 1e-14`), so without it the steps and multipliers
//! there would be the interior point's noise and the SQP could not converge tightly.
//!
//! The polished answer is kept only if it is consistent: every inactive row still holds and every
//! multiplier has the sign of its row; otherwise the interior point's answer stands.

use faer::Mat;
use faer::linalg::solvers::Solve;

use super::qp::QpData;

/// A row held as an equality.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Held {
    /// Constraint `i` at its lower (`true`) or upper limit.
    Limit(usize, bool),
    /// The step's box for variable `j` at its lower (`true`) or upper end.
    Box(usize, bool),
}

/// The polished step: `(d, y, μ)`, or None when it is not consistent.
pub(crate) fn polish(
    data: &QpData<'_>,
    (lo, hi): (&[f64], &[f64]),
    held: &[Held],
) -> Option<(Vec<f64>, Vec<f64>, Vec<f64>)> {
    let (n, m, h) = (data.g.len(), data.c.len(), held.len());
    // [B  −Gᵀ; G  0] [d; λ] = [−g; r], G the held rows.
    let mut k = Mat::<f64>::zeros(n + h, n + h);
    let mut rhs = Mat::<f64>::zeros(n + h, 1);
    for i in 0..n {
        for j in 0..n {
            k[(i, j)] = data.b[(i, j)];
        }
        rhs[(i, 0)] = -data.g[i];
    }
    for (r, row) in held.iter().enumerate() {
        let (coef, target): (Vec<f64>, f64) = match *row {
            Held::Limit(i, lower) => {
                ((0..n).map(|j| data.a[(i, j)]).collect(), if lower { lo[i] } else { hi[i] } - data.c[i])
            }
            Held::Box(j, lower) => {
                ((0..n).map(|c| if c == j { 1.0 } else { 0.0 }).collect(), if lower { data.low[j] } else { data.up[j] })
            }
        };
        for j in 0..n {
            k[(n + r, j)] = coef[j];
            k[(j, n + r)] = -coef[j];
        }
        rhs[(n + r, 0)] = target;
    }
    let sol = k.partial_piv_lu().solve(&rhs);
    if (0..n + h).any(|i| !sol[(i, 0)].is_finite()) {
        return None;
    }
    let d: Vec<f64> = (0..n).map(|i| sol[(i, 0)]).collect();
    let (mut y, mut mu) = (vec![0.0; m], vec![0.0; n]);
    for (r, row) in held.iter().enumerate() {
        let lambda = sol[(n + r, 0)];
        let (sign_ok, slot) = match *row {
            Held::Limit(i, lower) => ((lambda >= 0.0) == lower || lambda == 0.0, &mut y[i]),
            Held::Box(j, lower) => ((lambda >= 0.0) == lower || lambda == 0.0, &mut mu[j]),
        };
        if !sign_ok {
            return None;
        }
        *slot += lambda;
    }
    consistent(data, (lo, hi), &d).then_some((d, y, mu))
}

/// Whether `d` keeps every row of the QP (to rounding).
fn consistent(data: &QpData<'_>, (lo, hi): (&[f64], &[f64]), d: &[f64]) -> bool {
    let n = d.len();
    let tol = 1e-9;
    let in_box = (0..n).all(|j| d[j] >= data.low[j] - tol && d[j] <= data.up[j] + tol);
    in_box
        && (0..data.c.len()).all(|i| {
            let ci = data.c[i] + (0..n).map(|j| data.a[(i, j)] * d[j]).sum::<f64>();
            ci >= lo[i] - tol * (1.0 + lo[i].abs()) && ci <= hi[i] + tol * (1.0 + hi[i].abs())
        })
}
