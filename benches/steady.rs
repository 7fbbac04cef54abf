//! Steady-state benchmark: for every shipped flowsheet, the time of one residual evaluation, one
//! residual + Jacobian evaluation, and a cold-start Newton solve (median of repeated runs).
//! Run with `cargo bench --bench steady`; quote these figures, not test timings.

use std::time::{Duration, Instant};

use plantwide::flowsheet::load_file;
use plantwide::solve::{NewtonSettings, steady_state};

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn time<F: FnMut()>(mut f: F, budget: Duration) -> (Duration, usize) {
    f();
    let mut samples = Vec::new();
    let start = Instant::now();
    while samples.len() < 5 || (start.elapsed() < budget && samples.len() < 10_000) {
        let t = Instant::now();
        f();
        samples.push(t.elapsed());
    }
    let n = samples.len();
    (median(samples), n)
}

fn main() {
    let filter = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/flowsheets");
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .expect("flowsheets/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "json") && !p.to_string_lossy().ends_with(".schema.json"))
        .filter(|p| filter.as_ref().is_none_or(|f| p.to_string_lossy().contains(f.as_str())))
        .collect();
    files.sort();
    println!(
        "{:<32} {:>6} {:>8} {:>12} {:>14} {:>12} {:>6}",
        "flowsheet", "n", "nnz(J)", "residual", "residual+jac", "newton", "iters"
    );
    for f in files {
        let plant = match load_file(&f) {
            Ok(p) => p,
            Err(e) => {
                println!("{}: {e}", f.display());
                continue;
            }
        };
        let u = plant.input_values();
        let x0 = plant.initial_guess();
        let n = plant.n_vars();
        let mut r = vec![0.0; n];
        let (mut jx, mut ju) = (Vec::new(), Vec::new());
        plant.jacobian(&x0, &u, 0.0, &mut r, &mut jx, &mut ju);
        let nnz = jx.len();
        let budget = Duration::from_millis(400);
        let (t_res, _) = time(|| plant.residual(&x0, &u, 0.0, &mut r), budget);
        let (t_jac, _) = time(|| plant.jacobian(&x0, &u, 0.0, &mut r, &mut jx, &mut ju), budget);
        let mut iters: Option<usize> = None;
        let (t_newton, _) = time(
            || match steady_state(&plant, &u, None, &NewtonSettings::default()) {
                Ok(ss) => iters = Some(ss.report.iterations),
                Err(_) => iters = None,
            },
            Duration::from_secs(2),
        );
        let name = f.file_name().map(|s| s.to_string_lossy().to_string()).unwrap_or_default();
        let iters = iters.map_or("failed".to_string(), |k| k.to_string());
        println!("{:<32} {:>6} {:>8} {:>12.3?} {:>14.3?} {:>12.3?} {:>6}", name, n, nnz, t_res, t_jac, t_newton, iters);
    }
}
