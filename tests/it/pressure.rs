//! Column pressure as a state (`rigorous.vapour_volume`, `flowsheets/btx_column_pressure.json`):
//! held by a pressure controller on the cooling water it is the fixed-pressure column; left to
//! float it settles at the bubble pressure of the drum liquid at the condenser temperature; and the
//! vapour space's holdup keeps every run conservative.

use plantwide::flowsheet::{Override, Plant, load_file, load_with};
use plantwide::solve::{NewtonSettings, steady_state};

use crate::harness::{flowsheet, plantwide, value};

fn steady(name: &str, sets: &[(&str, &str)]) -> (Plant, Vec<f64>) {
    let overrides: Vec<Override> = sets.iter().map(|(p, v)| Override::new(*p, *v)).collect();
    let plant = load_with(std::path::Path::new(&flowsheet(name)), &overrides).unwrap_or_else(|e| panic!("{e}"));
    let u = plant.input_values();
    let ss = steady_state(&plant, &u, None, &NewtonSettings::default()).unwrap_or_else(|e| panic!("{e}"));
    (plant, ss.x)
}

/// Two routes to one column: the pressure state held at 1 atm by its controller, and the fixed-
/// pressure drum at its bubble point (`btx_column.json`): every variable they share agrees.
#[test]
fn a_held_pressure_state_is_the_fixed_pressure_column() {
    let fixed = load_file(std::path::Path::new(&flowsheet("btx_column.json"))).unwrap();
    let ss = steady_state(&fixed, &fixed.input_values(), None, &NewtonSettings::default()).unwrap();
    let (plant, x) = steady("btx_column_pressure.json", &[]);
    assert!((value(&plant, &x, "column.P") - 101_325.0).abs() < 1e-6);
    let mut worst: f64 = 0.0;
    for (v, a) in fixed.vars().iter().zip(&ss.x) {
        if let Some(j) = plant.var(&v.path) {
            worst = worst.max((x[j] - a).abs() / a.abs().max(1e-3));
        }
    }
    assert!(worst < 1e-9, "largest relative difference {worst:.2e}");
}

/// Floating pressure (controller in manual at several water flows and temperatures): the steady
/// top pressure is the bubble pressure of the distillate at the drum temperature, by the thermo
/// package's own bubble-pressure routine, to 1e-9; less or warmer water, higher pressure.
#[test]
fn a_floating_pressure_is_the_bubble_pressure_of_the_distillate() {
    let mut last = 0.0;
    for (water, t_in) in
        [("8 kg/s", "30 degC"), ("5.513462 kg/s", "30 degC"), ("4 kg/s", "30 degC"), ("4 kg/s", "40 degC")]
    {
        let doc = std::fs::read_to_string(flowsheet("btx_column_pressure.json")).unwrap();
        let text = doc.replace("\"coolant_T_in\": \"30 degC\"", &format!("\"coolant_T_in\": \"{t_in}\""));
        let plant = plantwide::flowsheet::load_str(&text, "btx_column_pressure.json")
            .unwrap()
            .variant(&[Override::new("pressure_control.auto", "0"), Override::new("pressure_control.op_manual", water)])
            .unwrap();
        let ss = steady_state(&plant, &plant.input_values(), None, &NewtonSettings::default())
            .unwrap_or_else(|e| panic!("{water} {t_in}: {e}"));
        let (p, t) = (value(&plant, &ss.x, "column.P"), value(&plant, &ss.x, "column.T[27]"));
        let x: Vec<f64> =
            plant.components().iter().map(|c| value(&plant, &ss.x, &format!("distillate.x[{c}]"))).collect();
        let bubble = plant.thermo().bubble_p(t, &x).unwrap().p;
        assert!((p - bubble).abs() < 1e-9 * p, "{water} {t_in}: P = {p}, bubble pressure {bubble}");
        assert!(p > last, "{water} {t_in}: P = {p} after {last}");
        last = p;
    }
}

/// A reboiler duty step: in auto the controller brings the pressure back to 1 atm; in manual it
/// floats to the steady state of the column at the new duty and the same water; both runs conserve
/// every component (the run's own check, 1e-9, counts the vapour space).
#[test]
fn the_pressure_loop_returns_and_the_floating_pressure_settles_where_the_steady_state_is() {
    let dir = std::env::temp_dir().join(format!("plantwide_pressure_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let final_p = |auto: &str| {
        let csv = dir.join(format!("run{auto}.csv"));
        let out = plantwide(&[
            "run",
            &flowsheet("btx_column_pressure.json"),
            "--scenario",
            &flowsheet("scenarios/btx_pressure_duty_step.json"),
            "--csv",
            csv.to_str().unwrap(),
            "--set",
            &format!("pressure_control.auto={auto}"),
        ]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let text = std::fs::read_to_string(&csv).unwrap();
        let rows: Vec<Vec<f64>> =
            text.lines().skip(1).map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
        let peak = rows.iter().map(|r| r[1]).fold(0.0, f64::max);
        (rows.last().unwrap()[1], peak)
    };
    let (auto, peak) = final_p("1");
    assert!((auto - 101_325.0).abs() < 1.0 && peak > 101_325.0 + 100.0, "final {auto} Pa, peak {peak} Pa");
    let (floating, _) = final_p("0");
    let (plant, x) = steady("btx_column_pressure.json", &[("pressure_control.auto", "0"), ("QR", "1.155 MW")]);
    let expected = value(&plant, &x, "column.P");
    assert!(expected > 101_325.0 + 500.0, "more boil-up, higher floating pressure: {expected}");
    assert!((floating - expected).abs() < 1e-3 * expected, "run ends at {floating} Pa, steady state {expected} Pa");
    std::fs::remove_dir_all(&dir).ok();
}
