//! Dynamic simulation of a [`Plant`] under a [`Scenario`]: the plant DAE `M dx/dt = f(x, u(t), t)`
//! integrated by [`Bdf`], stopped exactly at every discrete time (scenario events, controller scans,
//! analyzer samples and results), where the inputs change, the algebraic variables are made
//! consistent and the integrator restarts at order 1.
//!
//! **Inputs** are piecewise [`Waveform`]s (constant, ramp, sinusoid), changed only at events.
//! **Discrete controller behaviour** rewires the plant: a sampled controller's driven inputs read a
//! held input (set to the controller's output at every scan: zero-order hold), an analyzer's
//! controller reads a held copy of its measurement (sampled every `sample_time`, released
//! `dead_time` later), and a stuck valve's input stops following its controller.
//! **Totals**: quadrature variables `q_{s,c}` with `dq/dt = F_s x_{s,c}` are integrated with the
//! plant by the same BDF formula (excluded from error control), so that `Δ(holdup)` and
//! `∫(in − out) dt` obey the same discrete relation and can be compared to rounding.
//! **Conservation**: the boundary streams (outlets of `feed` units, inlets of `product` units)
//! are integrated the same way, whether recorded or not, and at the end of the run
//! `Δ(Σ_units holdup) = ∫(Σ_feeds − Σ_products) F z dt` is checked per component (mass for a
//! plant with reactions) to [`CONSERVATION_TOL`] ([`conservation`]); a run that fails it is a
//! [`SimError::Conservation`].
//! **Recording** interpolates the BDF polynomial at every recording time; at a scenario event a
//! row just before and one just after it are added (same time).
//! **Snapshots** hold the plant state, the driver state and the full BDF history (difference array,
//! order, step, Jacobian): resuming continues the uninterrupted trajectory exactly. A snapshot is
//! taken at the end of the first step at or after its time, so taking it does not change the
//! steps. Resuming a changed plant (other tunings or parameters) maps the state by variable path and
//! restarts at order 1 from consistent algebraic variables.

use serde::{Deserialize, Serialize};

use plantwide_flowsheet::scenario::{Action, Scenario};
use plantwide_flowsheet::{BlockKind, InputInfo, Plant, Read};
use plantwide_model::stream::{F, Z0};

use crate::dae::{Bdf, BdfSettings, BdfState, BdfStats, DaeError, DaeIntegrator, DaeSystem};
use crate::{PlantSystem, System};

pub mod conservation;
pub use conservation::{CONSERVATION_TOL, Conservation, ConservationError};

/// Version of the snapshot format.
pub const SNAPSHOT_VERSION: u32 = 1;

/// An input's value as a function of time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Waveform {
    /// Constant.
    Constant(f64),
    /// From `v0` at `t0` linearly to `v1` at `t1` [s], then `v1`.
    Ramp {
        /// Start [s].
        t0: f64,
        /// Value at start.
        v0: f64,
        /// End [s].
        t1: f64,
        /// Final value.
        v1: f64,
    },
    /// `base + amplitude·sin(2π(t − t0)/period)`.
    Sine {
        /// Start [s].
        t0: f64,
        /// Mean value.
        base: f64,
        /// Amplitude.
        amplitude: f64,
        /// Period [s].
        period: f64,
    },
}

impl Waveform {
    /// Value at `t`.
    pub fn at(&self, t: f64) -> f64 {
        match *self {
            Waveform::Constant(v) => v,
            Waveform::Ramp { t0, v0, t1, v1 } => {
                if t >= t1 {
                    v1
                } else {
                    v0 + (v1 - v0) * (t - t0) / (t1 - t0)
                }
            }
            Waveform::Sine { t0, base, amplitude, period } => {
                base + amplitude * (std::f64::consts::TAU * (t - t0) / period).sin()
            }
        }
    }
}

/// The plant at time-varying inputs, with quadratures of stream component flows appended.
struct PlantDae<'a> {
    plant: &'a Plant,
    waves: &'a [Waveform],
    mass: Vec<(usize, usize)>,
    /// Stream offsets of the totals.
    totals: Vec<usize>,
    n_plant: usize,
    nc: usize,
}

