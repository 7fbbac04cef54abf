//! Model predictive controllers in a run: each `"type": "mpc"` controller of the flowsheet gets a
//! [`Dmc`] built at the run's start, its step-response model measured by step tests on the
//! nonlinear plant at the starting state (or read from a file), and executes every `sample_time`:
//! it reads its CVs, solves its QP (clarabel) and holds its moves on its `mv<k>` inputs until the
//! next sample. The QP's status and solve time are logged per controller ([`MpcLog`]).

use std::collections::BTreeMap;

use plantwide_flowsheet::{Plant, VarPath};
use plantwide_model::BuildCx;
use plantwide_model::controllers::mpc::{Channels, MpcConfig, MpcModelSource, MpcPlan, plan};
use plantwide_model::registry::ControllerSpec;
use plantwide_mpc::{Dmc, StepModel};
use serde::{Deserialize, Serialize};

use super::session::Session;

/// What a model predictive controller did over a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MpcLog {
    /// Controller name.
    pub controller: String,
    /// Where its model came from (`step_test` or the file).
    pub model: String,
    /// The model's steady-state gain (its last step coefficient, SI), CVs × MVs.
    pub model_gain: Vec<Vec<f64>>,
    /// Executions.
    pub samples: usize,
    /// Executions per QP status (`Solved`, `AlmostSolved`, …).
    pub statuses: BTreeMap<String, usize>,
    /// Mean QP solve time \[s\].
    pub mean_solve_time: f64,
    /// Largest QP solve time \[s\].
    pub max_solve_time: f64,
    /// Mean interior-point iterations.
    pub mean_iterations: f64,
    /// Largest soft-limit slack used (in the CVs' scales).
    pub max_slack: f64,
    /// Executions with an input at a hard limit (within 1e-9 relative).
    pub samples_at_limit: usize,
}

/// A step-response model file: the model with the names of its inputs and outputs.
///
/// Read with every key checked (an unknown key is refused: a misspelt `"input"` must not leave the
/// channels unnamed) and its channels named, so that a controller can refuse a model of other
/// variables, or of its own in another order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawStepModelFile")]
pub struct StepModelFile {
    /// Input paths, in column order.
    pub inputs: Vec<String>,
    /// Output paths, in row order.
    pub outputs: Vec<String>,
    /// The model (SI, deviation variables).
    #[serde(flatten)]
    pub model: StepModel,
}

/// [`StepModelFile`] as written, every key known (serde cannot deny unknown keys through
/// `flatten`).
#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a step-response model: an object with inputs, outputs, ts, ny, nu and steps")]
struct RawStepModelFile {
    #[serde(default)]
    inputs: Vec<String>,
    #[serde(default)]
    outputs: Vec<String>,
    ts: f64,
    ny: usize,
    nu: usize,
    steps: Vec<Vec<f64>>,
}

impl TryFrom<RawStepModelFile> for StepModelFile {
    type Error = plantwide_mpc::MpcError;
    fn try_from(r: RawStepModelFile) -> Result<Self, Self::Error> {
        let model = StepModel { ts: r.ts, ny: r.ny, nu: r.nu, steps: r.steps };
        model.validate()?;
        Ok(StepModelFile { inputs: r.inputs, outputs: r.outputs, model })
    }
}

/// One controller in a run.
pub(super) struct MpcRun {
    pub name: String,
    pub dmc: Dmc,
    pub sample_time: f64,
    /// Next execution number (time = k · sample_time).
    pub next: u64,
    pub cvs: Vec<usize>,
    pub mv_inputs: Vec<usize>,
    pub sp_inputs: Vec<usize>,
    cv_scales: Vec<f64>,
    mv_scales: Vec<f64>,
    pub log: MpcLog,
    solve_times: f64,
    iterations: f64,
}

/// Why a model predictive controller could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("controller `{controller}`: {reason}")]
pub struct MpcError {
    /// Controller name.
    pub controller: String,
    /// What failed and what to change.
    pub reason: String,
}

/// Every model predictive controller of `plant`, built at state `x`.
pub(super) fn build_all(plant: &Plant, x: &[f64]) -> Result<Vec<MpcRun>, MpcError> {
    plant
        .spec()
        .controllers
        .iter()
        .filter_map(|(name, c)| match c {
            ControllerSpec::Mpc(cfg) => Some(build(plant, x, name, cfg)),
            _ => None,
        })
        .collect()
}

