//! Model predictive control: dynamic matrix control (Cutler & Ramaker 1980; QDMC, Garcia &
//! Morshedi 1986) of several controlled variables (CVs) by several manipulated variables (MVs),
//! executed every `sample_time` by the dynamic driver, which solves its quadratic program with
//! clarabel ([`plantwide_mpc::Dmc`]).
//!
//! At each sample the controller minimizes over the next `control_horizon` moves `ΔU`
//! `Σ_{l=1..P} Σ_i q_i (r_i − ŷ_i(k+l))² + Σ_{l<M} Σ_j r_j Δu_j(k+l)²` (+ the soft-limit penalty),
//! with `q_i = weight_i/scale_i²`, `r_j = move_weight_j/scale_j²` (the QP is posed in the scaled
//! variables `y/scale`, `u/scale`, so that its data are of order one), subject to the MVs' hard limits
//! `min ≤ u ≤ max`, `|Δu| ≤ rate` per sample, and the CVs' soft limits `min − ε ≤ ŷ ≤ max + ε`
//! (ε ≥ 0 penalized by `soft_weight · max q_i`, so the QP stays feasible). The prediction is the step-response
//! model plus the measured offset `d = y − ŷ(k|k−1)` held over the horizon (offset-free for a
//! constant disturbance), and the first move is applied, held until the next sample.
//!
//! The model is a step response from the MVs to the CVs, of `model_length` samples: by default
//! measured by step tests on the nonlinear plant at its steady state (each MV moved `± step`
//! in turn, the rest of the plant as the file has it, central differences), or read from a file
//! (`{"file": "model.json"}`, written by `plantwide identify --report`).
//!
//! In the DAE the controller holds its outputs: `op_j = mv_j`, `mv_j` inputs of its own that the
//! driver sets at each sample (at a steady state the MVs stay at the file's values); `sp_i` are
//! the CVs' setpoints as inputs a scenario may step (`<mpc>.sp1`, …). Outputs `op`, `op2`, … drive
//! the MVs in the order of `mvs`.

use plantwide_mpc::Settings;
use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::ControllerLinks;
use crate::{BuildCx, FieldError, InputSpec, Scalar, SignalSpec, UnitIo, UnitModel, VarSpec};

/// A controlled variable of a model predictive controller.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MpcCv {
    /// Variable path, e.g. `"column.x[41][light]"`.
    pub pv: String,
    /// Setpoint (input `sp<k>`).
    pub sp: QuantityValue,
    /// Weight on `((r − ŷ)/scale)²` (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weight: Option<f64>,
    /// Scale of the errors (default 1 SI unit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<QuantityValue>,
    /// Soft lower limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<QuantityValue>,
    /// Soft upper limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<QuantityValue>,
}

/// A manipulated variable of a model predictive controller.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MpcMv {
    /// Driven input, e.g. `"column.reflux"`.
    pub output: String,
    /// Move suppression: weight on `(Δu/scale)²` per move (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub move_weight: Option<f64>,
    /// Scale of the moves (default 1 SI unit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<QuantityValue>,
    /// Hard lower limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<QuantityValue>,
    /// Hard upper limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<QuantityValue>,
    /// Largest move per sample (hard).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate: Option<QuantityValue>,
    /// Step of the model's step test (default 0.01 % of the steady value, or of `scale` at 0: a
    /// simulation has no noise to rise above, and a high-purity column is far from linear over 1 %).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<QuantityValue>,
}

/// Where the step-response model comes from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum MpcModelSource {
    /// `"step_test"`: step tests on the nonlinear plant at its steady state.
    Builtin(BuiltinModel),
    /// `{"file": "model.json"}`: a step-response model file (relative to the flowsheet's folder).
    File {
        /// The file.
        file: String,
    },
}

impl Default for MpcModelSource {
    fn default() -> Self {
        MpcModelSource::Builtin(BuiltinModel::StepTest)
    }
}

/// A model the controller measures itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum BuiltinModel {
    /// Each MV stepped `± step` in turn on the nonlinear plant at its steady state, central
    /// differences of the CVs sampled every `sample_time`.
    StepTest,
}

