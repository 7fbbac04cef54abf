//! Model predictive control as the alternative to decentralized PI loops (Luyben (ed.), *Practical
//! Distillation Control*, 1992, ch. 6: "evaluating advanced control — predictive control vs PID
//! on a realistic model"): a `"type": "mpc"` controller on the CVs and MVs of a screening or a
//! scheme, judged on the same disturbance steps as the PI candidates.
//!
//! - **Gains**: the exact steady-state gains of the plant the controller sees (its MVs held, every
//!   other controller as the plant has it), CVs × MVs (SI), and their condition number — the
//!   sensitivity of a multivariable controller to model error grows with it (Skogestad &
//!   Postlethwaite 2005 §3.8); relative gains, the Niederlinski index and DIC are properties of a
//!   decentralized pairing and do not apply.
//! - **Closed-loop runs**: each disturbance stepped on the nonlinear plant from its steady state
//!   with the controller executing every sample (its QP solved by clarabel), as long as the PI
//!   candidates' runs; the figures of each CV against its setpoint, the MVs that reached a hard
//!   limit, and the QP's statuses and solve times per run ([`MpcLog`]).

use plantwide_analysis::linear::Linearization;
use plantwide_analysis::measures::{condition_number, rows, svd};
use plantwide_flowsheet::{Plant, VarPath};
use plantwide_model::controllers::mpc::MpcConfig;
use plantwide_model::registry::ControllerSpec;
use plantwide_solve::dynamic::{MpcLog, mv_limits};
use plantwide_units::{Dimension, QuantityValue};
use serde::{Deserialize, Serialize};

use plantwide_solve::{NewtonSettings, SolveError, steady_state};

use super::dynamic::{DynamicResult, Limited, run, unfinished_run};
use super::{OpenPlant, PairingRequest};
use crate::screen::ScreenError;

/// A model predictive controller judged.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MpcAlternative {
    /// Controller name.
    pub controller: String,
    /// Its controlled variables.
    pub cvs: Vec<String>,
    /// The inputs it drives.
    pub mvs: Vec<String>,
    /// Execution period \[s\].
    pub sample_time: f64,
    /// Prediction horizon \[samples\].
    pub prediction_horizon: usize,
    /// Control horizon \[samples\].
    pub control_horizon: usize,
    /// Steady-state gains of the plant it controls (its MVs held), CVs × MVs (SI).
    pub gain: Vec<Vec<f64>>,
    /// Condition number of `gain`.
    pub condition_number: Option<f64>,
    /// The disturbance runs (no loops, no detuning: `score` relative to the best alternative).
    pub dynamic: Option<DynamicResult>,
    /// What the controller did in each run that went through, in run order.
    pub qp: Vec<MpcLog>,
}

/// The model predictive controllers of `plant`: name and description.
pub fn controllers(plant: &Plant) -> Vec<(&String, &MpcConfig)> {
    plant
        .spec()
        .controllers
        .iter()
        .filter_map(|(n, c)| match c {
            ControllerSpec::Mpc(cfg) => Some((n, cfg)),
            _ => None,
        })
        .collect()
}

