//! What certifies an optimum besides the KKT residual: the active set, the shadow prices and the
//! reduced Hessian of the Lagrangian.
//!
//! Reduced Hessian: the active constraints' gradients (and the active bounds' unit rows) are
//! split by Gaussian elimination with complete pivoting into dependent degrees of freedom (one
//! per independent active constraint, the pivots) and free ones; moving free input `j` by one
//! unit while the dependent inputs keep the active constraints at their limits (to first order)
//! is the direction `z_j = e_j − D⁻¹ a_j`. The Hessian of the Lagrangian along the directions,
//! `Zᵀ ∇²L Z`, comes from central differences of the exact gradient of the Lagrangian
//! `∇L = ∇f − Aᵀy` (two plant solves per free input, step `h` = 1e-4 of the input's scale:
//! truncation ~h², rounding ~1e-12/h, so ~1e-8 relative). In the free inputs' own units it is the
//! `Juu` of self-optimizing control when the active set is that of the nominal optimum.

use faer::Mat;

use super::plant::{EvaluationFailure, PlantNlp};
use super::sqp::{Nlp, Point};

/// The relative step of the central differences.
const STEP: f64 = 1e-4;

/// Active rows: the constraint gradients and bound rows (scaled), as dense rows over `n`.
pub(crate) fn active_rows(n: usize, a: &Mat<f64>, constraints: &[usize], bounds: &[usize]) -> Vec<Vec<f64>> {
    let mut rows: Vec<Vec<f64>> = constraints.iter().map(|&i| (0..n).map(|j| a[(i, j)]).collect()).collect();
    rows.extend(bounds.iter().map(|&b| (0..n).map(|j| if j == b { 1.0 } else { 0.0 }).collect()));
    rows
}

/// The split of the degrees of freedom: free ones and the directions `z_j` (scaled).
#[derive(Debug, Clone)]
pub(crate) struct Directions {
    /// The free degrees of freedom.
    pub free: Vec<usize>,
    /// One direction per free input (each of length n).
    pub z: Vec<Vec<f64>>,
    /// The pivots `(active row, dependent degree of freedom)`: one per independent active row.
    pub pivots: Vec<(usize, usize)>,
}

/// Eliminate the active rows with complete pivoting; rows that become zero (dependent active
/// constraints) are dropped.
pub(crate) fn directions(n: usize, rows: &[Vec<f64>]) -> Directions {
    let mut r: Vec<Vec<f64>> = rows.to_vec();
    let scale = r.iter().flatten().fold(0.0_f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
    let mut pivots: Vec<(usize, usize)> = Vec::new();
    let mut used_rows = vec![false; r.len()];
    let mut dependent = vec![false; n];
    loop {
        let mut best = (0.0, 0, 0);
        for (i, row) in r.iter().enumerate().filter(|(i, _)| !used_rows[*i]) {
            for (j, v) in row.iter().enumerate().filter(|(j, _)| !dependent[*j]) {
                if v.abs() > best.0 {
                    best = (v.abs(), i, j);
                }
            }
        }
        if best.0 <= 1e-10 * scale {
            break;
        }
        let (_, pi, pj) = best;
        used_rows[pi] = true;
        dependent[pj] = true;
        pivots.push((pi, pj));
        let prow = r[pi].clone();
        for (i, row) in r.iter_mut().enumerate() {
            if i != pi {
                let f = row[pj] / prow[pj];
                row.iter_mut().zip(&prow).for_each(|(x, p)| *x -= f * p);
            }
        }
    }
    let free: Vec<usize> = (0..n).filter(|&j| !dependent[j]).collect();
    // With the pivot rows reduced, row pi reads prow[pj] δ_pj + Σ_free prow[f] δ_f = 0.
    let z = free
        .iter()
        .map(|&f| {
            let mut z = vec![0.0; n];
            z[f] = 1.0;
            for &(pi, pj) in &pivots {
                z[pj] = -r[pi][f] / r[pi][pj];
            }
            z
        })
        .collect();
    Directions { free, z, pivots }
}

/// `∇L = ∇f − Aᵀy` at a point.
fn lagrangian_gradient<S>(p: &Point<S>, y: &[f64]) -> Vec<f64> {
    (0..p.g.len()).map(|j| p.g[j] - (0..y.len()).map(|i| p.a[(i, j)] * y[i]).sum::<f64>()).collect()
}

/// `Zᵀ ∇²L Z` (scaled, symmetrized) at `v` by central differences of `∇L` along each direction.
///
/// # Errors
/// The plant could not be solved at a displaced point.
pub(crate) fn reduced_hessian(
    nlp: &mut PlantNlp<'_>,
    v: &[f64],
    near: &super::plant::State,
    y: &[f64],
    dirs: &Directions,
) -> Result<Mat<f64>, EvaluationFailure> {
    let k = dirs.z.len();
    let mut hz: Vec<Vec<f64>> = Vec::with_capacity(k);
    for z in &dirs.z {
        let at = |s: f64| -> Vec<f64> { v.iter().zip(z).map(|(vi, zi)| vi + s * STEP * zi).collect() };
        let plus = nlp.evaluate(&at(1.0), Some(near))?;
        let minus = nlp.evaluate(&at(-1.0), Some(near))?;
        let (gp, gm) = (lagrangian_gradient(&plus, y), lagrangian_gradient(&minus, y));
        hz.push(gp.iter().zip(&gm).map(|(a, b)| (a - b) / (2.0 * STEP)).collect());
    }
    let raw = Mat::from_fn(k, k, |a, b| dirs.z[a].iter().zip(&hz[b]).map(|(x, y)| x * y).sum::<f64>());
    Ok(Mat::from_fn(k, k, |a, b| 0.5 * (raw[(a, b)] + raw[(b, a)])))
}

/// Eigenvalues of a small symmetric matrix, ascending.
pub(crate) fn eigenvalues(h: &Mat<f64>) -> Vec<f64> {
    if h.nrows() == 0 {
        return Vec::new();
    }
    let mut e: Vec<f64> = match h.self_adjoint_eigen(faer::Side::Lower) {
        Ok(eig) => eig.S().column_vector().iter().copied().collect(),
        Err(_) => vec![f64::NAN; h.nrows()],
    };
    e.sort_by(f64::total_cmp);
    e
}
