//! Trend plots of a dynamic run: stacked panels against time, each with one or several curves
//! (several paths of one unit, or several runs or schemes overlaid, with a legend), a setpoint
//! drawn dashed under the curve that follows it, limits as dotted horizontal lines, and the
//! scenario's events as vertical markers across every panel.

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

/// One panel: its axis label, its curves and what is drawn behind them.
#[derive(Debug, Clone, Default)]
pub struct Overlay {
    /// Axis label, e.g. `column1.T[21] [K]`.
    pub label: String,
    /// Named curves, one value per time (an empty name: no legend entry).
    pub curves: Vec<(String, Vec<f64>)>,
    /// Dashed curves (setpoints, another run's trend), named, one value per time (NaN: not there),
    /// each in the colour of the curve it belongs to (`Some(k)`: `curves[k]`; `None`: black).
    pub dashed: Vec<(String, Option<usize>, Vec<f64>)>,
    /// Horizontal lines (limits: `op_min`, `op_max`), named.
    pub limits: Vec<(String, f64)>,
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
        .map(|t| Overlay {
            label: t.label.clone(),
            curves: vec![(String::new(), t.values.clone())],
            ..Overlay::default()
        })
        .collect();
    write_overlays(file, title, time_label, times, &panels, &[])
}

/// Write the panels to `file`: one per [`Overlay`], a legend where curves are named, and a
/// vertical marker at each `(time, label)` of `events` (times in the units of `times`).
pub fn write_overlays(
    file: &Path,
    title: &str,
    time_label: &str,
    times: &[f64],
    panels: &[Overlay],
    events: &[(f64, String)],
) -> Result<(), IoError> {
    let height = 70 + 240 * panels.len().max(1) as u32;
    write_figure(file, (1000, height), &Trends { title, time_label, times, trends: panels, events })
}

/// The stacked panels under one title.
struct Trends<'a> {
    title: &'a str,
    time_label: &'a str,
    times: &'a [f64],
    trends: &'a [Overlay],
    events: &'a [(f64, String)],
}

const COLOURS: [RGBColor; 4] = [BLUE, RED, RGBColor(0, 140, 0), RGBColor(200, 120, 0)];
const GREY: RGBColor = RGBColor(110, 110, 110);

/// The y range of a panel: every finite value of its curves, dashed curves and limits, padded by
/// 5 %; a series that moves by less than 1e-6 of its size in a ±1 % band (tick labels of a 1e-9
/// span are unreadable and mean nothing to a reader).
fn y_range(o: &Overlay) -> (f64, f64) {
    let dashed = o.dashed.iter().flat_map(|(_, _, v)| v.iter().copied());
    let curves = o.curves.iter().flat_map(|(_, v)| v.iter().copied()).chain(dashed);
    let finite = curves.chain(o.limits.iter().map(|l| l.1)).filter(|v| v.is_finite());
    let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let scale = lo.abs().max(hi.abs());
    let pad = if hi - lo < 1e-6 * scale || scale == 0.0 { 0.01 * scale.max(1e-12) } else { (hi - lo) * 0.05 };
    (lo - pad, hi + pad)
}

/// Points of `values` at `times` where both are finite.
fn points<'a>(times: &'a [f64], values: &'a [f64]) -> impl Iterator<Item = (f64, f64)> + Clone + 'a {
    times.iter().copied().zip(values.iter().copied()).filter(|(_, v)| v.is_finite())
}

impl Trends<'_> {
    /// One panel: mesh, event markers, limits, dashed curves, curves, legend.
    fn panel<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, trend: &Overlay) -> Result<(), IoError> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| IoError::Draw(e.to_string());
        let times = self.times;
        let (t0, t1) = (times.first().copied().unwrap_or(0.0), times.last().copied().unwrap_or(1.0));
        let t1 = if t1 > t0 { t1 } else { t0 + 1.0 };
        let (lo, hi) = y_range(trend);
        // Enough decimals to tell the ticks apart (about three significant digits of the span).
        let decimals = (2.0 - (hi - lo).log10().floor()).clamp(0.0, 10.0) as usize;
        let mut chart = ChartBuilder::on(area)
            .margin(10)
            .margin_right(40)
            .x_label_area_size(35)
            .y_label_area_size(90)
            .build_cartesian_2d(t0..t1, lo..hi)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(self.time_label)
            .y_desc(trend.label.as_str())
            .axis_desc_style(("sans-serif", 15))
            .y_label_formatter(&|v| format!("{v:.decimals$}"))
            .draw()
            .map_err(err)?;
        for (t, label) in self.events.iter().filter(|(t, _)| (t0..=t1).contains(t)) {
            let line = DashedLineSeries::new(vec![(*t, lo), (*t, hi)], 4, 4, GREY.stroke_width(1));
            chart.draw_series(line).map_err(err)?;
            let text = Text::new(label.clone(), (*t, hi), ("sans-serif", 12).into_font().color(&GREY));
            chart.draw_series(std::iter::once(text)).map_err(err)?;
        }
        for (name, v) in &trend.limits {
            let c = GREY;
            let line = DashedLineSeries::new(vec![(t0, *v), (t1, *v)], 2, 3, c.stroke_width(1));
            let s = chart.draw_series(line).map_err(err)?;
            s.label(name.as_str()).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
        }
        let mut others = COLOURS[1..].iter().cycle();
        for (name, of, values) in &trend.dashed {
            // One curve: its setpoint grey, other runs in colours of their own; several: each in
            // its curve's colour.
            let c = match of.filter(|_| trend.curves.len() > 1) {
                Some(k) => COLOURS[k % COLOURS.len()],
                None if name.ends_with("setpoint") => GREY,
                None => *others.next().unwrap_or(&BLACK),
            };
            let line = DashedLineSeries::new(points(times, values), 8, 5, c.stroke_width(1));
            let s = chart.draw_series(line).map_err(err)?;
            s.label(name.as_str()).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
        }
        for (k, (name, values)) in trend.curves.iter().enumerate() {
            let c = COLOURS[k % COLOURS.len()];
            let series = chart.draw_series(LineSeries::new(points(times, values), c.stroke_width(2))).map_err(err)?;
            if !name.is_empty() {
                series.label(name.as_str()).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
            }
        }
        let named = trend.curves.iter().any(|(n, _)| !n.is_empty());
        if named || !trend.dashed.is_empty() || !trend.limits.is_empty() {
            chart.configure_series_labels().background_style(WHITE.mix(0.8)).border_style(BLACK).draw().map_err(err)?;
        }
        Ok(())
    }
}

impl Figure for Trends<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), IoError> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| IoError::Draw(e.to_string());
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(self.title, ("sans-serif", 24).into_font()).map_err(err)?;
        let panels = root.split_evenly((self.trends.len().max(1), 1));
        for (panel, trend) in panels.iter().zip(self.trends) {
            self.panel(panel, trend)?;
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
        let panel = Overlay {
            label: "T [K]".into(),
            curves: vec![("this run".into(), trends[0].values.clone())],
            dashed: vec![("setpoint".into(), Some(0), vec![0.9; 50])],
            limits: vec![("op_max".into(), 1.2)],
        };
        let file = dir.join("o.svg");
        write_overlays(&file, "overlay", "time [min]", &times, &[panel], &[(10.0, "feed step".into())]).unwrap();
        let svg = std::fs::read_to_string(&file).unwrap();
        for text in ["this run", "setpoint", "op_max", "feed step"] {
            assert!(svg.contains(text), "{text} drawn");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