/// Judge controller `name` of `plant` at its steady state `x`: its gains and, with `duration`
/// and `r`'s disturbances, its runs. The runs record `r.cvs` (the controller's CVs, in the order
/// the alternatives share) and `r.record`.
///
/// # Errors
/// [`ScreenError::Analysis`] when the gains cannot be computed, [`ScreenError::Mpc`] when the
/// controller does not resolve; a run that stops is recorded as the result's `failure`.
pub fn assess_mpc(
    plant: &Plant,
    x: &[f64],
    name: &str,
    r: &PairingRequest,
    duration: Option<f64>,
) -> Result<MpcAlternative, ScreenError> {
    let Some(ControllerSpec::Mpc(cfg)) = plant.spec().controllers.get(name) else {
        return Err(ScreenError::Mpc { controller: name.into(), why: "not a model predictive controller".into() });
    };
    let bad = |why: String| ScreenError::Mpc { controller: name.into(), why };
    let cvs: Vec<String> = cfg.cvs.iter().map(|c| c.pv.clone()).collect();
    let mvs: Vec<String> = cfg.mvs.iter().map(|m| m.output.clone()).collect();
    let cv_vars: Vec<usize> =
        cvs.iter().map(|c| plant.var(c).ok_or_else(|| bad(format!("no variable `{c}`")))).collect::<Result<_, _>>()?;
    let own: Vec<usize> = (0..mvs.len())
        .map(|k| VarPath::mv(name, k))
        .map(|mv| plant.input(&mv).ok_or_else(|| bad(format!("no input `{mv}`"))))
        .collect::<Result<_, _>>()?;
    let analysis = |e| ScreenError::Analysis { structure: format!("controller {name}"), source: Box::new(e) };
    let g = Linearization::new(plant, x, &plant.input_values()).steady_gain(&own, &cv_vars).map_err(analysis)?;
    let condition = svd(g.as_ref()).ok().map(|d| condition_number(&d.singular_values));
    let limits = mv_limits(plant, name).map_err(|e| bad(e.reason))?;
    let ops: Vec<Limited> = mvs
        .iter()
        .zip(&limits)
        .enumerate()
        .map(|(k, (mv, &(lo, hi)))| Limited { op: VarPath::controller_output(name, k).into(), mv: mv.clone(), lo, hi })
        .collect();
    let sample_time = cfg.sample_time.to_si(Dimension::TIME).map_err(|e| bad(format!("sample_time: {e}")))?;
    let (dynamic, qp) = match duration {
        Some(d) if !r.disturbances.is_empty() => runs(plant, x, r, &ops, d),
        _ => (None, Vec::new()),
    };
    Ok(MpcAlternative {
        controller: name.into(),
        cvs,
        mvs,
        sample_time,
        prediction_horizon: cfg.prediction_horizon,
        control_horizon: cfg.control_horizon,
        gain: rows(g.as_ref()),
        condition_number: condition,
        dynamic,
        qp,
    })
}

/// Name of the controller a screening adds to the open plant.
pub const SCREEN_MPC: &str = "mpc";

/// The screening's model predictive controller, read at the request's edge: a controller
/// description whose `"type": "mpc"` and whose CVs' setpoints `sp` may be left out (a left-out
/// setpoint is the CV's steady value in the open plant, given when the plant is known).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "serde_json::Value", into = "serde_json::Value")]
pub struct ScreenMpc {
    /// The description; a left-out setpoint is 0 here until [`screen_mpc`] gives it.
    pub config: MpcConfig,
    /// Which CVs' setpoints were left out, by CV.
    pub steady_sp: Vec<bool>,
}

/// Why a screening's `mpc` is not a controller description.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct MpcDescriptionError(String);

impl TryFrom<serde_json::Value> for ScreenMpc {
    type Error = MpcDescriptionError;

    fn try_from(mut v: serde_json::Value) -> Result<Self, Self::Error> {
        let bad = |why: &str| MpcDescriptionError(why.to_string());
        let obj = v.as_object_mut().ok_or_else(|| bad("`mpc` must be one JSON object, a controller description"))?;
        match obj.remove("type") {
            None => {}
            Some(t) if t == "mpc" => {}
            Some(t) => return Err(MpcDescriptionError(format!("`mpc` must be of `\"type\": \"mpc\"`, not {t}"))),
        }
        let cvs = obj.get_mut("cvs").and_then(|c| c.as_array_mut()).ok_or_else(|| bad("`mpc` has no `cvs` list"))?;
        let mut steady_sp = Vec::with_capacity(cvs.len());
        for cv in cvs.iter_mut().filter_map(|c| c.as_object_mut()) {
            steady_sp.push(!cv.contains_key("sp"));
            cv.entry("sp").or_insert_with(|| 0.0.into());
        }
        let config = serde_json::from_value(v)
            .map_err(|e| MpcDescriptionError(format!("`mpc` is not an MPC controller description: {e}")))?;
        Ok(ScreenMpc { config, steady_sp })
    }
}

