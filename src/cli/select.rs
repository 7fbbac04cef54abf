//! `plantwide select --matrices FILE.json --size N [--best K] [--criterion worst|average]
//! [--max-nodes M] [--json]`: the best subsets of N candidate measurements to combine into
//! controlled variables (exact local method, bidirectional branch and bound) from published
//! linear data ([`plantwide::soc::matrices`]).

use std::path::PathBuf;

use plantwide::io::report::select as report;
use plantwide::soc::{Criterion, DEFAULT_MAX_NODES, Search, SocError, branch_and_bound, matrices};

use super::CliError;

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
    /// Linear data in place of a plant (JSON): `inputs`, `disturbances`, `measurements` (names),
    /// `Gy`, `Gyd`, `Juu`, `Jud` (lists of rows), `Wd`, `Wn` (a diagonal as a list, or a full matrix).
    #[arg(long, value_name = "FILE.json")]
    matrices: PathBuf,
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
    let model = matrices::read(&a.matrices).map_err(select_error)?;
    let criterion = match a.criterion {
        CriterionArg::Worst => Criterion::Worst,
        CriterionArg::Average => Criterion::Average,
    };
    let search = Search { size: a.size, best: a.best, criterion, max_nodes: a.max_nodes };
    let ranking = branch_and_bound(&model, &search).map_err(select_error)?;
    if a.json {
        let text = report::json(&model, a.size, criterion, &ranking).map_err(|e| CliError::numerical(e.to_string()))?;
        outln!("{text}");
    } else {
        out!("{}", report::text(&model, a.size, criterion, a.best, &ranking));
    }
    Ok(())
}

/// The library's message with the request's fields as this command line's flags; exit 1 for the
/// data or the request, 2 for a search that did not finish.
fn select_error(e: SocError) -> CliError {
    let fields = ["size", "best", "max_nodes"];
    let leading = fields.iter().copied().find(|f| e.to_string().starts_with(&format!("{f} ")));
    let message = super::with_flags(e.to_string(), leading, &fields);
    match e.is_user_error() {
        true => CliError::user(message),
        false => CliError::numerical(message),
    }
}
