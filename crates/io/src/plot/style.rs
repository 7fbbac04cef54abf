//! What tells the curves of a figure apart and where their names go: each curve's colour, line
//! pattern and markers ([`curve_style`]); the legend in a column of its own right of the data
//! ([`legend_width`]), so no entry hides a curve; titles shrunk to the figure's width
//! ([`title_font_size`]).

use plotters::coord::{CoordTranslate, Shift};
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use crate::error::IoError;

/// The curves' colours, in order.
pub(crate) const COLOURS: [RGBColor; 4] = [BLUE, RED, RGBColor(0, 140, 0), RGBColor(200, 120, 0)];
/// Limits, setpoints and event markers.
pub(crate) const GREY: RGBColor = RGBColor(110, 110, 110);

/// A marker drawn on a curve every so often.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    /// No marker.
    None,
    /// A filled circle.
    Circle,
    /// A filled triangle.
    Triangle,
    /// An open square.
    Square,
    /// A cross.
    Cross,
}

/// How one curve is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveStyle {
    /// Line colour.
    pub colour: RGBColor,
    /// Line width [px].
    pub width: u32,
    /// Dash and gap lengths [px]; `None`: a solid line.
    pub dash: Option<(u32, u32)>,
    /// The marker drawn about ten times along the curve.
    pub marker: Marker,
}

impl CurveStyle {
    /// A thin dashed line without markers (setpoints, limits, other runs).
    pub(crate) fn dashed(colour: RGBColor, dash: (u32, u32)) -> CurveStyle {
        CurveStyle { colour, width: 1, dash: Some(dash), marker: Marker::None }
    }
}

/// The style of curve `k` of a panel: its own colour and marker, and a line thinner than the
/// first curve's (a curve drawn over an equal one leaves the one under it showing). `patterned`
/// (no dashed setpoints or other runs in the panel, whose dashes would be confused with it):
/// curves after the first are dashed, dotted, dash-dotted, each differently.
pub fn curve_style(k: usize, patterned: bool) -> CurveStyle {
    const MARKERS: [Marker; 4] = [Marker::Circle, Marker::Triangle, Marker::Square, Marker::Cross];
    const DASHES: [Option<(u32, u32)>; 4] = [None, Some((10, 5)), Some((2, 4)), Some((16, 4))];
    CurveStyle {
        colour: COLOURS[k % COLOURS.len()],
        width: if k == 0 { 3 } else { 2 },
        dash: if patterned { DASHES[k % DASHES.len()] } else { None },
        marker: MARKERS[k % MARKERS.len()],
    }
}

/// The indices of the points of curve `k` of `n_curves` (`n_points` points) that carry its
/// marker: ten, evenly spaced and staggered between the curves, so that curves lying on one
/// another still show each marker.
pub fn marker_indices(k: usize, n_curves: usize, n_points: usize) -> Vec<usize> {
    if n_points == 0 {
        return Vec::new();
    }
    let every = n_points as f64 / 10.0;
    let offset = every * (k + 1) as f64 / (n_curves + 1) as f64;
    (0..10).map(|j| (offset + every * j as f64) as usize).filter(|&i| i < n_points).collect()
}

/// Draw `points` as a curve in `style` on `chart`, as curve `k` of `n_curves` for its markers.
pub(crate) fn draw_curve<DB: DrawingBackend, CT: CoordTranslate<From = (f64, f64)>>(
    chart: &mut ChartContext<'_, DB, CT>,
    points: &[(f64, f64)],
    style: &CurveStyle,
    (k, n_curves): (usize, usize),
) -> Result<(), IoError> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| IoError::Draw(e.to_string());
    let line = style.colour.stroke_width(style.width);
    match style.dash {
        Some((dash, gap)) => chart.draw_series(DashedLineSeries::new(points.iter().copied(), dash, gap, line)),
        None => chart.draw_series(LineSeries::new(points.iter().copied(), line)),
    }
    .map_err(err)?;
    let marked = marker_indices(k, n_curves, points.len()).into_iter().map(|i| points[i]);
    let (fill, open) = (style.colour.filled(), style.colour.stroke_width(2));
    match style.marker {
        Marker::None => return Ok(()),
        Marker::Circle => chart.draw_series(marked.map(|p| Circle::new(p, 4, fill))),
        Marker::Triangle => chart.draw_series(marked.map(|p| TriangleMarker::new(p, 6, fill))),
        Marker::Square => {
            chart.draw_series(marked.map(|p| EmptyElement::at(p) + Rectangle::new([(-4, -4), (4, 4)], open)))
        }
        Marker::Cross => chart.draw_series(marked.map(|p| Cross::new(p, 5, open))),
    }
    .map_err(err)?;
    Ok(())
}

