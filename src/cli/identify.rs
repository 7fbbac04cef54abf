//! `plantwide identify FILE --inputs … --outputs … [--design prbs|gbn|directional] [--noise σ]
//! [--seed N] [--duration T] [--closed-loop] [--json] [--report DIR]`: a plant test on the
//! nonlinear model, FIR/ARX/OE fits and their validation (the reference book's chapter 7).

use std::path::{Path, PathBuf};

use plantwide::analysis::select::{Signal, in_system, select_inputs, select_outputs};
use plantwide::io::html::markdown_to_html;
use plantwide::io::plot::{Overlay, write_overlays};
use plantwide::studies::identify::{Design, Identification, IdentifySettings, identify, number};
use plantwide::units::{Dimension, UnitSystem, parse_quantity_as};

use super::CliError;
use super::steady::{converge, load_with_overrides};

/// Test signal family (`--design`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DesignArg {
    /// Delayed copies of one PRBS (Eq. 7-10).
    Prbs,
    /// Independent generalized binary noise.
    Gbn,
    /// Independent signals along the input singular directions of the model's gain, the low-gain
    /// direction amplified (Koung & MacGregor 1991): for ill-conditioned plants.
    Directional,
}

/// Arguments of `plantwide identify`.
#[derive(Debug, clap::Args)]
pub struct IdentifyArgs {
    /// Flowsheet file (JSON).
    file: PathBuf,
    /// Inputs moved by the test, comma-separated, each `PATH[@unit]`.
    #[arg(long, value_delimiter = ',', required = true)]
    inputs: Vec<String>,
    /// Outputs measured, comma-separated, each `PATH[@unit]`.
    #[arg(long, value_delimiter = ',', required = true)]
    outputs: Vec<String>,
    /// Test signals.
    #[arg(long, value_enum, default_value_t = DesignArg::Directional)]
    design: DesignArg,
    /// White measurement noise σ per output, in the output's display unit (one for all, or one
    /// per output, comma-separated).
    #[arg(long, value_delimiter = ',', value_name = "σ", action = clap::ArgAction::Set)]
    noise: Vec<f64>,
    /// Seed of the test signals and the noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Length of the estimation test, e.g. `8000 min` (default four PRBS periods).
    #[arg(long, value_name = "T")]
    duration: Option<String>,
    /// Sample time, e.g. `10 min` (default τ_dom/20).
    #[arg(long, value_name = "T")]
    sample_time: Option<String>,
    /// Dominant time constant, e.g. `190 min` (default: the slowest of the exact linear model).
    #[arg(long, value_name = "T")]
    tau_dom: Option<String>,
    /// Largest move per input, in the input's display unit (one for all, or one per input;
    /// default 1 % of the steady value).
    #[arg(long, value_delimiter = ',', action = clap::ArgAction::Set)]
    amplitude: Vec<f64>,
    /// Closed-loop speed factor α of the PRBS design (Eq. 7-7).
    #[arg(long, default_value_t = 2.0)]
    alpha: f64,
    /// Settling factor β of the PRBS design (3: 95 %, 4: 98 %, 5: 99 %).
    #[arg(long, default_value_t = 3.0)]
    beta: f64,
    /// Directional design: output amplitude of the high-gain directions relative to the
    /// low-gain one's (1: Koung & MacGregor's equal amplitudes).
    #[arg(long, default_value_t = 2.0)]
    high_gain_boost: f64,
    /// Test in closed loop: the inputs are the outputs of the file's controllers, whose
    /// setpoints the test moves (setpoint injection).
    #[arg(long)]
    closed_loop: bool,
    /// Print `{"gain","rga","models","validation","design",…}` as JSON.
    #[arg(long)]
    json: bool,
    /// Write identify.md, identify.html, identify.json, the validation plot and step_model.json (the
    /// chosen models' step responses, a model for an `mpc` controller's `"model": {"file": …}`) here;
    /// step_model.json only when the verdict finds the model usable (or with --force).
    #[arg(long, value_name = "DIR")]
    report: Option<PathBuf>,
    /// Write step_model.json even when the verdict finds the model not usable (the exit code stays 2).
    #[arg(long, requires = "report")]
    force: bool,
    /// Override an input or a unit parameter first, e.g. `--set feed_source.F=1.01kmol/min`.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
}

