//! Errors of the analysis layer: bad requests (a path that names nothing, a unit of the wrong
//! dimension, an inconsistent transfer-function model) and numerical failures (a singular Jacobian, a
//! perturbed plant that does not re-converge). [`AnalysisError`] is the crate-level error
//! (`plantwide_analysis::Error`); the perturbation's own errors ([`PerturbError`], [`Unverified`])
//! join it by `From`.

use crate::perturb::PerturbError;

/// Why an analysis could not be done (the crate-level error, `plantwide_analysis::Error`).
#[derive(Debug, Clone, thiserror::Error)]
pub enum AnalysisError {
    /// A path, unit, range or option given by the user is wrong; the message says what would fix it.
    #[error("{0}")]
    Request(String),
    /// A matrix that must be invertible is (numerically) singular.
    #[error("{0}")]
    Singular(String),
    /// A perturbed plant did not re-converge, or too inaccurately for the effect of its step
    /// (boxed: it carries the solver's reason).
    #[error(transparent)]
    NotConverged(Box<PerturbError>),
    /// Perturbation gains that failed their check (step halving, RGA, exact linearization) at
    /// every step tried: never returned as if they were right.
    #[error("{0}")]
    PerturbationUnverified(Box<Unverified>),
}

/// Why perturbation gains were refused: the pair, the check, the two estimates and what to try
/// (boxed in [`AnalysisError::PerturbationUnverified`] to keep the error small).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "{file}: the perturbation {quantity} of `{output}` to `{input}` did not verify ({check}): {first:.6e} vs {second:.6e} differ by {difference:.1e} relative (tolerance {tolerance:.0e}) at relative step {step:.1e}; {}", advice(*.suggestion)
)]
pub struct Unverified {
    /// Flowsheet file.
    pub file: String,
    /// `gain` or `relative gain`.
    pub quantity: &'static str,
    /// Output path.
    pub output: String,
    /// Input path.
    pub input: String,
    /// Which comparison failed (`central differences at h and h/2`, …).
    pub check: &'static str,
    /// The first estimate (at `h`, or the perturbation's).
    pub first: f64,
    /// The second estimate (at `h/2`, or the exact linearization's).
    pub second: f64,
    /// Their relative difference.
    pub difference: f64,
    /// The tolerance it exceeds.
    pub tolerance: f64,
    /// Largest relative step of the last attempt.
    pub step: f64,
    /// A smaller relative step to try; `None` when the smaller step was tried and the re-converged
    /// steady states were too inaccurate for it.
    pub suggestion: Option<f64>,
}

/// What to try after a perturbation that did not verify.
fn advice(suggestion: Option<f64>) -> String {
    match suggestion {
        Some(step) => format!("try `step` {step:.0e} or `method` linear"),
        None => "a smaller step is below what the re-converged steady states resolve, so perturbation cannot verify these gains: use `method` linear (the exact linearization)".to_string(),
    }
}

impl From<PerturbError> for AnalysisError {
    fn from(e: PerturbError) -> Self {
        AnalysisError::NotConverged(Box::new(e))
    }
}

impl From<Unverified> for AnalysisError {
    fn from(e: Unverified) -> Self {
        AnalysisError::PerturbationUnverified(Box::new(e))
    }
}

impl AnalysisError {
    /// True for problems of the request (exit code 1), false for numerical failures (exit code 2).
    pub fn is_user_error(&self) -> bool {
        matches!(self, AnalysisError::Request(_))
    }
}

/// Shorthand for a [`AnalysisError::Request`].
pub(crate) fn request(message: impl Into<String>) -> AnalysisError {
    AnalysisError::Request(message.into())
}
