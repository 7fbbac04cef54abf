//! What certifies an optimum besides the KKT residual: the active set, the shadow prices and the
//! reduced Hessian of the Lagrangian.
//!
//! Reduced Hessian: the active constraints' gradients (and the active bounds' unit rows) are
//! split by Gaussian elimination with complete pivoting into dependent degrees of freedom (one
//! per independent active constraint, the pivots) and free ones; moving free input `j` by one
//! unit while the dependent inputs keep the active constraints at their limits (to first order)
//! is the direction `z_j = e_j − D⁻¹ a_j`. The Hessian of the Lagrangian along the directions,
//! `Zᵀ ∇²L Z`, is exact: the adjoint of the Lagrangian and the plant's second derivatives by
//! hyper-dual numbers ([`super::curvature`]), no plant solve. In the free inputs' own units it is
//! the `Juu` of self-optimizing control when the active set is that of the nominal optimum.

use faer::Mat;

use super::curvature::Curvature;
use super::plant::{EvaluationFailure, PlantNlp};

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

/// `Zᵀ ∇²L Z` (scaled) at the steady state `state` with multipliers `y`: exact, along the
/// physical moves of the directions ([`super::curvature`]).
///
/// # Errors
/// The plant Jacobian is singular there.
pub(crate) fn reduced_hessian(
    nlp: &PlantNlp<'_>,
    state: &super::plant::State,
    y: &[f64],
    dirs: &Directions,
) -> Result<Mat<f64>, EvaluationFailure> {
    let curvature = Curvature::new(nlp.plant(), state, &nlp.lagrangian_weights(y))?;
    let moves = curvature.moves(&dirs.z.iter().map(|z| nlp.input_move(z)).collect::<Vec<_>>())?;
    Ok(curvature.matrix(&moves))
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
