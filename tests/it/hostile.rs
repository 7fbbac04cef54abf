//! Hostile input (issue 13): every file under tests/hostile/ reproduces a defect found by a seeded
//! mutation fuzz (panics, aborts on huge allocations, hangs, silently accepted or dishonestly
//! "converged" plants). Each must now end with exit 1 naming the field, exit 2 naming the unit and
//! equation, or a certified answer with a warning where that is the truth.

use std::process::Output;
use std::time::{Duration, Instant};

use crate::harness;
use plantwide::flowsheet::load_file;
use plantwide::solve::{NewtonSettings, certify, steady_state};

/// Run `plantwide ARGS` and time it.
fn timed(args: &[&str]) -> (Output, Duration) {
    let t0 = Instant::now();
    let out = harness::plantwide(args);
    (out, t0.elapsed())
}

fn case(name: &str) -> String {
    harness::fixture(&format!("hostile/{name}"))
}

/// Run `args`, expect exit `code` within 10 s and every fragment in stderr.
fn expect(args: &[&str], code: i32, fragments: &[&str]) {
    let (out, took) = timed(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}: stderr:\n{stderr}");
    assert!(took < Duration::from_secs(10), "{args:?} took {took:?}");
    assert!(!stderr.contains("panicked"), "{args:?} panicked:\n{stderr}");
    for f in fragments {
        assert!(stderr.contains(f), "{args:?}: missing `{f}` in:\n{stderr}");
    }
}

#[test]
fn counts_that_would_exhaust_memory_are_refused_naming_the_field_and_the_limit() {
    for (file, n) in [
        ("column_a_stages_2pow63_panic.json", "9223372036854775808"),
        ("column_a_stages_1e9_abort.json", "1000000000"),
        ("column_a_stages_1e6_hang.json", "1000000"),
        ("column_a_stages_5000.json", "5000"),
    ] {
        expect(&["check", &case(file)], 1, &["units.column.stages", n, "PLANTWIDE_MAX_STAGES"]);
    }
    expect(&["check", &case("flash_vl_mixer_inlets_1e9_abort.json")], 1, &["units.mix.inlets", "PLANTWIDE_MAX_INLETS"]);
    let column_a = harness::flowsheet("column_a.json");
    expect(
        &["steady", &column_a, "--set", "column.stages=1000000"],
        1,
        &["units.column.stages", "PLANTWIDE_MAX_STAGES"],
    );
}

#[test]
fn a_raised_stage_limit_still_bounds_the_jacobian_block() {
    let out = harness::command()
        .args(["check", &case("column_a_stages_5000.json")])
        .env("PLANTWIDE_MAX_STAGES", "5000")
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("units.column") && stderr.contains("PLANTWIDE_MAX_BLOCK_ENTRIES"), "{stderr}");
}

#[test]
fn structural_mistakes_are_named_with_their_full_path() {
    expect(&["check", &case("column_a_duplicate_unit_key_silent.json")], 1, &["units.column", "appears twice"]);
    expect(
        &["check", &case("column_a_feed_stage_float_unclear_msg.json")],
        1,
        &["units.column.feeds[0].stage", "1.5", "whole number"],
    );
    expect(
        &["check", &case("btx_tray_dp_1p8e19_misleading_msg.json")],
        1,
        &["units.column.rigorous.tray_pressure_drop", "1.8446744073709552e19 Pa is beyond the ±1e9 Pa"],
    );
    expect(
        &["check", &case("example_4_1_negative_level_sp_dishonest.json")],
        1,
        &["controllers.reboiler_level.sp", "must not be negative"],
    );
}

