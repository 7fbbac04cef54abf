//! The snapshot format: the plant state, the driver state and the full BDF history (difference
//! array, order, step, Jacobian), so that resuming continues the uninterrupted trajectory exactly.
//! Resuming a changed plant (another fingerprint, other variables or inputs) maps the state and
//! the input waveforms by path and restarts the integrator at order 1.

use serde::{Deserialize, Serialize};

use plantwide_flowsheet::Plant;
use plantwide_flowsheet::scenario::Scenario;

use super::SimError;
use super::waveform::Waveform;
use crate::dae::BdfState;

/// Version of the snapshot format.
pub const SNAPSHOT_VERSION: u32 = 1;

/// The driver's own state (part of a snapshot).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DriverState {
    /// Input waveforms, one per input (plant inputs, then the analyzers' held inputs).
    pub waveforms: Vec<Waveform>,
    /// Values to return to after a pulse or sinusoid.
    pub saved: Vec<Option<f64>>,
    /// Paths of inputs frozen by `valve_stuck` or `feed_lost` events.
    pub stuck: Vec<String>,
    /// What undoes each fault still in force (a repair), in the order of `stuck`.
    #[serde(default)]
    pub faults: Vec<Fault>,
    /// Per analyzer: frozen (no new samples) by an `analyzer_frozen` event.
    #[serde(default)]
    pub frozen: Vec<bool>,
    /// Index of the next scenario event.
    pub next_event: usize,
    /// Next scan number of each sampled controller (time = k · scan).
    pub next_scan: Vec<u64>,
    /// Next sample number of each analyzer (time = k · sample time).
    pub next_sample: Vec<u64>,
    /// Pending analyzer results `(release time [s], value)`, per analyzer.
    pub pending: Vec<Vec<(f64, f64)>>,
    /// Next recording number (time = k · interval).
    pub next_record: u64,
    /// Snapshots already taken.
    pub snapshots_done: Vec<bool>,
    /// The conditions (`when`) that have acted, by [`Condition::key`](plantwide_flowsheet::scenario::Condition::key).
    #[serde(default)]
    pub fired: Vec<String>,
    /// The events of conditions that have acted, not applied yet, by the time they are due.
    #[serde(default)]
    pub triggered: Vec<Triggered>,
}

/// An event a condition started: the `event`-th of its `then` list, due its delay after `at`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Triggered {
    /// When the condition acted [s].
    pub at: f64,
    /// Its due time [s]: `at` plus the event's delay.
    pub due: f64,
    /// The condition, by [`Condition::key`](plantwide_flowsheet::scenario::Condition::key).
    pub when: String,
    /// The event's index in the condition's `then` list.
    pub event: usize,
}

impl DriverState {
    /// The state at the start of a run of `sc` on the (rewired) `plant`: every input constant at
    /// its value, nothing due yet but the first scan, sample and recording.
    pub(super) fn start(plant: &Plant, sc: &Scenario) -> DriverState {
        DriverState {
            waveforms: plant.inputs().iter().map(|i| Waveform::Constant(i.value)).collect(),
            saved: vec![None; plant.inputs().len()],
            stuck: Vec::new(),
            faults: Vec::new(),
            frozen: vec![false; sc.analyzers.len()],
            next_event: 0,
            next_scan: vec![1; sc.sampling.len()],
            next_sample: vec![0; sc.analyzers.len()],
            pending: vec![Vec::new(); sc.analyzers.len()],
            next_record: 0,
            snapshots_done: vec![false; sc.snapshots.len()],
            fired: Vec::new(),
            triggered: Vec::new(),
        }
    }
}

