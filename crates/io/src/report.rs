//! Each command's report, rendered here so that every face (the CLI, Python, the server) shows the
//! same text, JSON and figures for the same result. A face maps its arguments to the library's
//! request, calls the library, and prints or writes what these functions make of the result.
//!
//! - [`check`]: `plantwide check`: what a flowsheet holds, its degrees of freedom, its residence
//!   times.
//! - [`compare`]: `plantwide compare` and `plantwide.compare`: the schemes side by side, the report
//!   folder.
//! - [`identify`]: `plantwide identify` and `Plant.identify`: the test, the verdict, the models, the
//!   report folder with the step model.
//! - [`screen`]: `plantwide screen` and `Plant.screen`: a column's configurations or the pairings,
//!   the report folders, a column's tuned flowsheets.
//! - [`shown`]: the display units of the paths a report shows.
//! - [`size`]: `plantwide size` and `Plant.size`: the designs' table or the candidates' ranking,
//!   their figure, the report folder.
//! - [`steady`]: `plantwide steady`: the specs met, the stream table, the blocks' variables; the
//!   JSON of every variable.
//! - [`tune`]: `plantwide tune` and `Plant.tune`: the tuned loops, their Bode diagrams, the report
//!   folder.

pub mod check;
pub mod compare;
pub mod identify;
pub mod screen;
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
