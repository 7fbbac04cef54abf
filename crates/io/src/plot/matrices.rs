//! Heat maps of small matrices side by side, e.g. the relative gain arrays of a column's inventory
//! configurations: each cell coloured by its value on a log scale (blue for λ near 1, through
//! yellow to red for large |λ|; grey for a negative λ) and labelled with it; a matrix without
//! values (singular) drawn as an empty frame; a colour key under them reads the colours back.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::titled;
use super::{Figure, write_figure};
use crate::error::IoError;

/// One matrix of the figure.
#[derive(Debug, Clone, Default)]
pub struct LabelledMatrix {
    /// Title above it (e.g. `LV (rank 6)`).
    pub label: String,
    /// Rows of values, `None` when there are none (drawn as `singular`).
    pub values: Option<Vec<Vec<f64>>>,
    /// Row labels (outputs), drawn left of the rows; may be empty.
    pub rows: Vec<String>,
    /// Column labels (inputs), drawn above the columns; may be empty.
    pub cols: Vec<String>,
}

/// Room [px] for row and column labels when a matrix has them.
const LABELS: (i32, i32) = (130, 22);

/// Height of the colour key under the matrices [px].
const KEY: u32 = 64;

/// Write the matrices side by side to `file` (`.png` or `.svg`), 240 × 300 pixels each (more
/// with row and column labels), with the colour key under them.
pub fn write_matrices(file: &Path, title: &str, matrices: &[LabelledMatrix]) -> Result<(), IoError> {
    let labelled = matrices.iter().any(|m| !m.rows.is_empty() || !m.cols.is_empty());
    let (dx, dy) = if labelled { (LABELS.0 as u32, LABELS.1 as u32) } else { (0, 0) };
    let width = (40 + (240 + dx) * matrices.len().max(1) as u32).max(660);
    write_figure(file, (width, 330 + dy + KEY), &Matrices { title, matrices })
}

struct Matrices<'a> {
    title: &'a str,
    matrices: &'a [LabelledMatrix],
}

/// Colour of relative gain `v`: |ln λ| from 0 (blue) to ln 1000 (red); negative grey.
fn colour(v: f64) -> RGBColor {
    if v.is_nan() || v <= 0.0 {
        return RGBColor(170, 170, 170);
    }
    let s = (v.ln().abs() / 1000f64.ln()).clamp(0.0, 1.0);
    let (r, g, b) = if s < 0.5 {
        let t = s / 0.5;
        (70.0 + t * 185.0, 130.0 + t * 100.0, 220.0 - t * 170.0)
    } else {
        let t = (s - 0.5) / 0.5;
        (255.0, 230.0 - t * 170.0, 50.0)
    };
    RGBColor(r as u8, g as u8, b as u8)
}

/// The colour key: a bar from λ = 1 to |ln λ| = ln 1000 with λ and 1/λ at its ticks, and the
/// grey of a negative λ.
fn draw_key<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>) -> Result<(), IoError> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| IoError::Draw(e.to_string());
    let (x0, y0, width, height) = (30, 22, 420, 14);
    let font = ("sans-serif", 13).into_font().color(&BLACK);
    area.draw(&Text::new("colour of λ:", (x0, 4), font.clone())).map_err(err)?;
    for i in 0..width {
        let v = 1000f64.powf(f64::from(i) / f64::from(width - 1));
        let x = x0 + i;
        area.draw(&Rectangle::new([(x, y0), (x + 1, y0 + height)], colour(v).filled())).map_err(err)?;
    }
    for (k, tick) in ["1", "10 or 0.1", "100 or 0.01", "≥ 1000 or ≤ 0.001"].into_iter().enumerate() {
        let x = x0 + (k as i32 * (width - 1)) / 3;
        area.draw(&PathElement::new(vec![(x, y0 + height), (x, y0 + height + 4)], BLACK)).map_err(err)?;
        // The first label starts at its tick, the last a little before it, the others centred.
        let shift = match k {
            0 => 0,
            3 => 30,
            _ => 7 * tick.chars().count() as i32 / 2,
        };
        area.draw(&Text::new(tick, (x - shift, y0 + height + 6), font.clone())).map_err(err)?;
    }
    let grey = x0 + width + 130;
    area.draw(&Rectangle::new([(grey, y0), (grey + 30, y0 + height)], colour(-1.0).filled())).map_err(err)?;
    area.draw(&Text::new("λ ≤ 0", (grey + 36, y0), font)).map_err(err)?;
    Ok(())
}

