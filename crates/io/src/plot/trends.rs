//! Trend plots of a dynamic run: one panel per recorded path against time, stacked; or several
//! runs overlaid in each panel, with a legend (the responses of candidate control structures).

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{Figure, write_figure};
use crate::error::IoError;

/// One curve: its label (path and unit) and its values at the plot's times.
#[derive(Debug, Clone)]
pub struct Trend {
    /// Axis label, e.g. `bottoms.x[light] [-]`.
    pub label: String,
    /// Values, one per time.
    pub values: Vec<f64>,
}

/// One panel of overlaid curves: its axis label and `(name, values)` per curve.
#[derive(Debug, Clone)]
pub struct Overlay {
    /// Axis label, e.g. `column1.T[21] [K]`.
    pub label: String,
    /// Named curves, one value per time.
    pub curves: Vec<(String, Vec<f64>)>,
}

/// Write the trends to `file` (`.png` or `.svg`): `times` along x, labelled `time_label`; one
/// panel of 1000 × 240 pixels per trend.
pub fn write_trends(
    file: &Path,
    title: &str,
    time_label: &str,
    times: &[f64],
    trends: &[Trend],
) -> Result<(), IoError> {
    let panels: Vec<Overlay> = trends
        .iter()
        .map(|t| Overlay { label: t.label.clone(), curves: vec![(String::new(), t.values.clone())] })
        .collect();
    write_overlays(file, title, time_label, times, &panels)
}

/// Write overlaid curves to `file`: one panel per [`Overlay`], a legend where the curves are named.
pub fn write_overlays(
    file: &Path,
    title: &str,
    time_label: &str,
    times: &[f64],
    panels: &[Overlay],
) -> Result<(), IoError> {
    let height = 70 + 240 * panels.len().max(1) as u32;
    write_figure(file, (1000, height), &Trends { title, time_label, times, trends: panels })
}

/// The stacked panels under one title.
struct Trends<'a> {
    title: &'a str,
    time_label: &'a str,
    times: &'a [f64],
    trends: &'a [Overlay],
}

const COLOURS: [RGBColor; 4] = [BLUE, RED, RGBColor(0, 140, 0), RGBColor(200, 120, 0)];

impl Figure for Trends<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), IoError> {
        let Trends { title, time_label, times, trends } = *self;
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| IoError::Draw(e.to_string());
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(title, ("sans-serif", 24).into_font()).map_err(err)?;
        let panels = root.split_evenly((trends.len().max(1), 1));
        let (t0, t1) = (times.first().copied().unwrap_or(0.0), times.last().copied().unwrap_or(1.0));
        let t1 = if t1 > t0 { t1 } else { t0 + 1.0 };
        for (panel, trend) in panels.iter().zip(trends) {
            let finite = trend.curves.iter().flat_map(|(_, v)| v.iter().copied()).filter(|v| v.is_finite());
            let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
            let (lo, hi) = if !lo.is_finite() {
                (0.0, 1.0)
            } else {
                // A series that moves by less than 1e-6 of its size is drawn as constant in a ±1 % band
                // (tick labels of a 1e-9 span are unreadable and mean nothing to a reader).
                let scale = lo.abs().max(hi.abs());
                let pad =
                    if hi - lo < 1e-6 * scale || scale == 0.0 { 0.01 * scale.max(1e-12) } else { (hi - lo) * 0.05 };
                (lo - pad, hi + pad)
            };
            // Enough decimals to tell the ticks apart (about three significant digits of the span).
            let decimals = (2.0 - (hi - lo).log10().floor()).clamp(0.0, 10.0) as usize;
            let mut chart = ChartBuilder::on(panel)
                .margin(10)
                .x_label_area_size(35)
                .y_label_area_size(90)
                .build_cartesian_2d(t0..t1, lo..hi)
                .map_err(err)?;
            chart
                .configure_mesh()
                .x_desc(time_label)
                .y_desc(trend.label.as_str())
                .axis_desc_style(("sans-serif", 15))
                .y_label_formatter(&|v| format!("{v:.decimals$}"))
                .draw()
                .map_err(err)?;
            for (k, (name, values)) in trend.curves.iter().enumerate() {
                let points = times.iter().copied().zip(values.iter().copied()).filter(|(_, v)| v.is_finite());
                let c = COLOURS[k % COLOURS.len()];
                let series = chart.draw_series(LineSeries::new(points, c.stroke_width(2))).map_err(err)?;
                if !name.is_empty() {
                    series.label(name.as_str()).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
                }
            }
            if trend.curves.iter().any(|(n, _)| !n.is_empty()) {
                chart
                    .configure_series_labels()
                    .background_style(WHITE.mix(0.8))
                    .border_style(BLACK)
                    .draw()
                    .map_err(err)?;
            }
        }
        root.present().map_err(err)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_and_svg_are_written_and_other_extensions_refused() {
        let dir = std::env::temp_dir().join(format!("plantwide_plot_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let times: Vec<f64> = (0..50).map(f64::from).collect();
        let trends = vec![
            Trend { label: "level [m]".into(), values: times.iter().map(|t| 1.0 - (-t / 10.0).exp()).collect() },
            Trend { label: "flat [-]".into(), values: vec![2.0; 50] },
        ];
        for name in ["t.png", "t.svg"] {
            let file = dir.join(name);
            write_trends(&file, "step response", "time [min]", &times, &trends).unwrap();
            assert!(std::fs::metadata(&file).unwrap().len() > 1000, "{name} written");
        }
        let svg = std::fs::read_to_string(dir.join("t.svg")).unwrap();
        assert!(svg.contains("level [m]") && svg.contains("step response"));
        assert!(write_trends(&dir.join("t.jpg"), "x", "t", &times, &trends).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
