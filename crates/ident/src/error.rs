//! Typed errors of the identification crate.
//!
//! Every variant names the argument or field that was rejected so that a caller (CLI, JSON API)
//! can report it without parsing the message.

use serde::Serialize;
use thiserror::Error;

/// Errors returned by test-signal design, estimation and validation.
#[derive(Debug, Clone, PartialEq, Error, Serialize)]
pub enum IdentError {
    /// The data record is too short for the requested number of parameters.
    ///
    /// `needed` is the minimum number of usable samples (regression rows) for `what`,
    /// `got` the number available.
    #[error("data too short for {what}: need at least {needed} usable samples, got {got}")]
    TooShort {
        /// What was being estimated or computed.
        what: &'static str,
        /// Minimum number of usable samples.
        needed: usize,
        /// Number of usable samples available.
        got: usize,
    },
    /// Two series that must have the same length do not.
    #[error("length mismatch: {name} has {got} samples, expected {expected}")]
    LengthMismatch {
        /// Name of the offending series, e.g. `u[1]`.
        name: String,
        /// Expected length (that of the output series or the first argument).
        expected: usize,
        /// Actual length.
        got: usize,
    },
    /// An input never moves (constant column): its parameters are not identifiable.
    #[error("input u[{input}] is constant (does not move): regression is rank deficient")]
    ConstantInput {
        /// Zero-based index of the input.
        input: usize,
    },
    /// The regression matrix is (numerically) rank deficient at a named column.
    #[error("regression is rank deficient at parameter {column} ({name})")]
    RankDeficient {
        /// Zero-based column (parameter) index.
        column: usize,
        /// Parameter name, e.g. `b[1][2]`.
        name: String,
    },
    /// A model order, delay or lag is outside its allowed range.
    #[error("bad order: {field} = {value} ({reason})")]
    BadOrder {
        /// Name of the argument or field.
        field: String,
        /// Rejected value.
        value: usize,
        /// Why it was rejected.
        reason: &'static str,
    },
    /// The initial model of an iterative (output-error) fit is unstable.
    #[error("unstable initial model: F of input u[{input}] has a root of modulus {modulus}")]
    UnstableInitialModel {
        /// Zero-based input index.
        input: usize,
        /// Largest root modulus of the denominator (must be < 1).
        modulus: f64,
    },
    /// An iterative method did not converge or produced non-finite values.
    #[error("no convergence after {iterations} iterations: {reason}")]
    NoConvergence {
        /// Iterations performed.
        iterations: usize,
        /// What went wrong.
        reason: &'static str,
    },
    /// A design or tuning parameter is out of range.
    #[error("bad design parameter {field} = {value}: {reason}")]
    BadDesign {
        /// Name of the argument or field.
        field: &'static str,
        /// Rejected value.
        value: f64,
        /// Why it was rejected.
        reason: &'static str,
    },
    /// A series contains NaN or infinity.
    #[error("non-finite value in {name} at sample {index}")]
    NonFinite {
        /// Name of the series.
        name: String,
        /// Zero-based sample index.
        index: usize,
    },
    /// A requested allocation would exceed the crate's size limit.
    #[error("{what} too large: {got} exceeds the limit {limit}")]
    TooLarge {
        /// What would be allocated.
        what: &'static str,
        /// The limit.
        limit: usize,
        /// The requested size.
        got: usize,
    },
    /// A fitted first-order model cannot be written as a FOPTD (pole not in (0, 1)).
    #[error("input u[{input}]: pole {pole} is not in (0, 1), no FOPTD time constant")]
    NotFirstOrderLag {
        /// Zero-based input index.
        input: usize,
        /// Discrete pole a = −f1.
        pole: f64,
    },
    /// A dense linear-algebra routine failed.
    #[error("numerical failure in {0}")]
    Numerical(&'static str),
}
