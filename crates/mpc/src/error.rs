//! Typed errors. Every validation error names the offending field.

use thiserror::Error;

/// Errors of model construction, controller construction and execution.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MpcError {
    /// A vector or matrix has the wrong length.
    #[error("{field}: expected length {expected}, got {got}")]
    Dimension {
        /// Name of the field or argument.
        field: &'static str,
        /// Required length.
        expected: usize,
        /// Length supplied.
        got: usize,
    },
    /// A value is out of its admissible range (NaN, negative weight, `u_min > u_max`, ...).
    #[error("{field}: {reason}")]
    Invalid {
        /// Name of the field or argument.
        field: &'static str,
        /// Human-readable reason.
        reason: String,
    },
    /// The QP solver ended without a usable solution; `status` is clarabel's `SolverStatus`.
    #[error("QP solver failed with status {status}")]
    Solver {
        /// Clarabel status as text, e.g. `"PrimalInfeasible"`.
        status: String,
    },
    /// Clarabel refused the problem data (setup or in-place data update).
    #[error("QP setup: {0}")]
    Setup(String),
    /// `H = AᵀQA + R` is not positive definite, so the unconstrained closed form does not exist.
    #[error("Hessian AᵀQA + R is not positive definite (raise move_weights)")]
    SingularHessian,
}

impl MpcError {
    /// Shorthand for [`MpcError::Invalid`].
    pub(crate) fn invalid(field: &'static str, reason: impl Into<String>) -> Self {
        MpcError::Invalid { field, reason: reason.into() }
    }

    /// The field this error refers to, if any.
    pub fn field(&self) -> Option<&'static str> {
        match self {
            MpcError::Dimension { field, .. } | MpcError::Invalid { field, .. } => Some(field),
            _ => None,
        }
    }
}

/// Check that `v` has length `n`.
pub(crate) fn check_len(field: &'static str, v: &[f64], n: usize) -> Result<(), MpcError> {
    if v.len() != n {
        return Err(MpcError::Dimension { field, expected: n, got: v.len() });
    }
    Ok(())
}

/// Check that every entry of `v` is finite.
pub(crate) fn check_finite(field: &'static str, v: &[f64]) -> Result<(), MpcError> {
    if let Some(k) = v.iter().position(|x| !x.is_finite()) {
        return Err(MpcError::invalid(field, format!("entry {k} is not finite ({})", v[k])));
    }
    Ok(())
}

/// Check length and finiteness together.
pub(crate) fn check_vec(field: &'static str, v: &[f64], n: usize) -> Result<(), MpcError> {
    check_len(field, v, n)?;
    check_finite(field, v)
}
