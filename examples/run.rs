//! A dynamic scenario on column A: converge, step the feed +1 % (the shipped
//! `flowsheets/scenarios/column_a_feed_step.json`), integrate 2000 min and print the figures of
//! merit of every recorded path (IAE, largest deviation, 2 % settling time), as `plantwide run`
//! summarizes a run.
//!
//! `cargo run --example run`. The bottoms composition settles with a time constant near 200 min
//! (S&P 2005 §12.4: 194 min).

use plantwide::analysis::figures::summary;
use std::path::Path;

use plantwide::flowsheet::load_with;
use plantwide::flowsheet::scenario::{parse_scenario, resolve};
use plantwide::solve::dynamic::{Start, simulate};
use plantwide::solve::{StrategySettings, converge};

fn main() -> anyhow::Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let plant = load_with(&root.join("flowsheets/column_a.json"), &[])?;
    let sol = converge(&plant, &StrategySettings::default())?;
    let name = "flowsheets/scenarios/column_a_feed_step.json";
    let text = std::fs::read_to_string(root.join(name))?;
    let scenario = resolve(&parse_scenario(&text, name)?, &plant, name)?;
    let res = simulate(&plant, &scenario, Start::Steady(&sol.x), "example", &mut |_| {})?;
    println!("{}: {} steps to t = {:.0} min", scenario.name, res.stats.n_steps, res.t / 60.0);
    println!("{:<22} {:>12} {:>12} {:>12} {:>10}", "path (SI units)", "final", "max dev", "IAE [·s]", "settles");
    // The integrated totals of the boundary streams are recorded too; they close the balances.
    for p in summary(&res).into_iter().filter(|p| !p.path.contains(".total[")) {
        let settles = p.settling_time.map_or("-".to_string(), |t| format!("{:.0} min", t / 60.0));
        println!("{:<22} {:>12.6} {:>12.3e} {:>12.3e} {:>10}", p.path, p.last, p.max_deviation, p.iae, settles);
    }
    println!("component balances close to {:.1e} (relative)", res.conservation.worst());
    Ok(())
}
