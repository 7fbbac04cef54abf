//! Surge sizing (issue 18): how big a vessel must be, and with which level controller, so that a
//! disturbance reaching it leaves its level within a band and changes its outflow no faster than
//! a limit; and where in a plant surge capacity does that with the least volume.
//!
//! For a vessel with a PID level loop on a flow, and a disturbance (an input stepped by `Δ`):
//! 1. the flow change `Δu` the outflow must make is the difference of two checked steady states
//!    (before and after the disturbance, every loop as the file has it), and the liquid's molar
//!    volume `v_L` is read at the steady state;
//! 2. the three designs of [`closed_form`] give the cross-section `A = c v_L Δu²/(r Δh)` and the
//!    controller settings (P, critically damped PI from [`crate::tune::averaging`], and the optimal
//!    averaging law of `plantwide_model::controllers::averaging_level` with its `max_rate` at `r`);
//! 3. each design is written into the plant (the vessel's `area` or `diameter`, the level
//!    controller replaced under its own name) and verified by a nonlinear dynamic run of the whole
//!    plant: the largest level deviation and the largest rate of the outflow after the step.
//!
//! The closed forms take the disturbance as a step of `Δu` reaching the vessel; upstream dynamics
//! that smooth it make the verified figures smaller than the design's (the design is then
//! conservative), interaction through recycles can make them larger: the verification says which.
//!
//! Vessels: a `tank`, `cstr` or `flash` (level in m, cross-section from `area` or `diameter`), a
//! column's reflux drum `COL.drum` or base `COL.sump` (holdup in mol: the column model has no
//! geometry, so the area is that of a vertical drum holding the band volume over the level band,
//! and the level controller's band is `A Δh/v_L` mol), or a stream `S` — a new surge tank put on it.

pub mod candidates;
pub mod closed_form;
mod request;
pub mod residence;
mod run;
mod steady;
mod verify;
mod vessel;

use plantwide_flowsheet::Plant;
use plantwide_solve::dynamic::SessionError;
use plantwide_solve::{NewtonSettings, SteadyError, steady_state};
use serde::Serialize;

pub use candidates::{CandidateRanking, RankedCandidate, rank_candidates, rank_candidates_observed};
pub use closed_form::LevelDesign;
pub use request::{SizeRequest, Sizing, size};
use vessel::Vessel;

/// Relative tolerance of the verification: sampling, the integrator's tolerance and the optimal
/// law's rate-estimate filter (`t*/10⁴`) leave the verified peaks within it of the closed form.
pub const VERIFY_TOLERANCE: f64 = 1e-3;

/// A disturbance: input `path` moved by `change` (SI) from the start of the run, in `shape`.
#[derive(Debug, Clone, PartialEq)]
pub struct Disturbance {
    /// Input path (or alias).
    pub path: String,
    /// The step, the ramp's total change or the sinusoid's amplitude (SI, signed).
    pub change: f64,
    /// Its time course.
    pub shape: Shape,
}

impl Disturbance {
    /// The disturbance of a scenario: its one step, ramp or sinusoid of an input (the end of a ramp
    /// or a sinusoid implied; the event's time and the scenario's length are not used — the
    /// verification starts the disturbance from the steady state).
    ///
    /// # Errors
    /// [`SizeError::Disturbance`] for a scenario with no such event, with more than one, or with a
    /// pulse.
    pub fn from_scenario(
        scenario: &plantwide_flowsheet::scenario::Scenario,
        plant: &Plant,
    ) -> Result<Disturbance, SizeError> {
        use plantwide_flowsheet::scenario::Action;
        let refuse = |why: String| SizeError::Disturbance { path: format!("(scenario `{}`)", scenario.name), why };
        let mut found = Vec::new();
        for e in &scenario.events {
            let (input, change, shape) = match e.action {
                Action::Step { input, change } => (input, change, Shape::Step),
                Action::Ramp { input, change, end } => (input, change, Shape::Ramp { duration: end - e.t }),
                Action::Sinusoid { input, amplitude, period } => {
                    (input, plantwide_flowsheet::scenario::Change::By(amplitude), Shape::Sine { period })
                }
                Action::Pulse { .. } => {
                    return Err(refuse(format!("{}: a pulse; sizing takes a step, a ramp or a sinusoid", e.origin)));
                }
                _ => continue,
            };
            let info = &plant.inputs()[input];
            found.push(Disturbance { path: info.path.clone(), change: change.apply(info.value) - info.value, shape });
        }
        match found.len() {
            1 => Ok(found.remove(0)),
            0 => Err(refuse("the scenario has no step, ramp or sinusoid of an input".into())),
            n => Err(refuse(format!("the scenario has {n} disturbance events; sizing takes one"))),
        }
    }
}

