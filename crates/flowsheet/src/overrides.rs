//! `--set PATH=VALUE` overrides: a declared input (or its alias, or `stream.X` for the feed unit
//! that produces the stream), or any field of a unit's description.

use plantwide_units::parse_quantity_as;
use serde_json::Value;

use crate::error::did_you_mean;
use crate::plant::Plant;
use crate::spec::FlowsheetSpec;

/// Resolve an input path: `unit.input`, an alias, or `stream.X` meaning input `X` of the unit
/// that produces `stream`.
pub fn resolve_input(plant: &Plant, path: &str) -> Option<usize> {
    if let Some(i) = plant.input(path) {
        return Some(i);
    }
    let (head, rest) = path.split_once('.')?;
    let s = plant.streams.iter().find(|s| s.name == head)?;
    plant.input(&format!("{}.{rest}", plant.blocks[s.from.0].name))
}

/// Split `PATH=VALUE`.
pub fn split_assignment(text: &str) -> Result<(&str, &str), String> {
    let limit = plantwide_model::limits::Limits::get().string_len();
    if let Some(msg) = limit.check(text.chars().count(), "the length of this assignment") {
        return Err(format!("--set `{}`: {msg}", plantwide_model::limits::clip(text)));
    }
    text.split_once('=')
        .map(|(p, v)| (p.trim(), v.trim()))
        .ok_or_else(|| format!("`{text}`: expected PATH=VALUE, e.g. feed.F=1.01kmol/min"))
}

/// Apply one assignment to the input vector `u` if `path` names an input.
pub fn set_input(plant: &Plant, u: &mut [f64], path: &str, value: &str) -> Result<bool, String> {
    let Some(i) = resolve_input(plant, path) else { return Ok(false) };
    let info = &plant.inputs[i];
    if info.driven_by.is_some() {
        return Err(format!(
            "--set {path}: this input is driven by a controller; set the controller's setpoint (`<ctrl>.sp`) instead"
        ));
    }
    let v = parse_quantity_as(value, info.dim).map_err(|e| format!("--set {path}: {e}"))?;
    check_input_value(plant, i, v).map_err(|e| format!("--set {path}={value}: {e}"))?;
    u[i] = v;
    Ok(true)
}

/// Check value `v` (SI) of input `i` against its physical range: the one check that file values,
/// `--set` overrides and scenario events all pass ([`plantwide_model::limits::check_input`]).
pub fn check_input_value(plant: &Plant, i: usize, v: f64) -> Result<(), String> {
    let info = &plant.inputs[i];
    let block = &plant.blocks[info.block].name;
    let name = info.path.strip_prefix(&format!("{block}.")).unwrap_or(&info.path);
    plantwide_model::limits::check_input(name, info.dim, v)
}

/// Read the flowsheet at `path` and apply `--set PATH=VALUE` overrides: an input (validated like
/// the file's values) or a field of a unit or controller description (the description is then
/// validated and assembled again). Returns the plant and its input vector.
pub fn load_with(path: &std::path::Path, sets: &[String]) -> Result<(Plant, Vec<f64>), OverrideError> {
    let name = path.display().to_string();
    let text = crate::parse::read_text(path)?;
    let mut spec = crate::parse::parse_spec(&text, &name)?;
    let mut plant = crate::assemble(&spec, &name)?;
    let mut assignments = Vec::new();
    let mut reassemble = false;
    for s in sets {
        let (path, value) = split_assignment(s).map_err(OverrideError::Bad)?;
        let mut u = plant.input_values();
        if set_input(&plant, &mut u, path, value).map_err(OverrideError::Bad)? {
            assignments.push((path.to_string(), value.to_string()));
        } else {
            set_field(&mut spec, path, value).map_err(OverrideError::Bad)?;
            reassemble = true;
        }
    }
    if reassemble {
        plant = crate::assemble(&spec, &name)?;
    }
    let mut u = plant.input_values();
    for (path, value) in &assignments {
        set_input(&plant, &mut u, path, value).map_err(OverrideError::Bad)?;
    }
    check_compositions(&plant, &u).map_err(OverrideError::Bad)?;
    if !sets.is_empty() {
        check_unit_inputs(&plant, &u)
            .map_err(|(path, why)| OverrideError::Bad(format!("with --set, {path}: {why}")))?;
    }
    Ok((plant, u))
}

/// Each unit's own check of its input values ([`plantwide_model::UnitModel::check_inputs`]) at `u`:
/// `Err((JSON path of the input, why))`.
pub fn check_unit_inputs(plant: &Plant, u: &[f64]) -> Result<(), (String, String)> {
    for b in &plant.blocks {
        let values: Vec<f64> = b.input_ids.iter().map(|&i| u[i]).collect();
        let section = if b.kind == crate::BlockKind::Unit { "units" } else { "controllers" };
        b.unit
            .check_inputs(&plant.thermo, &values)
            .map_err(|(name, why)| (format!("{section}.{}.{name}", b.name), why))?;
    }
    Ok(())
}

/// The mole-fraction inputs `z[c]` of each unit (a feed's composition but its last component,
/// which makes up the balance) must not sum above 1: the last fraction would be negative.
pub fn check_compositions(plant: &Plant, u: &[f64]) -> Result<(), String> {
    for (bi, b) in plant.blocks.iter().enumerate() {
        let z: Vec<usize> = (0..plant.inputs.len())
            .filter(|&i| plant.inputs[i].block == bi && plant.inputs[i].path.starts_with(&format!("{}.z[", b.name)))
            .collect();
        let sum: f64 = z.iter().map(|&i| u[i]).sum();
        if sum > 1.0 + 1e-9 {
            let parts: Vec<String> = z.iter().map(|&i| format!("{} = {}", plant.inputs[i].path, u[i])).collect();
            return Err(format!(
                "{}: mole fractions sum to {sum} > 1, leaving a negative fraction for the last component; set them so that they sum to at most 1 ({})",
                b.name,
                parts.join(", ")
            ));
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
    /// An override cannot be applied (the message names it).
    #[error("{0}")]
    Bad(String),
}

/// Apply an assignment to a unit or controller field of the flowsheet description
/// (`unit.field=value`): the value is stored as written (a quantity string or a JSON literal).
pub fn set_field(spec: &mut FlowsheetSpec, path: &str, value: &str) -> Result<(), String> {
    let (head, field) = path.split_once('.').ok_or_else(|| format!("--set {path}: expected `unit.field`"))?;
    let mut doc = serde_json::to_value(&*spec).map_err(|e| e.to_string())?;
    let section = if spec.units.contains_key(head) {
        "units"
    } else if spec.controllers.contains_key(head) {
        "controllers"
    } else {
        let names = spec.units.keys().chain(spec.controllers.keys()).map(String::as_str);
        return Err(format!(
            "--set {path}: no unit, controller, stream or input named `{head}`{}",
            did_you_mean(head, names)
        ));
    };
    let obj = doc[section][head].as_object_mut().ok_or_else(|| format!("--set {path}: `{head}` is not an object"))?;
    if !obj.contains_key(field) {
        let known: Vec<&str> = obj.keys().map(String::as_str).collect();
        return Err(format!(
            "--set {path}: `{head}` has no field `{field}` set in the file (fields: {})",
            known.join(", ")
        ));
    }
    let parsed = serde_json::from_str::<Value>(value).unwrap_or_else(|_| Value::String(value.to_string()));
    obj.insert(field.to_string(), parsed);
    *spec = serde_json::from_value(doc).map_err(|e| format!("--set {path}: {e}"))?;
    Ok(())
}
