//! Is a sparse square matrix numerically singular, and along which direction? A sparse estimate
//! of the extreme singular values, in O(nnz) per iteration instead of the dense SVD's O(n³):
//!
//! - `σ_max` by power iteration on `AᵀA` (sparse products; a lower bound, within a few per cent
//!   after the fixed number of iterations used here);
//! - `σ_min` and its right singular vector `v` by inverse iteration on `AᵀA`, each step one solve
//!   with `Aᵀ` and one with `A` on the held sparse LU: `z = A⁻¹ A⁻ᵀ v`, `v ← z/‖z‖`. A start
//!   vector with a component `c` along `v_min` is amplified by `(σ₂/σ_min)²` per step relative to
//!   the rest, so a matrix with `σ_min ≤ 10⁻¹² σ_max` shows it after one or two steps; the estimate
//!   `‖A v‖` is an upper bound of `σ_min` at every step (Golub & Van Loan, *Matrix Computations*,
//!   4th ed., §8.2.2 and §7.6.1).
//!
//! A matrix whose LU finds no pivot (or whose factors give a non-finite solution) is singular to
//! working precision: the inverse iteration then runs on `A + εI` with `ε = 10⁻⁸ σ_max` only to
//! find the direction, which it amplifies by about `σ₂/ε` per step (the classical use of a shift
//! at an exact eigenvalue; a shift nearer round-off would cancel to a zero pivot again). Only if
//! that too finds no pivot is the pivot-less column reported.

use crate::sparse::{SparseError, SparseLu};

/// Power and inverse iterations at most (each stops earlier once its estimate settles).
const MAX_ITERATIONS: usize = 8;

/// The estimate of a matrix's extreme singular values.
#[derive(Debug, Clone, PartialEq)]
pub enum Rank {
    /// Factorized: estimates of `σ_max`, `σ_min` (an upper bound) and the unit vector `v` with
    /// `‖A v‖ = σ_min`.
    Estimated {
        /// Largest singular value (a lower bound).
        sigma_max: f64,
        /// Smallest singular value (an upper bound).
        sigma_min: f64,
        /// Its right singular vector.
        v: Vec<f64>,
    },
    /// Singular to working precision (no pivot, or a non-finite solution): `v`, the null
    /// direction found by the shifted inverse iteration.
    Singular {
        /// The null direction (unit vector).
        v: Vec<f64>,
    },
    /// The LU found no pivot for this column even shifted.
    Pivotless(Option<usize>),
}

/// `y = A x` for the triplets `a` (duplicates summed).
fn mul(a: &[(usize, usize, f64)], x: &[f64], y: &mut [f64]) {
    y.iter_mut().for_each(|v| *v = 0.0);
    a.iter().for_each(|&(i, j, v)| y[i] += v * x[j]);
}

/// `y = Aᵀ x`.
fn mul_t(a: &[(usize, usize, f64)], x: &[f64], y: &mut [f64]) {
    y.iter_mut().for_each(|v| *v = 0.0);
    a.iter().for_each(|&(i, j, v)| y[j] += v * x[i]);
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|a| a * a).sum::<f64>().sqrt()
}

/// A deterministic start vector with components of both signs and uneven sizes, so that it is
/// not orthogonal to a singular vector of a structured matrix (a vector of ones often is).
fn start(n: usize) -> Vec<f64> {
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut v: Vec<f64> = (0..n)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect();
    let k = norm(&v);
    v.iter_mut().for_each(|a| *a /= k);
    v
}

/// Whether the held factors solve a generic right-hand side to finite values (an exactly zero
/// pivot passes the factorization and shows here).
fn solvable(lu: &mut SparseLu, n: usize) -> bool {
    let mut z = start(n);
    lu.solve_in_place(&mut z).is_ok()
}

/// Largest singular value of the `n × n` matrix `a`, by power iteration on `AᵀA`.
fn sigma_max(n: usize, a: &[(usize, usize, f64)]) -> f64 {
    let (mut v, mut w, mut z) = (start(n), vec![0.0; n], vec![0.0; n]);
    let mut sigma = 0.0;
    for _ in 0..2 * MAX_ITERATIONS {
        mul(a, &v, &mut w);
        mul_t(a, &w, &mut z);
        let (s, k) = (norm(&w), norm(&z));
        if k == 0.0 {
            return s;
        }
        z.iter().zip(v.iter_mut()).for_each(|(a, b)| *b = a / k);
        let settled = (s - sigma).abs() <= 1e-3 * s;
        sigma = s;
        if settled {
            break;
        }
    }
    sigma
}

