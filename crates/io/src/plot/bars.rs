//! A ranking as a horizontal bar chart: one bar per candidate, best at the top, its value written
//! beside it (e.g. |ln λ11| of a column's configurations, or the dynamic scores of pairings).

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::titled;
use super::{Figure, write_figure};
use crate::error::IoError;

/// Write `bars` (`(label, value)`, in ranking order) to `file` (`.png` or `.svg`); non-finite
/// values are drawn as an empty row marked `–`.
pub fn write_bars(file: &Path, title: &str, value_label: &str, bars: &[(String, f64)]) -> Result<(), IoError> {
    let height = 110 + 36 * bars.len().max(1) as u32;
    let label_w = label_width(bars.iter().map(|(l, _)| l.as_str()));
    write_figure(file, (670 + label_w, height), &Bars { title, value_label, bars, label_w })
}

struct Bars<'a> {
    title: &'a str,
    value_label: &'a str,
    bars: &'a [(String, f64)],
    /// Room for the candidates' names left of the bars [px].
    label_w: u32,
}

/// The room [px] the longest of `labels` takes at the axis's font, with a little to spare.
fn label_width<'a>(labels: impl Iterator<Item = &'a str>) -> u32 {
    super::register_fonts();
    let font = ("sans-serif", 12).into_font();
    let widest = labels.map(|l| font.box_size(l).map_or(7 * l.chars().count() as u32, |s| s.0)).max();
    (widest.unwrap_or(0) + 30).clamp(120, 700)
}

impl Figure for Bars<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), IoError> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| IoError::Draw(e.to_string());
        root.fill(&WHITE).map_err(err)?;
        let root = titled(&root, self.title, 20.0)?;
        let n = self.bars.len().max(1);
        let top = self.bars.iter().map(|(_, v)| *v).filter(|v| v.is_finite()).fold(0.0, f64::max);
        let top = if top > 0.0 { 1.15 * top } else { 1.0 };
        let mut chart = ChartBuilder::on(&root)
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(self.label_w)
            // An integer range is inclusive: `0..n - 1` holds the n rows.
            .build_cartesian_2d(0.0..top, (0..n - 1).into_segmented())
            .map_err(err)?;
        let labels: Vec<&str> = self.bars.iter().map(|(l, _)| l.as_str()).collect();
        let label = |v: &SegmentValue<usize>| match v {
            SegmentValue::CenterOf(i) => {
                n.checked_sub(1 + *i).and_then(|k| labels.get(k)).map_or(String::new(), |s| s.to_string())
            }
            SegmentValue::Exact(_) | SegmentValue::Last => String::new(),
        };
        chart
            .configure_mesh()
            .disable_y_mesh()
            .x_desc(self.value_label)
            .y_label_formatter(&label)
            .y_labels(n)
            .label_style(("sans-serif", 12))
            .axis_desc_style(("sans-serif", 15))
            .draw()
            .map_err(err)?;
        // One histogram a bar: plotters sums a histogram's data in a hash map, so several bars in
        // one would be written in a different order on every run (the same picture, another file).
        for (k, (_, v)) in self.bars.iter().enumerate().filter(|(_, (_, v))| v.is_finite()) {
            let bar = Histogram::horizontal(&chart)
                .style(RGBColor(70, 130, 220).mix(0.8).filled())
                .margin(6)
                .data(std::iter::once((n - 1 - k, *v)));
            chart.draw_series(bar).map_err(err)?;
        }
        for (k, (_, v)) in self.bars.iter().enumerate() {
            let text = if v.is_finite() { format!("{v:.4}") } else { "–".to_string() };
            let at = if v.is_finite() { *v } else { 0.0 };
            let style = ("sans-serif", 14).into_font().color(&BLACK);
            let pos = (at + 0.01 * top, SegmentValue::CenterOf(n - 1 - k));
            chart.draw_series(std::iter::once(Text::new(text, pos, style))).map_err(err)?;
        }
        root.present().map_err(err)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ranking_is_drawn_best_first_with_its_values() {
        let dir = std::env::temp_dir().join(format!("plantwide_bars_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let bars = vec![("LB".to_string(), 0.579), ("DV".to_string(), 0.806), ("DB".to_string(), f64::NAN)];
        let file = dir.join("rank.svg");
        write_bars(&file, "ranking", "|ln λ11|", &bars).unwrap();
        let svg = std::fs::read_to_string(&file).unwrap();
        assert!(svg.contains("0.5790") && svg.contains("0.8060") && svg.contains("LB") && svg.contains("–"), "{svg}");
        write_bars(&dir.join("rank.png"), "ranking", "|ln λ11|", &bars).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
