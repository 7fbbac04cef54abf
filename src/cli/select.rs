//! `plantwide select --matrices FILE.json --size N [--best K] [--criterion worst|average]
//! [--max-nodes M] [--json]`: the best subsets of N candidate measurements to combine into
//! controlled variables (exact local method, bidirectional branch and bound) from published
//! linear data ([`plantwide::soc::matrices`]); and `plantwide select FILE --disturbances d=±Δ,…
//! --candidates y1,y2,… --errors y=±e,… --size N [--best K] [--criterion worst|average]
//! [--combinations] [--json]` (and `optimize`'s `--objective`, `--maximize`, `--vary`,
//! `--constraint`), the same on a plant at its economic optimum, each subset verified on the
//! nonlinear plant ([`plantwide::studies::optimize::select`]).

use std::path::PathBuf;

use plantwide::io::report::select as report;
use plantwide::soc::{Criterion, DEFAULT_MAX_NODES, Search, SocError, branch_and_bound, matrices};

use plantwide::studies::optimize::State;
use plantwide::studies::optimize::local::LocalRequest;
use plantwide::studies::optimize::select::select_on_plant;

use super::CliError;
use super::optimize::{ProblemArgs, request};
use super::steady::{converge, load_with_overrides};

/// The loss that ranks the subsets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CriterionArg {
    /// Worst-case loss ½σ̄(M)² over ‖[d'; n']‖₂ ≤ 1.
    Worst,
    /// Average loss ½‖M‖²_F over normally distributed [d'; n'].
    Average,
}

/// Arguments of `plantwide select`.
#[derive(Debug, clap::Args)]
pub struct SelectArgs {
    /// A flowsheet with an `"optimization"` section or the problem's flags: the local model is
    /// taken at its optimum.
    #[arg(required_unless_present = "matrices", conflicts_with = "matrices")]
    file: Option<PathBuf>,
    #[command(flatten)]
    problem: ProblemArgs,
    /// Linear data in place of a plant (JSON): `inputs`, `disturbances`, `measurements` (names),
    /// `Gy`, `Gyd`, `Juu`, `Jud` (lists of rows), `Wd`, `Wn` (a diagonal as a list, or a full matrix).
    #[arg(long, value_name = "FILE.json")]
    matrices: Option<PathBuf>,
    /// With FILE: the disturbances and their expected magnitudes, `PATH=±Δ` (comma-separated).
    #[arg(long, value_delimiter = ',', requires = "file", value_name = "PATH=±Δ")]
    disturbances: Vec<String>,
    /// With FILE: the candidate measurements, `PATH[@unit]` (variables, or degrees of freedom).
    #[arg(long, value_delimiter = ',', requires = "file", value_name = "PATH[@unit]")]
    candidates: Vec<String>,
    /// With FILE: each candidate's implementation error, `PATH=±e`.
    #[arg(long, value_delimiter = ',', requires = "file", value_name = "PATH=±e")]
    errors: Vec<String>,
    /// Print the combination H of every listed subset, not only the best's (JSON always has all).
    #[arg(long)]
    combinations: bool,
    /// With FILE: override an input or a unit parameter first.
    #[arg(long = "set", value_name = "PATH=VALUE", requires = "file")]
    set: Vec<String>,
    /// Measurements in each subset (from the number of inputs to the number of candidates).
    #[arg(long)]
    size: usize,
    /// How many of the best subsets to list.
    #[arg(long, default_value_t = 5)]
    best: usize,
    /// The loss that ranks the subsets.
    #[arg(long, value_enum, default_value = "worst")]
    criterion: CriterionArg,
    /// Nodes the branch and bound may evaluate before it gives up (exit 2).
    #[arg(long, default_value_t = DEFAULT_MAX_NODES)]
    max_nodes: u64,
    /// Print the ranking as JSON.
    #[arg(long)]
    json: bool,
}

pub fn run(a: &SelectArgs) -> Result<(), CliError> {
    let criterion = match a.criterion {
        CriterionArg::Worst => Criterion::Worst,
        CriterionArg::Average => Criterion::Average,
    };
    let search = Search { size: a.size, best: a.best, criterion, max_nodes: a.max_nodes };
    if let Some(file) = &a.file {
        return on_plant(a, file, &search);
    }
    let Some(matrices) = &a.matrices else { return Err(CliError::user("give a flowsheet FILE or --matrices")) };
    if !a.problem.is_empty() {
        return Err(CliError::user(
            "--objective, --maximize, --vary and --constraint pose the problem on a flowsheet FILE; --matrices already holds its local model",
        ));
    }
    let model = matrices::read(matrices).map_err(select_error)?;
    let ranking = branch_and_bound(&model, &search).map_err(select_error)?;
    if a.json {
        let text = report::json(&model, a.size, criterion, &ranking).map_err(|e| CliError::numerical(e.to_string()))?;
        outln!("{text}");
    } else {
        out!("{}", report::text(&model, a.size, criterion, a.best, &ranking));
        if a.combinations {
            out!("{}", report::all_h(&model, &ranking));
        }
    }
    Ok(())
}

/// `select FILE …`: optimize, form the local model, search, verify.
fn on_plant(a: &SelectArgs, file: &std::path::Path, search: &Search) -> Result<(), CliError> {
    let (plant, u) = load_with_overrides(file, &a.set)?;
    let spec = request(&a.problem, file, plant.spec().optimization.as_ref())?;
    let sol = converge(&plant, &u)?;
    let start = State { x: sol.x.clone(), u: sol.u.clone() };
    let request = LocalRequest {
        disturbances: a.disturbances.clone(),
        candidates: a.candidates.clone(),
        errors: a.errors.clone(),
    };
    let fields = ["disturbances", "candidates", "errors", "size", "best", "max_nodes"];
    let sel = select_on_plant(&plant, &spec, &start, &request, search)
        .map_err(|e| flagged(e.to_string(), e.is_user_error(), &fields))?;
    if a.json {
        let text =
            report::plant_json(&sel, a.size, search.criterion).map_err(|e| CliError::numerical(e.to_string()))?;
        outln!("{text}");
    } else {
        out!("{}", report::plant_text(&sel, a.size, search.criterion, a.best, a.combinations));
    }
    let failed = sel.failed();
    match plantwide::studies::request::failed_parts("select", &failed) {
        Some(m) => Err(CliError::numerical(m)),
        None => Ok(()),
    }
}

/// The library's message with the request's fields as this command line's flags; exit 1 for the
/// data or the request, 2 for a search that did not finish.
fn select_error(e: SocError) -> CliError {
    flagged(e.to_string(), e.is_user_error(), &["size", "best", "max_nodes"])
}

/// A library message (`text`) whose leading request field (`fields`) becomes this command
/// line's flag; exit 1 for a user's error, 2 otherwise.
fn flagged(text: String, user: bool, fields: &[&str]) -> CliError {
    let leading =
        fields.iter().copied().find(|f| text.starts_with(&format!("{f}:")) || text.starts_with(&format!("{f} ")));
    let message = super::with_flags(text, leading, fields);
    if user { CliError::user(message) } else { CliError::numerical(message) }
}
