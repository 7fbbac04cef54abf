//! plantwide-studies: studies run on a model of the plant, returning typed results that serialize
//! to the JSON the CLI prints.
//!
//! Today: [`tune`], controller tuning from a transfer-function model or a flowsheet's loops
//! (ultimate gain and frequency, relay and step tests, Ziegler–Nichols, Tyreus–Luyben, SIMC, IMC,
//! averaging level, Luyben's BLT detuning of n diagonal PI loops); [`screen`], control-structure
//! screening (a column's inventory configurations; plantwide pairings with steady-state filters
//! and a dynamic test); [`identify`], test design, plant test and FIR/ARX/OE fits (ch. 7).
#![warn(missing_docs)]

pub mod compare;
pub mod disturbance;
pub mod error;
pub mod identify;
mod numeric;
pub mod optimize;
pub mod request;
pub mod screen;
pub mod size;
pub mod tune;

pub use error::{Error, TuneError};
pub use screen::ScreenError;
pub use size::SizeError;
