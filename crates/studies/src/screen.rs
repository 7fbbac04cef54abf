//! Control-structure screening: a plant's candidate structures built as [`Plant`] variants through
//! the flowsheet library, each judged by the steady-state interaction measures of its loops.
//!
//! Today: [`mod@column`], the standard inventory configurations of one distillation column (LV, DV, LB,
//! DB, (L/D)V, L(V/B), (L/D)(V/B)), with the exact steady-state gains of its two qualities to the
//! two inputs each leaves free, RGA, Niederlinski index, condition numbers of the scaled gains, a
//! dynamic check of each (BLT-tuned loops stepped by the disturbances) that the ranking follows,
//! and a verdict; [`mod@pairings`], plantwide pairings of CVs to MVs.
//!
//! [`Plant`]: plantwide_flowsheet::Plant

pub mod column;
pub mod pairings;
mod request;

pub use column::{ColumnDynamic, ColumnRequest, ColumnScreen, ColumnStructure, screen_column, screen_column_with};
pub use pairings::{PairingRequest, PairingScreen, screen_pairings};
pub use request::{ScreenRequest, Screened, study};

/// Why a screening could not be done.
#[derive(Debug, Clone, thiserror::Error)]
pub enum ScreenError {
    /// A list of the request names one item twice.
    #[error(transparent)]
    Duplicate(#[from] crate::request::Duplicate),
    /// A field of the request that does not parse or does not fit.
    #[error("{field} {why}")]
    Field {
        /// The [`ScreenRequest`] field.
        field: &'static str,
        /// What is wrong, after the field's name.
        why: String,
    },
    /// The unit named is no column (it lacks the reflux, reboiler, distillate and bottoms inputs).
    #[error("no column `{name}` in the flowsheet{hint} (its columns: {columns})")]
    NotAColumn {
        /// The name asked for.
        name: String,
        /// A suggestion, or empty.
        hint: String,
        /// The flowsheet's columns.
        columns: String,
    },
    /// A column end's inventory has no level loop on one of the column's flows to move.
    #[error(
        "column `{column}`: no P or PI controller holds its {end} level (a PID with pv `{pv}` driving one of \
         {handles}); add the level loop the configurations rewire"
    )]
    NoLevelLoop {
        /// The column.
        column: String,
        /// `condenser` or `reboiler`.
        end: &'static str,
        /// The measurement looked for.
        pv: String,
        /// The column's flows.
        handles: String,
    },
    /// An output path names no variable.
    #[error("outputs: no variable `{path}`{hint}; give the two qualities as variable paths, e.g. distillate.x[light]")]
    NoOutput {
        /// The path.
        path: String,
        /// A suggestion, or empty.
        hint: String,
    },
    /// An allowed deviation that is not a positive amount.
    #[error("allowed_deviation {path}: {value} is no deviation; give a positive amount in the quality's unit")]
    Allowed {
        /// The quality.
        path: String,
        /// The value given (SI).
        value: f64,
    },
    /// No feed of free rate is upstream of the column, so the dynamic check has no default disturbances.
    #[error(
        "column `{column}`: no feed of free rate upstream ({why}), so the dynamic check has no default \
         disturbances; give them with `disturbances` PATH=±x%,… or screen with `steady_only`"
    )]
    NoFeed {
        /// The column.
        column: String,
        /// What its feeds are.
        why: String,
    },
    /// A configuration's tuned flowsheet could not be written back to a file's description.
    #[error("configuration {structure}: its tuned flowsheet cannot be written: {why}")]
    Write {
        /// The configuration.
        structure: String,
        /// Why.
        why: String,
    },
    /// Not two outputs.
    #[error("outputs: a column configuration controls two qualities (top, bottom); got {0}")]
    OutputCount(usize),
    /// A CV names no variable.
    #[error("cvs: no variable `{path}`{hint}")]
    NoCv {
        /// The path.
        path: String,
        /// A suggestion, or empty.
        hint: String,
    },
    /// A watched variable names no variable.
    #[error("watch: no variable `{path}`{hint}")]
    NoWatch {
        /// The path.
        path: String,
        /// A suggestion, or empty.
        hint: String,
    },
    /// Watched variables without disturbances to sweep.
    #[error("watch needs `disturbances` to sweep: the band is tested over ± each disturbance")]
    WatchWithoutDisturbances,
    /// An MV names no input.
    #[error("mvs: `{path}` is no input of the plant{hint}")]
    NoMv {
        /// The path.
        path: String,
        /// A suggestion, or empty.
        hint: String,
    },
    /// A throughput candidate that is not an MV.
    #[error(
        "throughput {path}: a throughput candidate must be one of the `mvs` (it is held while the others are paired)"
    )]
    ThroughputNotMv {
        /// The path.
        path: String,
    },
    /// A disturbance on an input that a candidate pairs: its controller drives it there, so the
    /// step cannot be applied.
    #[error(
        "disturbances {path}: it is also one of the `mvs`, and a candidate that pairs it drives it with a \
         controller, so it cannot be stepped there{held}: disturb an input no candidate pairs, or give it as \
         the only `throughput` candidate (held in every candidate, as a throughput manipulator is)"
    )]
    DisturbedMv {
        /// The disturbance's path.
        path: String,
        /// The other throughput candidates, whose candidates pair it (` (the candidates holding
        /// column.reflux pair it; a throughput change there is a step of column.reflux)`), or empty.
        held: String,
    },
    /// Not as many free MVs as CVs.
    #[error(
        "{cvs} CVs and {mvs} MVs{}: pairing needs as many MVs as CVs (one more with a `throughput` candidate), 1 to 8 of them",
        if *throughput { " with a throughput manipulator" } else { "" }
    )]
    NotSquare {
        /// CVs given.
        cvs: usize,
        /// MVs given.
        mvs: usize,
        /// Whether a throughput manipulator is held.
        throughput: bool,
    },
    /// A disturbance that is no free input of the open plant.
    #[error(
        "disturbances {path}: not an input of the plant that no controller drives; give a feed flow, composition or temperature"
    )]
    Disturbance {
        /// The path.
        path: String,
    },
    /// A disturbance that cannot be read, or whose step the plant refuses (no such input, a wrong
    /// unit, a value outside the input's physical range).
    #[error("disturbances {0}")]
    BadDisturbance(Box<crate::disturbance::DisturbanceError>),
    /// The sensitivity test could not be run for a throughput choice.
    #[error("sensitivity test (throughput {throughput}): {why}")]
    Sensitivity {
        /// The throughput manipulator (empty for none).
        throughput: String,
        /// Why.
        why: String,
    },
    /// A configuration could not be built.
    #[error("configuration {structure}: {source}")]
    Wiring {
        /// The configuration.
        structure: String,
        /// Why.
        source: Box<plantwide_flowsheet::OverrideError>,
    },
    /// The plant, or a configuration of it, has no steady state.
    #[error("configuration {structure}: {source}")]
    Steady {
        /// The configuration (`file` for the plant as written).
        structure: String,
        /// The solver's reason, naming the unit, equation and worst residual.
        source: Box<plantwide_solve::Error>,
    },
    /// A configuration's steady state is not the plant's (its qualities moved): its gains would
    /// describe another operating point.
    #[error(
        "configuration {structure}: its steady state has {output} = {value:.9e}, not the file's {base:.9e}; the \
         rewired level loops moved the operating point"
    )]
    Moved {
        /// The configuration.
        structure: String,
        /// The quality that moved.
        output: String,
        /// Its value in the configuration.
        value: f64,
        /// Its value in the plant as written.
        base: f64,
    },
    /// The plant has a model predictive controller: a screening opens loops around the CVs and
    /// MVs and pairs them, which a controller already there would fight.
    #[error(
        "controller `{controller}` is a model predictive controller: {study} takes no flowsheet with one; screen \
         the PID structure (remove `{controller}`) and give the controller as the screening's `mpc` to judge it beside the \
         pairings, or compare the two files with `plantwide compare`"
    )]
    ModelPredictive {
        /// The controller.
        controller: String,
        /// The study refused (`screen`, `compare`).
        study: &'static str,
    },
    /// A model predictive controller of the study does not resolve or cannot take part.
    #[error("controller `{controller}`: {why}")]
    Mpc {
        /// The controller.
        controller: String,
        /// What is wrong and what would fix it.
        why: String,
    },
    /// A linear-algebra step failed.
    #[error("configuration {structure}: {source}")]
    Analysis {
        /// The configuration.
        structure: String,
        /// Why.
        source: Box<plantwide_analysis::AnalysisError>,
    },
}

