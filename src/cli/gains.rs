//! `plantwide gains FILE --inputs P1,P2 --outputs Q1,Q2 [--pairing …] [--method linear|perturb]
//! [--json]`, `plantwide gains --tf MODEL.tf.json`, and `plantwide sensors FILE --column NAME
//! --inputs …`.

use std::path::{Path, PathBuf};

use plantwide::analysis::AnalysisError;
use plantwide::analysis::faer::{Mat, c64};
use plantwide::analysis::frequency::{self, FrequencyResults};
use plantwide::analysis::linear::Linearization;
use plantwide::analysis::measures::rows;
use plantwide::analysis::perturb::PerturbGains;
use plantwide::analysis::plant_model::{GainMethod, PlantGains, plant_gains};
use plantwide::analysis::report::{GainJson, GainReport, ReportOptions};
use plantwide::analysis::select::{
    Signal, SignalLabel, in_system, parse_block, parse_pairing, select_inputs, select_outputs,
};
use plantwide::analysis::sensors::select_temperature_sensors;
use plantwide::analysis::tf::TfSignal;
use plantwide::io::plot::{LabelledMatrix, write_matrices};
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

/// The RGA heat map of `r` into `file`, titled by `name`.
fn plot_rga(file: &Path, name: &str, r: &GainReport) -> Result<(), CliError> {
    let matrix = LabelledMatrix {
        label: "Λ(0)".into(),
        values: r.rga.as_ref().map(|l| rows(l.as_ref())),
        rows: r.outputs.iter().map(|s| s.path.clone()).collect(),
        cols: r.inputs.iter().map(|s| s.path.clone()).collect(),
    };
    write_matrices(file, &format!("relative gains of `{name}`"), &[matrix]).map_err(|e| CliError::user(e.to_string()))
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
    let note =
        perturbation.as_ref().map_or("linearization at the steady state, G(0) = −C J⁻¹ B".to_string(), perturb_note);
    let check = perturbation.map(|p| p.check);
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
        plot_rga(p, plant.name(), &report)?;
    }
    if a.json {
        let json = GainJson { perturbation: check.as_ref(), frequency: frequency.as_ref(), ..report.json() };
        outln!("{}", serde_json::to_string_pretty(&json).map_err(|e| CliError::user(e.to_string()))?);
        return Ok(());
    }
    outln!("steady-state gains of `{}` ({note})\n", plant.name());
    print_report(&report);
    if let Some(f) = &frequency {
        print_frequency_table(&report, f);
    }
    Ok(())
}

/// How perturbation gains were found and verified, in words.
fn perturb_note(p: &PerturbGains) -> String {
    let c = &p.check;
    format!(
        "perturbation: each input ± h and ± h/2 (relative h ≤ {:.1e}), re-converged, central differences extrapolated (Richardson); h vs h/2 differ by ≤ {:.1e}{} ({} attempt(s), {} Newton iterations; convergence error ≤ {:.1e} of the effect)",
        c.step,
        c.max_relative_difference,
        c.linear_relative_difference.map_or(String::new(), |d| format!(", linearization by {d:.1e}")),
        c.attempts,
        p.newton_iterations,
        p.error_ratio
    )
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
        plot_rga(p, &model.name, &report)?;
    }
    if a.json {
        let json = GainJson { frequency: frequency.as_ref(), ..report.json() };
        outln!("{}", serde_json::to_string_pretty(&json).map_err(|e| CliError::user(e.to_string()))?);
        return Ok(());
    }
    outln!("steady-state gains of `{}` (transfer-function model {name})\n", model.name);
    print_report(&report);
    if !model.disturbances.is_empty() {
        let gd = model.disturbance_gain();
        outln!("\ndisturbance gains Gd(0):");
        for (i, o) in model.outputs.iter().enumerate() {
            let cells: Vec<String> =
                (0..gd.ncols()).map(|j| format!("{}: {}", model.disturbances[j].name, sig(gd[(i, j)]))).collect();
            outln!("  {:<24} {}", o.name, cells.join("  "));
        }
    }
    if let Some(f) = &frequency {
        print_frequency_table(&report, f);
    }
    Ok(())
}

