//! `plantwide screen FILE --column COL --outputs TOP,BOTTOM [--json] [--report DIR]`: the inventory
//! configurations of a column, built through the library and judged by their steady-state gains.

use std::path::{Path, PathBuf};

use plantwide::studies::screen::{ColumnScreen, ScreenError, screen_column};

use super::CliError;
use super::steady::load_with_overrides;

/// Arguments of `plantwide screen`.
#[derive(Debug, clap::Args)]
pub struct ScreenArgs {
    /// Flowsheet file (JSON).
    #[arg(value_name = "FILE")]
    file: PathBuf,
    /// The column whose inventory configurations to screen (LV, DV, LB, DB, (L/D)V, L(V/B), (L/D)(V/B)).
    #[arg(long, value_name = "COL")]
    column: String,
    /// The two qualities, top then bottom (variable paths), e.g. distillate.x[light],bottoms.x[light].
    #[arg(long, value_name = "TOP,BOTTOM", value_delimiter = ',', required = true)]
    outputs: Vec<String>,
    /// Override an input or unit field before converging (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Write a report here: screen.md and screen.json.
    #[arg(long, value_name = "DIR")]
    report: Option<PathBuf>,
}

fn screen_error(e: ScreenError) -> CliError {
    if e.is_user_error() { CliError::user(e.to_string()) } else { CliError::numerical(e.to_string()) }
}

/// Run `plantwide screen`.
pub fn run(a: &ScreenArgs) -> Result<(), CliError> {
    let (plant, _) = load_with_overrides(&a.file, &a.set)?;
    let screen = screen_column(&plant, &a.column, &a.outputs).map_err(screen_error)?;
    let json = serde_json::to_string_pretty(&screen).map_err(|e| CliError::user(e.to_string()))?;
    if let Some(dir) = &a.report {
        write_report(dir, &a.file, &screen, &json)?;
    }
    if a.json {
        outln!("{json}");
    } else {
        outln!("{}", table(&screen, &a.file));
    }
    Ok(())
}

/// The configurations as a markdown table, best first within the regular ones.
fn table(s: &ColumnScreen, file: &Path) -> String {
    let mut t = format!(
        "inventory configurations of column `{}` in {} (qualities {} and {}; gains in SI at the steady state)\n\n",
        s.column,
        file.display(),
        s.outputs[0],
        s.outputs[1]
    );
    t.push_str(
        "| rank | structure | inputs | λ11 | Niederlinski | γ | γ* | verdict |\n|---|---|---|---|---|---|---|---|\n",
    );
    let num = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{v:.4}"));
    for c in &s.structures {
        t.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} |\n",
            c.rank.map_or("–".to_string(), |r| r.to_string()),
            c.name,
            c.inputs.join(", "),
            num(c.rga.as_ref().map(|r| r[0][0])),
            num(c.niederlinski),
            num(c.condition_number),
            num(c.minimized_condition_number),
            c.verdict
        ));
    }
    t
}

fn write_report(dir: &Path, file: &Path, s: &ColumnScreen, json: &str) -> Result<(), CliError> {
    let fail = |e: std::io::Error| CliError::user(format!("--report {}: {e}", dir.display()));
    std::fs::create_dir_all(dir).map_err(fail)?;
    std::fs::write(dir.join("screen.json"), json).map_err(fail)?;
    let md = format!("# Column configurations: `{}`\n\n{}", s.column, table(s, file));
    std::fs::write(dir.join("screen.md"), md).map_err(fail)
}
