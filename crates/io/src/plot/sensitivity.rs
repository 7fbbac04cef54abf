//! Sensitivity plots (*Practical Distillation Control* fig. 6-6): one panel per output, one curve
//! per disturbance against "% change from base", told apart by colour, line pattern and marker,
//! named in a legend right of the data.

use std::path::Path;

use plantwide_analysis::select::Signal;
use plantwide_analysis::sensitivity::Curve;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::{Sample, curve_style, draw_curve, draw_legend, legend_width, titled};
use super::{Figure, write_figure};
use crate::error::IoError;

fn plot_error<E: std::fmt::Debug>(e: E) -> IoError {
    IoError::Draw(format!("plot: {e:?}"))
}

/// Draw the sweep `curves` of `outputs` under `title` into `file` (`.png` or `.svg`); one panel
/// of 900 × 380 pixels per output.
pub fn write_sensitivity(file: &Path, title: &str, curves: &[Curve], outputs: &[Signal]) -> Result<(), IoError> {
    let height = 120 + 380 * outputs.len() as u32;
    let legend_w = legend_width(curves.iter().map(|c| c.disturbance.signal.path.as_str()));
    write_figure(file, (900 + legend_w, height), &Sensitivity { title, curves, outputs, legend_w })
}

/// One panel per output, one curve per disturbance.
struct Sensitivity<'a> {
    title: &'a str,
    curves: &'a [Curve],
    outputs: &'a [Signal],
    /// Width of the legend column right of every panel [px].
    legend_w: u32,
}

impl Figure for Sensitivity<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), IoError> {
        let Sensitivity { title, curves, outputs, legend_w } = *self;
        root.fill(&WHITE).map_err(plot_error)?;
        let root = titled(&root, title, 24.0)?;
        let panels = root.split_evenly((outputs.len().max(1), 1));
        let by_percent = curves.iter().all(|c| c.disturbance.base != 0.0);
        let x_desc = if by_percent { "% change from base".to_string() } else { "disturbance value (SI)".to_string() };
        for (k, (panel, out)) in panels.iter().zip(outputs).enumerate() {
            let (w, h) = panel.dim_in_pixel();
            let (panel, legend_area) = panel.split_horizontally(w.saturating_sub(legend_w));
            let series: Vec<(String, Vec<(f64, f64)>)> = curves
                .iter()
                .map(|c| {
                    let pts = c
                        .values
                        .iter()
                        .zip(&c.outputs)
                        .filter_map(|(v, y)| y.as_ref().map(|y| (c.disturbance.percent(*v), out.display_value(y[k]))))
                        .collect();
                    (c.disturbance.signal.path.clone(), pts)
                })
                .collect();
            let all = series.iter().flat_map(|(_, p)| p.iter());
            let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
            for &(x, y) in all {
                (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
            }
            if !x0.is_finite() {
                (x0, x1, y0, y1) = (-1.0, 1.0, -1.0, 1.0);
            }
            let pad = |lo: f64, hi: f64| {
                let span = (hi - lo).max(1e-12 * hi.abs().max(1e-300));
                (lo - 0.05 * span, hi + 0.05 * span)
            };
            let ((x0, x1), (y0, y1)) = (pad(x0, x1), pad(y0, y1));
            let mut chart = ChartBuilder::on(&panel)
                .margin(12)
                .x_label_area_size(45)
                .y_label_area_size(90)
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(plot_error)?;
            chart
                .configure_mesh()
                .x_desc(x_desc.as_str())
                .y_desc(format!("{} [{}]", out.path, out.unit))
                .axis_desc_style(("sans-serif", 16))
                .draw()
                .map_err(plot_error)?;
            let n = series.len();
            let mut legend = Vec::new();
            for (idx, (name, pts)) in series.into_iter().enumerate() {
                let style = curve_style(idx, true);
                draw_curve(&mut chart, &pts, &style, (idx, n))?;
                legend.push((name, Sample::Line(style)));
            }
            draw_legend(&legend_area, &legend, &[], h as i32 - 57)?;
        }
        root.present().map_err(plot_error)?;
        Ok(())
    }
}
