//! `plantwide steady FILE [--json] [--set PATH=VALUE ...] [--spec PATH=VALUE --vary INPUT ...]
//! [--method eo|sm|auto] [--units si|metric|field]`: the text shows every quantity with its unit
//! (SI, or the `--units` system's); JSON stays in SI.

use std::path::Path;

use plantwide::flowsheet::{BlockKind, Plant, SpecEntry};
use plantwide::model::stream::{F, H, P, T, Z0};
use plantwide::solve::{Method, Progress, Solution, StrategySettings, converge_observed};
use plantwide::units::{Display, UnitSystem};

use super::CliError;

/// Load `file`, apply `--set` overrides, return the plant at its design point and its input vector:
/// design specs in the file are met first and their varied inputs fixed at the values found
/// ([`Plant::fix_specs`]), so that dynamics and analyses start from the plant the specs define.
pub fn load_with_overrides(file: &Path, sets: &[String]) -> Result<(Plant, Vec<f64>), CliError> {
    let mut plant = load_plant(file, sets)?;
    let specs: Vec<(String, String, usize)> =
        plant.specs().iter().map(|s| (s.label(), s.vary.clone(), s.input)).collect();
    if let Some(sol) = plantwide::solve::fix_design_point(&mut plant).map_err(solve_error)? {
        for (label, vary, input) in specs {
            let dim = plant.inputs()[input].dim;
            eprintln!("note: design spec {label} met: `{vary}` = {}", with_unit(sol.u[input], dim));
        }
    }
    let u = plant.input_values();
    Ok((plant, u))
}

/// Load `file` and apply `--set` overrides; design specs stay to be met.
pub fn load_plant(file: &Path, sets: &[String]) -> Result<Plant, CliError> {
    let user = |e: plantwide::flowsheet::OverrideError| CliError::user(e.to_string());
    let overrides = sets.iter().map(|s| s.parse()).collect::<Result<Vec<_>, _>>().map_err(user)?;
    let plant = plantwide::flowsheet::load_with(file, &overrides).map_err(user)?;
    for note in plant.notes() {
        eprintln!("note: {}: {}", file.display(), super::library_flags(note.clone()));
    }
    Ok(plant)
}

/// `--spec PATH=VALUE` paired in order with `--vary INPUT`, added to `plant`'s own specs.
pub fn add_specs(plant: &mut Plant, specs: &[String], vary: &[String]) -> Result<(), CliError> {
    if specs.len() != vary.len() {
        return Err(CliError::user(format!(
            "--spec is given {} time(s) and --vary {} time(s): each spec pairs with one varied input (the k-th --spec with the k-th --vary), e.g. --spec distillate.x[light]=0.995 --vary column.reflux",
            specs.len(),
            vary.len()
        )));
    }
    let mut entries = Vec::with_capacity(specs.len());
    for (s, v) in specs.iter().zip(vary) {
        let (path, value) = plantwide::flowsheet::overrides::split_assignment(s).map_err(|e| {
            let message = e.to_string();
            CliError::user(format!("--spec {}", message.strip_prefix("set ").unwrap_or(&message)))
        })?;
        entries.push(SpecEntry { path: path.to_string(), value: value.into(), vary: v.clone() });
    }
    plant.add_specs(&entries).map_err(|e| CliError::user(format!("{}: {e}", plant.file())))
}

/// `v` (SI) with its SI unit (none for a dimensionless number).
fn with_unit(v: f64, dim: plantwide::units::Dimension) -> String {
    let v = plantwide::model::limits::number(v);
    if dim == plantwide::units::Dimension::DIMENSIONLESS { v } else { format!("{v} {dim}") }
}

/// Converge the way `plantwide steady` does by default (sequential-modular pass, then whole-plant
/// Newton), so that every command starts from the same steady state.
pub fn converge(plant: &Plant, u: &[f64]) -> Result<Solution, CliError> {
    converge_by(plant, u, MethodArg::Auto)
}

/// How `--method` finds the steady state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// Whole-plant Newton (equation oriented).
    Eo,
    /// Sequential modular: unit by unit in flow order, recycles converged on tear streams.
    Sm,
    /// Sequential modular to a loose tolerance, then whole-plant Newton (plants with recycles);
    /// whole-plant Newton alone otherwise.
    Auto,
}

