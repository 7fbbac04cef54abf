//! Trend plots of a dynamic run: stacked panels against time, each with one or several curves
//! (several paths of one unit, or several runs or schemes overlaid, told apart by colour, line
//! pattern and markers), a setpoint drawn dashed under the curve that follows it, limits as dotted
//! horizontal lines (named at the edge when far from the data, so the axis follows the moves), a
//! shaded band, the scenario's events as vertical markers across every panel, and each panel's
//! legend in a column right of its data.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::style::{
    COLOURS, CurveStyle, GREY, Marker, Sample, curve_style, draw_curve, draw_legend, legend_width, titled,
};
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
    /// Horizontal lines (limits: `op_min`, `op_max`), named; one far from the data is named at
    /// the panel's edge instead ([`y_scale`]).
    pub limits: Vec<(String, f64)>,
    /// A band shaded behind the curves (the room a level may use), named, from and to; always
    /// within the axis.
    pub band: Option<(String, f64, f64)>,
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

/// Write the panels to `file`: one per [`Overlay`], each with its legend in a column right of
/// the data, and a vertical marker at each `(time, label)` of `events` (times in the units of
/// `times`). The time axis runs over all of `times` (a run's duration is its scenario's).
pub fn write_overlays(
    file: &Path,
    title: &str,
    time_label: &str,
    times: &[f64],
    panels: &[Overlay],
    events: &[(f64, String)],
) -> Result<(), IoError> {
    let legend = panels.iter().flat_map(|o| {
        let (top, bottom) = legend(o, &y_scale(o));
        top.into_iter().chain(bottom).map(|(name, _)| name)
    });
    let legend_w = legend_width(legend.collect::<Vec<_>>().iter().map(String::as_str));
    let height = 70 + 240 * panels.len().max(1) as u32;
    let trends = Trends { title, time_label, times, trends: panels, events, legend_w };
    write_figure(file, (1000 + legend_w, height), &trends)
}

/// [`write_overlays`] with the time axis fitted to the response: it ends a little after the
/// last curve settles ([`settled_end`]), not where a study's run, sized for the slowest case,
/// happens to stop.
pub fn write_responses(
    file: &Path,
    title: &str,
    time_label: &str,
    times: &[f64],
    panels: &[Overlay],
    events: &[(f64, String)],
) -> Result<(), IoError> {
    let end = settled_end(times, panels, events);
    let n = times.partition_point(|t| *t <= end).max(1).min(times.len());
    let cut = |v: &Vec<f64>| v[..n.min(v.len())].to_vec();
    let panels: Vec<Overlay> = panels
        .iter()
        .map(|o| Overlay {
            curves: o.curves.iter().map(|(name, v)| (name.clone(), cut(v))).collect(),
            dashed: o.dashed.iter().map(|(name, of, v)| (name.clone(), *of, cut(v))).collect(),
            ..o.clone()
        })
        .collect();
    write_overlays(file, title, time_label, &times[..n], &panels, events)
}

/// Where a response plot's time axis ends: the last time any curve is more than 2 % of its
/// excursion from its final value (a curve that does not move is settled from the start), not
/// before the last event, plus 30 % of the time from the start for the reader to see it stay
/// there; at most the last of `times`.
pub fn settled_end(times: &[f64], panels: &[Overlay], events: &[(f64, String)]) -> f64 {
    let (Some(&t0), Some(&t_end)) = (times.first(), times.last()) else { return 1.0 };
    let mut settled = events.iter().map(|e| e.0).filter(|t| (t0..=t_end).contains(t)).fold(t0, f64::max);
    let curves = panels.iter().flat_map(|o| o.curves.iter().map(|c| &c.1).chain(o.dashed.iter().map(|d| &d.2)));
    for values in curves {
        let Some(last) = values.iter().rev().copied().find(|v| v.is_finite()) else { continue };
        let finite = values.iter().copied().filter(|v| v.is_finite());
        let excursion = finite.map(|v| (v - last).abs()).fold(0.0, f64::max);
        if excursion <= 1e-9 * last.abs() {
            continue;
        }
        let away = values.iter().rposition(|v| v.is_finite() && (v - last).abs() > 0.02 * excursion);
        if let Some(t) = away.and_then(|i| times.get(i + 1).or(times.last())) {
            settled = settled.max(*t);
        }
    }
    (settled + 0.3 * (settled - t0)).min(t_end)
}

