//! Errors of the studies.

use thiserror::Error;

/// Why a tuning request was refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TuneError {
    /// BLT needs as many inputs as outputs (one loop per output).
    #[error(
        "model `{model}` is not square ({n_outputs} outputs × {n_inputs} inputs): BLT pairs output i with input i; \
         give a model with as many inputs as outputs"
    )]
    NotSquare {
        /// Model name.
        model: String,
        /// Number of outputs.
        n_outputs: usize,
        /// Number of inputs.
        n_inputs: usize,
    },
    /// `G(0)` is singular: the outputs cannot be controlled independently by these inputs.
    #[error(
        "model `{model}` is singular at steady state (σ_min/σ_max of G(0) = {ratio:.3e}): the loops cannot all \
         be closed with integral action; remove a dependent output or input"
    )]
    SingularGain {
        /// Model name.
        model: String,
        /// Smallest over largest singular value of `G(0)`.
        ratio: f64,
    },
    /// A paired (diagonal) element has no phase crossover, so it has no ultimate gain.
    #[error(
        "element {output} ← {input} has no phase crossover (its phase never reaches −180°{detail}): it has no \
         ultimate gain; add the element's dead time or its measurement and valve lags, or tune this loop another way"
    )]
    NoPhaseCrossover {
        /// Output of the element.
        output: String,
        /// Input of the element.
        input: String,
        /// What the element is (e.g. ", a first-order lag without dead time").
        detail: String,
    },
    /// A relay test did not settle into a cycle.
    #[error("relay test: no limit cycle: {why}")]
    NoCycle {
        /// Why, and what to change.
        why: String,
    },
    /// The name is no PID controller of the plant.
    #[error("no PID controller `{name}` in the flowsheet (its PID loops: {loops})")]
    NotALoop {
        /// The name asked for.
        name: String,
        /// The PID controllers it has.
        loops: String,
    },
    /// Averaging-level tuning of a measurement that does not integrate.
    #[error(
        "`{controller}` measures {measurement}, which settles at a finite gain when its output moves: averaging \
         tuning is for levels (integrating measurements); use --method simc or blt"
    )]
    NotIntegrating {
        /// Controller.
        controller: String,
        /// Its measurement.
        measurement: String,
    },
    /// The file's action is the opposite of what the process gain needs.
    #[error(
        "`{controller}` has action \"{file}\" in the file, but its process gain needs \"{needed}\" (the loop would \
         run away); set its action to \"{needed}\""
    )]
    WrongAction {
        /// Controller.
        controller: String,
        /// The file's action.
        file: &'static str,
        /// The action needed.
        needed: &'static str,
    },
    /// Averaging-level settings cannot be computed.
    #[error(transparent)]
    Averaging(#[from] crate::tune::averaging::AveragingError),
    /// A numerical search failed.
    #[error("{0}")]
    Numerical(String),
}

impl TuneError {
    /// True for problems of the request (exit code 1), false for numerical failures (exit code 2).
    pub fn is_user_error(&self) -> bool {
        !matches!(self, TuneError::Numerical(_))
    }
}