/// Flowsheet description of a model predictive controller.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MpcConfig {
    /// Controlled variables.
    pub cvs: Vec<MpcCv>,
    /// Manipulated variables (driven inputs).
    pub mvs: Vec<MpcMv>,
    /// Execution period (e.g. `"2 min"`).
    pub sample_time: QuantityValue,
    /// Prediction horizon P [samples].
    pub prediction_horizon: usize,
    /// Control horizon M [samples], ≤ P.
    pub control_horizon: usize,
    /// Step-response model (default `"step_test"`).
    #[serde(default)]
    pub model: MpcModelSource,
    /// Samples of the step-response model N (default 2P); beyond, the response is held settled.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_length: Option<usize>,
    /// Penalty on the soft-limit slack ε relative to the largest CV weight: the QP adds
    /// `ρε + ½ρε²` with `ρ = soft_weight · max_i q_i` in the scaled variables (default 1). The
    /// slack is one per limit, shared by the horizon. Measured on column A (feed +20 %, boilup at
    /// its limit): 1–3 hold the limits to within a few 1e-4; 100 and more make the controller
    /// back off the saturated boilup and lose both qualities (the prediction's early, uncontrollable
    /// violation sets the slack) — keep it small.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub soft_weight: Option<f64>,
}

impl super::ControllerConfig for MpcConfig {
    fn paths(&self) -> super::ControllerPaths {
        super::ControllerPaths {
            measured: self.cvs.iter().enumerate().map(|(k, c)| (format!("cvs[{k}].pv"), c.pv.clone())).collect(),
            driven: self.mvs.iter().enumerate().map(|(k, m)| (format!("mvs[{k}].output"), m.output.clone())).collect(),
        }
    }
}

/// Largest horizon and model length accepted (samples): a bound on what a file can allocate.
pub const MAX_HORIZON: usize = 2000;

/// What the driver runs: the controller's settings, its QP in scaled variables `y/scale` and
/// `u/scale` (weights as given, limits divided by the scales), the rest in SI.
#[derive(Debug, Clone, PartialEq)]
pub struct MpcPlan {
    /// Execution period \[s\].
    pub sample_time: f64,
    /// Horizons, weights (scaled) and limits (SI).
    pub settings: Settings,
    /// Where the model comes from.
    pub model: MpcModelSource,
    /// Samples of the step-response model.
    pub model_length: usize,
    /// Step-test size per MV (SI).
    pub steps: Vec<f64>,
    /// Setpoints per CV (SI), the file's.
    pub setpoints: Vec<f64>,
    /// Scale of each CV (SI): the QP works in `y/scale`.
    pub cv_scales: Vec<f64>,
    /// Scale of each MV (SI): the QP works in `u/scale`.
    pub mv_scales: Vec<f64>,
}

fn opt(cx: &mut BuildCx<'_>, field: String, v: &Option<QuantityValue>, dim: Dimension, default: f64) -> f64 {
    v.as_ref().map_or(default, |q| cx.quantity(&field, q, dim))
}

fn weight(cx: &mut BuildCx<'_>, field: String, w: Option<f64>) -> f64 {
    let w = w.unwrap_or(1.0);
    if !(w.is_finite() && w >= 0.0) {
        cx.error(&field, format!("a weight must be a finite number ≥ 0 (got {w})"));
    }
    w.max(0.0)
}

fn scale(cx: &mut BuildCx<'_>, field: String, v: &Option<QuantityValue>, dim: Dimension) -> f64 {
    v.as_ref().map_or(1.0, |q| cx.positive(&field, q, dim))
}

/// Largest dense prediction matrix `(P·n_cv) × (M·n_mv)` and step model `N·n_cv·n_mv` accepted
/// (entries): a bound on what a file can make the controller allocate (80 MB each).
pub const MAX_ENTRIES: usize = 10_000_000;

/// The horizons and model length, checked.
fn horizons(c: &MpcConfig, cx: &mut BuildCx<'_>) -> (usize, usize, usize) {
    let (p, m) = (c.prediction_horizon, c.control_horizon);
    if !(1..=MAX_HORIZON).contains(&p) {
        cx.error("prediction_horizon", format!("must be 1 … {MAX_HORIZON} samples (got {p})"));
    }
    if m < 1 || m > p {
        cx.error("control_horizon", format!("must be 1 … prediction_horizon = {p} samples (got {m})"));
    }
    let n = c.model_length.unwrap_or(p.saturating_mul(2));
    if !(1..=MAX_HORIZON).contains(&n) {
        cx.error("model_length", format!("must be 1 … {MAX_HORIZON} samples (got {n})"));
    }
    let (ny, nu) = (c.cvs.len(), c.mvs.len());
    if p.saturating_mul(ny).saturating_mul(m).saturating_mul(nu) > MAX_ENTRIES {
        cx.error(
            "prediction_horizon",
            format!("P·n_cv × M·n_mv = {p}·{ny} × {m}·{nu} exceeds {MAX_ENTRIES} entries: shorten the horizons"),
        );
    }
    if n.saturating_mul(ny).saturating_mul(nu) > MAX_ENTRIES {
        cx.error("model_length", format!("N·n_cv·n_mv = {n}·{ny}·{nu} exceeds {MAX_ENTRIES} entries"));
    }
    (p.clamp(1, MAX_HORIZON), m.clamp(1, p.clamp(1, MAX_HORIZON)), n.clamp(1, MAX_HORIZON))
}

