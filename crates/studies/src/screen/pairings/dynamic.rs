//! The dynamic test of candidate pairings: each candidate's PI loops added to the open plant, tuned
//! together by Luyben's BLT on the exact linearization (with the measurement delay given), then
//! every disturbance stepped on the nonlinear plant from its steady state, every run of the same
//! length (given, or 20 reset times of the best-ranked candidate's slowest loop). Figures per CV: IAE,
//! largest deviation, settling time (2 % band); per run, the MVs that reached a limit (each loop's
//! output is bounded to [0, 2 u₀], or [2 u₀, 0] for a negative steady value u₀). The score of a
//! candidate is the mean over disturbances and CVs of its IAE over the best candidate's, so 1 is
//! best everywhere; a failed run scores infinity. Candidates run in parallel (rayon); each is a pure
//! function of the plant and the request, so the results do not depend on the thread count.
//! They are also the tasks of a sharded screening (task `t` the `t`-th candidate tested,
//! [`PairingRequest::share`]): each shard runs its own, a merge scores them all.

use plantwide_analysis::figures::summary;
use plantwide_flowsheet::scenario::{
    EventSpec, IntegratorSpec, RecordPathSpec, RecordSpec, SCENARIO_FORMAT_VERSION, ScenarioSpec,
};
use plantwide_flowsheet::{Plant, StructureEdit, VarPath};
use plantwide_model::ControllerSpec;
use plantwide_model::controllers::pid::PidConfig;
use plantwide_model::controllers::{Action, Setpoint};
use plantwide_solve::dynamic::{Start, simulate};
use plantwide_solve::{NewtonSettings, steady_state};
use plantwide_units::{Dimension, QuantityValue};
use rayon::prelude::*;
use serde::{Deserialize, Deserializer, Serialize};

use super::{OpenPlant, PairingRequest, PairingStructure};
use crate::screen::ScreenError;
use crate::tune::flowsheet::blt_loops;
use crate::tune::loops::{Measurement, plant_loop};

/// Why a candidate's dynamic test failed (recorded as its `failure`, the other candidates go on).
#[derive(Debug, Clone, thiserror::Error)]
pub enum CandidateFailure {
    /// Its loops could not be added to the open plant.
    #[error(transparent)]
    Wiring(#[from] plantwide_flowsheet::OverrideError),
    /// The plant with its loops has no steady state.
    #[error(transparent)]
    Steady(#[from] plantwide_solve::SteadyError),
    /// Its loops could not be tuned.
    #[error(transparent)]
    Tune(#[from] crate::TuneError),
    /// The disturbance run could not be set up.
    #[error(transparent)]
    Scenario(#[from] plantwide_flowsheet::LoadError),
    /// The disturbance run stopped.
    #[error(transparent)]
    Simulation(#[from] Box<plantwide_solve::dynamic::SimError>),
    /// A pair whose MV does not move its CV with the other loops open: no gain to close it with.
    #[error(
        "pair {cv} ← {mv}: its steady-state gain with the other loops open is {gain:e}, so no PI loop on it can \
         hold {cv}; pair {cv} with another MV"
    )]
    NoPairedGain {
        /// The CV.
        cv: String,
        /// The MV.
        mv: String,
        /// Its gain (SI).
        gain: f64,
    },
}

/// Settings of the dynamic test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DynamicSettings {
    /// How many of the best steady-state survivors to test.
    pub candidates: usize,
    /// Length of each run \[s\] (default: 20 times the longest reset time of the tuned loops).
    pub duration: Option<f64>,
    /// Measurement delay and lag of every loop, for the tuning.
    pub measurement: Measurement,
}

impl Default for DynamicSettings {
    fn default() -> Self {
        DynamicSettings { candidates: 4, duration: None, measurement: Measurement::default() }
    }
}

/// A loop of a tested candidate, as tuned.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TunedLoop {
    /// Controlled variable.
    pub cv: String,
    /// Manipulated variable.
    pub mv: String,
    /// Gain magnitude (SI).
    pub kc: f64,
    /// Reset time \[s\] (infinite, written `null`, for a loop without integral action).
    #[serde(deserialize_with = "infinite_if_null")]
    pub tau_i: f64,
    /// `direct` or `reverse`.
    pub action: String,
}

/// Figures of one CV in one run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CvFigures {
    /// Controlled variable.
    pub cv: String,
    /// Integral of the absolute error (SI unit × s; NaN, written `null`, when not recorded).
    #[serde(deserialize_with = "nan_if_null")]
    pub iae: f64,
    /// Largest deviation from the setpoint (NaN, written `null`, when not recorded).
    #[serde(deserialize_with = "nan_if_null")]
    pub max_deviation: f64,
    /// Time from the step until it stays within 2 % of its excursion \[s\].
    pub settling_time: Option<f64>,
}

