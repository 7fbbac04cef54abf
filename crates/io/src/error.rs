//! Errors of the file formats and figures: a malformed transfer-function file, a plot file of an
//! unknown kind, a figure that could not be drawn or written.

/// Why a file could not be read or a figure drawn.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IoError {
    /// A transfer-function file is unreadable or inconsistent.
    #[error("{file}: {path}: {message}")]
    TfFile {
        /// File name.
        file: String,
        /// JSON path of the offending field (`elements[2].lags[0]`).
        path: String,
        /// What is wrong and what would fix it.
        message: String,
    },
    /// A transfer-function element whose polynomial coefficients overflow in the time unit asked
    /// for (`Π(τ s + 1)` of many slow lags: τⁿ beyond 1e308).
    #[error(
        "model `{model}`: element {element}: its polynomial coefficients overflow with times in {time_unit} (a \
         product of {order} lags and leads of up to {slowest:e} {time_unit}): give a larger `time_unit` (min, h) \
         so that the coefficients stay finite"
    )]
    Overflow {
        /// Model name.
        model: String,
        /// The element (`y ← u`).
        element: String,
        /// The time unit of the coefficients.
        time_unit: String,
        /// Number of lags and leads.
        order: usize,
        /// Its slowest time constant in that unit.
        slowest: f64,
    },
    /// A plot file whose name ends in neither `.png` nor `.svg`.
    #[error("{file}: the plot file must end in .png or .svg")]
    PlotKind {
        /// The plot file.
        file: String,
    },
    /// A figure could not be drawn or its file not written: plotters' error, as each figure has
    /// always worded it (a trend plot by its message, a sensitivity plot as `plot: ` and its debug
    /// form).
    #[error("{0}")]
    Draw(String),
    /// A display unit asked for a path (`PATH@unit`) that is no unit, or not one of the path's
    /// dimension.
    #[error("outputs {path}@{unit}: {why}")]
    DisplayUnit {
        /// The path.
        path: String,
        /// The unit asked.
        unit: String,
        /// Why it cannot show the path.
        why: String,
    },
    /// A trend plot's panel (`"panel"` in a scenario's record) that holds paths shown in two
    /// units: a panel has one axis.
    #[error(
        "record.paths[{}].panel `{}`: `{}` is in {} and `{}` in {}; a panel has one axis: give them one unit",
        .0.index, .0.panel, .0.first.0, .0.first.1, .0.other.0, .0.other.1
    )]
    PanelUnits(Box<MixedPanel>),
    /// A figure with nothing to draw: every part it would show failed, and a plot of what is left
    /// would read as an answer.
    #[error("{file}: not written: {why}")]
    NothingToPlot {
        /// The plot file.
        file: String,
        /// Why there is nothing (which parts failed).
        why: String,
    },
}

/// The two units of one trend-plot panel ([`IoError::PanelUnits`]).
#[derive(Debug, Clone, PartialEq)]
pub struct MixedPanel {
    /// The record entry of the second unit.
    pub index: usize,
    /// The panel.
    pub panel: String,
    /// The panel's first path and its unit.
    pub first: (String, String),
    /// The path in another unit, and that unit.
    pub other: (String, String),
}

impl IoError {
    /// The request field an error is about, which its message starts with.
    pub fn field(&self) -> Option<&'static str> {
        matches!(self, IoError::DisplayUnit { .. }).then_some("outputs")
    }

    /// True when the file is missing because the study has no result to show (exit code 2 at the
    /// faces), false for a file that was asked wrongly or could not be written.
    pub fn is_missing_result(&self) -> bool {
        matches!(self, IoError::NothingToPlot { .. })
    }
}
