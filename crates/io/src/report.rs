//! Each command's report, rendered here so that every face (the CLI, Python, the server) shows the
//! same text, JSON and figures for the same result. A face maps its arguments to the library's
//! request, calls the library, and prints or writes what these functions make of the result.
//!
//! - [`check`]: `plantwide check`: what a flowsheet holds, its degrees of freedom, its residence
//!   times.
//! - [`compare`]: `plantwide compare` and `plantwide.compare`: the schemes side by side, the report
//!   folder.
//! - [`gains`]: `plantwide gains`: the gain report of a flowsheet or a transfer-function model, its
//!   JSON, the RGA heat map.
//! - [`identify`]: `plantwide identify` and `Plant.identify`: the test, the verdict, the models, the
//!   report folder with the step model.
//! - [`linearize`]: `plantwide linearize`: the state-space model's size, modes and steady-state
//!   gain; a transfer-function model's elements and poles.
//! - [`run`]: `plantwide run`: the trends as CSV, the summary as text or JSON; [`run_plot`], the
//!   trend plot.
//! - [`screen`]: `plantwide screen` and `Plant.screen`: a column's configurations or the pairings,
//!   the report folders, a column's tuned flowsheets.
//! - [`select`]: `plantwide select`: the best measurement subsets, their losses and combinations.
//! - [`sensitivity`]: `plantwide sensitivity`: the sweeps' tables.
//! - [`sensors`]: `plantwide sensors`: the stages and the criteria's choices, as text or JSON.
//! - [`shown`]: the display units of the paths a report shows.
//! - [`size`]: `plantwide size` and `Plant.size`: the designs' table or the candidates' ranking,
//!   their figure, the report folder.
//! - [`steady`]: `plantwide steady`: the specs met, the stream table, the blocks' variables; the
//!   JSON of every variable.
//! - [`tune`]: `plantwide tune` and `Plant.tune`: the tuned loops, their Bode diagrams, the report
//!   folder.

pub mod check;
pub mod compare;
pub mod components;
pub mod gains;
pub mod identify;
pub mod inventory;
pub mod linearize;
pub mod optimize;
pub mod run;
pub mod run_plot;
pub mod screen;
pub mod select;
pub mod sensitivity;
pub mod sensors;
pub mod shown;
pub mod size;
pub mod steady;
pub mod tune;

use std::path::Path;

use crate::IoError;

/// `value` as the pretty JSON every face prints and writes (SI units, `--json`).
///
/// # Errors
/// [`IoError::Draw`] if serde cannot write it (a non-string map key).
pub fn json<T: serde::Serialize>(value: &T) -> Result<String, IoError> {
    serde_json::to_string_pretty(value).map_err(|e| IoError::Draw(format!("JSON: {e}")))
}

/// Write `text` to `dir/name`, returning the name.
fn write(dir: &Path, name: &str, text: &str) -> Result<String, IoError> {
    let file = dir.join(name);
    std::fs::write(&file, text).map_err(|e| IoError::Draw(format!("{}: {e}", file.display())))?;
    Ok(name.to_string())
}

/// The first `n` characters of `s` (a name cut to its table column).
fn truncate(s: &str, n: usize) -> String {
    s.chars().take(n).collect()
}

/// A number with 6 significant digits: fixed notation for magnitudes in [1e-3, 1e6), else
/// scientific (the tables of `gains`, `sensors`, `linearize`, `sensitivity`).
fn sig6(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !v.is_finite() {
        format!("{v}")
    } else if (1e-3..1e6).contains(&a) {
        let decimals = (5 - a.log10().floor() as i32).max(0) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.5e}")
    }
}