/// The stacked panels under one title.
struct Trends<'a> {
    title: &'a str,
    time_label: &'a str,
    times: &'a [f64],
    trends: &'a [Overlay],
    events: &'a [(f64, String)],
    /// Width of the legend column right of every panel [px] (one for all, so the time axes line up).
    legend_w: u32,
}

/// Colour of the band of a panel (the room a level may use).
const BAND: RGBColor = RGBColor(0, 150, 60);

/// The y axis of a panel and where its limits go.
#[derive(Debug, Clone, PartialEq)]
pub struct YScale {
    /// Bottom of the axis.
    pub lo: f64,
    /// Top of the axis.
    pub hi: f64,
    /// Limits drawn as lines across the panel (within the axis).
    pub inside: Vec<(String, f64)>,
    /// Limits above the axis, named at its upper edge.
    pub above: Vec<(String, f64)>,
    /// Limits below the axis, named at its lower edge.
    pub below: Vec<(String, f64)>,
}

/// The y axis of a panel: fitted to its curves, dashed curves and band, with a limit drawn across
/// when it lies within one span of the data from them (a saturated output shows its limit
/// beside it) and named at the edge when it is farther (an output moving 0.2 within 0 … 6 is
/// shown moving, not flat); padded by 5 %. A series that moves by less than 1e-6 of its size gets
/// a ±1 % band (tick labels of a 1e-9 span are unreadable and mean nothing to a reader).
pub fn y_scale(o: &Overlay) -> YScale {
    let dashed = o.dashed.iter().flat_map(|(_, _, v)| v.iter().copied());
    let band = o.band.iter().flat_map(|(_, a, b)| [*a, *b]);
    let data = o.curves.iter().flat_map(|(_, v)| v.iter().copied()).chain(dashed).chain(band);
    let range = |vs: &mut dyn Iterator<Item = f64>| {
        vs.filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)))
    };
    let (mut lo, mut hi) = range(&mut { data });
    if !lo.is_finite() {
        (lo, hi) = range(&mut o.limits.iter().map(|l| l.1));
    }
    if !lo.is_finite() {
        (lo, hi) = (0.0, 1.0);
    }
    let reach = (hi - lo).max(1e-6 * lo.abs().max(hi.abs())).max(1e-12);
    let mut s = YScale { lo, hi, inside: Vec::new(), above: Vec::new(), below: Vec::new() };
    for (name, v) in o.limits.iter().filter(|l| l.1.is_finite()) {
        let limit = (name.clone(), *v);
        match *v {
            v if v > hi + reach => s.above.push(limit),
            v if v < lo - reach => s.below.push(limit),
            v => {
                (s.lo, s.hi) = (s.lo.min(v), s.hi.max(v));
                s.inside.push(limit);
            }
        }
    }
    let scale = s.lo.abs().max(s.hi.abs());
    let flat = s.hi - s.lo < 1e-6 * scale || scale == 0.0;
    let pad = if flat { 0.01 * scale.max(1e-12) } else { (s.hi - s.lo) * 0.05 };
    (s.lo, s.hi) = (s.lo - pad, s.hi + pad);
    s
}

/// Decimals of a panel's tick labels: about three significant digits of its span.
fn decimals(s: &YScale) -> usize {
    (2.0 - (s.hi - s.lo).log10().floor()).clamp(0.0, 10.0) as usize
}

/// The styles of a panel's dashed curves: each in its curve's colour when the panel has several
/// curves; with one, its setpoint grey and other runs in colours of their own.
fn dashed_styles(o: &Overlay) -> Vec<CurveStyle> {
    let mut others = COLOURS[1..].iter().cycle();
    let mut colour = |(name, of, _): &(String, Option<usize>, Vec<f64>)| match of.filter(|_| o.curves.len() > 1) {
        Some(k) => COLOURS[k % COLOURS.len()],
        None if name.ends_with("setpoint") => GREY,
        None => *others.next().unwrap_or(&BLACK),
    };
    o.dashed.iter().map(|d| CurveStyle::dashed(colour(d), (8, 5))).collect()
}