#[test]
fn a_file_that_is_not_utf8_is_reported_with_the_byte_offset() {
    let dir = std::env::temp_dir().join(format!("plantwide-hostile-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("latin1.json");
    std::fs::write(&path, b"{\n  \"name\": \"caf\xe9\"\n}\n").unwrap();
    expect(&["check", path.to_str().unwrap()], 1, &["latin1.json:2:15", "offset 16", "0xe9", "UTF-8"]);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_huge_unknown_component_name_is_answered_fast_and_not_echoed() {
    let text = std::fs::read_to_string(harness::flowsheet("surge_tank.json")).unwrap();
    let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    doc["components"] = serde_json::json!(["A".repeat(10_000_000)]);
    let dir = std::env::temp_dir().join(format!("plantwide-hostile-name-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("long_name.json");
    std::fs::write(&path, doc.to_string()).unwrap();
    let (out, took) = timed(&["check", path.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(took < Duration::from_secs(5), "{took:?}");
    assert!(
        stderr.len() < 2000 && stderr.contains("components[0]") && stderr.contains("PLANTWIDE_MAX_STRING_LEN"),
        "{}",
        &stderr[..stderr.len().min(500)]
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn set_goes_through_the_loaders_validation() {
    let f = harness::flowsheet("column_a.json");
    for (set, frag) in [
        ("feed_source.F=-1kmol/min", "must not be negative"),
        ("feed_source.z[light]=1.5", "outside the range 0 … 1"),
        ("feed_source.z[light]=-0.1", "must not be negative"),
        ("feed_source.P=-1 atm", "outside the range 1 … 1e9 Pa"),
        ("column.reflux=-1kmol/min", "must not be negative"),
        ("condenser_level.sp=-5 kmol", "must not be negative"),
        ("column.reflux=1e308", "1e308 mol/s is outside the range"),
    ] {
        expect(&["steady", &f, "--set", set], 1, &[&format!("--set {set}"), frag]);
    }
    // 1.3 Pa instead of 1.3 atm: in range for a pressure, but the saturated-liquid feed would boil
    // at 194 K, below benzene's triple point (Newton took 400 iterations to fail on it).
    expect(
        &["steady", &harness::flowsheet("btx_column.json"), "--set", "feed_source.P=1.3"],
        1,
        &["units.feed_source.P", "193.7 K", "below 278.7 K", "benzene"],
    );
    let f = harness::flowsheet("flash_recycle.json");
    for (set, frag) in [
        ("fresh.T=1e-300", "outside the range 1 … 5000 K"),
        ("split.split[1]=1.5", "outside the range 0 … 1"),
        ("drum.opening=-0.5", "must not be negative"),
    ] {
        expect(&["steady", &f, "--set", set], 1, &[&format!("--set {set}"), frag]);
    }
}

#[test]
fn an_infeasible_specification_is_not_reported_converged() {
    // DV column with D = 90 kmol/h from F = 60 kmol/h: Newton meets its equations with the
    // condenser holdup on its floor and a distillate whose fractions sum to 0.35.
    expect(
        &["steady", &case("column_a_dv_distillate_gt_feed_dishonest.json")],
        2,
        &[
            "not a valid steady state",
            "distillate",
            "sum of its mole fractions",
            "column.M[41] rests on its lower bound",
        ],
    );
    // A valve-drained flash with 1.5 MW: the drum runs empty. Newton either meets its equations
    // there (the liquid's fractions sum to 0.54: the certificate refuses it) or stops at a singular
    // Jacobian on the way, depending on rounding in a nearly singular matrix; either answer must
    // exit 2 and name the dry drum.
    expect(&["steady", &case("bt_flash_empty_drum_dishonest.json")], 2, &["drum.M rests on its lower bound"]);
}

#[test]
fn a_saturated_loop_off_setpoint_is_a_warning_in_text_and_json() {
    let file = case("column_a_xd_controller_saturated_silent.json");
    let (out, _) = timed(&["steady", &file]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0));
    assert!(stdout.contains("warning: controller `xd` is saturated") && stdout.contains("op_max"), "{stdout}");
    let (out, _) = timed(&["steady", &file, "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let w = &v["warnings"][0];
    assert_eq!(w["path"], "xd.op");
    assert_eq!(w["limit"], "op_max");
    // The limit is 2.8 kmol/min; the offset is the measured xD minus its setpoint 0.9999.
    assert!((w["value"].as_f64().unwrap() - 2.8 / 0.06).abs() < 1e-9);
    let xd = v["values"]["distillate.x[light]"].as_f64().unwrap();
    assert!((w["offset"].as_f64().unwrap() - (xd - 0.9999)).abs() < 1e-9 && xd < 0.999);
    // A loop within its limits gives no warning.
    let (out, _) = timed(&["steady", &harness::flowsheet("column_a.json"), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(v["warnings"], serde_json::json!([]));
}

#[test]
fn the_certificate_fails_on_a_state_that_violates_a_balance() {
    let (plant, ss) = harness::converge("column_a.json");
    assert!(certify(&plant, &ss.x, &ss.u).is_ok());
    let mut x = ss.x.clone();
    let d = plant.var("distillate.F").unwrap();
    x[d] *= 1.0 + 1e-6;
    let e = certify(&plant, &x, &ss.u).expect_err("a 1e-6 excess distillate breaks the column's balance");
    assert_eq!(e.unit, "column");
    assert!(e.equation.contains("balance") && e.relative.abs() > 1e-8, "{e}");
    let plant = load_file(std::path::Path::new(&harness::flowsheet("example_4_1.json"))).unwrap();
    let u = plant.input_values();
    let ss = steady_state(&plant, &u, None, &NewtonSettings::default()).unwrap();
    let mut x = ss.x.clone();
    let b = plant.var("bottoms.x[light]").unwrap();
    x[b] += 1e-6;
    let e = certify(&plant, &x, &u).expect_err("fractions no longer sum to 1");
    assert_eq!(e.unit, "bottoms");
}

/// A two-column methanol–water plant written as a new user would: its cold-start guess has dry
/// trays (a singular Jacobian there), which was reported as "the inventory of `lp` is uncontrolled"
/// although every drum and sump has a level loop. The diagnosis is now confirmed or refuted at the
/// converged point: the plant converges, and the true problem — `lp_xB` saturated at op_min — is a
/// warning. About 10 s in release, a minute in the test profile: run with `-- --include-ignored`.
#[test]
#[ignore = "slow: a two-column methanol-water plant from a dry-tray guess, about a minute in the test profile"]
fn a_singular_guess_is_not_called_an_uncontrolled_inventory() {
    let file = case("meoh_2col_design.json");
    let out = harness::command().args(["steady", &file, "--json"]).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(v["warnings"][0]["path"], "lp_xB.op");
    assert_eq!(v["warnings"][0]["limit"], "op_min");
}

/// A record interval of 1e-300 s over 1e12 s asks for infinitely many rows (the quotient overflows):
/// refused like any other request above the row limit (it grew the heap past 2 GiB in the fuzzer).
#[test]
fn a_record_request_that_overflows_is_refused() {
    let plant = load_file(std::path::Path::new(&harness::flowsheet("surge_tank_pi.json"))).unwrap();
    let text = r#"{"format_version": 1, "duration": "1e12 s", "events": [],
        "record": {"interval": "1e-300 s", "paths": ["tank.level"]}}"#;
    let spec = plantwide::flowsheet::scenario::parse_scenario(text, "s.json").unwrap();
    let e = plantwide::flowsheet::scenario::resolve(&spec, &plant, "s.json").expect_err("refused");
    let msg = e.to_string();
    assert!(msg.contains("record.interval") && msg.contains("PLANTWIDE_MAX_RECORD_ROWS"), "{msg}");
}

/// A named change to a flowsheet document and the fragments its error must contain.
type Mutation = (&'static str, fn(&mut serde_json::Value), &'static [&'static str]);

/// Values the fuzzer found silently accepted in a file, each refused naming its field.
#[test]
fn implausible_file_values_are_refused_naming_the_field() {
    let text = std::fs::read_to_string(harness::flowsheet("column_a.json")).unwrap();
    let base: serde_json::Value = serde_json::from_str(&text).unwrap();
    let dir = std::env::temp_dir().join(format!("plantwide-hostile-values-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases: [Mutation; 4] = [
        (
            "temperature_sp",
            |d| {
                d["controllers"]["t"] = serde_json::json!({"type": "pid", "pv": "column.T[10]", "output": "column.reflux",
                    "sp": -1e308, "kc": 1.0, "tau_i": "10 min"});
                d["controllers"]["condenser_level"]["output"] = serde_json::json!("column.distillate");
            },
            &["controllers.t.sp", "-1e308 K is beyond the ±5000 K"],
        ),
        (
            "op_limits_reversed",
            |d| {
                d["controllers"]["condenser_level"]["op_min"] = serde_json::json!("2 kmol/min");
                d["controllers"]["condenser_level"]["op_max"] = serde_json::json!("1 kmol/min");
            },
            &["controllers.condenser_level.op_max", "must exceed op_min"],
        ),
        (
            "molar_mass",
            |d| d["components"][0]["hypothetical"]["mw"] = serde_json::json!(9e18),
            &["components[0].hypothetical.mw", "beyond the plausible"],
        ),
        (
            "tiny_temperature_guess",
            |d| d["units"]["feed_source"]["P"] = serde_json::json!(1e-300),
            &["units.feed_source.P"],
        ),
    ];
    for (name, mutate, fragments) in cases {
        let mut doc = base.clone();
        mutate(&mut doc);
        let path = dir.join(format!("{name}.json"));
        std::fs::write(&path, doc.to_string()).unwrap();
        expect(&["check", path.to_str().unwrap()], 1, fragments);
    }
    std::fs::remove_dir_all(&dir).ok();
}