/// What a controller's CVs and MVs are in the plant: dimensions, the MVs' file values and the
/// physical ranges (SI) of both, in the order of `cvs` and `mvs`.
#[derive(Debug, Clone, Copy)]
pub struct Channels<'a> {
    /// Dimension of each CV.
    pub cv_dims: &'a [Dimension],
    /// Physical range of each CV (its variable's bounds).
    pub cv_ranges: &'a [(f64, f64)],
    /// Dimension and file value of each MV's driven input.
    pub mvs: &'a [(Dimension, f64)],
    /// Physical range of each MV's driven input.
    pub mv_ranges: &'a [(f64, f64)],
}

impl Channels<'_> {
    fn cv_range(&self, k: usize) -> (f64, f64) {
        self.cv_ranges.get(k).copied().unwrap_or((f64::NEG_INFINITY, f64::INFINITY))
    }
    fn mv_range(&self, k: usize) -> (f64, f64) {
        self.mv_ranges.get(k).copied().unwrap_or((f64::NEG_INFINITY, f64::INFINITY))
    }
}

/// Report `field` = `v` (SI) outside `range`, `what` naming whose range it is.
fn within(cx: &mut BuildCx<'_>, field: String, v: f64, range: (f64, f64), dim: Dimension, what: &str) {
    if let Some(why) = crate::limits::outside(v, range, dim) {
        cx.error(&field, format!("{why}; the range is {what}"));
    }
}

/// The controller's plan in SI from its description and its channels; problems are reported on
/// `cx`. A setpoint must lie in its CV's physical range and a hard MV limit in its input's; an MV
/// without a limit is held to its input's range (a flow is never moved below zero).
pub fn plan(c: &MpcConfig, cx: &mut BuildCx<'_>, ch: Channels<'_>) -> MpcPlan {
    let (cv_dims, mvs) = (ch.cv_dims, ch.mvs);
    if c.cvs.is_empty() || c.mvs.is_empty() {
        cx.error(
            if c.cvs.is_empty() { "cvs" } else { "mvs" },
            "give at least one controlled and one manipulated variable",
        );
    }
    let sample_time = cx.positive("sample_time", &c.sample_time, Dimension::TIME);
    let (p, m, n) = horizons(c, cx);
    let (mut q, mut y_min, mut y_max, mut setpoints) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut cv_scales, mut mv_scales) = (Vec::new(), Vec::new());
    for (k, (cv, &dim)) in c.cvs.iter().zip(cv_dims).enumerate() {
        let s = scale(cx, format!("cvs[{k}].scale"), &cv.scale, dim);
        cv_scales.push(s);
        q.push(weight(cx, format!("cvs[{k}].weight"), cv.weight));
        let sp = cx.quantity(&format!("cvs[{k}].sp"), &cv.sp, dim);
        within(cx, format!("cvs[{k}].sp"), sp, ch.cv_range(k), dim, "the controlled variable's");
        setpoints.push(sp);
        y_min.push(opt(cx, format!("cvs[{k}].min"), &cv.min, dim, f64::NEG_INFINITY) / s);
        y_max.push(opt(cx, format!("cvs[{k}].max"), &cv.max, dim, f64::INFINITY) / s);
    }
    let (mut r, mut u_min, mut u_max, mut du_max, mut steps) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (k, (mv, &(dim, value))) in c.mvs.iter().zip(mvs).enumerate() {
        let s = scale(cx, format!("mvs[{k}].scale"), &mv.scale, dim);
        mv_scales.push(s);
        r.push(weight(cx, format!("mvs[{k}].move_weight"), mv.move_weight));
        let (lo, hi) = ch.mv_range(k);
        let (min, max) =
            (opt(cx, format!("mvs[{k}].min"), &mv.min, dim, lo), opt(cx, format!("mvs[{k}].max"), &mv.max, dim, hi));
        within(cx, format!("mvs[{k}].min"), min, (lo, hi), dim, "that of the input it drives");
        within(cx, format!("mvs[{k}].max"), max, (lo, hi), dim, "that of the input it drives");
        u_min.push(min / s);
        u_max.push(max / s);
        du_max.push(mv.rate.as_ref().map_or(f64::INFINITY, |q| cx.positive(&format!("mvs[{k}].rate"), q, dim)) / s);
        let default_step = 1e-4 * if value != 0.0 { value.abs() } else { s };
        steps.push(mv.step.as_ref().map_or(default_step, |q| cx.positive(&format!("mvs[{k}].step"), q, dim)));
    }
    let relative = c.soft_weight.unwrap_or(1.0);
    if !(relative.is_finite() && relative > 0.0) {
        cx.error("soft_weight", format!("must be a finite number > 0 (got {relative})"));
    }
    let q_max = q.iter().copied().fold(0.0, f64::max);
    let soft_weight = if q_max > 0.0 { relative.abs() * q_max } else { relative.abs().max(f64::MIN_POSITIVE) };
    let settings = Settings {
        prediction_horizon: p,
        control_horizon: m,
        output_weights: q,
        move_weights: r,
        u_min,
        u_max,
        du_max,
        y_min,
        y_max,
        soft_weight,
    };
    MpcPlan { sample_time, settings, model: c.model.clone(), model_length: n, steps, setpoints, cv_scales, mv_scales }
}