impl From<ScreenMpc> for serde_json::Value {
    /// The description as it was read: a left-out setpoint left out.
    fn from(m: ScreenMpc) -> Self {
        let mut v = serde_json::to_value(&m.config).unwrap_or_default();
        if let Some(cvs) = v.get_mut("cvs").and_then(|c| c.as_array_mut()) {
            for (cv, _) in cvs.iter_mut().zip(&m.steady_sp).filter(|(_, steady)| **steady) {
                cv.as_object_mut().map(|o| o.remove("sp"));
            }
        }
        v
    }
}

/// The screening's model predictive controller (`r.mpc`) on the open plant, judged on the runs of
/// the PI candidates (`duration`): its CVs must be the screening's CVs, its MVs among its MVs; a
/// CV's setpoint left out is its steady value in the open plant.
///
/// # Errors
/// [`ScreenError::Mpc`] for a description that does not fit the screening or does not build,
/// [`ScreenError::Steady`] when the plant with it has no steady state.
pub(crate) fn screen_mpc(
    open: &OpenPlant,
    r: &PairingRequest,
    description: &ScreenMpc,
    duration: Option<f64>,
) -> Result<MpcAlternative, ScreenError> {
    let bad = |why: String| ScreenError::Mpc { controller: SCREEN_MPC.into(), why };
    let mut config = description.config.clone();
    for (cv, &steady) in config.cvs.iter_mut().zip(&description.steady_sp) {
        if let (true, Some(v)) = (steady, open.plant.var(&cv.pv)) {
            cv.sp = QuantityValue::Number(open.x[v]);
        }
    }
    let mut paths: Vec<String> = config.cvs.iter().map(|c| c.pv.clone()).collect();
    let mut wanted = r.cvs.clone();
    paths.sort();
    wanted.sort();
    if paths != wanted {
        let paths: Vec<&str> = config.cvs.iter().map(|c| c.pv.as_str()).collect();
        return Err(bad(format!(
            "the `mpc` controller's CVs [{}] must be the screening's `cvs` [{}]",
            paths.join(", "),
            r.cvs.join(", ")
        )));
    }
    if let Some(m) = config.mvs.iter().find(|m| !r.mvs.contains(&m.output)) {
        return Err(bad(format!(
            "the `mpc` controller's MV `{}` is not one of the screening's `mvs` [{}]",
            m.output,
            r.mvs.join(", ")
        )));
    }
    let spec = ControllerSpec::Mpc(config);
    let edit = plantwide_flowsheet::StructureEdit::AddController { name: SCREEN_MPC.into(), spec: Box::new(spec) };
    let plant = open.plant.restructure(&[edit]).map_err(|e| bad(e.to_string()))?;
    let guess = crate::screen::column::mapped_guess(&open.plant, &open.x, &plant);
    let st = steady_state(&plant, &plant.input_values(), Some(&guess), &NewtonSettings::default())
        .map_err(|e| ScreenError::Steady { structure: "mpc".into(), source: Box::new(SolveError::from(e).into()) })?;
    assess_mpc(&plant, &st.x, SCREEN_MPC, r, duration.filter(|d| *d > 0.0))
}

/// Every disturbance run; a run that stops is marked as failed and the others go on.
fn runs(
    plant: &Plant,
    x: &[f64],
    r: &PairingRequest,
    ops: &[Limited],
    duration: f64,
) -> (Option<DynamicResult>, Vec<MpcLog>) {
    let mut result =
        DynamicResult { detuning_factor: None, loops: Vec::new(), runs: Vec::new(), score: f64::NAN, failure: None };
    let mut qp = Vec::new();
    for d in r.steps() {
        match run(plant, x, r, &d, duration, ops) {
            Ok((one, logs)) => {
                result.runs.push(one);
                qp.extend(logs);
            }
            Err(why) => {
                result.runs.push(unfinished_run(r, &d, why));
                result.score = f64::INFINITY;
            }
        }
    }
    (Some(result), qp)
}