/// The time course of a disturbance. The designs are the closed forms of a step of the same size
/// (a ramp is gentler: the step's design holds it with margin; a sinusoid near the loop's natural
/// frequency can swing a PI-held level up to `e/2` times a step's peak, which the verification shows
/// and the refinement corrects); every design is verified under the shape given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// A step at `t = 0`.
    Step,
    /// A ramp from `t = 0` over `duration` \[s\].
    Ramp {
        /// \[s\]
        duration: f64,
    },
    /// `change · sin(2π t/period)` from `t = 0`, for 10 periods or the design's settling time.
    Sine {
        /// \[s\]
        period: f64,
    },
}

impl Shape {
    /// The waveform of input value `u0` moved by `change`.
    fn wave(self, u0: f64, change: f64) -> plantwide_solve::dynamic::Waveform {
        use plantwide_solve::dynamic::Waveform;
        match self {
            Shape::Step => Waveform::Constant(u0 + change),
            Shape::Ramp { duration } => Waveform::Ramp { t0: 0.0, v0: u0, t1: duration, v1: u0 + change },
            Shape::Sine { period } => Waveform::Sine { t0: 0.0, base: u0, amplitude: change, period },
        }
    }

    /// `step`, `ramp over 600 s`, `sinusoid of period 3600 s`.
    fn describe(self) -> String {
        match self {
            Shape::Step => "step".into(),
            Shape::Ramp { duration } => format!("ramp over {duration} s"),
            Shape::Sine { period } => format!("sinusoid of period {period} s"),
        }
    }
}

/// What to size for.
#[derive(Debug, Clone, PartialEq)]
pub struct SizeCriteria {
    /// The disturbance.
    pub disturbance: Disturbance,
    /// The largest allowed level deviation from the setpoint, either way \[m\].
    pub level_band: f64,
    /// The largest allowed rate of change of the outflow (its SI unit per second).
    pub max_outflow_rate: f64,
    /// The alternative criterion: instead of the rate limit, the outflow of a sinusoidal
    /// disturbance (the disturbance's `change` its amplitude) swings at most `ratio` times the
    /// inflow at `period`, in the periodic steady state (P and PI by their attenuation closed forms;
    /// the optimal law by its rate closed form for the steepest slope such a swing has, `ratio·Δu·ω`).
    pub attenuation: Option<Attenuation>,
    /// Length of each verification run \[s\] (default: 12 filter times for P, 14 times `1/ω_n`
    /// for PI, 25 ramp times for the optimal law, and at least 5 of the plant's slowest time
    /// constants). A run of a step or a ramp not settled by then is marked failed: its peaks are
    /// not known (a sinusoid's runs for exactly this long).
    pub duration: Option<f64>,
}

/// An attenuation criterion: outflow amplitude over inflow amplitude at a period.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Attenuation {
    /// The largest allowed ratio, in (0, 1).
    pub ratio: f64,
    /// The period \[s\].
    pub period: f64,
}

