//! The Newell–Lee evaporator written as one `equations` unit (`flowsheets/evaporator.json`, issue
//! 57) against an independent SciPy implementation of the paper's equations
//! (`tools/evaporator_scipy.py`, its numbers in `tests/data/evaporator/scipy.json`, in the paper's
//! units: kg/min, %, kPa, °C, kW, m, min, $/h): the steady state at the economic optimum of
//! Kariwala, Cao & Janardhanan (2008), a +10 % feed step with both PI loops closed, and the
//! closed-loop steady-state gains. Each comparison is also run against the same file with UA2 moved
//! by 1.5e-6 (relative), which must fail it: the tolerances discriminate.

use crate::harness::{fixture, flowsheet, plantwide};

/// Steady state: Newton's answer against `root(hybr)` at 1e-14, both at rounding level
/// (measured 1e-15); 1e-8 relative is the accuracy the issue asks of a steady state.
const STEADY_RTOL: f64 = 1e-8;
/// Trajectory: the scenario integrates at rtol 1e-10, SciPy's Radau at rtol 1e-10 and atol 1e-12,
/// so each carries a global error of order 1e-9 (measured worst 9e-9, the cost, a difference of
/// terms twenty times its size); 1e-7 leaves a factor of ten for the integrators and is still
/// below what a 1e-6 model error moves (2e-6 in P2).
const TRAJECTORY_RTOL: f64 = 1e-7;
/// Gains: the reference is exact to rounding (implicit-function theorem with complex-step
/// partials; SciPy's central differences of the nonlinear steady solve agree to 1.2e-8 of each
/// row's largest gain); plantwide's linearisation uses exact Jacobians (measured 3e-12), its
/// perturbation gains are Richardson-checked (measured 4e-10). Compared
/// relative to each output row's largest gain, because some gains are zero (the closed loops hold
/// X2 and L2) and the cost's gains to F1 and F200 vanish at the optimum.
const GAINS_RTOL: f64 = 1e-8;

/// The path of each reference variable in the flowsheet, its SI value from the paper's unit.
const VARIABLES: [(&str, &str); 15] = [
    ("L2", "evaporator.L2"),
    ("X2", "evaporator.X2"),
    ("P2", "evaporator.P2"),
    ("T2", "evaporator.T2"),
    ("T3", "evaporator.T3"),
    ("T100", "evaporator.T100"),
    ("Q100", "evaporator.Q100"),
    ("F100", "evaporator.F100"),
    ("F4", "evaporator.F4"),
    ("Q200", "evaporator.Q200"),
    ("T201", "evaporator.T201"),
    ("F5", "evaporator.F5"),
    ("F2", "x2_control.op"),
    ("F3", "level_control.op"),
    ("cost", "cost.value"),
];

/// The SI value of the paper-unit `value` of the reference variable `name`.
fn si(name: &str, value: f64) -> f64 {
    match name.as_bytes()[0] {
        b'L' => value,                         // m
        b'X' => value / 100.0,                 // %
        b'P' => value * 1e3,                   // kPa
        b'T' => value + 273.15,                // °C
        b'Q' => value * 1e3,                   // kW
        b'F' => value / 60.0,                  // kg/min
        _ if name == "cost" => value / 3600.0, // $/h
        _ => panic!("no unit for {name}"),
    }
}

