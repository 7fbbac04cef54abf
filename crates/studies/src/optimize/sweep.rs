//! The optimum re-found along a disturbance (`optimize --sweep PATH=LOW:HIGH:N`): N values from
//! LOW to HIGH, each optimum started from its neighbour's (walking out from the value nearest the
//! nominal one), and the runs of values with the same active set: the active-constraint regions
//! of Skogestad's step 2, between which the controlled variables must change.

use indexmap::IndexMap;
use plantwide_analysis::select::select_input;
use plantwide_flowsheet::Plant;
use plantwide_flowsheet::optimization::OptimizationSpec;
use plantwide_solve::{NewtonSettings, steady_state};
use plantwide_units::parse_quantity_as;
use serde::Serialize;

use super::request::{in_unit, unit_of};
use super::{OptimizeError, State, optimize};

/// The most values a sweep takes (each is a whole optimization).
pub const MAX_POINTS: usize = 200;

/// One value of the disturbance and its optimum.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepPoint {
    /// The disturbance's value (display unit).
    pub value: f64,
    /// The optimal objective (its display unit); None where no optimum was found.
    pub objective: Option<f64>,
    /// The active limits there.
    pub active: Vec<String>,
    /// The degrees of freedom at the optimum (SI).
    pub values: IndexMap<String, f64>,
    /// Why no optimum was found, if none was.
    pub failure: Option<String>,
}

/// A run of values with one active set.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Region {
    /// The active limits.
    pub active: Vec<String>,
    /// The first value of the run (display unit).
    pub from: f64,
    /// The last value of the run.
    pub to: f64,
}

/// The optimum along a disturbance.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sweep {
    /// The disturbance's path.
    pub disturbance: String,
    /// Its display unit.
    pub unit: String,
    /// The objective's display unit.
    pub objective_unit: String,
    /// One point per value, ascending.
    pub points: Vec<SweepPoint>,
    /// The active-constraint regions, ascending.
    pub regions: Vec<Region>,
}

impl Sweep {
    /// The values without an optimum, each with its reason.
    pub fn failed(&self) -> Vec<String> {
        let shown = |p: &SweepPoint| format!("{} = {} {}", self.disturbance, p.value, self.unit);
        self.points.iter().filter_map(|p| p.failure.as_ref().map(|f| format!("{}: {f}", shown(p)))).collect()
    }
}

fn field(message: String) -> OptimizeError {
    OptimizeError::Field { field: "sweep".into(), message }
}

/// Sweep the disturbance `text` (`PATH=LOW:HIGH:N`) from the steady state `start`.
///
/// # Errors
/// [`OptimizeError::Field`] naming `sweep` for a text that does not parse or a path that is no
/// free input; the nominal problem's own errors.
pub fn sweep(plant: &Plant, spec: &OptimizationSpec, start: &State, text: &str) -> Result<Sweep, OptimizeError> {
    let hint = || field(format!("`{text}`: expected PATH=LOW:HIGH:N, e.g. `feed.T=290 K:320 K:11`"));
    let (path, range) = text.split_once('=').ok_or_else(hint)?;
    let mut parts = range.rsplitn(3, ':');
    let (n, high, low) =
        (parts.next().ok_or_else(hint)?, parts.next().ok_or_else(hint)?, parts.next().ok_or_else(hint)?);
    let n: usize = n.trim().parse().map_err(|_| hint())?;
    if !(2..=MAX_POINTS).contains(&n) {
        return Err(field(format!("`{text}`: N must be from 2 to {MAX_POINTS}")));
    }
    let signal = select_input(plant, path.trim()).map_err(|e| field(e.to_string()))?;
    if spec.vary.keys().any(|k| plantwide_flowsheet::overrides::resolve_input(plant, k) == Some(signal.index)) {
        return Err(field(format!("`{}` is a degree of freedom (in `vary`), not a disturbance", signal.path)));
    }
    let dim = plant.inputs()[signal.index].dim;
    let end = |s: &str| parse_quantity_as(s.trim(), dim).map_err(|e| field(format!("`{text}`: {e}")));
    let (lo, hi) = (end(low)?, end(high)?);
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(field(format!("`{text}`: the range must go from low to high")));
    }
    let signal = in_unit(signal, unit_of(low).or_else(|| unit_of(high)));
    let values: Vec<f64> = (0..n).map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64).collect();
    let nominal = start.u[signal.index];
    let first =
        (0..n).min_by(|&a, &b| (values[a] - nominal).abs().total_cmp(&(values[b] - nominal).abs())).unwrap_or(0);
    let mut points: Vec<Option<SweepPoint>> = vec![None; n];
    let mut objective_unit = String::new();
    for walk in [(first..n).collect::<Vec<_>>(), (0..first).rev().collect()] {
        let mut from = start.clone();
        for k in walk {
            let (point, next) = one(plant, spec, &from, signal.index, values[k]);
            if let Some(next) = next {
                from = next;
            }
            if let Some(u) = &point.1 {
                objective_unit.clone_from(u);
            }
            points[k] = Some(SweepPoint { value: signal.display_value(values[k]), ..point.0 });
        }
    }
    let points: Vec<SweepPoint> = points.into_iter().flatten().collect();
    let regions = regions(&points);
    Ok(Sweep { disturbance: signal.path.clone(), unit: signal.unit.clone(), objective_unit, points, regions })
}

/// The optimum at the disturbance `value` (SI) from the state `from`: the point (its value set by
/// the caller), the objective's unit, and the optimum's state to start the next one from.
fn one(
    plant: &Plant,
    spec: &OptimizationSpec,
    from: &State,
    input: usize,
    value: f64,
) -> ((SweepPoint, Option<String>), Option<State>) {
    let failed = |f: String| {
        let p = SweepPoint { value, objective: None, active: Vec::new(), values: IndexMap::new(), failure: Some(f) };
        ((p, None), None)
    };
    let mut u = from.u.clone();
    u[input] = value;
    let settings = NewtonSettings::default();
    let moved = match steady_state(plant, &u, Some(&from.x), &settings) {
        Ok(s) => State { x: s.x, u: s.u },
        Err(e) => return failed(format!("no steady state at the inputs of the last optimum: {e}")),
    };
    let o = match optimize(plant, spec, &moved) {
        Ok(o) => o,
        Err(e) => return failed(e.to_string()),
    };
    let mut u = moved.u.clone();
    for (path, v) in o.values.iter().filter(|(p, _)| spec.vary.contains_key(*p)) {
        if let Some(i) = plantwide_flowsheet::overrides::resolve_input(plant, path) {
            u[i] = *v;
        }
    }
    let next = steady_state(plant, &u, Some(&moved.x), &settings).ok().map(|s| State { x: s.x, u: s.u });
    let mut active = o.active.clone();
    active.sort();
    let p = SweepPoint { value, objective: Some(o.objective), active, values: o.values.clone(), failure: None };
    ((p, Some(o.objective_unit.clone())), next)
}

/// The runs of consecutive optima with one active set.
fn regions(points: &[SweepPoint]) -> Vec<Region> {
    let mut out: Vec<Region> = Vec::new();
    for p in points.iter().filter(|p| p.failure.is_none()) {
        match out.last_mut() {
            Some(r) if r.active == p.active => r.to = p.value,
            _ => out.push(Region { active: p.active.clone(), from: p.value, to: p.value }),
        }
    }
    out
}
