//! Model predictive control (`"type": "mpc"`, dynamic matrix control solved by clarabel) on
//! Skogestad's column A: its step-test model against the exact linearization, offset-free
//! setpoint tracking, and the feed-rate disturbance that saturates the boilup, against the
//! decentralized PI loops of column_a_lv.json under the same limit.

use std::path::Path;

use crate::harness::{flowsheet, plantwide};

const KMOL_PER_MIN: f64 = 1000.0 / 60.0;

fn run_json(file: &str, scenario: &str, csv: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["run", file, "--scenario", scenario, "--csv", csv.to_str().unwrap(), "--json"];
    args.extend_from_slice(extra);
    let out = plantwide(&args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("--json prints JSON")
}

/// The CSV's columns by header (units stripped) and rows.
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(|h| h.split(" [").next().unwrap().trim().to_string()).collect();
    let rows = lines.map(|l| l.split(',').map(|v| v.trim().parse().unwrap()).collect()).collect();
    (header, rows)
}

fn column(header: &[String], rows: &[Vec<f64>], name: &str) -> Vec<f64> {
    let k = header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name} in {header:?}"));
    rows.iter().map(|r| r[k]).collect()
}

fn final_value(summary: &serde_json::Value, path: &str) -> f64 {
    summary["final_values"][path].as_f64().unwrap_or_else(|| panic!("no final value of {path}"))
}

fn iae(summary: &serde_json::Value, path: &str) -> f64 {
    let p = summary["paths"].as_array().unwrap().iter().find(|p| p["path"] == path).unwrap();
    p["iae"].as_f64().unwrap()
}

/// The controller's step-test model (each MV moved ±0.01 % on the nonlinear column, 200 samples
/// of 5 min) ends at the exact linearization's `G(0)` (the `gains` command, `−C J⁻¹ B`) less what
/// the slowest mode (τ ≈ 194 min) has not settled by 1000 min, `e^(−1000/194) ≈ 0.6 %`: within 1 %.
#[test]
fn step_test_model_of_column_a_ends_at_the_exact_gain() {
    let dir = tempdir("mpc_gain");
    let summary = run_json(
        &flowsheet("column_a_mpc.json"),
        &flowsheet("scenarios/column_a_feed_rate_20.json"),
        &dir.join("run.csv"),
        &[],
    );
    let model: Vec<Vec<f64>> = serde_json::from_value(summary["mpc"][0]["model_gain"].clone()).unwrap();
    let out = plantwide(&[
        "gains",
        &flowsheet("column_a.json"),
        "--inputs",
        "column.reflux@kmol/min,column.boilup@kmol/min",
        "--outputs",
        "distillate.x[light],bottoms.x[light]",
        "--json",
    ]);
    assert!(out.status.success());
    let exact: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for i in 0..2 {
        for j in 0..2 {
            let g = exact["gain"][i][j].as_f64().unwrap();
            let m = model[i][j] * KMOL_PER_MIN;
            assert!(((m - g) / g).abs() < 0.01, "G[{i}][{j}]: step test {m:.5} vs exact {g:.5}");
        }
    }
}

/// With no limit active, the DMC's output-disturbance feedback gives integral action: after a
/// distillate setpoint step 0.99 → 0.992 the qualities settle at their setpoints (to 2e-5, a
/// small fraction of the step), with every QP solved.
#[test]
fn mpc_tracks_a_setpoint_step_without_offset() {
    let dir = tempdir("mpc_sp");
    let scenario = dir.join("sp.json");
    std::fs::write(
        &scenario,
        r#"{"format_version": 1, "duration": "1500 min",
            "events": [{"type": "step", "at": "10 min", "path": "quality_mpc.sp1", "to": 0.992}],
            "record": {"interval": "5 min", "time_unit": "min",
                       "paths": ["distillate.x[light]", "bottoms.x[light]", {"path": "column.boilup", "unit": "kmol/min"}]}}"#,
    )
    .unwrap();
    let summary = run_json(&flowsheet("column_a_mpc.json"), scenario.to_str().unwrap(), &dir.join("run.csv"), &[]);
    let y_d = final_value(&summary, "distillate.x[light]");
    let x_b = final_value(&summary, "bottoms.x[light]");
    assert!((y_d - 0.992).abs() < 2e-5, "yD = {y_d}");
    assert!((x_b - 0.01).abs() < 2e-5, "xB = {x_b}");
    let log = &summary["mpc"][0];
    assert_eq!(log["samples"].as_u64(), Some(301));
    assert_eq!(log["statuses"]["Solved"].as_u64(), Some(301), "{log}");
}

