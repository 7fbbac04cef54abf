//! Controller tuning and limits.

use serde::{Deserialize, Serialize};

use crate::error::{MpcError, check_len, check_vec};

/// DMC tuning, horizons and limits (absolute engineering units).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    /// Prediction horizon `P` in samples (≥ 1).
    pub prediction_horizon: usize,
    /// Control horizon `M` in samples (number of future moves, `1 ≤ M ≤ P`).
    pub control_horizon: usize,
    /// Output weights `q_i ≥ 0` (length `ny`): `Q = diag(q)` repeated at every sample of the horizon.
    pub output_weights: Vec<f64>,
    /// Move-suppression weights `r_j ≥ 0` on `Δu_j` (length `nu`), repeated over the `M` moves.
    pub move_weights: Vec<f64>,
    /// Hard absolute lower input limits (length `nu`, `-INFINITY` allowed).
    pub u_min: Vec<f64>,
    /// Hard absolute upper input limits (length `nu`, `INFINITY` allowed).
    pub u_max: Vec<f64>,
    /// Hard rate limits `|Δu_j| ≤ du_max_j` per sample (length `nu`, `> 0`, `INFINITY` allowed).
    pub du_max: Vec<f64>,
    /// Soft lower output limits (length `ny`, `-INFINITY` allowed).
    pub y_min: Vec<f64>,
    /// Soft upper output limits (length `ny`, `INFINITY` allowed).
    pub y_max: Vec<f64>,
    /// Slack penalty `ρ ≥ 0` (must be `> 0` if any output limit is finite): the cost gets
    /// `ρ·ε + ½ρ·ε²` for each slack `ε ≥ 0`. There is one slack per finite output-limit side,
    /// shared by all `P` samples of the horizon (so the slack is the worst violation of that side).
    pub soft_weight: f64,
}

impl Settings {
    /// Settings with the given horizons and weights and no limits at all (all bounds infinite).
    pub fn unconstrained(
        prediction_horizon: usize,
        control_horizon: usize,
        output_weights: Vec<f64>,
        move_weights: Vec<f64>,
    ) -> Self {
        let (ny, nu) = (output_weights.len(), move_weights.len());
        Settings {
            prediction_horizon,
            control_horizon,
            output_weights,
            move_weights,
            u_min: vec![f64::NEG_INFINITY; nu],
            u_max: vec![f64::INFINITY; nu],
            du_max: vec![f64::INFINITY; nu],
            y_min: vec![f64::NEG_INFINITY; ny],
            y_max: vec![f64::INFINITY; ny],
            soft_weight: 0.0,
        }
    }

    /// Validate against a model with `ny` outputs and `nu` inputs.
    pub fn validate(&self, ny: usize, nu: usize) -> Result<(), MpcError> {
        if self.prediction_horizon == 0 {
            return Err(MpcError::invalid("prediction_horizon", "must be ≥ 1"));
        }
        if self.control_horizon == 0 {
            return Err(MpcError::invalid("control_horizon", "must be ≥ 1"));
        }
        if self.control_horizon > self.prediction_horizon {
            return Err(MpcError::invalid(
                "control_horizon",
                format!("M = {} exceeds prediction_horizon P = {}", self.control_horizon, self.prediction_horizon),
            ));
        }
        check_weights("output_weights", &self.output_weights, ny)?;
        check_weights("move_weights", &self.move_weights, nu)?;
        check_bounds(("u_min", "u_max"), &self.u_min, &self.u_max, nu)?;
        check_bounds(("y_min", "y_max"), &self.y_min, &self.y_max, ny)?;
        check_len("du_max", &self.du_max, nu)?;
        if let Some(x) = self.du_max.iter().find(|x| x.is_nan() || **x <= 0.0) {
            return Err(MpcError::invalid("du_max", format!("must be > 0, got {x}")));
        }
        let rho = self.soft_weight;
        if !(rho.is_finite() && rho >= 0.0) {
            return Err(MpcError::invalid("soft_weight", format!("must be finite and ≥ 0, got {rho}")));
        }
        let soft = self.y_min.iter().chain(&self.y_max).any(|y| y.is_finite());
        if soft && rho == 0.0 {
            return Err(MpcError::invalid("soft_weight", "must be > 0 when an output limit is finite"));
        }
        Ok(())
    }
}

/// Weights: length `n`, finite, `≥ 0`.
fn check_weights(field: &'static str, w: &[f64], n: usize) -> Result<(), MpcError> {
    check_vec(field, w, n)?;
    if let Some(x) = w.iter().find(|x| **x < 0.0) {
        return Err(MpcError::invalid(field, format!("must be ≥ 0, got {x}")));
    }
    Ok(())
}

/// Bounds: length `n`, no NaN, `lo < +∞`, `hi > −∞`, `lo ≤ hi`.
fn check_bounds(names: (&'static str, &'static str), lo: &[f64], hi: &[f64], n: usize) -> Result<(), MpcError> {
    check_len(names.0, lo, n)?;
    check_len(names.1, hi, n)?;
    for (k, (&l, &h)) in lo.iter().zip(hi).enumerate() {
        if l.is_nan() || l == f64::INFINITY {
            return Err(MpcError::invalid(names.0, format!("entry {k} is {l}")));
        }
        if h.is_nan() || h == f64::NEG_INFINITY {
            return Err(MpcError::invalid(names.1, format!("entry {k} is {h}")));
        }
        if l > h {
            return Err(MpcError::invalid(names.0, format!("entry {k}: {} = {l} exceeds {} = {h}", names.0, names.1)));
        }
    }
    Ok(())
}
