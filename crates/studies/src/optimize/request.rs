//! The problem as the file's `"optimization"` section writes it ([`OptimizationSpec`]), resolved
//! against a plant: the objective, degrees of freedom and constraints as indices, their limits
//! in SI and the display units the answer is given in. Messages name the section's fields
//! (`optimization.vary.feed.F.max`).

use plantwide_analysis::select::{Signal, select_input, select_output, split_unit};
use plantwide_flowsheet::Plant;
use plantwide_flowsheet::optimization::{Limits, OptimizationSpec, Sense};
use plantwide_units::{Dimension, QuantityValue, Unit};

use super::OptimizeError;

/// A degree of freedom: a free input with its bounds (SI).
#[derive(Debug, Clone)]
pub struct Dof {
    /// The input (its display unit: that of its bounds, else SI).
    pub signal: Signal,
    /// Lower bound (SI; −∞ when none).
    pub lb: f64,
    /// Upper bound (SI; +∞ when none).
    pub ub: f64,
}

/// A constraint: a variable between limits (SI).
#[derive(Debug, Clone)]
pub struct Constraint {
    /// The variable (its display unit: that of its limits, else SI).
    pub signal: Signal,
    /// Lower limit (SI; −∞ when none).
    pub lo: f64,
    /// Upper limit (SI; +∞ when none).
    pub hi: f64,
}

/// The problem resolved against a plant.
#[derive(Debug, Clone)]
pub struct Problem {
    /// The objective's variable, in its display unit.
    pub objective: Signal,
    /// Minimize or maximize.
    pub sense: Sense,
    /// Degrees of freedom, in the order of their paths.
    pub dofs: Vec<Dof>,
    /// Constraints, in the order of their paths.
    pub constraints: Vec<Constraint>,
}

fn field(field: impl Into<String>, message: impl Into<String>) -> OptimizeError {
    OptimizeError::Field { field: field.into(), message: message.into() }
}

/// The unit written in a limit (`"35.5 %"` → `%`), if any.
fn written_unit(q: &QuantityValue) -> Option<String> {
    let QuantityValue::Text(t) = q else { return None };
    unit_of(t)
}

/// The unit after the number of a quantity's text (`"0.25 %"` → `%`), if any.
pub(super) fn unit_of(text: &str) -> Option<String> {
    let t = text.trim();
    let end = t.find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '+' | '-' | 'e' | 'E'))).unwrap_or(t.len());
    let unit = t[end..].trim();
    (!unit.is_empty()).then(|| unit.to_string())
}

/// The limits in SI for a quantity of dimension `dim`, and the unit they are written in.
fn limits(at: &str, l: &Limits, dim: Dimension) -> Result<(f64, f64, Option<String>), OptimizeError> {
    let side = |name: &str, q: &Option<QuantityValue>, none: f64| -> Result<f64, OptimizeError> {
        let Some(q) = q else { return Ok(none) };
        let v = q.to_si(dim).map_err(|e| field(format!("{at}.{name}"), e.to_string()))?;
        if v.is_finite() { Ok(v) } else { Err(field(format!("{at}.{name}"), "must be a finite number")) }
    };
    let (lo, hi) = (side("min", &l.min, f64::NEG_INFINITY)?, side("max", &l.max, f64::INFINITY)?);
    if lo > hi {
        return Err(field(at, "`min` is above `max`: give the lower limit as `min`"));
    }
    Ok((lo, hi, l.min.as_ref().and_then(written_unit).or_else(|| l.max.as_ref().and_then(written_unit))))
}

/// `signal` shown in `unit` when one was written.
pub(super) fn in_unit(mut signal: Signal, unit: Option<String>) -> Signal {
    if let Some(u) = unit.and_then(|u| Unit::parse_difference(&u).ok().map(|p| (u, p.factor()))) {
        (signal.unit, signal.factor) = u;
    }
    signal
}

