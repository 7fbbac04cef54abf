//! `plantwide size FILE --vessel V --disturbance PATH=±Δ --level-band Δh --max-outflow-rate r
//! [--json] [--plot OUT]`: the cross-section and level controller (P, critically damped PI,
//! optimal averaging) that keep a vessel's level within `±Δh` and its outflow's rate under `r`,
//! each verified by a nonlinear run; `--candidates V1,V2,…` ranks where surge capacity does it
//! with the least volume.

use std::path::{Path, PathBuf};

use plantwide::io::{IoError, report};
use plantwide::studies::size::{Progress, SizeError, SizeRequest, size};
use plantwide::units::{QuantityValue, UnitSystem};

use super::CliError;
use super::steady::{converge, load_with_overrides};

/// Arguments of `plantwide size`.
#[derive(Debug, clap::Args)]
pub struct SizeArgs {
    /// Flowsheet file (JSON).
    #[arg(value_name = "FILE")]
    file: PathBuf,
    /// The vessel: a tank, CSTR or flash; a column's `COL.drum` or `COL.sump`; or a stream, for a
    /// new surge tank on it.
    #[arg(long, value_name = "V", required_unless_present = "candidates", conflicts_with = "candidates")]
    vessel: Option<String>,
    /// Rank these vessels (same forms as --vessel) by the surge volume they need.
    #[arg(long, value_name = "V1,V2,…", value_delimiter = ',')]
    candidates: Vec<String>,
    /// The disturbance, a step of an input: PATH=+x% or -x% (of its value), or an amount with its
    /// unit (PATH=+5 kmol/h, PATH=-2 K).
    #[arg(long, value_name = "PATH=±Δ", required_unless_present = "scenario")]
    disturbance: Option<String>,
    /// The disturbance as the one step, ramp or sinusoid of a scenario file (started at once from
    /// the steady state), instead of --disturbance.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["disturbance", "ramp", "sine", "attenuation"])]
    scenario: Option<PathBuf>,
    /// The disturbance as a ramp to the same change over this time, instead of a step.
    #[arg(long, value_name = "TIME", conflicts_with = "sine")]
    ramp: Option<String>,
    /// The disturbance as a sinusoid of amplitude Δ and this period, instead of a step.
    #[arg(long, value_name = "PERIOD")]
    sine: Option<String>,
    /// The largest allowed deviation of the level from its setpoint, either way (a length).
    #[arg(long, value_name = "Δh", allow_hyphen_values = true)]
    level_band: String,
    /// The largest allowed rate of change of the vessel's outflow (e.g. "5 kmol/h/min").
    #[arg(long, value_name = "r", allow_hyphen_values = true, required_unless_present = "attenuation")]
    max_outflow_rate: Option<String>,
    /// Instead of a rate limit: the outflow of the disturbance, a sinusoid of amplitude Δ at
    /// --period, may swing at most this fraction of the inflow's (in (0, 1)).
    #[arg(long, value_name = "RATIO", requires = "period", conflicts_with_all = ["max_outflow_rate", "ramp", "sine"], allow_hyphen_values = true)]
    attenuation: Option<f64>,
    /// The period of --attenuation.
    #[arg(long, value_name = "PERIOD", requires = "attenuation")]
    period: Option<String>,
    /// Length of each verification run (default: long enough for the design and the plant to
    /// settle); a run of a step or a ramp not settled by then is marked failed.
    #[arg(long, value_name = "TIME")]
    duration: Option<String>,
    /// Override an input or unit field before converging (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
    /// Print JSON (SI units) instead of a table.
    #[arg(long)]
    json: bool,
    /// Write a plot here (.png or .svg): the designs' level and outflow, or the candidates' volumes.
    #[arg(long, value_name = "OUT")]
    plot: Option<PathBuf>,
    /// Write the report to this folder: size.md and size.html (the table and the figure), size.json,
    /// size.svg.
    #[arg(long, value_name = "DIR")]
    report: Option<PathBuf>,
    /// Report each design and run as it is done on stderr even when stderr is not a terminal (a
    /// terminal gets a progress bar without it).
    #[arg(long)]
    progress: bool,
}

/// A refusal or failure of the library: its field's name (`level_band`) read as the flag it came
/// from (`--level-band`).
fn size_error(e: SizeError, a: &SizeArgs) -> CliError {
    let mut message = e.to_string();
    if let Some(field) = e.field()
        && let Some(rest) = message.strip_prefix(field)
    {
        message = format!("{}{rest}", flag(field, a));
    }
    if e.is_user_error() { CliError::user(message) } else { CliError::numerical(message) }
}

/// The flag of a [`SizeRequest`] field (`--scenario FILE` with its file).
fn flag(field: &str, a: &SizeArgs) -> String {
    match (field, &a.scenario) {
        ("scenario", Some(file)) => format!("--scenario {}", file.display()),
        _ => format!("--{}", field.replace('_', "-")),
    }
}

