//! Frequency results as data: at each ω the elements of `G(jω)` (real and imaginary parts,
//! magnitude, phase), its singular values, the frequency-dependent RGA `Λ(jω) = G ∘ (G⁻¹)ᵀ` and
//! the RGA number of a pairing — what `gains --frequencies` prints and `--json` carries, for a
//! flowsheet's linearization and a transfer-function model alike.

use faer::{Mat, c64};
use serde::Serialize;

use crate::measures::rga_complex;

/// A complex number with its polar form.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Complex {
    /// Real part.
    pub re: f64,
    /// Imaginary part.
    pub im: f64,
    /// |z|.
    pub magnitude: f64,
    /// arg z [degrees], in (−180, 180].
    pub phase_deg: f64,
}

impl From<c64> for Complex {
    fn from(z: c64) -> Complex {
        Complex { re: z.re, im: z.im, magnitude: z.norm(), phase_deg: z.im.atan2(z.re).to_degrees() }
    }
}

/// The results at one frequency.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrequencyPoint {
    /// ω [rad per the report's time unit].
    pub omega: f64,
    /// `G(jω)`, outputs × inputs, in the signals' display units.
    pub g: Vec<Vec<Complex>>,
    /// Singular values of `G(jω)`, non-increasing.
    pub singular_values: Vec<f64>,
    /// `Λ(jω)` (null when `G` is not square or singular there).
    pub rga: Option<Vec<Vec<Complex>>>,
    /// `Σ |Λ − I_pairing|` (null without a pairing or an RGA).
    pub rga_number: Option<f64>,
}

/// The frequency results of a report: the time unit of ω and one point per frequency.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrequencyResults {
    /// Time unit of ω (`rad/<unit>`).
    pub time_unit: String,
    /// One entry per frequency, in increasing ω.
    pub points: Vec<FrequencyPoint>,
}

fn rows(m: &Mat<c64>) -> Vec<Vec<Complex>> {
    (0..m.nrows()).map(|i| (0..m.ncols()).map(|j| m[(i, j)].into()).collect()).collect()
}

/// The point at `omega` (display units) of the response `g`, with the RGA number of `pairing`
/// (`pairing[i]` the input paired with output `i`; empty for none).
pub fn point(omega: f64, g: &Mat<c64>, pairing: &[usize]) -> FrequencyPoint {
    let singular_values = g.singular_values().unwrap_or_default();
    let rga = rga_complex(g.as_ref()).ok();
    let rga_number = rga.as_ref().filter(|_| !pairing.is_empty()).map(|l| {
        let mut number = 0.0;
        for i in 0..l.nrows() {
            for j in 0..l.ncols() {
                let p = if pairing[i] == j { 1.0 } else { 0.0 };
                number += (l[(i, j)] - c64::new(p, 0.0)).norm();
            }
        }
        number
    });
    FrequencyPoint { omega, g: rows(g), singular_values, rga: rga.as_ref().map(rows), rga_number }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_diagonal_response_has_the_identity_rga_and_its_elements_in_polar_form() {
        let g = Mat::from_fn(2, 2, |i, j| if i == j { c64::new(0.0, -(i as f64 + 1.0)) } else { c64::new(0.0, 0.0) });
        let p = point(0.5, &g, &[0, 1]);
        assert_eq!(p.g[1][1].magnitude, 2.0);
        assert!((p.g[0][0].phase_deg + 90.0).abs() < 1e-12);
        assert_eq!(p.singular_values, vec![2.0, 1.0]);
        assert!(p.rga_number.unwrap() < 1e-12);
        let wrong = point(0.5, &g, &[1, 0]);
        assert!((wrong.rga_number.unwrap() - 4.0).abs() < 1e-12);
    }
}
