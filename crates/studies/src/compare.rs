//! Schemes side by side — "is the energy saved worth the disturbances propagated?" (Luyben (ed.),
//! *Practical Distillation Control*, 1992, ch. 6: simulate with and without): each flowsheet as
//! its file builds it, judged on the same disturbances and outputs.
//!
//! Per scheme, at its steady state ([`plantwide_solve::converge`]):
//! 1. **Energy** ([`energy`]): every duty, and the totals of heating, cooling and heat recovered.
//! 2. **Control structure**: its quality loops — the PI loops whose measurement is not an
//!    inventory (a level, a holdup or a pressure), or the loops named — opened together, and the
//!    exact steady-state gains of the open plant from their MVs to their CVs
//!    ([`crate::screen::pairings::assess_pairing`]): RGA, Niederlinski index and DIC of the file's
//!    pairing, condition number.
//! 3. **Stability**: the eigenvalues of the exact linearization as built (loops in auto) and with
//!    the quality loops in manual (the open loop the operators face when a loop trips): unstable or
//!    integrating modes, slowest time constants.
//! 4. **Recycles**: each recycle's tear streams and loop gain (the spectral radius of the secant
//!    model of its tear map, from the sequential-modular pass).
//! 5. **Sensitivity** by continuation ([`plantwide_analysis::sensitivity::sweep`]): each output at
//!    ± each disturbance with the control structure active.
//! 6. **Closed-loop responses**: the quality loops tuned together by BLT on the exact linearization
//!    (`plantwide tune --method blt`), then each disturbance stepped on the nonlinear plant: IAE,
//!    largest deviation and settling time of the CVs and the outputs. Every scheme runs for the
//!    same time (given, or 20 reset times of the slowest loop of all schemes), so the figures
//!    compare. BLT assumes open-loop stable loops (its Nyquist test counts no right-half-plane
//!    poles, and the steady-state gain of an open-loop unstable loop has the wrong sign for the
//!    controller's action): a scheme unstable with its quality loops in manual keeps the file's
//!    tuning, and says so; [`CompareSettings::file_tuning`] keeps every file's tuning.

pub mod energy;
mod request;
pub mod verdict;

use plantwide_analysis::linear::Linearization;
use plantwide_analysis::measures::{condition_number, svd};
use plantwide_analysis::sensitivity::{Disturbance as Sweep, SweepSettings, sweep};
use plantwide_flowsheet::{Plant, VarPath};
use plantwide_model::ControllerSpec;
use plantwide_solve::dynamic::mv_limits;
use plantwide_solve::{NewtonSettings, StrategySettings, converge, steady_state};
use plantwide_units::Dimension;
use rayon::prelude::*;
use serde::Serialize;

use crate::screen::ScreenError;
use crate::screen::pairings::dynamic::Limited;
use crate::screen::pairings::mpc::{MpcAlternative, assess_mpc, controllers};
use crate::screen::pairings::{
    Disturbance, DynamicResult, DynamicSettings, PairingRequest, PairingStructure, Tuning, assess_pairing,
};
pub use energy::{Energy, Prices, UtilityCost, cost, energy};
pub use request::{CompareRequest, LoopTuning, study};

/// What to compare.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareSettings {
    /// Disturbances, each an input stepped by a fraction of its steady value or by an amount, up,
    /// down or both ways (the sensitivity sweeps go to both sides by that size).
    pub disturbances: Vec<Disturbance>,
    /// Outputs watched in every scheme: variable paths every scheme has, or inputs a controller
    /// drives (read as its output, as `gains` reads them).
    pub outputs: Vec<String>,
    /// Quality loops by controller name (empty: every PI loop on a non-inventory measurement).
    pub loops: Vec<String>,
    /// Settings of the closed-loop runs.
    pub dynamic: DynamicSettings,
    /// Keep the files' own tuning in every scheme (like for like) instead of BLT where it applies.
    pub file_tuning: bool,
    /// Utility prices for the yearly cost of each scheme's duties.
    pub prices: Prices,
}

