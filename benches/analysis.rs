//! Control-analysis benchmark: steady-state gains by linearization (one Jacobian, one sparse LU)
//! and by perturbation (2 re-converged steady states per input, in parallel), the state-space
//! elimination with its eigenvalues, and a 50-point frequency response — median of repeated runs.
//! Run with `cargo bench --bench analysis`; quote these figures, not test timings.
//!
//! Cases: column A (L, V → yD, xB) and, when the flowsheet is present, the reactor/column recycle
//! plant (fresh feed → recycle flow and reactor composition).

use std::time::{Duration, Instant};

use plantwide::analysis::linear::Linearization;
use plantwide::analysis::perturb::{PerturbSettings, perturb_gains};
use plantwide::analysis::select::{select_inputs, select_outputs};
use plantwide::flowsheet::load_file;
use plantwide::solve::{NewtonSettings, steady_state};

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn time<F: FnMut()>(mut f: F, budget: Duration) -> Duration {
    f();
    let mut samples = Vec::new();
    let start = Instant::now();
    while samples.len() < 5 || (start.elapsed() < budget && samples.len() < 10_000) {
        let t = Instant::now();
        f();
        samples.push(t.elapsed());
    }
    median(samples)
}

fn main() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/flowsheets");
    let cases: [(&str, &[&str], &[&str]); 2] = [
        ("column_a.json", &["column.reflux", "column.boilup"], &["distillate.x[light]", "bottoms.x[light]"]),
        ("reactor_column_recycle.json", &["fresh.F"], &["recycle.F", "effluent.x[A]"]),
    ];
    println!(
        "{:<30} {:>5} {:>7} {:>12} {:>12} {:>8} {:>14} {:>12} {:>10}",
        "flowsheet", "n", "states", "linear", "perturb", "ratio", "state space", "G(jω)×50", "max diff"
    );
    for (file, inputs, outputs) in cases {
        let path = std::path::Path::new(dir).join(file);
        if !path.exists() {
            println!("{file:<30} (not present)");
            continue;
        }
        let plant = match load_file(&path) {
            Ok(p) => p,
            Err(e) => {
                println!("{file:<30} {e}");
                continue;
            }
        };
        let ss = match steady_state(&plant, &plant.input_values(), None, &NewtonSettings::default()) {
            Ok(ss) => ss,
            Err(e) => {
                println!("{file:<30} {e}");
                continue;
            }
        };
        let to_strings = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let (ins, outs) =
            match (select_inputs(&plant, &to_strings(inputs)), select_outputs(&plant, &to_strings(outputs))) {
                (Ok(i), Ok(o)) => (i, o),
                (Err(e), _) | (_, Err(e)) => {
                    println!("{file:<30} {e}");
                    continue;
                }
            };
        let ii: Vec<usize> = ins.iter().map(|s| s.index).collect();
        let oo: Vec<usize> = outs.iter().map(|s| s.index).collect();
        let budget = Duration::from_secs(2);
        let mut g_lin = None;
        let t_lin = time(|| g_lin = Linearization::new(&plant, &ss.x, &ss.u).steady_gain(&ii, &oo).ok(), budget);
        let mut g_pert = None;
        let settings = PerturbSettings::default();
        let t_pert =
            time(|| g_pert = perturb_gains(&plant, &ss.x, &ss.u, &ii, &oo, &settings).ok().map(|p| p.gain), budget);
        let lin = Linearization::new(&plant, &ss.x, &ss.u);
        let mut n_states = 0;
        let t_ss = time(
            || {
                if let Ok(m) = lin.state_space(&ii, &oo) {
                    n_states = m.states.len();
                    let _ = m.eigenvalues();
                }
            },
            budget,
        );
        let omegas: Vec<f64> = (0..50).map(|k| 1e-5 * 10f64.powf(k as f64 / 10.0)).collect();
        let t_freq = time(
            || {
                let _ = lin.frequency_response(&ii, &oo, &omegas);
            },
            budget,
        );
        let diff = match (&g_lin, &g_pert) {
            (Some(a), Some(b)) => {
                let mut worst: f64 = 0.0;
                for i in 0..a.nrows() {
                    for j in 0..a.ncols() {
                        worst = worst.max((a[(i, j)] - b[(i, j)]).abs() / a[(i, j)].abs().max(f64::MIN_POSITIVE));
                    }
                }
                format!("{worst:.1e}")
            }
            _ => "failed".to_string(),
        };
        println!(
            "{:<30} {:>5} {:>7} {:>12.3?} {:>12.3?} {:>8.0} {:>14.3?} {:>12.3?} {:>10}",
            file,
            plant.n_vars(),
            n_states,
            t_lin,
            t_pert,
            t_pert.as_secs_f64() / t_lin.as_secs_f64(),
            t_ss,
            t_freq,
            diff
        );
    }
}
