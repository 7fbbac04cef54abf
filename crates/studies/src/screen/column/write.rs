//! A configuration's tuned plant as a flowsheet file: its description (the file's, with the level
//! loops moved, the ratio stations and the tuned quality loops `pair1`, `pair2`) and every input
//! value it ran with written into the unit field that sets it, checked by assembling the text
//! again: the file a user runs is the plant the screen ran.

use plantwide_flowsheet::{Plant, VarPath};

use super::{ColumnDynamic, ColumnStructure, file_stem};
use crate::screen::ScreenError;
use crate::screen::pairings::DynamicResult;

/// The flowsheet of configuration `s`'s tuned plant `tuned` (its check `result`).
///
/// # Errors
/// [`ScreenError::Write`] when the description cannot be serialized or assembled, or an input
/// value has no field to go to.
pub(super) fn flowsheet(
    tuned: &Plant,
    s: &ColumnStructure,
    result: &DynamicResult,
    d: &ColumnDynamic,
) -> Result<String, ScreenError> {
    let fail = |why: String| ScreenError::Write { structure: s.name.clone(), why };
    let mut doc = serde_json::to_value(tuned.spec()).map_err(|e| fail(e.to_string()))?;
    doc["name"] = format!("{}_{}", tuned.name(), file_stem(&s.name)).into();
    doc["description"] = description(tuned, s, result, d).into();
    // Written values are set in SI with their unit, then checked; a value set can move another's
    // default (a PID's bias follows its output's field), found in the next pass.
    let mut left = Vec::new();
    for _ in 0..4 {
        let text = render(&doc, tuned).map_err(|e| fail(e.to_string()))?;
        let written =
            plantwide_flowsheet::load_str(&text, &s.name).map_err(|e| fail(format!("it does not load: {e}")))?;
        let value = |path: &str| written.input(path).map_or(f64::NAN, |j| written.inputs()[j].value);
        let differ: Vec<usize> = (0..tuned.inputs().len())
            .filter(|&i| {
                let info = &tuned.inputs()[i];
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
                format!(
                    "`{}` = {} written as {}",
                    tuned.inputs()[i].path,
                    tuned.inputs()[i].value,
                    value(&tuned.inputs()[i].path)
                )
            })
            .collect();
        for i in differ {
            let info = &tuned.inputs()[i];
            if !set_input(&mut doc, &info.path, info.value, info.dim) {
                return Err(fail(format!("no field of the description sets input `{}`", info.path)));
            }
        }
    }
    Err(fail(format!("input values do not survive writing: {}", left.join(", "))))
}

/// `doc` as file text in the description's own order: its sections as the format lists them, and
/// units, streams, controllers and input names in `tuned`'s order (a JSON object would sort them).
fn render(doc: &serde_json::Value, tuned: &Plant) -> serde_json::Result<String> {
    let mut spec: plantwide_flowsheet::FlowsheetSpec = serde_json::from_value(doc.clone())?;
    let order = tuned.spec();
    spec.units.sort_by_cached_key(|k, _| order.units.get_index_of(k));
    spec.streams.sort_by_cached_key(|k, _| order.streams.get_index_of(k));
    spec.controllers.sort_by_cached_key(|k, _| order.controllers.get_index_of(k));
    spec.inputs.sort_by_cached_key(|k, _| order.inputs.get_index_of(k));
    serde_json::to_string_pretty(&spec).map(|t| t + "\n")
}

/// Set the field that holds input `path` (`unit.field`, in the unit's or controller's
/// description or one object down, e.g. a rigorous column's `rigorous.reboiler_duty`) to `value`
/// (SI) in its unit; false when there is none.
fn set_input(doc: &mut serde_json::Value, path: &str, value: f64, dim: plantwide_units::Dimension) -> bool {
    let p = VarPath::parse(path);
    let Some(field) = p.field() else { return false };
    let text: serde_json::Value =
        if dim.is_dimensionless() { serde_json::json!(value) } else { format!("{value} {dim}").into() };
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

/// What the written file is, in words.
fn description(tuned: &Plant, s: &ColumnStructure, result: &DynamicResult, d: &ColumnDynamic) -> String {
    let loops: Vec<String> = result
        .loops
        .iter()
        .enumerate()
        .map(|(i, l)| {
            format!("pair{} holds {} by {} (kc {:e}, tau_i {:e} s, {})", i + 1, l.cv, l.mv, l.kc, l.tau_i, l.action)
        })
        .collect();
    format!(
        "{} as inventory configuration {} (plantwide screen --column): {}; PI tuned together by BLT (F = {}) with a {} s \
         measurement dead time",
        tuned.name(),
        s.name,
        loops.join("; "),
        result.detuning_factor.map_or("–".into(), |f| format!("{f:.4}")),
        d.measurement.dead_time
    )
}
