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

/// Solves min ‖Xθ − y‖₂ by Householder QR (faer), on the columns of X scaled to unit norm (the
/// rank test is then on the regression's shape, not on its units: lagged outputs that move by
/// 10⁻¹² beside an input moved by 10⁴ W are not "dependent"; the column scaling of MATLAB's
/// `arx`, Ljung, *System Identification*, 2nd ed., §10.1). Returns `Err(column)` with the first
/// column that is zero or whose scaled R diagonal is negligible (numerically rank deficient), or
/// `Err(0)` if X has fewer rows than columns.
pub(crate) fn qr_lstsq(x: &Mat<f64>, y: &[f64]) -> Result<LsSolution, usize> {
    let (m, d) = (x.nrows(), x.ncols());
    if m < d || y.len() != m || d == 0 {
        return Err(0);
    }
    let norms: Vec<f64> = (0..d).map(|j| (0..m).map(|i| x[(i, j)] * x[(i, j)]).sum::<f64>().sqrt()).collect();
    if let Some(zero) = norms.iter().position(|n| !(*n > 0.0 && n.is_finite())) {
        return Err(zero);
    }
    let scaled = Mat::<f64>::from_fn(m, d, |i, j| x[(i, j)] / norms[j]);
    let qr = scaled.qr();
    let r = qr.thin_R();
    let rmax = (0..d).map(|i| r[(i, i)].abs()).fold(0.0, f64::max);
    if let Some(bad) =
        (0..d).find(|&i| r[(i, i)].abs().partial_cmp(&(RANK_TOL * rmax)) != Some(std::cmp::Ordering::Greater))
    {
        return Err(bad);
    }
    let rhs = faer::Col::<f64>::from_fn(m, |i| y[i]);
    let sol = qr.solve_lstsq(&rhs);
    let theta: Vec<f64> = (0..d).map(|i| sol[i] / norms[i]).collect();
    // R⁻¹ of X = Q R_s N (N the column norms): N⁻¹ R_s⁻¹, by back substitution column by column.
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
    for i in 0..d {
        for c in 0..d {
            rinv[(i, c)] /= norms[i];
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

/// Roots of the monic polynomial 1 + c₁q⁻¹ + … + c_n q⁻ⁿ (of zⁿ + c₁zⁿ⁻¹ + … + c_n), by the
/// companion matrix's eigenvalues; none if they cannot be found.
fn roots(c: &[f64]) -> Option<Vec<faer::c64>> {
    let n = c.len();
    if c.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let comp = Mat::<f64>::from_fn(n, n, |i, j| if i == 0 { -c[j] } else { f64::from(u8::from(i == j + 1)) });
    comp.eigenvalues().ok()
}

/// The polynomial of [`max_root_modulus`] with each root on or outside the unit circle moved
/// inside: reflected (`z → 1/z̄`, the same magnitude response up to a gain) and, for a root on the
/// circle, moved to `RADIUS_AFTER_REFLECTION` of it; the coefficients of the product
/// `Π (z − r_i)`, their real parts. An initial model of a slow plant sampled coarsely (an ARX
/// pole at 1.0000128 for τ 4.4e5 s sampled every 2.2e4 s, generated plant 0x199d55bcfab748f3)
/// is an integrator by a hair; Ljung (*System Identification*, 2nd ed., §10.5) starts a
/// prediction-error search from the stabilized model. None if the roots cannot be found.
pub fn stabilized(c: &[f64]) -> Option<Vec<f64>> {
    let mut poly = vec![faer::c64::new(1.0, 0.0)];
    for r in roots(c)? {
        let m2 = r.re * r.re + r.im * r.im;
        let r = if m2 >= 1.0 { faer::c64::new(r.re, r.im) * (RADIUS_AFTER_REFLECTION / m2) } else { r };
        // poly ← poly · (z − r), coefficients from the highest power down.
        poly.push(faer::c64::new(0.0, 0.0));
        for k in (1..poly.len()).rev() {
            poly[k] = poly[k] - poly[k - 1] * r;
        }
    }
    let out: Vec<f64> = poly[1..].iter().map(|z| z.re).collect();
    (max_root_modulus(&out) < 1.0).then_some(out)
}

/// A reflected root is brought to at most this fraction of the unit circle's radius (a root
/// exactly on it would stay there).
const RADIUS_AFTER_REFLECTION: f64 = 0.999;

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

    /// Columns 10¹⁶ apart in size (a lagged output of 10⁻¹² beside an input of 10⁴ W, plant
    /// `0x65d44e50b4502fc9` of the generator) are not dependent: θ is recovered, and the
    /// covariance's diagonal is the unscaled `(XᵀX)⁻¹`'s (closed form for orthogonal columns).
    #[test]
    fn a_regression_is_judged_on_its_shape_not_its_units() {
        let m = 40;
        let small = |i: usize| 1e-12 * (0.3 * i as f64).sin();
        let large = |i: usize| 1e4 * (0.7 * i as f64 + 1.0).cos();
        let x = Mat::<f64>::from_fn(m, 2, |i, j| if j == 0 { small(i) } else { large(i) });
        let theta = [-2.5e7, 3.0e-5];
        let y: Vec<f64> = (0..m).map(|i| theta[0] * small(i) + theta[1] * large(i)).collect();
        let sol = qr_lstsq(&x, &y).expect("two independent columns");
        for (got, want) in sol.theta.iter().zip(theta) {
            assert!((got - want).abs() <= 1e-10 * want.abs(), "{got:e} against {want:e}");
        }
        let p = covariance(&sol.rinv, 1.0);
        let gram = |f: &dyn Fn(usize) -> f64| (0..m).map(|i| f(i) * f(i)).sum::<f64>();
        let cross = (0..m).map(|i| small(i) * large(i)).sum::<f64>();
        let det = gram(&small) * gram(&large) - cross * cross;
        assert!((p[0][0] - gram(&large) / det).abs() <= 1e-8 * p[0][0]);
        assert!((p[1][1] - gram(&small) / det).abs() <= 1e-8 * p[1][1]);
        let zero = Mat::<f64>::from_fn(m, 2, |i, j| if j == 0 { 0.0 } else { large(i) });
        assert_eq!(qr_lstsq(&zero, &y).err(), Some(0));
    }

    /// (1 − 1.25q⁻¹)(1 − 0.5q⁻¹): the root 1.25 reflected to 0.8·0.999 → (1 − 0.7992q⁻¹)(1 −
    /// 0.5q⁻¹); a complex pair of modulus 1.1 to modulus 0.999/1.1 with the same angle; a stable
    /// polynomial is returned as it is.
    #[test]
    fn unstable_roots_are_reflected_inside_the_unit_circle() {
        let p = stabilized(&[-1.75, 0.625]).unwrap();
        let (a, b) = (0.8 * 0.999, 0.5);
        assert!((p[0] + a + b).abs() < 1e-12 && (p[1] - a * b).abs() < 1e-12, "{p:?}");
        let q = stabilized(&[0.0, 1.21]).unwrap();
        let m = 0.999 / 1.1;
        assert!(q[0].abs() < 1e-12 && (q[1] - m * m).abs() < 1e-12, "{q:?}");
        let s = stabilized(&[-1.4, 0.45]).unwrap();
        assert!((s[0] + 1.4).abs() < 1e-12 && (s[1] - 0.45).abs() < 1e-12, "{s:?}");
    }

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
