//! A live run: the scenario driver advanced on demand by an interactive simulator's clock, with
//! commands (an input's value, a controller's mode, any event of the scenario vocabulary) arriving
//! while it runs, and named snapshots to go back to.
//!
//! **When a command takes effect.** A command is checked when it arrives (a refusal carries the
//! message `--set` or a scenario file would get) and queued. The queue is applied at the next
//! *sync point*: the integrator's time when it next leaves it, which is the end of the last step
//! taken (never earlier than the time shown). There each command becomes a scenario event at
//! exactly that time, applied by the driver as a file's event is, all of them before one restart.
//! The steps before it are the ones a run with that event in its file takes (that run's last step
//! is clipped onto the event's time, which differs from the live step by rounding only), so the
//! scenario [`Live::journal`] writes — the file's events, then every command at its time, ending at
//! the current sync point — reproduces the live trajectory to rounding.
//!
//! **Clock.** [`Clock`] maps wall time to simulated time (speed, pause); the caller advances the
//! run to the clock's time with [`Live::advance_to`] and reads values interpolated within the last
//! step ([`Live::values_at`]).

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Instant;

use plantwide_flowsheet::Plant;
use plantwide_flowsheet::overrides::set_input;
use plantwide_flowsheet::scenario::{Event, EventSpec, Scenario, ScenarioSpec, resolve_continuing};
use plantwide_flowsheet::{Diagnostic, LoadError};
use plantwide_model::controllers::Mode;
use plantwide_units::QuantityValue;

use super::driver::{Driver, RunError};
use super::{SimError, Snapshot, Start};

/// Largest step of a live run whose scenario sets none \[s\]: a command waits at most this long
/// in simulated time for its sync point.
pub const LIVE_MAX_STEP: f64 = 10.0;

/// The most named snapshots a live run keeps.
pub const MAX_SNAPSHOTS: usize = 64;

/// Why a live run refused a command or stopped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LiveError {
    /// The command is not valid (a bad path, unit, value, name); the run goes on.
    #[error("{0}")]
    Refused(String),
    /// The run could not start (the scenario or a snapshot does not fit the plant).
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The integrator failed: the run is stopped until a snapshot is loaded.
    #[error("{0}")]
    Failed(String),
    /// The run stopped at an earlier failure; loading a snapshot continues it.
    #[error("the run is stopped: {0}")]
    Stopped(String),
}

/// A command that acts on the plant (as a scenario event).
#[derive(Debug, Clone, PartialEq)]
pub enum PlantCommand {
    /// An input (or a setpoint `<ctrl>.sp`) to a value with its unit, as `--set` writes it.
    Set {
        /// Input path or alias.
        path: String,
        /// Value, e.g. `"1.01 kmol/min"`.
        value: String,
    },
    /// A PID controller to auto or manual (bumpless).
    Mode {
        /// Controller name.
        controller: String,
        /// The mode.
        mode: Mode,
    },
    /// Any scenario event (its `at` is replaced by the sync point's time).
    Event(EventSpec),
}

/// A command checked and waiting for its sync point: the event as a file would write it (at 0)
/// and its resolution (times from 0).
#[derive(Debug, Clone)]
struct Queued {
    spec: EventSpec,
    events: Box<[Event]>,
}

/// A named snapshot: the run's state and the commands applied up to it (shared with the journal
/// and the other snapshots: a snapshot costs a pointer per command, not a copy of each).
#[derive(Debug, Clone)]
struct Saved {
    snapshot: Snapshot,
    journal: Vec<Arc<Queued>>,
}

/// A plant run live.
pub struct Live {
    /// The caller's plant (commands are resolved against it).
    plant: Plant,
    /// The scenario as written (the journal extends it) and as resolved, with an endless duration.
    spec: ScenarioSpec,
    base: Scenario,
    fingerprint: String,
    driver: Driver<'static>,
    /// Commands applied, their events at their times.
    journal: Vec<Arc<Queued>>,
    pending: Vec<Queued>,
    saved: BTreeMap<String, Saved>,
    /// Time of the last (re)start: values are not interpolated before it.
    floor: f64,
    failed: Option<String>,
}