/// One disturbance run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DisturbanceRun {
    /// `path +x %`.
    pub disturbance: String,
    /// Figures per CV.
    pub cvs: Vec<CvFigures>,
    /// MVs whose loop output reached a limit.
    pub saturated: Vec<String>,
    /// Why the run failed, as the simulation reports it (its figures are then `null`); `null` for
    /// a run that went through.
    #[serde(default)]
    pub failure: Option<String>,
    /// Where and how the plant left its operating range under these loops (a vessel ran dry or
    /// overflowed, a loop drove a flow below zero), as the simulation reports it: what this
    /// structure cannot ride through. Its figures are then `null`; `null` for a run that went
    /// through.
    #[serde(default)]
    pub lost: Option<String>,
    /// Recorded times \[s\] (for plots; not serialized).
    #[serde(skip)]
    pub times: Vec<f64>,
    /// Each CV's record at `times` (for plots; not serialized).
    #[serde(skip)]
    pub series: Vec<Vec<f64>>,
}

/// A candidate's dynamic test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DynamicResult {
    /// BLT's detuning factor.
    pub detuning_factor: Option<f64>,
    /// The tuned loops.
    pub loops: Vec<TunedLoop>,
    /// One run per disturbance.
    pub runs: Vec<DisturbanceRun>,
    /// Mean IAE relative to the best candidate's (1 best; infinite, written `null`, when a run
    /// failed or before the candidates are scored together).
    #[serde(deserialize_with = "infinite_if_null")]
    pub score: f64,
    /// Why the test as a whole failed (its loops could not be added or tuned), if it did; a
    /// failed run is marked in its own `failure`.
    pub failure: Option<String>,
}

impl DynamicResult {
    /// The loops were tuned and every run went through.
    pub fn completed(&self) -> bool {
        self.failure.is_none() && self.runs.iter().all(|r| r.failure.is_none())
    }

    /// Every run went through with the plant within its operating range (none [`lost`](DisturbanceRun::lost)).
    pub fn rides_through(&self) -> bool {
        self.completed() && self.runs.iter().all(|r| r.lost.is_none())
    }

    /// The runs the plant was lost in, each with how, for the test labelled `label`.
    pub fn losses(&self, label: &str) -> Vec<String> {
        let lost = self.runs.iter().filter_map(|r| Some((&r.disturbance, r.lost.as_ref()?)));
        lost.map(|(d, how)| format!("{label}, run {d}: {how}")).collect()
    }

    /// What failed, each with its reason, for the test labelled `label`: the test as a whole, or
    /// each run that failed.
    pub fn failures(&self, label: &str) -> Vec<String> {
        if let Some(why) = &self.failure {
            return vec![format!("{label}: {why}")];
        }
        let failed = self.runs.iter().filter_map(|r| Some((&r.disturbance, r.failure.as_ref()?)));
        failed.map(|(d, why)| format!("{label}, run {d}: {why}")).collect()
    }
}

/// A candidate's dynamic test as the task of a sharded screening: the result and the records of
/// its runs that plots need (which the result's JSON leaves out).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateTask {
    /// The result.
    pub result: DynamicResult,
    /// Each run's recorded times and CV series.
    pub traces: Vec<(Vec<f64>, Vec<Vec<f64>>)>,
}

impl From<&DynamicResult> for CandidateTask {
    fn from(r: &DynamicResult) -> Self {
        let traces = r.runs.iter().map(|run| (run.times.clone(), run.series.clone())).collect();
        CandidateTask { result: r.clone(), traces }
    }
}

impl From<CandidateTask> for DynamicResult {
    fn from(t: CandidateTask) -> Self {
        let mut r = t.result;
        for (run, (times, series)) in r.runs.iter_mut().zip(t.traces) {
            (run.times, run.series) = (times, series);
        }
        r
    }
}

/// A number written `null` (non-finite in JSON) read back as NaN.
fn nan_if_null<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// A number written `null` read back as +∞ (a reset time without integral action, the score of
/// a failed or unscored candidate).
fn infinite_if_null<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::INFINITY))
}