impl CompareSettings {
    /// The closed-loop runs of this request on a scheme's `cvs` and `mvs`: its disturbances, its
    /// outputs recorded.
    fn runs_of(&self, cvs: Vec<String>, mvs: Vec<String>) -> PairingRequest {
        PairingRequest {
            cvs,
            mvs,
            throughput: Vec::new(),
            disturbances: self.disturbances.clone(),
            watch: Vec::new(),
            dynamic: self.dynamic,
            record: self.outputs.clone(),
            mpc: None,
            share: Default::default(),
        }
    }
}

/// Why a comparison could not be made.
#[derive(Debug, Clone, thiserror::Error)]
pub enum CompareError {
    /// A scheme has no steady state.
    #[error("{file}: {source}")]
    Steady {
        /// Flowsheet file.
        file: String,
        /// Why.
        source: Box<plantwide_solve::SolveError>,
    },
    /// A disturbance a scheme refuses: no such input, a wrong unit, or a step outside the input's
    /// physical range.
    #[error("disturbances {0}")]
    Disturbance(Box<crate::disturbance::DisturbanceError>),
    /// A field of the request that does not parse or does not fit.
    #[error("{field} {why}")]
    Field {
        /// The [`CompareRequest`] field.
        field: &'static str,
        /// What is wrong, after the field's name.
        why: String,
    },
    /// An output or a loop the request names is not in a scheme.
    #[error("{file}: {what}")]
    Request {
        /// Flowsheet file.
        file: String,
        /// What is missing and what would fix it.
        what: String,
    },
    /// The structure analysis or the closed-loop test failed.
    #[error("{file}: {source}")]
    Screen {
        /// Flowsheet file.
        file: String,
        /// Why.
        source: Box<ScreenError>,
    },
    /// A linearization or a sweep failed.
    #[error("{file}: {source}")]
    Analysis {
        /// Flowsheet file.
        file: String,
        /// Why.
        source: Box<plantwide_analysis::AnalysisError>,
    },
}

impl From<crate::disturbance::DisturbanceError> for CompareError {
    fn from(e: crate::disturbance::DisturbanceError) -> Self {
        CompareError::Disturbance(Box::new(e))
    }
}

impl CompareError {
    /// The request field a refusal is about, which its message starts with.
    pub fn field(&self) -> Option<&'static str> {
        match self {
            CompareError::Field { field, .. } => Some(field),
            CompareError::Disturbance(_) => Some("disturbances"),
            _ => None,
        }
    }

    /// True for a request or a file at fault (exit 1), false for a numerical failure (exit 2).
    pub fn is_user_error(&self) -> bool {
        match self {
            CompareError::Steady { source, .. } => source.is_user_error(),
            CompareError::Request { .. } | CompareError::Disturbance(_) | CompareError::Field { .. } => true,
            CompareError::Screen { source, .. } => source.is_user_error(),
            CompareError::Analysis { source, .. } => source.is_user_error(),
        }
    }
}

/// A quality loop of a scheme.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct QualityLoop {
    /// Controller.
    pub controller: String,
    /// Its measurement (CV).
    pub cv: String,
    /// The input it drives (MV).
    pub mv: String,
}

/// Modes of a linearization.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Modes {
    /// Number of states.
    pub states: usize,
    /// Eigenvalues with a non-negative real part (to 1e-12 of the largest), `[re, im]` \[1/s\].
    pub unstable: Vec<[f64; 2]>,
    /// The five slowest stable time constants \[s\], slowest first.
    pub slowest: Vec<f64>,
}

/// Stability of a scheme.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Stability {
    /// As built: every loop in auto.
    pub as_built: Modes,
    /// The quality loops in manual (their outputs held at the steady values).
    pub open_loop: Modes,
    /// The open loop has a growing mode (real part above 1e-9 of the largest modulus).
    pub open_loop_unstable: bool,
}

