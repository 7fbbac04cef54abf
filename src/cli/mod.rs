//! Subcommands of the `plantwide` binary.

/// `print!` that ends the process quietly when stdout is closed (e.g. piped into `head`).
macro_rules! out {
    ($($t:tt)*) => { $crate::cli::write_out(format_args!($($t)*)) };
}

/// `println!` that ends the process quietly when stdout is closed.
macro_rules! outln {
    () => { $crate::cli::write_out(format_args!("\n")) };
    ($($t:tt)*) => {{ $crate::cli::write_out(format_args!($($t)*)); $crate::cli::write_out(format_args!("\n")) }};
}

/// Write to stdout; a closed pipe ends the process with success (the reader has what it wanted).
pub fn write_out(args: std::fmt::Arguments<'_>) {
    use std::io::Write;
    if std::io::stdout().lock().write_fmt(args).is_err() {
        std::process::exit(0);
    }
}

mod check;
mod components;
mod steady;

use std::path::PathBuf;

use clap::{Parser, Subcommand};

/// Plantwide process-control studies: flowsheets, steady state, dynamics and control analysis.
#[derive(Debug, Parser)]
#[command(version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Validate a flowsheet and summarize it: components, units, streams, controllers, degrees of
    /// freedom, recycles.
    Check {
        /// Flowsheet file (JSON).
        file: PathBuf,
    },
    /// List the built-in component library.
    Components {
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Converge the plant to steady state and print streams and units.
    Steady {
        /// Flowsheet file (JSON).
        file: PathBuf,
        /// Print a JSON object with every variable under its path (SI units).
        #[arg(long)]
        json: bool,
        /// Override an input or a unit parameter for this run, e.g. `--set feed.F=1.01kmol/min`.
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<String>,
    },
    /// Print the JSON Schema of flowsheet files (the shipped flowsheets/plantwide.schema.json).
    Schema,
}

/// A failed command: message and exit code.
#[derive(Debug)]
pub struct CliError {
    /// One-paragraph message.
    pub message: String,
    /// 1 user error, 2 numerical failure.
    pub code: u8,
}

impl CliError {
    fn user(message: impl Into<String>) -> CliError {
        CliError { message: message.into(), code: 1 }
    }
    fn numerical(message: impl Into<String>) -> CliError {
        CliError { message: message.into(), code: 2 }
    }
}

/// Run a parsed command line.
pub fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Check { file } => check::run(&file),
        Command::Components { json } => components::run(json),
        Command::Steady { file, json, set } => steady::run(&file, json, &set),
        Command::Schema => {
            let schema = schemars::schema_for!(plantwide::flowsheet::FlowsheetSpec);
            let text = serde_json::to_string_pretty(&schema).map_err(|e| CliError::user(e.to_string()))?;
            outln!("{text}");
            Ok(())
        }
    }
}