/// Refuse a plant with a model predictive controller for `study`.
pub(crate) fn without_mpc(plant: &plantwide_flowsheet::Plant, study: &'static str) -> Result<(), ScreenError> {
    let mpc =
        plant.spec().controllers.iter().find(|(_, c)| matches!(c, plantwide_model::registry::ControllerSpec::Mpc(_)));
    match mpc {
        Some((name, _)) => Err(ScreenError::ModelPredictive { controller: name.clone(), study }),
        None => Ok(()),
    }
}

impl From<crate::disturbance::DisturbanceError> for ScreenError {
    fn from(e: crate::disturbance::DisturbanceError) -> Self {
        ScreenError::BadDisturbance(Box::new(e))
    }
}

impl ScreenError {
    /// The [`ScreenRequest`] field a refusal is about, which its message starts with.
    pub fn field(&self) -> Option<&'static str> {
        match self {
            ScreenError::NoOutput { .. } | ScreenError::OutputCount(_) => Some("outputs"),
            ScreenError::Allowed { .. } => Some("allowed_deviation"),
            ScreenError::NoCv { .. } => Some("cvs"),
            ScreenError::NoWatch { .. } | ScreenError::WatchWithoutDisturbances => Some("watch"),
            ScreenError::NoMv { .. } => Some("mvs"),
            ScreenError::ThroughputNotMv { .. } => Some("throughput"),
            ScreenError::DisturbedMv { .. } | ScreenError::Disturbance { .. } | ScreenError::BadDisturbance(_) => {
                Some("disturbances")
            }
            ScreenError::Field { field, .. } => Some(field),
            ScreenError::Duplicate(d) => ScreenRequest::FIELDS.iter().copied().find(|f| *f == d.list),
            _ => None,
        }
    }

    /// True for problems of the request (exit code 1), false for numerical failures (exit code 2).
    pub fn is_user_error(&self) -> bool {
        match self {
            ScreenError::Steady { source, .. } => source.is_user_error(),
            ScreenError::Moved { .. }
            | ScreenError::Analysis { .. }
            | ScreenError::Sensitivity { .. }
            | ScreenError::Write { .. } => false,
            _ => true,
        }
    }
}
