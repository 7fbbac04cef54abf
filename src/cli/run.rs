//! `plantwide run FILE --scenario SCEN --csv OUT.csv [--plot OUT.png|OUT.svg] [--json]
//! [--set PATH=VALUE ...] [--resume SNAPSHOT] [--units si|metric|field]`: dynamic simulation from
//! the converged steady state (or a snapshot), with a progress bar on stderr, recorded trends as
//! CSV, a summary (table, or JSON with `--json`) and an optional trend plot. Each recorded path is
//! shown (CSV, plot, table) in the unit its scenario asked for, else in the `--units` system's;
//! JSON stays in SI.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use plantwide::flowsheet::Plant;
use plantwide::flowsheet::scenario::{Limits, parse_scenario, resolve_with};
use plantwide::flowsheet::scenario::{RecordPathSpec, ScenarioSpec};
use plantwide::io::plot::write_overlays;
use plantwide::solve::dynamic::{
    CONSERVATION_TOL, Conservation, Progress, SimError, SimulationResult, Snapshot, Start, simulate,
};
use plantwide::units::{Display, UnitSystem, convert_from_si, unit_dimension};

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
            display_units(&mut result, args.units, &spec);
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
            display_units(&mut partial, args.units, &spec);
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
    display_units(&mut res, args.units, &spec);
    write_trends_files(args, &res, &plot_cx, &sc.time_unit, time_factor)?;
    let wall = started.elapsed().as_secs_f64();
    print_summary(&res, args.json, wall, time_factor, &sc.time_unit)
}

/// Every column whose scenario entry names no unit shown in `units`' unit of its dimension; a unit
/// the scenario names (SI ones too) is kept.
fn display_units(res: &mut SimulationResult, units: UnitSystem, spec: &ScenarioSpec) {
    let asked = |k: usize| matches!(spec.record.paths.get(k), Some(RecordPathSpec::WithUnit { unit: Some(_), .. }));
    for (_, c) in res.columns.iter_mut().enumerate().filter(|(k, _)| !asked(*k)) {
        if let Ok(dim) = unit_dimension(&c.si_unit) {
            c.unit = units.unit_for(dim);
        }
    }
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
    write_csv(&args.csv, res, time_unit, time_factor)?;
    if let Some(p) = &args.plot {
        let times: Vec<f64> = res.times.iter().map(|t| t * time_factor).collect();
        let panels = super::run_plot::panels(res, cx.plant, cx.spec, &args.compare)?;
        let events = super::run_plot::events(res, cx.spec, time_factor);
        write_overlays(p, cx.title, &format!("time [{time_unit}]"), &times, &panels, &events)
            .map_err(|e| CliError::user(e.to_string()))?;
    }
    Ok(())
}

fn to_unit(v: f64, unit: &str) -> f64 {
    convert_from_si(v, unit).unwrap_or(v)
}

fn write_csv(path: &Path, res: &SimulationResult, time_unit: &str, time_factor: f64) -> Result<(), CliError> {
    let fail = |e: std::io::Error| CliError::user(format!("{}: cannot write the CSV file: {e}", path.display()));
    let file = std::fs::File::create(path).map_err(fail)?;
    let mut w = std::io::BufWriter::new(file);
    let mut header = vec![format!("time [{time_unit}]")];
    header.extend(res.columns.iter().map(|c| format!("{} [{}]", c.path, c.unit)));
    writeln!(w, "{}", header.iter().map(|h| csv_field(h)).collect::<Vec<_>>().join(",")).map_err(fail)?;
    for (t, row) in res.times.iter().zip(&res.rows) {
        let mut fields = vec![format!("{}", t * time_factor)];
        fields.extend(row.iter().zip(&res.columns).map(|(v, c)| format!("{}", to_unit(*v, &c.unit))));
        writeln!(w, "{}", fields.join(",")).map_err(fail)?;
    }
    w.flush().map_err(fail)
}

/// Quote a CSV field that holds a comma or a quote.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_string() }
}