impl Live {
    /// A live run of `plant` from the steady state `x0` under `spec` (already resolved against
    /// `plant` as `scenario`); `fingerprint` identifies the plant in snapshots. The run is endless:
    /// the scenario's duration only bounds what it asks for (recorded rows, samples).
    ///
    /// # Errors
    /// [`LiveError::Sim`] if the scenario does not fit the plant or no consistent start is found.
    pub fn new(
        plant: &Plant,
        x0: &[f64],
        spec: &ScenarioSpec,
        scenario: &Scenario,
        fingerprint: &str,
    ) -> Result<Live, LiveError> {
        let mut spec = spec.clone();
        let mut base = scenario.clone();
        base.duration = f64::INFINITY;
        base.snapshots.clear();
        spec.snapshots.clear();
        if !base.max_step.is_finite() {
            base.max_step = LIVE_MAX_STEP;
            spec.integrator.max_step = Some(QuantityValue::Number(LIVE_MAX_STEP));
        }
        let mut driver = Driver::new(Cow::Owned(plant.clone()), &base, Start::Steady(x0), fingerprint)?;
        driver.endless();
        driver.start().map_err(|e| LiveError::Failed(failure(plant, RunError::Dae(e))))?;
        Ok(Live {
            plant: plant.clone(),
            spec,
            base,
            fingerprint: fingerprint.to_string(),
            driver,
            journal: Vec::new(),
            pending: Vec::new(),
            saved: BTreeMap::new(),
            floor: 0.0,
            failed: None,
        })
    }

    /// The plant run (as the caller gave it).
    pub fn plant(&self) -> &Plant {
        &self.plant
    }

    /// The sync point: the integrator's time \[s\], where queued commands take effect.
    pub fn sync_time(&self) -> f64 {
        self.driver.t()
    }

    /// The earliest time values can be shown for: the last (re)start \[s\].
    pub fn floor(&self) -> f64 {
        self.floor
    }

    /// The failure that stopped the run, if any.
    pub fn failure(&self) -> Option<&str> {
        self.failed.as_deref()
    }

    /// Commands waiting for the next sync point.
    pub fn pending(&self) -> usize {
        self.pending.len()
    }

    /// Check `cmd` against the plant and queue it for the next sync point.
    ///
    /// # Errors
    /// [`LiveError::Refused`] with the message `--set` or a scenario file would get.
    pub fn command(&mut self, cmd: PlantCommand) -> Result<(), LiveError> {
        let zero = QuantityValue::Number(0.0);
        let spec = match cmd {
            PlantCommand::Set { path, value } => {
                // `--set`'s checks and messages; a path that names no input (`Ok(false)`) is
                // reported by the scenario's resolution below, with its suggestions.
                let mut u = self.plant.input_values();
                set_input(&self.plant, &mut u, &path, &value).map_err(|e| LiveError::Refused(e.to_string()))?;
                EventSpec::Step { at: zero, path, to: Some(QuantityValue::Text(value)), by: None }
            }
            PlantCommand::Mode { controller, mode } => EventSpec::Mode { at: zero, controller, mode, output: None },
            PlantCommand::Event(e) => at_time(e, 0.0),
        };
        // The journal is a scenario file: it may hold no more events than a scenario may.
        let limits = plantwide_model::limits::Limits::get();
        let held: usize =
            self.journal.iter().map(|q| q.events.len()).chain(self.pending.iter().map(|q| q.events.len())).sum();
        if held >= limits.max_events {
            return Err(LiveError::Refused(format!(
                "the live run's journal holds {held} events, the most a scenario may ({} = {}); save a snapshot's \
                 journal if needed and restart the server to command it further",
                plantwide_model::limits::Limits::MAX_EVENTS,
                limits.max_events
            )));
        }
        let events = self.resolve_one(&spec)?.into_boxed_slice();
        let Some(first) = events.first().map(|e| e.action.clone()) else { return Ok(()) };
        let queued =
            self.pending.iter().position(|q| q.events.first().is_some_and(|e| e.action.target() == first.target()));
        if let Some(k) = queued {
            let before = &self.pending[k].events[0].action;
            if before.is_fault() && first.is_repair() {
                // A fault repaired at the sync point it was queued for never happens: neither goes
                // into the journal (a scenario may not hold both at one time).
                self.pending.remove(k);
                return Ok(());
            }
            if before.is_repair() && first.is_fault() {
                return Err(LiveError::Refused(format!(
                    "its repair is queued for the sync point at t = {} s, and a scenario may not repair and fail \
                     it again at one time: step or resume first",
                    self.driver.t()
                )));
            }
            if before.is_fault() || before.is_repair() || first.is_fault() || first.is_repair() {
                // A change would silently drop a fault or repair already acknowledged, or go
                // into the journal beside it at one time on one target.
                return Err(LiveError::Refused(format!(
                    "a {} of it is queued for the sync point at t = {} s: step or resume first",
                    if before.is_fault() {
                        "fault"
                    } else if before.is_repair() {
                        "repair"
                    } else {
                        "change"
                    },
                    self.driver.t()
                )));
            }
            // Another change of the same target at the same sync point: the later one stands.
            self.pending.remove(k);
        }
        self.pending.push(Queued { spec, events });
        Ok(())
    }

