//! Dynamic-simulation benchmark: column A, feed step 1 → 1.01 kmol/min, 2000 min
//! (`flowsheets/scenarios/column_a_feed_step.json`), integrated by plantwide's BDF from the
//! converged steady state. Prints the median wall time of repeated runs and the integrator's
//! counters, then one JSON line for `tools/bench_dynamics_peers.py`, which runs the same model and
//! scenario with SciPy, CVODE and CasADi and reports the ratios. Run with
//! `cargo bench --bench dynamics`.
//!
//! The scenario records a row every 2 min (1001 rows); the same run recording only its end
//! (`final_only` in the JSON line) is the work of a peer asked for the final state alone.
//!
//! Beside it, the same scenario on the 82-state ODE the peers integrate (`column_a_ode.rs`:
//! everything but the holdups eliminated by hand), on the same BDF and settings from the plant's
//! steady holdups: the integrator's own cost, and so what the plant's DAE formulation adds.
//!
//! `--serve`: set up once, then answer requests on standard input, one per line, `recorded` or
//! `final`, each with one run of the scenario (recording every 2 min, or the end only) and one
//! JSON line `{"wall_s": …, "xB": …}` on standard output. The peers script alternates these runs
//! with a peer's, so that both sides of a ratio are timed milliseconds apart, in the same phase of
//! a shared machine's speed (on this VM it switches between two speeds a factor of ~2 apart every
//! few seconds).

mod column_a_ode;

use std::io::{BufRead, Write};
use std::time::{Duration, Instant};

use plantwide::flowsheet::load_file;
use plantwide::flowsheet::scenario::{parse_scenario, resolve};
use plantwide::solve::dae::{Bdf, BdfSettings, DaeIntegrator};
use plantwide::solve::dynamic::{SimulationResult, Start, simulate};
use plantwide::solve::{NewtonSettings, steady_state};

/// The number of timed runs: `--repeats N` on the command line (cargo adds `--bench`), else 15.
fn repeats() -> usize {
    let args: Vec<String> = std::env::args().collect();
    let n = args.windows(2).find(|w| w[0] == "--repeats").map(|w| w[1].parse().expect("--repeats takes a count"));
    n.unwrap_or(15).max(1)
}

fn main() {
    let root = env!("CARGO_MANIFEST_DIR");
    let flowsheet = format!("{root}/flowsheets/column_a.json");
    let scenario = format!("{root}/flowsheets/scenarios/column_a_feed_step.json");
    let text = std::fs::read_to_string(&scenario).expect("scenario file");
    let spec = parse_scenario(&text, &scenario).expect("valid scenario");
    let plant = load_file(std::path::Path::new(&flowsheet)).expect("valid flowsheet");
    let x0 = steady_state(&plant, &plant.input_values(), None, &NewtonSettings::default()).expect("steady state").x;
    let once_with = |final_only: bool| -> (Duration, SimulationResult) {
        let mut sc = resolve(&spec, &plant, &scenario).expect("scenario fits the plant");
        if final_only {
            sc.interval = sc.duration;
        }
        let t = Instant::now();
        let res = simulate(&plant, &sc, Start::Steady(&x0), "bench", &mut |_| {}).expect("integration");
        (t.elapsed(), res)
    };
    if std::env::args().any(|a| a == "--serve") {
        serve(&once_with);
        return;
    }
    let median = |final_only: bool| -> (Duration, SimulationResult) {
        let (_, res) = once_with(final_only);
        let mut times: Vec<Duration> = (0..repeats()).map(|_| once_with(final_only).0).collect();
        times.sort();
        (times[times.len() / 2], res)
    };
    let (wall, res) = median(false);
    let (final_wall, final_res) = median(true);
    // Rows just before and after the feed step at t = 0, and at the end.
    assert_eq!(final_res.rows.len(), 3, "recording the end only");
    assert_eq!(final_res.x, res.x, "recording does not change the trajectory");
    let col = |p: &str| {
        res.columns
            .iter()
            .position(|c| c.path == p)
            .map(|k| res.rows.last().map_or(f64::NAN, |r| r[k]))
            .unwrap_or(f64::NAN)
    };
    let ode = ode_run(&plant, &x0, &spec, &scenario);
    let s = res.stats;
    println!("column A feed step, 2000 min, rtol 1e-6, atol 1e-8·nominal ({} variables)", plant.n_vars());
    println!(
        "median wall {wall:.3?}: {} steps, {} residual evaluations, {} Jacobian evaluations, {} LU factorizations, {} error-test failures",
        s.n_steps, s.n_residual_evals, s.n_jacobian_evals, s.n_lu, s.n_error_test_failures
    );
    println!("the same recording the end only: median wall {final_wall:.3?}");
    let o = &ode.stats;
    println!(
        "the same on the peers' 82-state ODE: median wall {:.3?}: {} steps, {} residual evaluations, {} Jacobian evaluations, {} LU factorizations; xB = {:.10}",
        ode.wall, o.n_steps, o.n_residual_evals, o.n_jacobian_evals, o.n_lu, ode.xb
    );
    println!(
        "{{\"wall_s\": {}, \"steps\": {}, \"residual_evals\": {}, \"jacobian_evals\": {}, \"lu\": {}, \"xB\": {}, \"yD\": {}, \"final_only\": {{\"wall_s\": {}}}, \"ode\": {{\"wall_s\": {}, \"steps\": {}, \"residual_evals\": {}, \"jacobian_evals\": {}, \"lu\": {}, \"xB\": {}, \"yD\": {}}}}}",
        wall.as_secs_f64(),
        s.n_steps,
        s.n_residual_evals,
        s.n_jacobian_evals,
        s.n_lu,
        col("bottoms.x[light]"),
        col("distillate.x[light]"),
        final_wall.as_secs_f64(),
        ode.wall.as_secs_f64(),
        o.n_steps,
        o.n_residual_evals,
        o.n_jacobian_evals,
        o.n_lu,
        ode.xb,
        ode.yd
    );
}

