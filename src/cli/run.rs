//! `plantwide run FILE --scenario SCEN --csv OUT.csv [--plot OUT.png|OUT.svg] [--json]
//! [--set PATH=VALUE ...] [--resume SNAPSHOT] [--units si|metric|field]`: dynamic simulation from
//! the converged steady state (or a snapshot), with a progress bar on stderr, recorded trends as
//! CSV, a summary (table, or JSON with `--json`) and an optional trend plot. Each recorded path is
//! shown (CSV, plot, table) in the unit its scenario asked for, else in the `--units` system's;
//! JSON stays in SI.

use std::path::{Path, PathBuf};
use std::time::Instant;

use plantwide::flowsheet::Plant;
use plantwide::flowsheet::scenario::ScenarioSpec;
use plantwide::flowsheet::scenario::{Limits, parse_scenario, resolve_with};
use plantwide::io::report;
use plantwide::solve::dynamic::{Progress, SimError, SimulationResult, Snapshot, Start, simulate};
use plantwide::units::{UnitSystem, convert_from_si};

use super::CliError;
use super::steady::{converge, load_with_overrides};

/// Options of `plantwide run`.
#[derive(Debug)]
pub struct RunArgs {
    /// Flowsheet file.
    pub file: PathBuf,
    /// Scenario file.
    pub scenario: PathBuf,
    /// CSV output.
    pub csv: PathBuf,
    /// Plot output (`.png` or `.svg`).
    pub plot: Option<PathBuf>,
    /// Print the summary as JSON.
    pub json: bool,
    /// `--set` overrides.
    pub set: Vec<String>,
    /// Snapshot to resume from.
    pub resume: Option<PathBuf>,
    /// Display units of the paths the scenario recorded without one.
    pub units: UnitSystem,
    /// Earlier runs' CSV files whose trends the plot overlays, dashed.
    pub compare: Vec<PathBuf>,
}

