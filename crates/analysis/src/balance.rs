//! Diagonal balancing of a state matrix before an orthogonal reduction (the frequency response by
//! Laub's method, the eigenvalues): LAPACK's `dgebal` without permutation.

use faer::Mat;

/// The diagonal `s` (powers of 2) that balances `A`: `S⁻¹ A S` with `S = diag(s)` has each
/// state's off-diagonal row and column 1-norms within a factor of 2 of each other (Parlett &
/// Reinsch 1969, Numer. Math. 13, 293; LAPACK `dgebal` without permutation, as SLICOT's `TB05AD`
/// applies before Laub's method). `G = D + C S (jωI − S⁻¹AS)⁻¹ S⁻¹B` is unchanged and, the
/// factors being powers of 2, so are the entries' digits; what changes is the orthogonal
/// reduction's backward error `ε‖A‖`, which on a plant's state matrix (an energy state in J beside
/// a mole holdup and a controller's integral: entries 10¹⁰ apart) is far larger than the small
/// entries it perturbs — on a CSTR with two PI loops in manual it cost `G(jω)` 1.5e-5 of its value
/// at the phase crossover (and the BLT settings with it), and a CSTR's unstable pair under PI
/// control 1.5e-3 of its real part.
pub(crate) fn balancing(a: &Mat<f64>) -> Vec<f64> {
    let n = a.nrows();
    let mut a = a.clone();
    let mut s = vec![1.0; n];
    let mut converged = false;
    // Each sweep moves a factor by at least 2 only where that cuts the norm sum by 5 %, so the
    // sweeps end; the cap guards against a pathological cycle all the same.
    for _ in 0..64 * n.max(1) {
        if converged {
            break;
        }
        converged = true;
        for i in 0..n {
            let col: f64 = (0..n).filter(|&j| j != i).map(|j| a[(j, i)].abs()).sum();
            let row: f64 = (0..n).filter(|&j| j != i).map(|j| a[(i, j)].abs()).sum();
            if !(col > 0.0 && row > 0.0 && col.is_finite() && row.is_finite()) {
                continue;
            }
            let (mut f, mut c) = (1.0, col);
            while c < row / 2.0 {
                (c, f) = (c * 2.0, f * 2.0);
            }
            while c >= row * 2.0 {
                (c, f) = (c / 2.0, f / 2.0);
            }
            if c + row / f < 0.95 * (col + row) {
                converged = false;
                s[i] *= f;
                for j in 0..n {
                    a[(i, j)] /= f;
                    a[(j, i)] *= f;
                }
            }
        }
    }
    s
}

/// `(S⁻¹ A S, s)` with `s` from [`balancing`]: the same eigenvalues and, with `S⁻¹B` and `CS`, the
/// same transfer function.
pub(crate) fn balanced(a: &Mat<f64>) -> (Mat<f64>, Vec<f64>) {
    let s = balancing(a);
    let n = a.nrows();
    (Mat::from_fn(n, n, |i, j| a[(i, j)] * s[j] / s[i]), s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_balancing_evens_row_and_column_norms_by_powers_of_two() {
        let a = Mat::from_fn(3, 3, |i, j| [[-1.0, 1e8, 0.0], [1e-8, -2.0, 3e6], [0.0, 1e-6, -3.0]][i][j]);
        let s = balancing(&a);
        for (i, f) in s.iter().enumerate() {
            assert_eq!(f.log2().fract(), 0.0, "s[{i}] = {f} is a power of 2");
            let col: f64 = (0..3).filter(|&j| j != i).map(|j| (a[(j, i)] * s[i] / s[j]).abs()).sum();
            let row: f64 = (0..3).filter(|&j| j != i).map(|j| (a[(i, j)] * s[j] / s[i]).abs()).sum();
            assert!(col / row < 4.0 && row / col < 4.0, "state {i}: column {col} against row {row}");
        }
    }
}
