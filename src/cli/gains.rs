//! `plantwide gains FILE --inputs P1,P2 --outputs Q1,Q2 [--pairing …] [--method linear|perturb]
//! [--json]`, `plantwide gains --tf MODEL.tf.json`, and `plantwide sensors FILE --column NAME
//! --inputs …`.

use std::path::{Path, PathBuf};

use plantwide::analysis::AnalysisError;
use plantwide::analysis::faer::{Mat, c64};
use plantwide::analysis::frequency::{self, FrequencyResults};
use plantwide::analysis::linear::Linearization;
use plantwide::analysis::plant_model::{GainMethod, PlantGains, plant_gains};
use plantwide::analysis::report::{GainReport, ReportOptions};
use plantwide::analysis::select::{SignalLabel, in_system, parse_block, parse_pairing, select_inputs, select_outputs};
use plantwide::analysis::sensors::select_temperature_sensors;
use plantwide::analysis::tf::TfSignal;
use plantwide::io::report;
use plantwide::io::tf;
use plantwide::units::UnitSystem;
use plantwide::units::{Dimension, parse_quantity_as};

use super::CliError;
use super::linearize::{TimeUnit, frequency_grid};
use super::steady::{converge, load_with_overrides};

/// How gains are obtained from a flowsheet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Method {
    /// Linearization at the steady state: G(0) = −C J⁻¹ B (exact Jacobians, one sparse LU).
    Linear,
    /// Each input moved ± h, the plant re-converged, central differences (the book's method).
    Perturb,
}

/// Arguments of `plantwide gains`.
#[derive(Debug, clap::Args)]
pub struct GainsArgs {
    /// Flowsheet file (JSON).
    #[arg(required_unless_present = "tf", conflicts_with = "tf")]
    file: Option<PathBuf>,
    /// Analyse a transfer-function model (`*.tf.json`) instead of a flowsheet.
    #[arg(long, value_name = "MODEL")]
    tf: Option<PathBuf>,
    /// Manipulated inputs, comma-separated, each `PATH[@unit]` (e.g. `column.reflux@kmol/min`);
    /// with `--tf`, the model's input names to keep, in this order (default all).
    #[arg(long, value_delimiter = ',', required_unless_present = "tf")]
    inputs: Vec<String>,
    /// Outputs, comma-separated variable paths, each `PATH[@unit]`; with `--tf`, the model's
    /// output names to keep, in this order (default all).
    #[arg(long, value_delimiter = ',', required_unless_present = "tf")]
    outputs: Vec<String>,
    /// Pairing for the Niederlinski index and RGA number: `OUT=IN,…` or input positions in output
    /// order (`2,1`); default: diagonal.
    #[arg(long)]
    pairing: Option<String>,
    /// A block for the block relative gain, `OUTPUTS=INPUTS` (paths or 1-based positions, e.g.
    /// `1,2=1,2`); repeatable.
    #[arg(long = "block", value_name = "OUTPUTS=INPUTS")]
    blocks: Vec<String>,
    /// How the gains are obtained.
    #[arg(long, value_enum, default_value_t = Method::Linear)]
    method: Method,
    /// Relative step of `--method perturb`'s first attempt (default: chosen from the scales of
    /// the inputs and outputs); the gains are verified at h and h/2 and the step shrunk until
    /// they agree.
    #[arg(long)]
    step: Option<f64>,
    /// Expected range of each input, for scaling (quantities, or numbers in the display units).
    #[arg(long, value_delimiter = ',', value_name = "RANGE")]
    input_ranges: Vec<String>,
    /// Allowed deviation of each output, for scaling (quantities, or numbers in the display units).
    #[arg(long, value_delimiter = ',', value_name = "RANGE")]
    output_ranges: Vec<String>,
    /// Frequency-dependent RGA and singular values at `LOW:HIGH:N` (log-spaced, rad per
    /// `--time-unit`).
    #[arg(long, value_name = "LOW:HIGH:N")]
    frequencies: Option<String>,
    /// Time unit of `--frequencies` (default s).
    #[arg(long, default_value = "s")]
    time_unit: String,
    /// Print exactly `{"method","inputs","outputs","gain","rga","singular_values","condition_number","niederlinski"}`,
    /// for `--method perturb` also `"perturbation": {"step","steps","check","max_relative_difference",…}`, and
    /// with `--frequencies` also `"frequency": {"time_unit", "points": [{"omega", "g", "singular_values", "rga",
    /// "rga_number"}]}` (complex entries as `{"re","im","magnitude","phase_deg"}`).
    #[arg(long)]
    json: bool,
    /// Override an input or a unit parameter first, e.g. `--set feed_source.F=1.01kmol/min`.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
    /// Draw the relative gain array as a heat map here (`.png` or `.svg`).
    #[arg(long, value_name = "RGA.png", value_parser = super::output_file)]
    plot: Option<PathBuf>,
}

