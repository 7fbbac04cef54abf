//! Numerical solvers over a time-unaware nonlinear system: Newton with faer sparse LU, scaled
//! residuals, bounded backtracking line search and pseudo-transient continuation; structural
//! analysis (maximum matching) for degrees-of-freedom diagnostics.
//!
//! **Architecture Invariant:** solvers see a [`System`] (residual, Jacobian triplets, bounds,
//! nominal magnitudes, mass-matrix pattern), never a unit, a stream or a file.

#![warn(missing_docs)]

pub mod certify;
pub mod dae;
pub mod dynamic;
pub mod error;
pub mod newton;
pub mod rank;
pub mod sequential;
pub mod sparse;
pub mod specs;
pub mod steady;
pub mod structure;
pub mod system;

pub use certify::{CertificateFailure, Warning, certify, certify_to};
pub use error::Error;
pub use newton::{
    IterationRecord, NewtonReport, NewtonSettings, NewtonStatus, pseudo_transient_steps, solve_steady,
    solve_steady_observed,
};
pub use sequential::{
    Method, Progress, Solution, SolveError, StrategySettings, converge, converge_observed, fix_design_point,
};
pub use specs::SteadySystem;
pub use steady::{
    ConvergenceFailure, DofError, DofProbe, PlantSystem, SteadyError, SteadyState, dof_check, steady_state,
    steady_state_observed,
};
pub use structure::{Matching, maximum_matching};
pub use system::System;
