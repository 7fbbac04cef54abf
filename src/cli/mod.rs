//! Subcommands of the `plantwide` binary.

/// `print!` that ends the process quietly when stdout is closed (e.g. piped into `head`).
macro_rules! out {
    ($($t:tt)*) => { $crate::cli::write_out(format_args!($($t)*)) };
}

/// `println!` that ends the process quietly when stdout is closed.
macro_rules! outln {
    () => { $crate::cli::write_out(format_args!("\n")) };
    ($($t:tt)*) => {{ $crate::cli::write_out(format_args!($($t)*)); $crate::cli::write_out(format_args!("\n")) }};
}

/// A library message with the request's fields named as this face's flags: a message that starts
/// with its field (`level_band 5 kmol/h: …`), and each field it names in backticks (`` give a
/// longer `scan` ``), get `--level-band`, `--scan`. A backticked name followed by `:` is the
/// message's subject (a controller named `scan`), not a field, and is left as it is.
pub fn with_flags(message: String, leading: Option<&str>, fields: &[&str]) -> String {
    let flag = |f: &str| format!("--{}", f.replace('_', "-"));
    let mut message = match leading.and_then(|f| message.strip_prefix(f).map(|rest| (f, rest))) {
        Some((f, rest)) if rest.is_empty() || rest.starts_with([' ', ':']) => format!("{}{rest}", flag(f)),
        _ => message,
    };
    for f in fields {
        let (quoted, named) = (format!("`{f}`"), flag(f));
        let mut out = String::with_capacity(message.len());
        let mut rest = message.as_str();
        while let Some(k) = rest.find(&quoted) {
            let after = &rest[k + quoted.len()..];
            out.push_str(&rest[..k]);
            out.push_str(if after.starts_with(':') { &quoted } else { &named });
            rest = after;
        }
        out.push_str(rest);
        message = out;
    }
    message
}

/// The request fields that library messages outside the studies name in backticks (`` `step` ``,
/// `` `method` sm ``), each this command line's flag of the same name; the Python keywords are the
/// same names.
const LIBRARY_FIELDS: &[&str] =
    &["set", "spec", "pairing", "block", "disturb", "points", "shard", "step", "method", "time_unit"];

/// Fields that may lead a library message (`set feed.F: …`, `pairing `1,2`: …`).
const LEADING_FIELDS: &[&str] = &["set", "spec", "pairing", "block", "disturb", "points", "shard"];

/// `message` from the library with the request fields it names written as this command line's
/// flags ([`with_flags`] over [`LIBRARY_FIELDS`]).
pub fn library_flags(message: String) -> String {
    let leading =
        LEADING_FIELDS.iter().copied().find(|f| message.strip_prefix(f).is_some_and(|r| r.starts_with([' ', ':'])));
    with_flags(message, leading, LIBRARY_FIELDS)
}

/// Write to stdout; a closed pipe ends the process with success (the reader has what it wanted),
/// any other failure (a full disk) with exit 1 and the reason, not a silent loss of the output.
pub fn write_out(args: std::fmt::Arguments<'_>) {
    use std::io::Write;
    if let Err(e) = std::io::stdout().lock().write_fmt(args) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("error: cannot write the output: {e}");
        std::process::exit(1);
    }
}

mod check;
mod compare;
mod components;
mod gains;
mod identify;
mod linearize;
mod optimize;
mod run;
mod run_plot;
mod screen;
mod select;
mod sensitivity;
mod serve;
mod shard;
mod size;
mod steady;
mod tune;
mod tune_plant;

use std::path::PathBuf;

use clap::{Parser, Subcommand};

/// Display units of text, tables and plots (`--units`); JSON is always SI.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum UnitsArg {
    /// Coherent SI: mol/s, K, Pa, W.
    Si,
    /// kmol/h, degC, kPa, kW, kmol, m3.
    Metric,
    /// lbmol/h, degF, psia, Btu/h, lbmol, ft3.
    Field,
}

