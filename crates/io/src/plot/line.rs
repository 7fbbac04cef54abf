//! One curve `y(x)` with its points marked: the optimum along a swept disturbance. A point
//! without a value (`None`) breaks the curve there and is not drawn.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::titled;
use super::{Figure, write_figure};
use crate::error::IoError;

/// Write the curve `(xs, ys)` under `title` with the axis labels `(x, y)` into `file` (`.png`
/// or `.svg`), 900 × 480 pixels.
pub fn write_line(
    file: &Path,
    title: &str,
    labels: (&str, &str),
    xs: &[f64],
    ys: &[Option<f64>],
) -> Result<(), IoError> {
    write_figure(file, (900, 480), &Line { title, labels, xs, ys })
}

struct Line<'a> {
    title: &'a str,
    labels: (&'a str, &'a str),
    xs: &'a [f64],
    ys: &'a [Option<f64>],
}

/// `[lo, hi]` of the finite `values`, widened by 5 % (or by 1 when they are all equal).
fn span(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) =
        values.filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = if hi > lo { 0.05 * (hi - lo) } else { 1.0 };
    (lo - pad, hi + pad)
}

impl Figure for Line<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), IoError> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| IoError::Draw(e.to_string());
        root.fill(&WHITE).map_err(err)?;
        let root = titled(&root, self.title, 20.0)?;
        let (x0, x1) = span(self.xs.iter().copied());
        let (y0, y1) = span(self.ys.iter().flatten().copied());
        let mut chart = ChartBuilder::on(&root)
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(self.labels.0)
            .y_desc(self.labels.1)
            .label_style(("sans-serif", 12))
            .axis_desc_style(("sans-serif", 15))
            .draw()
            .map_err(err)?;
        let colour = RGBColor(70, 130, 220);
        let mut run: Vec<(f64, f64)> = Vec::new();
        let points = self.xs.iter().zip(self.ys).map(|(&x, y)| y.map(|y| (x, y)));
        for p in points.chain(std::iter::once(None)) {
            match p {
                Some(xy) => run.push(xy),
                None if !run.is_empty() => {
                    chart.draw_series(LineSeries::new(run.clone(), colour.stroke_width(2))).map_err(err)?;
                    chart.draw_series(run.iter().map(|&xy| Circle::new(xy, 3, colour.filled()))).map_err(err)?;
                    run.clear();
                }
                None => {}
            }
        }
        root.present().map_err(err)
    }
}
