//! Step-response (finite step response, FSR) models.

use serde::{Deserialize, Serialize};

use crate::error::{MpcError, check_len};

/// Step-response model in deviation variables.
///
/// `steps[k][i*nu + j]` = `S_k(i, j)` = response of output `i` at time `(k+1)·ts` to a unit step
/// in input `j` applied at `t = 0` (output units per input unit). `N = steps.len()` coefficients;
/// beyond the last one the response is held constant (`S_k = S_{N-1}` for `k ≥ N`, settled model),
/// so `S_{N-1}` is the steady-state gain matrix.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StepModel {
    /// Sample time (any time unit, > 0).
    pub ts: f64,
    /// Number of outputs.
    pub ny: usize,
    /// Number of inputs.
    pub nu: usize,
    /// Step coefficients, `N` rows of `ny*nu` (row-major `i*nu + j`).
    pub steps: Vec<Vec<f64>>,
}

impl StepModel {
    /// Validated constructor: `ts > 0` finite, `ny, nu ≥ 1`, `N ≥ 1`, each row of length `ny*nu`,
    /// all coefficients finite.
    pub fn new(ts: f64, ny: usize, nu: usize, steps: Vec<Vec<f64>>) -> Result<Self, MpcError> {
        let m = StepModel { ts, ny, nu, steps };
        m.validate()?;
        Ok(m)
    }

    /// Re-check the invariants of [`StepModel::new`] (useful after deserialisation).
    pub fn validate(&self) -> Result<(), MpcError> {
        if !(self.ts.is_finite() && self.ts > 0.0) {
            return Err(MpcError::invalid("ts", format!("must be > 0, got {}", self.ts)));
        }
        if self.ny == 0 {
            return Err(MpcError::invalid("ny", "must be ≥ 1"));
        }
        if self.nu == 0 {
            return Err(MpcError::invalid("nu", "must be ≥ 1"));
        }
        if self.steps.is_empty() {
            return Err(MpcError::invalid("steps", "need at least one coefficient"));
        }
        // A row of ny·nu coefficients: sizes whose product overflows cannot match any row.
        let Some(width) = self.ny.checked_mul(self.nu) else {
            return Err(MpcError::invalid(
                "ny",
                format!("{} × {} channels is not a size a model can have", self.ny, self.nu),
            ));
        };
        for (k, row) in self.steps.iter().enumerate() {
            check_len("steps", row, width)?;
            if row.iter().any(|x| !x.is_finite()) {
                return Err(MpcError::invalid("steps", format!("row {k} has a non-finite entry")));
            }
        }
        Ok(())
    }

    /// Sampled first-order-plus-dead-time matrix model.
    ///
    /// Element `(i, j)`: `s_ij(t) = K_ij (1 − exp(−(t − θ_ij)/τ_ij))` for `t > θ_ij`, else 0,
    /// sampled at `t = (k+1)·ts`, `k = 0..n-1`. `τ_ij = 0` gives a delayed pure gain. Because the
    /// input of a sampled controller is piecewise constant, these samples are the exact
    /// zero-order-hold step response of `K e^{−θs}/(τs + 1)` for any `θ ≥ 0`.
    /// `gains`, `taus`, `delays` are `ny × nu`; `taus, delays ≥ 0`; times in the units of `ts`.
    pub fn from_first_order(
        ts: f64,
        gains: &[Vec<f64>],
        taus: &[Vec<f64>],
        delays: &[Vec<f64>],
        n: usize,
    ) -> Result<Self, MpcError> {
        if !(ts.is_finite() && ts > 0.0) {
            return Err(MpcError::invalid("ts", format!("must be > 0, got {ts}")));
        }
        if n == 0 {
            return Err(MpcError::invalid("n", "must be ≥ 1"));
        }
        let ny = gains.len();
        if ny == 0 {
            return Err(MpcError::invalid("gains", "need at least one row"));
        }
        let nu = gains[0].len();
        if nu == 0 {
            return Err(MpcError::invalid("gains", "need at least one column"));
        }
        check_matrix("gains", gains, ny, nu, f64::NEG_INFINITY)?;
        check_matrix("taus", taus, ny, nu, 0.0)?;
        check_matrix("delays", delays, ny, nu, 0.0)?;
        let steps = (0..n)
            .map(|k| {
                let t = (k + 1) as f64 * ts;
                let mut row = vec![0.0; ny * nu];
                for i in 0..ny {
                    for j in 0..nu {
                        row[i * nu + j] = foptd_step(gains[i][j], taus[i][j], delays[i][j], t);
                    }
                }
                row
            })
            .collect();
        StepModel::new(ts, ny, nu, steps)
    }

    /// Number of step coefficients `N`.
    pub fn len(&self) -> usize {
        self.steps.len()
    }

    /// Always false for a validated model (kept for clippy's `len_without_is_empty`).
    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }

    /// Coefficient `S_k` (row-major `ny*nu`), held at `S_{N-1}` for `k ≥ N`.
    pub fn coefficient(&self, k: usize) -> &[f64] {
        let last = self.steps.len().saturating_sub(1);
        &self.steps[k.min(last)]
    }

    /// Steady-state gain matrix `ny × nu` (the last coefficient).
    pub fn gain(&self) -> Vec<Vec<f64>> {
        let last = self.coefficient(usize::MAX);
        (0..self.ny).map(|i| last[i * self.nu..(i + 1) * self.nu].to_vec()).collect()
    }
}

/// FOPTD step response at time `t` (see [`StepModel::from_first_order`]).
fn foptd_step(k: f64, tau: f64, theta: f64, t: f64) -> f64 {
    if t <= theta {
        0.0
    } else if tau == 0.0 {
        k
    } else {
        k * (1.0 - (-(t - theta) / tau).exp())
    }
}

/// Check an `ny × nu` matrix: shape, finiteness, entries `≥ lower`.
fn check_matrix(field: &'static str, m: &[Vec<f64>], ny: usize, nu: usize, lower: f64) -> Result<(), MpcError> {
    if m.len() != ny {
        return Err(MpcError::Dimension { field, expected: ny, got: m.len() });
    }
    for row in m {
        check_len(field, row, nu)?;
        if let Some(x) = row.iter().find(|x| !x.is_finite() || **x < lower) {
            return Err(MpcError::invalid(field, format!("entry {x} must be finite and ≥ {lower}")));
        }
    }
    Ok(())
}