fn fail(name: &str, reason: impl Into<String>) -> MpcError {
    MpcError { controller: name.to_string(), reason: reason.into() }
}

/// A controller resolved against the plant: its plan, CV variables, MV inputs and setpoint inputs.
type Resolved = (MpcPlan, Vec<usize>, Vec<usize>, Vec<usize>);

/// The plan of `cfg` in SI with its CVs, MV inputs and setpoint inputs.
fn resolve(plant: &Plant, name: &str, cfg: &MpcConfig) -> Result<Resolved, MpcError> {
    let cvs: Vec<usize> = cfg
        .cvs
        .iter()
        .map(|c| plant.var(&c.pv).ok_or_else(|| fail(name, format!("no variable `{}`", c.pv))))
        .collect::<Result<_, _>>()?;
    let input = |p: VarPath| plant.input(&p).ok_or_else(|| fail(name, format!("no input `{p}`")));
    let mv_inputs: Vec<usize> = (0..cfg.mvs.len()).map(|k| input(VarPath::mv(name, k))).collect::<Result<_, _>>()?;
    let sp_inputs: Vec<usize> =
        (0..cfg.cvs.len()).map(|k| input(VarPath::cv_setpoint(name, k))).collect::<Result<_, _>>()?;
    let cv_dims: Vec<_> = cvs.iter().map(|&v| plant.vars()[v].spec.dim).collect();
    let cv_ranges: Vec<_> = cvs.iter().map(|&v| plant.var_range(v)).collect();
    let mvs: Vec<_> = mv_inputs.iter().map(|&i| (plant.inputs()[i].dim, plant.inputs()[i].value)).collect();
    let mv_ranges: Vec<_> = cfg
        .mvs
        .iter()
        .map(|m| plant.input(&m.output).map_or((f64::NEG_INFINITY, f64::INFINITY), |i| plant.input_range(i)))
        .collect();
    let mut cx = BuildCx::new(plant.components(), plant.thermo(), format!("controllers.{name}"));
    let channels = Channels { cv_dims: &cv_dims, cv_ranges: &cv_ranges, mvs: &mvs, mv_ranges: &mv_ranges };
    let p = plan(cfg, &mut cx, channels);
    let p = cx.finish(p).map_err(|e| {
        fail(name, e.iter().map(|e| format!("{}: {}", e.path, e.message)).collect::<Vec<_>>().join("; "))
    })?;
    Ok((p, cvs, mv_inputs, sp_inputs))
}

/// The hard limits `(min, max)` of controller `name`'s MVs (SI; infinite where none is given),
/// for the studies that check a steady state against them.
///
/// # Errors
/// [`MpcError`] when `name` is not a model predictive controller of `plant` or does not resolve.
pub fn mv_limits(plant: &Plant, name: &str) -> Result<Vec<(f64, f64)>, MpcError> {
    let Some(ControllerSpec::Mpc(cfg)) = plant.spec().controllers.get(name) else {
        return Err(fail(name, "not a model predictive controller of the plant"));
    };
    let (p, ..) = resolve(plant, name, cfg)?;
    let s = &p.settings;
    Ok(p.mv_scales.iter().enumerate().map(|(k, sc)| (s.u_min[k] * sc, s.u_max[k] * sc)).collect())
}

/// The step-response model that controller `name` of `plant` reads from its model file, checked
/// as a run checks it (size limit, known keys, its channels, sample time, full-rank gain).
///
/// # Errors
/// [`MpcError`] when `name` is not a model predictive controller reading a file, or the file is
/// refused.
pub fn file_model(plant: &Plant, name: &str) -> Result<StepModel, MpcError> {
    let Some(ControllerSpec::Mpc(cfg)) = plant.spec().controllers.get(name) else {
        return Err(fail(name, "not a model predictive controller of the plant"));
    };
    let (p, ..) = resolve(plant, name, cfg)?;
    match &p.model {
        MpcModelSource::File { file } => model_file(plant, name, cfg, file, &p),
        MpcModelSource::Builtin(_) => Err(fail(name, "its model is measured by step tests, not read from a file")),
    }
}

