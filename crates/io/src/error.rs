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
}
