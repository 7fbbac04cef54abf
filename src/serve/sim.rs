//! The simulation thread: owns the [`Live`] run and its [`Clock`], advances the run to the clock's
//! time on every tick, answers requests from the HTTP handlers over a channel and publishes the
//! values at the time shown (read by `GET /api/state` and streamed to trend clients).
//!
//! The integration is CPU-bound, so it runs on a thread of its own rather than on the async
//! runtime; a tick gives it at most [`BUDGET`] of work, after which a run that cannot keep up with
//! the clock is shown where it is and the clock re-anchored there (`behind`).

use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::sync::{Arc, RwLock};
use std::time::{Duration, Instant};

use plantwide::flowsheet::scenario::{EventSpec, ScenarioSpec};
use plantwide::model::controllers::Mode;
use plantwide::solve::dynamic::{Clock, Live, LiveError, PlantCommand};
use tokio::sync::{broadcast, oneshot};

/// Wall time between publications.
pub const TICK: Duration = Duration::from_millis(100);
/// Most integration work per tick.
pub const BUDGET: Duration = Duration::from_millis(80);

/// What the page sees at one moment.
#[derive(Debug, Clone)]
pub struct Published {
    /// Time shown \[s\].
    pub time: f64,
    /// The integrator's time, where the next commands take effect \[s\].
    pub sync_time: f64,
    /// Whether the clock runs.
    pub running: bool,
    /// Simulated seconds per wall second.
    pub speed: f64,
    /// The run could not keep up with the clock at the last tick.
    pub behind: bool,
    /// Commands waiting for the next sync point.
    pub pending: usize,
    /// Why the run stopped, if it did.
    pub failure: Option<String>,
    /// Values (SI) of every path, at `time`.
    pub values: Vec<f64>,
}

/// One command of `POST /api/command`, typed.
#[derive(Debug, Clone)]
pub enum Command {
    /// Inputs to values, as `--set` writes them (one sync point).
    Set(Vec<(String, String)>),
    /// Controllers to auto or manual.
    Mode(Vec<(String, Mode)>),
    /// A scenario event.
    Event(Box<EventSpec>),
    /// Clock speed.
    Speed(f64),
    /// Stop the clock.
    Pause,
    /// Run the clock.
    Resume,
    /// One integrator step (the clock shows its end, paused).
    Step,
    /// Keep the state under a name.
    Snapshot(String),
    /// Go back to a named state.
    Load(String),
}

/// A request to the simulation thread.
pub enum Request {
    /// Apply a command; the reply is the sync point it takes effect at, or the refusal.
    Command(Command, oneshot::Sender<Result<f64, LiveError>>),
    /// The values at the sync point (exact, not interpolated).
    AtSync(oneshot::Sender<Published>),
    /// The scenario reproducing the run so far.
    Journal(oneshot::Sender<ScenarioSpec>),
    /// The names of the snapshots kept.
    Snapshots(oneshot::Sender<Vec<String>>),
}

/// The simulation thread's state.
pub struct Sim {
    live: Live,
    clock: Clock,
    behind: bool,
    latest: Arc<RwLock<Arc<Published>>>,
    stream: broadcast::Sender<Arc<Published>>,
}

impl Sim {
    /// A thread state for `live`, its clock at the start running at `speed`.
    pub fn new(
        live: Live,
        speed: f64,
        latest: Arc<RwLock<Arc<Published>>>,
        stream: broadcast::Sender<Arc<Published>>,
    ) -> Result<Sim, LiveError> {
        let mut clock = Clock::new(live.sync_time(), Instant::now());
        clock.set_speed(speed, Instant::now())?;
        Ok(Sim { live, clock, behind: false, latest, stream })
    }

    /// Stop the clock (a server started paused).
    pub fn pause(&mut self) {
        self.clock.pause(Instant::now());
    }

