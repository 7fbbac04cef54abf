//! `--set PATH=VALUE` overrides: a declared input (or its alias, or `stream.X` for the feed unit
//! that produces the stream), or any field of a unit's description.

use plantwide_units::parse_quantity_as;
use serde_json::Value;

use crate::error::did_you_mean;
use crate::path::VarPath;
use crate::plant::Plant;
use crate::spec::FlowsheetSpec;

/// Resolve an input path: `unit.input`, an alias, or `stream.X` meaning input `X` of the unit
/// that produces `stream`.
pub fn resolve_input(plant: &Plant, path: &str) -> Option<usize> {
    if let Some(i) = plant.input(path) {
        return Some(i);
    }
    let path = VarPath::parse(path);
    let s = plant.streams.iter().find(|s| s.name == path.owner())?;
    plant.input(VarPath::new(&plant.blocks[s.from.0].name, path.field()?))
}

/// One `--set PATH=VALUE` assignment: an input (its value with units) or a field of a unit or
/// controller description (a quantity string or a JSON literal).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Override {
    /// `unit.input`, an alias, `stream.X` or `unit.field`.
    pub path: String,
    /// The value as written.
    pub value: String,
}

impl Override {
    /// An assignment of `value` to `path`.
    pub fn new(path: impl Into<String>, value: impl Into<String>) -> Override {
        Override { path: path.into(), value: value.into() }
    }

    /// Parse `PATH=VALUE`.
    pub fn parse(text: &str) -> Result<Override, OverrideError> {
        let (p, v) = split_assignment(text)?;
        Ok(Override::new(p, v))
    }
}

impl std::str::FromStr for Override {
    type Err = OverrideError;
    fn from_str(s: &str) -> Result<Override, OverrideError> {
        Override::parse(s)
    }
}

/// Split `PATH=VALUE`.
pub fn split_assignment(text: &str) -> Result<(&str, &str), OverrideError> {
    let limit = plantwide_model::limits::Limits::get().string_len();
    if let Some(msg) = limit.check(text.chars().count(), "the length of this assignment") {
        return Err(OverrideError::TooLong { text: plantwide_model::limits::clip(text), why: msg });
    }
    text.split_once('=')
        .map(|(p, v)| (p.trim(), v.trim()))
        .ok_or_else(|| OverrideError::Syntax { text: text.to_string() })
}

/// Apply one assignment to the input vector `u` if `path` names an input (`Ok(false)` if it does not).
pub fn set_input(plant: &Plant, u: &mut [f64], path: &str, value: &str) -> Result<bool, OverrideError> {
    let Some(i) = resolve_input(plant, path) else { return Ok(false) };
    let info = &plant.inputs[i];
    if info.driven_by.is_some() {
        return Err(OverrideError::Driven { path: path.to_string() });
    }
    let v = parse_quantity_as(value, info.dim).map_err(|e| OverrideError::Value {
        path: path.to_string(),
        value: None,
        why: e.to_string(),
    })?;
    check_input_value(plant, i, v).map_err(|why| OverrideError::Value {
        path: path.to_string(),
        value: Some(value.to_string()),
        why: why.to_string(),
    })?;
    u[i] = v;
    Ok(true)
}

/// Check value `v` (SI) of input `i` against its physical range: the one check that file values,
/// `--set` overrides and scenario events all pass ([`plantwide_model::limits::check_input`]).
pub fn check_input_value(plant: &Plant, i: usize, v: f64) -> Result<(), plantwide_model::limits::RangeError> {
    let info = &plant.inputs[i];
    let block = &plant.blocks[info.block].name;
    let name = info.path.strip_prefix(&format!("{block}.")).unwrap_or(&info.path);
    plantwide_model::limits::check_input_within(name, info.dim, v, plant.input_range(i))
}

/// Read the flowsheet at `path` and apply `overrides`: inputs (validated like the file's values)
/// and fields of unit or controller descriptions (the description is then validated and
/// assembled again). The plant's input values include the overrides.
pub fn load_with(path: &std::path::Path, overrides: &[Override]) -> Result<Plant, OverrideError> {
    let name = path.display().to_string();
    load_str_with(&crate::parse::read_text(path)?, &name, overrides)
}

