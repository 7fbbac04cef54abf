//! Heat-integrated columns (`condenser_reboiler`, `flowsheets/methanol_water_pressure_staged.json`):
//! the high-pressure condenser's duty is the low-pressure reboiler's and UA ΔT at every steady
//! state and along a run; the floating high-pressure column sits at its distillate's bubble
//! pressure; the integrated plant reaches the design the spec solver found on the uncoupled
//! fixed-pressure pair; the auxiliary duties add to the main ones exactly.

use plantwide::flowsheet::{Override, Plant, load_str, load_with};
use plantwide::solve::{NewtonSettings, StrategySettings, converge, steady_state};

use crate::harness::{flowsheet, plantwide, value};

const WITH: &str = "methanol_water_pressure_staged.json";
const WITHOUT: &str = "methanol_water_pressure_staged_without_integration.json";
/// The coupling's UA in the shipped file [W/K].
const UA: f64 = 25_371.31;

fn steady(name: &str, sets: &[(&str, &str)]) -> (Plant, Vec<f64>) {
    let overrides: Vec<Override> = sets.iter().map(|(p, v)| Override::new(*p, *v)).collect();
    let plant = load_with(std::path::Path::new(&flowsheet(name)), &overrides).unwrap_or_else(|e| panic!("{e}"));
    let sol = converge(&plant, &StrategySettings::default()).unwrap_or_else(|e| panic!("{name} {sets:?}: {e}"));
    (plant, sol.x)
}

/// The value of input `path` at state `x`: the controller output driving it, or its own value.
fn input(plant: &Plant, x: &[f64], path: &str) -> f64 {
    let i = plant.input(path).unwrap_or_else(|| panic!("no input {path}"));
    plant.inputs()[i].driven_by.map_or(plant.input_values()[i], |v| x[v])
}

/// Q_C,HP (the high-pressure condenser's duty input and its `Qc`) = Q_R,LP (the low-pressure
/// reboiler's duty input) = UA (T_drum,HP − T_reboiler,LP) to 1e-9, at the design and at steady
/// states moved by throughput, feed composition, UA and the auxiliary reboiler; and the floating
/// top pressure is the bubble pressure of the distillate at the drum temperature, by the thermo
/// package's own routine, to 1e-9.
#[test]
fn the_coupling_duty_is_both_columns_and_ua_delta_t_at_every_steady_state() {
    let cases: [&[(&str, &str)]; 5] = [
        &[],
        &[("throughput", "110 kmol/h")],
        &[("feed_methanol", "0.45")],
        &[("integration.ua", "22 kW/K")],
        &[("lp_temperature.auto", "0"), ("lp_temperature.op_manual", "80 kW")],
    ];
    let mut pressures = Vec::new();
    for sets in cases {
        let (plant, x) = steady(WITH, sets);
        let q_c = input(&plant, &x, "hp.condenser_duty");
        let q_r = input(&plant, &x, "lp.reboiler_duty");
        let ua = input(&plant, &x, "integration.ua");
        let dt = value(&plant, &x, "hp.T[32]") - value(&plant, &x, "lp.T[1]");
        assert!((q_c - q_r).abs() < 1e-9 * q_c, "{sets:?}: Q_C,HP {q_c} W, Q_R,LP {q_r} W");
        assert!((q_c - ua * dt).abs() < 1e-9 * q_c, "{sets:?}: Q {q_c} W, UA dT {} W", ua * dt);
        assert!((value(&plant, &x, "hp.Qc") - q_c).abs() < 1e-9 * q_c, "{sets:?}: no auxiliary condenser");
        let p = value(&plant, &x, "hp.P");
        let xd: Vec<f64> = plant.components().iter().map(|c| value(&plant, &x, &format!("hp_D.x[{c}]"))).collect();
        let bubble = plant.thermo().bubble_p(value(&plant, &x, "hp.T[32]"), &xd).unwrap().p;
        assert!((p - bubble).abs() < 1e-9 * p, "{sets:?}: P {p} Pa, bubble pressure {bubble} Pa");
        pressures.push(p);
    }
    // More feed, more vapour to condense through the same UA: a higher pressure; a smaller UA
    // needs a larger temperature difference: higher still.
    assert!(pressures[1] > pressures[0] && pressures[3] > pressures[0], "{pressures:?}");
}

