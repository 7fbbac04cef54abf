//! plantwide-studies: studies run on a model of the plant, returning typed results that serialize
//! to the JSON the CLI prints.
//!
//! Today: [`tune`], controller tuning from a transfer-function model (ultimate gain and
//! frequency, Ziegler–Nichols and Tyreus–Luyben PI settings, Luyben's BLT detuning of n diagonal
//! PI loops).
#![warn(missing_docs)]

pub mod error;
mod numeric;
pub mod screen;
pub mod tune;

pub use error::TuneError;
/// The crate-level error: every public fallible function of this crate returns a [`TuneError`].
pub use error::TuneError as Error;