/// [`load_with`] for flowsheet text already read (`file` names it in messages).
pub fn load_str_with(text: &str, file: &str, overrides: &[Override]) -> Result<Plant, OverrideError> {
    let plant = crate::load_str(text, file)?;
    if overrides.is_empty() {
        return Ok(plant);
    }
    plant.variant(overrides)
}

/// Set the input `overrides` on `plant` (every one must name an input), then check the
/// compositions and each unit's own input checks.
pub(crate) fn apply_inputs(plant: &mut Plant, overrides: &[Override]) -> Result<(), OverrideError> {
    let mut u = plant.input_values();
    for o in overrides {
        if !set_input(plant, &mut u, &o.path, &o.value)? {
            return Err(OverrideError::NoTarget { path: o.path.clone(), hint: String::new() });
        }
        let dim = resolve_input(plant, &o.path).map(|i| plant.inputs[i].dim);
        let note = dim.and_then(|d| plantwide_model::build::bare_note(&o.value.as_str().into(), d));
        plant.notes.extend(note.map(|n| format!("set {}: {n}", o.path)));
    }
    check_compositions(plant, &u)?;
    if !overrides.is_empty() {
        check_unit_inputs(plant, &u)
            .map_err(|e| OverrideError::UnitInput { path: e.path, why: e.source.to_string() })?;
    }
    plant.set_input_values(&u);
    Ok(())
}

/// A unit's own check of an input value failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{path}: {source}")]
pub struct UnitInputError {
    /// JSON path of the input (`units.feed.P`).
    pub path: String,
    /// Why.
    pub source: Box<plantwide_model::InputError>,
}

/// Each unit's own check of its input values ([`plantwide_model::UnitModel::check_inputs`]) at `u`.
pub fn check_unit_inputs(plant: &Plant, u: &[f64]) -> Result<(), UnitInputError> {
    for b in &plant.blocks {
        let values: Vec<f64> = b.input_ids.iter().map(|&i| u[i]).collect();
        let section = b.kind.section();
        b.unit
            .check_inputs(&plant.thermo, &values)
            .map_err(|e| UnitInputError { path: format!("{section}.{}.{}", b.name, e.input()), source: Box::new(e) })?;
    }
    Ok(())
}

/// The mole-fraction inputs `z[c]` of each unit (a feed's composition but its last component,
/// which makes up the balance) must not sum above 1: the last fraction would be negative.
pub fn check_compositions(plant: &Plant, u: &[f64]) -> Result<(), OverrideError> {
    let mut by_block = vec![Vec::new(); plant.blocks.len()];
    for (i, input) in plant.inputs.iter().enumerate() {
        let path = VarPath::parse(&input.path);
        if path.owner() == plant.blocks[input.block].name && path.is_composition() {
            by_block[input.block].push(i);
        }
    }
    for (b, z) in plant.blocks.iter().zip(by_block) {
        let sum: f64 = z.iter().map(|&i| u[i]).sum();
        if sum > 1.0 + 1e-9 {
            let parts: Vec<String> = z.iter().map(|&i| format!("{} = {}", plant.inputs[i].path, u[i])).collect();
            return Err(OverrideError::Composition { unit: b.name.clone(), sum, parts: parts.join(", ") });
        }
    }
    Ok(())
}