impl<'a> PlantDae<'a> {
    fn new(plant: &'a Plant, waves: &'a [Waveform], totals: &[usize]) -> PlantDae<'a> {
        let n_plant = plant.n_vars();
        let nc = plant.components.len();
        let u: Vec<f64> = waves.iter().map(|w| w.at(0.0)).collect();
        let mut mass = PlantSystem::new(plant, &u).mass();
        let totals: Vec<usize> = totals.iter().map(|&s| plant.streams[s].offset).collect();
        mass.extend((n_plant..n_plant + totals.len() * nc).map(|k| (k, k)));
        PlantDae { plant, waves, mass, totals, n_plant, nc }
    }
    fn u(&self, t: f64) -> Vec<f64> {
        self.waves.iter().map(|w| w.at(t)).collect()
    }
}

impl DaeSystem for PlantDae<'_> {
    fn n(&self) -> usize {
        self.n_plant + self.totals.len() * self.nc
    }
    fn residual(&self, t: f64, x: &[f64], r: &mut [f64]) {
        let np = self.n_plant;
        self.plant.residual(&x[..np], &self.u(t), t, &mut r[..np]);
        for (k, &o) in self.totals.iter().enumerate() {
            for c in 0..self.nc {
                r[np + k * self.nc + c] = x[o + F] * x[o + Z0 + c];
            }
        }
    }
    fn jacobian(&self, t: f64, x: &[f64], r: &mut [f64], jac: &mut Vec<(usize, usize, f64)>) {
        let np = self.n_plant;
        let mut ju = Vec::new();
        self.plant.jacobian(&x[..np], &self.u(t), t, &mut r[..np], jac, &mut ju);
        for (k, &o) in self.totals.iter().enumerate() {
            for c in 0..self.nc {
                let row = np + k * self.nc + c;
                r[row] = x[o + F] * x[o + Z0 + c];
                jac.push((row, o + F, x[o + Z0 + c]));
                jac.push((row, o + Z0 + c, x[o + F]));
            }
        }
    }
    fn mass(&self) -> &[(usize, usize)] {
        &self.mass
    }
    fn nominal(&self, i: usize) -> f64 {
        if i < self.n_plant { self.plant.vars[i].spec.nominal } else { 1.0 }
    }
    fn bounds(&self, i: usize) -> (f64, f64) {
        if i < self.n_plant {
            let s = &self.plant.vars[i].spec;
            (s.lower, s.upper)
        } else {
            (f64::NEG_INFINITY, f64::INFINITY)
        }
    }
    fn error_controlled(&self, i: usize) -> bool {
        i < self.n_plant && self.mass.iter().any(|&(_, j)| j == i)
    }
    fn quadrature(&self, i: usize) -> bool {
        i >= self.n_plant
    }
}

/// The driver's own state (part of a snapshot).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DriverState {
    /// Input waveforms, one per input (plant inputs, then the analyzers' held inputs).
    pub waveforms: Vec<Waveform>,
    /// Values to return to after a pulse or sinusoid.
    pub saved: Vec<Option<f64>>,
    /// Paths of inputs frozen by `valve_stuck` events.
    pub stuck: Vec<String>,
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

/// Where a run starts.
#[derive(Debug, Clone, Copy)]
pub enum Start<'a> {
    /// From this state (a converged steady state) at t = 0.
    Steady(&'a [f64]),
    /// From a snapshot.
    Snapshot(&'a Snapshot),
}

/// What the driver reports while it runs.
#[derive(Debug)]
pub enum Progress<'a> {
    /// A step was taken.
    Step {
        /// Time reached [s].
        t: f64,
        /// End of the run [s].
        duration: f64,
    },
    /// A snapshot requested by the scenario is ready to be written.
    Snapshot {
        /// File named in the scenario.
        file: &'a str,
        /// The snapshot.
        snapshot: &'a Snapshot,
    },
}

/// Why a simulation stopped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// The integrator failed.
    #[error("{file}: integration failed: {source}{detail}")]
    Integration {
        /// Flowsheet file.
        file: String,
        /// Cause.
        source: DaeError,
        /// The equation and variable concerned, when known.
        detail: String,
        /// What was recorded up to the failure (the trends that lead to it).
        partial: Box<SimulationResult>,
    },
    /// The run finished but does not conserve material (a unit's balance or holdup is wrong, or
    /// the integration is not to be trusted).
    #[error("{file}: {source}")]
    Conservation {
        /// Flowsheet file.
        file: String,
        /// The balance that fails.
        source: ConservationError,
        /// The whole run.
        result: Box<SimulationResult>,
    },
    /// A snapshot does not fit this plant.
    #[error("{file}: the snapshot does not fit this plant: {reason}")]
    Snapshot {
        /// Flowsheet file.
        file: String,
        /// What is wrong.
        reason: String,
    },
}