/// A recycle of a scheme.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Recycle {
    /// Torn streams or signals.
    pub tears: Vec<String>,
    /// Loop gain (spectral radius of the tear map's secant model), when estimated (3 passes or
    /// more).
    pub loop_gain: Option<f64>,
    /// Passes of the sequential-modular start.
    pub passes: usize,
}

/// An output at ± a disturbance, with the control structure active.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sensitivity {
    /// `path ±x %`.
    pub disturbance: String,
    /// Output path.
    pub output: String,
    /// At the base case.
    pub base: f64,
    /// At the disturbance's low end (`None`: no steady state reached there).
    pub low: Option<f64>,
    /// At its high end.
    pub high: Option<f64>,
    /// Ends with no steady state for a physical reason, which is a finding and no failure: outside
    /// the input's physical range (the sweep mirrors the step asked for, and the mirror may not
    /// exist; not swept), or where a model predictive controller's output would lie beyond its
    /// limits.
    pub no_steady_state: Vec<String>,
    /// Ends the sweep failed to reach: where the continuation stopped, and Newton's verdict there
    /// (naming the equation and variable).
    pub failures: Vec<String>,
}

/// One scheme, judged.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Scheme {
    /// Plant name.
    pub name: String,
    /// Flowsheet file.
    pub file: String,
    /// Energy use.
    pub energy: Energy,
    /// Its yearly utility cost at the request's prices.
    pub cost: UtilityCost,
    /// Quality loops.
    pub loops: Vec<QualityLoop>,
    /// Steady-state gains of the opened quality loops, CVs × MVs (SI).
    pub gain: Vec<Vec<f64>>,
    /// Condition number of `gain`.
    pub condition_number: Option<f64>,
    /// The file's pairing: relative gains, NI, DIC and its closed-loop runs.
    pub structure: Option<PairingStructure>,
    /// Its model predictive controllers: gains, condition number and closed-loop runs.
    pub mpc: Vec<MpcAlternative>,
    /// How the quality loops of the closed-loop runs are tuned: `blt`, or `file` (asked for, or
    /// open loop unstable: BLT does not apply).
    pub tuning: &'static str,
    /// Stability.
    pub stability: Stability,
    /// Recycles.
    pub recycles: Vec<Recycle>,
    /// Sensitivity of the outputs.
    pub sensitivity: Vec<Sensitivity>,
}

impl Scheme {
    /// Every closed-loop test of the scheme with its label: the file's PI pairing, then each
    /// model predictive controller.
    pub fn tests(&self) -> Vec<(String, &DynamicResult)> {
        let pi = self.structure.as_ref().and_then(|t| t.dynamic.as_ref()).map(|d| (self.name.clone(), d));
        let mpc = self.mpc.iter().filter_map(|m| {
            let label = format!("{} (MPC `{}`)", self.name, m.controller);
            Some((label, m.dynamic.as_ref()?))
        });
        pi.into_iter().chain(mpc).collect()
    }

    /// The scheme's closed-loop runs, if its loops were tuned: its PI loops', else its first
    /// model predictive controller's that went through.
    pub fn runs(&self) -> Option<&DynamicResult> {
        self.tests().into_iter().map(|(_, d)| d).find(|d| d.failure.is_none())
    }
}

/// The schemes side by side.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Comparison {
    /// Disturbances (`path +x %`, `path -5 K`, `path ±x %`).
    pub disturbances: Vec<String>,
    /// Outputs.
    pub outputs: Vec<String>,
    /// Length of every closed-loop run \[s\].
    pub duration: Option<f64>,
    /// The schemes, in the order given.
    pub schemes: Vec<Scheme>,
    /// The parts asked for that failed, each with its reason (a closed-loop test or run, a sweep
    /// end the continuation could not reach), also marked where they stand; empty when all went
    /// through.
    pub failed: Vec<String>,
    /// The utility prices the costs are at.
    pub prices: Prices,
    /// One paragraph from the evidence above ([`verdict::verdict`]).
    pub verdict: String,
}

