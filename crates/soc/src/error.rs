//! Why a self-optimizing-control study could not be done: a local model whose data are wrong (the
//! field and what would fix it; exit 1 at the command line), a search request outside what the
//! model allows, or a search that ran out of its node budget before proving its ranking (exit 2).

/// Any failure of the crate.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SocError {
    /// The matrices file is not the JSON the format asks for.
    #[error("{file}: {path}: {message}")]
    Json {
        /// The file.
        file: String,
        /// Where in the file (`Gy[3]`, `.`).
        path: String,
        /// What the reader found.
        message: String,
    },
    /// A matrix or list of the model is wrong; `problem` says how and what would fix it.
    #[error("`{field}`: {problem}")]
    Field {
        /// The model's field (`Gy`, `Wn`, `measurements`).
        field: &'static str,
        /// What is wrong and what would fix it.
        problem: String,
    },
    /// The search asks for something the model cannot give.
    #[error("{0}")]
    Request(String),
    /// The branch and bound used its node budget before it proved the ranking.
    #[error(
        "branch and bound stopped after {nodes} nodes without proving the {best} best subsets of size {size} (the best found so far: {so_far}); raise `max_nodes`, or ask for fewer subsets (`best`)"
    )]
    NodeBudget {
        /// Nodes evaluated.
        nodes: u64,
        /// Subsets asked for.
        best: usize,
        /// Subset size.
        size: usize,
        /// The best subset found before the budget ran out, with its loss.
        so_far: String,
    },
    /// A factorization the method needs failed (a matrix singular to working precision).
    #[error("{0}")]
    Numerical(String),
}

impl SocError {
    /// True for problems of the data or the request (exit code 1), false for a search or a
    /// factorization that failed (exit code 2).
    pub fn is_user_error(&self) -> bool {
        matches!(self, SocError::Json { .. } | SocError::Field { .. } | SocError::Request(_))
    }
}

/// Shorthand for a [`SocError::Field`].
pub(crate) fn field(field: &'static str, problem: impl Into<String>) -> SocError {
    SocError::Field { field, problem: problem.into() }
}
