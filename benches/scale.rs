//! Scale benchmark in one process, the `cargo bench` twin of `tools/bench_scale.py`: a train of N
//! independent copies of Skogestad's column A (built from `flowsheets/column_a.json` as
//! `tools/column_train.py` builds it: names suffixed `_k`), timed per N for
//! - `load`: parse and assemble the flowsheet (what `plantwide check` does before printing),
//! - `steady`: the steady state from the initial guess,
//! - `run`: 60 min after copy 1's feed steps 1 → 1.01 kmol/min (rtol 1e-6, atol 1e-8),
//! - `gains`: column 1's 2 × 2 steady-state gains (L, V → yD, xB) by linearization,
//!
//! then the exponent b of time ∝ N^b fitted over 16 ≤ N ≤ 128 (the sizes run). Sizes 1 … 64 by
//! default; `PLANTWIDE_SCALE_SIZES=1,2,4,...,256` for more. Peak memory is per process and is
//! measured by the tools script, not here. Prints a table, then one JSON line.
//! Run with `cargo bench --bench scale`.

use std::time::Instant;

use plantwide::analysis::linear::Linearization;
use plantwide::analysis::select::{select_inputs, select_outputs};
use plantwide::flowsheet::load_str;
use plantwide::flowsheet::scenario::{parse_scenario, resolve};
use plantwide::solve::dynamic::{Start, simulate};
use plantwide::solve::{NewtonSettings, steady_state};
use serde_json::{Map, Value, json};

/// Unit and stream names of column A and their names in copy k (`tools/column_train.py`).
const UNITS: [(&str, &str); 4] =
    [("feed_source", "feed"), ("column", "column"), ("top_product", "top"), ("bottom_product", "bottom")];
const STREAMS: [(&str, &str); 3] = [("feed", "feed_stream"), ("distillate", "distillate"), ("bottoms", "bottoms")];

/// `column.feed` → `column_k.feed`.
fn rename(port: &str, k: usize) -> String {
    let (unit, rest) = port.split_once('.').map_or((port, None), |(u, r)| (u, Some(r)));
    let base = UNITS.iter().find(|(from, _)| *from == unit).map_or(unit, |(_, to)| to);
    rest.map_or(format!("{base}_{k}"), |r| format!("{base}_{k}.{r}"))
}

/// The train of `n` copies as flowsheet JSON.
fn train(base: &Value, n: usize) -> String {
    let (mut units, mut streams, mut controllers) = (Map::new(), Map::new(), Map::new());
    for k in 1..=n {
        for (from, to) in UNITS {
            units.insert(format!("{to}_{k}"), base["units"][from].clone());
        }
        for (from, to) in STREAMS {
            let mut s = base["streams"][from].clone();
            for key in ["from", "to"] {
                s[key] = json!(rename(s[key].as_str().unwrap_or_default(), k));
            }
            streams.insert(format!("{to}_{k}"), s);
        }
        for (name, c) in base["controllers"].as_object().into_iter().flatten() {
            let mut c = c.clone();
            for key in ["pv", "output"] {
                c[key] = json!(rename(c[key].as_str().unwrap_or_default(), k));
            }
            controllers.insert(format!("{name}_{k}"), c);
        }
    }
    json!({"format_version": 1, "name": format!("column_a_train_{n}"), "components": base["components"],
           "thermo": base["thermo"], "units": units, "streams": streams, "controllers": controllers})
    .to_string()
}

const SCENARIO: &str = r#"{"format_version": 1, "duration": "60 min", "integrator": {"rtol": 1e-6, "atol": 1e-8},
  "events": [{"type": "step", "at": "0 min", "path": "feed_1.F", "to": "1.01 kmol/min"}],
  "record": {"interval": "1 min", "time_unit": "min", "paths": ["bottoms_1.x[light]", "distillate_1.x[light]"]}}"#;

