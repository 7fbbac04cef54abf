//! `plantwide screen FILE --column COL --outputs TOP,BOTTOM [--disturbances …] [--steady-only]
//! [--write-dir DIR] [--json] [--report DIR]`: the inventory configurations of a column, built
//! through the library, judged by their scaled steady-state gains and ranked by a dynamic check
//! (each tuned by BLT and stepped by the disturbances), or by the steady state alone;
//! `plantwide screen FILE --cvs … --mvs … [--disturbances …] [--throughput …]`: the pairings of CVs
//! to MVs, filtered at steady state and the best tested dynamically; `--shard I/N` runs a share of
//! the dynamic tests (task `t`: the `t`-th candidate tested), `plantwide merge` scores them all.

use std::path::{Path, PathBuf};

use plantwide::io::IoError;
use plantwide::io::report::screen as report;
use plantwide::studies::screen::pairings::{CandidateTask, DynamicResult};
use plantwide::studies::screen::{ScreenError, ScreenRequest, Screened, study};
use plantwide::units::{QuantityValue, UnitSystem};

use super::CliError;
use super::shard::ShardArgs;
use super::steady::load_with_overrides;

/// Arguments of `plantwide screen`.
#[derive(Debug, clap::Args)]
pub struct ScreenArgs {
    /// Flowsheet file (JSON).
    #[arg(value_name = "FILE")]
    file: PathBuf,
    /// The column whose inventory configurations to screen (LV, DV, LB, DB, (L/D)V, L(V/B), (L/D)(V/B)).
    #[arg(long, value_name = "COL", required_unless_present = "cvs", conflicts_with = "cvs")]
    column: Option<String>,
    /// The two qualities, top then bottom (variable paths), e.g. distillate.x[light],bottoms.x[light].
    #[arg(long, value_name = "TOP,BOTTOM", value_delimiter = ',', requires = "column")]
    outputs: Vec<String>,
    /// Rank a column's configurations by their steady-state measures alone (fast): no dynamic check.
    #[arg(long, requires = "column", conflicts_with_all = ["write_dir", "disturbances", "duration"])]
    steady_only: bool,
    /// Write each configuration's flowsheet, its quality loops as tuned by the dynamic check
    /// (`<config>.json`: LV, DV, LB, LD-V, L-VB, LD-VB), and each run's scenario
    /// (`step<N>.scenario.json`) here, for `plantwide run`.
    #[arg(long, value_name = "DIR", requires = "column")]
    write_dir: Option<PathBuf>,
    /// The largest deviation allowed of each quality, top then bottom (in its unit, SI when bare):
    /// the scale of the gains and IAEs (default: a mole fraction's distance to 0 or 1).
    #[arg(long, value_name = "TOP,BOTTOM", value_delimiter = ',', requires = "column")]
    allowed_deviation: Vec<String>,
    /// Controlled variables to pair (variable paths), comma separated.
    #[arg(long, value_name = "CV1,CV2,…", value_delimiter = ',', requires = "mvs")]
    cvs: Vec<String>,
    /// Manipulated variables (input paths), comma separated.
    #[arg(long, value_name = "MV1,MV2,…", value_delimiter = ',')]
    mvs: Vec<String>,
    /// Throughput-manipulator candidates (each one of the MVs, held while the others are paired).
    #[arg(long, value_name = "MV,…", value_delimiter = ',')]
    throughput: Vec<String>,
    /// Disturbances of the dynamic and sensitivity tests: input paths, each stepped by +10 %, or
    /// PATH=+x%, -x%, ±x% (one run each way) or an amount with its unit (PATH=+5 K,
    /// PATH=-10 kmol/h); the sweeps go to both sides by the step's size. With --column the
    /// default is the rate ±10 % and composition ± a tenth of its room of each feed upstream.
    #[arg(long, value_name = "PATH[=±x%|±AMOUNT],…", value_delimiter = ',')]
    disturbances: Vec<String>,
    /// Uncontrolled variables that must stay in a band over ± each disturbance with the CVs held
    /// (sensitivity test), e.g. "column1.x[1][B]=0:0.02" or "reactor.T=340 K:360 K".
    #[arg(long, value_name = "PATH=LOW:HIGH")]
    watch: Vec<String>,
    /// How many steady-state survivors to test dynamically.
    #[arg(long, default_value_t = 4)]
    candidates: usize,
    /// Measurement dead time of every loop in the dynamic test's tuning.
    #[arg(long, value_name = "TIME", default_value = "1 min")]
    measurement_dead_time: String,
    /// Length of each dynamic run (default: 20 × the longest reset time of the tuned loops).
    #[arg(long, value_name = "TIME")]
    duration: Option<String>,
    /// A model predictive controller to judge beside the PI candidates on the same runs: a JSON
    /// file with one `"type": "mpc"` controller description (as in a flowsheet's `controllers`)
    /// on the --cvs and some of the --mvs; a CV's `sp` defaults to its steady value.
    #[arg(long, value_name = "FILE", requires = "cvs")]
    mpc: Option<PathBuf>,
    /// Override an input or unit field before converging (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Write a report here: screen.md and screen.json.
    #[arg(long, value_name = "DIR")]
    report: Option<PathBuf>,
    /// Sharding of the pairings' dynamic tests over processes.
    #[command(flatten)]
    pub shard: ShardArgs,
}

