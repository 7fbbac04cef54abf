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
