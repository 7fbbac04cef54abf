//! Inputs and outputs chosen for an analysis, written as paths with an optional display unit after
//! `@`: `column.reflux@kmol/min`, `distillate.x[light]`, `column.T[21]@degC`.
//!
//! An input is any free (not controller-driven) declared input, an alias, a tag naming an input, or
//! `stream.X` for input `X` of the unit producing `stream`; an output is any variable path or tag
//! name. A tag named without a unit is shown in its own (`"XMEAS(7)": "reactor.P@kPag"`). Gains are computed in SI and
//! reported in the display units: a gain `dy/du` in SI becomes `dy/du · f_u / f_y`, where `f` is
//! the SI value of one display unit as a *difference* (so `degC` and `K` give the same gains).

use plantwide_flowsheet::error::did_you_mean;
use plantwide_flowsheet::overrides::resolve_input;
use plantwide_flowsheet::{Plant, VarPath};
use plantwide_units::{Dimension, Unit};
use serde::Serialize;

use crate::error::{AnalysisError, request};

/// One input or output of an analysis.
#[derive(Debug, Clone, PartialEq)]
pub struct Signal {
    /// Path as written, without the unit.
    pub path: String,
    /// Display unit (the SI unit of the dimension when none was given).
    pub unit: String,
    /// SI value of one display unit, as a difference.
    pub factor: f64,
    /// Global input index (inputs) or variable index (outputs).
    pub index: usize,
}

/// Path and unit of a signal, as reported in JSON.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SignalLabel {
    /// Path.
    pub path: String,
    /// Display unit.
    pub unit: String,
}

impl Signal {
    /// Path and unit for reports.
    pub fn label(&self) -> SignalLabel {
        SignalLabel { path: self.path.clone(), unit: self.unit.clone() }
    }
    /// A value in SI converted to the display unit (absolute values: offsets such as degC apply).
    pub fn display_value(&self, si: f64) -> f64 {
        Unit::parse(&self.unit).map_or(si / self.factor, |u| u.from_si(si))
    }
}

/// Split `path@unit` into the path and the optional unit.
pub fn split_unit(text: &str) -> (&str, Option<&str>) {
    match text.rsplit_once('@') {
        Some((p, u)) => (p.trim(), Some(u.trim())),
        None => (text.trim(), None),
    }
}

/// Display unit and its SI factor for a quantity of dimension `dim` (the SI unit when `unit` is
/// `None`).
fn display_unit(what: &str, unit: Option<&str>, dim: Dimension) -> Result<(String, f64), AnalysisError> {
    let Some(unit) = unit else {
        let si = if dim == Dimension::DIMENSIONLESS { "-".to_string() } else { format!("{dim}") };
        return Ok((si, 1.0));
    };
    let parsed = Unit::parse_difference(unit).map_err(|e| request(format!("{what}@{unit}: {e}")))?;
    if parsed.dimension() != dim {
        return Err(request(format!(
            "{what}@{unit}: `{unit}` is {} but `{what}` is {} (e.g. {})",
            parsed.dimension().describe(),
            dim.describe(),
            dim.example_hint()
        )));
    }
    Ok((unit.to_string(), parsed.factor()))
}

/// `texts` (`path[@unit]`) with each path that names no unit given `system`'s unit of its
/// dimension (`--units metric`: `column.reflux` → `column.reflux@kmol/h`); a path that names one,
/// a tag with a unit of its own, or a path that resolves to nothing (reported later), is kept as
/// written.
pub fn in_system(plant: &Plant, texts: &[String], system: plantwide_units::UnitSystem) -> Vec<String> {
    texts
        .iter()
        .map(|t| {
            let (path, unit) = split_unit(t);
            let var = || plant.var(path).map(|v| plant.vars()[v].spec.dim);
            let dim = var().or_else(|| resolve_input(plant, path).map(|i| plant.inputs()[i].dim));
            match (unit, dim) {
                (None, _) if plant.tag_unit(path).is_some() => t.clone(),
                (None, Some(d)) if system.unit_for(d) != d.to_string() => format!("{path}@{}", system.unit_for(d)),
                _ => t.clone(),
            }
        })
        .collect()
}

/// Resolve free inputs written as `path[@unit]`.
pub fn select_inputs(plant: &Plant, texts: &[String]) -> Result<Vec<Signal>, AnalysisError> {
    texts.iter().map(|t| select_input(plant, t)).collect()
}