/// Compare `plants` on `request`; schemes are judged in parallel.
///
/// # Errors
/// [`CompareError`] naming the scheme's file and what failed.
pub fn compare(plants: &[Plant], request: &CompareSettings) -> Result<Comparison, CompareError> {
    let first: Vec<Scheme> = plants.par_iter().map(|p| scheme(p, request)).collect::<Result<_, _>>()?;
    // One run length for all: given, or 20 reset times of the slowest tuned loop of any scheme.
    let longest = |s: &Scheme| {
        s.structure
            .as_ref()
            .and_then(|t| t.dynamic.as_ref())
            .map_or(0.0, |d| d.loops.iter().map(|l| l.tau_i).filter(|t| t.is_finite()).fold(0.0, f64::max))
    };
    let duration = request.dynamic.duration.or_else(|| {
        let t = first.iter().map(longest).fold(0.0, f64::max);
        (t > 0.0).then_some(20.0 * t)
    });
    let schemes = match duration {
        Some(d) if request.dynamic.duration.is_none() && !request.disturbances.is_empty() => {
            let again = CompareSettings {
                dynamic: DynamicSettings { duration: Some(d), ..request.dynamic },
                ..request.clone()
            };
            plants
                .par_iter()
                .zip(first)
                .map(|(p, s)| if (20.0 * longest(&s) - d).abs() <= 1e-9 * d { Ok(s) } else { scheme(p, &again) })
                .collect::<Result<_, _>>()?
        }
        _ => first,
    };
    if let Some(s) =
        schemes.iter().find(|s| !s.mpc.is_empty() && duration.is_none() && !request.disturbances.is_empty())
    {
        return Err(CompareError::Request {
            file: s.file.clone(),
            what: "give a `duration`: no scheme has a PI quality loop whose reset time sets the length of the \
                   closed-loop runs, and a model predictive controller has none"
                .into(),
        });
    }
    let failed = failed_parts(&schemes);
    let mut c = Comparison {
        disturbances: request.disturbances.iter().map(Disturbance::label).collect(),
        outputs: request.outputs.clone(),
        duration,
        schemes,
        failed,
        prices: request.prices,
        verdict: String::new(),
    };
    c.verdict = verdict::verdict(&c);
    Ok(c)
}

/// The parts of the comparison that failed, each with its reason: closed-loop tests and runs of
/// the file's pairing and of each model predictive controller, and sweep ends the continuation
/// could not reach.
fn failed_parts(schemes: &[Scheme]) -> Vec<String> {
    let mut out = Vec::new();
    for s in schemes {
        out.extend(s.tests().into_iter().flat_map(|(label, d)| d.failures(&label)));
        for r in &s.sensitivity {
            for f in &r.failures {
                let part = format!("{}, sweep {}: {f}", s.name, r.disturbance);
                if !out.contains(&part) {
                    out.push(part);
                }
            }
        }
    }
    out
}

