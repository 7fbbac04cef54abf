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
    /// Perturbation gains that failed their check (step halving, RGA, exact linearization) at
    /// every step tried: never returned as if they were right.
    #[error(
        "{file}: the perturbation {quantity} of `{output}` to `{input}` did not verify ({check}): {first:.6e} vs {second:.6e} differ by {difference:.1e} relative (tolerance {tolerance:.0e}) at relative step {step:.1e}; try --step {suggestion:.0e} or --method linear"
    )]
    PerturbationUnverified {
        /// Flowsheet file.
        file: String,
        /// `gain` or `relative gain`.
        quantity: &'static str,
        /// Output path.
        output: String,
        /// Input path.
        input: String,
        /// Which comparison failed (`central differences at h and h/2`, …).
        check: &'static str,
        /// The first estimate (at `h`, or the perturbation's).
        first: f64,
        /// The second estimate (at `h/2`, or the exact linearization's).
        second: f64,
        /// Their relative difference.
        difference: f64,
        /// The tolerance it exceeds.
        tolerance: f64,
        /// Largest relative step of the last attempt.
        step: f64,
        /// A smaller relative step to try.
        suggestion: f64,
    },
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
