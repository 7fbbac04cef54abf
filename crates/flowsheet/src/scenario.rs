//! Dynamic scenario files (JSON): how long to run, what happens when (steps, ramps, pulses,
//! sinusoids on any input, setpoint changes through `<ctrl>.sp`, auto/manual switches, a valve
//! stuck, a feed lost), the discrete-time behaviour of controllers (DCS scan interval, analyzer
//! sample and dead time), what to record, and when to write snapshots.
//!
//! [`parse_scenario`] reads the file into a [`ScenarioSpec`] (every problem reported with its JSON
//! path); [`resolve`] checks it against a [`Plant`] (paths, dimensions) and converts every quantity
//! to SI, giving a [`Scenario`]. Times are from the start of the run, which is the converged
//! steady state unless a snapshot is resumed. Every value must be finite, every time `≥ 0`, every
//! duration, period and interval `> 0`, and what the file asks for (recorded rows and values,
//! events, controller scans and analyzer samples) must stay within [`Limits`], each of which an
//! environment variable raises (`PLANTWIDE_MAX_RECORD_ROWS`, `PLANTWIDE_MAX_RECORD_VALUES`,
//! `PLANTWIDE_MAX_EVENTS`, `PLANTWIDE_MAX_SAMPLES`).
//!
//! ```json
//! {"format_version": 1, "duration": "2000 min",
//!  "events": [{"type": "step", "at": "0 min", "path": "feed_source.F", "to": "1.01 kmol/min"}],
//!  "record": {"interval": "1 min", "paths": ["bottoms.x[light]", {"path": "distillate.F", "unit": "kmol/min"}]}}
//! ```

use std::collections::HashMap;

use indexmap::IndexMap;
use plantwide_model::Boundary;
use plantwide_model::controllers::Mode;
use plantwide_units::{Dimension, QuantityValue, convert_from_si, unit_dimension};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::error::{Diagnostic, LoadError, did_you_mean};
use crate::overrides::resolve_input;
use crate::path::VarPath;
use crate::plant::{BlockKind, Plant, Read};

pub use plantwide_model::limits::{Limits, LimitsError};

mod when;
pub use when::{Condition, WhenSpec};

/// The scenario format version this build reads.
pub const SCENARIO_FORMAT_VERSION: u32 = 1;

/// A scenario file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ScenarioSpec {
    /// Format version; must be 1.
    pub format_version: u32,
    /// Short name.
    #[serde(default)]
    pub name: String,
    /// What the scenario studies.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub description: String,
    /// Length of the run (e.g. `"2000 min"`).
    pub duration: QuantityValue,
    /// Integrator tolerances and step limits (defaults: rtol 1e-6, atol 1e-8 of each variable's
    /// nominal value, no step limit).
    #[serde(default)]
    pub integrator: IntegratorSpec,
    /// Events, in any order, each at `0 ≤ at ≤ duration`. Two events at the same time must act
    /// on different targets (inputs, or the modes of different controllers); they are then
    /// applied in file order, each seeing the inputs the earlier ones left. Two at the same time
    /// on one target are an error (which one wins would be an accident of order), and so is the
    /// end of a pulse or sinusoid at the time of an event on its input listed before it; an event
    /// listed after it may start where it ends (the end acts first). A ramp, pulse
    /// or sinusoid still running at the end of the run is cut by it.
    #[serde(default)]
    pub events: Vec<EventSpec>,
    /// Conditional events: what happens when a variable crosses a value (a trip, an interlock,
    /// the end of the run), each acting once ([`WhenSpec`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub when: Vec<WhenSpec>,
    /// DCS scan interval by controller name: the controller's output is held between scans.
    #[serde(default, skip_serializing_if = "IndexMap::is_empty")]
    pub sampling: IndexMap<String, QuantityValue>,
    /// Analyzers by controller name: the controller's measurement is sampled every `sample_time`
    /// and each result reaches the controller `dead_time` later, held until the next one.
    #[serde(default, skip_serializing_if = "IndexMap::is_empty")]
    pub analyzers: IndexMap<String, AnalyzerSpec>,
    /// What to record (default: every controller's measurement and output, every input an event moves).
    #[serde(default)]
    pub record: RecordSpec,
    /// Snapshot files to write during the run.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub snapshots: Vec<SnapshotSpec>,
}

/// Integrator settings of a scenario.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct IntegratorSpec {
    /// Relative tolerance (default 1e-6).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rtol: Option<f64>,
    /// Absolute tolerance as a fraction of each variable's nominal value (default 1e-8).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub atol: Option<f64>,
    /// Largest step (e.g. `"1 min"`; default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_step: Option<QuantityValue>,
    /// First step after each (re)start (default from the initial derivatives).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_step: Option<QuantityValue>,
}