/// One scheme judged on `r`.
fn scheme(plant: &Plant, r: &CompareSettings) -> Result<Scheme, CompareError> {
    let file = plant.file().to_string();
    let outputs: Vec<usize> = r.outputs.iter().map(|o| output(plant, o)).collect::<Result<_, _>>()?;
    for d in &r.disturbances {
        d.check(plant)?;
    }
    let sol = converge(plant, &StrategySettings::default())
        .map_err(|e| CompareError::Steady { file: file.clone(), source: Box::new(e) })?;
    let loops = quality_loops(plant, &r.loops)?;
    let analysis = |e| CompareError::Analysis { file: file.clone(), source: Box::new(e) };
    let stability = stability(plant, &sol.x, &sol.u, &loops).map_err(analysis)?;
    let keep = r.file_tuning || stability.open_loop_unstable;
    let tuning = if keep { Tuning::Given(file_tuning(plant, &loops)?) } else { Tuning::Blt };
    let (gain, condition, structure) = structure(plant, r, &loops, &tuning)?;
    let mpc = mpc(plant, &sol.x, r)?;
    let recycles = sol
        .sm
        .iter()
        .flat_map(|sm| &sm.sccs)
        // The secant model needs a few passes to say anything: a pass that starts converged has none.
        .map(|s| Recycle { tears: s.tears.clone(), loop_gain: s.loop_gain.filter(|_| s.passes >= 3), passes: s.passes })
        .collect();
    let sensitivity = match held_by_mpc(plant, &sol.x)? {
        Some((held, x, ops)) => sensitivity(&held, &x, &held.input_values(), r, &outputs, &ops),
        None => sensitivity(plant, &sol.x, &sol.u, r, &outputs, &[]),
    }
    .map_err(analysis)?;
    let energy = energy(plant, &sol.x, &sol.u);
    Ok(Scheme {
        name: plant.name().to_string(),
        file,
        cost: cost(&energy, &r.prices),
        energy,
        loops,
        gain,
        condition_number: condition,
        structure,
        mpc,
        tuning: if matches!(tuning, Tuning::Blt) { "blt" } else { "file" },
        stability,
        recycles,
        sensitivity,
    })
}

/// The variable output `o` reads in `plant`: a variable, or an input a controller drives (its
/// output), as `gains` reads outputs.
fn output(plant: &Plant, o: &str) -> Result<usize, CompareError> {
    let driven = || plantwide_flowsheet::overrides::resolve_input(plant, o).and_then(|i| plant.inputs()[i].driven_by);
    plant.var(o).or_else(driven).ok_or_else(|| {
        let names = plant.vars().iter().map(|v| v.path.as_str());
        let inputs = plant.inputs().iter().filter(|i| i.driven_by.is_some()).map(|i| i.path.as_str());
        CompareError::Request {
            file: plant.file().to_string(),
            what: format!(
                "no output `{o}`{}: every scheme must have every output (a variable, or an input a controller drives)",
                plantwide_flowsheet::error::did_you_mean(o, names.chain(inputs))
            ),
        }
    })
}

/// The quality loops: those named, or every PID with reset action whose measurement is not an
/// inventory (its dimension a length, an amount or a pressure).
fn quality_loops(plant: &Plant, named: &[String]) -> Result<Vec<QualityLoop>, CompareError> {
    let inventory = [Dimension::LENGTH, Dimension::AMOUNT, Dimension::PRESSURE];
    let mut loops = Vec::new();
    for (name, c) in &plant.spec().controllers {
        let ControllerSpec::Pid(pid) = c else { continue };
        let dim = plant.var(&pid.pv).map(|v| plant.vars()[v].spec.dim);
        let quality = pid.tau_i.is_some() && dim.is_some_and(|d| !inventory.contains(&d));
        let Some(mv) = pid.output.clone() else {
            // A quality loop that sets another controller (a ratio station's ratio, a cascade
            // slave's setpoint) cannot be opened at an input: left out, the scheme would be
            // compared without its quality control and say nothing of it.
            if (named.is_empty() && quality) || named.contains(name) {
                return Err(CompareError::Request {
                    file: plant.file().to_string(),
                    what: format!(
                        "quality loop `{name}` drives no input (its output `{name}.op` sets another controller, \
                         e.g. a ratio station's ratio): compare opens and tunes quality loops at the inputs they \
                         drive, so a scheme of ratio masters or cascade masters cannot be compared yet; compare \
                         its loops' gains (inputs `{name}.op_manual`, …) instead"
                    ),
                });
            }
            continue;
        };
        if (named.is_empty() && quality) || named.contains(name) {
            loops.push(QualityLoop { controller: name.clone(), cv: pid.pv.clone(), mv });
        }
    }
    if let Some(n) = named.iter().find(|n| !loops.iter().any(|l| &l.controller == *n)) {
        return Err(CompareError::Request {
            file: plant.file().to_string(),
            what: format!("`loops` names `{n}`, no PID controller driving an input"),
        });
    }
    Ok(loops)
}