/// Feed +20 % with the boilup limited to 3.5 kmol/min (the issue's disturbance that saturates a
/// valve). The decentralized PI loops (column_a_lv.json, the same limit by `--set`) hold the
/// distillate and lose the bottoms: xB ends at about 0.032, over its 0.02 specification. The MPC
/// holds the boilup limit and its move limit (0.2 kmol/min per 5 min sample) at every sample and
/// ends inside both specifications (yD ≥ 0.985, xB ≤ 0.02), trading the distillate error against the
/// bottoms one.
#[test]
fn mpc_keeps_column_a_within_limits_where_pi_loses_the_bottoms() {
    let dir = tempdir("mpc_feed");
    let scenario = flowsheet("scenarios/column_a_feed_rate_20.json");
    let csv = dir.join("mpc.csv");
    let mpc = run_json(&flowsheet("column_a_mpc.json"), &scenario, &csv, &[]);
    let pi = run_json(
        &flowsheet("column_a_lv.json"),
        &scenario,
        &dir.join("pi.csv"),
        &["--set", "bottom_composition.op_max=3.5 kmol/min"],
    );
    let (header, rows) = read_csv(&csv);
    let boilup = column(&header, &rows, "column.boilup");
    let reflux = column(&header, &rows, "column.reflux");
    assert!(boilup.iter().all(|v| *v <= 3.5 + 1e-9), "boilup above its limit");
    for series in [&boilup, &reflux] {
        // Recorded every minute, moved every 5 min: at most one move between two rows.
        let worst = series.windows(2).map(|w| (w[1] - w[0]).abs()).fold(0.0, f64::max);
        assert!(worst <= 0.2 + 1e-9, "a move of {worst} kmol/min exceeds the rate limit");
    }
    let (y_d, x_b) = (final_value(&mpc, "distillate.x[light]"), final_value(&mpc, "bottoms.x[light]"));
    assert!(y_d >= 0.985 && x_b <= 0.02, "MPC ends at yD = {y_d}, xB = {x_b}");
    assert!((boilup.last().unwrap() - 3.5).abs() < 1e-9, "the boilup limit is the active constraint");
    let x_b_pi = final_value(&pi, "bottoms.x[light]");
    assert!(x_b_pi > 0.03, "PI ends at xB = {x_b_pi}: expected the bottoms lost with the boilup saturated");
    let log = &mpc["mpc"][0];
    assert_eq!(log["samples"].as_u64(), Some(161));
    let failed: u64 = log["statuses"]
        .as_object()
        .unwrap()
        .iter()
        .filter(|(k, _)| k.as_str() != "Solved" && k.as_str() != "AlmostSolved")
        .map(|(_, v)| v.as_u64().unwrap())
        .sum();
    assert_eq!(failed, 0, "{log}");
    eprintln!(
        "IAE [mole fraction·min]: MPC yD {:.3} xB {:.3}; PI yD {:.3} xB {:.3}; QP mean {:.2} ms, max {:.2} ms",
        iae(&mpc, "distillate.x[light]") / 60.0,
        iae(&mpc, "bottoms.x[light]") / 60.0,
        iae(&pi, "distillate.x[light]") / 60.0,
        iae(&pi, "bottoms.x[light]") / 60.0,
        log["mean_solve_time"].as_f64().unwrap() * 1e3,
        log["max_solve_time"].as_f64().unwrap() * 1e3
    );
}

/// An edit of the controller's description.
type Edit = Box<dyn Fn(&mut serde_json::Value)>;

