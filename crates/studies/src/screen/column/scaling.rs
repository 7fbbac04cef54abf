//! Scaled gains (Skogestad & Postlethwaite 2005, §1.4): a gain in SI units mixes watts, mol/s and
//! mole fractions, so the condition number of the SI matrix measures the units more than the
//! column. Each input is scaled by its nominal value `u₀` (its steady-state value: a relative
//! change of 1 is the whole flow) and each quality by its allowed deviation `Δy` (given, or for a
//! mole fraction its distance to 0 or 1 — a distillate at 0.995 may lose 0.005 before it is
//! worthless —, else its steady value): `G̃ = diag(1/Δy) G diag(u₀)`, γ = `σ_max(G̃)/σ_min(G̃)`. The
//! same `Δy` scales each quality's IAE in the dynamic check. The RGA and γ* do not depend on the
//! scaling.

use faer::Mat;
use plantwide_analysis::measures::{condition_number, rows, svd};
use plantwide_flowsheet::Plant;
use serde::Serialize;

use super::{ColumnStructure, Variant, input_value};
use crate::screen::ScreenError;

/// How the gains and IAEs are scaled.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Scaling {
    /// Each quality's allowed deviation (SI), top first: the scale of its row of gains and of its
    /// IAE.
    pub allowed_deviation: Vec<f64>,
    /// Where each came from: `given`, `distance to 0 or 1` (a mole fraction) or `steady value`.
    pub basis: Vec<String>,
    /// How the inputs are scaled (each configuration lists its scales in `input_scales`).
    pub inputs: String,
}

/// The qualities' scales: `allowed` when given (each must be positive), else each quality's
/// distance to 0 or 1 when it is a mole fraction (dimensionless, strictly between them), else its
/// steady value's magnitude (1 when it is 0).
///
/// # Errors
/// [`ScreenError::Allowed`] for a given deviation that is not a positive number.
pub(super) fn outputs(
    plant: &Plant,
    x: &[f64],
    out: &[usize],
    paths: &[String],
    allowed: Option<[f64; 2]>,
) -> Result<Scaling, ScreenError> {
    let inputs = "each input by its nominal (steady-state) value".to_string();
    if let Some(a) = allowed {
        if let Some((path, &value)) = paths.iter().zip(&a).find(|(_, v)| !(v.is_finite() && **v > 0.0)) {
            return Err(ScreenError::Allowed { path: path.clone(), value });
        }
        return Ok(Scaling { allowed_deviation: a.to_vec(), basis: vec!["given".into(); 2], inputs });
    }
    let (allowed_deviation, basis) = out
        .iter()
        .map(|&v| {
            let y = x[v];
            if plant.vars()[v].spec.dim.is_dimensionless() && y > 0.0 && y < 1.0 {
                (y.min(1.0 - y), "distance to 0 or 1".to_string())
            } else {
                (if y == 0.0 { 1.0 } else { y.abs() }, "steady value".to_string())
            }
        })
        .unzip();
    Ok(Scaling { allowed_deviation, basis, inputs })
}

/// The scaled gains of configuration `s` (converged as `v`) and their condition number γ.
///
/// # Errors
/// [`ScreenError::Analysis`] when the singular values cannot be computed.
pub(super) fn apply(s: &mut ColumnStructure, v: &Variant, scaling: &Scaling) -> Result<(), ScreenError> {
    let u0: Vec<f64> = s
        .inputs
        .iter()
        .map(|p| input_value(&v.plant, &v.x, p).abs())
        .map(|u| if u > 0.0 && u.is_finite() { u } else { 1.0 })
        .collect();
    let g = scaled(&v.gain, &u0, &scaling.allowed_deviation);
    let analysis = |e| ScreenError::Analysis { structure: s.name.clone(), source: Box::new(e) };
    s.condition_number = Some(condition_number(&svd(g.as_ref()).map_err(analysis)?.singular_values));
    s.scaled_gain = Some(rows(g.as_ref()));
    s.input_scales = Some(u0);
    Ok(())
}

/// `diag(1/dy) g diag(u0)`.
fn scaled(g: &Mat<f64>, u0: &[f64], dy: &[f64]) -> Mat<f64> {
    Mat::from_fn(g.nrows(), g.ncols(), |i, j| g[(i, j)] * u0[j] / dy[i])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_condition_number_of_scaled_gains_is_the_closed_form_of_a_2x2() {
        // G = [[2e-9, -1e-9], [3e-9, -4e-9]] per W, u0 = 1e6 W, dy = 0.01: G̃ = [[0.2, -0.1],
        // [0.3, -0.4]]; σ² are the roots of σ⁴ − (Σg²) σ² + det² = 0.
        let g = Mat::from_fn(2, 2, |i, j| [[2e-9, -1e-9], [3e-9, -4e-9]][i][j]);
        let s = scaled(&g, &[1e6, 1e6], &[0.01, 0.01]);
        let e = [[0.2, -0.1], [0.3, -0.4]];
        for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            assert!((s[(i, j)] - e[i][j]).abs() < 1e-15, "{i}{j}");
        }
        let (sum, det): (f64, f64) = (0.04 + 0.01 + 0.09 + 0.16, 0.2 * -0.4 - (-0.1 * 0.3));
        let root = (sum * sum - 4.0 * det * det).sqrt();
        let want = ((sum + root) / (sum - root)).sqrt();
        let got = condition_number(&svd(s.as_ref()).unwrap().singular_values);
        assert!((got - want).abs() < 1e-12 * want, "{got} vs {want}");
    }
}
