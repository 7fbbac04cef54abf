//! The event driver: integrates between the discrete times of a run (scenario events, controller
//! scans, analyzer samples and releases, the end), applies what is due at each, restarts the
//! integrator when an input changed, records rows and hands out snapshots.
//!
//! The driver rewires the plant through the flowsheet's wiring methods: a sampled controller's
//! driven inputs are held ([`Plant::manual`]) and set to its output at every scan, an analyzer's
//! controller reads a held copy of its measurement ([`Plant::hold_measurement`]), and a stuck
//! valve's input is held at its last value ([`Plant::hold_input`]). It copies the caller's plant
//! when it first rewires it: a run that rewires nothing reads the caller's plant (a copy was a
//! tenth of a short run's setup).

use std::borrow::Cow;

mod conditions;

use plantwide_flowsheet::scenario::{Action, Event, Scenario};
use plantwide_flowsheet::{Plant, Read, VarPath};

use super::adapter::{DaeShape, PlantDae, Quadratures};
use super::instants;
use super::mpc::{self, MpcError, MpcLog, MpcRun};
use super::snapshot::{self, DriverState, SNAPSHOT_VERSION, Snapshot};
use super::table::Table;
use super::waveform::{Waveform, values_at};
use super::{Column, Conservation, Progress, SimError, SimulationResult, Start, conservation};
use crate::dae::{Bdf, BdfSettings, BdfState, DaeError, DaeIntegrator, DenseOutput};

thread_local! {
    /// The integrator of the last run finished on this thread, which the next run recycles
    /// ([`Bdf::recycle`]: the same results as a new one, bit for bit, without redoing the sparse
    /// LU's pattern work when the plant is the same). Studies run one plant many times, on the
    /// calling thread or a rayon worker each; one integrator per thread is held between runs.
    static SPARE: std::cell::RefCell<Option<Bdf>> = const { std::cell::RefCell::new(None) };
}

/// An integrator with `settings`: this thread's spare one recycled, else a new one.
fn integrator(settings: BdfSettings) -> Bdf {
    match SPARE.take() {
        Some(mut bdf) => {
            bdf.recycle(settings);
            bdf
        }
        None => Bdf::new(settings),
    }
}

/// One run in progress.
pub(super) struct Driver<'p> {
    /// The caller's plant, or its copy rewired for this run.
    plant: Cow<'p, Plant>,
    /// The scenario (its own copy: a live run adds events to it as commands arrive).
    sc: Scenario,
    st: DriverState,
    bdf: Bdf,
    /// The state entries the recorded rows read: only they are interpolated between steps.
    recorded: Vec<usize>,
    fingerprint: String,
    /// Per sampled controller: (driven input, its controller output variable).
    sampled: Vec<Vec<(usize, usize)>>,
    /// Per analyzer: (held input, measured variable).
    analyzers: Vec<(usize, usize)>,
    times: Vec<f64>,
    rows: Table,
    /// Per recorded path: the setpoint input of the controller that measures it.
    refs: Vec<Option<usize>>,
    /// Per recorded row: the references of the paths that have one (`refs`), in order.
    ref_rows: Table,
    events: Vec<(f64, String)>,
    /// Start from a snapshot of the same plant: the history to restore instead of restarting.
    restore: Option<BdfState>,
    x0: Vec<f64>,
    t0: f64,
    quad: Quadratures,
    shape: DaeShape,
    /// The model predictive controllers, executed at their samples.
    mpcs: Vec<MpcRun>,
    /// The first controller failure, which ends the run.
    failure: Option<MpcError>,
    /// The total holdups of the plant's vessels and stages (variables marked `inventory`).
    holdups: Vec<usize>,
    /// The inputs controllers drive: (input, the controller output variable driving it).
    driven: Vec<(usize, usize)>,
    /// The state buffer of [`Driver::step_once`] (events, interpolated rows), kept between steps.
    state_buf: Vec<f64>,
    /// The last step's dense output of the recorded entries (its buffers kept between steps).
    dense: DenseOutput,
    /// Why the run ended before its duration at a condition's `stop` (a trip the scenario asked for).
    tripped: Option<String>,
}

/// Why a run stopped early.
#[derive(Debug)]
pub(super) enum RunError {
    /// The integrator failed.
    Dae(DaeError),
    /// A model predictive controller's QP failed.
    Mpc(MpcError),
    /// A vessel ran dry: the plant cannot go on as modelled (the message names the holdup).
    Stopped(String),
}

impl From<DaeError> for RunError {
    fn from(e: DaeError) -> Self {
        RunError::Dae(e)
    }
}