/// Answers `recorded` / `final` lines on standard input with one timed run each (see the module
/// documentation) until the input ends; an unknown request ends the process with a message.
fn serve(once_with: &dyn Fn(bool) -> (Duration, SimulationResult)) {
    let stdout = std::io::stdout();
    for line in std::io::stdin().lock().lines() {
        let line = line.expect("standard input");
        let final_only = match line.trim() {
            "recorded" => false,
            "final" => true,
            other => panic!("--serve: unknown request '{other}' (expected 'recorded' or 'final')"),
        };
        let (wall, res) = once_with(final_only);
        let k = res.columns.iter().position(|c| c.path == "bottoms.x[light]").expect("bottoms.x[light] recorded");
        let xb = res.rows.last().map_or(f64::NAN, |r| r[k]);
        let mut out = stdout.lock();
        writeln!(out, "{{\"wall_s\": {}, \"xB\": {}}}", wall.as_secs_f64(), xb).expect("standard output");
        out.flush().expect("standard output");
    }
}

/// The ODE run's median wall time, counters and final compositions.
struct OdeRun {
    wall: Duration,
    stats: plantwide::solve::dae::BdfStats,
    xb: f64,
    yd: f64,
}

/// The scenario (its feed step to 1.01 kmol/min, duration and tolerances) on the peers' ODE from
/// the plant's steady holdups `x0`, median of [`repeats`] runs after one untimed.
fn ode_run(
    plant: &plantwide::flowsheet::Plant,
    x0: &[f64],
    spec: &plantwide::flowsheet::scenario::ScenarioSpec,
    file: &str,
) -> OdeRun {
    let sc = resolve(spec, plant, file).expect("scenario fits the plant");
    let holdup = |s: usize, c: &str| x0[plant.var(format!("column.n[{s}][{c}]")).expect("column A holdup")];
    let n0: Vec<f64> = (1..=41).flat_map(|s| [holdup(s, "light"), holdup(s, "heavy")]).collect();
    let sys = column_a_ode::ColumnOde::new(1.01 * 1000.0 / 60.0);
    let worst = column_a_ode::check_jacobian(&sys, &n0);
    assert!(worst < 1e-6, "hand-derived Jacobian off its central differences by {worst:e}");
    let settings = BdfSettings {
        rtol: sc.rtol,
        atol: sc.atol,
        max_step: sc.max_step,
        first_step: sc.first_step,
        ..BdfSettings::default()
    };
    let once = || {
        let t = Instant::now();
        let mut bdf = Bdf::new(settings.clone());
        bdf.restart(&sys, 0.0, &n0).expect("consistent start");
        while bdf.t() < sc.duration {
            bdf.step(&sys, sc.duration).expect("ODE step");
        }
        (t.elapsed(), bdf)
    };
    let (_, bdf) = once();
    let mut times: Vec<Duration> = (0..repeats()).map(|_| once().0).collect();
    times.sort();
    let x = bdf.x();
    let frac = |i: usize| x[2 * i] / (x[2 * i] + x[2 * i + 1]);
    OdeRun { wall: times[times.len() / 2], stats: bdf.stats(), xb: frac(0), yd: frac(40) }
}