/// A fault in force on an input and what its repair gives the input back to: the controller
/// output that drove it (by path, so that a snapshot resumed on a changed plant still finds it),
/// the sampled controller whose scans held it, or else its value before the fault.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fault {
    /// The input's path.
    pub path: String,
    /// Its value just before the fault (SI).
    pub before: f64,
    /// The controller output variable that drove it, if one did.
    pub driven_by: Option<String>,
    /// The sampled controller (index in the scenario's `sampling`) and output variable whose
    /// scans held it, if any.
    pub scanned_by: Option<(usize, String)>,
    /// The input as the scenario has it behind the fault: its waveform when the fault came, then
    /// changed by the scenario's events on the input during the fault (a step, a pulse's end),
    /// which do not reach the plant; a free input's repair gives it back this.
    #[serde(default)]
    pub behind: Option<Waveform>,
}

/// Everything needed to continue a run (serialize it with serde).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// Format version.
    pub format_version: u32,
    /// Identifies the plant description the state belongs to (chosen by the caller, e.g. a hash
    /// of the flowsheet text and overrides); a different one means "parameters changed".
    pub fingerprint: String,
    /// Time [s].
    pub t: f64,
    /// Paths of the state vector entries (plant variables, then totals).
    pub paths: Vec<String>,
    /// Paths of the inputs (plant inputs, then the analyzers' held inputs).
    pub inputs: Vec<String>,
    /// Driver state.
    pub driver: DriverState,
    /// Integrator state (its `d[0]` is the state vector).
    pub integrator: BdfState,
}

/// What a run resumed from a snapshot starts with.
pub(super) struct Resumed {
    /// The driver state, its waveforms mapped to this plant's inputs.
    pub(super) driver: DriverState,
    /// The integrator history to restore, if the plant is the snapshot's own (otherwise the run
    /// restarts at order 1).
    pub(super) integrator: Option<BdfState>,
}

/// Fit the driver's counters to `sc` at the snapshot's time `t`. A snapshot resumed with the
/// scenario it was taken in keeps them (the continuous run's own, so resuming is exact). With
/// another scenario (other events, recording interval, scan or sample times) a counter of the
/// old one means another instant in the new: the next event index would skip or replay events
/// and the next recording could lie before `t` (rows extrapolated backwards). Such counters are
/// recomputed from `t`: the next event is the first at or after `t`, the next recording, scan
/// and sample the first instant after it.
fn realign(driver: &mut DriverState, sc: &Scenario, t: f64) {
    let fits = |k: u64, period: f64| (k == 0 || (k - 1) as f64 * period <= t) && k as f64 * period >= t;
    let k = driver.next_event;
    let event_fits =
        k <= sc.events.len() && (k == 0 || sc.events[k - 1].t <= t) && sc.events.get(k).is_none_or(|e| e.t >= t);
    if !event_fits {
        driver.next_event = sc.events.partition_point(|e| e.t < t);
    }
    if !fits(driver.next_record, sc.interval) {
        driver.next_record = super::instants::after(t, sc.interval);
    }
    for (k, &(_, scan)) in driver.next_scan.iter_mut().zip(&sc.sampling) {
        if !fits(*k, scan) {
            *k = super::instants::after(t, scan);
        }
    }
    for (k, &(_, ts, _)) in driver.next_sample.iter_mut().zip(&sc.analyzers) {
        if !fits(*k, ts) {
            *k = super::instants::after(t, ts);
        }
    }
}

/// Keep the acted conditions and their pending events that `sc` has (by key and event index): a
/// snapshot resumed with its own scenario keeps them all; with another, that scenario's
/// conditions are armed afresh and the old ones' pending events dropped.
fn keep_conditions(driver: &mut DriverState, sc: &Scenario) {
    let keys: Vec<String> = sc.conditions.iter().map(|c| c.key()).collect();
    driver.fired.retain(|f| keys.contains(f));
    driver.triggered.retain(|t| {
        let c = keys.iter().position(|k| *k == t.when);
        c.is_some_and(|c| t.event < sc.conditions[c].then.len()) && t.due.is_finite() && t.due >= t.at
    });
}

