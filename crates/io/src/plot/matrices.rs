//! Heat maps of small matrices side by side, e.g. the relative gain arrays of a column's inventory
//! configurations: each cell coloured by its value on a log scale (blue for λ near 1, through
//! yellow to red for large |λ|; grey for a negative λ) and labelled with it; a matrix without
//! values (singular) drawn as an empty frame.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{Figure, write_figure};
use crate::error::IoError;

/// One matrix of the figure.
#[derive(Debug, Clone)]
pub struct LabelledMatrix {
    /// Title above it (e.g. `LV (rank 6)`).
    pub label: String,
    /// Rows of values, `None` when there are none (drawn as `singular`).
    pub values: Option<Vec<Vec<f64>>>,
}

/// Write the matrices side by side to `file` (`.png` or `.svg`), 240 × 300 pixels each.
pub fn write_matrices(file: &Path, title: &str, matrices: &[LabelledMatrix]) -> Result<(), IoError> {
    let width = 40 + 240 * matrices.len().max(1) as u32;
    write_figure(file, (width, 330), &Matrices { title, matrices })
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

impl Figure for Matrices<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), IoError> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| IoError::Draw(e.to_string());
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(self.title, ("sans-serif", 20).into_font()).map_err(err)?;
        let root = root.margin(10, 10, 20, 20);
        for (panel, m) in root.split_evenly((1, self.matrices.len().max(1))).iter().zip(self.matrices) {
            let panel = panel.titled(&m.label, ("sans-serif", 16).into_font()).map_err(err)?;
            let (w, h) = panel.dim_in_pixel();
            let side = (w.min(h) as i32 - 20).max(20);
            let Some(values) = &m.values else {
                panel.draw(&Rectangle::new([(10, 10), (10 + side, 10 + side)], BLACK.stroke_width(1))).map_err(err)?;
                let style = ("sans-serif", 16).into_font().color(&BLACK);
                panel.draw(&Text::new("singular", (side / 2 - 25, side / 2), style)).map_err(err)?;
                continue;
            };
            let n = values.len().max(1) as i32;
            let cell = side / n;
            for (i, row) in values.iter().enumerate() {
                for (j, &v) in row.iter().enumerate() {
                    let (x0, y0) = (10 + j as i32 * cell, 10 + i as i32 * cell);
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
            LabelledMatrix { label: "LV".into(), values: Some(vec![vec![35.9, -34.9], vec![-34.9, 35.9]]) },
            LabelledMatrix { label: "DB".into(), values: None },
        ];
        let file = dir.join("rga.svg");
        write_matrices(&file, "relative gains", &m).unwrap();
        let svg = std::fs::read_to_string(&file).unwrap();
        assert!(svg.contains("35.900") && svg.contains("-34.900") && svg.contains("singular"), "{svg}");
        write_matrices(&dir.join("rga.png"), "relative gains", &m).unwrap();
        assert!(std::fs::metadata(dir.join("rga.png")).unwrap().len() > 1000);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
