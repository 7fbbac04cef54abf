//! `plantwide optimize FILE [--json] [--report DIR] [--objective PATH[@unit]] [--maximize]
//! [--vary PATH[=LOW:HIGH]]… [--constraint PATH=LOW:HIGH]… [--set PATH=VALUE]…`: the economic
//! optimum of the file's `"optimization"` section, the flags replacing or adding to it
//! ([`plantwide::studies::optimize`]).

use std::path::PathBuf;

use plantwide::flowsheet::optimization::{Limits, OptimizationSpec, Sense};
use plantwide::io::report::optimize as report;
use plantwide::studies::optimize::{OptimizeError, State, optimize, parse_limits};

use super::CliError;
use super::steady::{converge, load_with_overrides};

/// The problem's flags, shared by `optimize` and `select FILE`: they replace or add to the
/// file's `"optimization"` section.
#[derive(Debug, clap::Args)]
pub struct ProblemArgs {
    /// The objective, replacing the file's: a tag's name or a variable path, `PATH[@unit]`.
    #[arg(long, value_name = "PATH[@unit]")]
    objective: Option<String>,
    /// Maximize the objective (a profit) instead of minimizing it.
    #[arg(long)]
    maximize: bool,
    /// A degree of freedom with optional bounds (`feed.F`, `column.reflux=2 kmol/min:4 kmol/min`,
    /// `x2_control.sp=35 %:`); repeatable. Given, they replace the file's `vary`.
    #[arg(long, value_name = "PATH[=LOW:HIGH]")]
    vary: Vec<String>,
    /// A limit on a variable, `PATH=LOW:HIGH` with either end empty (`distillate.x[light]=0.99:`);
    /// repeatable, added to (or replacing the same path of) the file's `constraints`.
    #[arg(long, value_name = "PATH=LOW:HIGH")]
    constraint: Vec<String>,
}

/// Arguments of `plantwide optimize`.
#[derive(Debug, clap::Args)]
pub struct OptimizeArgs {
    /// Flowsheet file (JSON), with an `"optimization"` section or the problem's flags.
    file: PathBuf,
    #[command(flatten)]
    problem: ProblemArgs,
    /// Print exactly `{"objective", "values", "active", "multipliers", "kkt_residual"}` and more:
    /// `objective_path`, `objective_unit`, `sense`, `limits`, `reduced_hessian`, `iterations`,
    /// `plant_solves`.
    #[arg(long)]
    json: bool,
    /// Write `optimum.json`, `optimum.txt` and `optimum.md` into this folder.
    #[arg(long, value_name = "DIR")]
    report: Option<PathBuf>,
    /// Re-optimize along a disturbance, `PATH=LOW:HIGH:N` (N values, ends included), and list
    /// the active-constraint regions; with `--report`, `sweep.png` draws the optimum along it.
    #[arg(long, value_name = "PATH=LOW:HIGH:N")]
    sweep: Option<String>,
    /// Override an input or a unit parameter first, e.g. `--set feed_source.F=1.01kmol/min`.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
}

impl ProblemArgs {
    /// No flag given.
    pub(super) fn is_empty(&self) -> bool {
        self.objective.is_none() && !self.maximize && self.vary.is_empty() && self.constraint.is_empty()
    }
}

/// The problem of `file`'s `"optimization"` section (`section`) with the flags applied.
pub(super) fn request(
    a: &ProblemArgs,
    file: &std::path::Path,
    section: Option<&OptimizationSpec>,
) -> Result<OptimizationSpec, CliError> {
    let mut spec = section.cloned().unwrap_or_default();
    if let Some(o) = &a.objective {
        spec.objective = o.clone();
    }
    if a.maximize {
        spec.sense = Sense::Maximize;
    }
    let user = |flag: &str, e: String| CliError::user(format!("--{flag} {e}"));
    if !a.vary.is_empty() {
        spec.vary.clear();
        for v in &a.vary {
            let (path, limits) = match v.split_once('=') {
                Some((p, l)) => (p.trim(), parse_limits(l).map_err(|e| user("vary", e.to_string()))?),
                None => (v.trim(), Limits::default()),
            };
            spec.vary.insert(path.to_string(), limits);
        }
    }
    for c in &a.constraint {
        let (path, l) =
            c.split_once('=').ok_or_else(|| user("constraint", format!("`{c}`: expected PATH=LOW:HIGH")))?;
        spec.constraints
            .insert(path.trim().to_string(), parse_limits(l).map_err(|e| user("constraint", e.to_string()))?);
    }
    if spec.objective.is_empty() {
        return Err(CliError::user(format!(
            "{}: no objective: give the file an `optimization` section or --objective (a tag such as `cost`, or a variable path)",
            file.display()
        )));
    }
    Ok(spec)
}

pub fn run(a: &OptimizeArgs) -> Result<(), CliError> {
    let (plant, u) = load_with_overrides(&a.file, &a.set)?;
    let spec = request(&a.problem, &a.file, plant.spec().optimization.as_ref())?;
    let sol = converge(&plant, &u)?;
    let start = State { x: sol.x.clone(), u: sol.u.clone() };
    if let Some(text) = &a.sweep {
        return run_sweep(a, &plant, &spec, &start, text);
    }
    let optimum = optimize(&plant, &spec, &start).map_err(|e| optimize_error(&a.file, e))?;
    if let Some(dir) = &a.report {
        let written = report::write_report(dir, &optimum).map_err(|e| CliError::user(e.to_string()))?;
        eprintln!("wrote {} in {}", written.join(", "), dir.display());
    }
    if a.json {
        let text = plantwide::io::report::json(&optimum).map_err(|e| CliError::numerical(e.to_string()))?;
        outln!("{text}");
    } else {
        out!("{}", report::text(&optimum));
    }
    Ok(())
}

/// Exit 1 for the request, 2 for the plant or the numbers; the file named.
fn optimize_error(file: &std::path::Path, e: OptimizeError) -> CliError {
    let text = e.to_string();
    let name = file.display().to_string();
    // Messages that name a path of the plant already carry the file.
    let message = if text.contains(&name) { text } else { format!("{name}: {text}") };
    if e.is_user_error() { CliError::user(message) } else { CliError::numerical(message) }
}

/// `--sweep`: the optimum along a disturbance; exit 2 when a value has no optimum.
fn run_sweep(
    a: &OptimizeArgs,
    plant: &plantwide::flowsheet::Plant,
    spec: &OptimizationSpec,
    start: &State,
    text: &str,
) -> Result<(), CliError> {
    let sw =
        plantwide::studies::optimize::sweep::sweep(plant, spec, start, text).map_err(|e| optimize_error(&a.file, e))?;
    if let Some(dir) = &a.report {
        let written = report::write_sweep(dir, &sw).map_err(|e| CliError::user(e.to_string()))?;
        eprintln!("wrote {} in {}", written.join(", "), dir.display());
    }
    if a.json {
        outln!("{}", plantwide::io::report::json(&sw).map_err(|e| CliError::numerical(e.to_string()))?);
    } else {
        out!("{}", report::sweep_text(&sw));
    }
    match plantwide::studies::request::failed_parts("optimize --sweep", &sw.failed()) {
        Some(m) => Err(CliError::numerical(m)),
        None => Ok(()),
    }
}
