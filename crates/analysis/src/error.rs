//! Errors of the analysis layer: bad requests (a path that names nothing, a unit of the wrong
//! dimension, a malformed transfer-function file) and numerical failures (a singular Jacobian, a
//! perturbed plant that does not re-converge).

/// Why an analysis could not be done.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AnalysisError {
    /// A path, unit, range or option given by the user is wrong; the message says what would fix it.
    #[error("{0}")]
    Request(String),
    /// A transfer-function file is unreadable or inconsistent.
    #[error("{file}: {path}: {message}")]
    TfFile {
        /// File name.
        file: String,
        /// JSON path of the offending field (`elements[2].lags[0]`).
        path: String,
        /// What is wrong and what would fix it.
        message: String,
    },
    /// A matrix that must be invertible is (numerically) singular.
    #[error("{0}")]
    Singular(String),
    /// A perturbed or swept plant did not re-converge.
    #[error("{0}")]
    NotConverged(String),
    /// A plot could not be drawn.
    #[error("plot: {0}")]
    Plot(String),
}

impl AnalysisError {
    /// True for problems of the request (exit code 1), false for numerical failures (exit code 2).
    pub fn is_user_error(&self) -> bool {
        matches!(self, AnalysisError::Request(_) | AnalysisError::TfFile { .. })
    }
}

/// Shorthand for a [`AnalysisError::Request`].
pub(crate) fn request(message: impl Into<String>) -> AnalysisError {
    AnalysisError::Request(message.into())
}
