//! Identification of a plant's transfer functions from a plant test on its nonlinear model, by the
//! method of the reference book's chapter 7 (Rivera, in Luyben, *Practical Distillation Control*,
//! 1992; spec `shared/reference/control-rules-and-identification.md` §2):
//!
//! 1. **Test design** ([`design`]): the dominant time constant `τ_dom` of the chosen elements
//!    (the slowest eigenvalue of their exact linear model, or given) sets the PRBS clock period
//!    `T_cl = 2.8 τ_dom/α` (Eq. 7-8) and register length `N ≥ 2παβ/2.8` (Eq. 7-9); several inputs
//!    get delayed copies of one PRBS, `D = N T_cl/p > T_99` apart (Eq. 7-10), or independent
//!    generalized binary noise, or — for an ill-conditioned plant such as a high-purity column —
//!    independent signals along the input singular directions of a prior gain, scaled so that the
//!    low-gain direction moves the outputs as much as the high-gain one (Koung & MacGregor 1991).
//!    The prior is the exact linearization at the steady state: what a steady-state rating model
//!    gives before a test (Luyben's 1987 procedure, §2.7).
//! 2. **Plant test** ([`plant_test`]): the nonlinear model integrated from its steady state, the
//!    inputs held over each sample (zero-order hold), the outputs sampled with seeded white
//!    measurement noise of standard deviation σ per output; a second test with fresh signals and
//!    noise is the validation data.
//! 3. **Estimation** ([`estimate`]), per output on the deviations from the pre-test steady state
//!    (multi-input, single-output models): FIR by ridge least squares (QR of the stacked
//!    regression, Eq. 7-50/7-51), ARX with its order chosen by Akaike's criterion (Eq. 7-31/7-38),
//!    and output error (Eq. 7-34/7-66) by Levenberg–Marquardt from the ARX fit.
//! 4. **Validation** on the fresh data: fit %, residual whiteness and residual–input
//!    cross-correlation against their 95 % bounds (§2.8). The reported gain is that of the model
//!    structure with the best validation fit over the outputs.

mod closed_loop;
mod design;
mod estimate;
mod plant_test;
mod request;
mod verdict;

use faer::Mat;
use plantwide_analysis::linear::Linearization;
use plantwide_analysis::measures::{rga, rows};
use plantwide_analysis::select::{Signal, SignalLabel};
use plantwide_flowsheet::Plant;
use serde::Serialize;

pub use closed_loop::select_driven;
pub use design::{Design, Directions, TestDesign};
pub use estimate::{ModelSummary, OutputValidation};
pub use request::{Identified, IdentifyRequest, study};
pub use verdict::{Criterion, MAX_GAIN_ERROR, MAX_RGA_ERROR, MIN_FIT, NEGLIGIBLE, Verdict, number};

/// Settings of an identification; `None` takes the default described on each field.
#[derive(Debug, Clone, PartialEq)]
pub struct IdentifySettings {
    /// How the inputs are moved.
    pub design: Design,
    /// Measurement-noise standard deviation per output (SI), or one for all; empty: none.
    pub noise: Vec<f64>,
    /// Seed of the test signals and the noise.
    pub seed: u64,
    /// Length of the estimation test \[s\] (default: four PRBS periods); the validation test lasts
    /// one period (at least three settling times).
    pub duration: Option<f64>,
    /// Sample time \[s\] (default `τ_dom/20`).
    pub sample_time: Option<f64>,
    /// Largest move of each input (SI; default 1 % of its steady value, or 1 SI unit at 0).
    pub amplitude: Option<Vec<f64>>,
    /// Dominant time constant \[s\] (default: the slowest of the elements' exact linear model).
    pub tau_dom: Option<f64>,
    /// Closed-loop speed factor α of Eq. 7-7 (default 2).
    pub alpha: f64,
    /// Settling factor β of Eq. 7-7 (default 3, 95 % settling).
    pub beta: f64,
    /// Test in closed loop by setpoint injection (the inputs are driven by PID loops).
    pub closed_loop: bool,
    /// Directional design: output amplitude of the high-gain directions relative to the
    /// low-gain one's (Koung & MacGregor: 1). Default 2: the elements of `G(0)` are dominated by
    /// the high-gain direction, which costs only `~σ_min/σ_max` of the input amplitude; on column A
    /// (σ = 1e-4, 8 seeds) it brings the largest element error from 5.7 % to 4.1 %, while 6
    /// drives the outputs far enough to bias them by the column's nonlinearity (up to 9 %).
    pub high_gain_boost: f64,
}

