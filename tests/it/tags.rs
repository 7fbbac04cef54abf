//! Tags (issue 57): named quantities computed from plant variables by an expression, with the
//! flowsheet's `parameters` carrying units (`$` included). Checked on column A's operating cost
//! `J = p_F F + p_V V − p_D D − p_B B` (Skogestad 2000) against its closed forms: with both levels
//! held by D and B (LV configuration), `D = V − L` and `B = F − D` at steady state, so
//! `J = L − (1 − p_V/(1 $/mol))·V` in $/s per mol/s of L and V, whatever the column does.

use std::path::Path;

use plantwide::flowsheet::load_file;
use plantwide::solve::{NewtonSettings, steady_state};

use crate::harness::{fixture, plantwide, value};

const FILE: &str = "data/column_a_tags.json";
/// Prices of tests/data/column_a_tags.json, $/mol.
const P_F: f64 = 1.0;
const P_V: f64 = 0.01;
const P_D: f64 = 2.0;
const P_B: f64 = 1.0;

fn json(args: &[&str]) -> serde_json::Value {
    let out = plantwide(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("--json prints JSON")
}

/// Exit code 1 and the message.
fn refused(text: &str) -> String {
    let dir = std::env::temp_dir().join(format!("plantwide-tags-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!("bad{}.json", text.len()));
    std::fs::write(&file, text).unwrap();
    let out = plantwide(&["check", file.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stdout));
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// tests/data/column_a_tags.json with its `tags` and `parameters` replaced.
fn with_tags(tags: serde_json::Value, parameters: Option<serde_json::Value>) -> String {
    let mut d: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(fixture(FILE)).unwrap()).unwrap();
    d["tags"] = tags;
    if let Some(p) = parameters {
        d["parameters"] = p;
    }
    d.to_string()
}

#[test]
fn the_cost_tag_is_its_expression_at_the_steady_state_and_its_gains_follow_the_mass_balance() {
    let plant = load_file(Path::new(&fixture(FILE))).unwrap();
    let ss = steady_state(&plant, &plant.input_values(), None, &NewtonSettings::default()).unwrap();
    let v = |p: &str| value(&plant, &ss.x, p);
    let u = |p: &str| ss.u[plant.input(p).unwrap()];
    let (f, l, boil) = (u("feed_source.F"), u("column.reflux"), u("column.boilup"));
    let (d, b) = (v("condenser_level.op"), v("reboiler_level.op"));
    let j = P_F * f + P_V * boil - P_D * d - P_B * b;
    assert!((v("cost.value") - j).abs() <= 1e-12 * j.abs(), "{} vs {j}", v("cost.value"));
    // The closed form through the balances: J = L − (1 − p_V)·V.
    assert!((j - (l - (1.0 - P_V) * boil)).abs() < 1e-8, "{j}");
    let imp = v("column.x[41][heavy]") + v("column.x[1][light]");
    assert!((v("impurity.value") - imp).abs() <= 1e-15, "{imp}");

    // Gains: ∂J/∂L = 1 and ∂J/∂V = −(1 − p_V) exactly (the balances are linear); the impurity's
    // gains are the sums of its two terms' gains, computed as outputs of their own.
    let g = json(&[
        "gains",
        &fixture(FILE),
        "--inputs",
        "column.reflux,column.boilup",
        "--outputs",
        "cost.value,impurity.value,column.x[41][heavy],column.x[1][light]",
        "--json",
    ]);
    let k = |i: usize, j: usize| g["gain"][i][j].as_f64().unwrap_or_else(|| panic!("gain[{i}][{j}] in {g}"));
    assert!((k(0, 0) - 1.0).abs() < 1e-9, "∂J/∂L = {}", k(0, 0));
    assert!((k(0, 1) + (1.0 - P_V)).abs() < 1e-9, "∂J/∂V = {}", k(0, 1));
    for j in 0..2 {
        let sum = k(2, j) + k(3, j);
        assert!((k(1, j) - sum).abs() <= 1e-10 * sum.abs(), "impurity gain {j}: {} vs {sum}", k(1, j));
    }
}

/// A design spec on a tag: `J = −8 $/s` by the boilup at the file's reflux has the closed form
/// `V = (L − J)/(1 − p_V)`.
#[test]
fn a_spec_on_a_tag_finds_the_boilup_of_the_closed_form() {
    let out = json(&["steady", &fixture(FILE), "--spec", "cost.value=-28800 $/h", "--vary", "column.boilup", "--json"]);
    let l = 2.70629e3 / 60.0;
    let want = (l + 8.0) / (1.0 - P_V);
    let got = out["values"]["column.boilup"].as_f64().unwrap_or_else(|| panic!("{}", out["values"]));
    assert!((got - want).abs() < 1e-7 * want, "V = {got} mol/s, closed form {want}");
    assert!((out["values"]["cost.value"].as_f64().unwrap() + 8.0).abs() < 1e-9);
}

/// In a run the tag is computed at every recorded time from the same variables.
#[test]
fn a_run_records_the_tag_as_its_expression_at_every_time() {
    let dir = std::env::temp_dir().join(format!("plantwide-tags-run-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("run.csv");
    let scen = fixture("data/scenarios/column_a_tags_boilup_step.json");
    let out = plantwide(&["run", &fixture(FILE), "--scenario", &scen, "--csv", csv.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<Vec<f64>> =
        text.lines().skip(1).map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
    assert!(rows.len() >= 31, "{} rows", rows.len());
    let mut moved = 0.0f64;
    for r in &rows {
        let (j, imp, f, boil, d, b, xd, xb) = (r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8]);
        let want = P_F * f + P_V * boil - P_D * d - P_B * b;
        assert!((j - want).abs() <= 1e-12 * want.abs(), "t = {}: {j} vs {want}", r[0]);
        assert!((imp - (xd + xb)).abs() <= 1e-15, "t = {}", r[0]);
        moved = moved.max((j - rows[0][1]).abs());
    }
    assert!(moved > 1e-3, "the step moves the cost ({moved} $/s)");
}

#[test]
fn bad_tags_are_refused_with_the_field_the_position_and_a_suggestion() {
    let msg = refused(&with_tags(serde_json::json!({"cost": "p_F*feed_source.F + column.boilup"}), None));
    assert!(msg.contains("tags.cost.expression") && msg.contains("$/s and mol/s") && msg.contains("^"), "{msg}");

    let msg = refused(&with_tags(serde_json::json!({"cost": "p_V*column.boilp"}), None));
    assert!(msg.contains("no variable, input or parameter `column.boilp`"), "{msg}");
    assert!(msg.contains("did you mean `column.boilup`") && msg.contains("^^^^^^^^^^^^"), "{msg}");

    let tag = serde_json::json!({"cost": {"expression": "p_V*column.boilup", "unit": "kg/s"}});
    let msg = refused(&with_tags(tag, None));
    assert!(msg.contains("tags.cost.unit") && msg.contains("a cost rate") && msg.contains("a mass flow"), "{msg}");

    let msg = refused(&with_tags(serde_json::json!({"column": "column.boilup"}), None));
    assert!(msg.contains("tags.column") && msg.contains("name space"), "{msg}");

    let msg = refused(&with_tags(
        serde_json::json!({"c": "q*column.boilup"}),
        Some(serde_json::json!({"q": "3 $/lightyear"})),
    ));
    assert!(msg.contains("parameters.q"), "{msg}");

    let msg = refused(&with_tags(serde_json::json!({"c": "der(column.boilup)"}), None));
    assert!(msg.contains("tags.c.expression"), "{msg}");
}

/// btx_column_pressure.json (its top pressure a state) with the tags a plant's own instrument list
/// would give (issue 56, item 5): a measurement in gauge pressure, a manipulated input in kW and a
/// gas flow in kscmh, under names that are not identifiers. Written to a temporary folder.
fn instrument_tagged() -> (std::path::PathBuf, std::path::PathBuf) {
    let text = std::fs::read_to_string(crate::harness::flowsheet("btx_column_pressure.json")).unwrap();
    let mut d: serde_json::Value = serde_json::from_str(&text).unwrap();
    d["tags"] = serde_json::json!({
        "XMEAS(7)": "column.P@kPag",
        "XMV(10)": "column.reboiler_duty @ kW",
        "FI-101": {"expression": "feed_source.F", "unit": "kscmh", "description": "feed, as gas at 0 degC and 1 atm"}
    });
    let dir = std::env::temp_dir().join(format!("plantwide-named-tags-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("btx_tagged.json");
    std::fs::write(&file, d.to_string()).unwrap();
    (dir, file)
}

/// `steady --json` prints each tag in its unit, checked against the variables it names and the
/// units' definitions written out here: kPag = (P − 101325 Pa)/1000; 1 kscmh = 10³ m³/h of ideal
/// gas at 0 °C and 1 atm, 22.41396954 L/mol (CODATA 2018), so 100 kmol/h is 2.241396954 kscmh.
/// A `--set` through a tag naming an input is the same edit as through the input's path.
#[test]
fn named_tags_print_in_their_units_and_stand_for_their_paths_in_set() {
    let (_dir, file) = instrument_tagged();
    let f = file.to_str().unwrap();
    let s = json(&["steady", f, "--set", "pressure_control.auto=0", "--json"]);
    let p = s["values"]["column.P"].as_f64().unwrap();
    let kpag = s["tags"]["XMEAS(7)"].as_f64().unwrap();
    assert!((kpag - (p - 101_325.0) / 1e3).abs() < 1e-9, "{kpag} kPag against P = {p} Pa");
    assert!((s["tags"]["XMV(10)"].as_f64().unwrap() - 1100.0).abs() < 1e-9, "{}", s["tags"]);
    assert!((s["tags"]["FI-101"].as_f64().unwrap() - 2.241_396_954).abs() < 1e-8, "{}", s["tags"]);

    let by_tag = json(&["steady", f, "--set", "pressure_control.auto=0", "--set", "XMV(10)=1.2 MW", "--json"]);
    let by_path =
        json(&["steady", f, "--set", "pressure_control.auto=0", "--set", "column.reboiler_duty=1.2 MW", "--json"]);
    assert_eq!(by_tag["values"], by_path["values"]);
    assert!((by_tag["tags"]["XMV(10)"].as_f64().unwrap() - 1200.0).abs() < 1e-9);
    assert!(by_tag["values"]["column.P"].as_f64().unwrap() > p + 1e3, "more boil-up raises the floating pressure");
}

/// `gains` named by tags equals `gains` named by the paths in the tags' units, and reports the
/// tags' units.
#[test]
fn gains_between_tags_are_the_gains_between_their_paths_in_their_units() {
    let (_dir, file) = instrument_tagged();
    let f = file.to_str().unwrap();
    let open = ["--set", "pressure_control.auto=0", "--json"];
    let by_tag = json(&[&["gains", f, "--inputs", "XMV(10),FI-101", "--outputs", "XMEAS(7)"][..], &open].concat());
    let by_path = json(
        &[
            &["gains", f, "--inputs", "column.reboiler_duty@kW,feed_source.F@kscmh", "--outputs", "column.P@kPa"][..],
            &open,
        ]
        .concat(),
    );
    let (gt, gp) = (&by_tag["gain"][0], &by_path["gain"][0]);
    for j in 0..2 {
        let (a, b) = (gt[j].as_f64().unwrap(), gp[j].as_f64().unwrap());
        assert!(b.abs() > 1e-6 && (a - b).abs() <= 1e-12 * b.abs(), "gain {j}: {a} against {b}");
    }
    let units = by_tag.to_string();
    assert!(units.contains("\"kPag\"") && units.contains("\"kscmh\"") && units.contains("\"kW\""), "{units}");
}

/// A run records a tag under its name in its unit, and an event may move an input by its tag: the
/// trend equals the path's, recorded beside it in SI, converted by kPag's definition.
#[test]
fn a_run_records_tags_in_their_units_and_steps_an_input_by_its_tag() {
    let (dir, file) = instrument_tagged();
    let scenario = serde_json::json!({
        "format_version": 1,
        "duration": "20 min",
        "events": [{"type": "step", "at": "2 min", "path": "XMV(10)", "to": "1155 kW"}],
        "record": {"interval": "1 min", "time_unit": "min", "paths": ["XMEAS(7)", "column.P", "XMV(10)"]}
    });
    let scen = dir.join("duty_step.json");
    std::fs::write(&scen, scenario.to_string()).unwrap();
    let csv = dir.join("run.csv");
    let args = ["run", file.to_str().unwrap(), "--scenario", scen.to_str().unwrap(), "--csv", csv.to_str().unwrap()];
    let out = plantwide(&[&args[..], &["--set", "pressure_control.auto=0", "--units", "metric"]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    let header = text.lines().next().unwrap();
    assert!(header.contains("XMEAS(7) [kPag]") && header.contains("XMV(10) [kW]"), "{header}");
    assert!(header.contains("column.P [kPa]"), "--units metric shows the path in kPa: {header}");
    let rows: Vec<Vec<f64>> =
        text.lines().skip(1).map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
    for r in &rows {
        assert!((r[1] - (r[2] - 101.325)).abs() < 1e-9, "t = {} min: {} kPag against {} kPa", r[0], r[1], r[2]);
    }
    let (first, last) = (&rows[0], &rows[rows.len() - 1]);
    assert!((first[3] - 1100.0).abs() < 1e-9 && (last[3] - 1155.0).abs() < 1e-9, "{first:?} … {last:?}");
    assert!(last[1] > first[1] + 0.1, "the step raises the floating pressure: {} → {} kPag", first[1], last[1]);
}

#[test]
fn bad_named_tags_are_refused_with_the_fix() {
    let base = |tags: serde_json::Value| {
        let text = std::fs::read_to_string(crate::harness::flowsheet("btx_column_pressure.json")).unwrap();
        let mut d: serde_json::Value = serde_json::from_str(&text).unwrap();
        d["tags"] = tags;
        d.to_string()
    };
    let msg = refused(&base(serde_json::json!({"PI.101": "column.P@kPag"})));
    assert!(msg.contains("tags.PI.101") && msg.contains("without '.'"), "{msg}");
    let msg = refused(&base(serde_json::json!({"PI-101": {"expression": "column.P@kPag", "unit": "bar"}})));
    assert!(msg.contains("tags.PI-101.unit") && msg.contains("given twice"), "{msg}");
    let msg = refused(&base(serde_json::json!({"PI-101": "column.P@kscmh"})));
    assert!(msg.contains("tags.PI-101.unit") && msg.contains("a pressure") && msg.contains("a molar flow"), "{msg}");
    let msg = refused(&base(serde_json::json!({"PI-101": "column.P@furlong"})));
    assert!(msg.contains("tags.PI-101.unit") && msg.contains("furlong"), "{msg}");
}
