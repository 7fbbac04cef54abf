//! The crate's error: every failure a caller of `plantwide_solve` can meet, each variant one
//! module's typed error (which carries the file, the unit or equation, and the numbers).

use crate::dae::DaeError;
use crate::dynamic::SimError;
use crate::sequential::SolveError;
use crate::sparse::SparseError;

/// Any failure of the solvers.
#[derive(Debug, Clone, thiserror::Error)]
pub enum Error {
    /// No steady state: an ill-posed plant, a sequential-modular or Newton failure, or a state that
    /// fails the certificate ([`crate::converge`]).
    #[error(transparent)]
    Steady(#[from] SolveError),
    /// A dynamic run failed ([`crate::dynamic::simulate`]).
    #[error(transparent)]
    Simulation(#[from] Box<SimError>),
    /// The integrator failed outside a plant run.
    #[error(transparent)]
    Dae(#[from] DaeError),
    /// A sparse factorization failed.
    #[error(transparent)]
    Sparse(#[from] SparseError),
}

impl From<SimError> for Error {
    fn from(e: SimError) -> Error {
        Error::Simulation(Box::new(e))
    }
}

impl Error {
    /// True for an ill-posed plant or bad settings (exit 1), false for a numerical failure (exit 2).
    pub fn is_user_error(&self) -> bool {
        match self {
            Error::Steady(e) => e.is_user_error(),
            Error::Simulation(e) => matches!(**e, SimError::Snapshot { .. } | SimError::Wiring(_)),
            Error::Dae(_) | Error::Sparse(_) => false,
        }
    }
}
