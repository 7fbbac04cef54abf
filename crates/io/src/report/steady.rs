//! The report of a steady state ([`Solution`]): how it was found, the warnings, the design specs
//! met, the stream table and each block's own variables, in the display units of a
//! [`UnitSystem`]; and its JSON (every variable under its path, SI). `plantwide steady` prints
//! [`text`] (or [`json`] with `--json`).

use std::collections::BTreeMap;

use plantwide_flowsheet::Plant;
use plantwide_model::stream::{F, H, P, T, Z0};
use plantwide_solve::{Method, Solution};
use plantwide_units::{Dimension, Display, UnitSystem, convert_from_si};
use serde::Serialize;

use crate::IoError;

/// `v` (SI) with its SI unit (none for a dimensionless number), as the notes of a design spec met
/// say it.
pub fn with_unit(v: f64, dim: Dimension) -> String {
    let v = plantwide_model::limits::number(v);
    if dim == Dimension::DIMENSIONLESS { v } else { format!("{v} {dim}") }
}

/// `v` (SI) of dimension `dim` in `system`'s unit, with the unit (none for a dimensionless
/// number), six decimals.
pub fn shown(v: f64, dim: Dimension, system: UnitSystem) -> String {
    if dim == Dimension::DIMENSIONLESS {
        return format!("{v:.6}");
    }
    match Display::new(&system.unit_for(dim)) {
        Ok(d) => format!("{:.6} {}", d.value(v), d.unit()),
        Err(_) => format!("{v:.6} {dim}"),
    }
}

/// Newton's iterations and scaled residual, or (the sequential-modular method alone) no
/// iterations and the largest tear residual.
fn iterations_and_residual(sol: &Solution) -> (usize, f64) {
    match (&sol.newton, &sol.sm) {
        (Some(n), _) => (n.iterations, n.residual),
        (None, Some(sm)) => (0, sm.sccs.iter().map(|s| s.residual).fold(0.0, f64::max)),
        (None, None) => (0, 0.0),
    }
}

/// The steady state as text: the sequential-modular log and how Newton took over, the method's
/// iterations and residual, the warnings, then [`specs`], [`streams`] and [`blocks`] in `units`
/// (default: the stream table in kmol/h, K, kPa, kJ/mol and every other quantity in SI).
pub fn text(plant: &Plant, sol: &Solution, units: Option<UnitSystem>) -> String {
    let mut t = String::new();
    if let Some(sm) = &sol.sm {
        sm.log().iter().for_each(|l| t.push_str(&format!("{l}\n")));
    }
    if let Some(why) = &sol.sm_failure {
        t.push_str(&format!("sequential-modular start incomplete ({why}); Newton took over\n"));
    }
    if let Some(how) = &sol.closed_loops {
        t.push_str(&format!("the cold start failed: {how}\n"));
    }
    let (iterations, residual) = iterations_and_residual(sol);
    t.push_str(&match (&sol.newton, &sol.sm) {
        (None, Some(sm)) => format!(
            "steady state of `{}`: converged by the sequential-modular method in {} passes, tear residual {residual:.2e}\n\n",
            plant.name(),
            sm.passes()
        ),
        _ => format!(
            "steady state of `{}`: converged in {iterations} iterations, scaled residual {residual:.2e}\n\n",
            plant.name()
        ),
    });
    for w in &sol.warnings {
        t.push_str(&format!("warning: {}\n\n", w.message));
    }
    t.push_str(&specs(plant, sol, units));
    t.push_str(&streams(plant, sol, units));
    t.push_str(&blocks(plant, sol, units));
    t
}

/// The stream table: F, T, P, h in `units` (default kmol/h, K, kPa, kJ/mol), then the mole
/// fractions; a blank line after it.
fn streams(plant: &Plant, sol: &Solution, units: Option<UnitSystem>) -> String {
    use plantwide_units::Dimension as D;
    let default = ["kmol/h", "K", "kPa", "kJ/mol"];
    let shown: Vec<Display> = [D::MOLAR_FLOW, D::TEMPERATURE, D::PRESSURE, D::MOLAR_ENERGY]
        .iter()
        .zip(default)
        .map(|(&d, u)| units.map_or(u.to_string(), |s| s.unit_for(d)))
        .map(|u| Display::new(&u).unwrap_or_else(|_| Display::new("1").expect("the unit 1")))
        .collect();
    let head = |k: usize, name: &str| format!("{name} {}", shown[k].unit());
    let mut t =
        format!("{:<14} {:>12} {:>9} {:>10} {:>11}", "stream", head(0, "F"), head(1, "T"), head(2, "P"), head(3, "h"));
    for c in plant.components() {
        t.push_str(&format!(" {:>10}", format!("x[{}]", super::truncate(c, 7))));
    }
    t.push('\n');
    for s in plant.streams() {
        let v = &sol.x[s.offset..s.offset + plant.stream_layout().len()];
        t.push_str(&format!(
            "{:<14} {:>12.4} {:>9.3} {:>10.3} {:>11.4}",
            super::truncate(&s.name, 14),
            shown[0].value(v[F]),
            shown[1].value(v[T]),
            shown[2].value(v[P]),
            shown[3].value(v[H])
        ));
        for z in &v[Z0..] {
            t.push_str(&format!(" {:>10.6}", z));
        }
        t.push('\n');
    }
    t.push('\n');
    t
}

