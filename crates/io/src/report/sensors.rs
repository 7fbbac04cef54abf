//! The report of a temperature-sensor selection ([`SensorSelection`]): each stage's temperature,
//! its gains and singular-vector weights, and the stage each criterion picks (SVD, sensitivity,
//! slope), as text in a temperature display unit or as JSON (SI). `plantwide sensors` prints
//! [`text`] (or [`json`] with `--json`).

use plantwide_analysis::measures::rows;
use plantwide_analysis::select::{Signal, SignalLabel};
use plantwide_analysis::sensors::SensorSelection;
use plantwide_units::Display;
use serde::Serialize;

use super::sig6 as sig;
use crate::IoError;

/// The selection for `column` in the plant `plant_name` as text, temperatures in `temperature`'s
/// unit and gains per each input's display unit.
pub fn text(plant_name: &str, column: &str, inputs: &[Signal], s: &SensorSelection, temperature: &Display) -> String {
    let tu = temperature.unit();
    let mut t =
        format!("temperature-sensor selection for `{column}` in `{plant_name}` (gains in {tu} per input unit)\n\n");
    t.push_str(&format!("{:>6} {:>10} {:>9}", "stage", format!("T [{tu}]"), format!("ΔT [{tu}]")));
    // Each input by its whole path (two loops' `op_manual` would read alike), the gain's unit as
    // "per" the input's (a compound unit after `/` would read as a quotient of the two).
    let headers: Vec<String> = inputs.iter().map(|i| format!("dT/d({}) [{tu} per {}]", i.path, i.unit)).collect();
    let widths: Vec<usize> = headers.iter().map(|h| h.chars().count().max(12)).collect();
    for (h, w) in headers.iter().zip(&widths) {
        t.push_str(&format!(" {h:>w$}"));
    }
    for k in 0..s.singular_values.len() {
        t.push_str(&format!(" {:>8}", format!("|U{}|", k + 1)));
    }
    t.push('\n');
    for (r, stage) in s.stages.iter().enumerate() {
        let dt = if r + 1 < s.stages.len() {
            format!("{:.4}", temperature.difference(s.temperatures[r + 1] - s.temperatures[r]))
        } else {
            String::new()
        };
        t.push_str(&format!("{:>6} {:>10.4} {:>9}", stage, temperature.value(s.temperatures[r]), dt));
        for (j, w) in widths.iter().enumerate() {
            t.push_str(&format!(" {:>w$}", sig(temperature.difference(s.gains[(r, j)]))));
        }
        for k in 0..s.singular_values.len() {
            t.push_str(&format!(" {:>8.4}", s.u[(r, k)].abs()));
        }
        t.push('\n');
    }
    let sv: Vec<String> = s.singular_values.iter().map(|v| sig(*v)).collect();
    t.push_str(&format!("\nsingular values: {}\n", sv.join(", ")));
    let stages = |v: &[usize]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>().join(", ");
    t.push_str(&format!("SVD criterion (largest |U| per singular direction): stages {}\n", stages(&s.svd_stages)));
    t.push_str(&format!(
        "sensitivity criterion (largest |gain| per input): stages {}\n",
        stages(&s.sensitivity_stages)
    ));
    t.push_str(&format!(
        "slope criterion (largest ΔT between adjacent stages): stages {} and {} ({:.4} {tu})\n",
        s.slope.0.0,
        s.slope.0.1,
        temperature.difference(s.slope.1)
    ));
    t
}

/// `plantwide sensors --json`, its keys in alphabetical order (the order it has always had).
#[derive(Serialize)]
struct SensorsJson<'a> {
    column: &'a str,
    gains: Vec<Vec<f64>>,
    inputs: Vec<SignalLabel>,
    sensitivity_stages: &'a [usize],
    singular_values: &'a [f64],
    slope: Slope,
    stages: &'a [usize],
    svd_stages: &'a [usize],
    temperatures: &'a [f64],
    u: Vec<Vec<f64>>,
}

/// The slope criterion: the adjacent stages and their temperature difference \[K\].
#[derive(Serialize)]
struct Slope {
    difference: f64,
    stages: [usize; 2],
}

/// The selection for `column` as JSON (SI): the stages, their temperatures, gains and left
/// singular vectors, and each criterion's stages.
///
/// # Errors
/// [`IoError::Draw`] if serde cannot write it.
pub fn json(column: &str, inputs: &[Signal], s: &SensorSelection) -> Result<String, IoError> {
    super::json(&SensorsJson {
        column,
        gains: rows(s.gains.as_ref()),
        inputs: inputs.iter().map(Signal::label).collect(),
        sensitivity_stages: &s.sensitivity_stages,
        singular_values: &s.singular_values,
        slope: Slope { difference: s.slope.1, stages: [s.slope.0.0, s.slope.0.1] },
        stages: &s.stages,
        svd_stages: &s.svd_stages,
        temperatures: &s.temperatures,
        u: rows(s.u.as_ref()),
    })
}
