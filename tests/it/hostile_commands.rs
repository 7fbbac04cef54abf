//! Hostile input to the commands added after the first fuzz campaign (issue 54): every file under
//! `tests/hostile/fuzz3/` reproduces a defect a seeded fuzz and hand-made cases found (its
//! README). Each must now give the answer an engineer expects: a run that completes, exit 1 naming
//! the file, field or flag and what would fix it, or exit 2 naming the element.

use std::process::Output;
use std::time::{Duration, Instant};

use crate::harness;

fn case(name: &str) -> String {
    harness::fixture(&format!("hostile/fuzz3/{name}"))
}

/// A scratch folder of this test process (scenarios may write snapshots into the working folder).
fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("plantwide_it_fuzz3_{name}_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Run `plantwide ARGS` in `dir` and return its output and how long it took.
fn run_in(dir: &std::path::Path, args: &[&str]) -> (Output, Duration) {
    let t0 = Instant::now();
    let out = harness::command().args(args).current_dir(dir).output().expect("the plantwide binary runs");
    (out, t0.elapsed())
}

/// Run `args`, expect exit `code` within 20 s and every fragment in stderr; returns stdout.
fn expect(args: &[&str], code: i32, fragments: &[&str]) -> String {
    let (out, took) = run_in(&scratch("expect"), args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}: stderr:\n{stderr}");
    assert!(took < Duration::from_secs(20), "{args:?} took {took:?}");
    assert!(!stderr.contains("panicked"), "{args:?} panicked:\n{stderr}");
    for f in fragments {
        assert!(stderr.contains(f), "{args:?}: missing `{f}` in:\n{stderr}");
    }
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// D1: a 0.7 s scan falls on `3 · 0.7 = 2.0999999999999996`, whose `t / 0.7` floors to 2, so the
/// third scan fell due again at once and the integrator stopped on a zero step. The run now ends
/// where the surge tank's PI loop puts it whatever its scan (level on its 1 m setpoint, outflow on
/// the new 60 mol/s inflow: the integral action's steady state).
#[test]
fn a_scan_period_that_is_not_a_round_number_runs_to_the_end() {
    let dir = scratch("scan07");
    let csv = dir.join("o.csv");
    let args = [
        "run",
        &harness::flowsheet("surge_tank_pi.json"),
        "--scenario",
        &case("scen_sampling_0.7s.json"),
        "--csv",
        csv.to_str().unwrap(),
        "--json",
    ];
    let (out, _) = run_in(&dir, &args);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["t_end"].as_f64(), Some(5000.0));
    let last = std::fs::read_to_string(&csv).unwrap();
    let row: Vec<f64> = last.lines().last().unwrap().split(',').map(|v| v.parse().unwrap()).collect();
    assert!((row[1] - 1.0).abs() < 1e-6 && (row[2] - 60.0).abs() < 1e-4, "level, outflow at the end: {row:?}");
}

/// D1: a model predictive controller sampled every 33.3 s executes at every `k · 33.3 s` of the
/// 2000-min run: ⌊120 000 / 33.3⌋ + 1 = 3604 times.
#[test]
fn an_mpc_sampled_every_33_point_3_seconds_executes_at_each_sample() {
    let dir = scratch("mpc333");
    let csv = dir.join("o.csv");
    let scenario = harness::flowsheet("scenarios/column_a_feed_step.json");
    let args =
        ["run", &case("mpc_sample_time_33.3s.json"), "--scenario", &scenario, "--csv", csv.to_str().unwrap(), "--json"];
    let (out, _) = run_in(&dir, &args);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let samples = json["mpc"][0]["samples"].as_u64().unwrap();
    assert_eq!(samples, (120_000.0f64 / 33.3).floor() as u64 + 1);
}

/// D2: a step model of other variables, of the controller's own in another order, with channels
/// unnamed, of a singular gain, or not a model at all, is refused before the run (exit 1 naming
/// the model file and what is wrong).
#[test]
fn an_mpc_model_of_other_channels_or_a_singular_gain_is_refused() {
    let scenario = harness::flowsheet("scenarios/column_a_feed_step.json");
    let csv = scratch("mpc_names").join("o.csv");
    let run = |file: &str, fragments: &[&str]| {
        expect(&["run", &case(file), "--scenario", &scenario, "--csv", csv.to_str().unwrap()], 1, fragments);
    };
    run("mpc_names/mpc_swapped_io.json", &["sm_swapped_io.json", "\"inputs\"", "in another order"]);
    run("mpc_names/mpc_wrong_names.json", &["sm_wrong_names.json", "feed_source.F", "column.reflux, column.boilup"]);
    run("mpc_names/mpc_singular.json", &["sm_singular.json", "singular", "no MV move sets the CVs independently"]);
    run("mpc_names/mpc_ragged.json", &["sm_ragged.json", "expected a step-response model"]);
}

/// D2: unknown keys of a model file are refused with their place (a misspelt `"input"` would
/// leave the channels unchecked); a model without channel names cannot be checked and is refused.
#[test]
fn a_step_model_file_with_an_unknown_key_or_no_channel_names_is_refused() {
    let dir = scratch("mpc_keys");
    let base = std::fs::read_to_string(case("mpc_names/mpc_swapped_io.json")).unwrap();
    let model: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(case("mpc_names/sm_swapped_io.json")).unwrap()).unwrap();
    let scenario = harness::flowsheet("scenarios/column_a_feed_step.json");
    for (name, edit, fragment) in [
        ("unknown", serde_json::json!({"input": ["column.reflux", "column.boilup"]}), "unknown field `input`"),
        ("unnamed", serde_json::json!({}), "names no channels"),
    ] {
        let mut m = model.clone();
        m.as_object_mut().unwrap().remove("inputs");
        m.as_object_mut().unwrap().extend(edit.as_object().unwrap().clone());
        std::fs::write(dir.join(format!("sm_{name}.json")), m.to_string()).unwrap();
        let file = dir.join(format!("{name}.json"));
        std::fs::write(&file, base.replace("sm_swapped_io.json", &format!("sm_{name}.json"))).unwrap();
        let csv = dir.join("o.csv");
        expect(
            &["run", file.to_str().unwrap(), "--scenario", &scenario, "--csv", csv.to_str().unwrap()],
            1,
            &[fragment],
        );
    }
}