/// The peaks of one verification run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verified {
    /// Largest `|level − setpoint|` \[m\] (none when the run failed: its peaks up to the failure
    /// are no answer).
    pub max_level_deviation: Option<f64>,
    /// Largest `|d outflow/dt|` (SI; none when the run failed).
    pub max_outflow_rate: Option<f64>,
    /// Both within [`VERIFY_TOLERANCE`] of the band and the rate limit, by [`verdict`].
    pub meets: bool,
    /// Length of the run \[s\].
    pub duration: f64,
    /// Why the design has no answer: its steady state not found, its run stopped, or its run not
    /// settled (the figures are then none and the design is listed under the sizing's `failed`).
    pub failure: Option<String>,
    /// A sinusoid: the level's and the outflow's half peak-to-peak swing over its last two periods,
    /// the outflow's over the inflow amplitude `|Δu|` (the periodic steady state).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub level_amplitude: Option<f64>,
    /// See `level_amplitude`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub attenuation: Option<f64>,
    /// The run's record (for plots; not serialized).
    #[serde(skip)]
    pub trace: Trace,
}

impl Verified {
    /// A design without an answer: `why` it has none.
    pub(crate) fn failed(why: String, duration: f64) -> Verified {
        Verified {
            max_level_deviation: None,
            max_outflow_rate: None,
            meets: false,
            duration,
            failure: Some(why),
            level_amplitude: None,
            attenuation: None,
            trace: Trace::default(),
        }
    }
}

/// The one verdict of sizing on a run's figures, each `(value, limit)` and `None` for a figure the
/// vessel cannot show (a column's drum or base has no geometry, so the file's holdup has no level
/// in m): `Some(false)` when the run failed or any figure exceeds its limit by more than
/// [`VERIFY_TOLERANCE`], `Some(true)` when every figure is shown and within, `None` when those
/// shown are within but one could not be judged. The designs' `meets`, the file's vessel's `meets`
/// and a candidate's `needs_surge` all come from here.
pub fn verdict(failed: bool, figures: &[(Option<f64>, f64)]) -> Option<bool> {
    if failed {
        return Some(false);
    }
    let mut judged = true;
    for &(value, limit) in figures {
        match value {
            Some(v) if v.is_nan() || v > limit * (1.0 + VERIFY_TOLERANCE) => return Some(false),
            Some(_) => {}
            None => judged = false,
        }
    }
    judged.then_some(true)
}

/// A verification run's record.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Trace {
    /// Times from the step \[s\].
    pub times: Vec<f64>,
    /// Level deviation \[m\] (a design on a column's holdup: of its equivalent vertical drum; the
    /// file's column holdup, which has no level: mol).
    pub deviation: Vec<f64>,
    /// Outflow (SI).
    pub outflow: Vec<f64>,
}

/// One design and its verification. Gains are in the level measurement's SI units (outflow per m,
/// or per mol for a column's holdup), times in s.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Design {
    /// `p`, `pi` or `optimal`.
    pub controller: LevelDesign,
    /// Cross-section \[m²\].
    pub area: f64,
    /// The closed form's cross-section \[m²\] (equal to `area` unless the run asked for more).
    pub closed_form_area: f64,
    /// How many times the design was corrected after its run exceeded a limit.
    pub refinements: usize,
    /// The flow change the controller is designed for (SI; the steady one unless refined).
    pub design_flow_change: f64,
    /// Optimal law refined: the band it was told to plan for \[m\] (inside the band asked).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub planned_band: Option<f64>,
    /// `area × level band` \[m³\]: the volume the level sweeps between setpoint and band edge.
    pub band_volume: f64,
    /// Controller gain magnitude (P and PI).
    pub kc: Option<f64>,
    /// Reset time \[s\] (PI).
    pub tau_i: Option<f64>,
    /// Optimal law: capacity (outflow × s per unit of measurement).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capacity: Option<f64>,
    /// Optimal law: the ramp's duration `Δu/r` \[s\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ramp_time: Option<f64>,
    /// Optimal law: the return time written (4 ramp times) \[s\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub return_time: Option<f64>,
    /// Column drum or base: the normal holdup run (mol), at least twice the band's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub normal_holdup: Option<f64>,
    /// A reactor: the level setpoint \[m\] that keeps its liquid volume at the file's (its
    /// conversion depends on it), `setpoint × file's area / area`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub normal_level: Option<f64>,
    /// The design's time \[s\]: P's filter time, PI's `1/ω_n`, the optimal law's ramp time (the
    /// run's sampling and its minimum length are in units of it).
    pub design_time: f64,
    /// The nonlinear run.
    pub verified: Verified,
}

