//! Small dense helpers on top of faer: QR least squares (Eq 7-50 solved by QR, not by the
//! normal equations, as the spec requires for ill-conditioned FIR regressions), covariance from
//! R⁻¹, and polynomial roots by companion-matrix eigenvalues.

use faer::Mat;
use faer::linalg::solvers::SolveLstsq;

/// Result of a QR least-squares solve of X θ ≈ y.
#[derive(Debug, Clone)]
pub(crate) struct LsSolution {
    /// θ̂ (length d).
    pub theta: Vec<f64>,
    /// R⁻¹ (d × d upper triangular) with X = QR, so (XᵀX)⁻¹ = R⁻¹R⁻ᵀ.
    pub rinv: Mat<f64>,
}

/// Relative threshold on |R_ii| / max|R_jj| below which column i is declared dependent.
const RANK_TOL: f64 = 1e-10;

/// Solves min ‖Xθ − y‖₂ by Householder QR (faer). Returns `Err(column)` with the first
/// column whose R diagonal is negligible (numerically rank deficient), or `Err(0)` if X has
/// fewer rows than columns.
pub(crate) fn qr_lstsq(x: &Mat<f64>, y: &[f64]) -> Result<LsSolution, usize> {
    let (m, d) = (x.nrows(), x.ncols());
    if m < d || y.len() != m || d == 0 {
        return Err(0);
    }
    let qr = x.qr();
    let r = qr.thin_R();
    let rmax = (0..d).map(|i| r[(i, i)].abs()).fold(0.0, f64::max);
    if let Some(bad) =
        (0..d).find(|&i| r[(i, i)].abs().partial_cmp(&(RANK_TOL * rmax)) != Some(std::cmp::Ordering::Greater))
    {
        return Err(bad);
    }
    let rhs = faer::Col::<f64>::from_fn(m, |i| y[i]);
    let sol = qr.solve_lstsq(&rhs);
    let theta: Vec<f64> = (0..d).map(|i| sol[i]).collect();
    // R⁻¹ by back substitution, column by column (R X = I).
    let mut rinv = Mat::<f64>::zeros(d, d);
    for c in 0..d {
        for i in (0..=c).rev() {
            let mut s = if i == c { 1.0 } else { 0.0 };
            for k in (i + 1)..=c {
                s -= r[(i, k)] * rinv[(k, c)];
            }
            rinv[(i, c)] = s / r[(i, i)];
        }
    }
    if theta.iter().any(|v| !v.is_finite()) {
        return Err(0);
    }
    Ok(LsSolution { theta, rinv })
}

/// Covariance λ·R⁻¹R⁻ᵀ = λ(XᵀX)⁻¹ as nested rows.
pub(crate) fn covariance(rinv: &Mat<f64>, lambda: f64) -> Vec<Vec<f64>> {
    let d = rinv.nrows();
    let mut p = vec![vec![0.0; d]; d];
    for (i, row) in p.iter_mut().enumerate() {
        for (j, pij) in row.iter_mut().enumerate() {
            let k0 = i.max(j);
            *pij = lambda * (k0..d).map(|k| rinv[(i, k)] * rinv[(j, k)]).sum::<f64>();
        }
    }
    p
}

/// Largest root modulus of the monic polynomial 1 + c₁q⁻¹ + … + c_n q⁻ⁿ, i.e. of
/// zⁿ + c₁zⁿ⁻¹ + … + c_n (companion-matrix eigenvalues via faer; closed form for n ≤ 1).
/// A polynomial is stable (all roots strictly inside the unit circle) iff this is < 1.
pub(crate) fn max_root_modulus(c: &[f64]) -> f64 {
    let n = c.len();
    match n {
        0 => 0.0,
        1 => c[0].abs(),
        _ => {
            if c.iter().any(|v| !v.is_finite()) {
                return f64::INFINITY;
            }
            let comp = Mat::<f64>::from_fn(n, n, |i, j| {
                if i == 0 {
                    -c[j]
                } else if i == j + 1 {
                    1.0
                } else {
                    0.0
                }
            });
            match comp.eigenvalues() {
                Ok(ev) => ev.iter().map(|z| z.re.hypot(z.im)).fold(0.0, f64::max),
                Err(_) => f64::INFINITY,
            }
        }
    }
}

/// Discrete transfer-function simulation w = q^(−nk) B(q)/F(q) u with zero initial conditions:
/// w(t) = Σ_{k=1..nb} b_k u(t−nk−k+1) − Σ_{k=1..nf} f_k w(t−k) (Eq 7-27 with A = 1).
pub(crate) fn filter_bf(b: &[f64], f: &[f64], nk: usize, u: &[f64]) -> Vec<f64> {
    let n = u.len();
    let mut w = vec![0.0; n];
    for t in 0..n {
        let mut s = 0.0;
        for (k, bk) in b.iter().enumerate() {
            if let Some(i) = t.checked_sub(nk + k) {
                s += bk * u[i];
            }
        }
        for (k, fk) in f.iter().enumerate() {
            if let Some(i) = t.checked_sub(k + 1) {
                s -= fk * w[i];
            }
        }
        w[t] = s;
    }
    w
}

/// Step response of q^(−nk) B/F over n samples (unit step at t = 0).
pub(crate) fn step_bf(b: &[f64], f: &[f64], nk: usize, n: usize) -> Vec<f64> {
    filter_bf(b, f, nk, &vec![1.0; n])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_of_known_polynomials() {
        // (1 − 0.5q⁻¹)(1 − 0.9q⁻¹) = 1 − 1.4q⁻¹ + 0.45q⁻²
        assert!((max_root_modulus(&[-1.4, 0.45]) - 0.9).abs() < 1e-12);
        // z² + 1.21 → |z| = 1.1 (complex pair)
        assert!((max_root_modulus(&[0.0, 1.21]) - 1.1).abs() < 1e-12);
        assert!((max_root_modulus(&[-0.7]) - 0.7).abs() < 1e-15);
    }

    #[test]
    fn lstsq_exact_and_rank_deficient() {
        let x = Mat::<f64>::from_fn(5, 2, |i, j| if j == 0 { 1.0 } else { i as f64 });
        let y: Vec<f64> = (0..5).map(|i| 2.0 + 3.0 * i as f64).collect();
        let s = qr_lstsq(&x, &y).unwrap();
        assert!((s.theta[0] - 2.0).abs() < 1e-12 && (s.theta[1] - 3.0).abs() < 1e-12);
        let x2 = Mat::<f64>::from_fn(5, 2, |i, _| i as f64);
        assert_eq!(qr_lstsq(&x2, &y).unwrap_err(), 1);
    }
}
