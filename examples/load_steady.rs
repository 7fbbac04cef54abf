//! Load a shipped flowsheet with an override, converge it the way `plantwide steady` does and
//! print its streams.
//!
//! `cargo run --example load_steady [FILE [PATH=VALUE ...]]`; by default column A
//! (`flowsheets/column_a.json`) with its feed raised 1 % (`feed_source.F=1.01 kmol/min`).

use std::path::PathBuf;

use plantwide::flowsheet::{Override, load_with};
use plantwide::model::stream::{F, T, Z0};
use plantwide::solve::{StrategySettings, converge};

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let file = args
        .next()
        .map_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("flowsheets/column_a.json"), PathBuf::from);
    let mut overrides = args.map(|a| a.parse()).collect::<Result<Vec<Override>, _>>()?;
    if overrides.is_empty() {
        overrides.push(Override::new("feed_source.F", "1.01 kmol/min"));
    }
    let plant = load_with(&file, &overrides)?;
    // Sequential-modular pass on the recycles (if any), then whole-plant Newton.
    let sol = converge(&plant, &StrategySettings::default())?;
    println!("steady state of `{}` with {overrides:?}", plant.name());
    print!("{:<14} {:>12} {:>9}", "stream", "F [kmol/h]", "T [K]");
    for c in plant.components() {
        print!(" {:>10}", format!("x[{c}]"));
    }
    println!();
    let width = plant.stream_layout().len();
    for s in plant.streams() {
        let v = &sol.x[s.offset..s.offset + width];
        print!("{:<14} {:>12.4} {:>9.3}", s.name, v[F] * 3.6, v[T]);
        for z in &v[Z0..] {
            print!(" {z:>10.6}");
        }
        println!();
    }
    Ok(())
}