    /// The faults in force once the queued commands apply: what a new command is checked against
    /// (a repair of a fault queued at this sync point, a second fault of one queued).
    fn ongoing(&self) -> plantwide_flowsheet::scenario::Ongoing {
        let mut ongoing = self.driver.ongoing();
        self.pending.iter().for_each(|q| ongoing.follow(&q.events));
        ongoing
    }

    /// Check every one of `cmds` and queue them all, or none if one is refused.
    ///
    /// # Errors
    /// The first refusal, as [`Live::command`].
    pub fn commands(&mut self, cmds: Vec<PlantCommand>) -> Result<(), LiveError> {
        let before = self.pending.clone();
        for c in cmds {
            if let Err(e) = self.command(c) {
                self.pending = before;
                return Err(e);
            }
        }
        Ok(())
    }

    /// The events of one command at time 0, resolved as a file's would be against the plant at
    /// its inputs' values now (a change `by` an amount is checked from the live value).
    fn resolve_one(&self, e: &EventSpec) -> Result<Vec<Event>, LiveError> {
        let t = self.driver.t();
        let mut plant = self.plant.clone();
        let now: Vec<f64> = (0..plant.inputs().len()).map(|i| self.driver.input_value(i, t)).collect();
        plant.set_input_values(&now);
        let spec = ScenarioSpec {
            format_version: self.spec.format_version,
            name: String::new(),
            description: String::new(),
            duration: QuantityValue::Number(1.0),
            integrator: Default::default(),
            events: vec![e.clone()],
            when: Vec::new(),
            sampling: Default::default(),
            analyzers: Default::default(),
            record: Default::default(),
            snapshots: Vec::new(),
        };
        match resolve_continuing(&spec, &plant, "command", self.ongoing()) {
            Ok(sc) => Ok(sc.events),
            Err(LoadError::Invalid { diagnostics, .. }) => Err(LiveError::Refused(message(&diagnostics))),
            Err(e) => Err(LiveError::Refused(e.to_string())),
        }
    }

    /// Apply the queued commands at the sync point: each becomes a scenario event at its time.
    fn apply_pending(&mut self) {
        if self.pending.is_empty() {
            return;
        }
        let t = self.driver.t();
        for mut q in std::mem::take(&mut self.pending) {
            q.spec = at_time(q.spec, t);
            q.events.iter_mut().for_each(|e| e.t += t);
            self.driver.insert_events(&q.events);
            self.journal.push(Arc::new(q));
        }
        self.floor = t;
    }

    /// Take one integrator step (after applying the queued commands).
    ///
    /// # Errors
    /// [`LiveError::Failed`] when the integrator fails (the run then stays stopped),
    /// [`LiveError::Stopped`] after such a failure, or when a scenario condition ends the run.
    pub fn step(&mut self) -> Result<(), LiveError> {
        if let Some(why) = &self.failed {
            return Err(LiveError::Stopped(why.clone()));
        }
        self.apply_pending();
        let done = self.driver.step_once(&mut |_| {});
        self.driver.forget_records();
        match done {
            Ok(_) => match self.driver.tripped() {
                // A condition's `stop` ends a live run as it ends a run: it stays stopped.
                Some(why) => {
                    let why = format!("{}: stopped: {why}", self.plant.file());
                    self.failed = Some(why.clone());
                    Err(LiveError::Stopped(why))
                }
                None => Ok(()),
            },
            Err(e) => {
                let why = failure(&self.plant, e);
                self.failed = Some(why.clone());
                Err(LiveError::Failed(why))
            }
        }
    }

    /// Take steps until the sync point reaches `t` or `deadline` passes; true if it was reached.
    ///
    /// # Errors
    /// As [`Live::step`].
    pub fn advance_to(&mut self, t: f64, deadline: Instant) -> Result<bool, LiveError> {
        while self.driver.t() < t {
            if Instant::now() >= deadline {
                return Ok(false);
            }
            self.step()?;
        }
        Ok(true)
    }

