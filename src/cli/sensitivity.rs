//! `plantwide sensitivity FILE --disturb PATH=-10%:+10% … --outputs Q1,Q2 [--points N] [--csv OUT]
//! [--plot OUT.png|OUT.svg] [--shard I/N [--part FILE]]`: disturbance sweeps with the flowsheet's
//! control structure active. Its tasks are the walks (each disturbance up and down from the base).

use std::path::PathBuf;

use plantwide::analysis::AnalysisError;
use plantwide::analysis::select::{in_system, select_outputs};
use plantwide::analysis::sensitivity::{Disturbance, SweepSettings, Walk, curves, walks};
use plantwide::io::IoError;
use plantwide::io::csv::sensitivity_csv;
use plantwide::io::plot::write_sensitivity;
use plantwide::io::report;
use plantwide::units::UnitSystem;

use super::CliError;
use super::shard::ShardArgs;
use super::steady::{converge, load_with_overrides};

/// Arguments of `plantwide sensitivity`.
#[derive(Debug, clap::Args)]
pub struct SensitivityArgs {
    /// Flowsheet file (JSON).
    file: PathBuf,
    /// A disturbance and its range, `PATH[@unit]=LOW:HIGH` with percentages of the base value or
    /// quantities (`feed_source.F=-10%:+10%`, `feed_source.F=0.9kmol/min:1.1kmol/min`); repeatable.
    #[arg(long = "disturb", value_name = "PATH=LOW:HIGH", required = true)]
    disturb: Vec<String>,
    /// Outputs, comma-separated variable paths, each `PATH[@unit]`.
    #[arg(long, value_delimiter = ',', required = true)]
    outputs: Vec<String>,
    /// Points over each range, ends included (the base case is added).
    #[arg(long, default_value_t = 21)]
    points: usize,
    /// Write the table as CSV here.
    #[arg(long, value_name = "OUT.csv", value_parser = super::output_file)]
    csv: Option<PathBuf>,
    /// Draw the curves into a PNG or SVG file.
    #[arg(long, value_name = "OUT.png|OUT.svg", value_parser = super::output_file)]
    plot: Option<PathBuf>,
    /// Override an input or a unit parameter first.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
    /// Sharding over processes.
    #[command(flatten)]
    pub shard: ShardArgs,
}

fn analysis_error(e: AnalysisError) -> CliError {
    if e.is_user_error() { CliError::user(e.to_string()) } else { CliError::numerical(e.to_string()) }
}

pub fn run(a: &SensitivityArgs, units: UnitSystem) -> Result<(), CliError> {
    // Checked before any work (the plot is drawn last).
    if let Some(p) = &a.plot
        && !matches!(p.extension().and_then(|e| e.to_str()), Some("svg" | "png"))
    {
        return Err(CliError::user("--plot: the file must end in .png or .svg"));
    }
    let (plant, u) = load_with_overrides(&a.file, &a.set)?;
    let disturbances = a
        .disturb
        .iter()
        .map(|d| Disturbance::parse(&plant, &u, d))
        .collect::<Result<Vec<_>, _>>()
        .map_err(analysis_error)?;
    let outputs = select_outputs(&plant, &in_system(&plant, &a.outputs, units)).map_err(analysis_error)?;
    let ss = converge(&plant, &u)?;
    let settings = SweepSettings { points: a.points, ..SweepSettings::default() };
    let idx: Vec<usize> = outputs.iter().map(|s| s.index).collect();
    a.shard.check_merged(2 * disturbances.len())?;
    let share = a.shard.share::<Walk>()?;
    let walks = walks(&plant, &ss.x, &ss.u, &disturbances, &idx, &settings, &share).map_err(analysis_error)?;
    if share.is_shard() {
        let done = walks.iter().enumerate().filter_map(|(t, w)| w.as_ref().map(|w| (t, w)));
        return a.shard.write_part("sensitivity", &a.file, walks.len(), done);
    }
    let walks: Vec<Walk> = walks.into_iter().flatten().collect();
    let base: Vec<f64> = idx.iter().map(|&i| ss.x[i]).collect();
    let curves = curves(&disturbances, settings.points, &base, &walks);
    out!("{}", report::sensitivity::text(plant.name(), &curves, &outputs));
    if let Some(path) = &a.csv {
        std::fs::write(path, sensitivity_csv(&curves, &outputs))
            .map_err(|e| CliError::user(format!("{}: cannot write: {e}", path.display())))?;
        outln!("\nwrote {}", path.display());
    }
    if let Some(path) = &a.plot {
        let title = format!("{}: sensitivity", plant.name());
        write_sensitivity(path, &title, &curves, &outputs).map_err(|e| match e {
            IoError::Draw(_) => CliError::numerical(e.to_string()),
            _ => CliError::user(e.to_string()),
        })?;
        outln!("wrote {}", path.display());
    }
    let failures: Vec<String> = curves.iter().flat_map(|c| &c.failures).map(|f| f.to_string()).collect();
    if !failures.is_empty() {
        let list: Vec<&str> = failures.iter().map(|s| s.as_str()).collect();
        return Err(CliError::numerical(format!("{}: the sweep stopped early: {}", plant.file(), list.join("; "))));
    }
    Ok(())
}