/// The styles of a panel's curves ([`curve_style`]; a lone curve without markers).
fn curve_styles(o: &Overlay) -> Vec<CurveStyle> {
    let n = o.curves.len();
    let style = |k| CurveStyle {
        marker: if n == 1 { Marker::None } else { curve_style(k, false).marker },
        ..curve_style(k, o.dashed.is_empty())
    };
    (0..n).map(style).collect()
}

/// The style of a limit drawn across a panel.
fn limit_style() -> CurveStyle {
    CurveStyle::dashed(GREY, (2, 3))
}

/// A panel's legend: its named curves, dashed curves, band and limits from the top, limits
/// above the axis first (at its upper edge) and those below it last (at its lower edge).
type Legend = (Vec<(String, Sample)>, Vec<(String, Sample)>);

/// The legend of panel `o` drawn on scale `s`.
fn legend(o: &Overlay, s: &YScale) -> Legend {
    let d = decimals(s);
    let above = s.above.iter().map(|(n, v)| (format!("↑ {n} {v:.d$} (above)"), Sample::Note));
    let mut top: Vec<(String, Sample)> = above.collect();
    let named = o.curves.iter().zip(curve_styles(o)).filter(|((n, _), _)| !n.is_empty());
    top.extend(named.map(|((n, _), st)| (n.clone(), Sample::Line(st))));
    let dashed = o.dashed.iter().zip(dashed_styles(o));
    top.extend(dashed.map(|((n, _, _), st)| (n.clone(), Sample::Line(st))));
    top.extend(o.band.iter().map(|(n, _, _)| (n.clone(), Sample::Patch(BAND.mix(0.15)))));
    top.extend(s.inside.iter().map(|(n, _)| (n.clone(), Sample::Line(limit_style()))));
    let bottom = s.below.iter().map(|(n, v)| (format!("↓ {n} {v:.d$} (below)"), Sample::Note)).collect();
    (top, bottom)
}

/// Points of `values` at `times` where both are finite.
/// Width of a character of the event labels (12 px sans-serif) \[px\], a generous average.
const LABEL_CHAR_PX: f64 = 6.6;
/// Rows of event labels before they start again at the top.
const LABEL_ROWS: usize = 4;

/// Where each event label goes on a plot `width` px wide spanning the times `(t0, t1)`: its row
/// (0 at the top), the first in which it overlaps no label placed before it, and whether it is
/// anchored on its right (a label that would run past the plot's right edge ends at its marker).
fn label_places(events: &[&(f64, String)], (t0, t1): (f64, f64), width: f64) -> Vec<(usize, bool)> {
    let mut ends = [f64::NEG_INFINITY; LABEL_ROWS];
    let mut out = Vec::with_capacity(events.len());
    for (t, label) in events {
        let x = (t - t0) / (t1 - t0).max(f64::MIN_POSITIVE) * width;
        let w = label.chars().count() as f64 * LABEL_CHAR_PX;
        let right = x + w > width;
        let (from, to) = if right { (x - w, x) } else { (x, x + w) };
        let row = (0..LABEL_ROWS).find(|&r| ends[r] + 4.0 <= from).unwrap_or(0);
        ends[row] = to;
        out.push((row, right));
    }
    out
}

fn points(times: &[f64], values: &[f64]) -> Vec<(f64, f64)> {
    times.iter().copied().zip(values.iter().copied()).filter(|(_, v)| v.is_finite()).collect()
}