    /// The paths of [`Live::values_at`]: every plant variable, then every input no controller
    /// drives (as `steady --json` lists them).
    pub fn paths(&self) -> Vec<String> {
        let vars = self.plant.vars().iter().map(|v| v.path.clone());
        vars.chain(self.free_inputs().map(|i| self.plant.inputs()[i].path.clone())).collect()
    }

    fn free_inputs(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.plant.inputs().len()).filter(|&i| self.plant.inputs()[i].driven_by.is_none())
    }

    /// The values (SI) of [`Live::paths`] at `t`, interpolated within the last step (`t` is
    /// clamped to the last restart and the sync point).
    pub fn values_at(&self, t: f64) -> Vec<f64> {
        let t = t.clamp(self.floor, self.driver.t());
        let mut x = vec![0.0; self.driver.x().len()];
        self.driver.interpolate(t, &mut x);
        x.truncate(self.plant.n_vars());
        x.extend(self.free_inputs().map(|i| self.driver.input_value(i, t)));
        x
    }

    /// Keep the run's state under `name` (replacing one of that name).
    ///
    /// # Errors
    /// [`LiveError::Refused`] for a name that is empty, longer than 64 characters or not made of
    /// letters, digits, `-`, `_` and `.`, or beyond [`MAX_SNAPSHOTS`].
    pub fn save(&mut self, name: &str) -> Result<(), LiveError> {
        let ok = !name.is_empty()
            && name.chars().count() <= 64
            && name.chars().all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c));
        if !ok {
            return Err(LiveError::Refused(format!(
                "snapshot name `{}`: use 1 to 64 letters, digits, `-`, `_` or `.`",
                name.chars().take(64).collect::<String>()
            )));
        }
        if self.saved.len() >= MAX_SNAPSHOTS && !self.saved.contains_key(name) {
            return Err(LiveError::Refused(format!(
                "snapshot `{name}`: {MAX_SNAPSHOTS} snapshots are kept already, the most a live run keeps; save under \
                 one of their names to replace it"
            )));
        }
        let saved = Saved { snapshot: self.driver.snapshot(), journal: self.journal.clone() };
        self.saved.insert(name.to_string(), saved);
        Ok(())
    }

    /// Go back to the snapshot `name`: its state, integrator history and commands; the queued
    /// commands are dropped and a stopped run runs again.
    ///
    /// # Errors
    /// [`LiveError::Refused`] if there is no such snapshot; [`LiveError::Sim`] if it cannot resume.
    pub fn load(&mut self, name: &str) -> Result<(), LiveError> {
        let Some(saved) = self.saved.get(name).cloned() else {
            let known: Vec<&str> = self.saved.keys().map(String::as_str).collect();
            return Err(LiveError::Refused(format!("no snapshot named `{name}` (saved: {})", known.join(", "))));
        };
        let mut sc = self.base.clone();
        sc.events.extend(saved.journal.iter().flat_map(|q| q.events.iter().cloned()));
        sc.events.sort_by(|a, b| a.t.total_cmp(&b.t));
        let owned = Cow::Owned(self.plant.clone());
        let mut driver = Driver::new(owned, &sc, Start::Snapshot(&saved.snapshot), &self.fingerprint)?;
        driver.endless();
        driver.start().map_err(|e| LiveError::Failed(failure(&self.plant, RunError::Dae(e))))?;
        self.driver = driver;
        self.journal = saved.journal;
        self.pending.clear();
        self.floor = saved.snapshot.t;
        self.failed = None;
        Ok(())
    }

    /// The names of the snapshots kept.
    pub fn snapshots(&self) -> Vec<String> {
        self.saved.keys().cloned().collect()
    }

    /// The scenario that reproduces this run from its start: the file's, with every command
    /// applied as an event at its time, ending at the sync point (and the step limit the live run
    /// used written out).
    pub fn journal(&self) -> ScenarioSpec {
        let mut spec = self.spec.clone();
        spec.events.extend(self.journal.iter().map(|q| q.spec.clone()));
        spec.duration = QuantityValue::Number(self.driver.t());
        spec
    }
}

/// `e` at time `t` \[s\].
fn at_time(mut e: EventSpec, t: f64) -> EventSpec {
    let at = QuantityValue::Number(t);
    match &mut e {
        EventSpec::Step { at: a, .. }
        | EventSpec::Ramp { at: a, .. }
        | EventSpec::Pulse { at: a, .. }
        | EventSpec::Sinusoid { at: a, .. }
        | EventSpec::Mode { at: a, .. }
        | EventSpec::ValveStuck { at: a, .. }
        | EventSpec::ValveRepaired { at: a, .. }
        | EventSpec::FeedLost { at: a, .. }
        | EventSpec::FeedRestored { at: a, .. }
        | EventSpec::AnalyzerFrozen { at: a, .. }
        | EventSpec::AnalyzerRepaired { at: a, .. } => *a = at,
    }
    e
}