/// One recorded column.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Column {
    /// Path.
    pub path: String,
    /// Output unit.
    pub unit: String,
    /// SI unit.
    pub si_unit: String,
}

/// A finished run (or, in [`SimError::Integration`], the part of it before the failure).
#[derive(Debug, Clone, PartialEq)]
pub struct SimulationResult {
    /// Recorded columns.
    pub columns: Vec<Column>,
    /// Recording times [s].
    pub times: Vec<f64>,
    /// Rows of SI values, one per time.
    pub rows: Vec<Vec<f64>>,
    /// Reference of each column over time (the controller's setpoint for a controlled variable),
    /// `None` to measure deviations from the first recorded value.
    pub references: Vec<Option<Vec<f64>>>,
    /// Scenario events applied: `(time [s], origin)`.
    pub events: Vec<(f64, String)>,
    /// Final state (plant variables, then totals).
    pub x: Vec<f64>,
    /// Final time [s].
    pub t: f64,
    /// Integrator counters.
    pub stats: BdfStats,
    /// Material balances from the start of the run (or the resumed snapshot) to `t`.
    pub conservation: Conservation,
}

/// Run `scenario` on `plant` from `start`. The plant is rewired for sampled controllers, analyzers
/// and stuck valves (and keeps that wiring). `fingerprint` identifies the plant description in
/// snapshots. Snapshots the scenario asks for are handed to `observer`, with the progress.
pub fn simulate(
    plant: &mut Plant,
    scenario: &Scenario,
    start: Start<'_>,
    fingerprint: &str,
    observer: &mut dyn FnMut(Progress<'_>),
) -> Result<SimulationResult, SimError> {
    let file = plant.file.clone();
    let mut d = Driver::new(plant, scenario, start, fingerprint)?;
    if let Err(source) = d.run(observer) {
        let detail = match source {
            DaeError::Initialization { equation, .. } if equation < d.plant.n_eqs() => {
                let var = d.plant.equation_variable(equation).map_or("-".to_string(), |v| d.plant.vars[v].path.clone());
                format!(
                    " ({}, variable {var}; a vessel running dry or overflowing, or a flow reversing, ends a run this way)",
                    d.plant.equation_name(equation)
                )
            }
            _ => String::new(),
        };
        return Err(SimError::Integration { file, source, detail, partial: Box::new(d.finish()) });
    }
    let res = d.finish();
    match res.conservation.check(CONSERVATION_TOL) {
        Ok(()) => Ok(res),
        Err(source) => Err(SimError::Conservation { file, source, result: Box::new(res) }),
    }
}

struct Driver<'p> {
    plant: &'p mut Plant,
    sc: &'p Scenario,
    st: DriverState,
    bdf: Bdf,
    fingerprint: String,
    /// Per sampled controller: (driven input, its controller output variable).
    sampled: Vec<Vec<(usize, usize)>>,
    /// Per analyzer: (held input, measured variable).
    analyzers: Vec<(usize, usize)>,
    times: Vec<f64>,
    rows: Vec<Vec<f64>>,
    refs: Vec<Option<usize>>,
    ref_rows: Vec<Vec<f64>>,
    events: Vec<(f64, String)>,
    /// Start from a snapshot of a changed plant: restart instead of restoring the history.
    restore: Option<BdfState>,
    x0: Vec<f64>,
    t0: f64,
    /// Streams integrated as quadratures: the scenario's totals, then the boundary streams not
    /// among them.
    quad: Vec<usize>,
    /// Boundary streams: (index into `quad`, +1 feed outlet / −1 product inlet).
    boundary: Vec<(usize, f64)>,
}

/// Make input `i` read its own value instead of its controller's output; returns that output
/// variable if it was driven.
fn free_input(plant: &mut Plant, i: usize) -> Option<usize> {
    let op = plant.inputs[i].driven_by.take()?;
    let slen = plant.stream_layout.len();
    for b in &mut plant.blocks {
        if let Some(k) = b.input_ids.iter().position(|&id| id == i) {
            let pos = if b.kind == BlockKind::Unit { b.layout.n_inlets * slen + k } else { k };
            b.reads[pos] = Read::Input(i);
        }
    }
    Some(op)
}