/// Resolve one free input written as `path[@unit]`.
pub fn select_input(plant: &Plant, text: &str) -> Result<Signal, AnalysisError> {
    let (path, unit) = split_unit(text);
    let unit = unit.or_else(|| plant.tag_unit(path));
    let Some(index) = resolve_input(plant, path) else {
        let free: Vec<&str> =
            plant.inputs().iter().filter(|i| i.driven_by.is_none()).map(|i| i.path.as_str()).collect();
        let names = free.iter().copied().chain(plant.aliases().keys().map(String::as_str));
        return Err(request(format!(
            "{}: no input `{path}`{}; free inputs: {}",
            plant.file(),
            did_you_mean(path, names),
            free.join(", ")
        )));
    };
    let info = &plant.inputs()[index];
    if let Some(op) = info.driven_by {
        let ctrl = &plant.blocks()[plant.vars()[op].block].name;
        let auto = plant.input(VarPath::auto(ctrl)).map(|i| plant.inputs()[i].value);
        let instead = match auto {
            // In manual its setpoint moves nothing (a zero gain): its manual output is the input.
            Some(0.0) => format!("`{ctrl}` is in manual: move its manual output `{ctrl}.op_manual` instead"),
            Some(_) => format!(
                "move its setpoint `{ctrl}.sp` instead (the loop closed), or its manual output \
                 `{ctrl}.op_manual` with `set` `{ctrl}.auto=0` (the loop open)"
            ),
            None => format!("move its setpoint `{ctrl}.sp` instead"),
        };
        return Err(request(format!(
            "{}: input `{path}` is driven by controller `{ctrl}`; {instead}, or choose an input no controller drives",
            plant.file()
        )));
    }
    let block = &plant.blocks()[info.block].name;
    let manual = plant.input(VarPath::auto(block)).is_some_and(|i| plant.inputs()[i].value == 0.0);
    if manual && info.path.strip_prefix(block.as_str()).is_some_and(|rest| rest.starts_with(".sp")) {
        // A gain of zero would be reported, and every measure from it meaningless.
        return Err(request(format!(
            "{}: `{path}` is the setpoint of `{block}`, which is in manual: it moves nothing; move its manual \
             output `{block}.op_manual`, or leave `{block}` in auto",
            plant.file()
        )));
    }
    let (unit, factor) = display_unit(path, unit, info.dim)?;
    Ok(Signal { path: path.to_string(), unit, factor, index })
}

/// Resolve output variables written as `path[@unit]`.
pub fn select_outputs(plant: &Plant, texts: &[String]) -> Result<Vec<Signal>, AnalysisError> {
    texts.iter().map(|t| select_output(plant, t)).collect()
}

/// Resolve one output variable written as `path[@unit]`: a variable, or an input a controller
/// drives (`column.reboiler_duty`), read as the controller output that drives it.
pub fn select_output(plant: &Plant, text: &str) -> Result<Signal, AnalysisError> {
    let (path, unit) = split_unit(text);
    let unit = unit.or_else(|| plant.tag_unit(path));
    let driven = || resolve_input(plant, path).and_then(|i| plant.inputs()[i].driven_by);
    let Some(index) = plant.var(path).or_else(driven) else {
        let hint = did_you_mean(path, plant.vars().iter().map(|v| v.path.as_str()));
        return Err(request(format!(
            "{}: no variable `{path}`{hint}; the steady state lists every variable path",
            plant.file()
        )));
    };
    let (unit, factor) = display_unit(path, unit, plant.vars()[index].spec.dim)?;
    Ok(Signal { path: path.to_string(), unit, factor, index })
}

/// A pairing of outputs with inputs: `pairing[i]` is the input (column) paired with output (row) `i`.
///
/// Parsed from `OUT=IN,OUT=IN` (paths without units, or 1-based positions) or from a list of
/// 1-based input positions in output order (`2,1`).
pub fn parse_pairing(text: &str, outputs: &[String], inputs: &[String]) -> Result<Vec<usize>, AnalysisError> {
    let n = outputs.len();
    if n != inputs.len() {
        return Err(request(format!(
            "pairing needs as many inputs as outputs (got {} inputs, {n} outputs)",
            inputs.len()
        )));
    }
    let mut pairing = vec![usize::MAX; n];
    let items: Vec<&str> = text.split(',').map(str::trim).filter(|s| !s.is_empty()).collect();
    if items.len() != n {
        return Err(request(format!(
            "pairing `{text}`: expected {n} pairs (one per output), e.g. `1,2` or `OUT=IN,…`"
        )));
    }
    for (k, item) in items.iter().enumerate() {
        let (out, inp) = match item.split_once('=') {
            Some((o, i)) => (position(o.trim(), outputs, "output")?, position(i.trim(), inputs, "input")?),
            None => (k, position(item, inputs, "input")?),
        };
        if pairing[out] != usize::MAX {
            return Err(request(format!("pairing `{text}`: output `{}` is paired twice", outputs[out])));
        }
        pairing[out] = inp;
    }
    let mut seen = vec![false; n];
    for &p in &pairing {
        if std::mem::replace(&mut seen[p], true) {
            return Err(request(format!("pairing `{text}`: input `{}` is paired twice", inputs[p])));
        }
    }
    Ok(pairing)
}

