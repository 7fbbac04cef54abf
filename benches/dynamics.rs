//! Dynamic-simulation benchmark: column A, feed step 1 → 1.01 kmol/min, 2000 min
//! (`flowsheets/scenarios/column_a_feed_step.json`), integrated by plantwide's BDF from the
//! converged steady state. Prints the median wall time of repeated runs and the integrator's
//! counters, then one JSON line for `tools/bench_bdf_scipy.py`, which runs the same model and
//! scenario with SciPy's BDF and reports the ratio. Run with `cargo bench --bench dynamics`.

use std::time::{Duration, Instant};

use plantwide::flowsheet::load_file;
use plantwide::flowsheet::scenario::{parse_scenario, resolve};
use plantwide::solve::dynamic::{SimulationResult, Start, simulate};
use plantwide::solve::{NewtonSettings, steady_state};

fn main() {
    let root = env!("CARGO_MANIFEST_DIR");
    let flowsheet = format!("{root}/flowsheets/column_a.json");
    let scenario = format!("{root}/flowsheets/scenarios/column_a_feed_step.json");
    let text = std::fs::read_to_string(&scenario).expect("scenario file");
    let spec = parse_scenario(&text, &scenario).expect("valid scenario");
    let plant = load_file(std::path::Path::new(&flowsheet)).expect("valid flowsheet");
    let x0 = steady_state(&plant, &plant.input_values(), None, &NewtonSettings::default()).expect("steady state").x;
    let once = || -> (Duration, SimulationResult) {
        let sc = resolve(&spec, &plant, &scenario).expect("scenario fits the plant");
        let t = Instant::now();
        let res = simulate(&plant, &sc, Start::Steady(&x0), "bench", &mut |_| {}).expect("integration");
        (t.elapsed(), res)
    };
    let (_, res) = once();
    let mut times: Vec<Duration> = (0..15).map(|_| once().0).collect();
    times.sort();
    let wall = times[times.len() / 2];
    let col = |p: &str| {
        res.columns
            .iter()
            .position(|c| c.path == p)
            .map(|k| res.rows.last().map_or(f64::NAN, |r| r[k]))
            .unwrap_or(f64::NAN)
    };
    let s = res.stats;
    println!("column A feed step, 2000 min, rtol 1e-6, atol 1e-8·nominal ({} variables)", plant.n_vars());
    println!(
        "median wall {wall:.3?}: {} steps, {} residual evaluations, {} Jacobian evaluations, {} LU factorizations, {} error-test failures",
        s.n_steps, s.n_residual_evals, s.n_jacobian_evals, s.n_lu, s.n_error_test_failures
    );
    println!(
        "{{\"wall_s\": {}, \"steps\": {}, \"residual_evals\": {}, \"jacobian_evals\": {}, \"lu\": {}, \"xB\": {}, \"yD\": {}}}",
        wall.as_secs_f64(),
        s.n_steps,
        s.n_residual_evals,
        s.n_jacobian_evals,
        s.n_lu,
        col("bottoms.x[light]"),
        col("distillate.x[light]")
    );
}