impl<'p> Driver<'p> {
    fn new(
        plant: &'p mut Plant,
        sc: &'p Scenario,
        start: Start<'_>,
        fingerprint: &str,
    ) -> Result<Driver<'p>, SimError> {
        let n_plant = plant.n_vars();
        let nc = plant.components.len();
        let (quad, boundary) = quadrature_streams(plant, &sc.totals);
        let n_total = n_plant + quad.len() * nc;
        let x_start: Vec<f64> = match start {
            Start::Steady(x) => {
                let mut v = x.to_vec();
                v.resize(n_total, 0.0);
                v
            }
            Start::Snapshot(s) => {
                let mut v = plant.initial_guess();
                v.resize(n_total, 0.0);
                let paths = state_paths(plant, &quad, sc.totals.len());
                for (p, val) in s.paths.iter().zip(&s.integrator.d[0]) {
                    if let Some(k) = paths.iter().position(|q| q == p) {
                        v[k] = *val;
                    }
                }
                v
            }
        };
        // Controllers whose measurement an analyzer delivers: which variable they read, before rewiring.
        let refs = sc.record.iter().map(|r| reference_of(plant, r.source)).collect();
        let mut waveforms: Vec<Waveform> = plant.inputs.iter().map(|i| Waveform::Constant(i.value)).collect();
        let mut analyzers = Vec::new();
        for &(b, _, _) in &sc.analyzers {
            let block = &plant.blocks[b];
            let pos = block.layout.n_inputs;
            let Read::Var(v) = block.reads[pos] else {
                return Err(SimError::Snapshot {
                    file: plant.file.clone(),
                    reason: format!("controller `{}` already reads a held measurement", block.name),
                });
            };
            let input = plant.inputs.len();
            let info = InputInfo {
                path: format!("{}.analyzer", block.name),
                dim: plant.vars[v].spec.dim,
                value: x_start[v],
                driven_by: None,
                block: b,
            };
            plant.inputs.push(info);
            plant.blocks[b].reads[pos] = Read::Input(input);
            waveforms.push(Waveform::Constant(x_start[v]));
            analyzers.push((input, v));
        }
        let mut sampled = Vec::new();
        for &(b, _) in &sc.sampling {
            let driven: Vec<usize> = (0..plant.inputs.len())
                .filter(|&i| plant.inputs[i].driven_by.is_some_and(|v| plant.vars[v].block == b))
                .collect();
            let pairs: Vec<(usize, usize)> =
                driven.into_iter().filter_map(|i| free_input(plant, i).map(|op| (i, op))).collect();
            for &(i, op) in &pairs {
                waveforms[i] = Waveform::Constant(x_start[op]);
            }
            sampled.push(pairs);
        }
        let mut st = DriverState {
            waveforms,
            saved: vec![None; plant.inputs.len()],
            stuck: Vec::new(),
            next_event: 0,
            next_scan: vec![1; sc.sampling.len()],
            next_sample: vec![0; sc.analyzers.len()],
            pending: vec![Vec::new(); sc.analyzers.len()],
            next_record: 0,
            snapshots_done: vec![false; sc.snapshots.len()],
        };
        let mut restore = None;
        let mut t0 = 0.0;
        if let Start::Snapshot(s) = start {
            t0 = s.t;
            let file = plant.file.clone();
            let bad = |reason: String| SimError::Snapshot { file: file.clone(), reason };
            if s.format_version != SNAPSHOT_VERSION {
                return Err(bad(format!(
                    "snapshot format_version {} (this build reads {SNAPSHOT_VERSION})",
                    s.format_version
                )));
            }
            for p in &s.driver.stuck {
                let i = plant
                    .inputs
                    .iter()
                    .position(|i| i.path == *p)
                    .ok_or_else(|| bad(format!("no input `{p}` to freeze")))?;
                free_input(plant, i);
                sampled.iter_mut().for_each(|s: &mut Vec<(usize, usize)>| s.retain(|&(j, _)| j != i));
            }
            let input_paths: Vec<String> = plant.inputs.iter().map(|i| i.path.clone()).collect();
            let same = s.fingerprint == fingerprint
                && s.paths == state_paths(plant, &quad, sc.totals.len())
                && s.inputs == input_paths;
            let mut driver = s.driver.clone();
            if !same {
                // Map the input waveforms by path; everything else keeps its meaning by index.
                let mut waves = st.waveforms.clone();
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
            if driver.next_scan.len() != st.next_scan.len() || driver.next_sample.len() != st.next_sample.len() {
                return Err(bad("the scenario's sampled controllers or analyzers differ from the snapshot's".into()));
            }
            driver.snapshots_done.resize(sc.snapshots.len(), true);
            st = driver;
            if same {
                restore = Some(s.integrator.clone());
            }
        }
        let bdf = Bdf::new(BdfSettings {
            rtol: sc.rtol,
            atol: sc.atol,
            max_step: sc.max_step,
            first_step: sc.first_step,
            ..BdfSettings::default()
        });
        Ok(Driver {
            plant,
            sc,
            st,
            bdf,
            fingerprint: fingerprint.to_string(),
            sampled,
            analyzers,
            times: Vec::new(),
            rows: Vec::new(),
            refs,
            ref_rows: Vec::new(),
            events: Vec::new(),
            restore,
            x0: x_start,
            t0,
            quad,
            boundary,
        })
    }