/// Estimate the extreme singular values of the `n × n` matrix `a` (see the module documentation).
pub fn estimate(n: usize, a: &[(usize, usize, f64)]) -> Rank {
    let smax = sigma_max(n, a);
    let mut lu = SparseLu::default();
    let singular = match lu.factor(n, a) {
        Ok(()) => false,
        Err(SparseError::Singular { .. } | SparseError::NonFinite { .. }) => true,
        Err(_) => return Rank::Pivotless(None),
    };
    let singular = singular || !solvable(&mut lu, n);
    if singular {
        let shift = 1e-8 * smax.max(f64::MIN_POSITIVE);
        let mut shifted = a.to_vec();
        shifted.extend((0..n).map(|i| (i, i, shift)));
        match lu.factor(n, &shifted) {
            Ok(()) => {}
            Err(SparseError::Singular { index, .. }) => return Rank::Pivotless(lu.pivot_column(index)),
            Err(_) => return Rank::Pivotless(None),
        }
    }
    let (mut v, mut av) = (start(n), vec![0.0; n]);
    let mut smin = f64::INFINITY;
    for k in 0..MAX_ITERATIONS {
        let mut z = v.clone();
        if lu.solve_transpose_in_place(&mut z).is_err() || lu.solve_in_place(&mut z).is_err() {
            return Rank::Pivotless(None);
        }
        let size = norm(&z);
        z.iter().zip(v.iter_mut()).for_each(|(a, b)| *b = a / size);
        mul(a, &v, &mut av);
        let s = norm(&av);
        let settled = k >= 1 && (smin - s).abs() <= 1e-3 * s;
        smin = s;
        if settled {
            break;
        }
    }
    if singular { Rank::Singular { v } } else { Rank::Estimated { sigma_max: smax, sigma_min: smin, v } }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tridiagonal `[-1, 2, -1]` matrix of order n: σ = 2 − 2 cos(kπ/(n+1)), k = 1 … n.
    fn laplacian(n: usize) -> Vec<(usize, usize, f64)> {
        let mut a = Vec::new();
        for i in 0..n {
            a.push((i, i, 2.0));
            if i > 0 {
                a.push((i, i - 1, -1.0));
                a.push((i - 1, i, -1.0));
            }
        }
        a
    }

    #[test]
    fn singular_values_of_the_laplacian_match_their_closed_form() {
        let n = 50;
        let pi = std::f64::consts::PI;
        let Rank::Estimated { sigma_max, sigma_min, v } = estimate(n, &laplacian(n)) else { panic!("factorizes") };
        let exact_max = 2.0 - 2.0 * (n as f64 * pi / (n as f64 + 1.0)).cos();
        let exact_min = 2.0 - 2.0 * (pi / (n as f64 + 1.0)).cos();
        assert!((sigma_max - exact_max).abs() < 5e-2 * exact_max, "{sigma_max} vs {exact_max}");
        assert!(sigma_min >= exact_min * (1.0 - 1e-12) && sigma_min < 1.01 * exact_min, "{sigma_min} vs {exact_min}");
        // v is the first eigenvector sin(jπ/(n+1)), up to sign.
        let s: Vec<f64> = (0..n).map(|j| ((j + 1) as f64 * pi / (n as f64 + 1.0)).sin()).collect();
        let cos = v.iter().zip(&s).map(|(a, b)| a * b).sum::<f64>().abs() / norm(&s);
        assert!(cos > 0.99, "{cos}");
    }

    #[test]
    fn a_nearly_singular_matrix_shows_its_null_direction() {
        // [[1, 1], [1, 1 + 1e-14]] ⊕ 3: σ_min ≈ 5e-15 along (1, −1, 0)/√2.
        let a = vec![(0, 0, 1.0), (0, 1, 1.0), (1, 0, 1.0), (1, 1, 1.0 + 1e-14), (2, 2, 3.0)];
        let Rank::Estimated { sigma_max, sigma_min, v } = estimate(3, &a) else { panic!("factorizes") };
        assert!(sigma_min < 1e-13 && (sigma_max - 3.0).abs() < 1e-2, "{sigma_min} {sigma_max}");
        assert!((v[0] + v[1]).abs() < 1e-6 && v[2].abs() < 1e-6 && (v[0].abs() - 0.5f64.sqrt()).abs() < 1e-6, "{v:?}");
    }

    #[test]
    fn an_exactly_singular_matrix_shows_its_null_direction_through_the_shift() {
        // [[1, 2], [2, 4]]: rank 1, null vector (2, −1)/√5; σ_max = 5.
        let a = vec![(0, 0, 1.0), (1, 0, 2.0), (0, 1, 2.0), (1, 1, 4.0)];
        let Rank::Singular { v } = estimate(2, &a) else { panic!("singular") };
        assert!((v[0].abs() - 2.0 / 5f64.sqrt()).abs() < 1e-7 && (v[0] + 2.0 * v[1]).abs() < 1e-7, "{v:?}");
        // A structurally singular pattern (column 1 empty): the shift puts a pivot on the
        // diagonal, and the null direction is e₁.
        let a = vec![(0, 0, 1.0), (1, 0, 1.0)];
        let Rank::Singular { v } = estimate(2, &a) else { panic!("singular") };
        assert!(v[0].abs() < 1e-7 && (v[1].abs() - 1.0).abs() < 1e-7, "{v:?}");
    }

    #[test]
    fn a_singular_plant_jacobian_whose_shifted_pivot_would_cancel_shows_its_direction() {
        // An uncontrolled tank's scaled Jacobian in miniature: N enters only h = v N / A, and the
        // balance F_in − F_out = 0 holds both flows; a shift at round-off cancels in elimination.
        // Unknowns (N, h, F_in, F_out) with F_in fixed: null direction (N, h) ∝ (1, v/A).
        let a = vec![(0, 0, -0.5), (0, 1, 1.0), (1, 2, 1.0), (1, 3, -1.0), (2, 2, 1.0), (3, 3, 1.0), (3, 2, -1.0)];
        let Rank::Singular { v } = estimate(4, &a) else { panic!("singular") };
        assert!((v[1] - 0.5 * v[0]).abs() < 1e-7 && v[2].abs() < 1e-7 && v[3].abs() < 1e-7, "{v:?}");
    }
}
