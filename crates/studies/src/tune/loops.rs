//! The PID loops of a plant as tuning sees them: what each measures and moves, the plant with
//! loops in manual (the way a plant test is run: the operator moves the output), and the exact
//! linear response of the measurements to the manual outputs at a steady state.
//!
//! A loop in manual holds its output at `op_manual`; its integral tracks that output
//! (`plantwide_model::controllers::pid`), so a steady state in auto stays one in manual with
//! `op_manual = op`. A cascade master in manual moves its slave's setpoint, with the slave in auto:
//! tuning slaves first and masters with them closed is the usual inner-first order.

use faer::{Mat, c64};
use plantwide_analysis::linear::{Linearization, StateSpace};
use plantwide_analysis::response::HessenbergResponse;
use plantwide_flowsheet::{Plant, VarPath};
use plantwide_model::ControllerSpec;
use plantwide_model::controllers::{Action, Setpoint};

use super::Tuning;
use super::blt::{BltSettings, LoopSystem, blt_system};
use super::ultimate::{Ultimate, ultimate};
use crate::TuneError;

/// One PID loop of a plant.
#[derive(Debug, Clone, PartialEq)]
pub struct PlantLoop {
    /// Controller name.
    pub name: String,
    /// Path of its measurement.
    pub pv_path: String,
    /// Its measurement (variable index).
    pub pv: usize,
    /// Its output (variable index).
    pub op: usize,
    /// Its `op_manual` input.
    pub op_manual: usize,
    /// Its `auto` input.
    pub auto: usize,
    /// Its action in the file.
    pub action: Action,
}

/// The PID loop `name` of `plant`.
///
/// # Errors
/// [`TuneError::NotALoop`] when `name` is no PID controller of the plant (listing those it has).
pub fn plant_loop(plant: &Plant, name: &str) -> Result<PlantLoop, TuneError> {
    let not_a_loop = || TuneError::NotALoop { name: name.to_string(), loops: pid_names(plant).join(", ") };
    let Some(ControllerSpec::Pid(cfg)) = plant.spec().controllers.get(name) else { return Err(not_a_loop()) };
    let b = plant.controller(name).map_err(|_| not_a_loop())?;
    let pv = plant.measured_var(b).ok_or_else(not_a_loop)?;
    let (Some(op), Some(op_manual), Some(auto)) = (
        plant.var(VarPath::controller_output(name, 0)),
        plant.input(VarPath::manual_output(name)),
        plant.input(VarPath::auto(name)),
    ) else {
        return Err(not_a_loop());
    };
    Ok(PlantLoop { name: name.to_string(), pv_path: cfg.pv.clone(), pv, op, op_manual, auto, action: cfg.action })
}

/// The PID loops `names` of `plant`, each named once.
///
/// # Errors
/// [`TuneError::Duplicate`] for a loop named twice, [`TuneError::NotALoop`] as [`plant_loop`].
pub fn plant_loops<T: AsRef<str>>(plant: &Plant, names: &[T]) -> Result<Vec<PlantLoop>, TuneError> {
    crate::request::unique("loops", names, |a, b| a == b)?;
    names.iter().map(|n| plant_loop(plant, n.as_ref())).collect()
}

/// The order in which the loops named `names` are computed together: the order of their
/// controllers in the file of `plant` (names it lacks last, by name). A model of several loops is
/// the same whatever order a user lists them in, but its arithmetic is not: the frequency response
/// of a trace composition (1e-14 per W beside flows of order one) is resolved to about 1e-6 of
/// its own size, and listing the loops the other way round moved a margin by that much (generated
/// column 0x9d41ed2c17189e4b). Computed in this order and reported in the user's, the answer is
/// the same to the bit. Returns the permutation: entry `k` is the index into `names` of the `k`-th
/// loop computed.
pub fn canonical_order<T: AsRef<str>>(plant: &Plant, names: &[T]) -> Vec<usize> {
    let controllers = &plant.spec().controllers;
    let mut order: Vec<usize> = (0..names.len()).collect();
    order.sort_by_key(|&k| (controllers.get_index_of(names[k].as_ref()).unwrap_or(usize::MAX), names[k].as_ref()));
    order
}