/// What a legend entry shows beside its name.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Sample {
    /// A piece of the curve, with its marker.
    Line(CurveStyle),
    /// A filled patch (a band).
    Patch(RGBAColor),
    /// No sample: a note (a limit off the axis).
    Note,
}

/// Height of a legend entry [px].
const ENTRY: i32 = 18;
/// Font size of legend entries.
const LEGEND_FONT: f64 = 13.0;

/// The width [px] of a legend column for entries named `names`: room for the sample and the
/// longest name at the legend's font (0 when there is none). The data area ends where it begins.
pub fn legend_width<'a>(names: impl IntoIterator<Item = &'a str>) -> u32 {
    super::register_fonts();
    let font = ("sans-serif", LEGEND_FONT).into_font();
    let widest = names.into_iter().map(|n| font.box_size(n).map_or(8 * n.chars().count() as u32, |s| s.0)).max();
    widest.map_or(0, |w| (w + 64).clamp(120, 420))
}

/// Draw `top` entries downwards from the top of `area` (a column beside the data) and `bottom`
/// entries upwards from `bottom_y` [px], the data area's lower edge.
pub(crate) fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    top: &[(String, Sample)],
    bottom: &[(String, Sample)],
    bottom_y: i32,
) -> Result<(), IoError> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| IoError::Draw(e.to_string());
    let font = ("sans-serif", LEGEND_FONT).into_font().color(&BLACK);
    let n_bottom = bottom.len() as i32;
    let rows = top.iter().enumerate().map(|(i, e)| (14 + ENTRY * i as i32, e));
    let rows = rows.chain(bottom.iter().enumerate().map(|(i, e)| (bottom_y - ENTRY * (n_bottom - i as i32) + 9, e)));
    for (y, (name, sample)) in rows {
        match sample {
            Sample::Line(s) => {
                let style = s.colour.stroke_width(s.width);
                let path = vec![(10, y), (40, y)];
                match s.dash {
                    Some((dash, gap)) => area.draw(&DashedPathElement::new(path, dash.min(8), gap.min(4), style)),
                    None => area.draw(&PathElement::new(path, style)),
                }
                .map_err(err)?;
                let at = (25, y);
                match s.marker {
                    Marker::None => Ok(()),
                    Marker::Circle => area.draw(&Circle::new(at, 4, s.colour.filled())),
                    Marker::Triangle => area.draw(&TriangleMarker::new(at, 6, s.colour.filled())),
                    Marker::Square => area.draw(&Rectangle::new([(21, y - 4), (29, y + 4)], s.colour.stroke_width(2))),
                    Marker::Cross => area.draw(&Cross::new(at, 5, s.colour.stroke_width(2))),
                }
                .map_err(err)?;
            }
            Sample::Patch(c) => area.draw(&Rectangle::new([(10, y - 6), (40, y + 6)], c.filled())).map_err(err)?,
            Sample::Note => {}
        }
        area.draw(&Text::new(name.clone(), (46, y - 7), font.clone())).map_err(err)?;
    }
    Ok(())
}

/// The largest font size, from `largest` down to 11, at which `title` fits in `width` pixels
/// with 10 px either side.
pub fn title_font_size(title: &str, width: u32, largest: f64) -> f64 {
    super::register_fonts();
    let fits = |size: f64| ("sans-serif", size).into_font().box_size(title).is_ok_and(|(w, _)| w + 20 <= width);
    let mut size = largest;
    while size > 11.0 && !fits(size) {
        size -= 1.0;
    }
    size
}

/// `root` with `title` above it, in a font no larger than `largest` that fits its width.
pub(crate) fn titled<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    largest: f64,
) -> Result<DrawingArea<DB, Shift>, IoError> {
    let size = title_font_size(title, root.dim_in_pixel().0, largest);
    root.titled(title, ("sans-serif", size).into_font()).map_err(|e| IoError::Draw(e.to_string()))
}