/// One event (`"type"`): every event has `at`, its time from the start of the run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum EventSpec {
    /// The input jumps `to` a value or `by` a change.
    Step {
        /// Time.
        at: QuantityValue,
        /// Input path (`feed_source.F`, an alias, `stream.F` of a feed, `lc.sp`).
        path: String,
        /// New value.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        to: Option<QuantityValue>,
        /// Change.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        by: Option<QuantityValue>,
    },
    /// The input moves linearly `to` a value or `by` a change over `duration`, then stays.
    Ramp {
        /// Time.
        at: QuantityValue,
        /// Input path.
        path: String,
        /// Final value.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        to: Option<QuantityValue>,
        /// Change.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        by: Option<QuantityValue>,
        /// Ramp time.
        duration: QuantityValue,
    },
    /// The input jumps `to` a value or `by` a change for `width`, then returns.
    Pulse {
        /// Time.
        at: QuantityValue,
        /// Input path.
        path: String,
        /// Value during the pulse.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        to: Option<QuantityValue>,
        /// Change during the pulse.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        by: Option<QuantityValue>,
        /// Pulse width.
        width: QuantityValue,
    },
    /// The input oscillates `u0 + amplitude·sin(2π(t − at)/period)` around its value `u0` at
    /// `at`, for `duration` (default: to the end), then returns to `u0`.
    Sinusoid {
        /// Time.
        at: QuantityValue,
        /// Input path.
        path: String,
        /// Amplitude (units of the input).
        amplitude: QuantityValue,
        /// Period.
        period: QuantityValue,
        /// How long it lasts.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        duration: Option<QuantityValue>,
    },
    /// A PID controller goes to manual (output held at `output`, default its current output:
    /// bumpless) or back to auto (the integral has tracked the manual output with lag τ_I, so the
    /// return is bumpless once the error has been steady for a few τ_I).
    Mode {
        /// Time.
        at: QuantityValue,
        /// Controller name.
        controller: String,
        /// `auto` or `manual`.
        mode: Mode,
        /// Manual output (units of the driven input).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        output: Option<QuantityValue>,
    },
    /// The input (a valve opening, a flow a controller drives) freezes at its current value, or
    /// goes `to` one (a valve failed closed: `0`, open: `1`); a controller that drove it keeps
    /// acting on nothing (and winds up if it integrates) until a `valve_repaired` event.
    ValveStuck {
        /// Time.
        at: QuantityValue,
        /// Input path.
        path: String,
        /// The value it fails to (default: where it is).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        to: Option<QuantityValue>,
    },
    /// A stuck or failed input works again: a controller that drove it takes it back (from
    /// wherever its output has wound to), a free input returns to where the scenario has it:
    /// its value before the fault, moved by the events on it during the fault (which go on
    /// behind the fault and do not reach the plant).
    ValveRepaired {
        /// Time.
        at: QuantityValue,
        /// Input path (as its `valve_stuck` event named it).
        path: String,
    },
    /// A feed unit's flow `F` drops to zero, whether or not a controller drives it (a supply
    /// failure overrides the flow controller, which winds up against it) until `feed_restored`.
    FeedLost {
        /// Time.
        at: QuantityValue,
        /// Feed unit name.
        unit: String,
    },
    /// A lost feed comes back: to its controller, or to its flow before the loss.
    FeedRestored {
        /// Time.
        at: QuantityValue,
        /// Feed unit name.
        unit: String,
    },
    /// A scenario analyzer (`analyzers`) freezes: its controller keeps reading its last result
    /// (no new samples, results in flight lost) until `analyzer_repaired`.
    AnalyzerFrozen {
        /// Time.
        at: QuantityValue,
        /// Controller whose measurement is the analyzer's.
        controller: String,
    },
    /// A frozen analyzer samples again from its next sample time.
    AnalyzerRepaired {
        /// Time.
        at: QuantityValue,
        /// Controller whose measurement is the analyzer's.
        controller: String,
    },
}

/// An analyzer on a controller's measurement.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AnalyzerSpec {
    /// Time between samples (e.g. `"5 min"`).
    pub sample_time: QuantityValue,
    /// Delay from sampling to result (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dead_time: Option<QuantityValue>,
}

/// What to record.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RecordSpec {
    /// Interval between recorded points (default: duration/1000).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interval: Option<QuantityValue>,
    /// Unit of the time column (default `min`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_unit: Option<String>,
    /// Variable or input paths, each a string (SI units) or `{"path": …, "unit": …, "panel": …}`.
    #[serde(default)]
    pub paths: Vec<RecordPathSpec>,
    /// Streams whose cumulative component amounts `∫ F x_c dt` [mol] are integrated with the
    /// plant (recorded as `<stream>.total[<component>]`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub totals: Vec<String>,
}

/// A recorded path.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum RecordPathSpec {
    /// In SI units.
    Path(String),
    /// In a given unit, or on a named plot panel.
    WithUnit {
        /// Variable or input path.
        path: String,
        /// Unit (e.g. `"kmol/min"`; default SI, or the `--units` system's).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        unit: Option<String>,
        /// Plot panel (e.g. `"temperatures"`): the paths that name one panel are drawn together,
        /// in one unit (default: a panel of its own).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        panel: Option<String>,
    },
}

/// A snapshot to write.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SnapshotSpec {
    /// Time: the snapshot is taken at the end of the first integration step at or after it.
    pub at: QuantityValue,
    /// File to write (relative to the working directory).
    pub file: String,
}

/// A change of an input value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Change {
    /// To this value (SI).
    To(f64),
    /// By this amount (SI).
    By(f64),
}

impl Change {
    /// The new value from the current one.
    pub fn apply(self, current: f64) -> f64 {
        match self {
            Change::To(v) => v,
            Change::By(d) => current + d,
        }
    }
}

/// What an event does (indices are the plant's input, variable and block indices; values SI,
/// times in seconds).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Action {
    /// Jump.
    Step {
        /// The input.
        input: usize,
        /// Its new value.
        change: Change,
    },
    /// Start a ramp ending at `end` [s].
    Ramp {
        /// The input.
        input: usize,
        /// Its value at `end`.
        change: Change,
        /// End of the ramp [s].
        end: f64,
    },
    /// End of a ramp: hold its final value.
    Hold {
        /// The input.
        input: usize,
    },
    /// Start of a pulse: save the value, then jump.
    Pulse {
        /// The input.
        input: usize,
        /// Its value during the pulse.
        change: Change,
    },
    /// Start a sinusoid `u(t) = u0 + amplitude · sin(2π (t − t0) / period)`.
    Sinusoid {
        /// The input.
        input: usize,
        /// Amplitude [SI].
        amplitude: f64,
        /// Period [s].
        period: f64,
    },
    /// End of a pulse or sinusoid: back to the value before it.
    Restore {
        /// The input.
        input: usize,
    },
    /// Switch a PID: its `auto` and `op_manual` inputs, its output variable.
    Mode {
        /// The controller's `auto` input (1 automatic, 0 manual).
        auto_input: usize,
        /// Its `op_manual` input.
        manual_input: usize,
        /// Its output variable.
        op: usize,
        /// Automatic after the event.
        auto: bool,
        /// The manual output to hold, if given (else the output at the switch: bumpless).
        output: Option<f64>,
    },
    /// Freeze an input where it is, or at `value` (a fault: the input leaves its controller).
    Stuck {
        /// The input.
        input: usize,
        /// The value it fails to (SI), if not where it is.
        value: Option<f64>,
    },
    /// End the fault on an input: back to its controller, or to its value before the fault.
    Repair {
        /// The input.
        input: usize,
    },
    /// Freeze or repair the analyzer on a controller's measurement.
    Analyzer {
        /// The controller's block.
        block: usize,
        /// Frozen after the event.
        frozen: bool,
    },
}