/// `loops` in the order a cascade is tuned: a slave (a loop whose setpoint is another listed loop's
/// output, `"sp": {"from": "<master>.op"}`) before its master, at any depth; otherwise as listed.
/// Each master is then tested with its slaves in auto at their new settings.
pub fn inner_first(plant: &Plant, loops: &[PlantLoop]) -> Vec<PlantLoop> {
    let master_of = |l: &PlantLoop| match plant.spec().controllers.get(&l.name) {
        Some(ControllerSpec::Pid(cfg)) => match &cfg.sp {
            Setpoint::Remote { from } => from.strip_suffix(".op").map(str::to_string),
            Setpoint::Value(_) => None,
        },
        _ => None,
    };
    // Depth of a loop below the listed masters above it: slaves deeper than their masters.
    let depth = |l: &PlantLoop| {
        let mut d = 0;
        let mut at = master_of(l);
        while let Some(m) = at.filter(|m| d < loops.len() && loops.iter().any(|o| &o.name == m)) {
            d += 1;
            at = loops.iter().find(|o| o.name == m).and_then(master_of);
        }
        d
    };
    let mut ordered: Vec<(usize, PlantLoop)> = loops.iter().map(|l| (depth(l), l.clone())).collect();
    ordered.sort_by_key(|(d, _)| std::cmp::Reverse(*d));
    ordered.into_iter().map(|(_, l)| l).collect()
}

/// The exact response of loop `l`'s element (no measurement dynamics) and the probe frequency
/// `ω = 1e-3 · |λ|_min` \[rad/s\], a thousand times below its slowest nonzero eigenvalue (those
/// under 1e-10 of the fastest count as the zeros of integrators): where `g(jω)` shows the element's
/// steady-state behaviour to `O((ω T)²)` without losing digits to an integrator's pole. Also
/// returns `|λ|_min` \[1/s\].
pub fn low_frequency_probe(plant: &Plant, x: &[f64], l: &PlantLoop) -> Result<(LoopResponse, f64, f64), TuneError> {
    let model = loop_model(plant, x, std::slice::from_ref(l))?;
    let ev = model.ss.eigenvalues().map_err(|e| TuneError::Linear(Box::new(e)))?;
    let scale = ev.iter().map(|v| v.norm()).fold(0.0, f64::max);
    let slow = ev.iter().map(|v| v.norm()).filter(|m| *m > 1e-10 * scale).fold(f64::INFINITY, f64::min);
    Ok((LoopResponse::new(model, Measurement::default()), 1e-3 * slow, slow))
}

/// Names of the PID controllers of `plant`, in file order.
pub fn pid_names(plant: &Plant) -> Vec<String> {
    plant
        .spec()
        .controllers
        .iter()
        .filter(|(_, c)| matches!(c, ControllerSpec::Pid(_)))
        .map(|(n, _)| n.clone())
        .collect()
}

/// `plant` with `loops` in manual at state `x`, each output held at its value in `x`.
pub fn in_manual(plant: &Plant, x: &[f64], loops: &[PlantLoop]) -> Plant {
    let mut p = plant.clone();
    for l in loops {
        p.set_input_value(l.auto, 0.0);
        p.set_input_value(l.op_manual, x[l.op]);
    }
    p
}

/// The exact linear model from the manual outputs of `loops` to their measurements, at the
/// steady state `x` of `plant` (loops in auto there), with every other loop as the file has it:
/// its state-space form (eigenvalues, steady gain) and its frequency response.
pub struct LoopModel {
    /// State-space form.
    pub ss: StateSpace,
    /// `G(jω)` by Laub's Hessenberg method.
    pub response: HessenbergResponse,
}

/// The [`LoopModel`] of `loops` at the steady state `x` of `plant`.
///
/// # Errors
/// [`TuneError::Linear`] when the linearization cannot be reduced to a state-space model.
pub fn loop_model(plant: &Plant, x: &[f64], loops: &[PlantLoop]) -> Result<LoopModel, TuneError> {
    let manual = in_manual(plant, x, loops);
    let lin = Linearization::new(&manual, x, &manual.input_values());
    let inputs: Vec<usize> = loops.iter().map(|l| l.op_manual).collect();
    let outputs: Vec<usize> = loops.iter().map(|l| l.pv).collect();
    let numerical = |e: plantwide_analysis::AnalysisError| TuneError::Linear(Box::new(e));
    let ss = lin.state_space(&inputs, &outputs).map_err(numerical)?;
    Ok(LoopModel { response: HessenbergResponse::new(&ss), ss })
}

/// The dynamics of a loop's measurement that the plant model leaves out (a thermocouple's lag, an
/// analyzer's dead time): `m(s) = e^(−θ_m s)/(τ_m s + 1)`. Luyben's habit is a 1-min dead time on
/// temperature loops and 3–5 min on composition analyzers; without such a term a loop of low
/// relative degree (reflux on the top tray) has no phase crossover and no ultimate gain.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Measurement {
    /// Dead time θ_m \[s\].
    pub dead_time: f64,
    /// First-order lag τ_m \[s\].
    pub lag: f64,
}