impl Default for IdentifySettings {
    fn default() -> Self {
        IdentifySettings {
            design: Design::Directional,
            noise: Vec::new(),
            seed: 1,
            duration: None,
            sample_time: None,
            amplitude: None,
            tau_dom: None,
            alpha: 2.0,
            beta: 3.0,
            closed_loop: false,
            high_gain_boost: 2.0,
        }
    }
}

/// Why an identification could not be done.
#[derive(Debug, Clone, thiserror::Error)]
pub enum IdentifyError {
    /// A request that cannot be met (too short a test, a bad option); the message says what to give.
    #[error("{0}")]
    Request(String),
    /// An input whose test moves would leave its physical range.
    #[error(
        "input `{input}` cannot move by ±{amplitude:.4e} (SI) about {value:.6e}: {why}; give a smaller `amplitude`"
    )]
    CannotMove {
        /// Input path.
        input: String,
        /// The test's largest move (SI).
        amplitude: f64,
        /// Its steady value (SI).
        value: f64,
        /// The range check's reason.
        why: String,
    },
    /// The prior gain is singular: no input direction moves the outputs in its low-gain direction.
    #[error(
        "the directional design needs a regular prior gain: G(0) of these inputs and outputs is singular \
         (smallest singular value of the amplitude-scaled gain {smallest:.1e}); remove a dependent output or \
         input, or use `design` prbs"
    )]
    SingularDesign {
        /// Smallest singular value of the prior gain scaled by the amplitudes.
        smallest: f64,
    },
    /// The linear model at the steady state could not be formed.
    #[error("linear model at the steady state: {0}")]
    Linear(Box<plantwide_analysis::AnalysisError>),
    /// The test signals or the fits could not be computed.
    #[error("{0}")]
    Estimation(String),
    /// The plant could not be integrated through the test.
    #[error(transparent)]
    Simulation(Box<plantwide_solve::dynamic::SessionError>),
}

impl IdentifyError {
    /// True for problems of the request (exit code 1), false for numerical failures (exit code 2).
    pub fn is_user_error(&self) -> bool {
        match self {
            IdentifyError::Request(_) | IdentifyError::CannotMove { .. } | IdentifyError::SingularDesign { .. } => true,
            IdentifyError::Linear(e) => e.is_user_error(),
            IdentifyError::Estimation(_) | IdentifyError::Simulation(_) => false,
        }
    }
}

impl From<plantwide_analysis::AnalysisError> for IdentifyError {
    fn from(e: plantwide_analysis::AnalysisError) -> Self {
        IdentifyError::Linear(Box::new(e))
    }
}

/// The exact linearization's gains, for comparison, and the identified gains' errors against them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExactComparison {
    /// `G(0) = −C J⁻¹ B` at the steady state (display units).
    pub gain: Vec<Vec<f64>>,
    /// Its relative gain array (square or not: `G ∘ (G⁺)ᵀ`).
    pub rga: Option<Vec<Vec<f64>>>,
    /// `|Ĝ_ij − G_ij| / |G_ij|` per element.
    pub gain_relative_error: Vec<Vec<f64>>,
    /// `|λ̂_11 − λ_11| / |λ_11|`.
    pub rga11_relative_error: Option<f64>,
}

/// The validation of the chosen model structure on fresh data.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ValidationReport {
    /// The structure whose gains are reported (`fir`, `arx`, `oe`).
    pub model: String,
    /// Per output: fit %, whiteness and cross-correlation of its residuals.
    pub outputs: Vec<OutputValidation>,
}

/// An identification: the `identify --json` document.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Identification {
    /// Inputs, with their display units.
    pub inputs: Vec<SignalLabel>,
    /// Outputs, with their display units.
    pub outputs: Vec<SignalLabel>,
    /// Identified steady-state gains (display units), outputs × inputs.
    pub gain: Vec<Vec<f64>>,
    /// Relative gain array of the identified gains (`None` when they are singular).
    pub rga: Option<Vec<Vec<f64>>>,
    /// Every fitted model: per output and structure, its orders, gains and validation.
    pub models: Vec<ModelSummary>,
    /// The chosen structure's validation.
    pub validation: ValidationReport,
    /// The test design.
    pub design: TestDesign,
    /// The exact linearization, for comparison.
    pub exact: ExactComparison,
    /// Whether the model can be used, criterion by criterion.
    pub verdict: Verdict,
    /// The measured validation outputs (deviations from the steady state, SI, with the noise),
    /// sampled every `design.sample_time`, for plots.
    #[serde(skip)]
    pub measured: Vec<Vec<f64>>,
    /// The chosen structure's step responses as a model for a model predictive controller
    /// (`"model": {"file": …}`; SI, sampled every `design.sample_time`).
    #[serde(skip)]
    pub step_model: plantwide_solve::dynamic::StepModelFile,
}