    fn t(&self) -> f64 {
        self.bdf.t()
    }

    /// The earliest discrete time after `t`.
    fn next_stop(&self, t: f64) -> f64 {
        let mut next = self.sc.duration;
        if let Some(e) = self.sc.events.get(self.st.next_event) {
            next = next.min(e.t);
        }
        for (k, &(_, scan)) in self.sc.sampling.iter().enumerate() {
            next = next.min(self.st.next_scan[k] as f64 * scan);
        }
        for (k, &(_, ts, _)) in self.sc.analyzers.iter().enumerate() {
            next = next.min(self.st.next_sample[k] as f64 * ts);
            for &(release, _) in &self.st.pending[k] {
                next = next.min(release);
            }
        }
        next.max(t)
    }

    fn push_row(&mut self, t: f64, x: &[f64]) {
        let (row, refs) = row_at(self.plant, self.sc, &self.refs, &self.st.waveforms, t, x);
        self.times.push(t);
        self.rows.push(row);
        self.ref_rows.push(refs);
    }

    /// Apply everything due at the current time; true if the integrator must restart.
    fn apply_due(&mut self, x: &mut [f64]) -> bool {
        self.apply_due_at(self.t(), x)
    }

    /// Apply everything due at `t` (the integrator's time, or the start before it is started).
    fn apply_due_at(&mut self, t: f64, x: &mut [f64]) -> bool {
        let mut changed = false;
        let mut scenario_event = false;
        while let Some(e) = self.sc.events.get(self.st.next_event).filter(|e| e.t <= t) {
            if !scenario_event && self.times.last() != Some(&t) {
                self.push_row(t, x);
            }
            scenario_event = true;
            let (action, origin) = (e.action.clone(), e.origin.clone());
            self.apply(&action, t, x);
            self.events.push((t, origin));
            self.st.next_event += 1;
            changed = true;
        }
        for (k, &(_, scan)) in self.sc.sampling.iter().enumerate() {
            if self.st.next_scan[k] as f64 * scan <= t {
                for &(i, op) in &self.sampled[k] {
                    changed |= self.st.waveforms[i] != Waveform::Constant(x[op]);
                    self.st.waveforms[i] = Waveform::Constant(x[op]);
                }
                self.st.next_scan[k] = (t / scan).floor() as u64 + 1;
            }
        }
        for (k, &(_, ts, td)) in self.sc.analyzers.iter().enumerate() {
            let (input, v) = self.analyzers[k];
            if self.st.next_sample[k] as f64 * ts <= t {
                self.st.pending[k].push((self.st.next_sample[k] as f64 * ts + td, x[v]));
                self.st.next_sample[k] = (t / ts).floor() as u64 + 1;
            }
            let due: Vec<(f64, f64)> = self.st.pending[k].iter().copied().filter(|&(r, _)| r <= t).collect();
            if let Some(&(_, value)) = due.last() {
                changed |= self.st.waveforms[input] != Waveform::Constant(value);
                self.st.waveforms[input] = Waveform::Constant(value);
            }
            self.st.pending[k].retain(|&(r, _)| r > t);
        }
        changed || scenario_event
    }