impl Action {
    /// What the action changes: an input, or a controller's mode (by its `auto` input). Two
    /// events at one time on one target would let their order decide the result.
    pub fn target(&self) -> usize {
        target(self)
    }
}

/// An event at a time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Event {
    /// Time [s].
    pub t: f64,
    /// What happens.
    pub action: Action,
    /// Where it came from (`events[3]`), for messages.
    pub origin: String,
}

/// A recorded quantity.
#[derive(Debug, Clone, PartialEq)]
pub struct Recorded {
    /// Path as written.
    pub path: String,
    /// What it reads.
    pub source: Read,
    /// Unit of the output, and its SI dimension.
    pub unit: String,
    /// Dimension.
    pub dim: Dimension,
}

/// A scenario checked against a plant, in SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// Name.
    pub name: String,
    /// Duration [s].
    pub duration: f64,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance (fraction of nominal values).
    pub atol: f64,
    /// Largest step [s].
    pub max_step: f64,
    /// First step [s].
    pub first_step: Option<f64>,
    /// Events sorted by time (stable).
    pub events: Vec<Event>,
    /// Conditional events, in file order.
    pub conditions: Vec<Condition>,
    /// `(controller block, scan interval [s])`.
    pub sampling: Vec<(usize, f64)>,
    /// `(controller block, sample time [s], dead time [s])`.
    pub analyzers: Vec<(usize, f64, f64)>,
    /// Recording interval [s].
    pub interval: f64,
    /// Time unit of the output.
    pub time_unit: String,
    /// Recorded quantities.
    pub record: Vec<Recorded>,
    /// Streams (indices) whose component totals are integrated.
    pub totals: Vec<usize>,
    /// `(time [s], file)`.
    pub snapshots: Vec<(f64, String)>,
}

/// Parse scenario text; `file` names it in messages.
pub fn parse_scenario(text: &str, file: &str) -> Result<ScenarioSpec, LoadError> {
    let walk = crate::parse::walk_diagnostics(text);
    if !walk.is_empty() {
        return Err(LoadError::Invalid { file: file.into(), diagnostics: walk });
    }
    let mut de = serde_json::Deserializer::from_str(text);
    let spec: ScenarioSpec = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        if inner.is_syntax() || inner.is_eof() {
            return LoadError::Syntax {
                file: file.into(),
                line: inner.line(),
                column: inner.column(),
                reason: inner.to_string(),
            };
        }
        let path = if path == "." { String::new() } else { path };
        LoadError::Invalid {
            file: file.into(),
            diagnostics: vec![Diagnostic::new(path, strip_position(&inner.to_string()))],
        }
    })?;
    if spec.format_version != SCENARIO_FORMAT_VERSION {
        let msg =
            format!("this build reads format_version {SCENARIO_FORMAT_VERSION}, the file has {}", spec.format_version);
        return Err(LoadError::Invalid {
            file: file.into(),
            diagnostics: vec![Diagnostic::new("format_version", msg)],
        });
    }
    Ok(spec)
}

fn strip_position(msg: &str) -> String {
    msg.rfind(" at line ").map_or(msg, |i| &msg[..i]).to_string()
}

/// Collects diagnostics while converting quantities.
struct Cx<'a> {
    plant: &'a Plant,
    diags: Vec<Diagnostic>,
    ongoing: Ongoing,
}

/// Smallest relative tolerance of a run: about 4500 units of rounding, where the corrector's
/// convergence test still sees more than rounding noise.
pub const MIN_RTOL: f64 = 1e-12;
/// Smallest absolute tolerance of a run (SI): a variable near zero is not asked for less than the
/// rounding of the unit-sized quantities it is computed from.
pub const MIN_ATOL: f64 = 1e-16;

/// What a run has going when a scenario continues it (a live command is resolved as a one-event
/// scenario): the inputs in a fault, the frozen analyzers and the analyzers it samples, so that a
/// repair of a fault made earlier is accepted.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Ongoing {
    /// Inputs stuck or failed (their faults not yet repaired).
    pub faulted: Vec<usize>,
    /// Controller blocks whose analyzer is frozen.
    pub frozen: Vec<usize>,
    /// Controller blocks the run samples by an analyzer.
    pub analyzers: Vec<usize>,
}

impl Ongoing {
    /// The faults and frozen analyzers once `events` have acted (a live run's queued commands).
    pub fn follow(&mut self, events: &[Event]) {
        for e in events {
            match e.action {
                Action::Stuck { input, .. } => self.faulted.push(input),
                Action::Repair { input } => self.faulted.retain(|&i| i != input),
                Action::Analyzer { block, frozen: true } => self.frozen.push(block),
                Action::Analyzer { block, frozen: false } => self.frozen.retain(|&b| b != block),
                _ => {}
            }
        }
    }
}

impl Action {
    /// Whether this is a fault (a valve stuck or failed, a feed lost, an analyzer frozen).
    pub fn is_fault(&self) -> bool {
        matches!(self, Action::Stuck { .. } | Action::Analyzer { frozen: true, .. })
    }
    /// Whether this is the repair of a fault (`valve_repaired`, `feed_restored`,
    /// `analyzer_repaired`).
    pub fn is_repair(&self) -> bool {
        matches!(self, Action::Repair { .. } | Action::Analyzer { frozen: false, .. })
    }
}