/// Seconds of `load`, `steady`, `run`, `gains` for the train of `n`, and its variable count.
fn measure(base: &Value, n: usize) -> (usize, [f64; 4]) {
    let text = train(base, n);
    let t = Instant::now();
    let plant = load_str(&text, "train.json").expect("the train loads");
    let load = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let ss = steady_state(&plant, &plant.input_values(), None, &NewtonSettings::default()).expect("steady state");
    let steady = t.elapsed().as_secs_f64();
    let spec = parse_scenario(SCENARIO, "train_scenario.json").expect("scenario");
    let sc = resolve(&spec, &plant, "train_scenario.json").expect("scenario fits");
    let t = Instant::now();
    simulate(&plant, &sc, Start::Steady(&ss.x), "bench", &mut |_| {}).expect("run");
    let run = t.elapsed().as_secs_f64();
    let strings = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let ins = select_inputs(&plant, &strings(&["column_1.reflux", "column_1.boilup"])).expect("inputs");
    let outs = select_outputs(&plant, &strings(&["distillate_1.x[light]", "bottoms_1.x[light]"])).expect("outputs");
    let (ii, oo): (Vec<usize>, Vec<usize>) =
        (ins.iter().map(|s| s.index).collect(), outs.iter().map(|s| s.index).collect());
    let t = Instant::now();
    Linearization::new(&plant, &ss.x, &ss.u).steady_gain(&ii, &oo).expect("gains");
    let gains = t.elapsed().as_secs_f64();
    (plant.n_vars(), [load, steady, run, gains])
}

/// Least-squares slope of ln t against ln N over the points with 16 ≤ N ≤ 128.
fn exponent(points: &[(usize, f64)]) -> Option<f64> {
    let p: Vec<(f64, f64)> =
        points.iter().filter(|(n, _)| (16..=128).contains(n)).map(|&(n, t)| ((n as f64).ln(), t.ln())).collect();
    if p.len() < 2 {
        return None;
    }
    let (mx, my) =
        (p.iter().map(|a| a.0).sum::<f64>() / p.len() as f64, p.iter().map(|a| a.1).sum::<f64>() / p.len() as f64);
    let sxy: f64 = p.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = p.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    Some(sxy / sxx)
}

fn main() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/flowsheets/column_a.json");
    let base: Value = serde_json::from_str(&std::fs::read_to_string(path).expect("column_a.json")).expect("JSON");
    let sizes: Vec<usize> = std::env::var("PLANTWIDE_SCALE_SIZES")
        .ok()
        .map(|s| s.split(',').filter_map(|v| v.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![1, 2, 4, 8, 16, 32, 64]);
    println!(
        "{:>5} {:>9} {:>10} {:>10} {:>10} {:>10}",
        "N", "variables", "load [s]", "steady [s]", "run [s]", "gains [s]"
    );
    let mut rows = Vec::new();
    for &n in &sizes {
        let (vars, t) = measure(&base, n);
        println!("{n:>5} {vars:>9} {:>10.4} {:>10.4} {:>10.4} {:>10.4}", t[0], t[1], t[2], t[3]);
        rows.push((n, vars, t));
    }
    let fit = |k: usize| exponent(&rows.iter().map(|&(n, _, t)| (n, t[k])).collect::<Vec<_>>());
    let both = exponent(&rows.iter().map(|&(n, _, t)| (n, t[1] + t[2])).collect::<Vec<_>>());
    let results: Vec<Value> = rows
        .iter()
        .map(|&(n, vars, t)| json!({"n": n, "variables": vars, "load_s": t[0], "steady_s": t[1], "run_s": t[2], "gains_s": t[3]}))
        .collect();
    let line = json!({"benchmark": "column_a_train_in_process", "results": results,
        "exponent_16_128": {"load": fit(0), "steady": fit(1), "run": fit(2), "gains": fit(3), "steady_run": both}});
    println!("{line}");
}