fn time(text: &Option<String>, flag: &str) -> Result<Option<f64>, CliError> {
    text.as_deref()
        .map(|t| parse_quantity_as(t, Dimension::TIME).map_err(|e| CliError::user(format!("{flag} `{t}`: {e}"))))
        .transpose()
}

/// Per-signal values in display units to SI (one value for all signals, or one per signal).
fn to_si(values: &[f64], signals: &[Signal]) -> Vec<f64> {
    match values {
        [one] => signals.iter().map(|s| one * s.factor).collect(),
        many => many
            .iter()
            .zip(signals)
            .map(|(v, s)| v * s.factor)
            .chain(many.iter().skip(signals.len()).copied())
            .collect(),
    }
}

fn settings(a: &IdentifyArgs, inputs: &[Signal], outputs: &[Signal]) -> Result<IdentifySettings, CliError> {
    Ok(IdentifySettings {
        design: match a.design {
            DesignArg::Prbs => Design::Prbs,
            DesignArg::Gbn => Design::Gbn,
            DesignArg::Directional => Design::Directional,
        },
        noise: to_si(&a.noise, outputs),
        seed: a.seed,
        duration: time(&a.duration, "--duration")?,
        sample_time: time(&a.sample_time, "--sample-time")?,
        amplitude: (!a.amplitude.is_empty()).then(|| to_si(&a.amplitude, inputs)),
        tau_dom: time(&a.tau_dom, "--tau-dom")?,
        alpha: a.alpha,
        beta: a.beta,
        closed_loop: a.closed_loop,
        high_gain_boost: a.high_gain_boost,
    })
}

pub fn run(a: &IdentifyArgs, units: UnitSystem) -> Result<(), CliError> {
    let (plant, u) = load_with_overrides(&a.file, &a.set)?;
    let analysis = |e: plantwide::analysis::AnalysisError| {
        if e.is_user_error() { CliError::user(e.to_string()) } else { CliError::numerical(e.to_string()) }
    };
    let ss = converge(&plant, &u)?;
    let outputs = select_outputs(&plant, &in_system(&plant, &a.outputs, units)).map_err(analysis)?;
    let inputs = if a.closed_loop {
        plantwide::studies::identify::select_driven(&plant, &in_system(&plant, &a.inputs, units))
            .map_err(|e| CliError::user(e.to_string()))?
    } else {
        select_inputs(&plant, &in_system(&plant, &a.inputs, units)).map_err(analysis)?
    };
    let s = settings(a, &inputs, &outputs)?;
    let id = identify(&plant, &ss.x, &ss.u, &inputs, &outputs, &s).map_err(|e| {
        if e.is_user_error() { CliError::user(e.to_string()) } else { CliError::numerical(e.to_string()) }
    })?;
    let json = serde_json::to_string_pretty(&id).map_err(|e| CliError::user(e.to_string()))?;
    let step_model = match (&a.report, id.verdict.reliable, a.force) {
        (None, ..) => StepModel::NoReport,
        (Some(_), true, _) => StepModel::Written,
        (Some(_), false, true) => StepModel::Forced,
        (Some(_), false, false) => StepModel::Withheld,
    };
    if let Some(dir) = &a.report {
        write_report(dir, &a.file, &id, &outputs, &json, step_model)?;
    }
    if a.json {
        outln!("{json}");
    } else {
        outln!("{}", markdown(&a.file, &id, step_model));
    }
    verdict_exit(&id, step_model, a.report.as_deref())
}

/// What became of step_model.json.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum StepModel {
    /// No --report.
    NoReport,
    /// Written: the model is usable.
    Written,
    /// Written although the model is not usable (--force).
    Forced,
    /// Not written: the model is not usable.
    Withheld,
}

impl StepModel {
    fn sentence(self) -> &'static str {
        match self {
            StepModel::NoReport => "",
            StepModel::Written => "step_model.json written (the model for an `mpc` controller).",
            StepModel::Forced => {
                "step_model.json written although the model is not usable, because --force was given: an MPC on it \
                 may move the plant the wrong way or too far."
            }
            StepModel::Withheld => {
                "step_model.json not written: the model is not usable for an `mpc` controller (--force writes it \
                 anyway)."
            }
        }
    }
}

