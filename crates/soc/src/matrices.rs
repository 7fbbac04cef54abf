//! Published linear data in place of a plant: the JSON file of `select --matrices`.
//!
//! ```json
//! {
//!   "inputs": ["F200", "F1"], "disturbances": ["X1", "T1", "T200"],
//!   "measurements": ["P2", "T2", "..."],
//!   "Gy":  [[...], ...],  "Gyd": [[...], ...],      (rows: measurements)
//!   "Juu": [[...], ...],  "Jud": [[...], ...],      (rows: inputs)
//!   "Wd": [0.25, 8, 5],                             (a diagonal as a vector, or a full matrix)
//!   "Wn": [1.285, 1, "..."]
//! }
//! ```
//!
//! Matrices are lists of rows. Units are the data's own; they only have to be consistent (the
//! losses are in the cost's unit).

use std::path::Path;

use faer::Mat;
use serde::Deserialize;

use crate::error::{SocError, field};
use crate::model::{LocalModel, Parts};

/// The file as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MatricesFile {
    inputs: Vec<String>,
    #[serde(default)]
    disturbances: Vec<String>,
    measurements: Vec<String>,
    #[serde(rename = "Gy")]
    gy: Vec<Vec<f64>>,
    #[serde(rename = "Gyd", default)]
    gyd: Vec<Vec<f64>>,
    #[serde(rename = "Juu")]
    juu: Vec<Vec<f64>>,
    #[serde(rename = "Jud", default)]
    jud: Vec<Vec<f64>>,
    #[serde(rename = "Wd", default)]
    wd: Weight,
    #[serde(rename = "Wn")]
    wn: Weight,
}

/// A weight: the diagonal as a vector, or the full matrix.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum Weight {
    Diagonal(Vec<f64>),
    Full(Vec<Vec<f64>>),
}

impl Default for Weight {
    fn default() -> Self {
        Weight::Diagonal(Vec::new())
    }
}

/// Read and check a matrices file.
///
/// # Errors
/// [`SocError::Json`] naming the place in the file that is not the format; [`SocError::Field`]
/// for data of the wrong shape or values (see [`LocalModel::new`]).
pub fn read(path: &Path) -> Result<LocalModel, SocError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| SocError::Json {
        file: file.clone(),
        path: ".".to_string(),
        message: format!("cannot be read ({e})"),
    })?;
    parse(&text, &file)
}

/// Parse and check the text of a matrices file named `file` (for messages).
///
/// # Errors
/// As [`read`].
pub fn parse(text: &str, file: &str) -> Result<LocalModel, SocError> {
    let mut de = serde_json::Deserializer::from_str(text);
    let text_error = |message: String| SocError::Json { file: file.to_string(), path: ".".to_string(), message };
    if text.starts_with('\u{feff}') {
        return Err(text_error("starts with a byte-order mark: save it as UTF-8 without one".to_string()));
    }
    let raw: MatricesFile = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let message = e.inner().to_string();
        let message = match message.contains("untagged enum Weight") {
            true => "give the magnitudes as a list (the diagonal) or as a list of rows (a full matrix)".to_string(),
            false => message,
        };
        SocError::Json { file: file.to_string(), path: e.path().to_string(), message }
    })?;
    de.end().map_err(|e| text_error(format!("{e}: the file holds more than one JSON value")))?;
    let (nu, nd, ny) = (raw.inputs.len(), raw.disturbances.len(), raw.measurements.len());
    let parts = Parts {
        gy: matrix("Gy", &raw.gy, ny, nu)?,
        gyd: matrix("Gyd", &raw.gyd, ny, nd)?,
        juu: matrix("Juu", &raw.juu, nu, nu)?,
        jud: matrix("Jud", &raw.jud, nu, nd)?,
        wd: weight("Wd", &raw.wd, nd)?,
        wn: weight("Wn", &raw.wn, ny)?,
        inputs: raw.inputs,
        disturbances: raw.disturbances,
        measurements: raw.measurements,
    };
    LocalModel::new(parts)
}

/// A list of rows as a matrix; an empty list stands for a matrix with no columns.
fn matrix(name: &'static str, given: &[Vec<f64>], rows: usize, cols: usize) -> Result<Mat<f64>, SocError> {
    if given.is_empty() && (rows == 0 || cols == 0) {
        return Ok(Mat::zeros(rows, cols));
    }
    let width = given.first().map_or(0, Vec::len);
    if let Some(k) = given.iter().position(|r| r.len() != width) {
        return Err(field(
            name,
            format!("row {k} has {} entries but row 0 has {width}: give rows of equal length", given[k].len()),
        ));
    }
    if (given.len(), width) != (rows, cols) {
        return Err(field(
            name,
            format!("is {} × {width}; it must be {rows} × {cols} (from the lists of names)", given.len()),
        ));
    }
    Ok(Mat::from_fn(rows, cols, |i, j| given[i][j]))
}

/// A weight as an `n × n` matrix.
fn weight(name: &'static str, given: &Weight, n: usize) -> Result<Mat<f64>, SocError> {
    match given {
        Weight::Diagonal(d) if d.len() == n => match d.iter().position(|v| *v < 0.0) {
            Some(k) => Err(field(name, format!("magnitude {k} (counted from 0) is negative: give magnitudes"))),
            None => Ok(Mat::from_fn(n, n, |i, j| if i == j { d[i] } else { 0.0 })),
        },
        Weight::Diagonal(d) => {
            Err(field(name, format!("has {} magnitudes; it needs {n} (from the lists of names)", d.len())))
        }
        Weight::Full(rows) => matrix(name, rows, n, n),
    }
}