/// Test the first `r.dynamic.candidates` structures that passed, in parallel, and score them; the
/// length of the runs \[s\] and the structures tested, in task order.
pub(super) fn test(
    open: &OpenPlant,
    r: &PairingRequest,
    structures: &mut [PairingStructure],
) -> Result<(f64, Vec<usize>), ScreenError> {
    let picked: Vec<usize> =
        (0..structures.len()).filter(|&k| structures[k].passed).take(r.dynamic.candidates).collect();
    let duration = test_picked(open, r, structures, picked.clone(), &Tuning::Blt)?;
    Ok((duration, picked))
}

/// How a tested structure's loops are tuned.
#[derive(Debug, Clone, PartialEq)]
pub enum Tuning {
    /// Together by BLT on the exact linearization (open-loop stable loops only: BLT's Nyquist
    /// test counts no open-loop poles in the right half-plane).
    Blt,
    /// As given, per pair: gain magnitude (SI), reset time \[s\] and action.
    Given(Vec<(f64, f64, &'static str)>),
}

/// Test the structures `picked`, in parallel, and score them; the length of the runs \[s\].
pub(super) fn test_picked(
    open: &OpenPlant,
    r: &PairingRequest,
    structures: &mut [PairingStructure],
    picked: Vec<usize>,
    tuning: &Tuning,
) -> Result<f64, ScreenError> {
    for d in &r.disturbances {
        match plantwide_flowsheet::overrides::resolve_input(&open.plant, &d.path) {
            Some(i) if open.plant.inputs()[i].driven_by.is_none() => {}
            _ => return Err(ScreenError::Disturbance { path: d.path.clone() }),
        }
    }
    let tune = |k: usize| match tuning {
        Tuning::Blt => tuned_plant(open, r, &structures[k]),
        Tuning::Given(loops) => given_plant(open, &structures[k], loops),
    };
    // The candidates this process runs (all, a shard's, or none when merging a sharded screening).
    let tunings: Vec<Option<TunedCandidate>> =
        picked.par_iter().enumerate().map(|(t, &k)| r.share.computes(t).then(|| tune(k))).collect();
    // One length for every run, so that IAEs compare: given, or 20 reset times of the best-ranked
    // candidate that could be tuned (tuned here when another process runs it).
    let duration = match r.dynamic.duration {
        Some(d) => d,
        None => {
            let tau = |t: usize| match &tunings[t] {
                Some(tuned) => tuned.as_ref().ok().map(|c| c.2.tau_i_max),
                None => tune(picked[t]).ok().map(|c| c.2.tau_i_max),
            };
            20.0 * (0..picked.len()).find_map(tau).unwrap_or(0.0)
        }
    };
    let mut results: Vec<Option<DynamicResult>> = picked
        .par_iter()
        .zip(tunings)
        .enumerate()
        .map(|(t, (&k, tuned))| match tuned {
            Some(tuned) => Some(candidate(&tuned, r, &pair_outputs(open, &structures[k]), duration)),
            None => r.share.given(t),
        })
        .collect();
    if !r.share.is_shard() {
        score(&mut results.iter_mut().flatten().collect::<Vec<_>>(), r.steps().len(), r.cvs.len());
    }
    for (k, t) in picked.into_iter().zip(results) {
        structures[k].dynamic = t;
    }
    Ok(duration)
}

/// Score each result that ran: the mean over its runs (`steps`) and CVs of its IAE over the best
/// IAE of all `results` there (1 when best everywhere); a result whose test or one of whose runs
/// failed, or lost the plant, has an infinite score (it cannot be compared run by run).
pub(crate) fn score(results: &mut [&mut DynamicResult], steps: usize, cvs: usize) {
    let best: Vec<Vec<f64>> = (0..steps)
        .map(|d| {
            let ok = || results.iter().filter(|t| t.rides_through());
            (0..cvs).map(|c| ok().map(|t| t.runs[d].cvs[c].iae).fold(f64::INFINITY, f64::min)).collect()
        })
        .collect();
    for t in results.iter_mut().filter(|t| !t.rides_through()) {
        t.score = f64::INFINITY;
    }
    for t in results.iter_mut().filter(|t| t.rides_through()) {
        let n = (steps * cvs).max(1) as f64;
        let sum: f64 = (0..steps)
            .flat_map(|d| (0..cvs).map(move |c| (d, c)))
            .map(|(d, c)| t.runs[d].cvs[c].iae / best[d][c].max(f64::MIN_POSITIVE))
            .sum();
        t.score = sum / n;
    }
}

/// Run one tuned candidate; a failure is recorded, not returned (the other candidates go on), and a
/// run that fails is marked in its place (the other runs go on).
pub(crate) fn candidate(tuned: &TunedCandidate, r: &PairingRequest, ops: &[Limited], duration: f64) -> DynamicResult {
    let (plant, x, tuned) = match tuned {
        Ok(t) => t,
        Err(why) => {
            return DynamicResult {
                detuning_factor: None,
                loops: Vec::new(),
                runs: Vec::new(),
                score: f64::INFINITY,
                failure: Some(why.to_string()),
            };
        }
    };
    let runs: Vec<DisturbanceRun> = r
        .steps()
        .iter()
        .map(|d| run(plant, x, r, d, duration, ops).map_or_else(|why| unfinished_run(r, d, why), |o| o.0))
        .collect();
    let score = if runs.iter().all(|r| r.failure.is_none() && r.lost.is_none()) { f64::NAN } else { f64::INFINITY };
    DynamicResult { detuning_factor: tuned.detuning, loops: tuned.loops.clone(), runs, score, failure: None }
}

/// The paths a run of `r` records figures of: its CVs, then its other recorded variables.
fn watched(r: &PairingRequest) -> Vec<&String> {
    r.cvs.iter().chain(r.record.iter().filter(|p| !r.cvs.contains(p))).collect()
}

/// A run of step `d` that did not finish: lost where the plant left its operating range (the
/// simulation stopped it), failed for any other reason.
pub(crate) fn unfinished_run(r: &PairingRequest, d: &super::Disturbance, why: CandidateFailure) -> DisturbanceRun {
    match &why {
        CandidateFailure::Simulation(e) if matches!(**e, plantwide_solve::dynamic::SimError::Stopped { .. }) => {
            DisturbanceRun { failure: None, lost: Some(why.to_string()), ..failed_run(r, d, String::new()) }
        }
        _ => failed_run(r, d, why.to_string()),
    }
}

/// A run of step `d` that failed for `why`: every figure `null`, nothing recorded.
pub(crate) fn failed_run(r: &PairingRequest, d: &super::Disturbance, why: String) -> DisturbanceRun {
    let cvs = watched(r)
        .into_iter()
        .map(|cv| CvFigures { cv: cv.clone(), iae: f64::NAN, max_deviation: f64::NAN, settling_time: None })
        .collect();
    DisturbanceRun {
        disturbance: d.label(),
        cvs,
        saturated: Vec::new(),
        failure: Some(why),
        lost: None,
        times: Vec::new(),
        series: Vec::new(),
    }
}

/// A candidate's plant with its tuned loops, its steady state and tuning, or why it has none.
pub(crate) type TunedCandidate = Result<(Plant, Vec<f64>, Tuned), CandidateFailure>;

/// The tuning of a candidate.
pub(crate) struct Tuned {
    detuning: Option<f64>,
    loops: Vec<TunedLoop>,
    /// Its longest reset time \[s\].
    pub(crate) tau_i_max: f64,
}

/// The controller description of pair `i` with gain `kc` and reset `tau_i` (SI).
fn loop_spec(open: &OpenPlant, s: &PairingStructure, i: usize, kc: f64, tau_i: f64, action: Action) -> PidConfig {
    let p = &s.pairs[i];
    let Limited { lo, hi, .. } = pair_outputs(open, s).swap_remove(i);
    let cv = open.plant.var(&p.cv);
    let c = cv.map_or(f64::NAN, |v| open.x[v]);
    let cv_dim = cv.map_or(Dimension::DIMENSIONLESS, |v| open.plant.vars()[v].spec.dim);
    let mv_dim = open.plant.input(&p.mv).map_or(Dimension::DIMENSIONLESS, |i| open.plant.inputs()[i].dim);
    let gain_dim = mv_dim.checked_div(cv_dim).unwrap_or(Dimension::DIMENSIONLESS);
    PidConfig {
        pv: p.cv.clone(),
        output: Some(p.mv.clone()),
        sp: Setpoint::Value(si(c, cv_dim)),
        kc: si(kc, gain_dim),
        tau_i: Some(si(tau_i, Dimension::TIME)),
        tau_d: None,
        filter_ratio: None,
        action,
        bias: None,
        op_min: Some(si(lo, mv_dim)),
        op_max: Some(si(hi, mv_dim)),
        mode: Default::default(),
        op_manual: None,
    }
}

/// `v` (SI) as a flowsheet quantity: with its SI unit, so that the file a study writes reads
/// without a note of a bare number (a plain number for a dimensionless one).
pub(crate) fn si(v: f64, dim: Dimension) -> QuantityValue {
    if dim.is_dimensionless() { QuantityValue::Number(v) } else { QuantityValue::Text(format!("{v} {dim}")) }
}

/// The open plant with the candidate's loops, tuned by BLT, and its steady state.
/// The open plant with the candidate's loops closed (gains `kc`, resets `ti`, `actions`) and its
/// steady state: the CVs on their setpoints, which at steady state no tuning changes.
pub(super) fn closed_plant(
    open: &OpenPlant,
    s: &PairingStructure,
    kc: &[f64],
    ti: &[f64],
    actions: &[&str],
) -> Result<(Plant, Vec<f64>), CandidateFailure> {
    let mut edits: Vec<StructureEdit> = Vec::new();
    for i in 0..s.pairs.len() {
        let name = format!("pair{}", i + 1);
        let action = if actions[i] == "direct" { Action::Direct } else { Action::Reverse };
        let mut spec = loop_spec(open, s, i, kc[i], ti[i], action);
        if let Some(station) = remote_ratio(open, &s.pairs[i].mv, &name, &mut spec) {
            edits.extend(station);
        }
        edits.insert(0, StructureEdit::AddController { name, spec: Box::new(ControllerSpec::Pid(spec)) });
    }
    let v = open.plant.restructure(&edits)?;
    let guess = crate::screen::column::mapped_guess(&open.plant, &open.x, &v);
    let st = steady_state(&v, &v.input_values(), Some(&guess), &NewtonSettings::default())?;
    Ok((v, st.x))
}

/// When `mv` is a ratio station's local ratio (`<station>.ratio`, an input no controller can
/// drive): loop `name` becomes the station's master — `spec` loses its output and starts from the
/// ratio as its bias — and the edits that give the station the remote ratio `{"from": "<name>.op"}`
/// (Shinskey's ratio trimmed by a composition controller; the `(L/D)` and `(V/B)` configurations).
fn remote_ratio(open: &OpenPlant, mv: &str, name: &str, spec: &mut PidConfig) -> Option<[StructureEdit; 2]> {
    let station = mv.strip_suffix(".ratio")?;
    let Some(ControllerSpec::Ratio(cfg)) = open.plant.spec().controllers.get(station) else {
        return None;
    };
    let (u0, dim) = open.plant.input(mv).map(|i| (open.plant.inputs()[i].value, open.plant.inputs()[i].dim))?;
    spec.output = None;
    spec.bias = Some(si(u0, dim));
    let mut cfg = cfg.clone();
    cfg.ratio =
        plantwide_model::controllers::ratio::RatioValue::Remote { from: VarPath::controller_output(name, 0).into() };
    Some([
        StructureEdit::RemoveController(station.to_string()),
        StructureEdit::AddController { name: station.to_string(), spec: Box::new(ControllerSpec::Ratio(cfg)) },
    ])
}

/// The steady-state gain of each of the candidate's pairs in the open plant (SI: CV unit per MV
/// unit).
fn paired_gains(open: &OpenPlant, r: &PairingRequest, s: &PairingStructure) -> Vec<f64> {
    s.pairs
        .iter()
        .enumerate()
        .map(|(i, p)| r.mvs.iter().position(|m| *m == p.mv).map_or(f64::NAN, |j| open.gain[(i, j)]))
        .collect()
}

/// The actions that make each of the candidate's loops a negative feedback.
pub(super) fn actions(open: &OpenPlant, r: &PairingRequest, s: &PairingStructure) -> Vec<&'static str> {
    paired_gains(open, r, s).into_iter().map(|g| if g < 0.0 { "direct" } else { "reverse" }).collect()
}

/// Reset time of the trial loops \[s\]: at steady state no reset time matters (the integral only
/// holds the CV on its setpoint), and with the loops in manual, as BLT linearizes them, neither
/// does the gain.
const TRIAL_TAU_I: f64 = 1e3;

/// The open plant with the candidate's loops closed at a trial tuning, and its steady state: each
/// loop's gain the inverse of its own steady-state process gain `|g_ii|`, so every loop has gain 1
/// at steady state whatever the units of its CV and MV. A fixed gain (1 in SI units) is no trial
/// tuning: a reboiler duty (W) holding a bottoms mole fraction needs some 10⁷ W per unit, and at
/// 1 W per unit the loop barely acts, so its integral is all but free: on a 32-stage column the
/// scaled Jacobian's σ_min/σ_max fell to 9·10⁻¹⁵, under the steady state's null-space probe's
/// 10⁻¹², which rightly reported `pair1.I` as undetermined (with `1/|g_ii|`: 4·10⁻⁴).
pub(super) fn trial_plant(
    open: &OpenPlant,
    r: &PairingRequest,
    s: &PairingStructure,
) -> Result<(Plant, Vec<f64>), CandidateFailure> {
    let gains = paired_gains(open, r, s);
    if let Some((p, g)) = s.pairs.iter().zip(&gains).find(|(_, g)| !(g.is_finite() && **g != 0.0)) {
        return Err(CandidateFailure::NoPairedGain { cv: p.cv.clone(), mv: p.mv.clone(), gain: *g });
    }
    let kc: Vec<f64> = gains.iter().map(|g| 1.0 / g.abs()).collect();
    closed_plant(open, s, &kc, &vec![TRIAL_TAU_I; s.pairs.len()], &actions(open, r, s))
}

/// The open plant with the candidate's loops at the settings given.
fn given_plant(open: &OpenPlant, s: &PairingStructure, loops: &[(f64, f64, &'static str)]) -> TunedCandidate {
    let kc: Vec<f64> = loops.iter().map(|l| l.0).collect();
    let ti: Vec<f64> = loops.iter().map(|l| l.1).collect();
    let actions: Vec<&str> = loops.iter().map(|l| l.2).collect();
    let (plant, x) = closed_plant(open, s, &kc, &ti, &actions)?;
    Ok((plant, x, tuned(s, &kc, &ti, &actions, None)))
}

/// The tuning record of a candidate's loops at gains `kc`, resets `ti` and `actions`.
fn tuned(s: &PairingStructure, kc: &[f64], ti: &[f64], actions: &[&str], detuning: Option<f64>) -> Tuned {
    let loops = (0..s.pairs.len())
        .map(|i| TunedLoop {
            cv: s.pairs[i].cv.clone(),
            mv: s.pairs[i].mv.clone(),
            kc: kc[i],
            tau_i: ti[i],
            action: actions[i].into(),
        })
        .collect();
    let tau_i_max = ti.iter().copied().filter(|t| t.is_finite()).fold(0.0, f64::max);
    Tuned { detuning, loops, tau_i_max }
}

/// The open plant with the candidate's loops, tuned together by BLT on the exact linearization
/// (with `r`'s measurement delay), and its steady state.
pub(crate) fn tuned_plant(open: &OpenPlant, r: &PairingRequest, s: &PairingStructure) -> TunedCandidate {
    let (trial, x) = trial_plant(open, r, s)?;
    let loops: Vec<_> =
        (0..s.pairs.len()).map(|i| plant_loop(&trial, &format!("pair{}", i + 1))).collect::<Result<_, _>>()?;
    let t = blt_loops(&trial, &x, &loops, r.dynamic.measurement)?;
    let kc: Vec<f64> = t.loops.iter().map(|l| l.kc.abs()).collect();
    let ti: Vec<f64> = t.loops.iter().map(|l| l.tau_i.unwrap_or(f64::INFINITY)).collect();
    let actions: Vec<&str> = t.loops.iter().map(|l| l.action).collect();
    let (plant, x) = closed_plant(open, s, &kc, &ti, &actions)?;
    Ok((plant, x, tuned(s, &kc, &ti, &actions, t.detuning_factor)))
}

/// Where in a run its disturbance steps, as a fraction of the run's duration.
pub const STEP_AT: f64 = 0.02;

/// A controller output a run watches for saturation: its variable, the MV it drives and its
/// limits (SI).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Limited {
    /// The controller's output variable (`pair1.op`, `mpc.op2`).
    pub op: String,
    /// The input it drives.
    pub mv: String,
    /// Lower limit.
    pub lo: f64,
    /// Upper limit.
    pub hi: f64,
}

/// The outputs of a candidate's loops with their limits: `[0, 2 u₀]` (or `[2 u₀, 0]`) for an MV
/// whose steady value in the open plant (which holds every MV) is `u₀`.
pub(crate) fn pair_outputs(open: &OpenPlant, s: &PairingStructure) -> Vec<Limited> {
    (0..s.pairs.len())
        .map(|i| {
            let mv = &s.pairs[i].mv;
            let u0 = open.plant.input(mv).map_or(0.0, |m| open.plant.inputs()[m].value);
            let (lo, hi) = (f64::min(0.0, 2.0 * u0), f64::max(0.0, 2.0 * u0));
            Limited { op: VarPath::controller_output(&format!("pair{}", i + 1), 0).into(), mv: mv.clone(), lo, hi }
        })
        .collect()
}

/// The scenario of a dynamic test's run: `d`'s input stepped by `change` (SI) at [`STEP_AT`] of
/// `duration` \[s\], `record` recorded at 500 intervals.
pub(crate) fn scenario(d: &super::Disturbance, change: f64, duration: f64, record: &[&String]) -> ScenarioSpec {
    let seconds = |t: f64| QuantityValue::Text(format!("{t} s"));
    ScenarioSpec {
        format_version: SCENARIO_FORMAT_VERSION,
        name: format!("{} step", d.path),
        duration: seconds(duration),
        integrator: IntegratorSpec { rtol: Some(1e-6), ..IntegratorSpec::default() },
        events: vec![EventSpec::Step {
            at: seconds(STEP_AT * duration),
            path: d.path.clone(),
            to: None,
            by: Some(QuantityValue::Number(change)),
        }],
        record: RecordSpec {
            interval: Some(seconds(duration / 500.0)),
            paths: record.iter().map(|p| RecordPathSpec::Path(p.to_string())).collect(),
            ..RecordSpec::default()
        },
        description: String::new(),
        when: Vec::new(),
        sampling: Default::default(),
        analyzers: Default::default(),
        snapshots: Vec::new(),
    }
}

/// One disturbance step on a controlled plant from its steady state `x`: the figures of `r`'s CVs
/// and recorded outputs, the MVs of `ops` that reached a limit, and what the plant's model
/// predictive controllers did.
pub(crate) fn run(
    plant: &Plant,
    x: &[f64],
    r: &PairingRequest,
    d: &super::Disturbance,
    duration: f64,
    ops: &[Limited],
) -> Result<(DisturbanceRun, Vec<plantwide_solve::dynamic::MpcLog>), CandidateFailure> {
    let u0 =
        plantwide_flowsheet::overrides::resolve_input(plant, &d.path).map_or(f64::NAN, |i| plant.inputs()[i].value);
    let watched = watched(r);
    let record: Vec<&String> = watched.iter().copied().chain(ops.iter().map(|o| &o.op)).collect();
    let spec = scenario(d, d.change(u0), duration, &record);
    let scenario = plantwide_flowsheet::scenario::resolve(&spec, plant, "screen")?;
    let res = simulate(plant, &scenario, Start::Steady(x), "screen", &mut |_| {}).map_err(Box::new)?;
    let figures = summary(&res);
    let cvs = watched
        .iter()
        .map(|&cv| {
            let f = figures.iter().find(|f| &f.path == cv);
            CvFigures {
                cv: cv.clone(),
                iae: f.map_or(f64::NAN, |f| f.iae),
                max_deviation: f.map_or(f64::NAN, |f| f.max_deviation),
                settling_time: f.and_then(|f| f.settling_time),
            }
        })
        .collect();
    let at = |v: f64, l: f64| l.is_finite() && (v - l).abs() <= 1e-9 * l.abs().max(1e-12);
    let saturated = ops
        .iter()
        .enumerate()
        .filter(|(i, o)| {
            let k = watched.len() + i;
            res.rows.iter().any(|row| at(row[k], o.lo) || at(row[k], o.hi))
        })
        .map(|(_, o)| o.mv.clone())
        .collect();
    let series = (0..watched.len()).map(|k| res.rows.iter().map(|row| row[k]).collect()).collect();
    let run = DisturbanceRun {
        disturbance: d.label(),
        cvs,
        saturated,
        failure: None,
        lost: None,
        times: res.times.clone(),
        series,
    };
    Ok((run, res.mpc))
}
