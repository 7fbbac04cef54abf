//! The `plantwide` command line. Exit codes: 0 success, 1 user error (bad input, bad file),
//! 2 numerical failure (no convergence).

mod cli;
mod serve;

use plantwide as _;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    // A malformed command line is a user error (exit 1), not clap's default 2, which here means
    // a numerical failure; --help and --version print and succeed.
    let args = match cli::Cli::try_parse() {
        Ok(args) => args,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() { ExitCode::from(1) } else { ExitCode::SUCCESS };
        }
    };
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", cli::library_flags(e.message));
            ExitCode::from(e.code)
        }
    }
}