    fn apply(&mut self, action: &Action, t: f64, x: &[f64]) {
        let w = &mut self.st.waveforms;
        match *action {
            Action::Step { input, change } => w[input] = Waveform::Constant(change.apply(w[input].at(t))),
            Action::Ramp { input, change, end } => {
                let v0 = w[input].at(t);
                w[input] = Waveform::Ramp { t0: t, v0, t1: end, v1: change.apply(v0) };
            }
            Action::Hold { input } => w[input] = Waveform::Constant(w[input].at(t)),
            Action::Pulse { input, change } => {
                let v0 = w[input].at(t);
                self.st.saved[input] = Some(v0);
                w[input] = Waveform::Constant(change.apply(v0));
            }
            Action::Sinusoid { input, amplitude, period } => {
                let base = w[input].at(t);
                self.st.saved[input] = Some(base);
                w[input] = Waveform::Sine { t0: t, base, amplitude, period };
            }
            Action::Restore { input } => {
                if let Some(v) = self.st.saved[input].take() {
                    w[input] = Waveform::Constant(v);
                }
            }
            Action::Mode { auto_input, manual_input, op, auto, output } => {
                if !auto {
                    w[manual_input] = Waveform::Constant(output.unwrap_or(x[op]));
                }
                w[auto_input] = Waveform::Constant(if auto { 1.0 } else { 0.0 });
            }
            Action::Stuck { input } => {
                let value = w[input].at(t);
                let frozen = free_input(self.plant, input).map_or(value, |op| x[op]);
                self.sampled.iter_mut().for_each(|s| s.retain(|&(i, _)| i != input));
                self.st.waveforms[input] = Waveform::Constant(frozen);
                self.st.stuck.push(self.plant.inputs[input].path.clone());
            }
        }
    }