/// Index of `name` (a path, without unit, or a 1-based position) in `list` (paths, maybe with units).
pub fn position(name: &str, list: &[String], what: &str) -> Result<usize, AnalysisError> {
    if let Ok(k) = name.parse::<usize>() {
        return if (1..=list.len()).contains(&k) {
            Ok(k - 1)
        } else {
            Err(request(format!("{what} position {k} is out of range 1..={}", list.len())))
        };
    }
    let bare: Vec<&str> = list.iter().map(|s| split_unit(s).0).collect();
    bare.iter().position(|p| *p == name).ok_or_else(|| {
        request(format!(
            "`{name}` is not one of the {what}s ({}){}",
            bare.join(", "),
            did_you_mean(name, bare.iter().copied())
        ))
    })
}

/// A block of a block pairing: the outputs and the inputs that control them together.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BlockSpec {
    /// Output (row) indices.
    pub outputs: Vec<usize>,
    /// Input (column) indices.
    pub inputs: Vec<usize>,
}

/// Parse `O1,O2=I1,I2` (paths without units or 1-based positions) into a block.
pub fn parse_block(text: &str, outputs: &[String], inputs: &[String]) -> Result<BlockSpec, AnalysisError> {
    let (o, i) = text
        .split_once('=')
        .ok_or_else(|| request(format!("block `{text}`: expected OUTPUTS=INPUTS, e.g. `1=1` or `1,2=2,3`")))?;
    let list = |s: &str, l: &[String], what: &str| -> Result<Vec<usize>, AnalysisError> {
        s.split(',').map(str::trim).filter(|x| !x.is_empty()).map(|x| position(x, l, what)).collect()
    };
    let block = BlockSpec { outputs: list(o, outputs, "output")?, inputs: list(i, inputs, "input")? };
    if block.outputs.is_empty() || block.outputs.len() != block.inputs.len() {
        return Err(request(format!("block `{text}`: a block needs as many inputs as outputs, at least one")));
    }
    Ok(block)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn pairings_by_position_and_by_name_agree() {
        let outs = names(&["d.x[a]", "b.x[a]"]);
        let ins = names(&["c.reflux@kmol/min", "c.boilup@kmol/min"]);
        assert_eq!(parse_pairing("2,1", &outs, &ins).unwrap(), vec![1, 0]);
        assert_eq!(parse_pairing("b.x[a]=c.reflux, d.x[a]=c.boilup", &outs, &ins).unwrap(), vec![1, 0]);
        assert!(parse_pairing("1,1", &outs, &ins).unwrap_err().to_string().contains("paired twice"));
        assert!(parse_pairing("1,3", &outs, &ins).unwrap_err().to_string().contains("out of range"));
        let e = parse_pairing("d.x[a]=c.reflx,b.x[a]=c.boilup", &outs, &ins).unwrap_err().to_string();
        assert!(e.contains("did you mean `c.reflux`"), "{e}");
    }

    #[test]
    fn blocks_need_square_shapes() {
        let outs = names(&["y1", "y2", "y3"]);
        let ins = names(&["u1", "u2", "u3"]);
        assert_eq!(
            parse_block("1,2=u2,u3", &outs, &ins).unwrap(),
            BlockSpec { outputs: vec![0, 1], inputs: vec![1, 2] }
        );
        assert!(parse_block("1,2=1", &outs, &ins).is_err());
        assert!(parse_block("1", &outs, &ins).is_err());
    }

    #[test]
    fn units_split_at_the_last_at_sign() {
        assert_eq!(split_unit("column.reflux@kmol/min"), ("column.reflux", Some("kmol/min")));
        assert_eq!(split_unit("distillate.x[light]"), ("distillate.x[light]", None));
    }
}