/// The state vector of length `n_state` for a run resumed from `s`: the plant's initial guess,
/// overwritten by path with the snapshot's values (`paths` are this run's state paths; entries
/// the snapshot lacks keep the guess, quadratures start at 0).
pub(super) fn mapped_state(plant: &Plant, paths: &[String], n_state: usize, s: &Snapshot) -> Vec<f64> {
    let mut v = plant.initial_guess();
    v.resize(n_state, 0.0);
    for (p, val) in s.paths.iter().zip(s.integrator.d.first().into_iter().flatten()) {
        if let Some(k) = paths.iter().position(|q| q == p) {
            v[k] = *val;
        }
    }
    v
}

/// Resume from `s`: check that it fits `sc` and the plant, freeze the inputs its stuck valves
/// froze (and drop them from the `sampled` controllers' held inputs), and map its driver state
/// onto `fresh` (the state a new run would start with). `paths` are this run's state paths.
pub(super) fn resume(
    plant: &mut Plant,
    sc: &Scenario,
    s: &Snapshot,
    fingerprint: &str,
    paths: &[String],
    fresh: DriverState,
    sampled: &mut [Vec<(usize, usize)>],
) -> Result<Resumed, SimError> {
    let file = plant.file().to_string();
    let bad = |reason: String| SimError::Snapshot { file: file.clone(), reason };
    if s.format_version != SNAPSHOT_VERSION {
        return Err(bad(format!("snapshot format_version {} (this build reads {SNAPSHOT_VERSION})", s.format_version)));
    }
    for p in &s.driver.stuck {
        let i = plant
            .inputs()
            .iter()
            .position(|i| i.path == *p)
            .ok_or_else(|| bad(format!("no input `{}` to freeze", plantwide_model::limits::clip(p))))?;
        plant.hold_input(i);
        sampled.iter_mut().for_each(|s| s.retain(|&(j, _)| j != i));
    }
    let input_paths: Vec<String> = plant.inputs().iter().map(|i| i.path.clone()).collect();
    if s.inputs.len() != s.driver.waveforms.len() || s.inputs.len() != s.driver.saved.len() {
        return Err(bad(format!(
            "{} inputs but {} waveforms and {} saved values: the file was changed after it was written",
            s.inputs.len(),
            s.driver.waveforms.len(),
            s.driver.saved.len()
        )));
    }
    let same = s.fingerprint == fingerprint && s.paths == paths && s.inputs == input_paths;
    let mut driver = s.driver.clone();
    if !same {
        // Map the input waveforms by path; everything else keeps its meaning by index.
        let mut waves = fresh.waveforms.clone();
        let mut saved = vec![None; input_paths.len()];
        for (k, p) in s.inputs.iter().enumerate() {
            if let Some(j) = input_paths.iter().position(|q| q == p) {
                waves[j] = s.driver.waveforms[k];
                saved[j] = s.driver.saved[k];
            }
        }
        driver.waveforms = waves;
        driver.saved = saved;
    }
    if driver.next_scan.len() != fresh.next_scan.len() || driver.next_sample.len() != fresh.next_sample.len() {
        return Err(bad("the scenario's sampled controllers or analyzers differ from the snapshot's".into()));
    }
    driver.snapshots_done.resize(sc.snapshots.len(), true);
    driver.frozen.resize(sc.analyzers.len(), false);
    // Checked here, where a snapshot that does not fit is refused as such: found at the start of
    // the run, the run had no state to hand out with its failure.
    if same {
        s.integrator.check(paths.len()).map_err(|why| bad(format!("its integrator state: {why}")))?;
    }
    if sc.duration <= s.t {
        return Err(bad(format!(
            "it was taken at t = {} s and the scenario ends at {} s: a resumed run goes on from the snapshot's \
             time, so the duration must reach past it",
            s.t, sc.duration
        )));
    }
    realign(&mut driver, sc, s.t);
    keep_conditions(&mut driver, sc);
    Ok(Resumed { driver, integrator: same.then(|| s.integrator.clone()) })
}
