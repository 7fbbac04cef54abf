//! File formats and figures of plantwide: what the faces (CLI, Python, server) read and write
//! besides flowsheets and scenarios (those are `plantwide_flowsheet`'s).
//!
//! - [`tf`]: the transfer-function model file (`*.tf.json`) → [`TfModel`](plantwide_analysis::tf::TfModel).
//! - [`export`]: the state-space model as JSON for MATLAB and python-control, with python-control-safe
//!   signal names and the path each stands for.
//! - [`npz`]: named arrays as a NumPy `.npz` archive (the state-space export's second format).
//! - [`csv`]: sensitivity sweeps as CSV.
//! - [`report`]: each command's and study's report (its table, JSON, CSV, figures), the same from
//!   every face.
//! - [`plot`]: trend plots of dynamic runs and sensitivity plots, PNG or SVG, with one embedded
//!   font (DejaVu Sans) registered once, so no system font library is needed.
//!
//! **Architecture Invariant:** io sits above the numerical crates (units, solve, analysis, studies)
//! and is never imported by them: they compute typed results, io turns those into text and
//! pictures. Writing a figure is the only file access here; reading a file's text is the
//! caller's.

#![warn(missing_docs)]

pub mod csv;
pub mod error;
pub mod export;
pub mod html;
pub mod npz;
pub mod part;
pub mod plot;
pub mod report;
pub mod tf;

pub use error::IoError;