/// Why a flowsheet with overrides could not be loaded.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OverrideError {
    /// The file, or the description after a field override, is invalid.
    #[error(transparent)]
    Load(#[from] crate::LoadError),
    /// The assignment is too long.
    #[error("set `{text}`: {why}")]
    TooLong {
        /// The assignment, clipped.
        text: String,
        /// The limit and how to raise it.
        why: String,
    },
    /// Not of the form `PATH=VALUE`.
    #[error("`{text}`: expected PATH=VALUE, e.g. feed.F=1.01kmol/min")]
    Syntax {
        /// The assignment.
        text: String,
    },
    /// The input is driven by a controller.
    #[error("set {path}: this input is driven by a controller; set the controller's setpoint (`<ctrl>.sp`) instead")]
    Driven {
        /// The input path.
        path: String,
    },
    /// The value does not parse as the input's quantity, or is outside its physical range.
    #[error("set {path}{}: {why}", value.as_ref().map(|v| format!("={v}")).unwrap_or_default())]
    Value {
        /// The input path.
        path: String,
        /// The value as written (when it parsed).
        value: Option<String>,
        /// What is wrong and what would fix it.
        why: String,
    },
    /// No input, unit or controller of that name.
    #[error("set {path}: no unit, controller, stream or input named `{}`{hint}", path.split('.').next().unwrap_or(path))]
    NoTarget {
        /// The path.
        path: String,
        /// A suggestion, or empty.
        hint: String,
    },
    /// The path is not `unit.field`, the unit is not an object, or it has no such field.
    #[error("set {path}: {why}")]
    Field {
        /// The path.
        path: String,
        /// What is wrong (the fields it has, the deserialization error).
        why: String,
    },
    /// A controller cannot be added or removed as asked ([`crate::Plant::restructure`]).
    #[error("controller `{controller}`: {why}")]
    Structure {
        /// The controller.
        controller: String,
        /// What is wrong.
        why: String,
    },
    /// A unit's mole fractions sum above 1.
    #[error(
        "{unit}: mole fractions sum to {sum} > 1, leaving a negative fraction for the last component; set them so that they sum to at most 1 ({parts})"
    )]
    Composition {
        /// The unit.
        unit: String,
        /// Their sum.
        sum: f64,
        /// `path = value` of each.
        parts: String,
    },
    /// A unit's own check of its inputs failed ([`plantwide_model::UnitModel::check_inputs`]).
    #[error("with `set`, {path}: {why}")]
    UnitInput {
        /// JSON path of the input.
        path: String,
        /// Why.
        why: String,
    },
}

/// Apply an assignment to a unit or controller field of the flowsheet description
/// (`unit.field=value`): the value is stored as written (a quantity string or a JSON literal).
pub fn set_field(spec: &mut FlowsheetSpec, path: &str, value: &str) -> Result<(), OverrideError> {
    let field_error = |why: String| OverrideError::Field { path: path.to_string(), why };
    let parsed_path = VarPath::parse(path);
    let head = parsed_path.owner();
    let field = parsed_path.field().ok_or_else(|| field_error("expected `unit.field`".into()))?;
    let mut doc = serde_json::to_value(&*spec).map_err(|e| field_error(e.to_string()))?;
    let section = if spec.units.contains_key(head) {
        "units"
    } else if spec.controllers.contains_key(head) {
        "controllers"
    } else {
        let names = spec.units.keys().chain(spec.controllers.keys()).map(String::as_str);
        return Err(OverrideError::NoTarget { path: path.to_string(), hint: did_you_mean(head, names) });
    };
    // An `equations` unit's parameters are set by name too (`reactor.k0=…`, a size study's
    // `tank.area=…`).
    let unit = &doc[section][head];
    let in_parameters = unit.get(field).is_none() && unit.get("parameters").and_then(|p| p.get(field)).is_some();
    let target = if in_parameters { &mut doc[section][head]["parameters"] } else { &mut doc[section][head] };
    let obj = target.as_object_mut().ok_or_else(|| field_error(format!("`{head}` is not an object")))?;
    if !obj.contains_key(field) {
        let known: Vec<&str> = obj.keys().map(String::as_str).collect();
        return Err(field_error(format!(
            "`{head}` has no field `{field}` set in the file (fields: {})",
            known.join(", ")
        )));
    }
    let mut parsed = serde_json::from_str::<Value>(value).unwrap_or_else(|_| Value::String(value.to_string()));
    if in_parameters {
        parsed = parameter_in_si(&obj[field], parsed);
    }
    obj.insert(field.to_string(), parsed);
    *spec = serde_json::from_value(doc).map_err(|e| field_error(e.to_string()))?;
    Ok(())
}

/// A bare number set on an `equations` unit's parameter is in SI units of the parameter's
/// dimension as the file writes it (`--set reactor.ua=3000` on `"ua": "2 kW/K"` is 3000 W/K), as
/// bare numbers are everywhere else, rather than dimensionless; anything else stays as written.
fn parameter_in_si(old: &Value, new: Value) -> Value {
    let (Some(x), Some(Ok(q))) = (new.as_f64(), old.as_str().map(plantwide_units::parse_quantity)) else {
        return new;
    };
    if q.dim.is_dimensionless() { new } else { Value::String(format!("{x:e} {}", q.dim)) }
}