impl From<UnitsArg> for plantwide::units::UnitSystem {
    fn from(a: UnitsArg) -> Self {
        match a {
            UnitsArg::Si => plantwide::units::UnitSystem::Si,
            UnitsArg::Metric => plantwide::units::UnitSystem::Metric,
            UnitsArg::Field => plantwide::units::UnitSystem::Field,
        }
    }
}

/// Plantwide process-control studies: flowsheets, steady state, dynamics and control analysis.
#[derive(Debug, Parser)]
#[command(version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Display units for every quantity whose path names no unit (`si`: mol/s, K, Pa, W;
    /// `metric`: kmol/h, degC, kPa, kW; `field`: lbmol/h, degF, psia, Btu/h): `steady` and `run`
    /// text, tables, CSV and plots (their `--json` stays SI); `gains`, `linearize` and
    /// `sensitivity` signals (their JSON labels each with its unit). Default: SI (`steady`'s stream
    /// table: kmol/h, K, kPa, kJ/mol).
    #[arg(long, value_enum, global = true)]
    units: Option<UnitsArg>,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Validate a flowsheet and summarize it: components, units, streams, controllers, degrees of
    /// freedom, recycles.
    Check {
        /// Flowsheet file (JSON).
        file: PathBuf,
    },
    /// List the built-in component library.
    Components {
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Converge the plant to steady state and print streams and units.
    Steady {
        /// Flowsheet file (JSON).
        file: PathBuf,
        /// Print a JSON object with every variable under its path (SI units).
        #[arg(long)]
        json: bool,
        /// Override an input or a unit parameter for this run, e.g. `--set feed.F=1.01kmol/min`.
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<String>,
        /// Design specification: hold a variable at a value, e.g. `--spec distillate.x[light]=0.995`;
        /// the k-th `--spec` is met by moving the k-th `--vary` input; all are solved together.
        #[arg(long = "spec", value_name = "PATH=VALUE")]
        spec: Vec<String>,
        /// Free input moved to meet the paired `--spec`, e.g. `--vary column.reflux`.
        #[arg(long = "vary", value_name = "INPUT")]
        vary: Vec<String>,
        /// How to converge: `eo` whole-plant Newton, `sm` sequential modular (unit by unit,
        /// recycles by tearing), `auto` sequential modular to 1e-4 then Newton.
        #[arg(long, value_enum, default_value = "auto")]
        method: steady::MethodArg,
    },
    /// Simulate the plant through a scenario from its steady state (or a snapshot): CSV of the
    /// recorded paths, a summary (IAE, ISE, max deviation, settling time) and optional trend plots.
    Run {
        /// Flowsheet file (JSON).
        file: PathBuf,
        /// Scenario file (JSON): duration, events, sampling, analyzers, record, snapshots.
        #[arg(long)]
        scenario: PathBuf,
        /// Write the recorded trends here (CSV, units in the header).
        #[arg(long, value_parser = output_file)]
        csv: PathBuf,
        /// Write trend plots here (.png or .svg).
        #[arg(long, value_parser = output_file)]
        plot: Option<PathBuf>,
        /// Print the summary as JSON.
        #[arg(long)]
        json: bool,
        /// Override an input or a unit parameter, e.g. `--set lc.kc=20mol/s/m`.
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<String>,
        /// Resume from a snapshot file written by an earlier run.
        #[arg(long)]
        resume: Option<PathBuf>,
        /// Overlay an earlier run's CSV on the plot (dashed; the same paths and units); repeatable.
        #[arg(long, value_name = "OTHER.csv")]
        compare: Vec<PathBuf>,
    },
    /// Print the JSON Schema of flowsheet files (the shipped flowsheets/plantwide.schema.json), or
    /// with `--scenario` of scenario files (flowsheets/scenario.schema.json).
    Schema {
        /// The schema of scenario files instead of flowsheet files.
        #[arg(long)]
        scenario: bool,
    },
    /// Steady-state gains (linearization or perturbation) and interaction measures: RGA, SVD,
    /// condition numbers, Niederlinski index, block relative gain; also of a transfer-function model.
    Gains(gains::GainsArgs),
    /// State-space model A, B, C, D at the steady state, eigenvalues, time constants; JSON export.
    Linearize(linearize::LinearizeArgs),
    /// Disturbance sweeps with the control structure active: table, CSV and plot.
    Sensitivity(sensitivity::SensitivityArgs),
    /// Tray-temperature sensor selection for a column (SVD, sensitivity and slope criteria).
    Sensors(gains::SensorsArgs),
    /// PI tuning of the diagonal loops of a transfer-function model: ultimate gains and periods,
    /// Ziegler–Nichols, Tyreus–Luyben, or Luyben's BLT detuning for interaction.
    Tune(tune::TuneArgs),
    /// Control-structure screening: a column's inventory configurations (LV, DV, LB, DB, (L/D)V,
    /// L(V/B), (L/D)(V/B)) with their steady-state gains, RGA, Niederlinski index, condition numbers.
    Screen(screen::ScreenArgs),
    /// Self-optimizing control: the best subsets of candidate measurements to combine into
    /// controlled variables (exact local method: worst-case and average loss, the optimal
    /// combination H), found by bidirectional branch and bound, from published linear data.
    Select(select::SelectArgs),
    /// The economic optimum at steady state: an objective (a tag with prices, or a variable), the
    /// inputs and setpoints it may move, limits on any variable; SQP on converged steady states
    /// with exact derivatives, giving the active constraints, their shadow prices, the KKT
    /// residual and the reduced Hessian.
    Optimize(optimize::OptimizeArgs),
    /// Surge sizing: the cross-section and level controller (P, critically damped PI, optimal
    /// averaging) that hold a vessel's level band and its outflow's rate limit, each verified by a
    /// nonlinear run; or a ranking of where surge capacity needs the least volume.
    Size(size::SizeArgs),
    /// Schemes side by side: energy, the control structure's gains, RGA, NI and condition number,
    /// open-loop and as-built eigenvalues, recycle loop gains, disturbance sensitivity by
    /// continuation and closed-loop responses with the quality loops tuned by BLT.
    Compare(compare::CompareArgs),
    /// Identification by a plant test on the nonlinear model (PRBS, GBN or directional design,
    /// open or closed loop, measurement noise), FIR/ARX/OE fits validated on fresh data; the
    /// identified gains and RGA beside the exact linearization's.
    Identify(identify::IdentifyArgs),
    /// Put together the part files of a job sharded with `--shard I/N` (sensitivity, screen) and
    /// finish it as the one-process run would: the same text, JSON, CSV, plots and report.
    Merge(shard::MergeArgs),
    /// The browser simulator: a local server running the plant live (the `run` integrator) with a
    /// page of the flowsheet, trends, faceplates, clock controls, disturbances and snapshots, and
    /// the JSON API the page uses.
    Serve(serve::ServeArgs),
}