/// The gains of the opened quality loops, their condition number and the file's pairing judged
/// (with its closed-loop runs when there are disturbances).
type StructureParts = (Vec<Vec<f64>>, Option<f64>, Option<PairingStructure>);

fn structure(
    plant: &Plant,
    r: &CompareSettings,
    loops: &[QualityLoop],
    tuning: &Tuning,
) -> Result<StructureParts, CompareError> {
    if loops.is_empty() {
        return Ok((Vec::new(), None, None));
    }
    let request = r.runs_of(loops.iter().map(|l| l.cv.clone()).collect(), loops.iter().map(|l| l.mv.clone()).collect());
    let pairing: Vec<usize> = (0..loops.len()).collect();
    let screen = |e| CompareError::Screen { file: plant.file().to_string(), source: Box::new(e) };
    let (open, s) = assess_pairing(plant, &request, &pairing, tuning).map_err(screen)?;
    let condition = svd(open.gain.as_ref()).ok().map(|d| condition_number(&d.singular_values));
    Ok((plantwide_analysis::measures::rows(open.gain.as_ref()), condition, Some(s)))
}

/// Each model predictive controller of the scheme judged at its steady state `x` on `r`'s
/// disturbances, its runs recording the controller's CVs and `r`'s outputs.
fn mpc(plant: &Plant, x: &[f64], r: &CompareSettings) -> Result<Vec<MpcAlternative>, CompareError> {
    let screen = |e| CompareError::Screen { file: plant.file().to_string(), source: Box::new(e) };
    controllers(plant)
        .iter()
        .map(|(name, cfg)| {
            let cvs = cfg.cvs.iter().map(|c| c.pv.clone()).collect();
            let request = r.runs_of(cvs, cfg.mvs.iter().map(|m| m.output.clone()).collect());
            assess_mpc(plant, x, name, &request, r.dynamic.duration).map_err(screen)
        })
        .collect()
}

/// The modes as built and with the quality loops in manual: each one's `auto` input 0 and its
/// `op_manual` at its steady output, so the steady state stays and its integral tracks.
fn stability(
    plant: &Plant,
    x: &[f64],
    u: &[f64],
    loops: &[QualityLoop],
) -> Result<Stability, plantwide_analysis::AnalysisError> {
    let as_built = modes(plant, x, u)?;
    let mut manual = plant.clone();
    for l in loops {
        let ctrl = l.controller.as_str();
        if let (Some(auto), Some(op_manual), Some(op)) = (
            manual.input(VarPath::auto(ctrl)),
            manual.input(VarPath::manual_output(ctrl)),
            plant.var(VarPath::controller_output(ctrl, 0)),
        ) {
            manual.set_input_value(auto, 0.0);
            manual.set_input_value(op_manual, x[op]);
        }
    }
    let open_loop = modes(&manual, x, &manual.input_values())?;
    let model = Linearization::new(&manual, x, &manual.input_values()).state_space(&[], &[])?;
    let ev = model.eigenvalues()?;
    let scale = ev.iter().map(|l| l.norm()).fold(0.0, f64::max);
    let open_loop_unstable = ev.iter().any(|l| l.re > 1e-9 * scale);
    Ok(Stability { as_built, open_loop, open_loop_unstable })
}