/// A library refusal or failure with the request's fields named as this command's flags.
fn screen_error(e: ScreenError) -> CliError {
    let message = super::with_flags(e.to_string(), e.field(), ScreenRequest::FIELDS);
    let message = message.replace("--keep-flowsheets", "--write-dir");
    if e.is_user_error() { CliError::user(message) } else { CliError::numerical(message) }
}

/// A file the command could not write, named by its flag.
fn io_error(flag: &str, e: IoError) -> CliError {
    CliError::user(format!("{flag} {}", super::with_flags(e.to_string(), e.field(), &[])))
}

/// The flags as the library's request (quantities as written; the library reads their units).
fn request(a: &ScreenArgs) -> Result<ScreenRequest, CliError> {
    Ok(ScreenRequest {
        column: a.column.clone(),
        outputs: a.outputs.clone(),
        steady_only: a.steady_only,
        keep_flowsheets: a.write_dir.is_some(),
        allowed_deviation: a.allowed_deviation.iter().map(|d| QuantityValue::from(d.trim())).collect(),
        cvs: a.cvs.clone(),
        mvs: a.mvs.clone(),
        throughput: a.throughput.clone(),
        disturbances: a.disturbances.clone(),
        watch: a.watch.clone(),
        candidates: a.candidates,
        measurement_dead_time: QuantityValue::from(a.measurement_dead_time.as_str()),
        duration: a.duration.as_deref().map(QuantityValue::from),
        mpc: a.mpc.as_deref().map(mpc_description).transpose()?,
    })
}

/// Run `plantwide screen`.
pub fn run(a: &ScreenArgs, system: UnitSystem) -> Result<(), CliError> {
    let (plant, _) = load_with_overrides(&a.file, &a.set)?;
    if a.column.is_some() && a.shard.is_shard() {
        return Err(CliError::user(
            "--shard splits the pairings' dynamic tests (--cvs … --mvs … --disturbances …); a column's seven \
             configurations run in one process, in parallel: drop --shard",
        ));
    }
    let request = request(a)?;
    let share =
        if a.column.is_some() { Default::default() } else { a.shard.share_as::<CandidateTask, DynamicResult>()? };
    let file = a.file.display().to_string();
    match study(&plant, &request, share).map_err(screen_error)? {
        Screened::Column(screen) => {
            if let Some(dir) = &a.report {
                report::write_column_report(dir, &file, &screen).map_err(|e| io_error("--report", e))?;
            }
            let written = a.write_dir.as_deref().map(|dir| report::write_flowsheets(dir, &screen)).transpose();
            let written = written.map_err(|e| io_error("--write-dir", e))?;
            if a.json {
                outln!("{}", plantwide::io::report::json(&screen).map_err(|e| io_error("--json", e))?);
            } else {
                outln!("{}", report::column_text(&screen, &file));
                if let (Some(dir), Some(n)) = (&a.write_dir, written) {
                    outln!("wrote {n} tuned flowsheets and {} scenarios to {}", screen.scenarios.len(), dir.display());
                }
            }
            failed_parts("screen", &screen.failed)
        }
        Screened::Pairings(screen) => {
            if a.shard.is_shard() {
                let done =
                    screen.tested.iter().enumerate().filter_map(|(t, &k)| {
                        screen.structures[k].dynamic.as_ref().map(|d| (t, CandidateTask::from(d)))
                    });
                return a.shard.write_part("screen", &a.file, screen.tested.len(), done);
            }
            a.shard.check_merged(screen.tested.len())?;
            let shown = report::shown(&plant, &request, system)
                .map_err(|e| CliError::user(super::with_flags(e.to_string(), e.field(), &[])))?;
            if let Some(dir) = &a.report {
                report::write_pairing_report(dir, &screen, &shown).map_err(|e| io_error("--report", e))?;
            }
            if a.json {
                outln!("{}", plantwide::io::report::json(&screen).map_err(|e| io_error("--json", e))?);
            } else {
                outln!("{}", report::pairing_text(&screen, &shown));
            }
            failed_parts("screen", &screen.failed)
        }
    }
}

/// Exit 2 when parts of a study failed (the report, already printed, marks them): the message
/// counts them and gives each one's reason.
pub(super) fn failed_parts(study: &str, failed: &[String]) -> Result<(), CliError> {
    plantwide::studies::request::failed_parts(study, failed).map_or(Ok(()), |m| Err(CliError::numerical(m)))
}

/// The `--mpc` file's controller description.
fn mpc_description(file: &Path) -> Result<plantwide::studies::screen::pairings::mpc::ScreenMpc, CliError> {
    let text = plantwide::flowsheet::read_text(file).map_err(|e| CliError::user(e.to_string()))?;
    serde_json::from_str(&text).map_err(|e| CliError::user(format!("--mpc {}: {e}", file.display())))
}