fn analysis_error(e: AnalysisError) -> CliError {
    if e.is_user_error() { CliError::user(e.to_string()) } else { CliError::numerical(e.to_string()) }
}

/// A range: a bare number in the display unit, or a quantity of the signal's dimension.
fn range(text: &str, dim: Option<(Dimension, f64)>) -> Result<f64, CliError> {
    if let Ok(v) = text.trim().parse::<f64>() {
        return Ok(v);
    }
    let Some((dim, factor)) = dim else {
        return Err(CliError::user(format!(
            "`{text}`: a transfer-function model takes ranges as numbers in its signals' units"
        )));
    };
    parse_quantity_as(text, dim).map(|si| si / factor).map_err(|e| CliError::user(format!("range `{text}`: {e}")))
}

/// Dimension and display-unit factor of each input or output (flowsheets only).
type Units = Vec<(Dimension, f64)>;

fn options(
    a: &GainsArgs,
    inputs: &[String],
    outputs: &[String],
    units: Option<(Units, Units)>,
) -> Result<ReportOptions, CliError> {
    let pairing =
        a.pairing.as_deref().map(|p| parse_pairing(p, outputs, inputs)).transpose().map_err(analysis_error)?;
    let blocks = a
        .blocks
        .iter()
        .map(|b| parse_block(b, outputs, inputs))
        .collect::<Result<Vec<_>, _>>()
        .map_err(analysis_error)?;
    let scaling = match (a.input_ranges.is_empty(), a.output_ranges.is_empty()) {
        (true, true) => None,
        (false, false) => {
            let (di, dout): (Vec<_>, Vec<_>) = match &units {
                Some((i, o)) => (i.iter().map(|d| Some(*d)).collect(), o.iter().map(|d| Some(*d)).collect()),
                None => (vec![None; inputs.len()], vec![None; outputs.len()]),
            };
            if a.input_ranges.len() != inputs.len() || a.output_ranges.len() != outputs.len() {
                return Err(CliError::user(format!(
                    "--input-ranges needs {} values and --output-ranges {} (one per input and output)",
                    inputs.len(),
                    outputs.len()
                )));
            }
            let ir = a.input_ranges.iter().zip(di).map(|(t, d)| range(t, d)).collect::<Result<Vec<_>, _>>()?;
            let or = a.output_ranges.iter().zip(dout).map(|(t, d)| range(t, d)).collect::<Result<Vec<_>, _>>()?;
            Some((ir, or))
        }
        _ => return Err(CliError::user("scaling needs both --input-ranges and --output-ranges")),
    };
    Ok(ReportOptions { pairing, blocks, scaling })
}

pub fn run(a: &GainsArgs, units: UnitSystem) -> Result<(), CliError> {
    if let Some(tf) = &a.tf {
        return run_tf(a, tf);
    }
    let Some(file) = &a.file else { return Err(CliError::user("give a flowsheet FILE or --tf MODEL")) };
    let (plant, u) = load_with_overrides(file, &a.set)?;
    let inputs = select_inputs(&plant, &in_system(&plant, &a.inputs, units)).map_err(analysis_error)?;
    let outputs = select_outputs(&plant, &in_system(&plant, &a.outputs, units)).map_err(analysis_error)?;
    let dims = (
        inputs.iter().map(|s| (plant.inputs()[s.index].dim, s.factor)).collect(),
        outputs.iter().map(|s| (plant.vars()[s.index].spec.dim, s.factor)).collect(),
    );
    let opts = options(a, &a.inputs, &a.outputs, Some(dims))?;
    let ss = converge(&plant, &u)?;
    let method = match a.method {
        Method::Linear => GainMethod::Linear,
        Method::Perturb => GainMethod::Perturb { step: a.step },
    };
    let PlantGains { report, perturbation } =
        plant_gains(&plant, (&ss.x, &ss.u), (&inputs, &outputs), method, &opts).map_err(analysis_error)?;
    let frequency = match &a.frequencies {
        Some(text) => {
            let tu = TimeUnit::parse(&a.time_unit)?;
            let omegas = frequency_grid(text, &tu)?;
            let (ii, oo): (Vec<usize>, Vec<usize>) =
                (inputs.iter().map(|s| s.index).collect(), outputs.iter().map(|s| s.index).collect());
            let lin = Linearization::new(&plant, &ss.x, &ss.u);
            let responses = lin.frequency_response(&ii, &oo, &omegas).map_err(analysis_error)?;
            let scale = |g: &Mat<c64>| {
                Mat::from_fn(g.nrows(), g.ncols(), |i, j| g[(i, j)] * (inputs[j].factor / outputs[i].factor))
            };
            let scaled: Vec<Mat<c64>> = responses.iter().map(scale).collect();
            Some(frequency_results(&report, &omegas, &scaled, &tu))
        }
        None => None,
    };
    if let Some(p) = &a.plot {
        report::gains::plot_rga(p, plant.name(), &report).map_err(|e| CliError::user(e.to_string()))?;
    }
    if a.json {
        let check = perturbation.as_ref().map(|p| &p.check);
        let json =
            report::gains::json(&report, check, frequency.as_ref()).map_err(|e| CliError::user(e.to_string()))?;
        outln!("{json}");
        return Ok(());
    }
    out!("{}", report::gains::plant_text(plant.name(), &report, perturbation.as_ref(), frequency.as_ref()));
    Ok(())
}