/// A command's problems in one line, each under its field (`to`, `path`) rather than the
/// one-event scenario's `events[0]`.
fn message(diagnostics: &[Diagnostic]) -> String {
    let one = |d: &Diagnostic| {
        let field = d.path.strip_prefix("events[0]").unwrap_or(&d.path).trim_start_matches('.');
        if field.is_empty() { d.message.clone() } else { format!("{field}: {}", d.message) }
    };
    diagnostics.iter().map(one).collect::<Vec<_>>().join("; ")
}

/// A driver failure's message, as `run` would give it.
fn failure(plant: &Plant, e: RunError) -> String {
    let file = plant.file();
    match e {
        RunError::Dae(source) => {
            format!("{file}: integration failed: {source}{}", super::failure_hint(&source))
        }
        RunError::Mpc(source) => format!("{file}: {source}"),
        RunError::Stopped(reason) => format!("{file}: stopped: {reason}"),
    }
}

/// Simulated time from wall time: `t = t₀ + speed · (now − w₀)` while running, `t₀` while paused.
/// Every change re-anchors at the time shown, so the shown time never jumps back.
#[derive(Debug, Clone, Copy)]
pub struct Clock {
    speed: f64,
    running: bool,
    t0: f64,
    w0: Instant,
}

impl Clock {
    /// Fastest speed accepted (simulated seconds per wall second).
    pub const MAX_SPEED: f64 = 1e6;

    /// A clock showing `t` at `now`, running at real time.
    pub fn new(t: f64, now: Instant) -> Clock {
        Clock { speed: 1.0, running: true, t0: t, w0: now }
    }

    /// The time shown at `now` \[s\].
    pub fn shown(&self, now: Instant) -> f64 {
        if self.running { self.t0 + self.speed * now.saturating_duration_since(self.w0).as_secs_f64() } else { self.t0 }
    }

    /// Simulated seconds per wall second.
    pub fn speed(&self) -> f64 {
        self.speed
    }

    /// Whether the clock runs.
    pub fn running(&self) -> bool {
        self.running
    }

    /// Run at `speed` from `now` on.
    ///
    /// # Errors
    /// [`LiveError::Refused`] unless `0 < speed ≤ MAX_SPEED`.
    pub fn set_speed(&mut self, speed: f64, now: Instant) -> Result<(), LiveError> {
        if !(speed > 0.0 && speed <= Self::MAX_SPEED) {
            return Err(LiveError::Refused(format!(
                "speed {speed}: give a number of simulated seconds per second above 0 and at most {:e}",
                Self::MAX_SPEED
            )));
        }
        self.at(self.shown(now), now);
        self.speed = speed;
        Ok(())
    }

    /// Stop at the time shown at `now`.
    pub fn pause(&mut self, now: Instant) {
        self.at(self.shown(now), now);
        self.running = false;
    }

    /// Run again from the time shown.
    pub fn resume(&mut self, now: Instant) {
        self.at(self.shown(now), now);
        self.running = true;
    }

    /// Show `t` at `now` (after a sync point moved the time on, a snapshot was loaded, or the run
    /// fell behind the clock).
    pub fn at(&mut self, t: f64, now: Instant) {
        self.t0 = t;
        self.w0 = now;
    }
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use plantwide_flowsheet::scenario::{parse_scenario, resolve};

    use super::*;

    /// A week-long session saves snapshots again and again: each must hold the journal's entries,
    /// not copies of them (64 snapshots of a 10 000-event journal were 64 × 10 000 copies).
    #[test]
    fn snapshots_share_the_journals_commands_rather_than_copy_them() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../flowsheets/surge_tank_pi.json");
        let plant = plantwide_flowsheet::load_file(std::path::Path::new(path)).expect("loads");
        let u = plant.input_values();
        let x0 = crate::steady_state(&plant, &u, None, &crate::NewtonSettings::default()).expect("converges").x;
        let spec =
            parse_scenario(r#"{"format_version": 1, "name": "live", "duration": "1 h"}"#, "live").expect("parses");
        let sc = resolve(&spec, &plant, "live").expect("resolves");
        let mut live = Live::new(&plant, &x0, &spec, &sc, "test").expect("starts");
        for value in ["51 mol/s", "49 mol/s"] {
            live.command(PlantCommand::Set { path: "F_in".into(), value: value.into() }).expect("a valid command");
            live.step().expect("steps");
        }
        live.save("a").expect("saves");
        live.save("b").expect("saves");
        assert_eq!(live.journal.len(), 2);
        for saved in live.saved.values() {
            assert!(saved.journal.iter().zip(&live.journal).all(|(s, j)| Arc::ptr_eq(s, j)), "a copy");
        }
        live.load("a").expect("loads");
        assert_eq!(live.journal().events.len(), 2);
    }