/// Exit 2 when the verdict finds the model not usable (the report, already printed, says why).
fn verdict_exit(id: &Identification, step_model: StepModel, report: Option<&Path>) -> Result<(), CliError> {
    if id.verdict.reliable {
        return Ok(());
    }
    let failed: Vec<String> = id.verdict.failed().map(|c| c.line()).collect();
    let mut file = match step_model {
        StepModel::NoReport => String::new(),
        s => format!("; {}", s.sentence().trim_end_matches('.')),
    };
    if let (StepModel::Withheld, Some(dir)) = (step_model, report)
        && dir.join("step_model.json").exists()
    {
        file.push_str(&format!(
            "; the step_model.json already in {} is an earlier run's, not this one's",
            dir.display()
        ));
    }
    Err(CliError::numerical(format!(
        "identify: the identified {} model is not usable ({} of its criteria failed, marked in the report): {}{file}",
        id.verdict.model,
        failed.len(),
        failed.join("; ")
    )))
}

fn matrix(rows: &[Vec<f64>]) -> String {
    rows.iter()
        .map(|r| format!("[{}]", r.iter().map(|v| sig(*v)).collect::<Vec<_>>().join(", ")))
        .collect::<Vec<_>>()
        .join("; ")
}

/// A number with five significant digits, fixed or in exponent form by its size.
fn sig(v: f64) -> String {
    if v == 0.0 || (1e-3..1e5).contains(&v.abs()) { format!("{v:.5}") } else { format!("{v:.4e}") }
}

/// The verdict as markdown: the overall answer, one row per criterion, and where each threshold
/// comes from.
fn verdict_markdown(id: &Identification, step_model: StepModel) -> String {
    let v = &id.verdict;
    let answer = if v.reliable { "usable" } else { "**not usable**" };
    let mut md = format!("## Verdict: the {} model is {answer}\n\n", v.model);
    let line = step_model.sentence();
    if !line.is_empty() {
        md.push_str(&format!("{line}\n\n"));
    }
    md.push_str("| criterion | at | value | must be | threshold | result |\n|---|---|---|---|---|---|\n");
    for c in &v.criteria {
        let result = match (c.pass, c.decides) {
            (true, _) => "pass",
            (false, true) => "**fail**",
            (false, false) => "warning",
        };
        let detail = c.detail.as_ref().map_or(String::new(), |d| format!(" ({d})"));
        md.push_str(&format!(
            "| {} | {}{detail} | {} | {} | {} | {result} |\n",
            c.criterion,
            c.at,
            number(c.value),
            c.must_be,
            number(c.threshold)
        ));
    }
    md.push_str("\nThresholds (a warning does not decide):\n\n");
    let mut seen = Vec::new();
    for c in &v.criteria {
        if !seen.contains(&c.criterion) {
            seen.push(c.criterion);
            md.push_str(&format!("- {}: {}\n", c.criterion, c.source));
        }
    }
    md
}

