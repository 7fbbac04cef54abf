//! Design specifications (`"specs"` in a file, `steady --spec PATH=VALUE --vary INPUT`): against
//! Skogestad's published column A and against the second route to the same number, PI
//! controllers whose integral action forces the same errors to zero.

use plantwide::flowsheet::{Plant, load_file};
use plantwide::solve::{NewtonSettings, steady_state};

use crate::harness::{component_balance_error, fixture, flowsheet, plantwide, value};
use plantwide::model::limits::number;

const KMOL_PER_MIN: f64 = 1000.0 / 60.0;

fn stdout_json(args: &[&str]) -> serde_json::Value {
    let out = plantwide(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("--json prints JSON")
}

fn fails(args: &[&str], code: i32) -> String {
    let out = plantwide(args);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {}", String::from_utf8_lossy(&out.stdout));
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// S&P 2005 §12.4: yD = 0.99 and xB = 0.01 at L = 2.70629, V = 3.20629 kmol/min (six figures
/// published). The file starts at L = 2.0, V = 2.5 kmol/min and the cold-start guess: the specs
/// find the published reflux and boilup.
#[test]
fn purity_specs_on_both_ends_find_column_a_published_reflux_and_boilup_from_a_cold_start() {
    let plant = load_file(std::path::Path::new(&fixture("data/column_a_purity_specs.json"))).unwrap();
    assert_eq!(plant.specs().len(), 2);
    let u0 = plant.input_values();
    let (l, v) = (plant.input("L").unwrap(), plant.input("V").unwrap());
    assert!((u0[l] / KMOL_PER_MIN - 2.0).abs() < 1e-12, "the file starts away from the answer");
    let ss = steady_state(&plant, &u0, None, &NewtonSettings::default()).unwrap_or_else(|e| panic!("{e}"));
    assert!((ss.u[l] / KMOL_PER_MIN - 2.70629).abs() < 5e-6, "L = {} kmol/min", ss.u[l] / KMOL_PER_MIN);
    assert!((ss.u[v] / KMOL_PER_MIN - 3.20629).abs() < 5e-6, "V = {} kmol/min", ss.u[v] / KMOL_PER_MIN);
    assert!((value(&plant, &ss.x, "distillate.x[light]") - 0.99).abs() < 1e-12);
    assert!((value(&plant, &ss.x, "bottoms.x[light]") - 0.01).abs() < 1e-12);
    assert!(component_balance_error(&plant, &ss.x, &[]) < 1e-10);
    // The reported point is the plant's steady state at the inputs found: reconverged with the
    // specs fixed, nothing moves.
    let mut fixed: Plant = plant.clone();
    fixed.fix_specs(&ss.u);
    assert!(fixed.specs().is_empty() && fixed.spec().specs.is_empty());
    let again = steady_state(&fixed, &fixed.input_values(), Some(&ss.x), &NewtonSettings::default()).unwrap();
    let drift = ss.x.iter().zip(&again.x).map(|(a, b)| (a - b).abs() / b.abs().max(1e-3)).fold(0.0, f64::max);
    assert!(drift < 1e-9, "relative drift {drift:.2e}");
}

/// Two routes to one number: the spec on `column_a.json` and the PI composition loops of
/// `column_a_lv.json` (same column, same inputs) at the same setpoints, each to the Newton
/// tolerance; their reflux and boilup agree to 1e-8 relative, at the published point and two more.
#[test]
fn a_spec_answer_equals_the_answer_of_a_pi_controller_on_the_same_input() {
    for (xd, xb) in [("0.99", "0.01"), ("0.995", "0.005"), ("0.999", "0.001")] {
        let spec = stdout_json(&[
            "steady",
            &flowsheet("column_a.json"),
            "--spec",
            &format!("distillate.x[light]={xd}"),
            "--vary",
            "column.reflux",
            "--spec",
            &format!("bottoms.x[light]={xb}"),
            "--vary",
            "V",
            "--json",
        ]);
        let pi = stdout_json(&[
            "steady",
            &flowsheet("column_a_lv.json"),
            "--set",
            &format!("top_composition.sp={xd}"),
            "--set",
            &format!("bottom_composition.sp={xb}"),
            // The file's output limits (6 kmol/min) would hold 0.999/0.001 short of its setpoints.
            "--set",
            "top_composition.op_max=20 kmol/min",
            "--set",
            "bottom_composition.op_max=20 kmol/min",
            "--json",
        ]);
        let pairs = [("column.reflux", "top_composition.op"), ("column.boilup", "bottom_composition.op")];
        for (input, op) in pairs {
            let (a, b) = (spec["values"][input].as_f64().unwrap(), pi["values"][op].as_f64().unwrap());
            assert!((a - b).abs() < 1e-8 * b.abs(), "{xd}/{xb}: spec {input} = {a}, PI {op} = {b}");
        }
        let met = spec["specs"].as_array().unwrap();
        assert_eq!(met.len(), 2);
        assert_eq!(met[1]["vary"], "column.boilup", "an alias resolves to the input path");
        assert_eq!(met[1]["input_value"], spec["values"]["column.boilup"]);
        assert!((met[0]["value"].as_f64().unwrap() - xd.parse::<f64>().unwrap()).abs() < 1e-12);
    }
}

/// The analyses start from the design point: gains of the spec'd file equal those of column A at
/// its published inputs (the same plant), to the precision of the published inputs.
#[test]
fn analyses_of_a_file_with_specs_start_at_the_point_the_specs_define() {
    let args = |file: &str| {
        let mut a = vec!["gains".to_string(), file.to_string()];
        a.extend(["--inputs", "L,V", "--outputs", "distillate.x[light],bottoms.x[light]", "--json"].map(String::from));
        a
    };
    let run = |file: &str| {
        let a = args(file);
        stdout_json(&a.iter().map(String::as_str).collect::<Vec<_>>())["gain"].clone()
    };
    let (spec, plain) = (run(&fixture("data/column_a_purity_specs.json")), run(&flowsheet("column_a.json")));
    for i in 0..2 {
        for j in 0..2 {
            let (a, b) = (spec[i][j].as_f64().unwrap(), plain[i][j].as_f64().unwrap());
            // The published inputs carry 6 figures: ~2e-6 relative in L and V, amplified ~100× in
            // the high-purity gains.
            assert!((a - b).abs() < 1e-3 * b.abs(), "G[{i}][{j}]: {a} vs {b}");
        }
    }
}

#[test]
fn an_infeasible_spec_exits_2_naming_it() {
    // D = B = F/2 (the level loops at their bias): 0.99 at both ends breaks the light balance.
    let err = fails(
        &[
            "steady",
            &flowsheet("column_a.json"),
            "--spec",
            "distillate.x[light]=0.99",
            "--vary",
            "L",
            "--spec",
            "bottoms.x[light]=0.99",
            "--vary",
            "V",
        ],
        2,
    );
    assert!(err.contains("design spec") && err.contains("`bottoms.x[light] = 0.99` by `column.boilup`"), "{err}");
    // Beyond the column's separating power: 41 stages give at most ~1e8 separation factor at
    // total reflux (N_min = ln(1e8)/ln 1.5 = 45.4 stages are needed).
    let err = fails(
        &[
            "steady",
            &flowsheet("column_a.json"),
            "--spec",
            "distillate.x[light]=0.9999",
            "--vary",
            "L",
            "--spec",
            "bottoms.x[light]=0.0001",
            "--vary",
            "V",
        ],
        2,
    );
    assert!(err.contains("`distillate.x[light] = 0.9999` by `column.reflux`"), "{err}");
}

/// A spec no steady state can meet is reported by the offset the plant really gives and the way
/// its input would have to move. A spec's equation is linear, so every Newton step meets it: the
/// last iterate read "off by 0" and "needs more than the input can give" at a lower bound. The
/// newcomer's file asks xB = 0.5 of a 0.45 feed; its command asks xD = 0.2. Checked against the
/// plant converged without the specs at the file's inputs (the offset there) and moved a little
/// (the direction).
#[test]
fn an_infeasible_spec_says_which_way_its_input_must_move_and_by_how_much_it_is_off() {
    let file = fixture("data/newcomer3/spec_infeasible_in_file.json");
    let mut plant = load_file(std::path::Path::new(&file)).unwrap();
    plant.fix_specs(&plant.input_values());
    let at = |plant: &Plant, path: &str, factor: f64, read: &str| {
        let mut u = plant.input_values();
        u[plant.input(path).unwrap()] *= factor;
        let ss = steady_state(plant, &u, None, &NewtonSettings::default()).unwrap_or_else(|e| panic!("{e}"));
        value(plant, &ss.x, read)
    };
    let xb = at(&plant, "column.reboiler_duty", 1.0, "bottoms.x[benzene]");
    assert!(at(&plant, "column.reboiler_duty", 0.95, "bottoms.x[benzene]") > xb, "less duty, more benzene below");
    let err = fails(&["steady", &file], 2);
    eprintln!("{err}");
    let duty = err.split("`bottoms.x[benzene] = 0.5` by `column.reboiler_duty` (specs[1]):").nth(1).unwrap();
    assert!(
        duty.contains(&format!("`bottoms.x[benzene]` = {} (off by {:+.3e})", number(xb), xb - 0.5))
            && duty.contains("`column.reboiler_duty` would have to go lower")
            && duty.contains("the spec asks for less than the input can give"),
        "{err}"
    );
    assert!(!err.contains("off by 0.000e0") && !err.contains("more than the input can give"), "{err}");
    // Less reflux, less benzene on top: xD = 0.2 asks for less reflux than zero.
    let plain = load_file(std::path::Path::new(&fixture("data/newcomer3/bt_column.json"))).unwrap();
    let xd = at(&plain, "column.reflux", 1.0, "distillate.x[benzene]");
    assert!(at(&plain, "column.reflux", 0.9, "distillate.x[benzene]") < xd, "less reflux, less benzene on top");
    let file = fixture("data/newcomer3/bt_column.json");
    let err = fails(&["steady", &file, "--spec", "distillate.x[benzene]=0.2", "--vary", "column.reflux"], 2);
    assert!(
        err.contains(&format!("(off by {:+.3e})", xd - 0.2))
            && err.contains("`column.reflux` would have to go lower")
            && err.contains("the spec asks for less than the input can give"),
        "{err}"
    );
}

#[test]
fn spec_mistakes_exit_1_naming_the_spec_and_the_fix() {
    let col = flowsheet("column_a.json");
    let cases: [(&[&str], &str); 6] = [
        (&["--spec", "distillate.x[light]=0.99"], "each spec pairs with one varied input"),
        (&["--spec", "distilate.x[light]=0.99", "--vary", "L"], "did you mean `distillate.x[light]`"),
        (&["--spec", "distillate.x[light]=1.5", "--vary", "L"], "outside the range of `distillate.x[light]`"),
        (
            &["--spec", "distillate.x[light]=0.99", "--vary", "column.distillate"],
            "driven by controller `condenser_level`",
        ),
        (
            &["--spec", "distillate.x[light]=0.99", "--vary", "L", "--spec", "bottoms.x[light]=0.01", "--vary", "L"],
            "already varied",
        ),
        (&["--spec", "distillate.x[light]=0.99", "--vary", "L", "--method", "sm"], "whole-plant Newton"),
    ];
    for (extra, needle) in cases {
        let mut args = vec!["steady", col.as_str()];
        args.extend_from_slice(extra);
        let err = fails(&args, 1);
        assert!(err.contains(needle), "{extra:?}: {err}");
    }
    // A spec whose input cannot move its variable: the feed's temperature does not depend on the
    // reflux, so the DOF check finds the varied input loose.
    let err = fails(&["steady", &col, "--spec", "feed.T=350 K", "--vary", "L"], 1);
    assert!(err.contains("column.reflux (varied by the spec on `feed.T`)") && err.contains("vary an input"), "{err}");
}

#[test]
fn a_file_spec_that_does_not_resolve_is_named_by_its_json_path() {
    let text = std::fs::read_to_string(fixture("data/column_a_purity_specs.json")).unwrap();
    let bad = text.replace("\"vary\": \"V\"", "\"vary\": \"column.boilupp\"");
    let path = std::env::temp_dir().join(format!("plantwide_bad_spec_{}.json", std::process::id()));
    std::fs::write(&path, bad).unwrap();
    let err = fails(&["steady", path.to_str().unwrap()], 1);
    std::fs::remove_file(&path).ok();
    assert!(err.contains("specs[1].vary") && err.contains("did you mean `column.boilup`"), "{err}");
}
