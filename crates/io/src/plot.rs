//! Figures as PNG or SVG files (chosen by the file extension), drawn with plotters: trend plots
//! of a dynamic run ([`write_trends`], several runs overlaid with [`write_overlays`]), sensitivity
//! plots ([`write_sensitivity`]), heat maps of small matrices ([`write_matrices`]), rankings as bar
//! charts ([`write_bars`]), Bode diagrams of tuned loops ([`write_bode`]) and single curves
//! ([`write_line`]). Curves are told
//! apart by colour, line pattern and marker, legends stand beside the data, and titles are sized
//! to fit. Text is
//! drawn with the embedded DejaVu Sans font under the family `sans-serif`, so no system font
//! library is needed.

mod bars;
mod bode;
mod line;
mod matrices;
mod sensitivity;
mod style;
mod trends;

use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};

pub use bars::write_bars;
pub use bode::{BodeLoop, write_bode};
pub use line::write_line;
pub use matrices::{LabelledMatrix, write_matrices};
pub use sensitivity::write_sensitivity;
pub use style::{CurveStyle, Marker, curve_style, legend_width, marker_indices, title_font_size};
pub use trends::{Overlay, Trend, YScale, settled_end, write_overlays, write_responses, write_trends, y_scale};

use crate::error::IoError;

static FONTS: Once = Once::new();

/// Register the embedded fonts once per process under the family `sans-serif`.
fn register_fonts() {
    FONTS.call_once(|| {
        // The embedded faces are valid TrueType data; a failure here would leave text undrawn.
        let _ = register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
        let _ = register_font("sans-serif", FontStyle::Bold, dejavu::sans::bold());
    });
}

/// A figure that can be drawn on any plotters backend.
trait Figure {
    /// Draw the whole figure on `root` and present it.
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), IoError>;
}

/// Draw `figure` into `file` (`.png` or `.svg`, any case) of `size` pixels.
fn write_figure(file: &Path, size: (u32, u32), figure: &impl Figure) -> Result<(), IoError> {
    register_fonts();
    let ext = file.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("svg") => figure.draw(SVGBackend::new(file, size).into_drawing_area()),
        Some("png") => figure.draw(BitMapBackend::new(file, size).into_drawing_area()),
        _ => Err(IoError::PlotKind { file: file.display().to_string() }),
    }
}