impl Measurement {
    /// `m(jω)`.
    pub fn response(&self, omega: f64) -> c64 {
        c64::new(0.0, -omega * self.dead_time).exp() / c64::new(1.0, omega * self.lag)
    }
}

/// The loops' frequency response as their controllers see it, `M(jω) G(jω)` with
/// `M = diag(m_i)`.
pub struct LoopResponse {
    model: LoopModel,
    measurement: Measurement,
}

impl LoopResponse {
    /// The response of `model` seen through `measurement` on every loop.
    pub fn new(model: LoopModel, measurement: Measurement) -> LoopResponse {
        LoopResponse { model, measurement }
    }

    /// The same model seen through `measurement` instead.
    pub fn seen_through(self, measurement: Measurement) -> LoopResponse {
        LoopResponse { measurement, ..self }
    }

    /// `M(jω) G(jω)` (non-finite where `jωI − A` is singular, which every search treats as no
    /// crossing).
    pub fn at(&self, omega: f64) -> Mat<c64> {
        let m = self.measurement.response(omega);
        let g = self.model.response.at(omega);
        Mat::from_fn(g.nrows(), g.ncols(), |i, k| g[(i, k)] * m)
    }

    /// The underlying linear model.
    pub fn model(&self) -> &LoopModel {
        &self.model
    }
}

/// The frequency range in which a state-space model's phase crossovers lie: three decades
/// below its slowest and above its fastest eigenvalue \[rad/s\].
pub(crate) fn frequency_range(ss: &StateSpace, loops: &[PlantLoop]) -> Result<(f64, f64), TuneError> {
    let ev = ss.eigenvalues().map_err(|e| TuneError::Linear(Box::new(e)))?;
    let mags: Vec<f64> = ev.iter().map(|l| l.norm()).filter(|m| *m > 0.0 && m.is_finite()).collect();
    let lo = mags.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = mags.iter().cloned().fold(0.0, f64::max);
    if mags.is_empty() {
        return Err(TuneError::NoDynamics {
            controller: loops.iter().map(|l| l.name.as_str()).collect::<Vec<_>>().join(", "),
        });
    }
    Ok((1e-3 * lo, 1e3 * hi))
}

/// Ultimate gain and frequency of each loop alone (the diagonal elements of `ss`), the other
/// tuned loops open (in manual).
///
/// # Errors
/// [`TuneError::NoPhaseCrossover`] naming a loop whose element never reaches −180°.
pub fn loop_ultimates(response: &LoopResponse, loops: &[PlantLoop]) -> Result<Vec<Ultimate>, TuneError> {
    let (lo, mut hi) = frequency_range(&response.model.ss, loops)?;
    let m = response.measurement;
    if m.dead_time > 0.0 {
        hi = hi.min(1e3 / m.dead_time);
    }
    (0..loops.len())
        .map(|i| {
            ultimate(|w| response.at(w)[(i, i)], lo, hi).ok_or_else(|| TuneError::NoPhaseCrossover {
                output: loops[i].pv_path.clone(),
                input: VarPath::controller_output(&loops[i].name, 0).into(),
                detail: " in the plant's linear model; a measurement dead time of about 1 min on a temperature or \
                         3–5 min on an analyzer (Luyben) gives it one"
                    .into(),
            })
        })
        .collect()
}

/// Luyben's BLT tuning of `loops` of `plant` at its steady state `x`, from the exact frequency
/// response of the linearized plant (the loops in manual, all other loops as in the file), each
/// loop's measurement seen through `measurement`.
/// Gains are in SI units of the controllers' outputs per SI unit of their measurements.
///
/// # Errors
/// As [`loop_model`], [`loop_ultimates`] and [`blt_system`].
pub fn plant_blt(
    plant: &Plant,
    x: &[f64],
    loops: &[PlantLoop],
    measurement: Measurement,
    settings: &BltSettings,
) -> Result<Tuning, TuneError> {
    let model = loop_model(plant, x, loops)?;
    let gain = model.ss.steady_gain().map_err(|e| TuneError::Linear(Box::new(e)))?;
    let response = LoopResponse::new(model, measurement);
    let ultimates = loop_ultimates(&response, loops)?;
    let g = |w: f64| -> Mat<c64> { response.at(w) };
    let system = LoopSystem {
        name: plant.name().to_string(),
        outputs: loops.iter().map(|l| l.pv_path.clone()).collect(),
        inputs: loops.iter().map(|l| VarPath::controller_output(&l.name, 0).to_string()).collect(),
        response: &g,
        gain,
        ultimates,
    };
    blt_system(&system, settings)
}