/// FNV-1a hash of the flowsheet text and the overrides: identifies the plant in snapshots.
pub(super) fn fingerprint(text: &str, sets: &[String]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes().chain(sets.iter().flat_map(|s| std::iter::once(0u8).chain(s.bytes()))) {
        h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

fn read(path: &Path) -> Result<String, CliError> {
    plantwide::flowsheet::read_text(path).map_err(|e| CliError::user(e.to_string()))
}

pub fn run(args: &RunArgs) -> Result<(), CliError> {
    let flowsheet_text = read(&args.file)?;
    let (mut plant, u) = load_with_overrides(&args.file, &args.set)?;
    plant.set_input_values(&u);
    let scen_name = args.scenario.display().to_string();
    let spec = parse_scenario(&read(&args.scenario)?, &scen_name).map_err(|e| CliError::user(e.to_string()))?;
    let sc = resolve_with(&spec, &plant, &scen_name, Limits::get()).map_err(|e| CliError::user(e.to_string()))?;
    let snapshot: Option<Snapshot> = match &args.resume {
        Some(p) => Some(
            serde_json::from_str(&read(p)?)
                .map_err(|e| CliError::user(format!("{}: not a snapshot file: {e}", p.display())))?,
        ),
        None => None,
    };
    let x0 = match &snapshot {
        Some(_) => Vec::new(),
        None => converge(&plant, &u)?.x,
    };
    let start = snapshot.as_ref().map_or(Start::Steady(&x0), Start::Snapshot);
    let time_factor = convert_from_si(1.0, &sc.time_unit).map_err(|e| CliError::user(e.to_string()))?;
    let bar = indicatif::ProgressBar::new(1000);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:40} {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let started = Instant::now();
    let mut write_error = None;
    let fp = fingerprint(&flowsheet_text, &args.set);
    let result = simulate(&plant, &sc, start, &fp, &mut |p| match p {
        Progress::Step { t, duration } => {
            let real = started.elapsed().as_secs_f64().max(1e-9);
            bar.set_position((1000.0 * t / duration) as u64);
            bar.set_message(format!("t = {:.4} {} ({:.0}× real time)", t * time_factor, sc.time_unit, t / real));
        }
        Progress::Snapshot { file, snapshot } => {
            let text = serde_json::to_string(snapshot).map_err(|e| e.to_string());
            if let Err(e) = text.and_then(|t| std::fs::write(file, t).map_err(|e| e.to_string())) {
                write_error = Some(CliError::user(format!("{file}: cannot write the snapshot: {e}")));
            }
        }
    });
    bar.finish_and_clear();
    let title = if sc.name.is_empty() { plant.name().to_string() } else { format!("{}: {}", plant.name(), sc.name) };
    let plot_cx = PlotContext { plant: &plant, spec: &spec, title: &title };
    let mut res = match result {
        Ok(res) => res,
        Err(e) if e.is_user_error() => return Err(CliError::user(e.to_string())),
        Err(SimError::Conservation { file, source, mut result }) => {
            report::run::display_units(&mut result, args.units, &spec);
            // The whole run is there: write and summarize it, then fail on the balance.
            write_trends_files(args, &result, &plot_cx, &sc.time_unit, time_factor)?;
            print_summary(&result, args.json, started.elapsed().as_secs_f64(), time_factor, &sc.time_unit)?;
            return Err(CliError::numerical(format!(
                "{file}: {source}; the integration is not to be trusted (trends in {})",
                args.csv.display()
            )));
        }
        Err(e) => {
            // The trends up to the failure show what led to it (a vessel draining, a loop saturating).
            let (SimError::Integration { partial, .. } | SimError::Stopped { partial, .. }) = &e else {
                return Err(CliError::numerical(e.to_string()));
            };
            let mut partial = partial.clone();
            report::run::display_units(&mut partial, args.units, &spec);
            let written = write_trends_files(args, &partial, &plot_cx, &sc.time_unit, time_factor);
            let at = format!("{:.6} {}", partial.t * time_factor, sc.time_unit);
            return Err(CliError::numerical(match written {
                Ok(()) => format!("{e}; the trends up to t = {at} are in {}", args.csv.display()),
                Err(w) => format!("{e}; {}", w.message),
            }));
        }
    };
    if let Some(e) = write_error {
        return Err(e);
    }
    report::run::display_units(&mut res, args.units, &spec);
    write_trends_files(args, &res, &plot_cx, &sc.time_unit, time_factor)?;
    let wall = started.elapsed().as_secs_f64();
    print_summary(&res, args.json, wall, time_factor, &sc.time_unit)
}

/// What the plot is drawn from besides the result: the plant (controller limits), the scenario
/// (panels, event labels) and the plot's title.
struct PlotContext<'a> {
    plant: &'a Plant,
    spec: &'a ScenarioSpec,
    title: &'a str,
}

/// The CSV file and, if asked for, the plot of the recorded trends.
fn write_trends_files(
    args: &RunArgs,
    res: &SimulationResult,
    cx: &PlotContext<'_>,
    time_unit: &str,
    time_factor: f64,
) -> Result<(), CliError> {
    let path = &args.csv;
    let fail = |e: std::io::Error| CliError::user(format!("{}: cannot write the CSV file: {e}", path.display()));
    std::fs::write(path, report::run::csv(res, time_unit, time_factor)).map_err(fail)?;
    if let Some(p) = &args.plot {
        let others = args.compare.iter().map(|p| super::run_plot::read_other(p)).collect::<Result<Vec<_>, _>>()?;
        let cx = report::run_plot::PlotContext {
            plant: cx.plant,
            spec: cx.spec,
            title: cx.title,
            time_unit,
            time_factor,
            others: &others,
        };
        report::run_plot::plot(p, res, &cx).map_err(|e| CliError::user(e.to_string()))?;
    }
    Ok(())
}

/// The run's summary on stdout: JSON or text.
fn print_summary(
    res: &SimulationResult,
    json: bool,
    wall: f64,
    time_factor: f64,
    time_unit: &str,
) -> Result<(), CliError> {
    if json {
        outln!("{}", report::run::json(res, wall).map_err(|e| CliError::user(e.to_string()))?);
        return Ok(());
    }
    out!("{}", report::run::text(res, wall, time_factor, time_unit).map_err(|e| CliError::user(e.to_string()))?);
    Ok(())
}