fn print_summary(
    res: &SimulationResult,
    json: bool,
    wall: f64,
    time_factor: f64,
    time_unit: &str,
) -> Result<(), CliError> {
    let summary = plantwide::analysis::figures::summary(res);
    let s = &res.stats;
    if json {
        let finals: serde_json::Map<String, serde_json::Value> =
            summary.iter().map(|p| (p.path.clone(), p.last.into())).collect();
        let out = serde_json::json!({
            "t_end": res.t,
            "wall_time_s": wall,
            "stats": s,
            "events": res.events.iter().map(|(t, o)| serde_json::json!({"t": t, "event": o})).collect::<Vec<_>>(),
            "final_values": finals,
            "paths": summary,
            "conservation": {
                "basis": res.conservation.basis,
                "tolerance": CONSERVATION_TOL,
                "max_relative_error": res.conservation.worst(),
                "balances": res.conservation.balances,
            },
            "mpc": res.mpc,
            "tripped": res.tripped,
        });
        outln!("{}", serde_json::to_string_pretty(&out).map_err(|e| CliError::user(e.to_string()))?);
        return Ok(());
    }
    outln!(
        "simulated {:.4} {time_unit} in {wall:.2} s: {} steps ({} error-test failures, {} Newton failures), {} residual and {} Jacobian evaluations, {} LU factorizations, {} restarts",
        res.t * time_factor,
        s.n_steps,
        s.n_error_test_failures,
        s.n_newton_failures,
        s.n_residual_evals,
        s.n_jacobian_evals,
        s.n_lu,
        s.n_restarts
    );
    for (t, origin) in res.events.iter().filter(|(_, o)| o.starts_with("when[")) {
        outln!("{origin} at t = {:.4} {time_unit}", t * time_factor);
    }
    if let Some(why) = &res.tripped {
        outln!("stopped by the scenario: {why}; the run ends there");
    }
    outln!(
        "{:<28} {:<10} {:>10} {:>14} {:>14} {:>14} {:>14} {:>14} {:>12}",
        "path",
        "unit",
        "reference",
        "initial",
        "final",
        format!("IAE [u·{time_unit}]"),
        format!("ISE [u²·{time_unit}]"),
        "max deviation",
        "settling"
    );
    for (p, c) in summary.iter().zip(&res.columns) {
        let d =
            Display::new(&c.unit).or_else(|_| Display::new(&c.si_unit)).map_err(|e| CliError::user(e.to_string()))?;
        let settling = p.settling_time.map_or("-".to_string(), |t| format!("{:.4} {time_unit}", t * time_factor));
        outln!(
            "{:<28} {:<10} {:>10} {:>14.7e} {:>14.7e} {:>14.4e} {:>14.4e} {:>14.4e} {:>12}",
            p.path,
            d.unit(),
            p.reference,
            d.value(p.initial),
            d.value(p.last),
            d.difference(p.iae) * time_factor,
            d.difference(d.difference(p.ise)) * time_factor,
            d.difference(p.max_deviation),
            settling
        );
    }
    print_conservation(&res.conservation);
    for m in &res.mpc {
        let statuses: Vec<String> = m.statuses.iter().map(|(k, v)| format!("{k} {v}")).collect();
        outln!(
            "mpc {}: {} samples (QP {}), solve time mean {:.3} ms, max {:.3} ms, {:.1} iterations, an input at a limit in {} samples, largest soft-limit slack {:.3e}; model: {}",
            m.controller,
            m.samples,
            statuses.join(", "),
            1e3 * m.mean_solve_time,
            1e3 * m.max_solve_time,
            m.mean_iterations,
            m.samples_at_limit,
            m.max_slack,
            m.model
        );
    }
    Ok(())
}

/// One line per balance: `Δ held` against `∫(in − out)`, and the relative error.
fn print_conservation(c: &Conservation) {
    let worst = c.worst();
    let verdict = if c.check(CONSERVATION_TOL).is_ok() { "ok" } else { "FAILED" };
    outln!(
        "conservation ({}): largest relative error {worst:.2e} (tolerance {CONSERVATION_TOL:.0e}): {verdict}",
        c.basis
    );
    for b in &c.balances {
        outln!(
            "  {:<20} Δheld {:>14.6e} {u}, fed {:>14.6e} {u}, removed {:>14.6e} {u}: relative error {:.2e}",
            b.name,
            b.held[1] - b.held[0],
            b.fed,
            b.removed,
            b.relative_error,
            u = b.unit
        );
    }
}
