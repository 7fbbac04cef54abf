//! Conditional events (`when`): what a scenario does when a variable crosses a value — a trip, an
//! interlock, the end of the run — rather than at a time known in advance (Aspen Dynamics' task
//! `WAIT FOR`, Modelica's `when`, gPROMS' `WHILE`/`CONTINUE UNTIL` schedules).
//!
//! ```json
//! "when": [
//!   {"path": "reactor.T", "above": "150 degC",
//!    "then": [{"type": "feed_lost", "at": "0 s", "unit": "fresh_A"},
//!             {"type": "feed_restored", "at": "30 min", "unit": "fresh_A"}]},
//!   {"path": "drum.M", "below": "50 kmol", "stop": true}
//! ]
//! ```
//!
//! A condition acts once, the first time it holds: at the start of the run if it holds there,
//! else where the variable crosses its value. The driver locates the crossing within the step
//! that made it hold, on the integrator's interpolating polynomial, to 100 units of rounding of
//! the time (as SUNDIALS' root finding), and the `then` events are applied from that instant,
//! each `at` its delay after it. A crossing and a crossing back within one integration step are
//! not seen (the root finding of SUNDIALS has the same limit; a `max_step` narrows it). `stop`
//! ends the run at the crossing: what was recorded up to there is the result.

use plantwide_units::QuantityValue;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{Action, Cx, Event, EventSpec, Limits, events_of};
use crate::error::{Diagnostic, did_you_mean};
use crate::overrides::resolve_input;

/// A conditional event in a scenario file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WhenSpec {
    /// The variable watched: a plant variable (`drum.M`, `reactor.T`, `column.x[3][light]`), or an
    /// input a controller drives (the controller's output is watched).
    pub path: String,
    /// Acts when the variable is above this value (units of the variable).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub above: Option<QuantityValue>,
    /// Acts when the variable is below this value (units of the variable).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub below: Option<QuantityValue>,
    /// Events to apply, each `at` its delay after the crossing (`"0 s"`: at once).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub then: Vec<EventSpec>,
    /// End the run at the crossing (a trip: the run's result is what was recorded up to it).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub stop: bool,
}

/// A conditional event checked against a plant (SI).
#[derive(Debug, Clone, PartialEq)]
pub struct Condition {
    /// The watched variable.
    pub var: usize,
    /// The value it crosses (SI).
    pub threshold: f64,
    /// `above` (true) or `below`.
    pub rising: bool,
    /// The events it applies, their times the delays after the crossing [s].
    pub then: Vec<Event>,
    /// Whether it ends the run.
    pub stop: bool,
    /// Where it came from (`when[2]`), for messages.
    pub origin: String,
    /// What it watches, for messages and snapshots (`` `drum.M` below 50000 mol ``).
    pub text: String,
}

impl Condition {
    /// How far `value` is into the condition: positive where it holds.
    pub fn excess(&self, value: f64) -> f64 {
        if self.rising { value - self.threshold } else { self.threshold - value }
    }

    /// Names the condition in a snapshot: its place and what it watches (a snapshot resumed with
    /// another scenario keeps only the conditions it has).
    pub fn key(&self) -> String {
        format!("{}: {}", self.origin, self.text)
    }
}

/// The scenario's conditions, checked and in SI; `analyzers` are the scenario analyzers' blocks
/// (a `then` event may freeze only those).
pub(super) fn conditions_of(
    cx: &mut Cx<'_>,
    specs: &[WhenSpec],
    analyzers: &[usize],
    limits: &Limits,
) -> Vec<Condition> {
    // Counted before any is expanded: the conditions and their events together stay within the
    // limit on events.
    let n = specs.len().saturating_add(specs.iter().map(|w| w.then.len()).sum());
    if super::too_many_events(cx, "when", n, limits) {
        return Vec::new();
    }
    let mut out = Vec::new();
    for (k, w) in specs.iter().enumerate() {
        let base = format!("when[{k}]");
        let var = watched(cx, &base, &w.path);
        let (bound, rising) = match (&w.above, &w.below) {
            (Some(q), None) => (q, true),
            (None, Some(q)) => (q, false),
            _ => {
                cx.diags.push(Diagnostic::new(&base, "give exactly one of `above` and `below` (the value crossed)"));
                continue;
            }
        };
        if w.stop != w.then.is_empty() {
            cx.diags.push(Diagnostic::new(
                &base,
                "give `then` (the events it starts) or `\"stop\": true` (the run ends at the crossing), one of them",
            ));
        }
        let then = events_of(cx, &format!("{base}.then"), &w.then, f64::INFINITY, limits);
        for e in &then {
            if let Action::Analyzer { block, .. } = e.action
                && !analyzers.contains(&block)
            {
                let name = &cx.plant.blocks[block].name;
                let why = format!("controller `{name}` has no scenario analyzer: list it under `analyzers`");
                cx.diags.push(Diagnostic::new(e.origin.clone(), why));
            }
        }
        let Some(var) = var else { continue };
        let dim = cx.plant.vars[var].spec.dim;
        let field = format!("{base}.{}", if rising { "above" } else { "below" });
        let threshold = cx.quantity(&field, bound, dim);
        let path = &cx.plant.vars[var].path;
        let value = plantwide_model::limits::number(threshold);
        let text = format!("`{path}` {} {value} {dim}", if rising { "above" } else { "below" });
        out.push(Condition { var, threshold, rising, then, stop: w.stop, origin: base, text });
    }
    out
}

/// The variable `path` names: a plant variable, or the output of the controller driving an input.
fn watched(cx: &mut Cx<'_>, base: &str, path: &str) -> Option<usize> {
    if let Some(v) = cx.plant.var(path) {
        return Some(v);
    }
    let field = format!("{base}.path");
    match resolve_input(cx.plant, path) {
        Some(i) => match cx.plant.inputs[i].driven_by {
            Some(v) => Some(v),
            None => {
                cx.diags.push(Diagnostic::new(
                    field,
                    format!(
                        "`{path}` is an input no controller drives: only the scenario's own events move it, so when \
                         it crosses a value is known; give those events the time instead"
                    ),
                ));
                None
            }
        },
        None => {
            let names = cx.plant.vars.iter().map(|v| v.path.as_str());
            let clipped = plantwide_model::limits::clip(path);
            cx.diags.push(Diagnostic::new(field, format!("no variable `{clipped}`{}", did_you_mean(path, names))));
            None
        }
    }
}