/// A failed command: message and exit code.
#[derive(Debug)]
pub struct CliError {
    /// One-paragraph message.
    pub message: String,
    /// 1 user error, 2 numerical failure.
    pub code: u8,
}

impl CliError {
    fn user(message: impl Into<String>) -> CliError {
        CliError { message: message.into(), code: 1 }
    }
    fn numerical(message: impl Into<String>) -> CliError {
        CliError { message: message.into(), code: 2 }
    }
}

/// Run a parsed command line.
pub fn run(cli: Cli) -> Result<(), CliError> {
    // A limit set in the environment but not a number is a user error, said before any work.
    // The environment is read here, once: the library takes the limits as they are installed.
    let limits = plantwide::model::limits::Limits::from_env().map_err(|e| CliError::user(e.to_string()))?;
    plantwide::model::limits::Limits::install(limits);
    match cli.command {
        Command::Check { file } => check::run(&file, cli.units.unwrap_or(UnitsArg::Si).into()),
        Command::Components { json } => components::run(json),
        Command::Steady { file, json, set, spec, vary, method } => {
            let units = cli.units.map(Into::into);
            steady::run(&steady::SteadyArgs { file: &file, json, sets: &set, specs: &spec, vary: &vary, method, units })
        }
        Command::Run { file, scenario, csv, plot, json, set, resume, compare } => {
            let units = cli.units.unwrap_or(UnitsArg::Si).into();
            run::run(&run::RunArgs { file, scenario, csv, plot, json, set, resume, units, compare })
        }
        Command::Gains(a) => gains::run(&a, cli.units.unwrap_or(UnitsArg::Si).into()),
        Command::Linearize(a) => linearize::run(&a, cli.units.unwrap_or(UnitsArg::Si).into()),
        Command::Sensitivity(a) => sensitivity::run(&a, cli.units.unwrap_or(UnitsArg::Si).into()),
        Command::Sensors(a) => gains::run_sensors(&a, cli.units.unwrap_or(UnitsArg::Si).into()),
        Command::Tune(a) => tune::run(&a),
        Command::Screen(a) => screen::run(&a, cli.units.unwrap_or(UnitsArg::Si).into()),
        Command::Select(a) => select::run(&a),
        Command::Optimize(a) => optimize::run(&a),
        Command::Size(a) => size::run(&a, cli.units.unwrap_or(UnitsArg::Si).into()),
        Command::Compare(a) => compare::run(&a, cli.units.unwrap_or(UnitsArg::Si).into()),
        Command::Identify(a) => identify::run(&a, cli.units.unwrap_or(UnitsArg::Si).into()),
        Command::Merge(a) => shard::run(&a),
        Command::Serve(a) => serve::run(&a),
        Command::Schema { scenario } => {
            let schema = match scenario {
                true => plantwide::flowsheet::schema::scenario_schema(),
                false => plantwide::flowsheet::schema::flowsheet_schema(),
            };
            let text = serde_json::to_string_pretty(&schema).map_err(|e| CliError::user(e.to_string()))?;
            outln!("{text}");
            Ok(())
        }
    }
}