impl Cx<'_> {
    fn quantity(&mut self, path: &str, q: &QuantityValue, dim: Dimension) -> f64 {
        let v = q.to_si(dim);
        self.finite(path, q, v)
    }
    /// A difference (`by`, `amplitude`: no offset of a temperature scale).
    fn difference(&mut self, path: &str, q: &QuantityValue, dim: Dimension) -> f64 {
        let v = q.to_si_difference(dim);
        self.finite(path, q, v)
    }
    fn finite<E: std::fmt::Display>(&mut self, path: &str, q: &QuantityValue, v: Result<f64, E>) -> f64 {
        match v {
            Ok(v) if v.is_finite() => v,
            Ok(_) => {
                self.diags.push(Diagnostic::new(path, format!("must be a finite number (got {q})")));
                f64::NAN
            }
            Err(e) => {
                self.diags.push(Diagnostic::new(path, e.to_string()));
                f64::NAN
            }
        }
    }
    fn time(&mut self, path: &str, q: &QuantityValue, positive: bool) -> f64 {
        let t = self.quantity(path, q, Dimension::TIME);
        if t.is_finite() && (t < 0.0 || (positive && t == 0.0)) {
            self.diags.push(Diagnostic::new(
                path,
                format!("must be {} (got {t} s)", if positive { "positive" } else { "≥ 0" }),
            ));
        }
        t
    }
    fn input(&mut self, path: &str, field: &str, free: bool) -> Option<usize> {
        let Some(i) = resolve_input(self.plant, path) else {
            let names =
                self.plant.inputs.iter().map(|i| i.path.as_str()).chain(self.plant.aliases.keys().map(String::as_str));
            self.diags.push(Diagnostic::new(
                field,
                format!("no input `{}`{}", plantwide_model::limits::clip(path), did_you_mean(path, names)),
            ));
            return None;
        };
        if free && let Some(v) = self.plant.inputs[i].driven_by {
            let ctrl = &self.plant.blocks[self.plant.vars[v].block].name;
            self.diags.push(Diagnostic::new(
                field,
                format!("input `{path}` is driven by controller `{ctrl}`: move its setpoint `{ctrl}.sp`, or switch it to manual with a `mode` event"),
            ));
            return None;
        }
        Some(i)
    }
    fn change(
        &mut self,
        base: &str,
        input: Option<usize>,
        to: &Option<QuantityValue>,
        by: &Option<QuantityValue>,
    ) -> Option<Change> {
        let dim = self.plant.inputs[input?].dim;
        match (to, by) {
            (Some(v), None) => Some(Change::To(self.quantity(&format!("{base}.to"), v, dim))),
            (None, Some(d)) => Some(Change::By(self.difference(&format!("{base}.by"), d, dim))),
            _ => {
                self.diags.push(Diagnostic::new(base, "give exactly one of `to` (new value) and `by` (change)"));
                None
            }
        }
    }
    /// A sampling period `period` [s] must give at most `limits.max_samples` samples over the run.
    fn samples(&mut self, field: &str, what: &str, period: f64, duration: f64, limits: &Limits) {
        let n = duration / period;
        if !n.is_nan() && n > limits.max_samples as f64 {
            self.diags.push(Diagnostic::new(
                field,
                format!(
                    "one every {} s over the run's duration of {} s is {n:.3e} {what}, more than the limit of {} ({} raises it): give a longer period",
                    secs(period),
                    secs(duration),
                    limits.max_samples,
                    Limits::MAX_SAMPLES
                ),
            ));
        }
    }
    fn controller(&mut self, name: &str, field: &str) -> Option<usize> {
        let found = self.plant.blocks.iter().position(|b| b.kind == BlockKind::Controller && b.name == name);
        if found.is_none() {
            let names = self.plant.blocks.iter().filter(|b| b.kind == BlockKind::Controller).map(|b| b.name.as_str());
            self.diags.push(Diagnostic::new(field, format!("no controller `{name}`{}", did_you_mean(name, names))));
        }
        found
    }
}

/// [`resolve_with`] under the default [`Limits`].
pub fn resolve(spec: &ScenarioSpec, plant: &Plant, file: &str) -> Result<Scenario, LoadError> {
    resolve_with(spec, plant, file, &Limits::default())
}

/// Check `spec` against `plant` and `limits` and convert it to SI; `file` names the scenario in
/// messages.
///
/// # Errors
/// [`LoadError::Invalid`] with every problem under its JSON path: unknown paths, wrong
/// dimensions, non-finite values, negative times, zero or negative durations and intervals,
/// events after the end of the run or colliding with another on the same target, and requests
/// beyond `limits`.
pub fn resolve_with(spec: &ScenarioSpec, plant: &Plant, file: &str, limits: &Limits) -> Result<Scenario, LoadError> {
    resolve_in(Cx { plant, diags: Vec::new(), ongoing: Ongoing::default() }, spec, file, limits)
}

/// [`resolve`] for events that continue a run with `ongoing` faults and analyzers (a live
/// command).
///
/// # Errors
/// As [`resolve_with`].
pub fn resolve_continuing(
    spec: &ScenarioSpec,
    plant: &Plant,
    file: &str,
    ongoing: Ongoing,
) -> Result<Scenario, LoadError> {
    resolve_in(Cx { plant, diags: Vec::new(), ongoing }, spec, file, &Limits::default())
}