fn build(plant: &Plant, x: &[f64], name: &str, cfg: &MpcConfig) -> Result<MpcRun, MpcError> {
    let (p, cvs, mv_inputs, sp_inputs) = resolve(plant, name, cfg)?;
    let (model, source) = match &p.model {
        MpcModelSource::Builtin(_) => (step_test(plant, x, name, &p, &cvs, &mv_inputs)?, "step_test".to_string()),
        MpcModelSource::File { file } => (model_file(plant, name, cfg, file, &p)?, file.clone()),
    };
    let u0: Vec<f64> = mv_inputs.iter().zip(&p.mv_scales).map(|(&i, s)| plant.inputs()[i].value / s).collect();
    let y0: Vec<f64> = cvs.iter().zip(&p.cv_scales).map(|(&v, s)| x[v] / s).collect();
    let dmc = Dmc::new(scaled(&model, &p), p.settings.clone(), &u0, &y0).map_err(|e| fail(name, e.to_string()))?;
    let log = MpcLog {
        controller: name.to_string(),
        model: source,
        model_gain: model.gain(),
        samples: 0,
        statuses: BTreeMap::new(),
        mean_solve_time: 0.0,
        max_solve_time: 0.0,
        mean_iterations: 0.0,
        max_slack: 0.0,
        samples_at_limit: 0,
    };
    Ok(MpcRun {
        name: name.to_string(),
        dmc,
        sample_time: p.sample_time,
        next: 0,
        cvs,
        mv_inputs,
        sp_inputs,
        cv_scales: p.cv_scales,
        mv_scales: p.mv_scales,
        log,
        solve_times: 0.0,
        iterations: 0.0,
    })
}

/// The model in the QP's scaled variables: `S_ij · scale_u,j / scale_y,i`.
fn scaled(m: &StepModel, p: &MpcPlan) -> StepModel {
    let (ny, nu) = (m.ny, m.nu);
    let steps = m
        .steps
        .iter()
        .map(|row| (0..ny * nu).map(|k| row[k] * p.mv_scales[k % nu] / p.cv_scales[k / nu]).collect())
        .collect();
    StepModel { ts: m.ts, ny, nu, steps }
}

/// The step-response model by step tests on the nonlinear plant from `x`: each MV moved `+h` and
/// `−h` in turn (the others held, every other controller as the file has it), the CVs sampled
/// every `sample_time` for `model_length` samples, `S_k = (y⁺(kT) − y⁻(kT))/(2h)`: central
/// differences, whose error is of second order in `h` (the plant's curvature cancels).
fn step_test(
    plant: &Plant,
    x: &[f64],
    name: &str,
    p: &MpcPlan,
    cvs: &[usize],
    mvs: &[usize],
) -> Result<StepModel, MpcError> {
    let (ny, nu, n) = (cvs.len(), mvs.len(), p.model_length);
    let mut steps = vec![vec![0.0; ny * nu]; n];
    for (j, &mv) in mvs.iter().enumerate() {
        let h = p.steps[j];
        let mut runs = Vec::new();
        for sign in [1.0, -1.0] {
            let mut s = Session::new(plant, x).map_err(|e| fail(name, format!("step test: {e}")))?;
            s.set_input(mv, plant.inputs()[mv].value + sign * h);
            let mut y = Vec::with_capacity(n);
            for k in 1..=n {
                s.advance_to(k as f64 * p.sample_time)
                    .map_err(|e| fail(name, format!("step test of mvs[{j}]: {e}")))?;
                y.push(cvs.iter().map(|&v| s.state()[v]).collect::<Vec<f64>>());
            }
            runs.push(y);
        }
        for (k, row) in steps.iter_mut().enumerate() {
            for i in 0..ny {
                row[i * nu + j] = (runs[0][k][i] - runs[1][k][i]) / (2.0 * h);
            }
        }
    }
    StepModel::new(p.sample_time, ny, nu, steps).map_err(|e| fail(name, e.to_string()))
}