/// Why a flag's value cannot name a file to write.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub(crate) enum OutputFileError {
    /// The value is empty.
    #[error("an empty path: give a file name")]
    Empty,
    /// It names a folder.
    #[error("`{0}` is a folder: give a file name in it")]
    Folder(String),
    /// Its folder does not exist.
    #[error("the folder `{0}` does not exist: create it, or write the file elsewhere")]
    NoFolder(String),
}

/// The value of a flag naming a file to write: its folder must exist and it must not be a folder,
/// checked when the command line is read (a run is not started only to fail at its end).
pub(crate) fn output_file(value: &str) -> Result<PathBuf, OutputFileError> {
    let path = PathBuf::from(value);
    if value.is_empty() {
        return Err(OutputFileError::Empty);
    }
    if path.is_dir() {
        return Err(OutputFileError::Folder(value.to_string()));
    }
    let folder = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
    if !folder.is_dir() {
        return Err(OutputFileError::NoFolder(folder.display().to_string()));
    }
    Ok(path)
}

#[cfg(test)]
mod flag_tests {
    use super::with_flags;

    #[test]
    fn fields_read_as_flags_but_a_subject_named_like_one_does_not() {
        let m = with_flags("scan 3 kg: not a time".into(), Some("scan"), &["scan"]);
        assert_eq!(m, "--scan 3 kg: not a time");
        let m = with_flags("`lc`: give a longer `scan`, or `method` relay".into(), None, &["scan", "method"]);
        assert_eq!(m, "`lc`: give a longer --scan, or --method relay");
        let m = with_flags("`scan`: its element has no lag; give `scan`".into(), None, &["scan"]);
        assert_eq!(m, "`scan`: its element has no lag; give --scan");
        assert_eq!(with_flags("scanner off".into(), Some("scan"), &[]), "scanner off");
    }
}