/// Bad descriptions exit 1 naming the field: a control horizon beyond the prediction horizon,
/// horizons whose dense QP would not fit a bounded allocation, an MV starting outside its limits,
/// a scenario sampling the controller (it executes on its own clock), a model file that is missing or of the wrong shape.
#[test]
fn bad_mpc_descriptions_are_refused_by_field() {
    let dir = tempdir("mpc_bad");
    let base: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(flowsheet("column_a_mpc.json")).unwrap()).unwrap();
    let scenario = flowsheet("scenarios/column_a_feed_rate_20.json");
    let cases: Vec<(&str, Edit, &str)> = vec![
        ("horizon", Box::new(|c| c["control_horizon"] = 50.into()), "control_horizon"),
        (
            "huge",
            Box::new(|c| {
                c["prediction_horizon"] = 2000.into();
                c["control_horizon"] = 2000.into();
            }),
            "exceeds 10000000 entries",
        ),
        ("start", Box::new(|c| c["mvs"][1]["max"] = "3 kmol/min".into()), "mvs[1]"),
        ("missing", Box::new(|c| c["model"] = serde_json::json!({"file": "no_such_model.json"})), "no_such_model.json"),
        ("shape", Box::new(|c| c["model"] = serde_json::json!({"file": "shape_model.json"})), "2 CVs and 2 MVs"),
    ];
    std::fs::write(dir.join("shape_model.json"), r#"{"ts": 300.0, "ny": 1, "nu": 1, "steps": [[0.1], [0.2]]}"#)
        .unwrap();
    let sampled = dir.join("sampled.json");
    std::fs::write(&sampled, r#"{"format_version": 1, "duration": "10 min", "sampling": {"quality_mpc": "1 min"}}"#)
        .unwrap();
    let csv = dir.join("sampled.csv");
    let out = plantwide(&[
        "run",
        &flowsheet("column_a_mpc.json"),
        "--scenario",
        sampled.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("quality_mpc") && err.contains("sampling"), "{err}");
    for (name, edit, expected) in cases {
        let mut fs = base.clone();
        edit(&mut fs["controllers"]["quality_mpc"]);
        let file = dir.join(format!("{name}.json"));
        std::fs::write(&file, serde_json::to_string(&fs).unwrap()).unwrap();
        let csv = dir.join("bad.csv");
        let out = plantwide(&["run", file.to_str().unwrap(), "--scenario", &scenario, "--csv", csv.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{name}: {err}");
        assert!(err.contains(expected), "{name}: `{expected}` not in: {err}");
    }
}

fn tempdir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("plantwide_it_{name}_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// An identified model drives the controller: `identify --report` (directional test, σ = 1e-4,
/// 5-min samples) writes step_model.json; the controller reading it (`"model": {"file": …}`)
/// runs the feed-rate scenario, its model's gain within 5 % of the published G(0) (the
/// identification's own tolerance), the boilup within its limit.
#[test]
fn an_identified_step_model_drives_the_controller() {
    let dir = tempdir("mpc_identified");
    let out = plantwide(&[
        "identify",
        &flowsheet("column_a.json"),
        "--inputs",
        "column.reflux@kmol/min,column.boilup@kmol/min",
        "--outputs",
        "distillate.x[light],bottoms.x[light]",
        "--noise",
        "1e-4",
        "--amplitude",
        "0.02",
        "--sample-time",
        "5 min",
        "--report",
        dir.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut fs: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(flowsheet("column_a_mpc.json")).unwrap()).unwrap();
    let c = &mut fs["controllers"]["quality_mpc"];
    c["model"] = serde_json::json!({"file": "step_model.json"});
    c.as_object_mut().unwrap().remove("model_length");
    let file = dir.join("column_a_mpc_identified.json");
    std::fs::write(&file, serde_json::to_string(&fs).unwrap()).unwrap();
    let summary =
        run_json(file.to_str().unwrap(), &flowsheet("scenarios/column_a_feed_rate_20.json"), &dir.join("run.csv"), &[]);
    let log = &summary["mpc"][0];
    assert_eq!(log["model"], "step_model.json");
    assert_eq!(log["samples"].as_u64(), Some(161));
    // S&P 2005 eq. 12.17 (within 0.3 % of the exact linearization, `step_test_model_…` above).
    let exact = [[0.878, -0.864], [1.082, -1.096]];
    for (i, row) in exact.iter().enumerate() {
        for (j, g) in row.iter().enumerate() {
            let m = log["model_gain"][i][j].as_f64().unwrap() * KMOL_PER_MIN;
            assert!(((m - g) / g).abs() < 0.05, "identified G[{i}][{j}] = {m:.4} vs exact {g}");
        }
    }
    let (header, rows) = read_csv(&dir.join("run.csv"));
    assert!(column(&header, &rows, "column.boilup").iter().all(|v| *v <= 3.5 + 1e-9));
}

/// `screen` takes no flowsheet with a model predictive controller in it (its loops would be opened
/// around a controller it does not pair): refused with the controller named and `--mpc` offered.
#[test]
fn screen_refuses_a_flowsheet_with_an_mpc_and_offers_mpc_flag() {
    let mpc = flowsheet("column_a_mpc.json");
    let out = plantwide(&["screen", &mpc, "--column", "column", "--outputs", "distillate.x[light],bottoms.x[light]"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("quality_mpc") && err.contains("--mpc"), "{err}");
}

/// A screening's `--mpc` description is read into the controller's type before any work: one
/// of another type, or with a field an MPC does not have, is refused by name (exit 1).
#[test]
fn a_bad_screening_mpc_description_is_refused_by_field() {
    let dir = tempdir("screen_mpc_bad");
    let lv = flowsheet("column_a_lv.json");
    let cases = [
        (r#"{"type": "pid", "cvs": []}"#, r#"must be of `"type": "mpc"`, not "pid""#),
        (r#"{"mvs": []}"#, "`mpc` has no `cvs` list"),
        (
            r#"{"cvs": [{"pv": "distillate.x[light]"}], "mvs": [{"output": "column.reflux"}], "sample_time": "1 min",
                "prediction_horizon": 10, "control_horizon": 2, "bogus": 1}"#,
            "unknown field `bogus`",
        ),
    ];
    for (k, (text, needle)) in cases.iter().enumerate() {
        let file = dir.join(format!("mpc{k}.json"));
        std::fs::write(&file, text).unwrap();
        let cvs = "distillate.x[light],bottoms.x[light]";
        let args = ["screen", &lv, "--cvs", cvs, "--mvs", "column.reflux,column.boilup", "--mpc"];
        let out = plantwide(&[&args[..], &[file.to_str().unwrap()]].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{text}: {err}");
        assert!(err.contains("--mpc") && err.contains(needle), "{text}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

fn scheme<'a>(c: &'a serde_json::Value, file: &str) -> &'a serde_json::Value {
    c["schemes"].as_array().unwrap().iter().find(|s| s["file"].as_str().unwrap().ends_with(file)).unwrap()
}

fn sensitivity<'a>(s: &'a serde_json::Value, disturbance: &str, output: &str) -> &'a serde_json::Value {
    s["sensitivity"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["disturbance"].as_str().unwrap().starts_with(disturbance) && r["output"] == output)
        .unwrap()
}

/// `compare` judges the MPC scheme beside the PI loops on column A. Two routes to one number: at
/// the feed −10 % end the MPC held on its setpoints (design specs) and the PI loops (integral
/// action) reach the same steady state, tray 21 included; at +10 % the MPC's boilup would need
/// more than its 3.5 kmol/min limit, which the sensitivity names and the closed-loop run shows.
#[test]
fn compare_judges_an_mpc_scheme_beside_the_pi_loops() {
    let (lv, mpc) = (flowsheet("column_a_lv.json"), flowsheet("column_a_mpc.json"));
    let outputs = "distillate.x[light],bottoms.x[light],column.x[21][light]";
    let out = plantwide(&[
        "compare",
        &lv,
        &mpc,
        "--disturbances",
        "feed_source.F=+10%",
        "--outputs",
        outputs,
        "--duration",
        "800 min",
        "--json",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let c: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let (pi, m) = (scheme(&c, "column_a_lv.json"), scheme(&c, "column_a_mpc.json"));
    let alt = &m["mpc"][0];
    assert_eq!(alt["controller"], "quality_mpc");
    // The same 2×2 plant seen through the opened PI loops and through the MPC's held MVs.
    let (k_pi, k_mpc) = (pi["condition_number"].as_f64().unwrap(), alt["condition_number"].as_f64().unwrap());
    assert!((k_mpc / k_pi - 1.0).abs() < 1e-4 && (140.0..150.0).contains(&k_mpc), "κ {k_mpc} vs {k_pi}");
    for (path, sp) in [("distillate.x[light]", 0.99), ("bottoms.x[light]", 0.01)] {
        let low = sensitivity(m, "feed_source.F", path)["low"].as_f64().unwrap();
        assert!((low - sp).abs() < 1e-9, "{path} at feed −10 %: {low}");
    }
    let tray = |s| sensitivity(s, "feed_source.F", "column.x[21][light]")["low"].as_f64().unwrap();
    assert!((tray(m) - tray(pi)).abs() < 1e-7, "tray 21: MPC {} vs PI {}", tray(m), tray(pi));
    let high = sensitivity(m, "feed_source.F", "bottoms.x[light]");
    assert!(high["high"].is_null(), "{high}");
    // A physical finding, not a failure of the study: the sweep reached the point.
    assert_eq!(high["failures"], serde_json::json!([]), "{high}");
    let why = high["no_steady_state"].to_string();
    assert!(why.contains("quality_mpc.op2") && why.contains("column.boilup") && why.contains("58.333333"), "{why}");
    assert!(!sensitivity(pi, "feed_source.F", "bottoms.x[light]")["high"].is_null());
    let run = &alt["dynamic"]["runs"][0];
    assert_eq!(run["saturated"], serde_json::json!(["column.boilup"]), "{run}");
    let qp = &alt["qp"][0];
    // 800 min at 5 min: executions at 0, 5, …, 800 min.
    assert_eq!(qp["samples"], 161, "{qp}");
    assert_eq!(qp["statuses"]["Solved"], 161, "{qp}");
    assert!(run["cvs"].as_array().unwrap().iter().all(|f| f["iae"].as_f64().unwrap() > 0.0), "{run}");
}

/// `screen --mpc` judges a model predictive controller on the runs of the PI candidates, and the
/// scores are the mean IAE ratios to the best of all tested (recomputed here from the IAEs).
#[test]
fn screen_judges_an_mpc_beside_the_pairings() {
    let dir = tempdir("screen_mpc");
    let file = dir.join("mpc.json");
    let m = |cvs: &str| {
        format!(
            r#"{{"cvs": {cvs},
             "mvs": [{{"output": "column.reflux", "scale": "0.1 kmol/min", "min": 0, "max": "6 kmol/min"}},
                     {{"output": "column.boilup", "scale": "0.1 kmol/min", "min": 0, "max": "6 kmol/min"}}],
             "sample_time": "5 min", "prediction_horizon": 40, "control_horizon": 5, "model_length": 200}}"#
        )
    };
    let cvs =
        r#"[{"pv": "distillate.x[light]", "scale": 0.001, "weight": 4}, {"pv": "bottoms.x[light]", "scale": 0.001}]"#;
    std::fs::write(&file, m(cvs)).unwrap();
    let lv = flowsheet("column_a_lv.json");
    let args = |f: &str| {
        let v =
            ["screen", &lv, "--cvs", "distillate.x[light],bottoms.x[light]", "--mvs", "column.reflux,column.boilup"];
        let mut v: Vec<String> = v.iter().map(|s| s.to_string()).collect();
        v.extend(
            ["--disturbances", "feed_source.F=+10%,feed_source.z[light]=+5%", "--duration", "800 min"]
                .map(String::from),
        );
        v.extend(["--mpc".to_string(), f.to_string(), "--json".to_string()]);
        v
    };
    let a = args(file.to_str().unwrap());
    let out = plantwide(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let s: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let mut tested: Vec<&serde_json::Value> = s["structures"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|c| c.get("dynamic").filter(|d| d["failure"].is_null() && !d.is_null()))
        .collect();
    tested.push(&s["mpc"]["dynamic"]);
    let iae = |t: &serde_json::Value, d: usize, c: usize| t["runs"][d]["cvs"][c]["iae"].as_f64().unwrap();
    for t in &tested {
        let mut sum = 0.0;
        for d in 0..2 {
            for c in 0..2 {
                let best = tested.iter().map(|u| iae(u, d, c)).fold(f64::INFINITY, f64::min);
                sum += iae(t, d, c) / best;
            }
        }
        let score = t["score"].as_f64().unwrap();
        assert!((score - sum / 4.0).abs() < 1e-12 * score && score >= 1.0, "{score} vs {}", sum / 4.0);
    }
    assert_eq!(s["mpc"]["qp"].as_array().unwrap().len(), 2);
    // A controller on other CVs than the screening's is refused by name.
    let bad = dir.join("bad.json");
    std::fs::write(&bad, m(r#"[{"pv": "distillate.x[light]"}, {"pv": "column.x[21][light]"}]"#)).unwrap();
    let a = args(bad.to_str().unwrap());
    let out = plantwide(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("--mpc") && err.contains("column.x[21][light]") && err.contains("--cvs"), "{err}");
}