/// Run `plantwide size`: the report is printed whole (a failed part marked where it stands), then
/// the command exits 2 when a part failed or the plot had nothing to show.
pub fn run(a: &SizeArgs, system: UnitSystem) -> Result<(), CliError> {
    let (plant, u) = load_with_overrides(&a.file, &a.set)?;
    let request = request(a)?;
    request.criteria(&plant).map_err(|e| size_error(e, a))?;
    if let Some(out) = &a.plot {
        check_plot_path(out)?;
    }
    let x = converge(&plant, &u)?.x;
    let parts = request.parts();
    let bar = progress_bar(parts as u64);
    let lines = a.progress && !std::io::IsTerminal::is_terminal(&std::io::stderr());
    let tell = |p: Progress<'_>| {
        bar.inc(1);
        let how = if p.failed { "failed" } else { "done" };
        let message = format!("`{}`: {} {how}", p.vessel, p.part);
        if lines {
            eprintln!("size: {}/{parts} {message}", bar.position());
        }
        bar.set_message(message);
    };
    let sizing = size(&plant, &x, &request, &tell);
    bar.finish_and_clear();
    let sizing = sizing.map_err(|e| size_error(e, a))?;
    let io = |e: IoError| {
        if e.is_missing_result() { CliError::numerical(e.to_string()) } else { CliError::user(e.to_string()) }
    };
    let plotted = a.plot.as_deref().map(|out| report::size::plot(out, &sizing, system)).transpose();
    if a.json {
        outln!("{}", report::json(&sizing).map_err(io)?);
    } else {
        outln!("{}", report::size::text(&sizing, &plant, system).map_err(io)?);
    }
    if let Some(dir) = &a.report {
        report::size::write_report(dir, &sizing, &plant, system).map_err(|e| {
            let e = io(e);
            CliError { message: format!("--report {}", e.message), code: e.code }
        })?;
    }
    let plot_error = plotted.err().map(|e| {
        let e = io(e);
        CliError { message: format!("--plot {}", e.message), code: e.code }
    });
    match (super::screen::failed_parts("size", sizing.failed()), plot_error) {
        (Ok(()), None) => Ok(()),
        (Ok(()), Some(e)) => Err(e),
        (Err(e), None) => Err(e),
        (Err(e), Some(p)) => Err(CliError { message: format!("{}; {}", e.message, p.message), code: e.code }),
    }
}

/// Refuse a plot that could not be written before the runs, not after them: a name ending in
/// neither `.png` nor `.svg`, or a folder that does not exist.
fn check_plot_path(out: &Path) -> Result<(), CliError> {
    let ext = out.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("png" | "svg")) {
        return Err(CliError::user(format!("--plot {}: the plot file must end in .png or .svg", out.display())));
    }
    match out.parent().filter(|p| !p.as_os_str().is_empty()) {
        Some(dir) if !dir.is_dir() => Err(CliError::user(format!(
            "--plot {}: the folder {} does not exist (create it first)",
            out.display(),
            dir.display()
        ))),
        _ => Ok(()),
    }
}

/// A bar of `parts` on stderr, drawn only when stderr is a terminal (never on stdout; `--progress`
/// prints a line per part instead where it is not).
fn progress_bar(parts: u64) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(parts);
    bar.set_style(
        indicatif::ProgressStyle::with_template("sizing {pos}/{len} parts [{elapsed_precise}] {bar:30} {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.enable_steady_tick(std::time::Duration::from_millis(250));
    bar
}

/// The flags as the library's request (quantities as written; the library reads their units).
fn request(a: &SizeArgs) -> Result<SizeRequest, CliError> {
    let scenario = match &a.scenario {
        Some(file) => {
            let name = file.display().to_string();
            let text = plantwide::flowsheet::read_text(file).map_err(|e| CliError::user(format!("--scenario {e}")))?;
            let spec = plantwide::flowsheet::scenario::parse_scenario(&text, &name)
                .map_err(|e| CliError::user(e.to_string()))?;
            Some(spec)
        }
        None => None,
    };
    let quantity = |t: &Option<String>| t.as_deref().map(QuantityValue::from);
    Ok(SizeRequest {
        vessel: a.vessel.clone(),
        candidates: a.candidates.clone(),
        disturbance: a.disturbance.clone(),
        scenario,
        ramp: quantity(&a.ramp),
        sine: quantity(&a.sine),
        level_band: QuantityValue::from(a.level_band.as_str()),
        max_outflow_rate: quantity(&a.max_outflow_rate),
        attenuation: a.attenuation,
        period: quantity(&a.period),
        duration: quantity(&a.duration),
    })
}