/// A model predictive controller in the DAE: outputs held at the driver's moves.
#[derive(Debug, Clone)]
pub struct Mpc {
    cvs: Vec<String>,
    /// Per MV: dimension and file value (SI).
    mvs: Vec<(Dimension, f64)>,
    cv_dims: Vec<Dimension>,
    setpoints: Vec<f64>,
    /// Physical range of each input, in [`UnitModel::inputs`] order (the MVs', then the CVs').
    ranges: Vec<(f64, f64)>,
}

impl Mpc {
    /// Build from the flowsheet description and the resolved links.
    pub fn build(c: &MpcConfig, mut cx: BuildCx<'_>, links: &ControllerLinks) -> Result<Mpc, Vec<FieldError>> {
        let channels = Channels {
            cv_dims: &links.measured_dims,
            cv_ranges: &links.measured_ranges,
            mvs: &links.driven,
            mv_ranges: &links.driven_ranges,
        };
        let plan = plan(c, &mut cx, channels);
        for (k, (mv, &(_, value))) in c.mvs.iter().zip(&links.driven).enumerate() {
            let s = plan.mv_scales.get(k).copied().unwrap_or(1.0);
            let (lo, hi) = (plan.settings.u_min[k] * s, plan.settings.u_max[k] * s);
            if value < lo || value > hi {
                cx.error(
                    &format!("mvs[{k}]"),
                    format!("`{}` starts at {value:.6e} (SI), outside its limits [{lo:.6e}, {hi:.6e}]", mv.output),
                );
            }
        }
        let cvs = c.cvs.iter().map(|cv| cv.pv.clone()).collect();
        let (mvs, cv_dims) = (links.driven.clone(), links.measured_dims.clone());
        let ranges =
            (0..mvs.len()).map(|k| channels.mv_range(k)).chain((0..cv_dims.len()).map(|k| channels.cv_range(k)));
        let ranges = ranges.collect();
        cx.finish(Mpc { cvs, mvs, cv_dims, setpoints: plan.setpoints, ranges })
    }
}

/// Name of output `k` (0-based): `op`, `op2`, … (the flowsheet's wiring of driven inputs).
fn output_name(k: usize) -> String {
    if k == 0 { "op".into() } else { format!("op{}", k + 1) }
}

impl UnitModel for Mpc {
    fn type_name(&self) -> &'static str {
        "mpc"
    }
    /// An MV input takes its driven input's range, a setpoint its CV's.
    fn input_range(&self, k: usize) -> Option<(f64, f64)> {
        self.ranges.get(k).copied()
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        self.mvs
            .iter()
            .enumerate()
            .map(|(k, &(dim, v))| VarSpec::algebraic(output_name(k), dim, v.abs().max(1e-6)))
            .collect()
    }
    fn inputs(&self) -> Vec<InputSpec> {
        let mv = self.mvs.iter().enumerate().map(|(k, &(dim, value))| InputSpec {
            name: format!("mv{}", k + 1),
            dim,
            value,
        });
        let sp = self.setpoints.iter().zip(&self.cv_dims).enumerate().map(|(k, (&value, &dim))| InputSpec {
            name: format!("sp{}", k + 1),
            dim,
            value,
        });
        mv.chain(sp).collect()
    }
    fn signals(&self) -> Vec<SignalSpec> {
        self.cvs.iter().enumerate().map(|(k, p)| SignalSpec { role: format!("cv{}", k + 1), path: p.clone() }).collect()
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        for (k, rk) in r.iter_mut().enumerate().take(self.mvs.len()) {
            *rk = io.var(k) - io.input(k);
        }
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        for (k, v) in own.iter_mut().enumerate() {
            *v = io.input(k);
        }
    }
}