/// The sizing of one vessel; serializes to the issue's `{"designs": [...]}` with the context.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VesselSizing {
    /// The vessel as asked.
    pub vessel: String,
    /// `vessel`, `column_drum`, `column_sump` or `new_surge_tank`.
    pub kind: &'static str,
    /// Its level controller.
    pub level_controller: String,
    /// The flow it moves (input path).
    pub outflow: String,
    /// `path +Δ` of the disturbance (SI).
    pub disturbance: String,
    /// The disturbed input's path and its change (SI, signed).
    pub disturbance_path: String,
    /// See `disturbance_path`.
    pub disturbance_change: f64,
    /// The disturbance's time course (for display).
    #[serde(skip)]
    pub shape: Shape,
    /// The steady change of the outflow the disturbance needs (SI).
    pub flow_change: f64,
    /// Molar volume of the vessel's liquid \[m³/mol\].
    pub liquid_molar_volume: f64,
    /// Level band asked \[m\].
    pub level_band: f64,
    /// Rate limit asked (SI; under an attenuation criterion the steepest slope of the allowed
    /// outflow swing, `ratio·|Δu|·ω`).
    pub max_outflow_rate: f64,
    /// The attenuation criterion, if asked.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub attenuation: Option<Attenuation>,
    /// The vessel as the file has it, run through the same disturbance (a new tank: the stream
    /// without it).
    pub current: Current,
    /// The three designs.
    pub designs: Vec<Design>,
    /// The parts that have no answer, each with its reason (a design's steady state or run, the
    /// file's vessel's run), also marked where they stand; empty when all went through.
    pub failed: Vec<String>,
}

/// The file's own vessel and controller through the disturbance.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Current {
    /// Its cross-section \[m²\] (none for a column's holdup or a stream).
    pub area: Option<f64>,
    /// Largest deviation of the level \[m\]: a vessel with a level only (none for a column's drum
    /// or base, whose holdup has no level in the model, for a stream, or when the run failed).
    pub max_deviation: Option<f64>,
    /// A column's drum or base: largest deviation of its holdup \[mol\] (the column model has no
    /// drum geometry, so no level band can be judged on it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_holdup_deviation: Option<f64>,
    /// Largest rate of the outflow (SI; none when the run failed).
    pub max_outflow_rate: Option<f64>,
    /// Within the band (where the vessel has a level) and the rate limit, by [`verdict`]: none when
    /// the rate holds but the band cannot be judged (a column's holdup).
    pub meets: Option<bool>,
    /// Length of the run \[s\].
    pub duration: f64,
    /// Why the run stopped or did not settle, if it did (the figures are then none).
    pub failure: Option<String>,
    /// A sinusoid: the outflow's swing over the inflow's in the last two periods.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub attenuation: Option<f64>,
    /// Where the level left the vessel in the run (`above its top at 4 m`, `below its bottom`):
    /// the model holds no overflow or dry running, so the vessel as the file has it cannot take
    /// the disturbance at all.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub outside: Option<String>,
    /// The run's record (for plots; not serialized).
    #[serde(skip)]
    pub trace: Trace,
}

/// What a sizing reports as it goes (for a progress bar): a part of vessel `vessel` done.
#[derive(Debug, Clone, Copy)]
pub struct Progress<'a> {
    /// The vessel as asked.
    pub vessel: &'a str,
    /// `p design`, `pi design`, `optimal design` or `file's vessel`.
    pub part: &'a str,
    /// The part failed.
    pub failed: bool,
}