/// A number with 6 significant digits: fixed notation for magnitudes in [1e-3, 1e6), else
/// scientific.
pub fn sig(v: f64) -> String {
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

fn heading(s: &SignalLabel) -> String {
    format!("{} [{}]", s.path, s.unit)
}

fn print_matrix(title: &str, rows_: &[SignalLabel], cols: &[SignalLabel], m: &Mat<f64>) {
    let w = rows_.iter().map(|s| heading(s).chars().count()).max().unwrap_or(0).max(title.chars().count());
    let cw = cols.iter().map(|s| heading(s).chars().count()).max().unwrap_or(0).max(14);
    out!("{title:<w$}");
    for c in cols {
        out!("  {:>cw$}", heading(c));
    }
    outln!();
    for (i, r) in rows_.iter().enumerate() {
        out!("{:<w$}", heading(r));
        for j in 0..cols.len() {
            out!("  {:>cw$}", sig(m[(i, j)]));
        }
        outln!();
    }
}

fn print_report(r: &GainReport) {
    print_matrix("gain", &r.outputs, &r.inputs, &r.gain);
    outln!();
    match &r.rga {
        Some(l) => print_matrix("relative gain array", &r.outputs, &r.inputs, l),
        None => outln!("relative gain array: undefined (the gain matrix is singular)"),
    }
    let sv: Vec<String> = r.svd.singular_values.iter().map(|s| sig(*s)).collect();
    outln!("\nsingular values: {}", sv.join(", "));
    outln!("condition number: {}", sig(r.condition_number));
    if let Some(g) = r.min_condition_number {
        outln!("minimized condition number (optimal input and output scaling): {}", sig(g));
    }
    let dir_labels = |n: usize| {
        (1..=n).map(|k| SignalLabel { path: format!("direction {k}"), unit: "-".into() }).collect::<Vec<_>>()
    };
    let k = r.svd.singular_values.len();
    outln!();
    print_matrix("output directions U", &r.outputs, &dir_labels(k), &r.svd.u);
    print_matrix("input directions V", &r.inputs, &dir_labels(k), &r.svd.v);
    if let (Some(p), Some(ni), Some(rn)) = (&r.pairing, r.niederlinski, r.rga_number) {
        let pairs: Vec<String> =
            p.iter().enumerate().map(|(i, &j)| format!("{}–{}", r.outputs[i].path, r.inputs[j].path)).collect();
        outln!("\npairing: {}", pairs.join(", "));
        if let Some(l) = &r.rga {
            let lam: Vec<String> = p.iter().enumerate().map(|(i, &j)| format!("{:.4}", l[(i, j)])).collect();
            outln!("paired relative gains: {}", lam.join(", "));
        }
        let verdict = if ni < 0.0 { " (negative: unstable under integral action for any tuning)" } else { "" };
        outln!("Niederlinski index: {ni:.6}{verdict}");
        outln!("RGA number: {rn:.4}");
    }
    for (b, m) in &r.block_relative_gains {
        let outs: Vec<&str> = b.outputs.iter().map(|&i| r.outputs[i].path.as_str()).collect();
        let ins: Vec<&str> = b.inputs.iter().map(|&j| r.inputs[j].path.as_str()).collect();
        let det = m.determinant();
        outln!("\nblock relative gain of {} with {} (det {det:.6}):", outs.join(", "), ins.join(", "));
        for row in rows(m.as_ref()) {
            let cells: Vec<String> = row.iter().map(|v| format!("{v:>14.6}")).collect();
            outln!("  {}", cells.join(" "));
        }
    }
    if let Some(s) = &r.scaled {
        outln!();
        print_matrix("scaled gain", &r.outputs, &r.inputs, &s.gain);
        let sv: Vec<String> = s.singular_values.iter().map(|v| sig(*v)).collect();
        outln!("scaled singular values: {}; condition number {:.4}", sv.join(", "), s.condition_number);
        outln!("Morari resiliency index (smallest scaled singular value): {:.6}", s.resiliency_index);
    }
}

fn print_frequency_table(r: &GainReport, f: &FrequencyResults) {
    outln!("\nfrequency response (ω in rad/{}):", f.time_unit);
    let pairing = r.pairing.clone().unwrap_or_default();
    out!("{:>12} {:>14} {:>14}", "ω", "σ_max", "σ_min");
    for (i, &j) in pairing.iter().enumerate() {
        out!(" {:>12}", format!("|λ{}{}|", i + 1, j + 1));
    }
    outln!(" {:>12}", if pairing.is_empty() { "" } else { "RGA number" });
    for p in &f.points {
        let sv = &p.singular_values;
        let (smax, smin) = (sv.first().copied().unwrap_or(f64::NAN), sv.last().copied().unwrap_or(f64::NAN));
        out!("{:>12} {:>14} {:>14}", sig(p.omega), sig(smax), sig(smin));
        match (&p.rga, p.rga_number) {
            (Some(l), Some(number)) => {
                for (i, &j) in pairing.iter().enumerate() {
                    out!(" {:>12}", sig(l[i][j].magnitude));
                }
                outln!(" {:>12}", sig(number));
            }
            _ => outln!(),
        }
    }
    outln!("\nG(jω) elements, |g| and phase [deg]:");
    out!("{:>12}", "ω");
    for o in &r.outputs {
        for i in &r.inputs {
            out!(" {:>26}", format!("{} ← {}", truncate(&o.path, 11), truncate(&i.path, 11)));
        }
    }
    outln!();
    for p in &f.points {
        out!("{:>12}", sig(p.omega));
        for row in &p.g {
            for z in row {
                out!(" {:>26}", format!("{} ∠{:.2}", sig(z.magnitude), z.phase_deg));
            }
        }
        outln!();
    }
}

/// The first `n` characters of `s`.
fn truncate(s: &str, n: usize) -> String {
    s.chars().take(n).collect()
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
    let tu = temperature.unit().to_string();
    let ss = converge(&plant, &u)?;
    let s = select_temperature_sensors(&plant, &ss.x, &ss.u, &a.column, &inputs).map_err(analysis_error)?;
    if a.json {
        let doc = serde_json::json!({
            "column": a.column,
            "inputs": inputs.iter().map(Signal::label).collect::<Vec<_>>(),
            "stages": s.stages,
            "temperatures": s.temperatures,
            "gains": rows(s.gains.as_ref()),
            "singular_values": s.singular_values,
            "u": rows(s.u.as_ref()),
            "svd_stages": s.svd_stages,
            "sensitivity_stages": s.sensitivity_stages,
            "slope": {"stages": [s.slope.0.0, s.slope.0.1], "difference": s.slope.1},
        });
        outln!("{}", serde_json::to_string_pretty(&doc).map_err(|e| CliError::user(e.to_string()))?);
        return Ok(());
    }
    outln!("temperature-sensor selection for `{}` in `{}` (gains in {tu} per input unit)\n", a.column, plant.name());
    out!("{:>6} {:>10} {:>9}", "stage", format!("T [{tu}]"), format!("ΔT [{tu}]"));
    // Each input by its whole path (two loops' `op_manual` would read alike), the gain's unit as
    // "per" the input's (a compound unit after `/` would read as a quotient of the two).
    let headers: Vec<String> = inputs.iter().map(|i| format!("dT/d({}) [{tu} per {}]", i.path, i.unit)).collect();
    let widths: Vec<usize> = headers.iter().map(|h| h.chars().count().max(12)).collect();
    for (h, w) in headers.iter().zip(&widths) {
        out!(" {h:>w$}");
    }
    for k in 0..s.singular_values.len() {
        out!(" {:>8}", format!("|U{}|", k + 1));
    }
    outln!();
    for (r, stage) in s.stages.iter().enumerate() {
        let dt = if r + 1 < s.stages.len() {
            format!("{:.4}", temperature.difference(s.temperatures[r + 1] - s.temperatures[r]))
        } else {
            String::new()
        };
        out!("{:>6} {:>10.4} {:>9}", stage, temperature.value(s.temperatures[r]), dt);
        for (j, w) in widths.iter().enumerate() {
            out!(" {:>w$}", sig(temperature.difference(s.gains[(r, j)])));
        }
        for k in 0..s.singular_values.len() {
            out!(" {:>8.4}", s.u[(r, k)].abs());
        }
        outln!();
    }
    let sv: Vec<String> = s.singular_values.iter().map(|v| sig(*v)).collect();
    outln!("\nsingular values: {}", sv.join(", "));
    let stages = |v: &[usize]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>().join(", ");
    outln!("SVD criterion (largest |U| per singular direction): stages {}", stages(&s.svd_stages));
    outln!("sensitivity criterion (largest |gain| per input): stages {}", stages(&s.sensitivity_stages));
    outln!(
        "slope criterion (largest ΔT between adjacent stages): stages {} and {} ({:.4} {tu})",
        s.slope.0.0,
        s.slope.0.1,
        temperature.difference(s.slope.1)
    );
    Ok(())
}