/// D5: a model file is read under the file-size limit by what is read, not by what the file system
/// says (`/dev/zero` reports a length of 0).
#[test]
fn an_endless_model_file_is_refused_at_the_size_limit() {
    let scenario = harness::flowsheet("scenarios/column_a_feed_step.json");
    let csv = scratch("devzero").join("o.csv");
    let out = harness::command()
        .args(["run", &case("mpc_model_devzero.json"), "--scenario", &scenario, "--csv", csv.to_str().unwrap()])
        .env("PLANTWIDE_MAX_FILE_BYTES", "100000")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("/dev/zero") && stderr.contains("PLANTWIDE_MAX_FILE_BYTES"), "{stderr}");
}

/// D3: a sinusoid much faster than the vessel's settling is refused with the shortest period the
/// verification can follow, instead of a run that never ends.
#[test]
fn a_sinusoid_too_fast_to_follow_is_refused_with_the_period_that_can_be() {
    let args = [
        "size",
        &harness::flowsheet("surge_tank_pi.json"),
        "--vessel",
        "tank",
        "--disturbance",
        "inflow.F=+10%",
        "--level-band",
        "0.2 m",
        "--max-outflow-rate",
        "0.1 mol/s/s",
        "--sine",
        "1e-3 s",
    ];
    expect(&args, 1, &["inflow.F", "period of at least"]);
}