    /// Commands at one sync point (a paused session) are checked against the faults the queued
    /// ones leave: a stuck valve repaired before time moves cancels (the journal holds neither
    /// and replays), a second fault of a queued one is refused, and so is a fault of a valve
    /// whose repair is queued (a serve soak had 239 refusals "has failed already" of faults
    /// repaired moments before, the repair still queued), and a change of an input whose fault is
    /// queued (it replaced the fault, acknowledged and then dropped).
    #[test]
    fn commands_at_one_sync_point_see_the_faults_queued_before_them() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../flowsheets/surge_tank_pi.json");
        let plant = plantwide_flowsheet::load_file(std::path::Path::new(path)).expect("loads");
        let x0 = crate::steady_state(&plant, &plant.input_values(), None, &crate::NewtonSettings::default())
            .expect("converges")
            .x;
        let spec = parse_scenario(r#"{"format_version": 1, "name": "live", "duration": "1 h"}"#, "live").unwrap();
        let sc = resolve(&spec, &plant, "live").expect("resolves");
        let mut live = Live::new(&plant, &x0, &spec, &sc, "test").expect("starts");
        let event = |text: &str| PlantCommand::Event(serde_json::from_str(text).expect("an event"));
        let stuck = r#"{"type": "valve_stuck", "at": 0, "path": "tank.outflow"}"#;
        let repaired = r#"{"type": "valve_repaired", "at": 0, "path": "tank.outflow"}"#;
        live.command(event(stuck)).expect("a fault");
        let twice = live.command(event(stuck)).expect_err("a second fault of a queued one");
        assert!(twice.to_string().contains("has failed already"), "{twice}");
        live.command(event(repaired)).expect("the queued fault repaired");
        assert_eq!(live.pending(), 0, "fault and repair cancel");
        live.step().expect("steps");
        assert!(live.journal().events.is_empty());
        live.command(event(stuck)).expect("a fault");
        live.step().expect("steps");
        live.command(event(repaired)).expect("a repair");
        let again = live.command(event(stuck)).expect_err("a fault while its repair is queued");
        assert!(again.to_string().contains("its repair is queued"), "{again}");
        live.step().expect("steps");
        live.command(event(stuck)).expect("a fault after the repair applied");
        live.step().expect("steps");
        // A change of a feed whose loss is queued would drop the acknowledged fault: refused.
        live.command(event(r#"{"type": "feed_lost", "at": 0, "unit": "inflow"}"#)).expect("a lost feed");
        let set = live.command(PlantCommand::Set { path: "F_in".into(), value: "60 mol/s".into() });
        assert!(set.expect_err("a change over a queued fault").to_string().contains("a fault of it is queued"));
        live.step().expect("steps");
        let journal = live.journal();
        assert_eq!(journal.events.len(), 4, "{:?}", journal.events);
        let text = serde_json::to_string(&journal).unwrap();
        resolve(&parse_scenario(&text, "journal").unwrap(), &plant, "journal").expect("the journal replays");
    }

    #[test]
    fn the_clock_runs_at_its_speed_stops_when_paused_and_never_jumps_back() {
        let w0 = Instant::now();
        let at = |s: f64| w0 + Duration::from_secs_f64(s);
        let mut c = Clock::new(100.0, w0);
        assert_eq!(c.shown(at(2.0)), 102.0);
        c.set_speed(60.0, at(2.0)).expect("a valid speed");
        assert_eq!(c.shown(at(3.0)), 162.0);
        c.pause(at(3.0));
        assert_eq!((c.shown(at(10.0)), c.running()), (162.0, false));
        c.resume(at(10.0));
        assert_eq!(c.shown(at(11.0)), 222.0);
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, 2.0 * Clock::MAX_SPEED] {
            assert!(matches!(c.set_speed(bad, at(11.0)), Err(LiveError::Refused(_))), "{bad}");
        }
        assert_eq!(c.speed(), 60.0);
    }
}