    /// Serve requests and advance the run until every sender is gone.
    pub fn run(mut self, rx: &Receiver<Request>) {
        let mut next_tick = Instant::now();
        loop {
            self.advance();
            self.publish();
            next_tick += TICK;
            let now = Instant::now();
            if next_tick < now {
                next_tick = now;
            }
            // Requests until the next tick; each command's effect is published at once.
            loop {
                match rx.recv_timeout(next_tick.saturating_duration_since(Instant::now())) {
                    Ok(req) => self.handle(req),
                    Err(RecvTimeoutError::Timeout) => break,
                    Err(RecvTimeoutError::Disconnected) => return,
                }
            }
        }
    }

    /// Advance the run to the clock's time, within the tick's budget.
    fn advance(&mut self) {
        let now = Instant::now();
        if !self.clock.running() || self.live.failure().is_some() {
            return;
        }
        match self.live.advance_to(self.clock.shown(now), now + BUDGET) {
            Ok(reached) => {
                self.behind = !reached;
                if !reached {
                    self.clock.at(self.live.sync_time(), Instant::now());
                }
            }
            Err(_) => self.clock.pause(now),
        }
        self.catch_up(Instant::now());
    }

    /// Commands applied at a sync point ahead of the clock move the clock on to it.
    fn catch_up(&mut self, now: Instant) {
        if self.clock.shown(now) < self.live.floor() {
            self.clock.at(self.live.floor(), now);
        }
    }

    /// The time shown: the clock's, within what the run has reached.
    fn shown(&self, now: Instant) -> f64 {
        self.clock.shown(now).clamp(self.live.floor(), self.live.sync_time())
    }

    fn snapshot_at(&self, time: f64) -> Published {
        Published {
            time,
            sync_time: self.live.sync_time(),
            running: self.clock.running(),
            speed: self.clock.speed(),
            behind: self.behind,
            pending: self.live.pending(),
            failure: self.live.failure().map(str::to_string),
            values: self.live.values_at(time),
        }
    }

    fn publish(&self) {
        let p = Arc::new(self.snapshot_at(self.shown(Instant::now())));
        if let Ok(mut w) = self.latest.write() {
            *w = p.clone();
        }
        // No subscriber is not an error.
        let _ = self.stream.send(p);
    }

    fn handle(&mut self, req: Request) {
        match req {
            Request::Command(c, reply) => {
                let result = self.command(c);
                // Published before the answer: a client reading the state after it sees the command.
                self.publish();
                let _ = reply.send(result);
            }
            Request::AtSync(reply) => {
                let _ = reply.send(self.snapshot_at(self.live.sync_time()));
            }
            Request::Journal(reply) => {
                let _ = reply.send(self.live.journal());
            }
            Request::Snapshots(reply) => {
                let _ = reply.send(self.live.snapshots());
            }
        }
    }

    /// Apply `c`; the sync point at which it takes effect.
    fn command(&mut self, c: Command) -> Result<f64, LiveError> {
        let now = Instant::now();
        match c {
            Command::Set(pairs) => self
                .live
                .commands(pairs.into_iter().map(|(path, value)| PlantCommand::Set { path, value }).collect())?,
            Command::Mode(modes) => self.live.commands(
                modes.into_iter().map(|(controller, mode)| PlantCommand::Mode { controller, mode }).collect(),
            )?,
            Command::Event(e) => self.live.command(PlantCommand::Event(*e))?,
            Command::Speed(k) => self.clock.set_speed(k, now)?,
            Command::Pause => self.clock.pause(now),
            Command::Resume => self.clock.resume(now),
            Command::Step => {
                self.clock.pause(now);
                self.live.step()?;
                self.clock.at(self.live.sync_time(), now);
            }
            Command::Snapshot(name) => self.live.save(&name)?,
            Command::Load(name) => {
                self.live.load(&name)?;
                self.clock.at(self.live.sync_time(), now);
            }
        }
        self.catch_up(now);
        Ok(self.live.sync_time())
    }
}