fn resolve_in(mut cx: Cx<'_>, spec: &ScenarioSpec, file: &str, limits: &Limits) -> Result<Scenario, LoadError> {
    let plant = cx.plant;
    let duration = cx.time("duration", &spec.duration, true);
    let int = &spec.integrator;
    let rtol = int.rtol.unwrap_or(1e-6);
    let atol = int.atol.unwrap_or(1e-8);
    // The floors bound the work a file can ask for: below them the error test asks a variable
    // near zero for less than the rounding of the quantities it is computed from, and the steps
    // shrink without end (an atol of 1e-300 took a million steps for 2 s of a reactor).
    for (name, v, floor) in [("integrator.rtol", rtol, MIN_RTOL), ("integrator.atol", atol, MIN_ATOL)] {
        if !(v.is_finite() && v >= floor && v < 1.0) {
            cx.diags.push(Diagnostic::new(
                name,
                format!(
                    "must be a number from {} up to 1, the range in which the integrator's error test is more than \
                     rounding (got {})",
                    plantwide_model::limits::number(floor),
                    plantwide_model::limits::number(v)
                ),
            ));
        }
    }
    let max_step = int.max_step.as_ref().map_or(f64::INFINITY, |q| cx.time("integrator.max_step", q, true));
    let first_step = int.first_step.as_ref().map(|q| cx.time("integrator.first_step", q, true));
    let events = events_of(&mut cx, "events", &spec.events, duration, limits);
    let mut sampling = Vec::new();
    for (name, q) in &spec.sampling {
        let field = format!("sampling.{name}");
        let scan = cx.time(&field, q, true);
        cx.samples(&field, "scans", scan, duration, limits);
        if let Some(b) = cx.controller(name, &field) {
            sampling.push((b, scan));
        }
    }
    let mut analyzers = Vec::new();
    for (name, a) in &spec.analyzers {
        let field = format!("analyzers.{name}");
        let ts = cx.time(&format!("{field}.sample_time"), &a.sample_time, true);
        cx.samples(&format!("{field}.sample_time"), "samples", ts, duration, limits);
        let td = a.dead_time.as_ref().map_or(0.0, |q| cx.time(&format!("{field}.dead_time"), q, false));
        if let Some(b) = cx.controller(name, &field) {
            if plant.blocks[b].layout.n_signals == 0 {
                cx.diags.push(Diagnostic::new(field, format!("controller `{name}` reads no measurement")));
            } else {
                analyzers.push((b, ts, td));
            }
        }
    }
    check_faults(&mut cx, &events, &analyzers);
    let blocks: Vec<usize> = analyzers.iter().map(|&(b, ..)| b).chain(cx.ongoing.analyzers.iter().copied()).collect();
    let conditions = when::conditions_of(&mut cx, &spec.when, &blocks, limits);
    let rec = &spec.record;
    let interval = rec.interval.as_ref().map_or(duration / 1000.0, |q| cx.time("record.interval", q, true));
    let time_unit = rec.time_unit.clone().unwrap_or_else(|| "min".into());
    if unit_dimension(&time_unit).ok() != Some(Dimension::TIME) {
        cx.diags.push(Diagnostic::new(
            "record.time_unit",
            format!("`{time_unit}` is not a unit of time (e.g. \"s\", \"min\", \"h\")"),
        ));
    }
    let record = recorded(&mut cx, rec, &events, &conditions);
    let mut totals = Vec::new();
    for (k, name) in rec.totals.iter().enumerate() {
        match plant.streams.iter().position(|s| s.name == *name) {
            Some(s) => totals.push(s),
            None => cx.diags.push(Diagnostic::new(
                format!("record.totals[{k}]"),
                format!("no stream `{name}`{}", did_you_mean(name, plant.streams.iter().map(|s| s.name.as_str()))),
            )),
        }
    }
    let mut snapshots = Vec::new();
    for (k, s) in spec.snapshots.iter().enumerate() {
        if s.file.trim().is_empty() {
            cx.diags.push(Diagnostic::new(
                format!("snapshots[{k}].file"),
                "is empty: give the file to write the snapshot to (e.g. \"column_a_600s.snapshot.json\")",
            ));
        }
        snapshots.push((cx.time(&format!("snapshots[{k}].at"), &s.at, false), s.file.clone()));
    }
    let n_columns = record.len() + totals.len() * plant.components.len();
    let n_events = events.len() + conditions.iter().map(|c| c.then.len()).sum::<usize>();
    record_budget(&mut cx, (duration, interval), n_events, n_columns, limits);
    if !cx.diags.is_empty() {
        return Err(LoadError::Invalid { file: file.into(), diagnostics: cx.diags });
    }
    Ok(Scenario {
        name: spec.name.clone(),
        duration,
        rtol,
        atol,
        max_step,
        first_step,
        events,
        conditions,
        sampling,
        analyzers,
        interval,
        time_unit,
        record,
        totals,
        snapshots,
    })
}

/// The recorded quantities: `rec.paths`, or by default every controller's measurement and output,
/// every input an event moves and every variable a condition watches.
fn recorded(cx: &mut Cx<'_>, rec: &RecordSpec, events: &[Event], conditions: &[Condition]) -> Vec<Recorded> {
    let mut record = Vec::new();
    let paths: Vec<(String, Option<String>)> = if rec.paths.is_empty() {
        default_paths(cx.plant, events, conditions)
    } else {
        rec.paths
            .iter()
            .map(|p| match p {
                RecordPathSpec::Path(p) => (p.clone(), None),
                RecordPathSpec::WithUnit { path, unit, .. } => (path.clone(), unit.clone()),
            })
            .collect()
    };
    let mut seen: HashMap<(Read, String), usize> = HashMap::new();
    for (k, (path, unit)) in paths.iter().enumerate() {
        let field = format!("record.paths[{k}]");
        let (source, dim) = match (cx.plant.var(path), resolve_input(cx.plant, path)) {
            (Some(v), _) => (Read::Var(v), cx.plant.vars[v].spec.dim),
            (None, Some(i)) => (Read::Input(i), cx.plant.inputs[i].dim),
            (None, None) => {
                let names = cx
                    .plant
                    .vars
                    .iter()
                    .map(|v| v.path.as_str())
                    .chain(cx.plant.inputs.iter().map(|i| i.path.as_str()));
                cx.diags.push(Diagnostic::new(
                    field,
                    format!("no variable or input `{path}`{}", did_you_mean(path, names)),
                ));
                continue;
            }
        };
        let unit = match unit {
            Some(u) if unit_dimension(u).ok() == Some(dim) && convert_from_si(1.0, u).is_ok() => u.clone(),
            Some(u) => {
                cx.diags.push(Diagnostic::new(
                    format!("{field}.unit"),
                    format!("`{u}` is not a unit of {} (SI: {dim})", dim.describe()),
                ));
                continue;
            }
            None => cx.plant.tag_unit(path).map_or_else(|| dim.to_string(), str::to_string),
        };
        if let Some(first) = seen.get(&(source, unit.clone())) {
            cx.diags.push(Diagnostic::new(
                field,
                format!("`{path}` is recorded already (record.paths[{first}]) in the same unit: record it once"),
            ));
            continue;
        }
        seen.insert((source, unit.clone()), k);
        record.push(Recorded { path: path.clone(), source, unit, dim });
    }
    record
}