/// The parts of one vessel's sizing that report [`Progress`]: three designs and the file's vessel.
pub const PARTS_PER_VESSEL: usize = 4;

/// Where the continuation from the file's vessel to a design's stopped.
#[derive(Debug, Clone, thiserror::Error)]
#[error(
    "no steady state beyond {reached} on the way from the file's {from} to the design's {to} (at {next}: \
     {reason}){limits}{why}"
)]
pub struct Stall {
    /// The file's size (`area 4 m²`, `normal holdup 40000 mol`).
    pub from: String,
    /// The design's.
    pub to: String,
    /// The last size with a steady state.
    pub reached: String,
    /// The size tried next.
    pub next: String,
    /// The solver's reason there, in short (status, residual, worst equation).
    pub reason: String,
    /// The loops near a limit at the last steady state (`; at area 2.9 m²: `c` within 0.4 % of
    /// op_max (…)`), or empty.
    pub limits: String,
    /// What it means for this vessel (`; a reactor's cross-section also sets its volume …`), or
    /// empty.
    pub why: String,
}

/// Why a sizing was refused or failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum SizeError {
    /// More candidates than a ranking takes.
    #[error("candidates: {n} vessels, above the {max} a ranking sizes (each by three verified designs): rank fewer")]
    Candidates {
        /// As given.
        n: usize,
        /// The limit.
        max: usize,
    },
    /// A list of the request names one item twice.
    #[error(transparent)]
    Duplicate(#[from] crate::request::Duplicate),
    /// A field of the request that does not parse, is missing, or does not go with another.
    #[error("{field} {why}")]
    Field {
        /// The [`SizeRequest`] field.
        field: &'static str,
        /// What is wrong, after the field's name (`must be a positive time`, `0.3 kg: …`).
        why: String,
    },
    /// No vessel of that name.
    #[error("`{name}` is no vessel of the flowsheet: {why}; vessels with a level: {known}")]
    Vessel {
        /// As asked.
        name: String,
        /// Why.
        why: String,
        /// What could be sized.
        known: String,
    },
    /// The vessel's level is not held by a PID on a flow.
    #[error("vessel `{vessel}`: {why}")]
    LevelLoop {
        /// The vessel.
        vessel: String,
        /// Why.
        why: String,
    },
    /// The band does not fit the vessel or is not positive.
    #[error("level_band {} m for `{vessel}`: {why}", plantwide_model::limits::number(*.band))]
    Band {
        /// The vessel.
        vessel: String,
        /// The band \[m\].
        band: f64,
        /// Why.
        why: String,
    },
    /// The rate limit is not positive.
    #[error(
        "max_outflow_rate {} (SI): must be a positive rate of change of the outflow (e.g. \"5 kmol/h/min\")",
        plantwide_model::limits::number(*.value)
    )]
    Rate {
        /// As given (SI).
        value: f64,
    },
    /// The attenuation criterion is not a ratio in (0, 1) at a positive period.
    #[error("attenuation: {why}")]
    Attenuation {
        /// Why.
        why: String,
    },
    /// The disturbance is no free input or is zero.
    #[error("disturbance {path}: {why}")]
    Disturbance {
        /// Its path.
        path: String,
        /// Why.
        why: String,
    },
    /// The disturbance does not move the vessel's outflow.
    #[error(
        "the disturbance {path} does not move the outflow `{outflow}` of `{vessel}` at steady state (change {change:.3e}): \
         there is no surge to size there"
    )]
    Unreached {
        /// The vessel.
        vessel: String,
        /// Its outflow.
        outflow: String,
        /// The disturbance.
        path: String,
        /// The change found (SI).
        change: f64,
    },
    /// A design could not be written into the plant.
    #[error("writing the {what} into the flowsheet: {source}")]
    Structure {
        /// What.
        what: String,
        /// The flowsheet's reason.
        source: plantwide_flowsheet::OverrideError,
    },
    /// No steady state.
    #[error("{what}: {source}")]
    Steady {
        /// Which plant.
        what: String,
        /// The solver's reason.
        source: Box<SteadyError>,
    },
    /// No steady state on the way from the file's vessel to a design's.
    #[error("{what}: {stall}")]
    Continuation {
        /// Which plant.
        what: String,
        /// Where the way stopped and why.
        stall: Box<Stall>,
        /// The solver's reason in full.
        source: Box<SteadyError>,
    },
    /// A verification run stopped.
    #[error("{what}: {source}")]
    Simulation {
        /// Which run.
        what: String,
        /// The integrator's reason.
        source: Box<SessionError>,
    },
}