/// D8: a setpoint outside its measurement's range and an output limit outside the driven input's
/// range are input errors naming the field (they used to reach Newton and end in exit 2).
#[test]
fn controller_settings_outside_the_physical_range_are_refused_by_field() {
    expect(
        &["check", &case("pid_sp_molefraction_1.5.json")],
        1,
        &["controllers.xd_control.sp", "1.5 is outside the range 0 … 1", "the measurement's"],
    );
    expect(
        &["check", &case("pid_opmax_negative_flow.json")],
        1,
        &["controllers.reboiler_level.op_max", "-1 mol/s", "must not be negative", "input it drives"],
    );
}

/// D9: 90 lags of an hour have polynomial coefficients beyond 1e308 in seconds: exit 2 naming the
/// element and the larger time unit that keeps them finite (which then works); their ultimate
/// gain is `(1 + (τω_u)²)^45` at the crossover of `90 atan(τω) + θω = π`; a gain of 1e308 or a 90th-order lead–lag with
/// dead time has a phase crossover (they were "no phase crossover").
#[test]
fn high_order_and_extreme_transfer_functions_are_exact_or_refused_by_element() {
    let lags = case("tf/lags90_1h.tf.json");
    expect(&["linearize", "--tf", &lags], 2, &["y ← u", "--time-unit"]);
    let out = expect(&["linearize", "--tf", &lags, "--time-unit", "h"], 0, &[]);
    assert!(!out.contains("null") && !out.contains("NaN"), "{out}");
    let out = expect(&["tune", "--tf", &lags, "--method", "zn", "--json"], 0, &[]);
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let ku = json["loops"][0]["ku"].as_f64().unwrap_or_else(|| panic!("{json}"));
    // Behind the file's minute of dead time: 90 atan(3600 ω) + 60 ω = π, by bisection.
    let (mut lo, mut hi) = (0.0, (std::f64::consts::PI / 90.0).tan() / 3600.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if 90.0 * (3600.0 * mid).atan() + 60.0 * mid < std::f64::consts::PI { lo = mid } else { hi = mid }
    }
    let exact = (1.0 + (3600.0 * lo).powi(2)).powf(45.0);
    assert!((ku - exact).abs() < 1e-8 * exact, "Ku {ku} against {exact}");
    expect(&["tune", "--tf", &case("tf/ll90.tf.json"), "--method", "zn"], 0, &[]);
    let out = expect(&["tune", "--tf", &case("tf/gain_1e308.tf.json"), "--method", "zn", "--json"], 0, &[]);
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let ku = json["loops"][0]["ku"].as_f64().unwrap();
    assert!(ku > 0.0 && ku < 1e-300, "Ku of a 1e308 gain: {ku}");
}

/// D11: an empty unit name and an empty snapshot file are named by their field.
#[test]
fn empty_names_are_refused_by_field() {
    expect(&["check", &case("unit_empty_name.json")], 1, &["units.\"\"", "may not be empty"]);
    let csv = scratch("snap").join("o.csv");
    let args = [
        "run",
        &harness::flowsheet("column_a.json"),
        "--scenario",
        &case("scen_snapshot_empty_file.json"),
        "--csv",
        csv.to_str().unwrap(),
    ];
    expect(&args, 1, &["snapshots[0].file", "is empty"]);
}