/// Each unit's and controller's own variables outside the streams, with their units (SI, or
/// `units`'); a block with more than twelve, its first six and their count.
fn blocks(plant: &Plant, sol: &Solution, units: Option<UnitSystem>) -> String {
    let slen = plant.stream_layout().len();
    let mut in_stream = vec![false; plant.n_vars()];
    plant.streams().iter().for_each(|s| in_stream[s.offset..s.offset + slen].fill(true));
    let system = units.unwrap_or_default();
    let mut t = String::new();
    for b in plant.blocks() {
        let own = b.own_offset..b.own_offset + b.layout.n_own();
        let prefix = format!("{}.", b.name);
        let internal: Vec<String> = own
            .filter(|&j| !in_stream[j])
            .map(|j| {
                let v = &plant.vars()[j];
                format!("{}={}", v.path.trim_start_matches(&prefix), shown(sol.x[j], v.spec.dim, system))
            })
            .collect();
        let kind = b.kind.label();
        if internal.len() > 12 {
            t.push_str(&format!(
                "{kind} {:<14} {:<10} {} … ({} variables; the JSON output lists them all)\n",
                b.name,
                b.unit.type_name(),
                internal[..6].join("  "),
                internal.len()
            ));
        } else if !internal.is_empty() {
            t.push_str(&format!("{kind} {:<14} {:<10} {}\n", b.name, b.unit.type_name(), internal.join("  ")));
        }
    }
    t
}

/// Each design spec met: the varied input's value found (and the file's), the held variable's
/// value, in `units` as the streams are (else SI); a blank line after them.
fn specs(plant: &Plant, sol: &Solution, units: Option<UnitSystem>) -> String {
    let value = |v: f64, dim| units.map_or_else(|| with_unit(v, dim), |u| shown(v, dim, u));
    let mut t = String::new();
    for s in plant.specs() {
        let (was, dim) = (plant.inputs()[s.input].value, plant.inputs()[s.input].dim);
        t.push_str(&format!(
            "design spec {}: met with `{}` = {} (from {}), `{}` = {}\n",
            s.origin,
            s.vary,
            value(sol.u[s.input], dim),
            value(was, dim),
            s.path,
            value(sol.x[s.var], plant.vars()[s.var].spec.dim)
        ));
    }
    if !plant.specs().is_empty() {
        t.push('\n');
    }
    t
}

/// `plantwide steady --json`. Its keys in alphabetical order, at every level: the order this JSON
/// has always had (serde_json's map sorts its keys, and the solver's reports are shown through
/// one).
#[derive(Serialize)]
struct SteadyJson<'a> {
    converged: bool,
    iterations: usize,
    method: Method,
    residual: f64,
    sequential_modular: serde_json::Value,
    specs: Vec<SpecJson<'a>>,
    tags: BTreeMap<&'a str, f64>,
    values: BTreeMap<String, f64>,
    warnings: serde_json::Value,
}

/// A design spec met (SI).
#[derive(Serialize)]
struct SpecJson<'a> {
    input_value: f64,
    origin: &'a str,
    path: &'a str,
    target: f64,
    value: f64,
    vary: &'a str,
}

/// The steady state found by `method` as JSON: every variable and free input under its path
/// (SI), each tag's value under its name in the tag's unit (SI without one), the specs met, the
/// sequential-modular report and the warnings.
///
/// # Errors
/// [`IoError::Draw`] if serde cannot write it.
pub fn json(plant: &Plant, sol: &Solution, method: Method) -> Result<String, IoError> {
    let value = |v: serde_json::Result<serde_json::Value>| v.map_err(|e| IoError::Draw(format!("JSON: {e}")));
    let (iterations, residual) = iterations_and_residual(sol);
    let specs = plant
        .specs()
        .iter()
        .map(|s| SpecJson {
            input_value: sol.u[s.input],
            origin: &s.origin,
            path: &s.path,
            target: s.target,
            value: sol.x[s.var],
            vary: &s.vary,
        })
        .collect();
    super::json(&SteadyJson {
        converged: true,
        iterations,
        method,
        residual,
        sequential_modular: value(serde_json::to_value(&sol.sm))?,
        specs,
        tags: plant
            .tags()
            .iter()
            .map(|(name, t)| {
                let si = sol.x[t.var];
                (name.as_str(), t.unit.as_deref().map_or(si, |u| convert_from_si(si, u).unwrap_or(si)))
            })
            .collect(),
        values: sol.values(plant).into_iter().collect(),
        warnings: value(serde_json::to_value(&sol.warnings))?,
    })
}