/// A step-response model file, relative to the flowsheet's folder, checked against the controller:
/// read under the file-size limit, every key known, its channels the controller's CVs and MVs in
/// order, its sample time the controller's, its gain of full rank in the controller's scales.
fn model_file(plant: &Plant, name: &str, cfg: &MpcConfig, file: &str, p: &MpcPlan) -> Result<StepModel, MpcError> {
    let base = std::path::Path::new(plant.file()).parent().unwrap_or(std::path::Path::new("."));
    let path = base.join(file);
    let bad = |reason: String| fail(name, format!("model file {}: {reason}", path.display()));
    let text = plantwide_flowsheet::read_text(&path).map_err(|e| bad(e.to_string()))?;
    if serde_json::from_str::<serde::de::IgnoredAny>(&text).is_ok()
        && let Some(d) = plantwide_flowsheet::parse::walk_diagnostics(&text).into_iter().next()
    {
        return Err(bad(format!("{}: {}", d.path, d.message)));
    }
    let de = &mut serde_json::Deserializer::from_str(&text);
    let m: StepModelFile = serde_path_to_error::deserialize(&mut *de).map_err(|e| {
        let at = e.path().to_string();
        let at = if at == "." { String::new() } else { format!("{at}: ") };
        bad(format!("{at}{}", e.into_inner()))
    })?;
    // Nothing after the model: a file with more in it is not the file it seems.
    de.end().map_err(|e| bad(e.to_string()))?;
    let (ny, nu) = (cfg.cvs.len(), cfg.mvs.len());
    if m.model.ny != ny || m.model.nu != nu {
        return Err(bad(format!("is {}×{} but the controller has {ny} CVs and {nu} MVs", m.model.ny, m.model.nu)));
    }
    check_channels(plant, cfg, &m).map_err(|e| bad(e.to_string()))?;
    if (m.model.ts - p.sample_time).abs() > 1e-9 * p.sample_time {
        return Err(bad(format!(
            "is sampled every {} s but the controller executes every {} s: give sample_time = {} s",
            m.model.ts, p.sample_time, m.model.ts
        )));
    }
    check_gain(&scaled(&m.model, p)).map_err(|e| bad(e.to_string()))?;
    Ok(m.model)
}

/// The file's `outputs` must be the controller's CVs (`cvs[k].pv`) and its `inputs` the inputs
/// its MVs drive (`mvs[k].output`), in the same order, compared as resolved variables and inputs
/// (so `stream.z[c]` and `stream.x[c]` are one).
fn check_channels(plant: &Plant, cfg: &MpcConfig, m: &StepModelFile) -> Result<(), ModelMismatch> {
    if m.inputs.is_empty() || m.outputs.is_empty() {
        return Err(ModelMismatch::NoChannels);
    }
    let want_out: Vec<&str> = cfg.cvs.iter().map(|c| c.pv.as_str()).collect();
    let want_in: Vec<&str> = cfg.mvs.iter().map(|v| v.output.as_str()).collect();
    let same_var = |a: &str, b: &str| plant.var(a).is_some() && plant.var(a) == plant.var(b);
    let same_input = |a: &str, b: &str| plant.input(a).is_some() && plant.input(a) == plant.input(b);
    let mismatch = |what: &str, field: &str, got: &[String], want: &[&str]| {
        let order = if got.len() == want.len() && want.iter().all(|w| got.iter().any(|g| g == w)) {
            " (the same channels in another order: the model's rows and columns would drive the wrong ones)"
        } else {
            ""
        };
        // At most 8 names, each clipped: a file may list thousands.
        let list = |v: &[&str]| {
            let shown: Vec<String> = v.iter().take(8).map(|n| plantwide_model::limits::clip(n)).collect();
            if v.len() > 8 { format!("{}, … ({} in all)", shown.join(", "), v.len()) } else { shown.join(", ") }
        };
        let got: Vec<&str> = got.iter().map(String::as_str).collect();
        ModelMismatch::Channels(format!(
            "\"{what}\" are [{}] but the controller's {field} are [{}]{order}",
            list(&got),
            list(want)
        ))
    };
    if m.outputs.len() != want_out.len() || !m.outputs.iter().zip(&want_out).all(|(a, b)| same_var(a, b)) {
        return Err(mismatch("outputs", "CVs (cvs[k].pv)", &m.outputs, &want_out));
    }
    if m.inputs.len() != want_in.len() || !m.inputs.iter().zip(&want_in).all(|(a, b)| same_input(a, b)) {
        return Err(mismatch("inputs", "MVs (mvs[k].output)", &m.inputs, &want_in));
    }
    Ok(())
}