/// The file's settings of each quality loop (SI): gain magnitude, reset time and action.
fn file_tuning(plant: &Plant, loops: &[QualityLoop]) -> Result<Vec<(f64, f64, &'static str)>, CompareError> {
    let bad = |what: String| CompareError::Request { file: plant.file().to_string(), what };
    loops
        .iter()
        .map(|l| {
            let Some(ControllerSpec::Pid(c)) = plant.spec().controllers.get(&l.controller) else {
                return Err(bad(format!("`{}` is not a PID controller", l.controller)));
            };
            let (mv, cv) = (plant.input(&l.mv), plant.var(&l.cv));
            let dim = mv.zip(cv).map(|(i, v)| plant.inputs()[i].dim / plant.vars()[v].spec.dim);
            let kc = dim
                .and_then(|d| c.kc.to_si(d).ok())
                .ok_or_else(|| bad(format!("controllers.{}.kc: not a gain of its loop", l.controller)))?;
            let ti = c.tau_i.as_ref().and_then(|t| t.to_si(Dimension::TIME).ok()).unwrap_or(f64::INFINITY);
            let action = match c.action {
                plantwide_model::controllers::Action::Reverse => "reverse",
                plantwide_model::controllers::Action::Direct => "direct",
            };
            Ok((kc.abs(), ti, action))
        })
        .collect()
}

fn modes(plant: &Plant, x: &[f64], u: &[f64]) -> Result<Modes, plantwide_analysis::AnalysisError> {
    let model = Linearization::new(plant, x, u).state_space(&[], &[])?;
    let unstable = model.unstable(1e-12)?.iter().map(|l| [l.re, l.im]).collect();
    let mut slowest = model.time_constants()?;
    slowest.sort_by(|a, b| b.total_cmp(a));
    slowest.truncate(5);
    Ok(Modes { states: model.states.len(), unstable, slowest })
}

/// A plant held by its model predictive controllers, its steady state and their outputs.
type Held = (Plant, Vec<f64>, Vec<Limited>);

/// The scheme's steady state with its model predictive controllers holding their CVs on their
/// setpoints ([`Plant::with_mpc_at_setpoints`]), from its steady state `x`, and their outputs with
/// their limits; `None` for a scheme without one.
fn held_by_mpc(plant: &Plant, x: &[f64]) -> Result<Option<Held>, CompareError> {
    let mpcs = controllers(plant);
    if mpcs.is_empty() {
        return Ok(None);
    }
    let file = || plant.file().to_string();
    let held =
        plant.with_mpc_at_setpoints().map_err(|e| CompareError::Request { file: file(), what: e.to_string() })?;
    let st = steady_state(&held, &held.input_values(), Some(x), &NewtonSettings::default())
        .map_err(|e| CompareError::Steady { file: file(), source: Box::new(e.into()) })?;
    let mut ops = Vec::new();
    for (name, cfg) in mpcs {
        let limits = mv_limits(plant, name).map_err(|e| CompareError::Request { file: file(), what: e.to_string() })?;
        for (k, (mv, (lo, hi))) in cfg.mvs.iter().zip(limits).enumerate() {
            ops.push(Limited { op: VarPath::controller_output(name, k).into(), mv: mv.output.clone(), lo, hi });
        }
    }
    Ok(Some((held, st.x, ops)))
}

/// Each output at ± each disturbance, by continuation from the steady state; an end where a model
/// predictive controller's output (`ops`) would lie outside its limits has no value: the
/// controller cannot hold its CVs there.
fn sensitivity(
    plant: &Plant,
    x: &[f64],
    u: &[f64],
    r: &CompareSettings,
    outputs: &[usize],
    ops: &[Limited],
) -> Result<Vec<Sensitivity>, plantwide_analysis::AnalysisError> {
    let op_vars: Vec<usize> = ops.iter().filter_map(|o| plant.var(&o.op)).collect();
    let watched: Vec<usize> = outputs.iter().chain(&op_vars).copied().collect();
    let mut rows = Vec::new();
    for d in crate::disturbance::sweeps(&r.disturbances) {
        let (low, high, no_steady_state, failures) = ends(plant, (x, u), d, (&watched, outputs.len()), ops)?;
        for (k, o) in r.outputs.iter().enumerate() {
            rows.push(Sensitivity {
                disturbance: d.sweep_label(),
                output: o.clone(),
                base: x[outputs[k]],
                low: low.as_ref().map(|v| v[k]),
                high: high.as_ref().map(|v| v[k]),
                no_steady_state: no_steady_state.clone(),
                failures: failures.clone(),
            });
        }
    }
    Ok(rows)
}

