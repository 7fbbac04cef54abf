//! A flowsheet's gains and linear model between chosen signals at its steady state: what
//! `plantwide gains` and `plantwide linearize` report, and what the Python face returns, computed
//! once here so that every face shows the same numbers.

use faer::{Mat, c64};
use plantwide_flowsheet::Plant;

use crate::error::AnalysisError;
use crate::linear::{Linearization, StateSpace};
use crate::perturb::{PerturbGains, PerturbSettings, perturb_gains};
use crate::report::{GainReport, ReportOptions};
use crate::select::Signal;

/// SI gains → display units: `G_ij · f_uj / f_yi`.
pub fn display_gain(si: &Mat<f64>, inputs: &[Signal], outputs: &[Signal]) -> Mat<f64> {
    Mat::from_fn(si.nrows(), si.ncols(), |i, j| si[(i, j)] * inputs[j].factor / outputs[i].factor)
}

/// How a flowsheet's steady-state gains are obtained.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GainMethod {
    /// Linearization at the steady state: `G(0) = −C J⁻¹ B`.
    Linear,
    /// Each input moved, the plant re-converged, central differences verified
    /// ([`perturb_gains`]); `step` is the relative step of the first attempt (default: chosen).
    Perturb {
        /// Relative step of the first attempt.
        step: Option<f64>,
    },
}

/// The gain report of a flowsheet, with how perturbation gains were verified.
#[derive(Debug, Clone)]
pub struct PlantGains {
    /// Gains in display units and every interaction measure.
    pub report: GainReport,
    /// The perturbation's steps and check (`GainMethod::Perturb` only).
    pub perturbation: Option<PerturbGains>,
}

/// The gains of `plant` at its steady state `(x, u)` from `inputs` to `outputs` by `method`, with
/// the measures `options` ask for.
pub fn plant_gains(
    plant: &Plant,
    (x, u): (&[f64], &[f64]),
    (inputs, outputs): (&[Signal], &[Signal]),
    method: GainMethod,
    options: &ReportOptions,
) -> Result<PlantGains, AnalysisError> {
    let ii: Vec<usize> = inputs.iter().map(|s| s.index).collect();
    let oo: Vec<usize> = outputs.iter().map(|s| s.index).collect();
    let (si, name, perturbation) = match method {
        GainMethod::Linear => (Linearization::new(plant, x, u).steady_gain(&ii, &oo)?, "linear", None),
        GainMethod::Perturb { step } => {
            let settings = PerturbSettings { step, ..PerturbSettings::default() };
            let p = perturb_gains(plant, x, u, &ii, &oo, &settings)?;
            (p.gain.clone(), "perturb", Some(p))
        }
    };
    let gain = display_gain(&si, inputs, outputs);
    let labels = |s: &[Signal]| s.iter().map(Signal::label).collect::<Vec<_>>();
    let report = GainReport::new(name, labels(inputs), labels(outputs), gain, options)?;
    Ok(PlantGains { report, perturbation })
}

/// A plant's state-space model at its steady state between chosen signals, with the values and
/// labels an export needs.
#[derive(Debug, Clone)]
pub struct PlantModel {
    /// `A, B, C, D` (SI, per second).
    pub model: StateSpace,
    /// `−C J⁻¹ B` (SI): the steady-state gain by the direct route, to check `D − C A⁻¹ B` against.
    pub direct_gain: Mat<f64>,
    /// Eigenvalues of `A` [1/s].
    pub eigenvalues: Vec<c64>,
    /// `(ω [rad/s], G(jω))` in display units at each frequency asked for.
    pub responses: Vec<(f64, Mat<c64>)>,
    /// State paths, one per row of `A`.
    pub states: Vec<String>,
    /// Steady values of the states (SI).
    pub state_values: Vec<f64>,
    /// Steady input values (SI).
    pub input_values: Vec<f64>,
    /// Steady output values (SI).
    pub output_values: Vec<f64>,
}

impl PlantModel {
    /// The model of `plant` at its steady state `(x, u)` from `inputs` to `outputs`, with `G(jω)`
    /// at `omegas` [rad/s].
    pub fn at(
        plant: &Plant,
        (x, u): (&[f64], &[f64]),
        (inputs, outputs): (&[Signal], &[Signal]),
        omegas: &[f64],
    ) -> Result<PlantModel, AnalysisError> {
        let ii: Vec<usize> = inputs.iter().map(|s| s.index).collect();
        let oo: Vec<usize> = outputs.iter().map(|s| s.index).collect();
        let lin = Linearization::new(plant, x, u);
        let model = lin.state_space(&ii, &oo)?;
        let direct_gain = lin.steady_gain(&ii, &oo)?;
        let eigenvalues = model.eigenvalues()?;
        let scale =
            |g: Mat<c64>| Mat::from_fn(g.nrows(), g.ncols(), |i, j| g[(i, j)] * (inputs[j].factor / outputs[i].factor));
        let responses =
            lin.frequency_response(&ii, &oo, omegas)?.into_iter().zip(omegas).map(|(g, &w)| (w, scale(g))).collect();
        Ok(PlantModel {
            states: model.states.iter().map(|&i| plant.vars()[i].path.clone()).collect(),
            state_values: model.states.iter().map(|&i| x[i]).collect(),
            input_values: ii.iter().map(|&i| u[i]).collect(),
            output_values: oo.iter().map(|&i| x[i]).collect(),
            model,
            direct_gain,
            eigenvalues,
            responses,
        })
    }
}