/// D12: a path recorded 20 000 times (a 182 MB CSV) is refused naming both places; a list of a
/// study that names an item twice is refused naming both entries.
#[test]
fn duplicates_are_refused_naming_both_places() {
    let csv = scratch("dup").join("o.csv");
    let args = [
        "run",
        &harness::flowsheet("surge_tank_pi.json"),
        "--scenario",
        &case("scen_record_20000_dup_paths.json"),
        "--csv",
        csv.to_str().unwrap(),
    ];
    expect(&args, 1, &["record.paths[1]", "record.paths[0]", "tank.level"]);
    let column_a_lv = harness::flowsheet("column_a_lv.json");
    expect(
        &["tune", &column_a_lv, "--loops", "top_composition,top_composition", "--method", "blt"],
        1,
        &["--loops", "top_composition", "entries 1 and 2"],
    );
    let screen = [
        "screen",
        &column_a_lv,
        "--cvs",
        "distillate.x[light],distillate.z[light]",
        "--mvs",
        "column.reflux,column.boilup",
    ];
    expect(&screen, 1, &["--cvs", "entries 1 and 2"]);
    let size = [
        "size",
        &harness::flowsheet("surge_tank_pi.json"),
        "--candidates",
        "tank,tank",
        "--disturbance",
        "inflow.F=+10%",
        "--level-band",
        "0.2 m",
        "--max-outflow-rate",
        "0.1 mol/s/s",
    ];
    expect(&size, 1, &["--candidates", "tank", "entries 1 and 2"]);
}

/// D7, D13: a study flag beyond the models' range and a zero scan are refused at once, naming the
/// flag; an event that takes an input out of its range says so in one sentence.
#[test]
fn study_flags_out_of_range_are_refused_naming_the_flag() {
    let tank = harness::flowsheet("surge_tank_pi.json");
    expect(
        &["tune", &tank, "--loop", "lc", "--method", "averaging", "--flow-change", "1e300 mol/s"],
        1,
        &["--flow-change", "1e300", "range in which the models hold"],
    );
    expect(&["tune", &tank, "--loop", "lc", "--method", "simc", "--scan", "0 s"], 1, &["`lc`", "not a positive time"]);
    let dir = scratch("event_range");
    let scenario = dir.join("negative.json");
    std::fs::write(
        &scenario,
        r#"{"format_version": 1, "duration": "100 s", "events": [{"type": "step", "at": "10 s", "path": "F_in", "to": "-5 mol/s"}]}"#,
    )
    .unwrap();
    let csv = dir.join("o.csv");
    expect(
        &["run", &tank, "--scenario", scenario.to_str().unwrap(), "--csv", csv.to_str().unwrap()],
        1,
        &[
            "takes `inflow.F` out of its range: -5 mol/s is outside the range 0 … 1e6 mol/s",
            "(it must not be negative)",
        ],
    );
}

/// Found by the grown fuzz: an absolute tolerance of 1e-300 made the reactor's run take a million
/// steps (minutes) for 2 s; tolerances below the floors where the error test is more than
/// rounding are refused by field.
#[test]
fn integrator_tolerances_below_rounding_are_refused_by_field() {
    let dir = scratch("tolerance");
    for (field, value) in [("atol", "1e-300"), ("rtol", "1e-15")] {
        let scenario = dir.join(format!("{field}.json"));
        std::fs::write(
            &scenario,
            format!(r#"{{"format_version": 1, "duration": "100 s", "integrator": {{"{field}": {value}}}}}"#),
        )
        .unwrap();
        let csv = dir.join("o.csv");
        let args = [
            "run",
            &harness::flowsheet("surge_tank_pi.json"),
            "--scenario",
            scenario.to_str().unwrap(),
            "--csv",
            csv.to_str().unwrap(),
        ];
        expect(&args, 1, &[&format!("integrator.{field}"), "more than rounding"]);
    }
}

/// Found by the grown fuzz: a transfer-function file quoted a 100 kB name back in its message,
/// and kept one of two keys given twice unseen; both are refused by field, briefly.
#[test]
fn a_transfer_function_file_with_a_key_twice_or_an_endless_name_is_refused_briefly() {
    let dir = scratch("tf_walk");
    let twice = dir.join("twice.tf.json");
    std::fs::write(
        &twice,
        r#"{"format_version": 1, "name": "t", "inputs": [{"name": "u"}], "inputs": [{"name": "v"}],
            "outputs": [{"name": "y"}], "elements": [{"output": "y", "input": "u", "gain": 1.0, "lags": ["1 min"]}]}"#,
    )
    .unwrap();
    expect(&["linearize", "--tf", twice.to_str().unwrap()], 1, &["twice.tf.json", "inputs"]);
    let long = dir.join("long.tf.json");
    let name = "u".repeat(100_000);
    std::fs::write(
        &long,
        format!(
            r#"{{"format_version": 1, "name": "t", "inputs": [{{"name": "{name}"}}], "outputs": [{{"name": "y"}}],
                "elements": [{{"output": "y", "input": "{name}", "gain": 1.0, "lags": ["1 min"]}}]}}"#
        ),
    )
    .unwrap();
    let err = expect(&["linearize", "--tf", long.to_str().unwrap()], 1, &["long.tf.json"]);
    assert!(err.len() < 2000, "a {} character message", err.len());
}

