//! Dynamic simulation of a [`Plant`] under a [`Scenario`]: the plant DAE `M dx/dt = f(x, u(t), t)`
//! integrated by [`Bdf`](crate::dae::Bdf), stopped exactly at every discrete time (scenario events, controller scans,
//! analyzer samples and results), where the inputs change, the algebraic variables are made
//! consistent and the integrator restarts at order 1.
//!
//! **Inputs** are piecewise [`Waveform`]s (constant, ramp, sinusoid), changed only at events.
//! **Discrete controller behaviour** rewires a copy of the plant (the caller's is left as it is),
//! through the flowsheet's wiring methods only: a sampled controller's driven inputs read a held
//! input (set to the controller's output at every scan: zero-order hold), an analyzer's
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
//!
//! Layout: `waveform` (input waveforms), `adapter` (the DAE over the plant and the quadratures of
//! the integrated streams), `driver` (the event driver), `live` (the driver advanced by an
//! interactive clock, commands applied as events), `snapshot` (the snapshot format),
//! [`conservation`] (the material balance checked at the end); this file is the public face.

use serde::Serialize;

use plantwide_flowsheet::scenario::Scenario;
use plantwide_flowsheet::{Plant, WiringError};

use crate::dae::{BdfStats, DaeError};

mod adapter;
pub mod conservation;
mod driver;
mod instants;
mod live;
mod mpc;
mod session;
mod snapshot;
mod table;
mod waveform;

pub use conservation::{CONSERVATION_TOL, Conservation, ConservationError};
pub use live::{Clock, LIVE_MAX_STEP, Live, LiveError, MAX_SNAPSHOTS, PlantCommand};
pub use mpc::{MpcError, MpcLog, StepModelFile, file_model, mv_limits};
pub use session::{Session, SessionError};
pub use snapshot::{DriverState, SNAPSHOT_VERSION, Snapshot};
pub use table::{Rows, Table};
pub use waveform::Waveform;

use driver::Driver;

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
        /// What the failure may mean for the plant ([`failure_hint`]).
        detail: String,
        /// What was recorded up to the failure (the trends that lead to it).
        partial: Box<SimulationResult>,
    },
    /// The plant stopped: a vessel ran dry (with the run up to there).
    #[error("{file}: stopped: {reason}")]
    Stopped {
        /// Flowsheet file.
        file: String,
        /// Which holdup, when, and what keeps it from happening.
        reason: String,
        /// What was recorded up to the stop.
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
    /// The scenario's analyzers do not fit the plant's wiring.
    #[error(transparent)]
    Wiring(#[from] WiringError),
    /// A model predictive controller could not be built (its model) or its QP failed during the
    /// run (with the run up to there, if it had started).
    #[error("{file}: {source}")]
    Mpc {
        /// Flowsheet file.
        file: String,
        /// The controller and what failed.
        source: MpcError,
        /// The run up to the failure.
        partial: Option<Box<SimulationResult>>,
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

impl SimError {
    /// True when the run never started for a reason the caller can fix (a snapshot or analyzer
    /// that does not fit the plant, an MPC whose model cannot be built): the CLI's exit 1; a run
    /// that failed on its way is numerical (exit 2).
    pub fn is_user_error(&self) -> bool {
        matches!(self, SimError::Snapshot { .. } | SimError::Wiring(_) | SimError::Mpc { partial: None, .. })
    }
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
    pub rows: Table,
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
    /// Per model predictive controller: its QP statuses and solve times.
    pub mpc: Vec<MpcLog>,
    /// The condition (`when` with `"stop": true`) that ended the run before its duration, and
    /// where: the trip the scenario asked for (the run is complete up to `t`).
    pub tripped: Option<String>,
}

/// Run `scenario` on `plant` from `start`. A copy of the plant is rewired for sampled
/// controllers, analyzers and stuck valves; `plant` itself is not changed. `fingerprint`
/// identifies the plant description in snapshots. Snapshots the scenario asks for are handed to
/// `observer`, with the progress.
///
/// # Errors
/// [`SimError::Snapshot`] or [`SimError::Wiring`] if the snapshot or the scenario does not fit
/// the plant; [`SimError::Integration`] if the integrator stops (with the run up to there);
/// [`SimError::Conservation`] if the finished run does not conserve material.
pub fn simulate(
    plant: &Plant,
    scenario: &Scenario,
    start: Start<'_>,
    fingerprint: &str,
    observer: &mut dyn FnMut(Progress<'_>),
) -> Result<SimulationResult, SimError> {
    let file = plant.file().to_string();
    let mut d = Driver::new(std::borrow::Cow::Borrowed(plant), scenario, start, fingerprint)?;
    match d.run(observer) {
        Ok(()) => {}
        Err(driver::RunError::Dae(source)) => {
            let detail = failure_hint(&source).to_string();
            return Err(SimError::Integration { file, source, detail, partial: Box::new(d.finish()) });
        }
        Err(driver::RunError::Mpc(source)) => {
            return Err(SimError::Mpc { file, source, partial: Some(Box::new(d.finish())) });
        }
        Err(driver::RunError::Stopped(reason)) => {
            return Err(SimError::Stopped { file, reason, partial: Box::new(d.finish()) });
        }
    }
    let res = d.finish();
    match res.conservation.check(CONSERVATION_TOL) {
        Ok(()) => Ok(res),
        Err(source) => Err(SimError::Conservation { file, source, result: Box::new(res) }),
    }
}

/// What an integration failure may mean for the plant, after the integrator's own message (which
/// names the unit, equation and variable): a consistent start that fails is most often a state the
/// plant cannot reach — a vessel running dry or overflowing, a flow reversing, or, on a
/// controller's equation, an output the plant cannot take ([`DaeSystem::equation_hint`]).
pub(crate) fn failure_hint(source: &DaeError) -> &'static str {
    match source {
        DaeError::Initialization(inc) => inc
            .equation
            .hint
            .unwrap_or("; a vessel running dry or overflowing, or a flow reversing, ends a run this way"),
        _ => "",
    }
}