impl Figure for Matrices<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), IoError> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| IoError::Draw(e.to_string());
        root.fill(&WHITE).map_err(err)?;
        let root = titled(&root, self.title, 20.0)?;
        let (root, key) = root.split_vertically(root.dim_in_pixel().1.saturating_sub(KEY));
        draw_key(&key)?;
        let root = root.margin(10, 10, 20, 20);
        for (panel, m) in root.split_evenly((1, self.matrices.len().max(1))).iter().zip(self.matrices) {
            let panel = panel.titled(&m.label, ("sans-serif", 16).into_font()).map_err(err)?;
            let labelled = !m.rows.is_empty() || !m.cols.is_empty();
            let (ox, oy) = if labelled { (10 + LABELS.0, 10 + LABELS.1) } else { (10, 10) };
            let (w, h) = panel.dim_in_pixel();
            let side = ((w as i32 - ox).min(h as i32 - oy) - 10).max(20);
            let Some(values) = &m.values else {
                panel.draw(&Rectangle::new([(ox, oy), (ox + side, oy + side)], BLACK.stroke_width(1))).map_err(err)?;
                let style = ("sans-serif", 16).into_font().color(&BLACK);
                panel.draw(&Text::new("singular", (side / 2 - 25, side / 2), style)).map_err(err)?;
                continue;
            };
            let n = values.len().max(values.first().map_or(1, Vec::len)).max(1) as i32;
            let cell = side / n;
            let small = ("sans-serif", 12).into_font().color(&BLACK);
            let short = |s: &str| s.chars().take(18).collect::<String>();
            for (i, r) in m.rows.iter().enumerate() {
                let y = oy + i as i32 * cell + cell / 2 - 6;
                panel.draw(&Text::new(short(r), (4, y), small.clone())).map_err(err)?;
            }
            for (j, c) in m.cols.iter().enumerate() {
                let x = ox + j as i32 * cell + 4;
                panel.draw(&Text::new(short(c), (x, oy - 16), small.clone())).map_err(err)?;
            }
            for (i, row) in values.iter().enumerate() {
                for (j, &v) in row.iter().enumerate() {
                    let (x0, y0) = (ox + j as i32 * cell, oy + i as i32 * cell);
                    panel.draw(&Rectangle::new([(x0, y0), (x0 + cell, y0 + cell)], colour(v).filled())).map_err(err)?;
                    panel
                        .draw(&Rectangle::new([(x0, y0), (x0 + cell, y0 + cell)], WHITE.stroke_width(2)))
                        .map_err(err)?;
                    let text = if v.abs() >= 1000.0 { format!("{v:.2e}") } else { format!("{v:.3}") };
                    let style = ("sans-serif", 15).into_font().color(&BLACK);
                    panel.draw(&Text::new(text, (x0 + cell / 2 - 24, y0 + cell / 2 - 7), style)).map_err(err)?;
                }
            }
        }
        root.present().map_err(err)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matrices_are_drawn_with_their_values_and_a_singular_one_marked() {
        let dir = std::env::temp_dir().join(format!("plantwide_matrices_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let m = [
            LabelledMatrix {
                label: "LV".into(),
                values: Some(vec![vec![35.9, -34.9], vec![-34.9, 35.9]]),
                rows: vec!["yD".into(), "xB".into()],
                cols: vec!["reflux".into(), "boilup".into()],
            },
            LabelledMatrix { label: "DB".into(), values: None, ..LabelledMatrix::default() },
        ];
        let file = dir.join("rga.svg");
        write_matrices(&file, "relative gains", &m).unwrap();
        let svg = std::fs::read_to_string(&file).unwrap();
        assert!(svg.contains("35.900") && svg.contains("-34.900") && svg.contains("singular"), "{svg}");
        assert!(svg.contains("reflux") && svg.contains("xB"), "labels drawn");
        assert!(svg.contains("colour of λ:") && svg.contains("λ ≤ 0") && svg.contains("10 or 0.1"), "key drawn");
        write_matrices(&dir.join("rga.png"), "relative gains", &m).unwrap();
        assert!(std::fs::metadata(dir.join("rga.png")).unwrap().len() > 1000);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