/// newcomer3 D11: a plot into a missing folder failed after the whole run with a raw backend
/// error. Output files are checked when the command line is read, naming the flag and the folder.
#[test]
fn an_output_file_in_a_missing_folder_is_refused_before_the_run() {
    let missing = scratch("d11").join("missing_dir").join("o.png");
    let scenario = harness::flowsheet("scenarios/surge_tank_inflow_step.json");
    let tank = harness::flowsheet("surge_tank_pi.json");
    let args = ["run", &tank, "--scenario", &scenario, "--csv", "/dev/null", "--plot", missing.to_str().unwrap()];
    expect(&args, 1, &["--plot", "missing_dir", "does not exist"]);
    let sensitivity = ["sensitivity", &tank, "--csv", missing.to_str().unwrap()];
    expect(&sensitivity, 1, &["--csv", "missing_dir", "does not exist"]);
}

/// Found by the 100 000-mutant fuzz: an element of 10 000 lags kept `tune` busy for minutes.
/// An element's order is bounded, refused by field.
#[test]
fn a_transfer_function_of_ten_thousand_lags_is_refused_by_field() {
    let dir = scratch("tf_order");
    let file = dir.join("lags.tf.json");
    let lags = vec!["\"14.4 min\""; 10_000].join(",");
    std::fs::write(
        &file,
        format!(
            r#"{{"format_version": 1, "name": "t", "inputs": [{{"name": "u"}}], "outputs": [{{"name": "y"}}],
                "elements": [{{"output": "y", "input": "u", "gain": 1.0, "lags": [{lags}]}}]}}"#
        ),
    )
    .unwrap();
    expect(&["tune", "--tf", file.to_str().unwrap(), "--method", "zn"], 1, &["elements[0].lags", "more than the 200"]);
}

/// Found by the 100 000-mutant fuzz: a step model or transfer-function file with more after its
/// JSON was read as if the rest were not there, an empty transfer-function model exported null
/// coefficients, and a snapshot whose history is empty panicked before it was checked.
#[test]
fn trailing_text_empty_models_and_hollow_snapshots_are_refused() {
    let dir = scratch("fuzz100k");
    let tf = dir.join("empty.tf.json");
    std::fs::write(
        &tf,
        r#"{"format_version": 1, "name": "t", "inputs": [{"name": "u"}], "outputs": [{"name": "y"}], "elements": []}"#,
    )
    .unwrap();
    expect(&["linearize", "--tf", tf.to_str().unwrap()], 1, &["elements", "at least one element"]);
    let trailing = dir.join("trailing.tf.json");
    std::fs::write(
        &trailing,
        r#"{"format_version": 1, "name": "t", "inputs": [{"name": "u"}], "outputs": [{"name": "y"}],
            "elements": [{"output": "y", "input": "u", "gain": 1.0, "lags": ["1 min"]}]} extra"#,
    )
    .unwrap();
    expect(&["linearize", "--tf", trailing.to_str().unwrap()], 1, &["trailing characters"]);
    // A snapshot of the surge tank with its history emptied.
    let tank = harness::flowsheet("surge_tank_pi.json");
    let scenario = dir.join("s.json");
    let snap = dir.join("snap.json");
    std::fs::write(
        &scenario,
        format!(
            r#"{{"format_version": 1, "duration": "100 s", "snapshots": [{{"at": "50 s", "file": "{}"}}]}}"#,
            snap.display()
        ),
    )
    .unwrap();
    let csv = dir.join("o.csv");
    let run = ["run", &tank, "--scenario", scenario.to_str().unwrap(), "--csv", csv.to_str().unwrap()];
    expect(&run, 0, &[]);
    let mut s: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&snap).unwrap()).unwrap();
    s["integrator"]["d"] = serde_json::json!([]);
    let hollow = dir.join("hollow.json");
    std::fs::write(&hollow, s.to_string()).unwrap();
    let resume = [&run[..], &["--resume", hollow.to_str().unwrap()]].concat();
    expect(&resume, 1, &["does not fit this plant", "integrator state"]);
}