impl SizeError {
    /// The [`SizeRequest`] field a refusal is about, which its message starts with (a face that
    /// calls the field otherwise, the CLI's `--level-band`, puts its own name there).
    pub fn field(&self) -> Option<&'static str> {
        match self {
            SizeError::Field { field, .. } => Some(field),
            SizeError::Candidates { .. } | SizeError::Duplicate(_) => Some("candidates"),
            SizeError::Band { .. } => Some("level_band"),
            SizeError::Rate { .. } => Some("max_outflow_rate"),
            SizeError::Attenuation { .. } => Some("attenuation"),
            SizeError::Disturbance { .. } => Some("disturbance"),
            _ => None,
        }
    }

    /// True for problems of the request (exit code 1), false for numerical failures (exit code 2).
    pub fn is_user_error(&self) -> bool {
        !matches!(self, SizeError::Steady { .. } | SizeError::Simulation { .. } | SizeError::Continuation { .. })
    }
}

/// Size vessel `name` of `plant` (at its steady state `x`) for `r`.
///
/// # Errors
/// [`SizeError`]: a bad request (vessel, band, rate, disturbance), a disturbance that does not
/// reach the vessel, or a plant that cannot be solved before or after the disturbance. A design
/// or a run that has no answer is not an error: it is marked where it stands and listed under
/// [`VesselSizing::failed`].
pub fn size_vessel(plant: &Plant, x: &[f64], name: &str, r: &SizeCriteria) -> Result<VesselSizing, SizeError> {
    size_vessel_observed(plant, x, name, r, &|_| {})
}

