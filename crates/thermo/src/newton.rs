//! Newton's method for small square systems with an exact Jacobian from forward-mode dual
//! numbers, and the dense linear solve it needs (private).

use num_dual::Dual64;

/// Solve `a · x = b` in place by Gaussian elimination with partial pivoting (`a` row-major
/// `m × m`). Returns `None` for a singular or non-finite matrix.
pub(crate) fn solve_dense(a: &mut [f64], b: &mut [f64]) -> Option<()> {
    let m = b.len();
    if a.len() != m * m {
        return None;
    }
    for col in 0..m {
        let mut piv = col;
        for r in col + 1..m {
            if a[r * m + col].abs() > a[piv * m + col].abs() {
                piv = r;
            }
        }
        let pv = a[piv * m + col];
        if pv == 0.0 || !pv.is_finite() {
            return None;
        }
        if piv != col {
            for k in 0..m {
                a.swap(col * m + k, piv * m + k);
            }
            b.swap(col, piv);
        }
        for r in col + 1..m {
            let factor = a[r * m + col] / pv;
            if factor != 0.0 {
                for k in col..m {
                    a[r * m + k] -= factor * a[col * m + k];
                }
                b[r] -= factor * b[col];
            }
        }
    }
    for col in (0..m).rev() {
        let mut s = b[col];
        for k in col + 1..m {
            s -= a[col * m + k] * b[k];
        }
        b[col] = s / a[col * m + col];
    }
    b.iter().all(|v| v.is_finite()).then_some(())
}

/// Rounding level of order-one residuals.
const NOISE: f64 = 1e-14;

fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// Evaluate the residual in f64 (duals with zero derivative part).
fn value<F>(res: &mut F, u: &[f64]) -> Option<Vec<f64>>
where
    F: FnMut(&[Dual64]) -> Option<Vec<Dual64>>,
{
    let ud: Vec<Dual64> = u.iter().map(|&v| Dual64::from(v)).collect();
    let r: Vec<f64> = res(&ud)?.iter().map(|d| d.re).collect();
    r.iter().all(|v| v.is_finite()).then_some(r)
}

/// Newton iteration on `res(u) = 0` from `u`, with the Jacobian built column by column from
/// dual numbers and a backtracking line search on `‖res‖∞`. Stops after a step with
/// `‖Δu‖∞ ≤ 1e-14 (1 + ‖u‖∞)` or when the residual is exactly zero.
///
/// The residuals must be scaled to order one (log K-values, Rachford–Rice sums): when no step
/// decreases a residual below `NOISE` = 1e-14 any further, the iteration is converged.
///
/// Returns the iterations used, or `Err(last residual norm)`.
pub(crate) fn newton<F>(u: &mut [f64], mut res: F, max_iter: usize) -> Result<usize, f64>
where
    F: FnMut(&[Dual64]) -> Option<Vec<Dual64>>,
{
    let m = u.len();
    let mut r = value(&mut res, u).ok_or(f64::NAN)?;
    if r.len() != m {
        return Err(f64::NAN);
    }
    for it in 1..=max_iter {
        let rn = inf_norm(&r);
        if rn == 0.0 {
            return Ok(it - 1);
        }
        let mut jac = vec![0.0; m * m];
        for j in 0..m {
            let ud: Vec<Dual64> =
                u.iter().enumerate().map(|(k, &v)| Dual64::new(v, if k == j { 1.0 } else { 0.0 })).collect();
            let rd = res(&ud).ok_or(rn)?;
            for i in 0..m {
                jac[i * m + j] = rd[i].eps;
            }
        }
        let mut step: Vec<f64> = r.iter().map(|v| -v).collect();
        solve_dense(&mut jac, &mut step).ok_or(rn)?;
        let un = inf_norm(u);
        if inf_norm(&step) <= 1e-14 * (1.0 + un) {
            for (ui, si) in u.iter_mut().zip(&step) {
                *ui += si;
            }
            return Ok(it);
        }
        let mut lambda = 1.0;
        loop {
            let trial: Vec<f64> = u.iter().zip(&step).map(|(a, s)| a + lambda * s).collect();
            match value(&mut res, &trial) {
                Some(rt) if inf_norm(&rt) < rn || (lambda < 1.0 / 1024.0 && inf_norm(&rt) <= rn * 1.0000001) => {
                    u.copy_from_slice(&trial);
                    r = rt;
                    break;
                }
                _ if rn <= NOISE => {
                    // At the rounding floor the full Newton step no longer decreases the residual
                    // (an ill-conditioned Jacobian can make that step exceed the step tolerance).
                    return Ok(it);
                }
                _ => {
                    lambda *= 0.5;
                    if lambda < 1e-10 {
                        return Err(rn);
                    }
                }
            }
        }
    }
    let rn = inf_norm(&r);
    if rn <= NOISE { Ok(max_iter) } else { Err(rn) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dense_solve() {
        let mut a = vec![0.0, 2.0, 1.0, 1.0, 1.0, 1.0, 3.0, 0.0, 1.0];
        let mut b = vec![5.0, 5.0, 6.0];
        solve_dense(&mut a, &mut b).unwrap();
        for (v, e) in b.iter().zip([1.0, 1.0, 3.0]) {
            assert!((v - e).abs() < 1e-14);
        }
    }

    #[test]
    fn newton_solves_nonlinear_system() {
        // x² + y² = 4, x·y = 1 (root near (1.93, 0.52))
        let mut u = vec![2.0, 0.3];
        newton(&mut u, |v| Some(vec![v[0] * v[0] + v[1] * v[1] - 4.0, v[0] * v[1] - 1.0]), 50).unwrap();
        assert!((u[0].powi(2) + u[1].powi(2) - 4.0).abs() < 1e-14);
        assert!((u[0] * u[1] - 1.0).abs() < 1e-14);
    }
}