/// The second 100 000-mutant fuzz (seed 20261209: 7 failures, 4 classes besides a harness slip):
/// a reaction order of -1e308 overflowed the rate constant's dimension (a panic), a scenario of
/// 1000 events on a 1000-character path quoted it whole in each of 50 lines (52 kB), and a
/// snapshot's statistics count at the top of `usize` overflowed when counted on.
#[test]
fn huge_reaction_orders_long_paths_and_overflowing_counts_are_refused_by_field() {
    let dir = scratch("fuzz20261209");
    let text = std::fs::read_to_string(harness::flowsheet("two_column_plant.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["units"]["reactor"]["reactions"][0]["orders"] = serde_json::json!({"A": 1, "B": -1e308});
    let orders = dir.join("orders.json");
    std::fs::write(&orders, v.to_string()).unwrap();
    expect(
        &["check", orders.to_str().unwrap()],
        1,
        &["units.reactor.reactions[0].orders.B: an order of -1e308 is beyond ±20"],
    );
    let tank = harness::flowsheet("surge_tank_pi.json");
    let path = "F_in".repeat(250);
    let events: Vec<String> =
        (0..1000).map(|k| format!(r#"{{"type": "step", "at": "{k} s", "path": "{path}", "to": "1 mol/s"}}"#)).collect();
    let scenario = dir.join("long.json");
    std::fs::write(
        &scenario,
        format!(r#"{{"format_version": 1, "duration": "2000 s", "events": [{}]}}"#, events.join(",")),
    )
    .unwrap();
    let csv = dir.join("o.csv");
    let (out, _) =
        run_in(&dir, &["run", &tank, "--scenario", scenario.to_str().unwrap(), "--csv", csv.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("(1000 characters)") && err.len() < 10_000, "{} bytes: {err:.300}", err.len());
    // A snapshot whose Newton count is at the top of usize.
    let snap = dir.join("snap.json");
    let take = format!(
        r#"{{"format_version": 1, "duration": "100 s", "snapshots": [{{"at": "50 s", "file": "{}"}}]}}"#,
        snap.display()
    );
    let first = dir.join("first.json");
    std::fs::write(&first, take).unwrap();
    let run = ["run", &tank, "--scenario", first.to_str().unwrap(), "--csv", csv.to_str().unwrap()];
    expect(&run, 0, &[]);
    let mut s: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&snap).unwrap()).unwrap();
    s["integrator"]["stats"]["n_newton_iters"] = serde_json::json!(u64::MAX);
    std::fs::write(&snap, s.to_string()).unwrap();
    let longer = dir.join("longer.json");
    std::fs::write(&longer, r#"{"format_version": 1, "duration": "200 s"}"#).unwrap();
    let resume = [
        "run",
        &tank,
        "--scenario",
        longer.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
        "--resume",
        snap.to_str().unwrap(),
    ];
    expect(&resume, 1, &["a statistics count above 9007199254740992"]);
}
