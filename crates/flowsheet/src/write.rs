//! A plant as a flowsheet file: its description with every input value it holds written into the
//! unit or controller field that sets it, checked by loading the text again, so that the file a
//! user runs is the plant that was studied (a screen's tuned configuration, say).
//!
//! The fields are found by name in the description's serialized form: an input `unit.field` is
//! the unit's (or controller's) field `field`, or one object down (a rigorous column's
//! `rigorous.reboiler_duty`). Which typed field an input comes from is the unit's business; the
//! file format is the one place that knows both.

use serde_json::Value;

use crate::{FlowsheetSpec, Plant, VarPath};

/// Why a plant cannot be written as a flowsheet file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WriteError {
    /// The description does not serialize, or its edited form is no description.
    #[error("{0}")]
    Format(String),
    /// The written text does not load.
    #[error("it does not load: {0}")]
    DoesNotLoad(String),
    /// No field of the description sets this input.
    #[error("no field of the description sets input `{0}`")]
    NoField(String),
    /// Values still differ after writing (a field whose default follows another, unresolved).
    #[error("input values do not survive writing: {0}")]
    DoesNotSurvive(String),
}

/// `plant` as flowsheet file text named `name`, described by `description`, with every input value
/// it holds written (in SI, with its unit) into the field that sets it, in the description's own
/// order. The text is loaded again and every input compared to 1e-12 relative; a value set can
/// move another's default (a PID's bias follows its output's field), so up to four passes.
///
/// # Errors
/// [`WriteError`] when the description cannot be serialized or loaded again, an input has no
/// field, or values still differ after four passes.
pub fn flowsheet_text(plant: &Plant, name: &str, description: &str) -> Result<String, WriteError> {
    let format = |e: serde_json::Error| WriteError::Format(e.to_string());
    let mut doc = serde_json::to_value(plant.spec()).map_err(format)?;
    doc["name"] = name.into();
    doc["description"] = description.into();
    let mut left = Vec::new();
    for _ in 0..4 {
        let text = render(&doc, plant).map_err(format)?;
        let written = crate::load_str(&text, name).map_err(|e| WriteError::DoesNotLoad(e.to_string()))?;
        let value = |path: &str| written.input(path).map_or(f64::NAN, |j| written.inputs()[j].value);
        let differ: Vec<usize> = (0..plant.inputs().len())
            .filter(|&i| {
                let info = &plant.inputs()[i];
                // NaN (no such input written) differs too.
                let same = (value(&info.path) - info.value).abs() <= 1e-12 * info.value.abs().max(1e-300);
                !same
            })
            .collect();
        if differ.is_empty() {
            return Ok(text);
        }
        left = differ
            .iter()
            .map(|&i| {
                let info = &plant.inputs()[i];
                format!("`{}` = {} written as {}", info.path, info.value, value(&info.path))
            })
            .collect();
        for i in differ {
            let info = &plant.inputs()[i];
            if !set_input(&mut doc, &info.path, info.value, info.dim) {
                return Err(WriteError::NoField(info.path.clone()));
            }
        }
    }
    Err(WriteError::DoesNotSurvive(left.join(", ")))
}

/// `doc` as file text in the description's own order: its sections as the format lists them, and
/// units, streams, controllers and input names in `plant`'s order (a JSON object would sort them).
fn render(doc: &Value, plant: &Plant) -> serde_json::Result<String> {
    let mut spec: FlowsheetSpec = serde_json::from_value(doc.clone())?;
    let order = plant.spec();
    spec.units.sort_by_cached_key(|k, _| order.units.get_index_of(k));
    spec.streams.sort_by_cached_key(|k, _| order.streams.get_index_of(k));
    spec.controllers.sort_by_cached_key(|k, _| order.controllers.get_index_of(k));
    spec.inputs.sort_by_cached_key(|k, _| order.inputs.get_index_of(k));
    serde_json::to_string_pretty(&spec).map(|t| t + "\n")
}

/// Set the field that holds input `path` (`unit.field`, in the unit's or controller's
/// description or one object down, e.g. a rigorous column's `rigorous.reboiler_duty`) to `value`
/// (SI) in its unit; false when there is none.
fn set_input(doc: &mut Value, path: &str, value: f64, dim: plantwide_units::Dimension) -> bool {
    let p = VarPath::parse(path);
    let Some(field) = p.field() else { return false };
    let text: Value = if dim.is_dimensionless() { Value::from(value) } else { format!("{value} {dim}").into() };
    if let Some(obj) = doc["units"].get_mut(p.owner()).and_then(|o| o.as_object_mut()) {
        if let Some(slot) = obj.get_mut(field) {
            *slot = text;
            return true;
        }
        for (_, nested) in obj.iter_mut() {
            if let Some(slot) = nested.as_object_mut().and_then(|n| n.get_mut(field)) {
                *slot = text;
                return true;
            }
        }
        return false;
    }
    let Some(obj) = doc["controllers"].get_mut(p.owner()).and_then(|o| o.as_object_mut()) else { return false };
    // A controller's input is a field of its description (`op_manual`, `sp`). A PID's manual output
    // defaults to its bias, and its bias to the value its output had when the plant was assembled:
    // a manual output that differs from the written file's is that bias, written with it so that
    // the loop's integral starts where the screen's did.
    if field == "op_manual" && !obj.contains_key("bias") {
        obj.insert("bias".into(), text.clone());
    }
    obj.insert(field.into(), text);
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Column A with its reflux, its feed and a level setpoint moved (not in the file): the text
    /// written loads as a plant with every input at the moved values, under the name given.
    #[test]
    fn a_plant_written_with_its_inputs_loads_with_them() {
        let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../../flowsheets/column_a.json");
        let mut plant = crate::load_file(std::path::Path::new(file)).unwrap();
        let mut u = plant.input_values();
        for (path, factor) in [("column.reflux", 1.1), ("feed_source.F", 0.93), ("condenser_level.sp", 1.2)] {
            let i = plant.input(path).unwrap_or_else(|| panic!("no input {path}"));
            u[i] *= factor;
        }
        plant.set_input_values(&u);
        let text = flowsheet_text(&plant, "column_a_moved", "column A, moved").unwrap();
        let back = crate::load_str(&text, "column_a_moved").unwrap();
        assert_eq!(back.name(), "column_a_moved");
        assert_eq!(back.inputs().len(), plant.inputs().len());
        for (info, &want) in plant.inputs().iter().zip(&u) {
            let got = back.inputs()[back.input(&info.path).unwrap()].value;
            assert!((got - want).abs() <= 1e-12 * want.abs(), "{}: {got} written, {want} held", info.path);
        }
    }
}