/// The identification as markdown.
fn markdown(file: &Path, id: &Identification, step_model: StepModel) -> String {
    let d = &id.design;
    let label = |s: &plantwide::analysis::select::SignalLabel| format!("`{}` [{}]", s.path, s.unit);
    let mut md = format!("# Identification of `{}`\n\n", file.display());
    md.push_str(&format!(
        "Inputs {}; outputs {}.\n\n## Test\n\n- design `{}`, τ_dom = {:.1} min, α = {}, β = {}\n- sample time {:.2} min, PRBS clock {:.1} min, {} registers (N = {}), period {:.0} min, band {:.2e}…{:.2e} rad/min\n- estimation test {:.0} min, validation test {:.0} min (fresh signals and noise)\n- amplitudes {}\n",
        id.inputs.iter().map(label).collect::<Vec<_>>().join(", "),
        id.outputs.iter().map(label).collect::<Vec<_>>().join(", "),
        serde_json::to_value(d.design).ok().and_then(|v| v.as_str().map(String::from)).unwrap_or_default(),
        d.tau_dom / 60.0, d.alpha, d.beta, d.sample_time / 60.0, d.clock_period / 60.0, d.registers, d.period_clocks,
        d.period / 60.0, d.band[0] * 60.0, d.band[1] * 60.0, d.duration / 60.0, d.validation_duration / 60.0,
        d.amplitude.iter().zip(&id.inputs).map(|(v, s)| format!("{v:.4e} {}", s.unit)).collect::<Vec<_>>().join(", "),
    ));
    if let Some(dir) = &d.directions {
        md.push_str(&format!(
            "- directions: singular values {:?} (κ = {:.1}), relative amplitudes {:?}\n",
            dir.singular_values, dir.condition_number, dir.scales
        ));
    }
    md.push('\n');
    md.push_str(&verdict_markdown(id, step_model));
    md.push_str(&format!("\n## Gains ({} model)\n\n", id.validation.model));
    md.push_str(&format!("- identified G(0) = {}\n- exact G(0) = {}\n", matrix(&id.gain), matrix(&id.exact.gain)));
    md.push_str(&format!("- relative errors {}\n", matrix(&id.exact.gain_relative_error)));
    match &id.rga {
        Some(r) => md.push_str(&format!("- identified RGA = {}\n", matrix(r))),
        None => md.push_str("- identified RGA: none (the identified gain is singular)\n"),
    }
    if let Some(r) = &id.exact.rga {
        md.push_str(&format!("- exact RGA = {}\n", matrix(r)));
    }
    if let Some(e) = id.exact.rga11_relative_error {
        md.push_str(&format!("- λ11 relative error {:.2} %\n", 100.0 * e));
    }
    md.push_str(
        "\n## Models (validation data)\n\nfit %: against the measured output; noise-free fit %: against the plant's own \
         response (what the verdict judges); reliable: the criteria of one output (denominator, gain signs, gain error, \
         fit).\n\n| output | model | orders | gains | fit % | noise-free fit % | white | independent | reliable |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for m in &id.models {
        md.push_str(&format!(
            "| `{}` | {} | {} | {} | {:.2} | {:.2} | {} | {} | {} |\n",
            m.output,
            m.model,
            m.orders,
            m.gain.iter().map(|v| sig(*v)).collect::<Vec<_>>().join(", "),
            m.fit_percent,
            m.fit_noise_free,
            m.white,
            m.independent,
            m.reliable
        ));
    }
    md
}

fn write_report(
    dir: &Path,
    file: &Path,
    id: &Identification,
    outputs: &[Signal],
    json: &str,
    step_model: StepModel,
) -> Result<(), CliError> {
    let fail = |e: std::io::Error| CliError::user(format!("--report {}: {e}", dir.display()));
    std::fs::create_dir_all(dir).map_err(fail)?;
    std::fs::write(dir.join("identify.json"), json).map_err(fail)?;
    if step_model != StepModel::Withheld {
        let model = serde_json::to_string_pretty(&id.step_model).map_err(|e| CliError::user(e.to_string()))?;
        std::fs::write(dir.join("step_model.json"), model).map_err(fail)?;
    }
    let ts = id.design.sample_time;
    let n = id.measured.first().map_or(0, Vec::len);
    let times: Vec<f64> = (0..n).map(|k| k as f64 * ts / 60.0).collect();
    let panels: Vec<Overlay> = outputs
        .iter()
        .zip(&id.measured)
        .zip(&id.validation.outputs)
        .map(|((o, y), v)| Overlay {
            label: format!("Δ{} [{}]", o.path, o.unit),
            curves: vec![
                ("measured".into(), y.iter().map(|v| v / o.factor).collect()),
                (
                    format!("{} model ({:.1} %)", id.validation.model, v.fit_percent),
                    v.predicted.iter().map(|v| v / o.factor).collect(),
                ),
            ],
            ..Overlay::default()
        })
        .collect();
    write_overlays(
        &dir.join("validation.png"),
        "validation: fresh test, model simulated",
        "time [min]",
        &times,
        &panels,
        &[],
    )
    .map_err(|e| CliError::user(format!("--report {}: {e}", dir.display())))?;
    let md = format!("{}\n![validation](validation.png)\n", markdown(file, id, step_model));
    std::fs::write(dir.join("identify.html"), markdown_to_html("Identification", &md)).map_err(fail)?;
    std::fs::write(dir.join("identify.md"), md).map_err(fail)
}