    fn run(&mut self, observer: &mut dyn FnMut(Progress<'_>)) -> Result<(), DaeError> {
        let totals = self.quad.clone();
        let interval = self.sc.interval;
        let mut x = self.x0.clone();
        match self.restore.take() {
            Some(state) => {
                let sys = PlantDae::new(self.plant, &self.st.waveforms, &totals);
                self.bdf.restore(&sys, state)?;
                x.copy_from_slice(self.bdf.x());
            }
            None => {
                // Record the start, apply what is due at it, then one consistent (re)start.
                let t0 = self.t0;
                if self.st.next_record as f64 * interval <= t0 {
                    self.push_row(t0, &x);
                    self.st.next_record = (t0 / interval).floor() as u64 + 1;
                }
                let events = self.st.next_event;
                self.apply_due_at(t0, &mut x);
                let sys = PlantDae::new(self.plant, &self.st.waveforms, &totals);
                self.bdf.restart(&sys, t0, &x)?;
                if self.st.next_event > events {
                    x.copy_from_slice(self.bdf.x());
                    self.push_row(t0, &x);
                }
            }
        }
        loop {
            let t = self.t();
            x.copy_from_slice(self.bdf.x());
            let scenario_events = self.st.next_event;
            if self.apply_due(&mut x) {
                let sys = PlantDae::new(self.plant, &self.st.waveforms, &totals);
                self.bdf.restart(&sys, t, &x)?;
                if self.st.next_event > scenario_events {
                    x.copy_from_slice(self.bdf.x());
                    self.push_row(t, &x);
                }
            }
            if t >= self.sc.duration {
                return Ok(());
            }
            let t_stop = self.next_stop(t);
            let sys = PlantDae::new(self.plant, &self.st.waveforms, &totals);
            let mut xi = vec![0.0; x.len()];
            while self.bdf.t() < t_stop {
                self.bdf.step(&sys, t_stop)?;
                let now = self.bdf.t();
                while (self.st.next_record as f64 * interval) <= now
                    && self.st.next_record as f64 * interval <= self.sc.duration
                {
                    let tr = self.st.next_record as f64 * interval;
                    if tr == now {
                        xi.copy_from_slice(self.bdf.x());
                    } else {
                        self.bdf.interpolate(tr, &mut xi);
                    }
                    let (row, refs) = row_at(self.plant, self.sc, &self.refs, &self.st.waveforms, tr, &xi);
                    self.times.push(tr);
                    self.rows.push(row);
                    self.ref_rows.push(refs);
                    self.st.next_record += 1;
                }
                for k in 0..self.sc.snapshots.len() {
                    if !self.st.snapshots_done[k] && self.sc.snapshots[k].0 <= now {
                        self.st.snapshots_done[k] = true;
                        let snap = Snapshot {
                            format_version: SNAPSHOT_VERSION,
                            fingerprint: self.fingerprint.clone(),
                            t: now,
                            paths: state_paths(self.plant, &self.quad, self.sc.totals.len()),
                            inputs: self.plant.inputs.iter().map(|i| i.path.clone()).collect(),
                            driver: self.st.clone(),
                            integrator: self.bdf.state().clone(),
                        };
                        observer(Progress::Snapshot { file: &self.sc.snapshots[k].1, snapshot: &snap });
                    }
                }
                observer(Progress::Step { t: now, duration: self.sc.duration });
            }
        }
    }

    /// Material balances from `x0` to the integrator's state.
    fn conservation(&self) -> Conservation {
        let (plant, nc, np) = (&*self.plant, self.plant.components.len(), self.plant.n_vars());
        let (t, x1) = (self.bdf.t(), self.bdf.x());
        let u: Vec<f64> = self.st.waveforms.iter().map(|w| w.at(t)).collect();
        let held = [
            conservation::plant_holdup(plant, &self.x0[..np], &u, self.t0),
            conservation::plant_holdup(plant, &x1[..np], &u, t),
        ];
        let (mut fed, mut removed) = (vec![0.0; nc], vec![0.0; nc]);
        for &(k, sign) in &self.boundary {
            let side = if sign > 0.0 { &mut fed } else { &mut removed };
            let q = np + k * nc..np + (k + 1) * nc;
            side.iter_mut().zip(x1[q.clone()].iter().zip(&self.x0[q])).for_each(|(v, (q1, q0))| *v += q1 - q0);
        }
        let mw: Vec<f64> = plant.thermo.components.iter().map(|c| c.mw).collect();
        let mw = conservation::reacts(plant).then_some(mw.as_slice());
        Conservation::new(&plant.components, mw, [&held[0], &held[1]], &fed, &removed)
    }

    fn finish(self) -> SimulationResult {
        let conservation = self.conservation();
        let mut columns: Vec<Column> = self
            .sc
            .record
            .iter()
            .map(|r| Column { path: r.path.clone(), unit: r.unit.clone(), si_unit: r.dim.to_string() })
            .collect();
        for &s in &self.sc.totals {
            for c in &self.plant.components {
                columns.push(Column {
                    path: format!("{}.total[{c}]", self.plant.streams[s].name),
                    unit: "mol".into(),
                    si_unit: "mol".into(),
                });
            }
        }
        let n_tot = columns.len() - self.refs.len();
        let references = self
            .refs
            .iter()
            .enumerate()
            .map(|(k, r)| r.map(|_| self.ref_rows.iter().map(|row| row[k]).collect()))
            .chain(std::iter::repeat_n(None, n_tot))
            .collect();
        SimulationResult {
            columns,
            times: self.times,
            rows: self.rows,
            references,
            events: self.events,
            x: self.bdf.x().to_vec(),
            t: self.bdf.t(),
            stats: self.bdf.stats(),
            conservation,
        }
    }
}

/// One recorded row at `t` from the state `x`, and the references. An input driven by a
/// controller is recorded as the controller's output, the value the plant receives.
fn row_at(
    plant: &Plant,
    sc: &Scenario,
    refs: &[Option<usize>],
    waves: &[Waveform],
    t: f64,
    x: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    let mut row: Vec<f64> = sc
        .record
        .iter()
        .map(|r| match r.source {
            Read::Var(v) => x[v],
            Read::Input(i) => plant.inputs[i].driven_by.map_or_else(|| waves[i].at(t), |v| x[v]),
        })
        .collect();
    let np = plant.n_vars();
    row.extend_from_slice(&x[np..np + sc.totals.len() * plant.components.len()]);
    (row, refs.iter().map(|r| r.map_or(f64::NAN, |i| waves[i].at(t))).collect())
}

/// Paths of the state vector: plant variables, then `<stream>.total[<component>]` for the first
/// `n_recorded` quadrature streams `quad` (the scenario's totals) and
/// `<stream>.boundary_total[<component>]` for the rest.
fn state_paths(plant: &Plant, quad: &[usize], n_recorded: usize) -> Vec<String> {
    let mut p: Vec<String> = plant.vars.iter().map(|v| v.path.clone()).collect();
    for (k, &s) in quad.iter().enumerate() {
        let kind = if k < n_recorded { "total" } else { "boundary_total" };
        p.extend(plant.components.iter().map(|c| format!("{}.{kind}[{c}]", plant.streams[s].name)));
    }
    p
}

/// The streams to integrate: the scenario's `totals`, then the boundary streams not among them;
/// and the boundary streams as (index into that list, +1 feed outlet / −1 product inlet).
fn quadrature_streams(plant: &Plant, totals: &[usize]) -> (Vec<usize>, Vec<(usize, f64)>) {
    let mut quad = totals.to_vec();
    let mut boundary = Vec::new();
    for (s, sign) in conservation::boundary_streams(plant) {
        let k = quad.iter().position(|&q| q == s).unwrap_or_else(|| {
            quad.push(s);
            quad.len() - 1
        });
        boundary.push((k, sign));
    }
    (quad, boundary)
}

/// The setpoint input of the controller that measures `source`, if any.
fn reference_of(plant: &Plant, source: Read) -> Option<usize> {
    let Read::Var(v) = source else { return None };
    plant.blocks.iter().filter(|b| b.kind == BlockKind::Controller).find_map(|b| {
        let measures = b.layout.n_signals > 0 && b.reads.get(b.layout.n_inputs) == Some(&Read::Var(v));
        measures.then(|| plant.input(&format!("{}.sp", b.name))).flatten()
    })
}

/// Figures of merit of one recorded path (SI units, times in seconds).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathSummary {
    /// Path.
    pub path: String,
    /// SI unit.
    pub unit: String,
    /// First recorded value.
    pub initial: f64,
    /// Last recorded value.
    pub last: f64,
    /// What deviations are measured from: `setpoint` or `initial`.
    pub reference: &'static str,
    /// `∫|e| dt` (trapezoid over the recorded points), `e` the deviation from the reference.
    pub iae: f64,
    /// `∫e² dt`.
    pub ise: f64,
    /// The deviation of largest magnitude (signed).
    pub max_deviation: f64,
    /// Time [s] after the first event until the path stays within 2 % of its largest excursion
    /// from its final value; `None` if it never moved.
    pub settling_time: Option<f64>,
}