/// Two routes to one design. The spec solver, on the uncoupled pair at a fixed 7 atm, found the
/// inputs that give 99.5 / 0.5 mol% methanol at both ends of both columns (those are the file's
/// values, to 7 digits); the integrated plant, whose high-pressure column floats, reaches that
/// design by itself: 7 atm and the four purities. And the plant without integration, with the
/// same inputs, is the same state: its utilities are the integrated plant's plus the heat the
/// coupling recovers, on both the heating and the cooling side.
#[test]
fn the_integrated_pair_reaches_its_design_and_saves_the_coupling_duty_twice() {
    let (plant, x) = steady(WITH, &[]);
    let p = value(&plant, &x, "hp.P");
    assert!((p - 7.0 * 101_325.0).abs() < 1e-6 * p, "HP top pressure {p} Pa");
    for (path, target) in [
        ("hp_D.x[methanol]", 0.995),
        ("hp_B.x[methanol]", 0.005),
        ("lp_D.x[methanol]", 0.995),
        ("lp_B.x[methanol]", 0.005),
    ] {
        let v = value(&plant, &x, path);
        assert!((v - target).abs() < 1e-7, "{path} = {v}");
    }
    // The same steady state by the fixed-pressure spec route, from the shipped uncoupled file.
    let out = plantwide(&[
        "steady",
        &flowsheet(WITHOUT),
        "--json",
        "--spec",
        "hp_D.x[methanol]=0.995",
        "--vary",
        "hp.reflux",
        "--spec",
        "lp_D.x[methanol]=0.995",
        "--vary",
        "lp.reflux",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let spec: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let by_spec = |path: &str| spec["values"][path].as_f64().unwrap_or_else(|| panic!("{path}"));
    for path in ["hp.reflux", "lp.reflux"] {
        let (a, b) = (input(&plant, &x, path), by_spec(path));
        assert!((a - b).abs() < 1e-6 * b, "{path}: file {a}, spec route {b}");
    }
    let (heat_with, recovered) = (
        input(&plant, &x, "hp.reboiler_duty") + input(&plant, &x, "lp.auxiliary_reboiler_duty"),
        value(&plant, &x, "integration.op"),
    );
    let (wo, y) = steady(WITHOUT, &[]);
    let heat_without = input(&wo, &y, "hp.reboiler_duty") + input(&wo, &y, "lp.reboiler_duty");
    assert!(
        (heat_with + recovered - heat_without).abs() < 1e-6 * heat_without,
        "{heat_with} + {recovered} vs {heat_without}"
    );
    let cool_with = value(&plant, &x, "lp.Qc") + value(&plant, &x, "hp.Qc") - recovered;
    let cool_without = value(&wo, &y, "lp.Qc") + value(&wo, &y, "hp.Qc");
    assert!(
        (cool_with + recovered - cool_without).abs() < 1e-6 * cool_without,
        "{cool_with} + {recovered} vs {cool_without}"
    );
}

/// Along the shipped feed-rate step: the recorded coupling duty equals both columns' duty inputs
/// and UA ΔT at every recorded instant to 1e-9, the run conserves every component, and it ends at
/// the steady state of the higher feed (a second route: the plant Newton) to 1e-4 in the top
/// pressure.
#[test]
fn the_coupling_closes_along_a_run_that_settles_at_the_new_steady_state() {
    let dir = std::env::temp_dir().join(format!("plantwide_heat_integration_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let shipped = std::fs::read_to_string(flowsheet("scenarios/methanol_water_feed_step.json")).unwrap();
    let mut scenario: serde_json::Value = serde_json::from_str(&shipped).unwrap();
    scenario["record"]["paths"] = serde_json::json!([
        "integration.op",
        "integration.op2",
        "hp.condenser_duty",
        "lp.reboiler_duty",
        "hp.T[32]",
        "lp.T[1]",
        "hp.P"
    ]);
    let path = dir.join("scenario.json");
    std::fs::write(&path, scenario.to_string()).unwrap();
    let csv = dir.join("run.csv");
    let out =
        plantwide(&["run", &flowsheet(WITH), "--scenario", path.to_str().unwrap(), "--csv", csv.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("conservation (moles)") && stdout.contains(": ok"), "{stdout}");
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<Vec<f64>> =
        text.lines().skip(1).map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    assert!(rows.len() > 100);
    for r in &rows {
        let q = r[1];
        for (k, other) in [(2, "op2"), (3, "hp.condenser_duty"), (4, "lp.reboiler_duty")] {
            assert!((r[k] - q).abs() < 1e-9 * q, "t = {} min: {other} {} W, op {q} W", r[0], r[k]);
        }
        assert!((q - UA * (r[5] - r[6])).abs() < 1e-9 * q, "t = {} min: Q {q} W, UA dT {} W", r[0], UA * (r[5] - r[6]));
    }
    let (plant, x) = steady(WITH, &[("throughput", "110 kmol/h")]);
    let (end, expected) = (rows.last().unwrap()[7], value(&plant, &x, "hp.P"));
    assert!((end - expected).abs() < 1e-4 * expected, "run ends at {end} Pa, steady state {expected} Pa");
    assert!(expected > 1.015 * 7.0 * 101_325.0, "more feed, higher pressure: {expected} Pa");
    std::fs::remove_dir_all(&dir).ok();
}

/// A column heated by `reboiler_duty` Q1 and an auxiliary reboiler Q2 is the column heated by Q1 +
/// Q2; one cooled by `condenser_duty` C1 and an auxiliary condenser C2 is the one cooled by C1 + C2
/// (each to 1e-9 in every shared variable).
#[test]
fn auxiliary_duties_add_to_the_main_ones() {
    let doc = std::fs::read_to_string(flowsheet("btx_column_pressure.json")).unwrap();
    let base = doc.replace(
        "\"reboiler_duty\": \"1.1 MW\"",
        "\"reboiler_duty\": \"0.8 MW\", \"auxiliary_reboiler_duty\": \"0.3 MW\"",
    );
    assert_ne!(base, doc);
    let solve = |text: &str| {
        let plant = load_str(text, "btx_column_pressure.json")
            .unwrap()
            .variant(&[
                Override::new("pressure_control.auto", "0"),
                Override::new("pressure_control.op_manual", "5 kg/s"),
            ])
            .unwrap();
        let ss = steady_state(&plant, &plant.input_values(), None, &NewtonSettings::default()).unwrap();
        (plant, ss.x)
    };
    let agree = |(a, x): &(Plant, Vec<f64>), (b, y): &(Plant, Vec<f64>)| {
        let mut worst: f64 = 0.0;
        for (v, xa) in a.vars().iter().zip(x) {
            if let Some(j) = b.var(&v.path) {
                worst = worst.max((y[j] - xa).abs() / xa.abs().max(1e-3));
            }
        }
        worst
    };
    let (single, split) = (solve(&doc), solve(&base));
    assert!(agree(&single, &split) < 1e-9, "reboiler: {:.2e}", agree(&single, &split));
    assert!((value(&split.0, &split.1, "column.Qc") - value(&single.0, &single.1, "column.Qc")).abs() < 1e-3);
    // Condenser: a duty-specified drum with a pressure state, 1.0 + 0.1 MW against 1.1 MW.
    let duty = |text: &str, extra: &str| {
        text.replace(
            "\"condenser\": {\"coolant_flow\": \"5.513462 kg/s\", \"coolant_T_in\": \"30 degC\", \"ua\": \"60 kW/K\"}",
            &format!("\"condenser_duty\": {extra}"),
        )
        .replace("\"output\": \"column.coolant_flow\"", "\"output\": \"column.condenser_duty\"")
        .replace("\"op_min\": \"0 kg/s\", \"op_max\": \"60 kg/s\"", "\"op_min\": \"0 W\", \"op_max\": \"3 MW\"")
        .replace("\"kc\": \"0.5 kg/s/kPa\"", "\"kc\": \"100 W/Pa\"")
        .replace("\"water\": \"column.coolant_flow\"", "\"water\": \"column.condenser_duty\"")
    };
    let solve_duty = |text: &str| {
        let plant = load_str(text, "btx_column_pressure.json").unwrap();
        let plant = plant
            .variant(&[
                Override::new("pressure_control.auto", "0"),
                Override::new("pressure_control.op_manual", "1.0 MW"),
            ])
            .unwrap();
        let ss = steady_state(&plant, &plant.input_values(), None, &NewtonSettings::default())
            .unwrap_or_else(|e| panic!("{e}"));
        (plant, ss.x)
    };
    let one = solve_duty(&duty(&doc, "\"1.0 MW\""));
    let two = solve_duty(&duty(&doc, "\"1.0 MW\", \"auxiliary_condenser_duty\": \"0.05 MW\""));
    let qc = |(p, x): &(Plant, Vec<f64>)| value(p, x, "column.Qc");
    assert!((qc(&one) - 1.0e6).abs() < 1e-6 && (qc(&two) - 1.05e6).abs() < 1e-6, "{} {}", qc(&one), qc(&two));
    let p = |(pl, x): &(Plant, Vec<f64>)| value(pl, x, "column.P");
    assert!(p(&two) < p(&one), "more duty, lower floating pressure: {} vs {}", p(&two), p(&one));
}

/// Bad descriptions exit 1 naming the field: a coupling whose `condensing` is not a temperature,
/// an auxiliary condenser on a drum at its bubble point.
#[test]
fn a_coupling_on_the_wrong_variable_or_an_auxiliary_condenser_without_a_duty_is_named() {
    let dir = std::env::temp_dir().join(format!("plantwide_heat_integration_bad_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let doc = std::fs::read_to_string(flowsheet(WITH)).unwrap();
    for (from, to, field) in [
        ("\"condensing\": \"hp.T[32]\"", "\"condensing\": \"hp.M[32]\"", "controllers.integration.condensing"),
        (
            "\"auxiliary_reboiler_duty\": \"50.1764 kW\"",
            "\"auxiliary_reboiler_duty\": \"50.1764 kW\", \"auxiliary_condenser_duty\": \"10 kW\"",
            "units.lp.rigorous.auxiliary_condenser_duty",
        ),
    ] {
        let text = doc.replace(from, to);
        assert_ne!(text, doc, "{from}");
        let file = dir.join("bad.json");
        std::fs::write(&file, text).unwrap();
        let out = plantwide(&["check", file.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(1), "{field}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(field), "{field}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `plantwide compare` books the coupling as recovered heat, once: the integrated scheme's heating
/// (the high-pressure reboiler and the auxiliary one) plus what the coupling recovers is the
/// uncoupled scheme's heating, and likewise for cooling, to 1e-6; the recovered duty is UA ΔT.
#[test]
fn compare_books_the_coupling_as_recovered_heat() {
    let dir = std::env::temp_dir().join(format!("plantwide_heat_integration_compare_{}", std::process::id()));
    let out = plantwide(&[
        "compare",
        &flowsheet(WITH),
        &flowsheet(WITHOUT),
        "--disturbances",
        "throughput=+10%",
        "--outputs",
        "hp_D.P",
        "--tuning",
        "file",
        "--report",
        dir.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("compare.json")).unwrap()).unwrap();
    let energy = |k: usize, what: &str| report["schemes"][k]["energy"][what].as_f64().unwrap();
    let recovered = energy(0, "recovered");
    assert_eq!(energy(1, "recovered"), 0.0);
    for what in ["heating", "cooling"] {
        let (with, without) = (energy(0, what), energy(1, what));
        assert!((with + recovered - without).abs() < 1e-6 * without, "{what}: {with} + {recovered} vs {without}");
    }
    let (plant, x) = steady(WITH, &[]);
    let ua_dt = UA * (value(&plant, &x, "hp.T[32]") - value(&plant, &x, "lp.T[1]"));
    assert!((recovered - ua_dt).abs() < 1e-6 * ua_dt, "recovered {recovered} W, UA dT {ua_dt} W");
    std::fs::remove_dir_all(&dir).ok();
}