/// The frequency results at `omegas` [rad/s] of the responses (display units), ω reported per
/// `tu`.
fn frequency_results(r: &GainReport, omegas: &[f64], responses: &[Mat<c64>], tu: &TimeUnit) -> FrequencyResults {
    let pairing = r.pairing.clone().unwrap_or_default();
    let points = omegas.iter().zip(responses).map(|(w, g)| frequency::point(w * tu.seconds, g, &pairing)).collect();
    FrequencyResults { time_unit: tu.name.clone(), points }
}

fn run_tf(a: &GainsArgs, file: &Path) -> Result<(), CliError> {
    let name = file.display().to_string();
    let text = plantwide::flowsheet::read_text(file).map_err(|e| CliError::user(e.to_string()))?;
    let model = tf::parse(&text, &name).map_err(|e| CliError::user(e.to_string()))?;
    let model = model.select(&a.inputs, &a.outputs).map_err(|e| CliError::user(format!("{name}: {e}")))?;
    if a.method == Method::Perturb {
        return Err(CliError::user(
            "--method perturb needs a flowsheet; a transfer-function model's gains are its element gains",
        ));
    }
    let label = |s: &TfSignal| SignalLabel { path: s.name.clone(), unit: s.unit.clone() };
    let ins: Vec<String> = model.inputs.iter().map(|s| s.name.clone()).collect();
    let outs: Vec<String> = model.outputs.iter().map(|s| s.name.clone()).collect();
    let opts = options(a, &ins, &outs, None)?;
    let report = GainReport::new(
        "transfer_function",
        model.inputs.iter().map(label).collect(),
        model.outputs.iter().map(label).collect(),
        model.gain(),
        &opts,
    )
    .map_err(analysis_error)?;
    let frequency = match &a.frequencies {
        Some(text) => {
            let tu = TimeUnit::parse(&a.time_unit)?;
            let omegas = frequency_grid(text, &tu)?;
            let responses: Vec<Mat<c64>> = omegas.iter().map(|&w| model.response(w)).collect();
            Some(frequency_results(&report, &omegas, &responses, &tu))
        }
        None => None,
    };
    if let Some(p) = &a.plot {
        report::gains::plot_rga(p, &model.name, &report).map_err(|e| CliError::user(e.to_string()))?;
    }
    if a.json {
        let json = report::gains::json(&report, None, frequency.as_ref()).map_err(|e| CliError::user(e.to_string()))?;
        outln!("{json}");
        return Ok(());
    }
    out!("{}", report::gains::tf_text(&model, &name, &report, frequency.as_ref()));
    Ok(())
}

/// Arguments of `plantwide sensors`.
#[derive(Debug, clap::Args)]
pub struct SensorsArgs {
    /// Flowsheet file (JSON).
    file: PathBuf,
    /// The column whose stage temperatures `NAME.T[i]` are candidates.
    #[arg(long)]
    column: String,
    /// Manipulated inputs, comma-separated, each `PATH[@unit]`.
    #[arg(long, value_delimiter = ',', required = true)]
    inputs: Vec<String>,
    /// Print JSON.
    #[arg(long)]
    json: bool,
    /// Override an input or a unit parameter first.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
}

pub fn run_sensors(a: &SensorsArgs, units: UnitSystem) -> Result<(), CliError> {
    let (plant, u) = load_with_overrides(&a.file, &a.set)?;
    let inputs = select_inputs(&plant, &in_system(&plant, &a.inputs, units)).map_err(analysis_error)?;
    let temperature = plantwide::units::Display::new(&units.unit_for(Dimension::TEMPERATURE))
        .map_err(|e| CliError::user(e.to_string()))?;
    let ss = converge(&plant, &u)?;
    let s = select_temperature_sensors(&plant, &ss.x, &ss.u, &a.column, &inputs).map_err(analysis_error)?;
    if a.json {
        let json = report::sensors::json(&a.column, &inputs, &s).map_err(|e| CliError::user(e.to_string()))?;
        outln!("{json}");
        return Ok(());
    }
    out!("{}", report::sensors::text(plant.name(), &a.column, &inputs, &s, &temperature));
    Ok(())
}