/// Display gains: `dy/du · f_u / f_y`.
fn display_gain(g: &Mat<f64>, inputs: &[Signal], outputs: &[Signal]) -> Vec<Vec<f64>> {
    (0..outputs.len())
        .map(|i| (0..inputs.len()).map(|j| g[(i, j)] * inputs[j].factor / outputs[i].factor).collect())
        .collect()
}

fn comparison(exact: &Mat<f64>, identified: &Mat<f64>, inputs: &[Signal], outputs: &[Signal]) -> ExactComparison {
    let gain_relative_error = (0..exact.nrows())
        .map(|i| (0..exact.ncols()).map(|j| ((identified[(i, j)] - exact[(i, j)]) / exact[(i, j)]).abs()).collect())
        .collect();
    let rga_exact = rga(exact.as_ref()).ok();
    let rga11_relative_error = match (&rga_exact, rga(identified.as_ref()).ok()) {
        (Some(a), Some(b)) => Some(((b[(0, 0)] - a[(0, 0)]) / a[(0, 0)]).abs()),
        _ => None,
    };
    ExactComparison {
        gain: display_gain(exact, inputs, outputs),
        rga: rga_exact.map(|r| rows(r.as_ref())),
        gain_relative_error,
        rga11_relative_error,
    }
}

/// Identify the gains and models from `inputs` to `outputs` of `plant` at its steady state `x`
/// (inputs `u`), by a plant test on the nonlinear model designed and fitted as [`IdentifySettings`]
/// asks.
///
/// # Errors
/// [`IdentifyError`]: a request that cannot be met (exit 1) or a numerical failure (exit 2).
pub fn identify(
    plant: &Plant,
    x: &[f64],
    u: &[f64],
    inputs: &[Signal],
    outputs: &[Signal],
    settings: &IdentifySettings,
) -> Result<Identification, IdentifyError> {
    check_settings(settings, outputs.len())?;
    let (ii, oo): (Vec<usize>, Vec<usize>) =
        (inputs.iter().map(|s| s.index).collect(), outputs.iter().map(|s| s.index).collect());
    let lin = Linearization::new(plant, x, u);
    let (exact, closed) = if settings.closed_loop {
        let l = closed_loop::loops(plant, x, inputs, &oo)?;
        (l.gain.clone(), Some(l))
    } else {
        (lin.steady_gain(&ii, &oo)?, None)
    };
    let tau_dom = match (settings.tau_dom, &closed) {
        (Some(t), _) => t,
        (None, None) => slowest_time_constant(&lin, &ii, &oo)?,
        (None, Some(l)) => {
            let manual = crate::tune::loops::in_manual(plant, x, &l.loops);
            let ops: Vec<usize> = l.loops.iter().map(|l| l.op_manual).collect();
            slowest_time_constant(&Linearization::new(&manual, x, &manual.input_values()), &ops, &oo)?
        }
    };
    let test = design::design(plant, u, inputs, &exact, tau_dom, settings)?;
    let noise = per_output_noise(settings, outputs.len());
    let ts = test.design.sample_time;
    let amplitude: Vec<f64> = test.design.amplitude.iter().zip(inputs).map(|(a, s)| a * s.factor).collect();

    let (probe, est_moves, val_moves) = match &closed {
        None => {
            let resolve = Some(plant_test::resolve(&exact, &amplitude));
            (
                plant_test::Probe { set: ii, outputs: oo, measured_inputs: None, resolve },
                test.estimation,
                test.validation,
            )
        }
        Some(l) => {
            let ops = l.loops.iter().map(|l| l.op).collect();
            let probe =
                plant_test::Probe { set: l.setpoints.clone(), outputs: oo, measured_inputs: Some(ops), resolve: None };
            let est = closed_loop::setpoint_moves(&l.gain_pv, &test.estimation);
            (probe, est, closed_loop::setpoint_moves(&l.gain_pv, &test.validation))
        }
    };
    let estimation = plant_test::run(plant, x, &probe, &est_moves, &noise, (ts, settings.seed))?;
    let validation = plant_test::run(plant, x, &probe, &val_moves, &noise, (ts, settings.seed ^ 0x5eed))?;
    let mut fits = estimate::fit_all(&estimation, &validation, &test.design, inputs, outputs)?;
    let reference = verdict::Reference { exact: &exact, amplitude: &amplitude, inputs, outputs };
    let best = verdict::choose(&reference, &fits);
    let verdict = verdict::judge(&reference, &fits.iter().map(|f| &f[best]).collect::<Vec<_>>());
    let models = estimate::summaries(&fits, inputs, outputs, &|i, s| reference.output_passes(i, &fits[i][s]));
    let chosen: Vec<estimate::Fitted> = fits.iter_mut().map(|f| f.swap_remove(best)).collect();
    let gain = Mat::from_fn(outputs.len(), inputs.len(), |i, j| chosen[i].gain[j]);
    let step: Vec<Vec<Vec<f64>>> = chosen.iter().map(|f| f.step.clone()).collect();
    Ok(Identification {
        inputs: inputs.iter().map(Signal::label).collect(),
        outputs: outputs.iter().map(Signal::label).collect(),
        gain: display_gain(&gain, inputs, outputs),
        rga: rga(gain.as_ref()).ok().map(|r| rows(r.as_ref())),
        models,
        validation: ValidationReport {
            model: verdict.model.clone(),
            outputs: chosen.into_iter().map(|f| f.validation).collect(),
        },
        design: test.design,
        exact: comparison(&exact, &gain, inputs, outputs),
        verdict,
        measured: validation.y,
        step_model: step_model(&step, ts, inputs, outputs)?,
    })
}

