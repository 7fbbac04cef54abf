//! The `plantwide` command line: output formats, overrides and exit codes.

use crate::harness::{self, plantwide};

fn steady_json(args: &[&str]) -> serde_json::Value {
    let mut all = vec!["steady", "--json"];
    all.extend_from_slice(args);
    let out = plantwide(&all);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn steady_json_has_the_documented_shape() {
    let v = steady_json(&[&harness::flowsheet("column_a.json")]);
    assert_eq!(v["converged"], true);
    assert!(v["iterations"].as_u64().is_some());
    assert!(v["residual"].as_f64().is_some_and(|r| r < 1e-9));
    let values = v["values"].as_object().unwrap();
    // Every stream and unit variable under its path, in SI units, plus free inputs.
    for path in [
        "feed.F",
        "distillate.x[light]",
        "bottoms.T",
        "column.M[41]",
        "column.x[21][light]",
        "condenser_level.op",
        "column.reflux",
    ] {
        assert!(values.contains_key(path), "missing {path}");
    }
    assert!((values["distillate.x[light]"].as_f64().unwrap() - 0.99).abs() < 1e-6);
    assert!((values["column.reflux"].as_f64().unwrap() - 2.70629e3 / 60.0).abs() < 1e-9);
}

#[test]
fn set_overrides_an_input_through_its_stream_and_a_unit_field() {
    // `feed.F` names the stream; the input belongs to the feed unit that produces it.
    let v = steady_json(&[&harness::flowsheet("column_a.json"), "--set", "feed.F=1.01kmol/min"]);
    let f = v["values"]["feed.F"].as_f64().unwrap();
    assert!((f - 1010.0 / 60.0).abs() < 1e-9, "feed.F = {f}");
    // The mass balance moves the extra feed to the products.
    let d = v["values"]["distillate.F"].as_f64().unwrap();
    let b = v["values"]["bottoms.F"].as_f64().unwrap();
    assert!((d + b - f).abs() < 1e-9 * f);
    // A unit parameter that is not an input: the tray holdup.
    let v = steady_json(&[&harness::flowsheet("column_a.json"), "--set", "column.tray_holdup=1kmol"]);
    assert!((v["values"]["column.M[10]"].as_f64().unwrap() - 1000.0).abs() < 1e-6);
}

#[test]
fn bad_overrides_are_user_errors() {
    let out = plantwide(&["steady", &harness::flowsheet("column_a.json"), "--set", "column.trays=3"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("`column` has no field `trays`"));
    let out = plantwide(&["steady", &harness::flowsheet("column_a.json"), "--set", "feed.F=3 K"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("is a temperature but a molar flow is expected"));
    let out = plantwide(&["steady", &harness::flowsheet("column_a.json"), "--set", "column.distillate=1kmol/min"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("driven by a controller"));
}

/// A duty that vaporizes the whole feed leaves the drum without liquid: there is no steady state,
/// and the failure is numerical (exit 2) with the worst equation named.
#[test]
fn no_steady_state_is_a_numerical_failure_naming_the_worst_equation() {
    let out = plantwide(&["steady", &harness::flowsheet("flash_recycle.json"), "--set", "heater.duty=1.6MW"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("steady state not found") && err.contains("worst equation:") && err.contains("variable"),
        "{err}"
    );
}

/// A PI level controller whose output sits at its upper limit at the cold-start guess (level guessed
/// 0.8 m above a 0.2 m setpoint with Kc = 500 mol/s/m: the unclamped output is 450 mol/s, the limit
/// 60). Clamped, the outflow no longer depends on the level and the Jacobian is singular there,
/// but the plant is well posed: the degrees-of-freedom probe must not call it "not determined", and
/// the steady state has the level on its setpoint and the outflow equal to the inflow.
#[test]
fn a_controller_at_its_limit_at_the_guess_is_not_called_undetermined() {
    let mut spec: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(harness::flowsheet("surge_tank_pi.json")).unwrap()).unwrap();
    let lc = &mut spec["controllers"]["lc"];
    lc["op_max"] = "60 mol/s".into();
    lc["kc"] = "500 mol/s/m".into();
    lc["sp"] = "0.2 m".into();
    let path = std::env::temp_dir().join(format!("plantwide_saturated_guess_{}.json", std::process::id()));
    std::fs::write(&path, serde_json::to_string(&spec).unwrap()).unwrap();
    let out = steady_json(&[path.to_str().unwrap()]);
    std::fs::remove_file(&path).unwrap();
    let v = &out["values"];
    assert!((v["tank.level"].as_f64().unwrap() - 0.2).abs() < 1e-9, "{v}");
    assert!((v["lc.op"].as_f64().unwrap() - 50.0).abs() < 1e-9, "{v}");
}

#[test]
fn components_lists_the_library() {
    let out = plantwide(&["components"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for c in ["water", "ethanol", "benzene", "toluene", "o-xylene", "diphenyl", "hydrogen", "nrtl"] {
        assert!(text.contains(c), "missing {c}");
    }
}

/// `--set PATH=VALUE` of an input is the same edit in the file: the same inputs, the same
/// cold-start guess to the bit, the same sequential-modular passes and Newton iterations, the same
/// steady state. (The feed's guess read the file's flow, pressure, temperature and composition
/// instead of its inputs: `--set feed_source.F=540 kmol/h` on the newcomer's 150 kmol/h column
/// started Newton from a column profile for 150 kmol/h and failed, Singular, where the file edit
/// converged in one iteration.) The file edits are made on the JSON text here, independently of
/// `--set`'s own machinery.
#[test]
fn set_of_an_input_converges_as_the_same_edit_in_the_file() {
    use plantwide::flowsheet::{Override, load_str, load_with};
    use plantwide::solve::{StrategySettings, converge};
    use serde_json::json;
    let cases = [
        (
            harness::fixture("data/newcomer3/bt_column.json"),
            "feed_source.F",
            "540 kmol/h",
            ("feed_source", "F", json!("540 kmol/h")),
        ),
        (
            harness::flowsheet("column_a.json"),
            "feed_source.F",
            "1.2 kmol/min",
            ("feed_source", "F", json!("1.2 kmol/min")),
        ),
        (
            harness::flowsheet("column_a.json"),
            "feed_source.z[light]",
            "0.6",
            ("feed_source", "z", json!({"light": 0.6, "heavy": 0.4})),
        ),
        (harness::flowsheet("two_column_plant.json"), "fresh_A.F", "110 kmol/h", ("fresh_A", "F", json!("110 kmol/h"))),
    ];
    for (file, path, value, (unit, field, edit)) in cases {
        let text = std::fs::read_to_string(&file).unwrap();
        let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
        doc["units"][unit][field] = edit;
        let by_file = load_str(&doc.to_string(), &file).unwrap_or_else(|e| panic!("{e}"));
        let by_set = load_with(std::path::Path::new(&file), &[Override::new(path, value)]).unwrap();
        assert_eq!(by_set.input_values(), by_file.input_values(), "{file}: {path}");
        assert_eq!(by_set.initial_guess(), by_file.initial_guess(), "{file}: {path}: cold-start guess");
        let settings = StrategySettings::default();
        let (a, b) = (converge(&by_set, &settings).unwrap(), converge(&by_file, &settings).unwrap());
        let passes =
            |s: &plantwide::solve::Solution| s.sm.as_ref().map(|r| r.sccs.iter().map(|c| c.passes).sum::<usize>());
        let newton = |s: &plantwide::solve::Solution| s.newton.as_ref().map(|r| r.iterations);
        eprintln!("{file} {path}={value}: passes {:?}, Newton {:?}", passes(&a), newton(&a));
        assert_eq!((passes(&a), newton(&a)), (passes(&b), newton(&b)), "{file}: {path}");
        let worst = a.x.iter().zip(&b.x).map(|(p, q)| (p - q).abs() / q.abs().max(1e-3)).fold(0.0, f64::max);
        assert!(worst <= 1e-10, "{file}: {path}: {worst:e}");
    }
    // The newcomer's command itself.
    let out =
        plantwide(&["steady", &harness::fixture("data/newcomer3/bt_column.json"), "--set", "feed_source.F=540 kmol/h"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && text.contains("converged in 1 iterations"),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A number without a unit is read in SI, which a user may not have meant (newcomer3 D6: `--set
/// feed_source.T=80` made an 80 K liquid feed, and a file's `"F": 150` is 150 mol/s, not kmol/h):
/// each gets a note naming the field, what it was read as and what to write. A number with its
/// unit, a dimensionless one, and every shipped flowsheet get none.
#[test]
fn a_number_without_a_unit_gets_a_note_of_what_it_was_read_as() {
    let stderr = |args: &[&str]| {
        let out = plantwide(args);
        assert!(out.status.success(), "{:?}: {}", args, String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let hx = harness::fixture("data/newcomer3/with_hx.json");
    let note = stderr(&["steady", &hx, "--set", "feed_source.T=80"]);
    assert!(note.contains("--set feed_source.T: 80 has no unit and is read in SI, as 80 K"), "{note}");
    assert!(note.contains(r#""80 degC""#), "{note}");
    assert!(!stderr(&["steady", &hx, "--set", "feed_source.T=80 degC"]).contains("no unit"));
    assert!(!stderr(&["steady", &hx, "--set", "feed_source.z[benzene]=0.45"]).contains("no unit"));
    let bare = stderr(&["check", &harness::fixture("data/newcomer3/unit_bare_number_150.json")]);
    assert!(bare.contains("units.feed_source.F: 150 has no unit and is read in SI, as 150 mol/s"), "{bare}");
    for entry in std::fs::read_dir(format!("{}/flowsheets", env!("CARGO_MANIFEST_DIR"))).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if name.ends_with(".json") && !name.ends_with(".schema.json") {
            let text = stderr(&["check", path.to_str().unwrap()]);
            assert!(!text.contains("no unit"), "{name}: {text}");
        }
    }
}

/// A step of a temperature by a percentage is refused (newcomer3 D16: "+5 %" of the feed's
/// 313.15 K was 15.66 K, unstated, where 5 % of its 40 degC is 2 K), naming both readings and
/// the form to use (the same step as a difference runs: `compare.rs`, `feed_source.T=+5 K`).
#[test]
fn a_percentage_step_of_a_temperature_is_refused_with_both_readings() {
    let files = [harness::fixture("data/newcomer3/with_hx.json"), harness::fixture("data/newcomer3/without_hx.json")];
    let compare = |step: &str| {
        plantwide(&["compare", &files[0], &files[1], "--disturbances", step, "--outputs", "distillate.x[benzene]"])
    };
    let out = compare("feed_source.T=+5%");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("5 % of 313.15 K is 15.6575 K, of 40 degC 2 K") && err.contains("feed_source.T=+5 K"),
        "{err}"
    );
    let bare = plantwide(&[
        "compare",
        &files[0],
        &files[1],
        "--disturbances",
        "feed_source.T",
        "--outputs",
        "distillate.x[benzene]",
    ]);
    assert_eq!(bare.status.code(), Some(1), "PATH alone steps 10 %: {}", String::from_utf8_lossy(&bare.stderr));
}

/// A controller's inputs in `gains`: a driven input's message names what to move given the
/// controller's mode (in manual its setpoint moves nothing, and `gains` on it printed an all-zero
/// matrix with exit 0; the message sent the tutorial's writer there), and a manual controller's
/// setpoint is refused.
#[test]
fn gains_on_a_controllers_inputs_name_what_moves_in_its_mode() {
    let file = format!("{}/docs/tutorial/bt_column.json", harness::ROOT);
    let outputs = "distillate.x[benzene],column.T[8]";
    let manual = ["--set", "top_composition.auto=0", "--set", "tray_temperature.auto=0"];
    let err = |args: &[&str]| {
        let out = plantwide(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let driven = ["gains", &file, "--inputs", "column.reflux,column.reboiler_duty", "--outputs", outputs];
    let e = err(&[&driven[..], &manual[..]].concat());
    assert!(e.contains("`top_composition` is in manual: move its manual output `top_composition.op_manual`"), "{e}");
    assert!(
        err(&driven).contains("or its manual output `top_composition.op_manual` with --set `top_composition.auto=0`")
    );
    let sp = ["gains", &file, "--inputs", "top_composition.sp,tray_temperature.sp", "--outputs", outputs];
    let e = err(&[&sp[..], &manual[..]].concat());
    assert!(
        e.contains("`top_composition.sp` is the setpoint of `top_composition`, which is in manual: it moves nothing"),
        "{e}"
    );
    let open =
        ["gains", &file, "--inputs", "top_composition.op_manual,tray_temperature.op_manual", "--outputs", outputs];
    let out = plantwide(&[&open[..], &manual[..]].concat());
    assert!(out.status.success() && String::from_utf8_lossy(&out.stdout).contains("RGA number: 6.0310"));
}
