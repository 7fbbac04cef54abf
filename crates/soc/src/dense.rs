//! Small dense helpers over faer: rows and principal submatrices of a subset, triangular solves
//! with a Cholesky factor, a thin SVD as plain vectors, the Moore–Penrose pseudo-inverse.

use faer::linalg::triangular_solve::{solve_lower_triangular_in_place, solve_upper_triangular_in_place};
use faer::{Mat, MatRef, Par, Side};

use crate::error::SocError;

/// Rows `s` of `m`.
pub(crate) fn rows(m: MatRef<'_, f64>, s: &[usize]) -> Mat<f64> {
    Mat::from_fn(s.len(), m.ncols(), |i, j| m[(s[i], j)])
}

/// The principal submatrix `m[s, s]`.
pub(crate) fn principal(m: MatRef<'_, f64>, s: &[usize]) -> Mat<f64> {
    Mat::from_fn(s.len(), s.len(), |i, j| m[(s[i], s[j])])
}

/// The lower Cholesky factor `L` of a symmetric positive definite `a` (`a = L Lᵀ`).
pub(crate) fn cholesky(a: MatRef<'_, f64>, what: &str) -> Result<Mat<f64>, SocError> {
    let llt = a
        .llt(Side::Lower)
        .map_err(|_| SocError::Numerical(format!("{what} is not positive definite to working precision")))?;
    Ok(llt.L().to_owned())
}

/// `L⁻¹ x` for a lower-triangular `L`.
pub(crate) fn lower_solve(l: MatRef<'_, f64>, x: MatRef<'_, f64>) -> Mat<f64> {
    let mut out = x.to_owned();
    solve_lower_triangular_in_place(l, out.as_mut(), Par::Seq);
    out
}

/// `L⁻ᵀ x` for a lower-triangular `L`.
pub(crate) fn lower_transpose_solve(l: MatRef<'_, f64>, x: MatRef<'_, f64>) -> Mat<f64> {
    let mut out = x.to_owned();
    solve_upper_triangular_in_place(l.transpose(), out.as_mut(), Par::Seq);
    out
}

/// A thin SVD `a = U diag(σ) Vᵀ`, σ non-increasing.
pub(crate) struct ThinSvd {
    pub u: Mat<f64>,
    pub sigma: Vec<f64>,
    pub v: Mat<f64>,
}

pub(crate) fn thin_svd(a: MatRef<'_, f64>) -> Result<ThinSvd, SocError> {
    let s = a.thin_svd().map_err(|e| SocError::Numerical(format!("the SVD did not converge: {e:?}")))?;
    Ok(ThinSvd { u: s.U().to_owned(), sigma: s.S().column_vector().iter().copied().collect(), v: s.V().to_owned() })
}

/// Whether singular values `sigma` (non-increasing) of an `m × n` matrix make it rank-deficient to
/// working precision: σ_min ≤ max(m, n) · ε · σ_max (the rank rule of MATLAB's `rank` and `pinv`).
pub(crate) fn rank_deficient(sigma: &[f64], m: usize, n: usize) -> bool {
    match (sigma.first(), sigma.last()) {
        (Some(&hi), Some(&lo)) => lo <= m.max(n) as f64 * f64::EPSILON * hi,
        _ => true,
    }
}

/// The Moore–Penrose pseudo-inverse, singular values below the rank rule of [`rank_deficient`]
/// dropped.
pub(crate) fn pinv(a: MatRef<'_, f64>) -> Result<Mat<f64>, SocError> {
    let (m, n) = (a.nrows(), a.ncols());
    let s = thin_svd(a)?;
    let tol = m.max(n) as f64 * f64::EPSILON * s.sigma.first().copied().unwrap_or(0.0);
    let k = s.sigma.len();
    Ok(Mat::from_fn(n, m, |i, j| {
        (0..k).filter(|&r| s.sigma[r] > tol).map(|r| s.v[(i, r)] * s.u[(j, r)] / s.sigma[r]).sum()
    }))
}
