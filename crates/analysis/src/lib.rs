//! Control analysis of a plant (or of a transfer-function model): linearization, steady-state
//! gains by two independent routes, interaction measures, sensitivity sweeps and temperature-sensor
//! selection.
//!
//! - [`linear`]: Jacobians at a steady state → `G(0) = −C J⁻¹ B`, state space `A, B, C, D` with
//!   the algebraic variables eliminated, eigenvalues, `G(jω)`.
//! - [`perturb`]: the book's gains — each input moved ± h and ± h/2, the plant re-converged,
//!   central differences extrapolated (Richardson) and verified, never returned unverified.
//! - [`measures`], [`min_cond`]: RGA, RGA number, SVD, condition number and its minimized value,
//!   Niederlinski index, block relative gain, scaling, Morari resiliency index.
//! - [`figures`]: figures of merit of a dynamic run (IAE, ISE, largest deviation, settling time).
//! - [`tf`]: transfer-function matrix models (gain, lags, leads, dead time per element) and
//!   their `G(jω)`.
//! - [`sensitivity`]: disturbance sweeps with the control structure active, by continuation.
//! - [`sensors`]: tray-temperature sensor selection (SVD and slope criteria).
//! - [`report`]: the gain report shared by flowsheets and transfer-function models.
//! - [`plant_model`]: a flowsheet's gain report and state-space model between chosen signals, as
//!   every face shows them.
//!
//! **Architecture Invariant:** nothing here reads or writes files or the terminal, parses a file
//! format or draws: file formats and plots are `plantwide_io`'s, files and the terminal the CLI's.

#![warn(missing_docs)]

pub(crate) mod balance;
pub mod continuation;
pub mod error;
pub mod figures;
pub mod frequency;
pub mod linear;
pub mod measures;
pub mod min_cond;
pub mod perturb;
pub mod plant_model;
pub mod report;
pub mod response;
pub mod select;
pub mod sensitivity;
pub mod sensors;
pub mod shard;
pub mod tf;

pub use error::AnalysisError;
/// The crate-level error: every public fallible function of this crate returns an
/// [`AnalysisError`].
pub use error::AnalysisError as Error;
/// The linear algebra the API speaks (`Mat`, `c64`).
pub use faer;