/// The recorded rows (`⌊duration / interval⌋ + 1` plus two per event) and values (rows ×
/// `n_columns`) must stay within `limits`; `times = (duration, interval)` [s].
fn record_budget(cx: &mut Cx<'_>, times: (f64, f64), n_events: usize, n_columns: usize, limits: &Limits) {
    let (duration, interval) = times;
    let rows = (duration / interval).floor() + 1.0 + 2.0 * n_events as f64;
    if rows.is_nan() {
        return; // duration or interval already reported
    }
    let raise = |var: &str| format!("{var} raises it");
    if rows > limits.max_record_rows as f64 {
        cx.diags.push(Diagnostic::new(
            "record.interval",
            format!(
                "one row every {} s over the run's duration of {} s is {rows:.3e} rows, more than the limit of {} ({}): give a longer interval",
                secs(interval),
                secs(duration),
                limits.max_record_rows,
                raise(Limits::MAX_RECORD_ROWS)
            ),
        ));
    } else if rows * n_columns as f64 > limits.max_record_values as f64 {
        cx.diags.push(Diagnostic::new(
            "record.paths",
            format!(
                "{rows} rows × {n_columns} columns is {:.3e} recorded values, more than the limit of {} ({}): record fewer paths or give a longer interval",
                rows * n_columns as f64,
                limits.max_record_values,
                raise(Limits::MAX_RECORD_VALUES)
            ),
        ));
    }
}

/// The scenario's events in SI, sorted by time (stably: file order at equal times). Reports an
/// event after the end of the run, more events than `limits.max_events`, and two events at the
/// same time on the same target (an input, or a controller's mode), whose order would decide the
/// result; events at the same time on different targets are applied in file order.
/// `list` names the list in messages (`events`, `when[0].then`).
fn events_of(cx: &mut Cx<'_>, list: &str, specs: &[EventSpec], duration: f64, limits: &Limits) -> Vec<Event> {
    // (event, label for messages)
    let mut events: Vec<(Event, String)> = Vec::new();
    // Counted before expansion too, so that a flood of events is not expanded and checked first.
    if too_many_events(cx, list, specs.len(), limits) {
        return Vec::new();
    }
    for (k, e) in specs.iter().enumerate() {
        let base = format!("{list}[{k}]");
        let expanded = event(cx, &base, e);
        if let Some(first) = expanded.first()
            && first.t > duration
        {
            cx.diags.push(Diagnostic::new(
                format!("{base}.at"),
                format!("{} s is after the end of the run (duration {} s)", secs(first.t), secs(duration)),
            ));
        }
        for (j, ev) in expanded.into_iter().enumerate() {
            let label = if j == 0 { base.clone() } else { format!("{base} (its end at {} s)", secs(ev.t)) };
            events.push((ev, label));
        }
    }
    if too_many_events(cx, list, events.len(), limits) {
        return Vec::new();
    }
    events.retain(|(e, _)| e.t.is_finite());
    events.sort_by(|a, b| a.0.t.total_cmp(&b.0.t));
    for (i, (a, la)) in events.iter().enumerate() {
        let origin = |l: &str| l.split(' ').next().unwrap_or_default().to_string();
        for (b, lb) in events[i + 1..].iter().take_while(|(b, _)| b.t == a.t) {
            // One event's start and end at one time: its duration is zero, reported already. An
            // event listed after a pulse or sinusoid may start where it ends: the end acts first
            // (the order of the file, and of a live run's journal, whose commands come after).
            let starts_at_an_earlier_end = la.contains(" (its end at ") && !lb.contains(" (its end at ");
            if target(&a.action) == target(&b.action) && origin(la) != origin(lb) && !starts_at_an_earlier_end {
                let what = target_name(cx.plant, &a.action);
                cx.diags.push(Diagnostic::new(
                    origin(lb),
                    format!(
                        "{la} and {lb} both act on {what} at {} s, so their order would decide the result: merge them into one event or move one (events at the same time on different targets are applied in file order)",
                        secs(a.t)
                    ),
                ));
            }
        }
    }
    check_values(cx, &events);
    events.into_iter().map(|(e, _)| e).collect()
}

/// Every value an event gives an input, followed from the flowsheet's values in time order, within
/// the input's physical range: the check file values and `--set` pass
/// ([`crate::overrides::check_input_value`]). A sinusoid is checked at its peaks.
fn check_values(cx: &mut Cx<'_>, events: &[(Event, String)]) {
    let mut u = cx.plant.input_values();
    let mut saved: Vec<Option<f64>> = vec![None; u.len()];
    for (k, (e, label)) in events.iter().enumerate() {
        let (input, values): (usize, Vec<f64>) = match e.action {
            Action::Step { input, change } | Action::Ramp { input, change, .. } => {
                (input, vec![change.apply(u[input])])
            }
            Action::Pulse { input, change } => {
                saved[input] = Some(u[input]);
                (input, vec![change.apply(u[input])])
            }
            Action::Restore { input } => (input, vec![saved[input].take().unwrap_or(u[input])]),
            Action::Sinusoid { input, amplitude, .. } => {
                saved[input] = Some(u[input]);
                (input, vec![u[input] - amplitude.abs(), u[input] + amplitude.abs()])
            }
            // `u` follows the values the scenario gives its inputs: a fault holds the input
            // apart from them (changes during it go on behind it, and the repair gives the input
            // back to them, or to its controller, whose output the check does not follow), so
            // the failed value is checked and `u` kept.
            Action::Stuck { input, value: Some(v) } => {
                if let Err(why) = crate::overrides::check_input_value(cx.plant, input, v) {
                    let path = &cx.plant.inputs[input].path;
                    let origin = label.split(' ').next().unwrap_or_default();
                    cx.diags.push(Diagnostic::new(origin, format!("takes `{path}` out of its range: {why}")));
                    return;
                }
                continue;
            }
            _ => continue,
        };
        for &v in &values {
            if let Err(why) = crate::overrides::check_input_value(cx.plant, input, v) {
                let path = &cx.plant.inputs[input].path;
                cx.diags.push(Diagnostic::new(
                    label.split(' ').next().unwrap_or_default(),
                    format!("takes `{path}` out of its range: {why}"),
                ));
                return;
            }
        }
        if !matches!(e.action, Action::Sinusoid { .. }) {
            u[input] = values[0];
            // A feed's fractions but its last (the balance) must not pass 1 together: another
            // event may have raised one of them earlier. Checked once all the events at one time
            // have acted (they may move fractions of one feed together).
            let last_at_time = events.get(k + 1).is_none_or(|(next, _)| next.t != e.t);
            if let (true, Err(why)) = (last_at_time, crate::overrides::check_compositions(cx.plant, &u)) {
                cx.diags.push(Diagnostic::new(label.split(' ').next().unwrap_or_default(), why.to_string()));
                return;
            }
        }
    }
}

