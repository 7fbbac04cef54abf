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
    u[i] = parse_quantity_as(value, info.dim).map_err(|e| format!("--set {path}: {e}"))?;
    Ok(true)
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
