//! `plantwide linearize FILE --inputs P1,P2 --outputs Q1,Q2 --out model.json [--time-unit min]
//! [--frequencies LOW:HIGH:N]`: the state-space model at the steady state, for MATLAB and
//! python-control (see `plantwide_io::export` for how to load it); `plantwide linearize --tf
//! MODEL.tf.json [--inputs …] [--outputs …]`: a transfer-function model's elements as numerator,
//! denominator and dead time, its poles and gains (see `plantwide_io::tf::export`).

use std::path::PathBuf;

use plantwide::analysis::frequency::{self, FrequencyResults};
use plantwide::analysis::plant_model::PlantModel;
use plantwide::analysis::select::{in_system, select_inputs, select_outputs};
use plantwide::io::export::ModelExport;
use plantwide::io::report;
use plantwide::units::UnitSystem;
use plantwide::units::{Dimension, Unit};

use super::CliError;
use super::steady::{converge, load_with_overrides};

/// Arguments of `plantwide linearize`.
#[derive(Debug, clap::Args)]
pub struct LinearizeArgs {
    /// Flowsheet file (JSON).
    #[arg(required_unless_present = "tf", conflicts_with = "tf")]
    file: Option<PathBuf>,
    /// A transfer-function model (`*.tf.json`) instead of a flowsheet.
    #[arg(long, value_name = "MODEL")]
    tf: Option<PathBuf>,
    /// Inputs, comma-separated, each `PATH[@unit]`; with `--tf`, the model's input names to keep
    /// (default all).
    #[arg(long, value_delimiter = ',', required_unless_present = "tf")]
    inputs: Vec<String>,
    /// Outputs, comma-separated variable paths, each `PATH[@unit]`; with `--tf`, the model's
    /// output names to keep (default all).
    #[arg(long, value_delimiter = ',', required_unless_present = "tf")]
    outputs: Vec<String>,
    /// Write the model here: JSON, or a NumPy archive when the name ends in `.npz`.
    #[arg(long, value_name = "MODEL.json|MODEL.npz", value_parser = super::output_file)]
    out: Option<PathBuf>,
    /// Time unit of the exported A and B, eigenvalues and time constants (default s).
    #[arg(long, default_value = "s")]
    time_unit: String,
    /// Also export G(jω) at `LOW:HIGH:N` (log-spaced, rad per --time-unit).
    #[arg(long, value_name = "LOW:HIGH:N")]
    frequencies: Option<String>,
    /// Override an input or a unit parameter first.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
}

/// A time unit for display: its name and length in seconds.
pub struct TimeUnit {
    /// As written (`min`).
    pub name: String,
    /// Seconds per unit.
    pub seconds: f64,
}

impl TimeUnit {
    /// Parse a time unit (`s`, `min`, `h`).
    pub fn parse(name: &str) -> Result<TimeUnit, CliError> {
        let u = Unit::parse(name).map_err(|e| CliError::user(format!("--time-unit {name}: {e}")))?;
        if u.dimension() != Dimension::TIME {
            return Err(CliError::user(format!("--time-unit {name}: not a time unit (e.g. s, min, h)")));
        }
        Ok(TimeUnit { name: name.to_string(), seconds: u.factor() })
    }
}

/// `LOW:HIGH:N` (rad per time unit) → `N` log-spaced frequencies in rad/s.
pub fn frequency_grid(text: &str, tu: &TimeUnit) -> Result<Vec<f64>, CliError> {
    let bad = || {
        CliError::user(format!(
            "--frequencies `{text}`: expected LOW:HIGH:N with 0 < LOW < HIGH and N ≥ 2, e.g. 0.001:1:25"
        ))
    };
    let parts: Vec<&str> = text.split(':').map(str::trim).collect();
    let [lo, hi, n] = parts[..] else { return Err(bad()) };
    let (lo, hi, n): (f64, f64, usize) =
        (lo.parse().map_err(|_| bad())?, hi.parse().map_err(|_| bad())?, n.parse().map_err(|_| bad())?);
    if !(lo > 0.0 && hi > lo && hi.is_finite() && n >= 2) {
        return Err(bad());
    }
    Ok((0..n).map(|k| lo * (hi / lo).powf(k as f64 / (n - 1) as f64) / tu.seconds).collect())
}