/// Report `n` events in `list` above [`Limits::max_events`] (a ramp, a pulse or a timed sinusoid
/// counts two).
fn too_many_events(cx: &mut Cx<'_>, list: &str, n: usize, limits: &Limits) -> bool {
    let over = n > limits.max_events;
    if over {
        cx.diags.push(Diagnostic::new(
            list,
            format!(
                "{n} events (a ramp, a pulse or a sinusoid with a duration counts two) are more than the limit of {} ({} raises it)",
                limits.max_events,
                Limits::MAX_EVENTS
            ),
        ));
    }
    over
}

/// A time [s] for messages: plain in 1e-3 … 1e6, else in exponent form.
fn secs(t: f64) -> String {
    if t == 0.0 || (1e-3..1e6).contains(&t.abs()) { format!("{t}") } else { format!("{t:e}") }
}

/// What an action changes: an input, or a controller's mode (by its `auto` input).
fn target(a: &Action) -> usize {
    match *a {
        Action::Step { input, .. }
        | Action::Ramp { input, .. }
        | Action::Hold { input }
        | Action::Pulse { input, .. }
        | Action::Sinusoid { input, .. }
        | Action::Restore { input }
        | Action::Stuck { input, .. }
        | Action::Repair { input } => input,
        Action::Mode { auto_input, .. } => auto_input,
        // An analyzer's held measurement: one past the plant's inputs per controller block, so it
        // never equals an input.
        Action::Analyzer { block, .. } => usize::MAX - block,
    }
}

fn target_name(plant: &Plant, a: &Action) -> String {
    match *a {
        Action::Mode { auto_input, .. } => {
            format!("the mode of controller `{}`", plant.blocks[plant.inputs[auto_input].block].name)
        }
        Action::Analyzer { block, .. } => format!("the analyzer of controller `{}`", plant.blocks[block].name),
        _ => {
            let i = target(a);
            let mut aliases: Vec<&str> =
                plant.aliases.iter().filter(|&(_, &j)| j == i).map(|(name, _)| name.as_str()).collect();
            aliases.sort_unstable();
            match aliases.first() {
                Some(alias) => format!("`{alias}` (`{}`)", plant.inputs[i].path),
                None => format!("`{}`", plant.inputs[i].path),
            }
        }
    }
}

/// Every controller's measurement and output, every input an event moves (a conditional one too)
/// and every variable a condition watches.
fn default_paths(plant: &Plant, events: &[Event], conditions: &[Condition]) -> Vec<(String, Option<String>)> {
    let mut paths: Vec<String> = Vec::new();
    for b in plant.blocks.iter().filter(|b| b.kind == BlockKind::Controller) {
        paths.extend(b.unit.signals().into_iter().filter(|s| s.role == "pv").map(|s| s.path));
        paths.extend(
            plant.vars[b.own_offset..b.own_offset + b.layout.n_own()]
                .iter()
                .filter(|v| VarPath::parse(&v.path).is_controller_output())
                .map(|v| v.path.clone()),
        );
    }
    paths.extend(conditions.iter().map(|c| plant.vars[c.var].path.clone()));
    for e in events.iter().chain(conditions.iter().flat_map(|c| &c.then)) {
        if let Action::Step { input, .. }
        | Action::Ramp { input, .. }
        | Action::Pulse { input, .. }
        | Action::Sinusoid { input, .. }
        | Action::Stuck { input, .. } = e.action
        {
            paths.push(plant.inputs[input].path.clone());
        }
    }
    let mut seen = std::collections::HashSet::new();
    paths.retain(|p| seen.insert(p.clone()));
    paths.into_iter().map(|p| (p, None)).collect()
}