fn reference() -> serde_json::Value {
    let text = std::fs::read_to_string(fixture("data/evaporator/scipy.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// The flowsheet, or a copy with UA2 moved by 1.5e-6 (relative) written to a temporary file.
fn flowsheet_file(perturbed: bool) -> String {
    let path = flowsheet("evaporator.json");
    if !perturbed {
        return path;
    }
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("\"6.84 kW/K\""));
    // One copy per call: the tests run in parallel, and a copy being written is not yet JSON.
    static COPIES: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let k = COPIES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let copy = std::env::temp_dir().join(format!("evaporator_ua2_{}_{k}.json", std::process::id()));
    std::fs::write(&copy, text.replace("\"6.84 kW/K\"", "\"6.84001 kW/K\"")).unwrap();
    copy.to_string_lossy().into_owned()
}

fn run_json(args: &[&str]) -> serde_json::Value {
    let out = plantwide(args);
    assert!(out.status.success(), "plantwide {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Largest relative difference of `steady --json` from the reference steady state, and where.
fn steady_error(file: &str) -> (f64, String) {
    let v = run_json(&["steady", file, "--json"]);
    assert_eq!(v["converged"], true);
    let reference = reference();
    let mut worst = (0.0, String::new());
    for (name, path) in VARIABLES {
        let want = si(name, reference["steady"][name].as_f64().unwrap());
        let got = v["values"][path].as_f64().unwrap_or_else(|| panic!("no {path} in {}", v["values"]));
        let err = (got - want).abs() / want.abs();
        if err > worst.0 {
            worst = (err, format!("{path}: {got} vs SciPy {want}"));
        }
    }
    worst
}

#[test]
fn steady_state_is_scipys_at_the_economic_optimum() {
    let (err, at) = steady_error(&flowsheet_file(false));
    assert!(err < STEADY_RTOL, "largest relative difference {err:e} at {at}");
    let (err, at) = steady_error(&flowsheet_file(true));
    assert!(err > 10.0 * STEADY_RTOL, "UA2 + 1.5e-6 should be seen: {err:e} at {at}");
    // The reference's operating point is its own recomputed optimum, as the paper's to the digits
    // the file carries (F1 = 9.469, F200 = 217.739 kg/min; J = -582.233 $/h).
    let r = reference();
    let opt = &r["optimum"];
    assert!((opt["F1"].as_f64().unwrap() - 9.469).abs() < 5e-4, "{opt}");
    assert!((opt["F200"].as_f64().unwrap() - 217.739).abs() < 5e-4, "{opt}");
    assert!((opt["cost"].as_f64().unwrap() + 582.233).abs() < 5e-4, "{opt}");
}

/// Columns of the scenario's CSV, in the order its `record.paths` list them (paper units).
const RECORDED: [&str; 9] = ["L2", "X2", "P2", "F2", "F3", "T2", "F4", "F100", "cost"];

/// Largest relative difference of the recorded feed-step run from SciPy's samples, and where.
fn trajectory_error(file: &str, tag: &str) -> (f64, String) {
    let csv = std::env::temp_dir().join(format!("evaporator_{tag}_{}.csv", std::process::id()));
    let scenario = flowsheet("scenarios/evaporator_feed_step.json");
    let out = plantwide(&["run", file, "--scenario", &scenario, "--csv", &csv.to_string_lossy()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    std::fs::remove_file(&csv).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    assert!(header.starts_with("time [min],evaporator.L2 [m],evaporator.X2 [%],evaporator.P2 [kPa]"), "{header}");
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|x| x.parse::<f64>().unwrap()).collect()).collect();
    let reference = reference();
    let traj = &reference["trajectory"];
    let times: Vec<f64> = traj["t"].as_array().unwrap().iter().map(|t| t.as_f64().unwrap()).collect();
    assert_eq!(times.len(), 25);
    let mut worst = (0.0, String::new());
    for (k, &t) in times.iter().enumerate() {
        // The event time 2.5 min is recorded twice (before and after the step); no sample sits there.
        let row = rows.iter().rfind(|r| (r[0] - t).abs() < 1e-9).unwrap_or_else(|| panic!("no sample at {t} min"));
        for (j, name) in RECORDED.iter().enumerate() {
            let want = traj[name][k].as_f64().unwrap();
            let err = (row[j + 1] - want).abs() / want.abs();
            if err > worst.0 {
                worst = (err, format!("{name} at {t} min: {} vs SciPy {want}", row[j + 1]));
            }
        }
    }
    worst
}

#[test]
fn feed_step_follows_scipys_radau() {
    let (err, at) = trajectory_error(&flowsheet_file(false), "nominal");
    assert!(err < TRAJECTORY_RTOL, "largest relative difference {err:e} at {at}");
    let (err, at) = trajectory_error(&flowsheet_file(true), "perturbed");
    assert!(err > 10.0 * TRAJECTORY_RTOL, "UA2 + 1.5e-6 should be seen: {err:e} at {at}");
}

/// `gains --json --method METHOD` for the reference's inputs and outputs, in the paper's units.
fn gains(file: &str, method: &str) -> Vec<Vec<f64>> {
    let r = reference();
    let unit = |name: &str| match name.as_bytes()[0] {
        b'X' => "%",
        b'P' => "kPa",
        b'T' => "degC",
        b'Q' => "kW",
        b'F' => "kg/min",
        _ if name == "cost" => "$/h",
        _ => "",
    };
    let path =
        |name: &str| VARIABLES.iter().find(|(n, _)| *n == name).map_or(format!("evaporator.{name}"), |v| v.1.into());
    let with_unit = |name: &str| match unit(name) {
        "" => path(name),
        u => format!("{}@{u}", path(name)),
    };
    let list = |key: &str| -> String {
        r["gains"][key].as_array().unwrap().iter().map(|n| with_unit(n.as_str().unwrap())).collect::<Vec<_>>().join(",")
    };
    let v = run_json(&[
        "gains",
        file,
        "--inputs",
        &list("inputs"),
        "--outputs",
        &list("outputs"),
        "--method",
        method,
        "--json",
    ]);
    v["gain"]
        .as_array()
        .unwrap()
        .iter()
        .map(|row| row.as_array().unwrap().iter().map(|g| g.as_f64().unwrap()).collect())
        .collect()
}

/// Largest difference of plantwide's gains from the reference, over each row's largest gain.
fn gains_error(file: &str, method: &str) -> (f64, String) {
    let r = reference();
    let g = gains(file, method);
    let names = |key: &str| -> Vec<String> {
        r["gains"][key].as_array().unwrap().iter().map(|n| n.as_str().unwrap().to_owned()).collect()
    };
    let (inputs, outputs) = (names("inputs"), names("outputs"));
    let mut worst = (0.0, String::new());
    for (i, row) in r["gains"]["gain"].as_array().unwrap().iter().enumerate() {
        let want: Vec<f64> = row.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
        let scale = want.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        for (j, w) in want.iter().enumerate() {
            let err = (g[i][j] - w).abs() / scale;
            if err > worst.0 {
                worst = (err, format!("d{}/d{}: {} vs SciPy {w}", outputs[i], inputs[j], g[i][j]));
            }
        }
    }
    worst
}

#[test]
fn closed_loop_gains_are_scipys() {
    // Two routes: the linearisation at the converged Newton Jacobian (measured 3e-12) and
    // perturb-and-reconverge with its Richardson check (measured 4e-10).
    for method in ["linear", "perturb"] {
        let (err, at) = gains_error(&flowsheet_file(false), method);
        assert!(err < GAINS_RTOL, "{method}: largest difference over the row's largest gain {err:e} at {at}");
    }
    let (err, at) = gains_error(&flowsheet_file(true), "linear");
    assert!(err > 10.0 * GAINS_RTOL, "UA2 + 1.5e-6 should be seen: {err:e} at {at}");
    // At the optimum the cost's gradient in the free inputs (F1, F200) vanishes: what is left is
    // the rounding of the optimum to the file's three decimals, against 1473 $/h per % of X1.
    let g = gains(&flowsheet_file(false), "linear");
    let cost = g.last().unwrap();
    assert!(cost[0].abs() < 1e-3 && cost[1].abs() < 1e-3 && cost[3].abs() > 1e3, "{cost:?}");
}

/// The model's constants against the paper's own operating point: at Newell & Lee's nominal
/// inputs (Newell & Lee 1989, *Applied Process Control: A Case Study*, ch. 2; the values as
/// tabulated again by Kariwala, Cao & Janardhanan 2008) with X2 held at 25 % and L2 at 1 m, every
/// published steady-state value is reproduced to one unit of its last printed digit, the steam
/// pressure the level needs (194.7 kPa) included. One unit, not half: the table truncates some
/// values — its own condenser equation at its own T3 = 80.6 °C gives Q200 = 307.97 kW and
/// T201 = 46.15 °C, printed 307.9 and 46.1. The SciPy check above shares the equations; this
/// one checks the equations' constants against the source.
#[test]
fn the_evaporator_reproduces_newell_and_lees_nominal_steady_state() {
    let out = plantwide(&["steady", &fixture("data/evaporator/nominal.json"), "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let published: [(&str, &str, f64, f64); 13] = [
        // (name in the paper's unit system, path, published value, one unit of its last digit)
        ("F2", "x2_control.op", 2.0, 0.1),
        ("F4", "evaporator.F4", 8.0, 0.1),
        ("F5", "evaporator.F5", 8.0, 0.1),
        ("P2", "evaporator.P2", 50.5, 0.1),
        ("P100", "level_control.op", 194.7, 0.1),
        ("T2", "evaporator.T2", 84.6, 0.1),
        ("T3", "evaporator.T3", 80.6, 0.1),
        ("T100", "evaporator.T100", 119.9, 0.1),
        ("T201", "evaporator.T201", 46.1, 0.1),
        ("F100", "evaporator.F100", 9.3, 0.1),
        ("Q100", "evaporator.Q100", 339.0, 1.0),
        ("Q200", "evaporator.Q200", 307.9, 0.1),
        ("L2", "evaporator.L2", 1.0, 0.01),
    ];
    let mut off = Vec::new();
    for (name, path, value, unit) in published {
        let x = v["values"][path].as_f64().unwrap_or_else(|| panic!("{path} missing"));
        let (lo, hi) = (si(name, value - unit), si(name, value + unit));
        if !(lo..=hi).contains(&x) {
            off.push(format!("{name}: {x} SI, published {value} ± {unit}"));
        }
    }
    assert!(off.is_empty(), "{}", off.join("\n"));
}
