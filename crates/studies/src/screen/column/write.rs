//! A configuration's tuned plant as a flowsheet file: its description (the file's, with the level
//! loops moved, the ratio stations and the tuned quality loops `pair1`, `pair2`) and every input
//! value it ran with, written by [`plantwide_flowsheet::write::flowsheet_text`]: the file a user
//! runs is the plant the screen ran.

use plantwide_flowsheet::Plant;

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
    let name = format!("{}_{}", tuned.name(), file_stem(&s.name));
    plantwide_flowsheet::write::flowsheet_text(tuned, &name, &description(tuned, s, result, d))
        .map_err(|e| ScreenError::Write { structure: s.name.clone(), why: e.to_string() })
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
        "{} as inventory configuration {} (from plantwide's column screen): {}; PI tuned together by BLT (F = {}) with a {} s \
         measurement dead time",
        tuned.name(),
        s.name,
        loops.join("; "),
        result.detuning_factor.map_or("–".into(), |f| format!("{f:.4}")),
        d.measurement.dead_time
    )
}