/// `linearize --tf`: the elements (numerator, denominator, dead time), poles and gains of a
/// transfer-function model, printed and, with `--out`, written as JSON.
fn run_tf(a: &LinearizeArgs, file: &std::path::Path, tu: &TimeUnit) -> Result<(), CliError> {
    let name = file.display().to_string();
    let text = plantwide::flowsheet::read_text(file).map_err(|e| CliError::user(e.to_string()))?;
    let model = plantwide::io::tf::parse(&text, &name).map_err(|e| CliError::user(e.to_string()))?;
    let model = model.select(&a.inputs, &a.outputs).map_err(|e| CliError::user(format!("{name}: {e}")))?;
    let omegas = a.frequencies.as_deref().map(|f| frequency_grid(f, tu)).transpose()?;
    let frequency = omegas.map(|w| FrequencyResults {
        time_unit: tu.name.clone(),
        points: w.iter().map(|&w| frequency::point(w * tu.seconds, &model.response(w), &[])).collect(),
    });
    let doc = plantwide::io::tf::export(&model, (&tu.name, tu.seconds), frequency.as_ref())
        .map_err(|e| CliError::numerical(e.to_string()))?;
    out!("{}", report::linearize::tf_text(&model, &doc, &tu.name));
    if let Some(out) = &a.out {
        let text = serde_json::to_string_pretty(&doc).map_err(|e| CliError::user(e.to_string()))?;
        std::fs::write(out, text + "\n")
            .map_err(|e| CliError::user(format!("{}: cannot write: {e}", out.display())))?;
        out!("{}", report::linearize::tf_written(out));
    }
    Ok(())
}

pub fn run(a: &LinearizeArgs, units: UnitSystem) -> Result<(), CliError> {
    let tu = TimeUnit::parse(&a.time_unit)?;
    if let Some(tf) = &a.tf {
        return run_tf(a, tf, &tu);
    }
    let Some(file) = &a.file else { return Err(CliError::user("give a flowsheet FILE or --tf MODEL")) };
    let (plant, u) = load_with_overrides(file, &a.set)?;
    let map = |e: plantwide::analysis::AnalysisError| {
        if e.is_user_error() { CliError::user(e.to_string()) } else { CliError::numerical(e.to_string()) }
    };
    let inputs = select_inputs(&plant, &in_system(&plant, &a.inputs, units)).map_err(map)?;
    let outputs = select_outputs(&plant, &in_system(&plant, &a.outputs, units)).map_err(map)?;
    let omegas = a.frequencies.as_deref().map(|f| frequency_grid(f, &tu)).transpose()?.unwrap_or_default();
    let ss = converge(&plant, &u)?;
    let pm = PlantModel::at(&plant, (&ss.x, &ss.u), (&inputs, &outputs), &omegas).map_err(map)?;
    let (model, direct) = (&pm.model, &pm.direct_gain);
    out!("{}", report::linearize::heading(plant.name(), &pm, inputs.len(), outputs.len()));
    let slow = model.time_constants().map_err(map)?;
    let unstable = model.unstable(1e-12).map_err(map)?;
    out!("{}", report::linearize::modes(&slow, &unstable, (&tu.name, tu.seconds)));
    if unstable.is_empty() {
        let gain = model.steady_gain().map_err(map)?;
        out!("{}", report::linearize::gain(&gain, direct, &inputs, &outputs));
    }
    if let Some(out) = &a.out {
        let export = ModelExport {
            name: plant.name(),
            model: &pm,
            inputs: &inputs,
            outputs: &outputs,
            time_unit: (&tu.name, tu.seconds),
        };
        let npz = out.extension().is_some_and(|e| e == "npz");
        let bytes = match npz {
            true => plantwide::io::npz::archive(&plantwide::io::npz::linear_model(&export)),
            false => (export.to_json_string() + "\n").into_bytes(),
        };
        std::fs::write(out, bytes).map_err(|e| CliError::user(format!("{}: cannot write: {e}", out.display())))?;
        out!("{}", report::linearize::written(out, npz));
    }
    Ok(())
}
