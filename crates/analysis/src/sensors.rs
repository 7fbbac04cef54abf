//! Temperature-sensor selection for a column (*Practical Distillation Control* ch. 8; Moore 1992).
//!
//! With the flowsheet's control structure as given (level loops closed, composition loops open),
//! the steady-state gains `K_ij = dT_i/du_j` of every stage temperature `column.T[i]` to the
//! manipulated inputs come from the linearization (`−C J⁻¹ B`). Then:
//! - **SVD criterion:** `K = U Σ Vᵀ`; for each singular direction `k` (one per input) the stage with
//!   the largest `|U_ik|` is the most sensitive and most independent place for a sensor; a stage
//!   already taken by a stronger direction is skipped.
//! - **Sensitivity criterion:** for each input, the stage with the largest `|K_ij|`.
//! - **Slope criterion:** the largest temperature difference between adjacent stages
//!   `|T_{i+1} − T_i|` — where the profile is steepest a temperature tracks composition best.
//!
//! Gains are in K per input display unit, so the SVD depends on those units; choose units in which
//! equal moves of the inputs are equally significant (e.g. both flows in kmol/min).
//!
//! # References
//! - C. F. Moore, *Selection of controlled and manipulated variables*, in W. L. Luyben (ed.),
//!   *Practical Distillation Control*, Van Nostrand Reinhold 1992, ch. 8.

use faer::Mat;
use plantwide_flowsheet::{Plant, VarPath};
use plantwide_model::Shape;

use crate::error::{AnalysisError, request};
use crate::linear::Linearization;
use crate::measures::svd;
use crate::select::Signal;

/// Result of the sensor-selection analysis.
#[derive(Debug, Clone)]
pub struct SensorSelection {
    /// Stage numbers (1 = reboiler), in order.
    pub stages: Vec<usize>,
    /// Stage temperatures \[K\].
    pub temperatures: Vec<f64>,
    /// `dT_i/du_j` [K per input display unit], stages × inputs.
    pub gains: Mat<f64>,
    /// Singular values of the gain matrix.
    pub singular_values: Vec<f64>,
    /// Left singular vectors (stages × directions).
    pub u: Mat<f64>,
    /// SVD criterion: the recommended stage for each singular direction.
    pub svd_stages: Vec<usize>,
    /// Sensitivity criterion: the stage with the largest gain for each input.
    pub sensitivity_stages: Vec<usize>,
    /// Slope criterion: the adjacent stages `(i, i + 1)` with the largest `|T_{i+1} − T_i|`, and it \[K\].
    pub slope: ((usize, usize), f64),
}

/// Analyse the stage temperatures `column.T[i]` of `column` at the steady state `(x, u)`.
pub fn select_temperature_sensors(
    plant: &Plant,
    x: &[f64],
    u: &[f64],
    column: &str,
    inputs: &[Signal],
) -> Result<SensorSelection, AnalysisError> {
    let mut stages = Vec::new();
    let mut vars = Vec::new();
    for stage in 1.. {
        match plant.var(VarPath::new(column, "T").index(stage)) {
            Some(i) => {
                stages.push(stage);
                vars.push(i);
            }
            None => break,
        }
    }
    if stages.len() < 2 {
        let columns: Vec<&str> =
            plant.blocks().iter().filter(|b| b.unit.shape() == Shape::Column).map(|b| b.name.as_str()).collect();
        return Err(request(format!(
            "{}: `{column}` has no stage temperatures `{column}.T[1]`, `{column}.T[2]`, …; columns in this flowsheet: {}",
            plant.file(),
            if columns.is_empty() { "none".to_string() } else { columns.join(", ") }
        )));
    }
    if inputs.is_empty() {
        return Err(request("sensor selection needs at least one manipulated input"));
    }
    let input_idx: Vec<usize> = inputs.iter().map(|s| s.index).collect();
    let si = Linearization::new(plant, x, u).steady_gain(&input_idx, &vars)?;
    let gains = Mat::from_fn(si.nrows(), si.ncols(), |i, j| si[(i, j)] * inputs[j].factor);
    let s = svd(gains.as_ref())?;
    let mut svd_stages: Vec<usize> = Vec::new();
    for k in 0..s.singular_values.len() {
        let best = (0..stages.len())
            .filter(|i| !svd_stages.contains(&stages[*i]))
            .max_by(|a, b| s.u[(*a, k)].abs().total_cmp(&s.u[(*b, k)].abs()))
            .map(|i| stages[i]);
        svd_stages.extend(best);
    }
    let sensitivity_stages = (0..inputs.len())
        .filter_map(|j| {
            (0..stages.len()).max_by(|a, b| gains[(*a, j)].abs().total_cmp(&gains[(*b, j)].abs())).map(|i| stages[i])
        })
        .collect();
    let temperatures: Vec<f64> = vars.iter().map(|&i| x[i]).collect();
    let slope = (0..stages.len() - 1)
        .map(|i| ((stages[i], stages[i + 1]), (temperatures[i + 1] - temperatures[i]).abs()))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or(((stages[0], stages[0]), 0.0));
    Ok(SensorSelection {
        stages,
        temperatures,
        gains,
        singular_values: s.singular_values,
        u: s.u,
        svd_stages,
        sensitivity_stages,
        slope,
    })
}