impl Trends<'_> {
    /// One panel: band, mesh, event markers, limits, dashed curves, curves; its legend beside it.
    fn panel<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, trend: &Overlay) -> Result<(), IoError> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| IoError::Draw(e.to_string());
        let (w, h) = area.dim_in_pixel();
        let (area, legend_area) = area.split_horizontally(w.saturating_sub(self.legend_w));
        let times = self.times;
        let (t0, t1) = (times.first().copied().unwrap_or(0.0), times.last().copied().unwrap_or(1.0));
        let t1 = if t1 > t0 { t1 } else { t0 + 1.0 };
        let scale = y_scale(trend);
        let (lo, hi) = (scale.lo, scale.hi);
        let decimals = decimals(&scale);
        let mut chart = ChartBuilder::on(&area)
            .margin(10)
            .margin_right(25)
            .x_label_area_size(35)
            .y_label_area_size(90)
            .build_cartesian_2d(t0..t1, lo..hi)
            .map_err(err)?;
        if let Some((_, a, b)) = trend.band {
            chart.draw_series([Rectangle::new([(t0, a), (t1, b)], BAND.mix(0.15).filled())]).map_err(err)?;
            let edges = [a, b].map(|v| PathElement::new(vec![(t0, v), (t1, v)], BAND.stroke_width(1)));
            chart.draw_series(edges).map_err(err)?;
        }
        chart
            .configure_mesh()
            .x_desc(self.time_label)
            .y_desc(trend.label.as_str())
            .axis_desc_style(("sans-serif", 15))
            .y_label_formatter(&|v| format!("{v:.decimals$}"))
            .draw()
            .map_err(err)?;
        let shown: Vec<&(f64, String)> = self.events.iter().filter(|(t, _)| (t0..=t1).contains(t)).collect();
        let plot = chart.plotting_area().dim_in_pixel();
        let places = label_places(&shown, (t0, t1), plot.0 as f64);
        // A row of labels is 14 px of the plot's height.
        let row = (hi - lo) * 14.0 / f64::from(plot.1.max(1));
        for ((t, label), (rows_down, right)) in shown.iter().zip(places) {
            let line = DashedLineSeries::new(vec![(*t, lo), (*t, hi)], 4, 4, GREY.stroke_width(1));
            chart.draw_series(line).map_err(err)?;
            let anchor = Pos::new(if right { HPos::Right } else { HPos::Left }, VPos::Top);
            let font = ("sans-serif", 12).into_font().color(&GREY).pos(anchor);
            let text = Text::new(label.clone(), (*t, hi - rows_down as f64 * row), font);
            chart.draw_series(std::iter::once(text)).map_err(err)?;
        }
        for (_, v) in &scale.inside {
            draw_curve(&mut chart, &[(t0, *v), (t1, *v)], &limit_style(), (0, 1))?;
        }
        for ((_, _, values), style) in trend.dashed.iter().zip(dashed_styles(trend)) {
            draw_curve(&mut chart, &points(times, values), &style, (0, 1))?;
        }
        let n = trend.curves.len();
        for (k, ((_, values), style)) in trend.curves.iter().zip(curve_styles(trend)).enumerate() {
            draw_curve(&mut chart, &points(times, values), &style, (k, n))?;
        }
        let (top, bottom) = legend(trend, &scale);
        draw_legend(&legend_area, &top, &bottom, h as i32 - 45)
    }
}

impl Figure for Trends<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), IoError> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| IoError::Draw(e.to_string());
        root.fill(&WHITE).map_err(err)?;
        let root = titled(&root, self.title, 24.0)?;
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

    /// Labels that would overlap go a row down; one past the right edge ends at its marker.
    #[test]
    fn event_labels_do_not_overlap_and_stay_inside() {
        let ev = [(0.0, "step F".to_string()), (1.0, "a long label here".to_string()), (50.0, "x".to_string())];
        let ev: Vec<&(f64, String)> = ev.iter().collect();
        let wide = label_places(&ev, (0.0, 100.0), 1000.0);
        assert_eq!(wide, vec![(0, false), (1, false), (0, false)]);
        let at_end = [(99.0, "tank.level < 0.5 m".to_string())];
        let at_end: Vec<&(f64, String)> = at_end.iter().collect();
        assert_eq!(label_places(&at_end, (0.0, 100.0), 1000.0), vec![(0, true)]);
    }

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
            band: None,
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