/// Converge by `method` with a progress spinner on stderr (hidden when stderr is not a terminal),
/// mapping failures to exit codes.
pub fn converge_by(plant: &Plant, u: &[f64], method: MethodArg) -> Result<Solution, CliError> {
    let method = match method {
        MethodArg::Eo => Method::Eo,
        MethodArg::Sm => Method::Sm,
        MethodArg::Auto => Method::Auto,
    };
    let bar = indicatif::ProgressBar::new_spinner();
    let mut observer = |p: Progress<'_>| {
        bar.set_message(match p {
            Progress::Pass(r) => {
                format!("sequential modular, recycle {} pass {}: tear residual {:.2e}", r.recycle, r.pass, r.residual)
            }
            Progress::Newton(r) => {
                let phase = if r.pseudo_dt.is_some() { "pseudo-transient" } else { "Newton" };
                format!("{phase} iteration {}: scaled residual {:.2e}", r.iter + 1, r.residual)
            }
        });
        bar.tick();
    };
    let settings = StrategySettings { method, ..StrategySettings::default() };
    debug_assert_eq!(plant.input_values(), u, "the plant carries the input values it is converged at");
    let result = converge_observed(plant, &settings, &mut observer);
    bar.finish_and_clear();
    result.map_err(solve_error)
}

/// A failed convergence: an ill-posed plant is the user's error (exit 1), else numerical (exit 2).
fn solve_error(e: plantwide::solve::SolveError) -> CliError {
    if e.is_user_error() { CliError::user(e.to_string()) } else { CliError::numerical(e.to_string()) }
}

/// What `plantwide steady` is asked.
pub struct SteadyArgs<'a> {
    /// Flowsheet file.
    pub file: &'a Path,
    /// Print JSON.
    pub json: bool,
    /// `--set PATH=VALUE`.
    pub sets: &'a [String],
    /// `--spec PATH=VALUE`.
    pub specs: &'a [String],
    /// `--vary INPUT`, paired in order with `specs`.
    pub vary: &'a [String],
    /// `--method`.
    pub method: MethodArg,
    /// `--units`: display units of the text (default: the stream table in kmol/h, K, kPa, kJ/mol
    /// and every other quantity in SI).
    pub units: Option<UnitSystem>,
}

pub fn run(a: &SteadyArgs<'_>) -> Result<(), CliError> {
    let (json, method) = (a.json, a.method);
    let mut plant = load_plant(a.file, a.sets)?;
    add_specs(&mut plant, a.specs, a.vary)?;
    let u = plant.input_values();
    let sol = converge_by(&plant, &u, method)?;
    let (iterations, residual) = match (&sol.newton, &sol.sm) {
        (Some(n), _) => (n.iterations, n.residual),
        (None, Some(sm)) => (0, sm.sccs.iter().map(|s| s.residual).fold(0.0, f64::max)),
        (None, None) => (0, 0.0),
    };
    if json {
        return print_json(&plant, &sol, method, iterations, residual);
    }
    if let Some(sm) = &sol.sm {
        sm.log().iter().for_each(|l| outln!("{l}"));
    }
    if let Some(why) = &sol.sm_failure {
        outln!("sequential-modular start incomplete ({why}); Newton took over");
    }
    if let Some(how) = &sol.closed_loops {
        outln!("the cold start failed: {how}");
    }
    match (&sol.newton, &sol.sm) {
        (None, Some(sm)) => outln!(
            "steady state of `{}`: converged by the sequential-modular method in {} passes, tear residual {residual:.2e}\n",
            plant.name(),
            sm.passes()
        ),
        _ => outln!(
            "steady state of `{}`: converged in {iterations} iterations, scaled residual {residual:.2e}\n",
            plant.name()
        ),
    }
    for w in &sol.warnings {
        outln!("warning: {}\n", w.message);
    }
    print_specs(&plant, &sol, a.units);
    print_streams(&plant, &sol, a.units);
    print_blocks(&plant, &sol, a.units);
    Ok(())
}

