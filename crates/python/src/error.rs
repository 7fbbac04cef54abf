//! The library's errors as Python exceptions: `PlantwideError`, with `InputError` for what the CLI
//! exits 1 on (a bad file, field, path or value; an ill-posed plant) and `ConvergenceError` for
//! what it exits 2 on (a numerical failure). The message is the library's, unchanged.

use pyo3::PyErr;
use pyo3::create_exception;
use pyo3::exceptions::PyException;

// Named in the package `plantwide` (which re-exports them), so that pickle finds them there: an
// error raised on a Dask worker reaches the client as the same class.

create_exception!(plantwide, PlantwideError, PyException, "An error reported by the plantwide library.");
create_exception!(
    plantwide,
    InputError,
    PlantwideError,
    "A bad flowsheet, scenario, field, path or value, or an ill-posed plant (the CLI's exit 1)."
);
create_exception!(
    plantwide,
    ConvergenceError,
    PlantwideError,
    "A numerical failure: no steady state, an integration or a perturbation that failed (the CLI's exit 2)."
);

/// A failed call, classified as the CLI classifies it.
#[derive(Debug, thiserror::Error)]
pub enum FaceError {
    /// The caller's input is wrong (exit 1).
    #[error("{0}")]
    Input(String),
    /// The numerics failed (exit 2).
    #[error("{0}")]
    Convergence(String),
}

impl FaceError {
    /// Classify `e` by `user` (the library's `is_user_error`).
    pub fn classify(e: impl std::fmt::Display, user: bool) -> FaceError {
        if user { FaceError::Input(e.to_string()) } else { FaceError::Convergence(e.to_string()) }
    }
    /// An input error from any library error.
    pub fn input(e: impl std::fmt::Display) -> FaceError {
        FaceError::Input(e.to_string())
    }
}

impl From<plantwide_solve::SolveError> for FaceError {
    fn from(e: plantwide_solve::SolveError) -> Self {
        let user = e.is_user_error();
        FaceError::classify(e, user)
    }
}

impl From<plantwide_analysis::AnalysisError> for FaceError {
    fn from(e: plantwide_analysis::AnalysisError) -> Self {
        let user = e.is_user_error();
        FaceError::classify(e, user)
    }
}

impl From<plantwide_studies::screen::ScreenError> for FaceError {
    fn from(e: plantwide_studies::screen::ScreenError) -> Self {
        let user = e.is_user_error();
        FaceError::classify(e, user)
    }
}

impl From<plantwide_studies::Error> for FaceError {
    fn from(e: plantwide_studies::Error) -> Self {
        let user = e.is_user_error();
        FaceError::classify(e, user)
    }
}

impl From<plantwide_studies::TuneError> for FaceError {
    fn from(e: plantwide_studies::TuneError) -> Self {
        let user = e.is_user_error();
        FaceError::classify(e, user)
    }
}

impl From<plantwide_studies::optimize::OptimizeError> for FaceError {
    fn from(e: plantwide_studies::optimize::OptimizeError) -> Self {
        let user = e.is_user_error();
        FaceError::classify(e, user)
    }
}

impl From<plantwide_flowsheet::OverrideError> for FaceError {
    fn from(e: plantwide_flowsheet::OverrideError) -> Self {
        FaceError::input(e)
    }
}

impl From<FaceError> for PyErr {
    fn from(e: FaceError) -> PyErr {
        match e {
            FaceError::Input(m) => InputError::new_err(m),
            FaceError::Convergence(m) => ConvergenceError::new_err(m),
        }
    }
}
