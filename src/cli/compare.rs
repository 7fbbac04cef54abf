//! `plantwide compare A.json B.json … --disturbances … --outputs … [--report DIR]`: schemes side by
//! side (energy, control structure, stability, recycles, sensitivity, closed-loop responses) as
//! markdown on stdout (or JSON), and with `--report DIR` as compare.md, compare.json and plots.

use std::path::PathBuf;

use plantwide::io::report::compare as report;
use plantwide::studies::compare::{CompareError, CompareRequest, LoopTuning, Prices, study};
use plantwide::units::{QuantityValue, UnitSystem};

use super::CliError;
use super::steady::load_with_overrides;

/// Arguments of `plantwide compare`.
#[derive(Debug, clap::Args)]
pub struct CompareArgs {
    /// Flowsheet files (JSON) of the schemes, two or more.
    #[arg(value_name = "FILE", num_args = 2.., required = true)]
    files: Vec<PathBuf>,
    /// Disturbances, comma-separated: `PATH` (+10 % of its steady value), `PATH=+x%`, `-x%`,
    /// `±x%` (one closed-loop run each way) or an amount with its unit (`PATH=+5 K`,
    /// `PATH=-10 kmol/h`); the sensitivity sweeps go to both sides by the step's size.
    #[arg(long, value_name = "PATH[=±x%|±AMOUNT],…", value_delimiter = ',', required = true)]
    disturbances: Vec<String>,
    /// Outputs watched in every scheme, comma-separated: variable paths, or inputs a controller
    /// drives (its output), each with an optional display unit (`column.reboiler_duty@MW`).
    #[arg(long, value_name = "P1,P2,…", value_delimiter = ',', required = true)]
    outputs: Vec<String>,
    /// Quality loops by controller name (default: every PI loop whose measurement is not a level,
    /// holdup or pressure).
    #[arg(long, value_name = "C1,C2,…", value_delimiter = ',')]
    loops: Vec<String>,
    /// Measurement dead time the BLT tuning of the quality loops allows for.
    #[arg(long, value_name = "TIME", default_value = "1 min")]
    measurement_dead_time: String,
    /// Tuning of the quality loops in the closed-loop runs: `blt` (BLT where the open loop is
    /// stable, the file's settings where it is not) or `file` (every file's own settings: like
    /// for like when the files share them).
    #[arg(long, value_enum, default_value = "blt")]
    tuning: TuningArg,
    /// Length of each closed-loop run (default: 20 reset times of the slowest tuned loop).
    #[arg(long, value_name = "TIME")]
    duration: Option<String>,
    /// Price of the heating utility in $/GJ (default: low-pressure steam, 7.78 $/GJ, Luyben 2013).
    #[arg(long, value_name = "USD_PER_GJ", allow_negative_numbers = true, default_value_t = Prices::default().heating)]
    heating_price: f64,
    /// Price of the cooling utility in $/GJ (default: cooling water, 0.354 $/GJ, Turton et al. 2012).
    #[arg(long, value_name = "USD_PER_GJ", allow_negative_numbers = true, default_value_t = Prices::default().cooling)]
    cooling_price: f64,
    /// Operating hours a year for the yearly utility cost.
    #[arg(long, value_name = "H", allow_negative_numbers = true, default_value_t = Prices::default().hours)]
    hours: f64,
    /// Print the comparison as JSON.
    #[arg(long)]
    json: bool,
    /// Write a report here: compare.md, compare.json, energy.png and responses_<k>.png.
    #[arg(long, value_name = "DIR")]
    report: Option<PathBuf>,
}

/// How `compare` tunes the quality loops.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TuningArg {
    /// BLT where it applies.
    Blt,
    /// The files' own settings.
    File,
}

/// Run `plantwide compare`.
pub fn run(a: &CompareArgs, system: UnitSystem) -> Result<(), CliError> {
    let plants = a.files.iter().map(|f| load_with_overrides(f, &[]).map(|(p, _)| p)).collect::<Result<Vec<_>, _>>()?;
    let request = CompareRequest {
        disturbances: a.disturbances.clone(),
        outputs: a.outputs.clone(),
        loops: a.loops.clone(),
        measurement_dead_time: QuantityValue::from(a.measurement_dead_time.as_str()),
        tuning: match a.tuning {
            TuningArg::Blt => LoopTuning::Blt,
            TuningArg::File => LoopTuning::File,
        },
        duration: a.duration.as_deref().map(QuantityValue::from),
        heating_price: a.heating_price,
        cooling_price: a.cooling_price,
        hours: a.hours,
    };
    let c = study(&plants, &request).map_err(compare_error)?;
    let io = |e: plantwide::io::IoError| CliError::user(super::with_flags(e.to_string(), e.field(), &[]));
    let shown = report::shown(&plants, &a.outputs, &c, system).map_err(io)?;
    if let Some(dir) = &a.report {
        report::write_report(dir, &c, &shown)
            .map_err(|e| CliError::user(format!("--report {}: {e}", dir.display())))?;
    }
    if a.json {
        outln!("{}", plantwide::io::report::json(&c).map_err(io)?);
    } else {
        outln!("{}", report::text(&c, &shown));
    }
    super::screen::failed_parts("compare", &c.failed)
}

/// A library refusal or failure with the request's fields named as this command's flags.
fn compare_error(e: CompareError) -> CliError {
    let message = super::with_flags(e.to_string(), e.field(), CompareRequest::FIELDS);
    if e.is_user_error() { CliError::user(message) } else { CliError::numerical(message) }
}
