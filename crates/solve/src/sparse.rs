//! Sparse LU on faer, with the symbolic analysis done once per pattern.

use faer::Col;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMat, Triplet};

/// Why a sparse factorization failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SparseError {
    /// The matrix could not be built from the triplets.
    #[error("invalid sparse matrix: {0}")]
    Build(String),
    /// LU failed (structurally or numerically singular).
    #[error("sparse LU failed: {0}")]
    Factor(String),
}

/// A pattern (as triplet positions) and its symbolic LU.
type Symbolic = (Vec<(usize, usize)>, SymbolicLu<usize>);

/// A sparse LU solver that reuses the symbolic factorization while the pattern is unchanged.
#[derive(Debug, Default)]
pub struct SparseLu {
    symbolic: Option<Symbolic>,
}

impl SparseLu {
    /// Factorize the `n × n` matrix given by `triplets` and solve `A x = b` in place.
    pub fn solve(&mut self, n: usize, triplets: &[(usize, usize, f64)], b: &mut [f64]) -> Result<(), SparseError> {
        let trip: Vec<Triplet<usize, usize, f64>> = triplets.iter().map(|&(i, j, v)| Triplet::new(i, j, v)).collect();
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &trip)
            .map_err(|e| SparseError::Build(format!("{e:?}")))?;
        let pattern: Vec<(usize, usize)> = triplets.iter().map(|&(i, j, _)| (i, j)).collect();
        let reuse = matches!(&self.symbolic, Some((p, _)) if *p == pattern);
        if !reuse {
            let sym = SymbolicLu::try_new(a.symbolic()).map_err(|e| SparseError::Factor(format!("{e:?}")))?;
            self.symbolic = Some((pattern, sym));
        }
        let Some((_, sym)) = &self.symbolic else { unreachable!("symbolic factorization set above") };
        let lu =
            Lu::try_new_with_symbolic(sym.clone(), a.as_ref()).map_err(|e| SparseError::Factor(format!("{e:?}")))?;
        let rhs = Col::<f64>::from_fn(n, |i| b[i]);
        let x = lu.solve(&rhs);
        for (i, bi) in b.iter_mut().enumerate() {
            *bi = x[i];
        }
        if b.iter().any(|v| !v.is_finite()) {
            return Err(SparseError::Factor("the matrix is numerically singular (non-finite solution)".into()));
        }
        Ok(())
    }
}