/// A model the controller can use: finite in its scaled variables, and a steady-state gain of
/// full rank (σ_min > 1e-12 σ_max): with a singular gain no move sets the CVs independently, and
/// the QP drives the MVs along the null direction without bound.
fn check_gain(scaled: &StepModel) -> Result<(), ModelMismatch> {
    if scaled.steps.iter().flatten().any(|v| !v.is_finite()) {
        return Err(ModelMismatch::Overflow);
    }
    let g = scaled.gain();
    let (ny, nu) = (scaled.ny, scaled.nu);
    let svd = faer::Mat::<f64>::from_fn(ny, nu, |i, j| g[i][j]).thin_svd().map_err(|_| ModelMismatch::NoSvd)?;
    let s = svd.S().column_vector();
    let (hi, lo) = (s[0], s[ny.min(nu) - 1]);
    if lo.is_nan() || lo <= 1e-12 * hi {
        return Err(ModelMismatch::Singular { hi, lo });
    }
    Ok(())
}

/// Why a step-response model file does not fit its controller.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
enum ModelMismatch {
    /// It lists no inputs or outputs.
    #[error(
        "names no channels: give \"inputs\" (the MVs' driven inputs) and \"outputs\" (the CVs), in the order of the \
         controller's mvs and cvs, as an identification's report writes them"
    )]
    NoChannels,
    /// Its channels are not the controller's: which, against which.
    #[error("{0}")]
    Channels(String),
    /// Its coefficients overflow once scaled.
    #[error(
        "its coefficients overflow in the controller's scaled variables (coefficient × MV scale / CV scale): check \
         the coefficients' units (SI) and the scales"
    )]
    Overflow,
    /// Its gain has no SVD.
    #[error("its gain has no SVD")]
    NoSvd,
    /// Its steady-state gain is singular.
    #[error(
        "its steady-state gain (last step coefficients, in the controller's scales) is singular: singular values \
         {hi:.4e} … {lo:.4e}; no MV move sets the CVs independently — check the model, or control fewer CVs"
    )]
    Singular {
        /// Largest singular value.
        hi: f64,
        /// Smallest.
        lo: f64,
    },
}

impl MpcRun {
    /// Time of the next execution \[s\].
    pub fn next_time(&self) -> f64 {
        self.next as f64 * self.sample_time
    }

    /// Execute at `t` if due: read the CVs in `x` and the setpoints, solve, and return the moves
    /// as `(input, value)`; `None` if not due.
    pub fn execute(
        &mut self,
        t: f64,
        x: &[f64],
        setpoint: impl Fn(usize) -> f64,
    ) -> Result<Option<Vec<(usize, f64)>>, MpcError> {
        if self.next_time() > t {
            return Ok(None);
        }
        let y: Vec<f64> = self.cvs.iter().zip(&self.cv_scales).map(|(&v, s)| x[v] / s).collect();
        let sp: Vec<f64> = self.sp_inputs.iter().zip(&self.cv_scales).map(|(&i, s)| setpoint(i) / s).collect();
        let m = self.dmc.step(&y, &sp).map_err(|e| fail(&self.name, format!("at t = {t:.6e} s: {e}")))?;
        self.next = super::instants::after(t, self.sample_time);
        let log = &mut self.log;
        log.samples += 1;
        *log.statuses.entry(m.status.clone()).or_insert(0) += 1;
        self.solve_times += m.solve_time;
        self.iterations += f64::from(m.iterations);
        log.mean_solve_time = self.solve_times / log.samples as f64;
        log.mean_iterations = self.iterations / log.samples as f64;
        log.max_solve_time = log.max_solve_time.max(m.solve_time);
        log.max_slack = log.max_slack.max(m.slack);
        let s = self.dmc.settings();
        let at_limit = m.u.iter().enumerate().any(|(j, &u)| {
            let tol = 1e-9 * u.abs().max(1.0);
            (u - s.u_min[j]).abs() <= tol || (u - s.u_max[j]).abs() <= tol
        });
        log.samples_at_limit += usize::from(at_limit);
        Ok(Some(self.mv_inputs.iter().copied().zip(m.u.iter().zip(&self.mv_scales).map(|(u, s)| u * s)).collect()))
    }
}