/// The step responses (per output, per input) as a step-response model file.
fn step_model(
    step: &[Vec<Vec<f64>>],
    ts: f64,
    inputs: &[Signal],
    outputs: &[Signal],
) -> Result<plantwide_solve::dynamic::StepModelFile, IdentifyError> {
    let (ny, nu) = (outputs.len(), inputs.len());
    let n = step.first().and_then(|s| s.first()).map_or(0, Vec::len);
    let steps = (0..n).map(|k| (0..ny * nu).map(|e| step[e / nu][e % nu][k]).collect()).collect();
    let model =
        plantwide_mpc::StepModel::new(ts, ny, nu, steps).map_err(|e| IdentifyError::Estimation(e.to_string()))?;
    Ok(plantwide_solve::dynamic::StepModelFile {
        inputs: inputs.iter().map(|s| s.path.clone()).collect(),
        outputs: outputs.iter().map(|s| s.path.clone()).collect(),
        model,
    })
}

fn check_settings(s: &IdentifySettings, n_outputs: usize) -> Result<(), IdentifyError> {
    let bad = |what: &str| Err(IdentifyError::Request(what.to_string()));
    if !(s.alpha.is_finite() && s.alpha > 0.0) {
        return bad("α (closed-loop speed factor) must be > 0");
    }
    if !(s.high_gain_boost.is_finite() && s.high_gain_boost > 0.0) {
        return bad("`high_gain_boost` must be > 0 (1: equal output amplitude in every direction)");
    }
    if !(s.beta.is_finite() && s.beta >= 1.0) {
        return bad("β (settling factor) must be ≥ 1 (3 for 95 % settling)");
    }
    if s.noise.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
        return bad("every σ of `noise` must be a finite number ≥ 0");
    }
    if s.noise.len() > 1 && s.noise.len() != n_outputs {
        return Err(IdentifyError::Request(format!(
            "`noise` gives {} values for {n_outputs} outputs: give one σ for all or one per output",
            s.noise.len()
        )));
    }
    for (what, v) in [("`duration`", s.duration), ("`sample_time`", s.sample_time), ("`tau_dom`", s.tau_dom)] {
        if v.is_some_and(|v| !(v.is_finite() && v > 0.0)) {
            return Err(IdentifyError::Request(format!("{what} must be > 0")));
        }
    }
    Ok(())
}

fn per_output_noise(s: &IdentifySettings, n: usize) -> Vec<f64> {
    match s.noise.as_slice() {
        [] => vec![0.0; n],
        [one] => vec![*one; n],
        many => many.to_vec(),
    }
}

/// The slowest time constant \[s\] of the exact linear model from `inputs` to `outputs`.
fn slowest_time_constant(lin: &Linearization, inputs: &[usize], outputs: &[usize]) -> Result<f64, IdentifyError> {
    let ss = lin.state_space(inputs, outputs)?;
    let taus = ss.time_constants()?;
    taus.first().copied().filter(|t| t.is_finite() && *t > 0.0).ok_or_else(|| {
        IdentifyError::Request("the elements have no stable time constant to size the test by; give `tau_dom`".into())
    })
}