/// The state a run starts from, extended by the quadratures (0 at a steady start).
fn initial_state(plant: &Plant, quad: &Quadratures, start: Start<'_>) -> Vec<f64> {
    let n_state = quad.n_state(plant);
    match start {
        Start::Steady(x) => {
            let mut v = x.to_vec();
            v.resize(n_state, 0.0);
            v
        }
        Start::Snapshot(s) => snapshot::mapped_state(plant, &quad.state_paths(plant), n_state, s),
    }
}

/// Hold the measurement of every analyzer's controller at its value in `x`; returns per analyzer
/// (held input, measured variable).
fn hold_analyzers(plant: &mut Plant, sc: &Scenario, x: &[f64]) -> Result<Vec<(usize, usize)>, SimError> {
    let mut analyzers = Vec::new();
    for &(b, _, _) in &sc.analyzers {
        // Without a measured variable there is nothing to hold: `hold_measurement` refuses.
        let value = plant.measured_var(b).map_or(0.0, |v| x[v]);
        analyzers.push(plant.hold_measurement(b, value)?);
    }
    Ok(analyzers)
}

/// Put every sampled controller's loop in manual at `x` (its driven inputs then follow its output
/// only at scans); returns per sampled controller (held input, output variable).
fn hold_sampled(plant: &mut Plant, sc: &Scenario, x: &[f64]) -> Vec<Vec<(usize, usize)>> {
    sc.sampling.iter().map(|&(b, _)| plant.manual(b, x)).collect()
}

/// The BDF settings a scenario asks for.
fn bdf_settings(sc: &Scenario) -> BdfSettings {
    BdfSettings {
        rtol: sc.rtol,
        atol: sc.atol,
        max_step: sc.max_step,
        first_step: sc.first_step,
        ..BdfSettings::default()
    }
}