/// [`size_vessel`], telling `progress` as each design and the file's vessel are done.
///
/// # Errors
/// See [`size_vessel`].
pub fn size_vessel_observed(
    plant: &Plant,
    x: &[f64],
    name: &str,
    r: &SizeCriteria,
    progress: &(dyn Fn(Progress<'_>) + Sync),
) -> Result<VesselSizing, SizeError> {
    check_request(plant, r)?;
    let v = Vessel::resolve(plant, x, name, r)?;
    let flow_change = v.flow_change(r)?;
    let effective = r.attenuation.map(|a| {
        let omega = std::f64::consts::TAU / a.period;
        SizeCriteria {
            disturbance: Disturbance { shape: Shape::Sine { period: a.period }, ..r.disturbance.clone() },
            max_outflow_rate: a.ratio * flow_change.abs() * omega,
            ..r.clone()
        }
    });
    let r = effective.as_ref().unwrap_or(r);
    let mut designs = Vec::with_capacity(LevelDesign::ALL.len());
    for d in LevelDesign::ALL {
        let design = verify::design(&v, d, flow_change, r)?;
        let part = format!("{} design", d.name());
        progress(Progress { vessel: name, part: &part, failed: design.verified.failure.is_some() });
        designs.push(design);
    }
    let current = verify::current(&v, r, &designs, flow_change)?;
    progress(Progress { vessel: name, part: "file's vessel", failed: current.failure.is_some() });
    let mut failed: Vec<String> = designs
        .iter()
        .filter_map(|d| {
            d.verified.failure.as_ref().map(|why| format!("the {} design of `{name}`: {why}", d.controller.name()))
        })
        .collect();
    if let Some(why) = &current.failure {
        failed.push(format!("`{name}` as the file has it: {why}"));
    }
    let dim = plant.input(&r.disturbance.path).map_or("(SI)".to_string(), |i| plant.inputs()[i].dim.to_string());
    Ok(VesselSizing {
        vessel: name.to_string(),
        kind: v.kind_name(),
        level_controller: v.controller.clone(),
        outflow: v.outflow.clone(),
        disturbance: format!(
            "{} {:+.6e} {dim}, {}",
            r.disturbance.path,
            r.disturbance.change,
            r.disturbance.shape.describe()
        ),
        disturbance_path: r.disturbance.path.clone(),
        disturbance_change: r.disturbance.change,
        shape: r.disturbance.shape,
        flow_change,
        liquid_molar_volume: v.v_l,
        level_band: r.level_band,
        max_outflow_rate: r.max_outflow_rate,
        attenuation: r.attenuation,
        current,
        designs,
        failed,
    })
}

/// The checks that need no vessel: band, rate, disturbance.
fn check_request(plant: &Plant, r: &SizeCriteria) -> Result<(), SizeError> {
    match r.attenuation {
        Some(a) if a.ratio.is_nan() || a.ratio <= 0.0 || a.ratio >= 1.0 => {
            return Err(SizeError::Attenuation { why: format!("the ratio {} must lie between 0 and 1", a.ratio) });
        }
        Some(a) if a.period.is_nan() || a.period <= 0.0 || a.period.is_infinite() => {
            return Err(SizeError::Attenuation { why: format!("the period {} s must be a positive time", a.period) });
        }
        Some(_) => {}
        None if r.max_outflow_rate.is_nan() || r.max_outflow_rate <= 0.0 || r.max_outflow_rate.is_infinite() => {
            return Err(SizeError::Rate { value: r.max_outflow_rate });
        }
        None => {}
    }
    if r.level_band.is_nan() || r.level_band <= 0.0 || r.level_band.is_infinite() {
        return Err(SizeError::Band {
            vessel: String::new(),
            band: r.level_band,
            why: "must be a positive length (the largest deviation either way, e.g. \"0.3 m\")".into(),
        });
    }
    let d = &r.disturbance;
    let bad = |why: &str| Err(SizeError::Disturbance { path: d.path.clone(), why: why.to_string() });
    match plantwide_flowsheet::overrides::resolve_input(plant, &d.path) {
        None => bad("no input of the flowsheet has this path (a feed's `F`, a unit's parameter, an alias)"),
        Some(i) if plant.inputs()[i].driven_by.is_some() => {
            bad("this input is moved by a controller; disturb a free input (a feed, a setpoint)")
        }
        Some(_) if d.change.is_nan() || d.change == 0.0 || d.change.is_infinite() => {
            bad("the step must be a nonzero finite change, e.g. +10% or \"+20 kmol/h\"")
        }
        Some(_) => match d.shape {
            Shape::Ramp { duration: t } | Shape::Sine { period: t } if t.is_nan() || t <= 0.0 || t.is_infinite() => {
                bad("the ramp's duration or the sinusoid's period must be a positive time")
            }
            _ => Ok(()),
        },
    }
}

/// The steady state of `v` from the guess `x` of `base` (variables matched by path).
fn steady_from(base: &Plant, x: &[f64], v: &Plant, what: &str) -> Result<Vec<f64>, SizeError> {
    newton(v, &crate::screen::column::mapped_guess(base, x, v))
        .map_err(|e| SizeError::Steady { what: what.to_string(), source: Box::new(e) })
}

/// The steady state of `v` from `guess`, the solver's reason when none is found.
fn newton(v: &Plant, guess: &[f64]) -> Result<Vec<f64>, SteadyError> {
    steady_state(v, &v.input_values(), Some(guess), &NewtonSettings::default()).map(|s| s.x)
}
