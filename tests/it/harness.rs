//! The shared harness of the integration tests: the `plantwide` binary as a command, the paths of
//! the shipped flowsheets and of the test fixtures, and the checks several test modules make (load
//! and converge a shipped flowsheet, read values by path, conservation around every unit).

use std::process::{Command, Output};

use plantwide::flowsheet::{BlockKind, Plant, load_file};
use plantwide::model::stream::{F, Z0};
use plantwide::solve::{NewtonSettings, SteadyState, steady_state};

/// The repository root (the root package's manifest directory).
pub const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The `plantwide` binary built for these tests, as a command to add arguments to.
pub fn command() -> Command {
    Command::new(env!("CARGO_BIN_EXE_plantwide"))
}

/// Run `plantwide ARGS` to completion and return its exit status and output.
pub fn plantwide(args: &[&str]) -> Output {
    command().args(args).output().expect("the plantwide binary runs")
}

/// Path of a shipped flowsheet (`flowsheets/NAME`).
pub fn flowsheet(name: &str) -> String {
    format!("{ROOT}/flowsheets/{name}")
}

/// Path of a test fixture (`tests/NAME`: `data/…`, `broken/…`, `hostile/…`).
pub fn fixture(name: &str) -> String {
    format!("{ROOT}/tests/{name}")
}

/// Load and converge a shipped flowsheet from a cold start.
pub fn converge(name: &str) -> (Plant, SteadyState) {
    let plant = load_file(std::path::Path::new(&flowsheet(name))).unwrap_or_else(|e| panic!("{e}"));
    let u = plant.input_values();
    let ss = steady_state(&plant, &u, None, &NewtonSettings::default()).unwrap_or_else(|e| panic!("{e}"));
    (plant, ss)
}

/// Value of the variable at `path`.
pub fn value(plant: &Plant, x: &[f64], path: &str) -> f64 {
    x[plant.var(path).unwrap_or_else(|| panic!("no variable {path}"))]
}

/// Largest relative component-balance error `|Σ in F z − Σ out F z| / Σ in F z` over all process
/// units except those listed in `generating` (reactors), and over the plant as a whole.
pub fn component_balance_error(plant: &Plant, x: &[f64], generating: &[&str]) -> f64 {
    let nc = plant.components().len();
    let width = plant.stream_layout().len();
    let mut worst: f64 = 0.0;
    let flows = |s: &plantwide::flowsheet::StreamInfo| -> Vec<f64> {
        let v = &x[s.offset..s.offset + width];
        (0..nc).map(|j| v[F] * v[Z0 + j]).collect()
    };
    for (bi, b) in plant.blocks().iter().enumerate() {
        if b.kind != BlockKind::Unit
            || b.layout.n_inlets == 0
            || b.layout.n_outlets == 0
            || generating.contains(&b.name.as_str())
        {
            continue;
        }
        let mut inn = vec![0.0; nc];
        let mut out = vec![0.0; nc];
        for s in plant.streams() {
            if s.to.0 == bi {
                inn.iter_mut().zip(flows(s)).for_each(|(a, b)| *a += b);
            }
            if s.from.0 == bi {
                out.iter_mut().zip(flows(s)).for_each(|(a, b)| *a += b);
            }
        }
        let total: f64 = inn.iter().sum();
        for j in 0..nc {
            worst = worst.max((inn[j] - out[j]).abs() / total.max(1e-300));
        }
    }
    worst
}

/// Print to the real stderr (not captured by the test harness: a campaign's summary always shows).
pub fn say(line: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "{line}");
}

/// An environment variable read as a count or a seed (decimal or `0x` hex); a value that is not a
/// number fails the test naming it.
pub fn env_u64(name: &str) -> Option<u64> {
    let v = std::env::var(name).ok()?;
    let v = v.trim();
    match v.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(hex, 16).ok(),
        None => v.parse().ok(),
    }
    .or_else(|| panic!("{name}={v}: not a number"))
}