/// The objective: a tag's name (read as `<tag>.value`, shown in its declared unit) or a
/// variable path, with an optional `@unit`.
fn objective(plant: &Plant, text: &str) -> Result<Signal, OptimizeError> {
    let (path, unit) = split_unit(text);
    let tag = plant.spec().tags.get(path);
    let (path, unit) = match tag {
        Some(t) => (format!("{path}.value"), unit.map(str::to_string).or_else(|| t.unit().map(str::to_string))),
        None => (path.to_string(), unit.map(str::to_string)),
    };
    let text = match unit {
        Some(u) => format!("{path}@{u}"),
        None => path,
    };
    select_output(plant, &text).map_err(|e| field("optimization.objective", e.to_string()))
}

impl Problem {
    /// Resolve `spec` against `plant`.
    ///
    /// # Errors
    /// [`OptimizeError::Field`] naming the field: an unknown path, an input a controller drives, a
    /// limit of the wrong dimension, no degree of freedom, a path given twice.
    pub fn new(plant: &Plant, spec: &OptimizationSpec) -> Result<Problem, OptimizeError> {
        let objective = objective(plant, &spec.objective)?;
        if spec.vary.is_empty() {
            return Err(field("optimization.vary", "is empty: name the inputs or setpoints the optimum may move"));
        }
        let mut dofs: Vec<Dof> = Vec::new();
        // In the order of their paths, whatever the face's order: every face then gives the same
        // problem to the last bit (a file's sections reach here sorted, as JSON objects are read).
        let mut vary: Vec<_> = spec.vary.iter().collect();
        vary.sort_by(|a, b| a.0.cmp(b.0));
        for (path, l) in vary {
            let at = format!("optimization.vary.{path}");
            let signal = select_input(plant, path).map_err(|e| field(&at, e.to_string()))?;
            if let Some(d) = dofs.iter().find(|d| d.signal.index == signal.index) {
                return Err(field(&at, format!("is `{}` again: give each input once", d.signal.path)));
            }
            let (lb, ub, unit) = limits(&at, l, plant.inputs()[signal.index].dim)?;
            if lb == ub {
                return Err(field(&at, "has `min` = `max`: an input held at one value is no degree of freedom"));
            }
            dofs.push(Dof { signal: in_unit(signal, unit), lb, ub });
        }
        let mut constraints: Vec<Constraint> = Vec::new();
        let mut limited: Vec<_> = spec.constraints.iter().collect();
        limited.sort_by(|a, b| a.0.cmp(b.0));
        for (path, l) in limited {
            let at = format!("optimization.constraints.{path}");
            if let Some(d) = plantwide_flowsheet::overrides::resolve_input(plant, path)
                .and_then(|i| dofs.iter_mut().find(|d| d.signal.index == i))
            {
                // A limit on a degree of freedom is a bound on it.
                let (lo, hi, _) = limits(&at, l, plant.inputs()[d.signal.index].dim)?;
                (d.lb, d.ub) = (d.lb.max(lo), d.ub.min(hi));
                if d.lb > d.ub {
                    return Err(field(&at, format!("leaves `{}` no value between its bounds", d.signal.path)));
                }
                continue;
            }
            let signal = select_output(plant, path).map_err(|e| field(&at, e.to_string()))?;
            if constraints.iter().any(|c| c.signal.index == signal.index) {
                return Err(field(&at, "names a variable already constrained: give its limits once"));
            }
            let (lo, hi, unit) = limits(&at, l, plant.vars()[signal.index].spec.dim)?;
            if lo.is_infinite() && hi.is_infinite() {
                return Err(field(&at, "has no `min` or `max`"));
            }
            constraints.push(Constraint { signal: in_unit(signal, unit), lo, hi });
        }
        Ok(Problem { objective, sense: spec.sense, dofs, constraints })
    }
}

/// A `LOW:HIGH` text without its `:`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("`{0}`: expected LOW:HIGH (an end may be empty, e.g. `35.5 %:`)")]
pub struct NoRange(pub String);

/// The `Limits` of a text `LOW:HIGH` (either end may be empty: `35.5 %:`), for the faces' flags.
///
/// # Errors
/// [`NoRange`] when there is no `:`.
pub fn parse_limits(text: &str) -> Result<Limits, NoRange> {
    let (lo, hi) = text.split_once(':').ok_or_else(|| NoRange(text.to_string()))?;
    let end = |s: &str| (!s.trim().is_empty()).then(|| QuantityValue::Text(s.trim().to_string()));
    Ok(Limits { min: end(lo), max: end(hi) })
}