impl<'p> Driver<'p> {
    /// A run of `sc` on `plant` (copied when rewired) from `start`; `fingerprint` identifies the
    /// plant description in snapshots.
    pub(super) fn new(
        plant: Cow<'p, Plant>,
        sc: &Scenario,
        start: Start<'_>,
        fingerprint: &str,
    ) -> Result<Driver<'p>, SimError> {
        let quad = Quadratures::new(&plant, &sc.totals);
        let x0 = initial_state(&plant, &quad, start);
        let mpcs = mpc::build_all(&plant, &x0[..plant.n_vars()]).map_err(|e| SimError::Mpc {
            file: plant.file().to_string(),
            source: e,
            partial: None,
        })?;
        let discrete = sc.sampling.iter().map(|&(b, _)| b).chain(sc.analyzers.iter().map(|&(b, _, _)| b));
        if let Some(name) = discrete.map(|b| &plant.blocks()[b].name).find(|n| mpcs.iter().any(|m| &m.name == *n)) {
            let reason = format!(
                "the scenario samples `{name}` (sampling or analyzers), a model predictive controller, which executes \
                 every sample_time of its own and reads its CVs then: remove it from the scenario's sampling and analyzers"
            );
            return Err(SimError::Mpc {
                file: plant.file().to_string(),
                source: MpcError { controller: name.clone(), reason },
                partial: None,
            });
        }
        if !mpcs.is_empty() && matches!(start, Start::Snapshot(_)) {
            return Err(SimError::Snapshot {
                file: plant.file().to_string(),
                reason: "a run with model predictive controllers does not resume from a snapshot (their predictions \
                         are not saved): run the scenario from the steady state"
                    .into(),
            });
        }
        // Every controller output (a scan, a stuck valve or a switch to manual reads one).
        let outputs: Vec<usize> = plant.inputs().iter().filter_map(|i| i.driven_by).collect();
        let mut plant = plant;
        // Which controller measures each recorded path: read before the analyzers rewire it.
        let refs: Vec<Option<usize>> = sc.record.iter().map(|r| reference_of(&plant, r.source)).collect();
        let analyzers = if sc.analyzers.is_empty() { Vec::new() } else { hold_analyzers(plant.to_mut(), sc, &x0)? };
        let mut sampled = if sc.sampling.is_empty() { Vec::new() } else { hold_sampled(plant.to_mut(), sc, &x0) };
        let mut st = DriverState::start(&plant, sc);
        let (mut restore, mut t0) = (None, 0.0);
        if let Start::Snapshot(s) = start {
            let paths = quad.state_paths(&plant);
            let resumed = snapshot::resume(plant.to_mut(), sc, s, fingerprint, &paths, st, &mut sampled)?;
            (st, restore, t0) = (resumed.driver, resumed.integrator, s.t);
        }
        let recorded = recorded_state(&plant, sc);
        let n_totals = sc.totals.len() * plant.components().len();
        // What the driver reads between steps; a model predictive controller reads its model's
        // states, which may be anything.
        let mut reads = outputs;
        let holdups: Vec<usize> = (0..plant.n_vars()).filter(|&v| plant.vars()[v].spec.inventory).collect();
        reads.extend(holdups.iter().copied());
        let driven: Vec<(usize, usize)> =
            plant.inputs().iter().enumerate().filter_map(|(i, info)| info.driven_by.map(|v| (i, v))).collect();
        reads.extend(driven.iter().map(|&(_, v)| v));
        reads.extend(recorded.iter().copied().filter(|&v| v < plant.n_vars()));
        reads.extend(analyzers.iter().map(|&(_, v)| v));
        reads.extend(sampled.iter().flatten().map(|&(_, op)| op));
        reads.extend(sc.conditions.iter().map(|c| c.var));
        let shape = DaeShape::new(&plant, &quad.streams, mpcs.is_empty().then_some(reads.as_slice()));
        // Between steps only the recorded variables are interpolated: the integrator need not
        // keep the history of the other explicit ones.
        let mut bdf = integrator(bdf_settings(sc));
        // The watched variables of conditions are interpolated too, to locate their crossings.
        let watched: Vec<usize> = recorded.iter().copied().chain(sc.conditions.iter().map(|c| c.var)).collect();
        bdf.watch(&watched);
        Ok(Driver {
            shape,
            recorded,
            plant,
            sc: sc.clone(),
            st,
            bdf,
            fingerprint: fingerprint.to_string(),
            sampled,
            analyzers,
            // One row per interval (a few more at events): no regrowth in a run.
            times: Vec::with_capacity(rows_expected(sc)),
            rows: Table::with_capacity(sc.record.len() + n_totals, rows_expected(sc)),
            ref_rows: Table::with_capacity(refs.iter().flatten().count(), rows_expected(sc)),
            refs,
            events: Vec::new(),
            restore,
            x0,
            t0,
            quad,
            mpcs,
            failure: None,
            holdups,
            driven,
            state_buf: Vec::new(),
            dense: DenseOutput::default(),
            tripped: None,
        })
    }

    /// No budget of steps (a live run's duration is endless); before [`Driver::start`].
    /// A live run reads any variable at any time: none is output-only.
    pub(super) fn endless(&mut self) {
        self.bdf.recycle(BdfSettings { max_steps: usize::MAX, ..bdf_settings(&self.sc) });
        self.shape = DaeShape::new(&self.plant, &self.quad.streams, None);
    }

    /// The integrator's time \[s\]: the last step's end (a sync point).
    pub(super) fn t(&self) -> f64 {
        self.bdf.t()
    }

    /// The state at the last sync point (plant variables, then totals).
    pub(super) fn x(&self) -> &[f64] {
        self.bdf.x()
    }

    /// The state at `t` (within the last step) interpolated by the BDF polynomial into `out`.
    pub(super) fn interpolate(&self, t: f64, out: &mut [f64]) {
        let t = t.clamp(self.bdf.t_prev().min(self.bdf.t()), self.bdf.t());
        if t == self.bdf.t() {
            out.copy_from_slice(self.bdf.x());
        } else {
            self.bdf.interpolate(t, out);
        }
    }

    /// Why a condition ended the run, if one did.
    pub(super) fn tripped(&self) -> Option<&str> {
        self.tripped.as_deref()
    }

    /// The value of input `i` at `t` (SI).
    pub(super) fn input_value(&self, i: usize, t: f64) -> f64 {
        self.st.waveforms[i].at(t)
    }

    /// Add `events` (none before the integrator's time) to the scenario, each after the events
    /// at or before its time: where a file listing them last would sort them.
    pub(super) fn insert_events(&mut self, events: &[Event]) {
        for e in events {
            let tail = &self.sc.events[self.st.next_event..];
            let at = self.st.next_event + tail.iter().take_while(|f| f.t <= e.t).count();
            self.sc.events.insert(at, e.clone());
        }
    }

    /// Drop the rows recorded so far (a live run hands out values itself and keeps no history).
    pub(super) fn forget_records(&mut self) {
        self.times.clear();
        self.rows.clear();
        self.ref_rows.clear();
        self.events.clear();
    }

    /// Everything needed to continue the run from here.
    pub(super) fn snapshot(&self) -> Snapshot {
        Snapshot {
            format_version: SNAPSHOT_VERSION,
            fingerprint: self.fingerprint.clone(),
            t: self.bdf.t(),
            paths: self.quad.state_paths(&self.plant),
            inputs: self.plant.inputs().iter().map(|i| i.path.clone()).collect(),
            driver: self.st.clone(),
            integrator: self.bdf.state(),
        }
    }

    /// The faults and analyzers in force, for a command that continues the run.
    pub(super) fn ongoing(&self) -> plantwide_flowsheet::scenario::Ongoing {
        let plant = &self.plant;
        plantwide_flowsheet::scenario::Ongoing {
            faulted: self.st.faults.iter().filter_map(|f| plant.input(&f.path)).collect(),
            frozen: self.sc.analyzers.iter().zip(&self.st.frozen).filter(|(_, f)| **f).map(|(&(b, ..), _)| b).collect(),
            analyzers: self.sc.analyzers.iter().map(|&(b, ..)| b).collect(),
        }
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
        for m in &self.mpcs {
            next = next.min(m.next_time());
        }
        if let Some(due) = self.next_triggered() {
            next = next.min(due);
        }
        next.max(t)
    }

    /// Record the row at `t` from the state `x`, and the references of the recorded paths that
    /// have one (in order). An input driven by a controller is recorded as the controller's
    /// output, the value the plant receives.
    fn push_row(&mut self, t: f64, x: &[f64]) {
        self.times.push(t);
        let (plant, waves) = (&self.plant, &self.st.waveforms);
        let (np, n_tot) = (plant.n_vars(), self.sc.totals.len() * plant.components().len());
        let record = &self.sc.record;
        self.rows.push_with(|row| {
            let (paths, totals) = row.split_at_mut(record.len());
            for (v, r) in paths.iter_mut().zip(record) {
                *v = match r.source {
                    Read::Var(v) => x[v],
                    Read::Input(i) => plant.inputs()[i].driven_by.map_or_else(|| waves[i].at(t), |v| x[v]),
                };
            }
            totals.copy_from_slice(&x[np..np + n_tot]);
        });
        let refs = &self.refs;
        self.ref_rows
            .push_with(|row| row.iter_mut().zip(refs.iter().flatten()).for_each(|(v, &i)| *v = waves[i].at(t)));
    }

    /// Apply everything due at `t` (the integrator's time, or the start before it is started);
    /// true if the integrator must restart.
    fn apply_due_at(&mut self, t: f64, x: &mut [f64]) -> bool {
        let scenario_event = self.apply_events(t, x);
        let scenario_event = self.apply_triggered(t, x, scenario_event);
        let scanned = self.apply_scans(t, x);
        let sampled = self.apply_samples(t, x);
        let moved = self.apply_mpc(t, x);
        scanned || sampled || scenario_event || moved
    }

    /// The model predictive controllers due at `t`: each solves its QP at the state `x` and holds
    /// its moves on its inputs; true if one changed. A failure is kept and ends the run.
    fn apply_mpc(&mut self, t: f64, x: &[f64]) -> bool {
        let mut changed = false;
        for k in 0..self.mpcs.len() {
            let waves = &self.st.waveforms;
            match self.mpcs[k].execute(t, x, |i| waves[i].at(t)) {
                Ok(Some(moves)) => {
                    for (i, v) in moves {
                        changed |= self.st.waveforms[i] != Waveform::Constant(v);
                        self.st.waveforms[i] = Waveform::Constant(v);
                    }
                }
                Ok(None) => {}
                Err(e) => {
                    self.failure.get_or_insert(e);
                }
            }
        }
        changed
    }

    /// Apply the scenario events due at `t` (a row just before the first); true if any was.
    fn apply_events(&mut self, t: f64, x: &[f64]) -> bool {
        let mut scenario_event = false;
        while let Some(e) = self.sc.events.get(self.st.next_event).filter(|e| e.t <= t).cloned() {
            if !scenario_event && self.times.last() != Some(&t) {
                self.push_row(t, x);
            }
            scenario_event = true;
            let (action, origin) = (e.action, e.origin);
            self.apply(&action, t, x);
            self.events.push((t, origin));
            self.st.next_event += 1;
        }
        scenario_event
    }

    /// The scans of sampled controllers due at `t`: their held inputs take the output's value in
    /// `x` (zero-order hold); true if one changed.
    fn apply_scans(&mut self, t: f64, x: &[f64]) -> bool {
        let mut changed = false;
        for (k, &(_, scan)) in self.sc.sampling.iter().enumerate() {
            if self.st.next_scan[k] as f64 * scan <= t {
                for &(i, op) in &self.sampled[k] {
                    changed |= self.st.waveforms[i] != Waveform::Constant(x[op]);
                    self.st.waveforms[i] = Waveform::Constant(x[op]);
                }
                self.st.next_scan[k] = instants::after(t, scan);
            }
        }
        changed
    }

    /// The analyzer samples due at `t` (queued for release one dead time later) and the results
    /// released by `t` (the held measurement takes the latest); true if a held value changed.
    fn apply_samples(&mut self, t: f64, x: &[f64]) -> bool {
        let mut changed = false;
        for (k, &(_, ts, td)) in self.sc.analyzers.iter().enumerate() {
            let (input, v) = self.analyzers[k];
            if self.st.frozen[k] {
                // A frozen analyzer takes no sample and releases nothing; its held value stays.
                if self.st.next_sample[k] as f64 * ts <= t {
                    self.st.next_sample[k] = instants::after(t, ts);
                }
                continue;
            }
            if self.st.next_sample[k] as f64 * ts <= t {
                self.st.pending[k].push((self.st.next_sample[k] as f64 * ts + td, x[v]));
                self.st.next_sample[k] = instants::after(t, ts);
            }
            let due: Vec<(f64, f64)> = self.st.pending[k].iter().copied().filter(|&(r, _)| r <= t).collect();
            if let Some(&(_, value)) = due.last() {
                changed |= self.st.waveforms[input] != Waveform::Constant(value);
                self.st.waveforms[input] = Waveform::Constant(value);
            }
            self.st.pending[k].retain(|&(r, _)| r > t);
        }
        changed
    }

    /// Apply one scenario action at `t`, state `x`. A change of an input in a fault goes on
    /// behind the fault ([`snapshot::Fault::behind`]): the fault holds the input, as a stuck
    /// valve or a lost feed does whatever the setpoint.
    fn apply(&mut self, action: &Action, t: f64, x: &[f64]) {
        let changed = match *action {
            Action::Step { input, .. }
            | Action::Ramp { input, .. }
            | Action::Hold { input }
            | Action::Pulse { input, .. }
            | Action::Sinusoid { input, .. }
            | Action::Restore { input } => Some(input),
            _ => None,
        };
        let path = changed.map(|i| self.plant.inputs()[i].path.clone());
        let fault = path.and_then(|p| self.st.faults.iter().position(|f| f.path == p));
        if let (Some(input), Some(k)) = (changed, fault) {
            let before = Waveform::Constant(self.st.faults[k].before);
            let behind = self.st.faults[k].behind.take().unwrap_or(before);
            let held = std::mem::replace(&mut self.st.waveforms[input], behind);
            self.apply_free(action, t, x);
            self.st.faults[k].behind = Some(std::mem::replace(&mut self.st.waveforms[input], held));
            return;
        }
        self.apply_free(action, t, x);
    }

    /// [`Driver::apply`] to the inputs' waveforms as they stand.
    fn apply_free(&mut self, action: &Action, t: f64, x: &[f64]) {
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
            Action::Stuck { input, value } => self.fail_input(input, value, t, x),
            Action::Repair { input } => self.repair_input(input, x),
            Action::Analyzer { block, frozen } => {
                if let Some(k) = self.sc.analyzers.iter().position(|&(b, ..)| b == block) {
                    self.st.frozen[k] = frozen;
                    if frozen {
                        self.st.pending[k].clear();
                    }
                }
            }
        }
    }

    /// A fault on `input` at `t`: it leaves the controller that drove it (or the scans that held
    /// it) and stays where it is, or at `value`; what its repair gives it back to is kept.
    fn fail_input(&mut self, input: usize, value: Option<f64>, t: f64, x: &[f64]) {
        let scheduled = self.st.waveforms[input];
        let current = scheduled.at(t);
        let op = self.plant.to_mut().hold_input(input);
        let before = op.map_or(current, |op| x[op]);
        let scanned_by = self.sampled.iter().enumerate().find_map(|(k, s)| {
            s.iter().find(|&&(i, _)| i == input).map(|&(_, op)| (k, self.plant.vars()[op].path.clone()))
        });
        self.sampled.iter_mut().for_each(|s| s.retain(|&(i, _)| i != input));
        self.st.waveforms[input] = Waveform::Constant(value.unwrap_or(before));
        let path = self.plant.inputs()[input].path.clone();
        let driven_by = op.map(|op| self.plant.vars()[op].path.clone());
        let behind = Some(scheduled);
        self.st.faults.push(snapshot::Fault { path: path.clone(), before, driven_by, scanned_by, behind });
        self.st.stuck.push(path);
    }

    /// The end of the fault on `input`: back to its controller (whose output has wound wherever
    /// the fault left it), to its scans, or to its value before the fault.
    fn repair_input(&mut self, input: usize, x: &[f64]) {
        let path = &self.plant.inputs()[input].path;
        let Some(k) = self.st.faults.iter().position(|f| f.path == *path) else { return };
        let fault = self.st.faults.remove(k);
        self.st.stuck.retain(|p| *p != fault.path);
        let var = |p: &str| self.plant.var(p);
        match (fault.driven_by.as_deref().and_then(var), fault.scanned_by.as_ref()) {
            (Some(op), _) => {
                self.plant.to_mut().release_input(input, op);
                self.st.waveforms[input] = Waveform::Constant(x[op]);
            }
            (None, Some((k, p))) => match var(p) {
                Some(op) => {
                    self.sampled[*k].push((input, op));
                    self.st.waveforms[input] = Waveform::Constant(x[op]);
                }
                None => self.st.waveforms[input] = Waveform::Constant(fault.before),
            },
            (None, None) => {
                self.st.waveforms[input] = fault.behind.unwrap_or(Waveform::Constant(fault.before));
            }
        }
    }

    /// (Re)start the integrator at `t` from `x` after applying what is due there; a row after the
    /// scenario events applied, if any.
    fn restart_after_due(&mut self, t: f64, x: &mut [f64]) -> Result<(), DaeError> {
        let events = self.events.len();
        if self.apply_due_at(t, x) {
            let sys = PlantDae::new(&self.plant, &self.st.waveforms, &self.shape);
            self.bdf.restart_after_discontinuity(&sys, t, x)?;
            if self.events.len() > events {
                x.copy_from_slice(self.bdf.x());
                self.push_row(t, x);
            }
        }
        Ok(())
    }

    /// Start the integrator: restore a snapshot's history, or record the start, apply what is
    /// due at it and make one consistent start. Returns the state.
    pub(super) fn start(&mut self) -> Result<Vec<f64>, DaeError> {
        let mut x = self.x0.clone();
        if let Some(state) = self.restore.take() {
            let sys = PlantDae::new(&self.plant, &self.st.waveforms, &self.shape);
            self.bdf.restore(&sys, state)?;
            x.copy_from_slice(self.bdf.x());
            self.conditions_at_start();
            return Ok(x);
        }
        let (t0, interval) = (self.t0, self.sc.interval);
        if self.st.next_record as f64 * interval <= t0 {
            self.push_row(t0, &x);
            self.st.next_record = instants::after(t0, interval);
        }
        let events = self.events.len();
        self.apply_due_at(t0, &mut x);
        let sys = PlantDae::new(&self.plant, &self.st.waveforms, &self.shape);
        self.bdf.restart(&sys, t0, &x)?;
        if self.events.len() > events {
            x.copy_from_slice(self.bdf.x());
            self.push_row(t0, &x);
        }
        self.conditions_at_start();
        Ok(x)
    }

    /// Run to the scenario's end, reporting steps and snapshots to `observer`.
    pub(super) fn run(&mut self, observer: &mut dyn FnMut(Progress<'_>)) -> Result<(), RunError> {
        self.start()?;
        while self.step_once(observer)? {}
        self.complete_outputs()?;
        Ok(())
    }

    /// Solve the output-only variables at the integrator's time (before its state is handed
    /// out whole: the result, a snapshot).
    fn complete_outputs(&mut self) -> Result<(), DaeError> {
        let sys = PlantDae::new(&self.plant, &self.st.waveforms, &self.shape);
        self.bdf.complete_outputs(&sys)
    }

    /// Apply what is due at the integrator's time (restarting it if an input changed), then take
    /// one step towards the next discrete time; false once the run's end is reached. Taking the
    /// steps one call at a time changes nothing: with nothing due, the application is a no-op.
    pub(super) fn step_once(&mut self, observer: &mut dyn FnMut(Progress<'_>)) -> Result<bool, RunError> {
        if let Some(e) = self.failure.take() {
            return Err(RunError::Mpc(e));
        }
        if self.tripped.is_some() {
            return Ok(false);
        }
        let t = self.t();
        let mut x = std::mem::take(&mut self.state_buf);
        // The state is copied out only when something is due now (`next_stop` is the earliest
        // thing due, or the end): between, `x` is the buffer the recorded rows interpolate into.
        if self.next_stop(t) <= t {
            x.clear();
            x.extend_from_slice(self.bdf.x());
            self.restart_after_due(t, &mut x)?;
        } else {
            x.resize(self.bdf.x().len(), 0.0);
        }
        if let Some(e) = self.failure.take() {
            return Err(RunError::Mpc(e));
        }
        if t >= self.sc.duration {
            return Ok(false);
        }
        let t_stop = self.next_stop(t);
        let sys = PlantDae::new(&self.plant, &self.st.waveforms, &self.shape);
        self.bdf.step(&sys, t_stop)?;
        if !self.conditions_after_step(&mut x)? {
            self.record_through(self.bdf.t(), &mut x);
        }
        let now = self.bdf.t();
        if self.tripped.is_some() && self.times.last() != Some(&now) {
            x.copy_from_slice(self.bdf.x());
            self.push_row(now, &x);
        }
        self.state_buf = x;
        if let Some(why) = self.ran_dry().or_else(|| self.driven_out_of_range()) {
            return Err(RunError::Stopped(why));
        }
        self.offer_snapshots(now, observer)?;
        observer(Progress::Step { t: now, duration: self.sc.duration });
        Ok(true)
    }

    /// A vessel or stage whose total holdup went below zero in the last step (by more than a
    /// millionth of its nominal holdup, beyond the integrator's error): what is drawn from it (an
    /// outflow an input or a controller sets, which goes on at an empty vessel) outran what flows
    /// in, and the model has no meaning past that point.
    fn ran_dry(&self) -> Option<String> {
        let x = self.bdf.x();
        let plant = &self.plant;
        let v = *self.holdups.iter().find(|&&v| x[v] < -1e-6 * plant.vars()[v].spec.nominal)?;
        let var = &plant.vars()[v];
        Some(format!(
            "`{}` ran dry at t = {} s (holdup {} mol): what is drawn from it (an outflow set by an input or a controller \
             that goes on at an empty vessel) outran what flows in; a level controller on it, or a lower limit on the \
             controllers that draw from it, keeps it from running dry",
            var.path,
            plantwide_model::limits::number(self.bdf.t()),
            plantwide_model::limits::number(x[v]),
        ))
    }

    /// An input a controller drives taken out of its physical range in the last step (a flow
    /// below zero: a controller with no lower limit asking a valve to pass a reversed flow), by
    /// more than a millionth of the output's nominal value, on a side the controller does not
    /// limit: the models do not hold past it.
    fn driven_out_of_range(&self) -> Option<String> {
        let (x, plant) = (self.bdf.x(), &*self.plant);
        self.driven.iter().find_map(|&(i, v)| {
            let (lo, hi) = plant.input_range(i);
            let tol = 1e-6 * plant.vars()[v].spec.nominal.abs();
            let value = x[v];
            // A side the controller limits holds by its own clamp (what is beyond is the
            // corrector's tolerance on the output, not the controller's intent).
            let (op_min, op_max) = plant.blocks()[plant.vars()[v].block]
                .unit
                .output_limits()
                .unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
            let below = value < lo - tol && op_min == f64::NEG_INFINITY;
            let above = value > hi + tol && op_max == f64::INFINITY;
            if !(below || above || !value.is_finite()) {
                return None;
            }
            let info = &plant.inputs()[i];
            let dim = info.dim;
            let why = plantwide_model::limits::check_input_within(&info.path, dim, value, (lo, hi))
                .err()
                .map_or_else(String::new, |e| e.to_string());
            Some(format!(
                "`{}` drives `{}` out of its range at t = {} s: {why}; a limit on the controller's output (op_min, \
                 op_max) makes it saturate there instead",
                plant.vars()[v].path,
                info.path,
                plantwide_model::limits::number(self.bdf.t()),
            ))
        })
    }

    /// Record every row due by `now` (and by the end), interpolated within the last step.
    fn record_through(&mut self, now: f64, xi: &mut [f64]) {
        let interval = self.sc.interval;
        let mut gathered = false;
        while (self.st.next_record as f64 * interval) <= now
            && self.st.next_record as f64 * interval <= self.sc.duration
        {
            let tr = self.st.next_record as f64 * interval;
            if tr == self.bdf.t() {
                xi.copy_from_slice(self.bdf.x());
            } else {
                if !gathered {
                    self.bdf.dense_output_into(&self.recorded, &mut self.dense);
                    gathered = true;
                }
                self.dense.at(tr, xi);
            }
            self.push_row(tr, xi);
            self.st.next_record += 1;
        }
    }

    /// Hand the snapshots due by `now` to `observer`.
    fn offer_snapshots(&mut self, now: f64, observer: &mut dyn FnMut(Progress<'_>)) -> Result<(), DaeError> {
        for k in 0..self.sc.snapshots.len() {
            if !self.st.snapshots_done[k] && self.sc.snapshots[k].0 <= now {
                self.st.snapshots_done[k] = true;
                self.complete_outputs()?;
                let snap = self.snapshot();
                observer(Progress::Snapshot { file: &self.sc.snapshots[k].1, snapshot: &snap });
                // The run goes on from the snapshot as a resume from it does (the integrator
                // restored from the state it saved): the held LU factors and the untracked
                // variables are rebuilt from the snapshot in both, so that a resumed run is the
                // continuous one bit for bit, not just within rounding.
                let sys = PlantDae::new(&self.plant, &self.st.waveforms, &self.shape);
                self.bdf.restore(&sys, snap.integrator)?;
            }
        }
        Ok(())
    }

    /// Material balances from `x0` to the integrator's state.
    fn conservation(&self) -> Conservation {
        let (plant, nc, np) = (&self.plant, self.plant.components().len(), self.plant.n_vars());
        // A run that failed at its start ends where it started.
        let (t, x1) = if self.bdf.has_state() { (self.bdf.t(), self.bdf.x()) } else { (self.t0, &self.x0[..]) };
        let u = values_at(&self.st.waveforms, t);
        let held = [
            conservation::plant_holdup(plant, &self.x0[..np], &u, self.t0),
            conservation::plant_holdup(plant, &x1[..np], &u, t),
        ];
        let (fed, removed) = self.quad.fed_and_removed(np, nc, &self.x0, x1);
        let mw: Vec<f64> = plant.thermo().components.iter().map(|c| c.mw).collect();
        let mw = conservation::reacts(plant).then_some(mw.as_slice());
        Conservation::new(plant.components(), mw, [&held[0], &held[1]], &fed, &removed)
    }

    /// The recorded columns: the scenario's paths, then `<stream>.total[<component>]` [mol].
    fn columns(&self) -> Vec<Column> {
        let mut columns: Vec<Column> = self
            .sc
            .record
            .iter()
            .map(|r| Column { path: r.path.clone(), unit: r.unit.clone(), si_unit: r.dim.to_string() })
            .collect();
        for &s in &self.sc.totals {
            for c in self.plant.components() {
                columns.push(Column {
                    path: VarPath::new(&self.plant.streams()[s].name, "total").index(c).into(),
                    unit: "mol".into(),
                    si_unit: "mol".into(),
                });
            }
        }
        columns
    }

    /// The run so far as a result.
    /// The output-only variables are solved first (done already after a completed run); if
    /// they cannot be (a run that failed), they are NaN in the final state, not stale values.
    pub(super) fn finish(mut self) -> SimulationResult {
        // The error, if any, is the run's own failure seen again or left as NaN: nothing to add.
        if self.bdf.has_state() {
            let _ = self.complete_outputs();
        }
        let conservation = self.conservation();
        let columns = self.columns();
        let n_tot = columns.len() - self.refs.len();
        let references = self
            .refs
            .iter()
            .scan(0, |m, r| {
                // `ref_rows` hold the referenced columns only, in order: `m` counts them.
                let col = r.map(|_| self.ref_rows.column(*m).collect());
                *m += usize::from(r.is_some());
                Some(col)
            })
            .chain(std::iter::repeat_n(None, n_tot))
            .collect();
        let result = SimulationResult {
            columns,
            times: self.times,
            rows: self.rows,
            references,
            events: self.events,
            x: if self.bdf.has_state() { self.bdf.x().to_vec() } else { self.x0.clone() },
            t: if self.bdf.has_state() { self.bdf.t() } else { self.t0 },
            stats: self.bdf.stats(),
            conservation,
            mpc: self.mpcs.into_iter().map(|m| m.log).collect::<Vec<MpcLog>>(),
            tripped: self.tripped,
        };
        SPARE.set(Some(self.bdf));
        result
    }
}

/// The rows a run of `sc` records at its interval (capped: an endless or very long run grows
/// its storage as it goes).
fn rows_expected(sc: &Scenario) -> usize {
    let n = sc.duration / sc.interval;
    if n.is_finite() && n >= 0.0 { (n as usize).saturating_add(2).min(1 << 16) } else { 0 }
}

/// The state entries a recorded row reads ([`Driver::push_row`]): the recorded variables, the controller
/// outputs that drive recorded inputs, and the recorded totals.
fn recorded_state(plant: &Plant, sc: &Scenario) -> Vec<usize> {
    let np = plant.n_vars();
    let mut v: Vec<usize> = sc
        .record
        .iter()
        .filter_map(|r| match r.source {
            Read::Var(v) => Some(v),
            Read::Input(i) => plant.inputs()[i].driven_by,
        })
        .collect();
    v.extend(np..np + sc.totals.len() * plant.components().len());
    v
}

/// The setpoint input of the controller that measures `source`, if any: `<ctrl>.sp` of a loop,
/// `<ctrl>.sp<k>` of a model predictive controller's k-th CV.
fn reference_of(plant: &Plant, source: Read) -> Option<usize> {
    let Read::Var(v) = source else { return None };
    (0..plant.blocks().len()).find_map(|b| {
        let name = &plant.blocks()[b].name;
        let (k, _) = plant.measured_vars(b).into_iter().find(|&(_, m)| m == v)?;
        plant
            .input(VarPath::cv_setpoint(name, k))
            .or_else(|| (k == 0).then(|| plant.input(VarPath::setpoint(name))).flatten())
    })
}