fn event(cx: &mut Cx<'_>, base: &str, e: &EventSpec) -> Vec<Event> {
    let at = |cx: &mut Cx<'_>, q: &QuantityValue| cx.time(&format!("{base}.at"), q, false);
    let ev = |t: f64, action: Action| Event { t, action, origin: base.to_string() };
    let path_field = format!("{base}.path");
    match e {
        EventSpec::Step { at: t, path, to, by } => {
            let t = at(cx, t);
            let input = cx.input(path, &path_field, true);
            let change = cx.change(base, input, to, by);
            input.zip(change).map(|(input, change)| vec![ev(t, Action::Step { input, change })]).unwrap_or_default()
        }
        EventSpec::Ramp { at: t, path, to, by, duration } => {
            let t = at(cx, t);
            let d = cx.time(&format!("{base}.duration"), duration, true);
            let input = cx.input(path, &path_field, true);
            let change = cx.change(base, input, to, by);
            input
                .zip(change)
                .map(|(input, change)| {
                    vec![ev(t, Action::Ramp { input, change, end: t + d }), ev(t + d, Action::Hold { input })]
                })
                .unwrap_or_default()
        }
        EventSpec::Pulse { at: t, path, to, by, width } => {
            let t = at(cx, t);
            let w = cx.time(&format!("{base}.width"), width, true);
            let input = cx.input(path, &path_field, true);
            let change = cx.change(base, input, to, by);
            input
                .zip(change)
                .map(|(input, change)| {
                    vec![ev(t, Action::Pulse { input, change }), ev(t + w, Action::Restore { input })]
                })
                .unwrap_or_default()
        }
        EventSpec::Sinusoid { at: t, path, amplitude, period, duration } => {
            let t = at(cx, t);
            let input = cx.input(path, &path_field, true);
            let period = cx.time(&format!("{base}.period"), period, true);
            let end = duration.as_ref().map(|d| t + cx.time(&format!("{base}.duration"), d, true));
            let Some(input) = input else { return Vec::new() };
            let amplitude = cx.difference(&format!("{base}.amplitude"), amplitude, cx.plant.inputs[input].dim);
            let mut v = vec![ev(t, Action::Sinusoid { input, amplitude, period })];
            v.extend(end.map(|end| ev(end, Action::Restore { input })));
            v
        }
        EventSpec::Mode { at: t, controller, mode, output } => {
            let t = at(cx, t);
            let field = format!("{base}.controller");
            let Some(b) = cx.controller(controller, &field) else { return Vec::new() };
            let (auto_input, manual_input) =
                (cx.plant.input(VarPath::auto(controller)), cx.plant.input(VarPath::manual_output(controller)));
            let (Some(auto_input), Some(manual_input), Some(op)) =
                (auto_input, manual_input, cx.plant.var(VarPath::controller_output(controller, 0)))
            else {
                let kind = cx.plant.blocks[b].unit.type_name();
                cx.diags.push(Diagnostic::new(
                    field,
                    format!("controller `{controller}` ({kind}) has no auto/manual switch; only `pid` controllers do"),
                ));
                return Vec::new();
            };
            let dim = cx.plant.inputs[manual_input].dim;
            let output = output.as_ref().map(|q| cx.quantity(&format!("{base}.output"), q, dim));
            vec![ev(t, Action::Mode { auto_input, manual_input, op, auto: *mode == Mode::Auto, output })]
        }
        EventSpec::ValveStuck { at: t, path, to } => {
            let t = at(cx, t);
            let Some(input) = cx.input(path, &path_field, false) else { return Vec::new() };
            let dim = cx.plant.inputs[input].dim;
            let value = to.as_ref().map(|q| cx.quantity(&format!("{base}.to"), q, dim));
            vec![ev(t, Action::Stuck { input, value })]
        }
        EventSpec::ValveRepaired { at: t, path } => {
            let t = at(cx, t);
            cx.input(path, &path_field, false).map(|input| vec![ev(t, Action::Repair { input })]).unwrap_or_default()
        }
        EventSpec::FeedLost { at: t, unit } => {
            let t = at(cx, t);
            let input = feed_flow(cx, base, unit);
            input.map(|input| vec![ev(t, Action::Stuck { input, value: Some(0.0) })]).unwrap_or_default()
        }
        EventSpec::FeedRestored { at: t, unit } => {
            let t = at(cx, t);
            feed_flow(cx, base, unit).map(|input| vec![ev(t, Action::Repair { input })]).unwrap_or_default()
        }
        EventSpec::AnalyzerFrozen { at: t, controller } | EventSpec::AnalyzerRepaired { at: t, controller } => {
            let t = at(cx, t);
            let frozen = matches!(e, EventSpec::AnalyzerFrozen { .. });
            let block = cx.controller(controller, &format!("{base}.controller"));
            block.map(|block| vec![ev(t, Action::Analyzer { block, frozen })]).unwrap_or_default()
        }
    }
}

/// The flow input `F` of feed unit `unit` (refused, naming `base.unit`, if there is none).
fn feed_flow(cx: &mut Cx<'_>, base: &str, unit: &str) -> Option<usize> {
    let input = cx.plant.input(VarPath::new(unit, "F"));
    if input.is_none() || !cx.plant.blocks.iter().any(|b| b.name == *unit && b.unit.boundary() == Boundary::Source) {
        cx.diags.push(Diagnostic::new(format!("{base}.unit"), format!("no feed unit `{unit}` with an input `F`")));
    }
    input
}

/// Faults in time order: an input fails once before it is repaired, a repair follows a fault, a
/// frozen analyzer is a scenario analyzer and is repaired after it froze.
fn check_faults(cx: &mut Cx<'_>, events: &[Event], analyzers: &[(usize, f64, f64)]) {
    let mut faulted: std::collections::HashSet<usize> = cx.ongoing.faulted.iter().copied().collect();
    let mut frozen: std::collections::HashSet<usize> = cx.ongoing.frozen.iter().copied().collect();
    let sampled: Vec<usize> = analyzers.iter().map(|&(b, ..)| b).chain(cx.ongoing.analyzers.iter().copied()).collect();
    for e in events {
        let what = target_name(cx.plant, &e.action);
        let why = match e.action {
            Action::Stuck { input, .. } if !faulted.insert(input) => {
                format!("{what} has failed already: repair it (valve_repaired, feed_restored) before it fails again")
            }
            Action::Repair { input } if !faulted.remove(&input) => {
                format!("{what} has no fault to repair at {} s (no valve_stuck or feed_lost before it)", secs(e.t))
            }

            Action::Analyzer { block, .. } if !sampled.contains(&block) => {
                format!("{what} is no scenario analyzer: list the controller under `analyzers` to sample it")
            }
            Action::Analyzer { block, frozen: true } if !frozen.insert(block) => format!("{what} is frozen already"),
            Action::Analyzer { block, frozen: false } if !frozen.remove(&block) => {
                format!("{what} is not frozen at {} s (no analyzer_frozen before it)", secs(e.t))
            }
            _ => continue,
        };
        cx.diags.push(Diagnostic::new(e.origin.clone(), why));
    }
}