/// The stream table: F, T, P, h in the `--units` system (default kmol/h, K, kPa, kJ/mol), then the
/// mole fractions.
fn print_streams(plant: &Plant, sol: &Solution, units: Option<UnitSystem>) {
    use plantwide::units::Dimension as D;
    let default = ["kmol/h", "K", "kPa", "kJ/mol"];
    let shown: Vec<Display> = [D::MOLAR_FLOW, D::TEMPERATURE, D::PRESSURE, D::MOLAR_ENERGY]
        .iter()
        .zip(default)
        .map(|(&d, u)| units.map_or(u.to_string(), |s| s.unit_for(d)))
        .map(|u| Display::new(&u).unwrap_or_else(|_| Display::new("1").expect("the unit 1")))
        .collect();
    let head = |k: usize, name: &str| format!("{name} {}", shown[k].unit());
    out!("{:<14} {:>12} {:>9} {:>10} {:>11}", "stream", head(0, "F"), head(1, "T"), head(2, "P"), head(3, "h"));
    for c in plant.components() {
        out!(" {:>10}", format!("x[{}]", truncate(c, 7)));
    }
    outln!();
    for s in plant.streams() {
        let v = &sol.x[s.offset..s.offset + plant.stream_layout().len()];
        out!(
            "{:<14} {:>12.4} {:>9.3} {:>10.3} {:>11.4}",
            truncate(&s.name, 14),
            shown[0].value(v[F]),
            shown[1].value(v[T]),
            shown[2].value(v[P]),
            shown[3].value(v[H])
        );
        for z in &v[Z0..] {
            out!(" {:>10.6}", z);
        }
        outln!();
    }
    outln!();
}

/// Each unit's and controller's own variables outside the streams, with their units (SI, or the
/// `--units` system's).
fn print_blocks(plant: &Plant, sol: &Solution, units: Option<UnitSystem>) {
    let slen = plant.stream_layout().len();
    let mut in_stream = vec![false; plant.n_vars()];
    plant.streams().iter().for_each(|s| in_stream[s.offset..s.offset + slen].fill(true));
    let system = units.unwrap_or_default();
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
        let kind = if b.kind == BlockKind::Controller { "controller" } else { "unit" };
        if internal.len() > 12 {
            outln!(
                "{kind} {:<14} {:<10} {} … ({} variables; `--json` lists them all)",
                b.name,
                b.unit.type_name(),
                internal[..6].join("  "),
                internal.len()
            );
        } else if !internal.is_empty() {
            outln!("{kind} {:<14} {:<10} {}", b.name, b.unit.type_name(), internal.join("  "));
        }
    }
}

/// `v` (SI) of dimension `dim` in `system`'s unit, with the unit (none for a dimensionless number).
pub(super) fn shown(v: f64, dim: plantwide::units::Dimension, system: UnitSystem) -> String {
    if dim == plantwide::units::Dimension::DIMENSIONLESS {
        return format!("{v:.6}");
    }
    match Display::new(&system.unit_for(dim)) {
        Ok(d) => format!("{:.6} {}", d.value(v), d.unit()),
        Err(_) => format!("{v:.6} {dim}"),
    }
}

/// Each spec met: the varied input's value found (and the file's), the held variable's value.
fn print_specs(plant: &Plant, sol: &Solution, units: Option<UnitSystem>) {
    // In the `--units` system asked for, as the streams are; else SI.
    let value = |v: f64, dim| units.map_or_else(|| with_unit(v, dim), |u| shown(v, dim, u));
    for s in plant.specs() {
        let (was, dim) = (plant.inputs()[s.input].value, plant.inputs()[s.input].dim);
        outln!(
            "design spec {}: met with `{}` = {} (from {}), `{}` = {}",
            s.origin,
            s.vary,
            value(sol.u[s.input], dim),
            value(was, dim),
            s.path,
            value(sol.x[s.var], plant.vars()[s.var].spec.dim)
        );
    }
    if !plant.specs().is_empty() {
        outln!();
    }
}

/// The steady state as JSON: every variable and free input under its path (SI), the specs met.
fn print_json(
    plant: &Plant,
    sol: &Solution,
    method: MethodArg,
    iterations: usize,
    residual: f64,
) -> Result<(), CliError> {
    let values: serde_json::Map<String, serde_json::Value> =
        sol.values(plant).into_iter().map(|(path, v)| (path, v.into())).collect();
    let out = serde_json::json!({
        "converged": true,
        "method": format!("{method:?}").to_lowercase(),
        "iterations": iterations,
        "residual": residual,
        "sequential_modular": sol.sm,
        "warnings": sol.warnings,
        "specs": specs_json(plant, sol),
        "values": values,
    });
    outln!("{}", serde_json::to_string_pretty(&out).map_err(|e| CliError::user(e.to_string()))?);
    Ok(())
}

/// The specs met: each one's variable, target, varied input and the value found (SI).
fn specs_json(plant: &Plant, sol: &Solution) -> serde_json::Value {
    plant
        .specs()
        .iter()
        .map(|s| {
            serde_json::json!({
                "path": s.path,
                "target": s.target,
                "value": sol.x[s.var],
                "vary": s.vary,
                "input_value": sol.u[s.input],
                "origin": s.origin,
            })
        })
        .collect()
}

fn truncate(s: &str, n: usize) -> String {
    s.chars().take(n).collect()
}
