//! Recycle benchmark: passes and time of the sequential-modular pass with each accelerator (direct
//! substitution, Wegstein, Broyden), of the whole-plant Newton (EO) and of `auto`, from the cold
//! start, on the shipped recycle plants at the nominal point and at +20 % fresh feed (median of
//! repeated runs). Run with `cargo bench --bench recycle`; quote these figures, not test timings.

use std::time::{Duration, Instant};

use plantwide::flowsheet::load_file;
use plantwide::solve::sequential::{
    Accelerator, Method, SmSettings, StrategySettings, solve_sequential, steady_state_by,
};
use plantwide::solve::{NewtonSettings, steady_state};

/// One lbmol/h in mol/s.
const LBMOL_H: f64 = 453.592_37 / 3600.0;

/// A shipped recycle plant: flowsheet, label of the +20 % case, and the inputs it sets [SI].
type Case = (&'static str, &'static str, &'static [(&'static str, f64)]);

const CASES: &[Case] = &[
    ("reactor_column_recycle.json", "F0 +20 %", &[("F0", 1.2 * 239.5 * LBMOL_H)]),
    (
        "reactor_column_recycle_fixed_effluent.json",
        "F, level sp +20 %",
        &[("F", 1.2 * 500.0 * LBMOL_H), ("reactor_level.sp", 1.2 * 3.0)],
    ),
    ("flash_vapour_liquid_recycle.json", "F0 +20 %", &[("F0", 1.2 * 100.0 / 3.6)]),
    ("flash_recycle.json", "feed +20 %", &[("fresh.F", 1.2 * 100.0 / 3.6)]),
];

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

/// Median time of `f` (after one warm-up run) and the count it reports.
fn time<F: FnMut() -> String>(mut f: F, budget: Duration) -> (Duration, String) {
    let count = f();
    let mut samples = Vec::new();
    let start = Instant::now();
    while samples.len() < 3 || (start.elapsed() < budget && samples.len() < 1000) {
        let t = Instant::now();
        f();
        samples.push(t.elapsed());
    }
    (median(samples), count)
}

fn main() {
    let filter = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/flowsheets");
    println!(
        "{:<44} {:<18} {:>16} {:>16} {:>16} {:>14} {:>14} {:>7}",
        "flowsheet", "point", "direct", "Wegstein", "Broyden", "EO Newton", "auto", "gain"
    );
    println!(
        "{:<44} {:<18} {:>16} {:>16} {:>16} {:>14} {:>14}",
        "", "", "passes  time", "passes  time", "passes  time", "iters  time", "time"
    );
    for (file, label, sets) in CASES {
        if filter.as_ref().is_some_and(|f| !file.contains(f.as_str())) {
            continue;
        }
        let plant = match load_file(std::path::Path::new(&format!("{dir}/{file}"))) {
            Ok(p) => p,
            Err(e) => {
                println!("{file}: {e}");
                continue;
            }
        };
        for (point, sets) in [("nominal", &[][..]), (*label, *sets)] {
            let mut u = plant.input_values();
            for (path, v) in sets {
                match plant.input(path) {
                    Some(i) => u[i] = *v,
                    None => println!("{file}: no input {path}"),
                }
            }
            let budget = Duration::from_millis(1500);
            let mut gain = f64::NAN;
            let mut cells = Vec::new();
            for m in [Accelerator::Direct, Accelerator::Wegstein, Accelerator::Broyden] {
                let settings = SmSettings { accelerator: m, ..SmSettings::default() };
                let (t, passes) = time(
                    || match solve_sequential(&plant, &u, None, &settings) {
                        Ok(sol) => {
                            gain = sol.report.sccs.iter().filter_map(|s| s.loop_gain).fold(0.0, f64::max);
                            sol.report.passes().to_string()
                        }
                        Err(_) => "fail".into(),
                    },
                    budget,
                );
                cells.push(format!("{passes:>6} {t:>9.2?}"));
            }
            let (t_eo, iters) = time(
                || match steady_state(&plant, &u, None, &NewtonSettings::default()) {
                    Ok(ss) => ss.report.iterations.to_string(),
                    Err(_) => "fail".into(),
                },
                budget,
            );
            let auto = StrategySettings { method: Method::Auto, ..StrategySettings::default() };
            let (t_auto, ok) = time(
                || steady_state_by(&plant, &u, &auto, &mut |_| {}).map_or("fail".into(), |_| String::new()),
                budget,
            );
            println!(
                "{:<44} {:<18} {:>16} {:>16} {:>16} {:>5} {:>8.2?} {:>14} {:>7.3}",
                file,
                point,
                cells[0],
                cells[1],
                cells[2],
                iters,
                t_eo,
                if ok.is_empty() { format!("{t_auto:.2?}") } else { ok },
                gain
            );
        }
    }
}