impl SimulationResult {
    /// Figures of merit of every recorded column.
    pub fn summary(&self) -> Vec<PathSummary> {
        let t_first = self.events.first().map_or(self.times.first().copied().unwrap_or(0.0), |e| e.0);
        (0..self.columns.len()).map(|k| self.path_summary(k, t_first)).collect()
    }

    fn path_summary(&self, k: usize, t_first: f64) -> PathSummary {
        let y: Vec<f64> = self.rows.iter().map(|r| r[k]).collect();
        let (initial, last) = (y.first().copied().unwrap_or(f64::NAN), y.last().copied().unwrap_or(f64::NAN));
        let reference = self.references[k].as_ref();
        let e: Vec<f64> = y.iter().enumerate().map(|(i, v)| v - reference.map_or(initial, |r| r[i])).collect();
        let (mut iae, mut ise) = (0.0, 0.0);
        for i in 1..y.len() {
            let dt = self.times[i] - self.times[i - 1];
            iae += 0.5 * dt * (e[i].abs() + e[i - 1].abs());
            ise += 0.5 * dt * (e[i] * e[i] + e[i - 1] * e[i - 1]);
        }
        let max_deviation = e.iter().copied().fold(0.0, |m: f64, v| if v.abs() > m.abs() { v } else { m });
        let excursion = y.iter().map(|v| (v - last).abs()).fold(0.0, f64::max);
        let settling_time = (excursion > 1e-12 * last.abs().max(1e-300)).then(|| {
            let band = 0.02 * excursion;
            let outside = (0..y.len()).rev().find(|&i| (y[i] - last).abs() > band);
            outside.map_or(0.0, |i| (self.times[(i + 1).min(y.len() - 1)] - t_first).max(0.0))
        });
        PathSummary {
            path: self.columns[k].path.clone(),
            unit: self.columns[k].si_unit.clone(),
            initial,
            last,
            reference: if reference.is_some() { "setpoint" } else { "initial" },
            iae,
            ise,
            max_deviation,
            settling_time,
        }
    }
}
