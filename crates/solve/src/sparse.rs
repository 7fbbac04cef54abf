//! Sparse LU on faer, with the symbolic analysis done once per pattern.

use faer::Col;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::LuError;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{CreationError, SparseColMat, Triplet};

/// Why a sparse factorization failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SparseError {
    /// A triplet lies outside the `n × n` matrix (a wiring bug, never user input).
    #[error("invalid sparse matrix: entry ({row}, {col}) outside the {n} × {n} matrix")]
    OutOfBounds {
        /// Row of the entry.
        row: usize,
        /// Column of the entry.
        col: usize,
        /// Order of the matrix.
        n: usize,
    },
    /// faer could not allocate, or an index overflowed.
    #[error("sparse LU of order {n} with {nnz} entries: out of memory or index overflow")]
    Resources {
        /// Order of the matrix.
        n: usize,
        /// Number of triplets.
        nnz: usize,
    },
    /// No pivot at elimination step `index`: the matrix is structurally or numerically singular.
    #[error("sparse LU failed: no pivot at step {index} of {n} (singular matrix)")]
    Singular {
        /// The elimination step.
        index: usize,
        /// Order of the matrix.
        n: usize,
    },
    /// The solution is not finite: the matrix is numerically singular.
    #[error("sparse LU failed: the matrix of order {n} is numerically singular (non-finite solution)")]
    NonFinite {
        /// Order of the matrix.
        n: usize,
    },
}

impl SparseError {
    fn creation(e: CreationError, n: usize, nnz: usize) -> SparseError {
        match e {
            CreationError::OutOfBounds { row, col } => SparseError::OutOfBounds { row, col, n },
            CreationError::Generic(_) => SparseError::Resources { n, nnz },
        }
    }

    fn lu(e: LuError, n: usize, nnz: usize) -> SparseError {
        match e {
            LuError::SymbolicSingular { index } => SparseError::Singular { index, n },
            LuError::Generic(_) => SparseError::Resources { n, nnz },
        }
    }
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
            .map_err(|e| SparseError::creation(e, n, trip.len()))?;
        let pattern: Vec<(usize, usize)> = triplets.iter().map(|&(i, j, _)| (i, j)).collect();
        let reuse = matches!(&self.symbolic, Some((p, _)) if *p == pattern);
        if !reuse {
            let sym = SymbolicLu::try_new(a.symbolic()).map_err(|e| SparseError::creation(e.into(), n, trip.len()))?;
            self.symbolic = Some((pattern, sym));
        }
        let Some((_, sym)) = &self.symbolic else { unreachable!("symbolic factorization set above") };
        let lu = Lu::try_new_with_symbolic(sym.clone(), a.as_ref()).map_err(|e| SparseError::lu(e, n, trip.len()))?;
        let rhs = Col::<f64>::from_fn(n, |i| b[i]);
        let x = lu.solve(&rhs);
        for (i, bi) in b.iter_mut().enumerate() {
            *bi = x[i];
        }
        if b.iter().any(|v| !v.is_finite()) {
            return Err(SparseError::NonFinite { n });
        }
        Ok(())
    }
}
