//! `plantwide steady FILE [--json] [--set PATH=VALUE ...] [--method eo|sm|auto]`.

use std::path::Path;

use plantwide::flowsheet::{BlockKind, Plant};
use plantwide::model::stream::{F, H, P, T, Z0};
use plantwide::solve::{Method, Progress, Solution, StrategySettings, converge_observed};

use super::CliError;

/// Load `file`, apply `--set` overrides, return the plant and its input vector.
pub fn load_with_overrides(file: &Path, sets: &[String]) -> Result<(Plant, Vec<f64>), CliError> {
    let user = |e: plantwide::flowsheet::OverrideError| CliError::user(e.to_string());
    let overrides = sets.iter().map(|s| s.parse()).collect::<Result<Vec<_>, _>>().map_err(user)?;
    let plant = plantwide::flowsheet::load_with(file, &overrides).map_err(user)?;
    let u = plant.input_values();
    Ok((plant, u))
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
    result
        .map_err(|e| if e.is_user_error() { CliError::user(e.to_string()) } else { CliError::numerical(e.to_string()) })
}

pub fn run(file: &Path, json: bool, sets: &[String], method: MethodArg) -> Result<(), CliError> {
    let (plant, u) = load_with_overrides(file, sets)?;
    let sol = converge_by(&plant, &u, method)?;
    let (iterations, residual) = match (&sol.newton, &sol.sm) {
        (Some(n), _) => (n.iterations, n.residual),
        (None, Some(sm)) => (0, sm.sccs.iter().map(|s| s.residual).fold(0.0, f64::max)),
        (None, None) => (0, 0.0),
    };
    if json {
        let mut values = serde_json::Map::new();
        for (v, x) in plant.vars().iter().zip(&sol.x) {
            values.insert(v.path.clone(), (*x).into());
        }
        for (i, x) in plant.inputs().iter().zip(&sol.u) {
            if i.driven_by.is_none() {
                values.insert(i.path.clone(), (*x).into());
            }
        }
        let out = serde_json::json!({
            "converged": true,
            "method": format!("{method:?}").to_lowercase(),
            "iterations": iterations,
            "residual": residual,
            "sequential_modular": sol.sm,
            "warnings": sol.warnings,
            "values": values,
        });
        outln!("{}", serde_json::to_string_pretty(&out).map_err(|e| CliError::user(e.to_string()))?);
        return Ok(());
    }
    if let Some(sm) = &sol.sm {
        sm.log().iter().for_each(|l| outln!("{l}"));
    }
    if let Some(why) = &sol.sm_failure {
        outln!("sequential-modular start incomplete ({why}); Newton took over");
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
    let comps = plant.components();
    out!("{:<14} {:>12} {:>9} {:>10} {:>11}", "stream", "F kmol/h", "T K", "P kPa", "h kJ/mol");
    for c in comps {
        out!(" {:>10}", format!("x[{}]", truncate(c, 7)));
    }
    outln!();
    for s in plant.streams() {
        let v = &sol.x[s.offset..s.offset + plant.stream_layout().len()];
        out!(
            "{:<14} {:>12.4} {:>9.3} {:>10.3} {:>11.4}",
            truncate(&s.name, 14),
            v[F] * 3.6,
            v[T],
            v[P] / 1e3,
            v[H] / 1e3
        );
        for z in &v[Z0..] {
            out!(" {:>10.6}", z);
        }
        outln!();
    }
    outln!();
    let slen = plant.stream_layout().len();
    let mut in_stream = vec![false; plant.n_vars()];
    plant.streams().iter().for_each(|s| in_stream[s.offset..s.offset + slen].fill(true));
    for b in plant.blocks() {
        let own = b.own_offset..b.own_offset + b.layout.n_own();
        let prefix = format!("{}.", b.name);
        let internal: Vec<String> = own
            .filter(|&j| !in_stream[j])
            .map(|j| format!("{}={:.6}", plant.vars()[j].path.trim_start_matches(&prefix), sol.x[j]))
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
    Ok(())
}

fn truncate(s: &str, n: usize) -> String {
    s.chars().take(n).collect()
}
