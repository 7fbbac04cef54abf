//! `plantwide steady FILE [--json] [--set PATH=VALUE ...] [--spec PATH=VALUE --vary INPUT ...]
//! [--method eo|sm|auto] [--units si|metric|field]`: the text shows every quantity with its unit
//! (SI, or the `--units` system's); JSON stays in SI.

use std::path::Path;

use plantwide::flowsheet::{Plant, SpecEntry};
use plantwide::io::report;
use plantwide::solve::{Method, Progress, Solution, StrategySettings, converge_observed};
use plantwide::units::UnitSystem;

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
            eprintln!("note: design spec {label} met: `{vary}` = {}", report::steady::with_unit(sol.u[input], dim));
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
    /// otherwise whole-plant Newton, started from a sequential-modular pass if it has not converged
    /// from the cold start within 20 iterations.
    Auto,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Method {
        match m {
            MethodArg::Eo => Method::Eo,
            MethodArg::Sm => Method::Sm,
            MethodArg::Auto => Method::Auto,
        }
    }
}

/// Converge by `method` with a progress spinner on stderr (hidden when stderr is not a terminal),
/// mapping failures to exit codes.
pub fn converge_by(plant: &Plant, u: &[f64], method: MethodArg) -> Result<Solution, CliError> {
    let method = Method::from(method);
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
    let mut plant = load_plant(a.file, a.sets)?;
    add_specs(&mut plant, a.specs, a.vary)?;
    let u = plant.input_values();
    let sol = converge_by(&plant, &u, a.method)?;
    if a.json {
        let text = report::steady::json(&plant, &sol, a.method.into()).map_err(|e| CliError::user(e.to_string()))?;
        outln!("{text}");
        return Ok(());
    }
    out!("{}", report::steady::text(&plant, &sol, a.units));
    Ok(())
}
