//! The `plantwide` command line. Exit codes: 0 success, 1 user error (bad input, bad file),
//! 2 numerical failure (no convergence).

mod cli;

use plantwide as _;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", e.message);
            ExitCode::from(e.code)
        }
    }
}