/// The watched values at the two ends of `d`'s sweep from the steady state `(x, u)` (`None` where
/// there is none), the ends with no steady state for a physical reason, and the ends the sweep
/// failed to reach. `watched` holds the outputs first (`n_outputs` of them), then the model
/// predictive controllers' outputs `ops`.
type Ends = (Option<Vec<f64>>, Option<Vec<f64>>, Vec<String>, Vec<String>);

fn ends(
    plant: &Plant,
    (x, u): (&[f64], &[f64]),
    d: &Disturbance,
    (watched, n_outputs): (&[usize], usize),
    ops: &[Limited],
) -> Result<Ends, plantwide_analysis::AnalysisError> {
    let u0 = plantwide_flowsheet::overrides::resolve_input(plant, &d.path).map_or(f64::NAN, |i| u[i]);
    let mut range = Sweep::parse(plant, u, &d.sweep_range(u0))?;
    // An end outside the input's physical range (a mole fraction above 1) is no steady state to
    // look for: it is reported as such, and the sweep goes to the other end only (that side's
    // walk has no point: a point just inside the base, where the range may end, is no sweep).
    let (mut no_steady_state, mut failures) = (Vec::new(), Vec::new());
    let i = range.signal.index;
    let number = plantwide_model::limits::number;
    for end in [range.low, range.high] {
        if let Err(why) = plantwide_flowsheet::overrides::check_input_value(plant, i, end) {
            no_steady_state.push(format!("{} at {}: {why} (not swept)", d.path, number(end)));
        }
    }
    let inside = |v: f64| plantwide_flowsheet::overrides::check_input_value(plant, i, v).is_ok();
    let (low_ok, high_ok) = (inside(range.low), inside(range.high));
    range.low = if low_ok { range.low } else { range.base };
    range.high = if high_ok { range.high } else { range.base };
    let settings = SweepSettings { points: 2, ..Default::default() };
    let curve = sweep(plant, x, u, std::slice::from_ref(&range), watched, &settings)?.remove(0);
    failures.extend(curve.failures.iter().map(|fl| fl.to_string()));
    let mut at = |value: f64, ok: bool| {
        let failed = curve.failures.iter().any(|fl| (fl.value < range.base) == (value < range.base));
        if failed || !ok {
            return None;
        }
        let k = if value < range.base { 0 } else { curve.outputs.len() - 1 };
        let v = curve.outputs.get(k).cloned().flatten()?;
        let beyond: Vec<String> = ops_beyond(ops, &v[n_outputs..]);
        if beyond.is_empty() {
            return Some(v);
        }
        let end = number(value);
        no_steady_state.push(format!(
            "{} at {end}: {}; the controller cannot hold its CVs there",
            d.path,
            beyond.join(", ")
        ));
        None
    };
    let (low, high) = (at(range.low, low_ok), at(range.high, high_ok));
    Ok((low, high, no_steady_state, failures))
}

/// The controller outputs of `ops` whose steady values `v` lie outside their limits, described.
fn ops_beyond(ops: &[Limited], v: &[f64]) -> Vec<String> {
    ops.iter()
        .zip(v)
        .filter(|(o, v)| **v < o.lo || **v > o.hi)
        .map(|(o, v)| {
            let (side, l) = if *v < o.lo { ("min", o.lo) } else { ("max", o.hi) };
            let n = plantwide_model::limits::number;
            format!("`{}` (driving `{}`) would need {}, beyond its {side} {}", o.op, o.mv, n(*v), n(l))
        })
        .collect()
}
