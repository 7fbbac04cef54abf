//! Text in the units asked for: `run`'s table in the unit a recorded path asked for, else in the
//! `--units` system's (values with the scale's zero, deviations and integrals without it, per the
//! scenario's time unit); `steady`'s variables with their units. Each figure is checked against
//! the same run's SI JSON, converted by hand.

use approx::abs_diff_eq;

use crate::harness::{flowsheet, plantwide};

/// The table rows of `run`'s text output, by path: (unit, initial, final, IAE, max deviation).
fn table(stdout: &str) -> Vec<(String, String, f64, f64, f64, f64)> {
    stdout
        .lines()
        .skip_while(|l| !l.starts_with("path "))
        .skip(1)
        .take_while(|l| !l.starts_with("conservation"))
        .map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            let num = |k: usize| f[k].parse::<f64>().unwrap_or_else(|_| panic!("{l}"));
            (f[0].to_string(), f[1].to_string(), num(3), num(4), num(5), num(7))
        })
        .collect()
}

fn scenario_with(dir: &std::path::Path, paths: serde_json::Value) -> String {
    let text = std::fs::read_to_string(flowsheet("scenarios/fehe_reactor_feed_temperature.json")).unwrap();
    let mut sc: serde_json::Value = serde_json::from_str(&text).unwrap();
    sc["record"]["paths"] = paths;
    let path = dir.join("scenario.json");
    std::fs::write(&path, sc.to_string()).unwrap();
    path.display().to_string()
}

#[test]
fn run_shows_each_path_in_the_unit_it_asked_for_or_in_the_chosen_system() {
    let dir = std::env::temp_dir().join(format!("plantwide_display_units_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let sc = scenario_with(
        &dir,
        serde_json::json!(["effluent.T", {"path": "trim.duty", "unit": "MW"}, "feed.F", "effluent.x[A]", {"path": "heated.T", "unit": "K"}]),
    );
    let csv = dir.join("run.csv").display().to_string();
    let file = flowsheet("fehe_reactor.json");
    let json = plantwide(&["run", &file, "--scenario", &sc, "--csv", &csv, "--json"]);
    assert!(json.status.success(), "{}", String::from_utf8_lossy(&json.stderr));
    let si: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let si = |k: usize, what: &str| si["paths"][k][what].as_f64().unwrap();
    for (system, t_unit, flow_unit, t_zero, t_step, flow_factor) in [
        ("si", "K", "mol/s", 0.0, 1.0, 1.0),
        ("metric", "degC", "kmol/h", 273.15, 1.0, 3.6),
        ("field", "degF", "lbmol/h", 459.67, 1.8, 3600.0 / 453.59237),
    ] {
        let out = plantwide(&["run", &file, "--scenario", &sc, "--csv", &csv, "--units", system]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let text = String::from_utf8_lossy(&out.stdout).to_string();
        assert!(text.contains("IAE [u·s]"), "{text}");
        let rows = table(&text);
        assert_eq!(rows.len(), 5, "{text}");
        // effluent.T: the value with the scale's zero, the deviation and IAE without.
        let (path, unit, initial, _, iae, dev) = rows[0].clone();
        assert_eq!((path.as_str(), unit.as_str()), ("effluent.T", t_unit), "{system}");
        // trim.duty asked for MW: MW whatever the system.
        assert_eq!(rows[1].1, "MW", "{system}");
        assert_eq!(rows[2].1, flow_unit, "{system}");
        // A mole fraction stays a mole fraction.
        assert_eq!(rows[3].1, "1", "{system}");
        // A unit the scenario names, even an SI one, is kept whatever the system.
        assert_eq!(rows[4].1, "K", "{system}");
        // Printed with 8 significant digits (values: 1e-7) or 5 (integrals and deviations: 6e-5).
        for (what, shown, expected, rel) in [
            ("T initial", initial, si(0, "initial") * t_step - t_zero, 1e-7),
            ("T IAE", iae, si(0, "iae") * t_step, 6e-5),
            ("T max deviation", dev, si(0, "max_deviation") * t_step, 6e-5),
            ("duty initial", rows[1].2, si(1, "initial") / 1e6, 1e-7),
            ("duty final", rows[1].3, si(1, "last") / 1e6, 1e-7),
            ("flow", rows[2].2, si(2, "initial") * flow_factor, 1e-7),
            ("x", rows[3].2, si(3, "initial"), 1e-7),
            ("heated.T in K", rows[4].2, si(4, "initial"), 1e-7),
        ] {
            assert!(
                abs_diff_eq!(shown, expected, epsilon = rel * expected.abs()),
                "{system} {what}: {shown} vs {expected}"
            );
        }
        // The CSV header carries the same units.
        let header = std::fs::read_to_string(&csv).unwrap().lines().next().unwrap().to_string();
        assert!(header.contains(&format!("effluent.T [{t_unit}]")) && header.contains("trim.duty [MW]"), "{header}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn steady_shows_every_variable_with_its_unit() {
    let file = flowsheet("fehe_reactor.json");
    let out = plantwide(&["steady", &file, "--json"]);
    let si: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let q = si["values"]["trim.Q"].as_f64().unwrap();
    let op = si["values"]["temperature_control.op"].as_f64().unwrap();
    for (system, factor, unit) in
        [(None, 1.0, "W"), (Some("metric"), 1e-3, "kW"), (Some("field"), 3.412141633, "Btu/h")]
    {
        let mut args = vec!["steady", file.as_str()];
        if let Some(s) = system {
            args.extend(["--units", s]);
        }
        let out = plantwide(&args);
        assert!(out.status.success());
        let text = String::from_utf8_lossy(&out.stdout).to_string();
        for (line_start, name, value) in [("unit trim", "Q=", q), ("controller temperature_control", "op=", op)] {
            let line = text.lines().find(|l| l.starts_with(line_start)).unwrap_or_else(|| panic!("{text}"));
            let rest = &line[line.find(name).unwrap() + name.len()..];
            let mut words = rest.split_whitespace();
            let v: f64 = words.next().unwrap().parse().unwrap();
            assert_eq!(words.next(), Some(unit), "{system:?}: {line}");
            assert!(
                (v - value * factor).abs() < 1e-5 * (value * factor).abs(),
                "{system:?}: {v} vs {}",
                value * factor
            );
        }
    }
    let metric = plantwide(&["steady", &file, "--units", "metric"]);
    let text = String::from_utf8_lossy(&metric.stdout);
    assert!(text.contains("T degC") && text.contains("F kmol/h"), "{text}");
}

/// An input a controller drives is addressable as an output (`trim.duty`, read as the output of
/// the controller that drives it, `temperature_control.op`), in the unit asked for; its gain equals
/// the central difference of two steady states (a second route) to 1e-6.
#[test]
fn a_driven_input_is_an_output_in_the_unit_asked_for() {
    let file = flowsheet("fehe_reactor.json");
    let gain = |output: &str| {
        let out = plantwide(&["gains", &file, "--inputs", "feed_T", "--outputs", output, "--json"]);
        assert!(out.status.success(), "{output}: {}", String::from_utf8_lossy(&out.stderr));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["outputs"][0]["unit"], "kW");
        v["gain"][0][0].as_f64().unwrap()
    };
    let (driven, op) = (gain("trim.duty@kW"), gain("temperature_control.op@kW"));
    assert_eq!(driven, op);
    let duty = |t: &str| {
        let out = plantwide(&["steady", &file, "--json", "--set", &format!("feed_T={t}")]);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        v["values"]["trim.Q"].as_f64().unwrap()
    };
    let central = (duty("300.5 K") - duty("299.5 K")) / 1e3;
    assert!((driven - central).abs() < 1e-6 * central.abs(), "gain {driven} kW/K, central difference {central} kW/K");
}

/// `--units` reaches the analysis commands: a gain printed per lbmol/h (field) is the SI gain per
/// mol/s times the size of one lbmol/h in mol/s, and a path that names its unit keeps it.
#[test]
fn gains_take_the_unit_system_for_paths_that_name_no_unit() {
    let file = flowsheet("column_a.json");
    let args = ["gains", &file, "--inputs", "L,V@kmol/min", "--outputs", "distillate.x[light]", "--json"];
    let si = plantwide(&args);
    let field = plantwide(&[&args[..], &["--units", "field"]].concat());
    let (si, field): (serde_json::Value, serde_json::Value) =
        (serde_json::from_slice(&si.stdout).unwrap(), serde_json::from_slice(&field.stdout).unwrap());
    assert_eq!(field["inputs"][0]["unit"], "lbmol/h");
    assert_eq!(field["inputs"][1]["unit"], "kmol/min");
    let lbmol_h = 0.45359237 / 3600.0 * 1000.0; // mol/s
    let (g_si, g_field) = (si["gain"][0][0].as_f64().unwrap(), field["gain"][0][0].as_f64().unwrap());
    assert!((g_field - g_si * lbmol_h).abs() < 1e-12 * g_si.abs(), "{g_field} vs {}", g_si * lbmol_h);
    assert_eq!(si["gain"][0][1], field["gain"][0][1]);
}

fn stdout_of(args: &[&str]) -> String {
    let out = plantwide(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// `check` lists the free inputs with the file's values and the residence times' holdups and
/// flows in the chosen system: column A's reflux 2.70629 kmol/min is 162.3774 kmol/h, its drum
/// holdup 0.5 kmol; in SI 45.10483 mol/s and 500 mol.
#[test]
fn check_shows_values_in_the_chosen_system() {
    let metric = stdout_of(&["--units", "metric", "check", &flowsheet("column_a.json")]);
    assert!(metric.contains("column.reflux = 162.377400 kmol/h"), "{metric}");
    assert!(metric.contains("feed_source.P = 101.325000 kPa"), "{metric}");
    assert!(metric.contains("holdup 0.500000 kmol"), "{metric}");
    let si = stdout_of(&["check", &flowsheet("column_a.json")]);
    assert!(si.contains("column.reflux = 45.104833 mol/s"), "{si}");
    assert!(si.contains("holdup 500.000000 mol"), "{si}");
}

/// `size` in the chosen system: the outflow change 10 mol/s is 36 kmol/h, the rate limit
/// 3 mol/s per min is 10.8 kmol/h per min, the P controller's gain (outflow change over half
/// the band, 10 mol/s / 0.2 m = 50 mol/s/m) is 180 kmol/h/m; in SI the same numbers as given.
#[test]
fn size_shows_flows_rates_and_gains_in_the_chosen_system() {
    let file = flowsheet("surge_tank_pi.json");
    let run = |units: &str| {
        stdout_of(&[
            "--units",
            units,
            "size",
            &file,
            "--vessel",
            "tank",
            "--disturbance",
            "F_in=+10 mol/s",
            "--level-band",
            "0.2 m",
            "--max-outflow-rate",
            "3 mol/s/min",
        ])
    };
    let metric = run("metric");
    assert!(metric.contains("outflow change 3.6000e1 kmol/h"), "{metric}");
    assert!(metric.contains("rate limit 1.0800e1 kmol/h/min"), "{metric}");
    assert!(metric.contains("| p | 0.1811 | 0.0362 | 180.0000 |"), "{metric}");
    let si = run("si");
    assert!(si.contains("for F_in +1.000000e1 mol/s"), "{si}");
    assert!(si.contains("| p | 0.1811 | 0.0362 | 50.0000 |"), "{si}");
}

/// `compare` shows its outputs in the unit each `--outputs` entry asks for, else in the chosen
/// system, and the tuning in display units: the FEHE reactor's effluent at 420 K is 146.85 °C;
/// the trim heater's file gain 3 kW/K is 3 kW/degC.
#[test]
fn compare_shows_outputs_and_tuning_in_display_units() {
    let text = stdout_of(&[
        "--units",
        "metric",
        "compare",
        &flowsheet("fehe_reactor.json"),
        &flowsheet("fehe_reactor_without_fehe.json"),
        "--disturbances",
        "feed_T=+3 K",
        "--outputs",
        "effluent.T,effluent.x[A]@1",
        "--tuning",
        "file",
    ]);
    assert!(text.contains("| effluent.T [degC] | fehe_reactor | 146.8500 | 146.8500 | 146.8500 |"), "{text}");
    assert!(text.contains("effluent.x[A] [-]"), "{text}");
    assert!(text.contains("Kc 3.0000 kW/degC"), "{text}");
    assert!(!text.contains("(SI)"), "{text}");
}

/// `sensors` and `linearize` in the chosen system: column A's reboiler at 355.2255 K is
/// 82.0755 °C, the temperature gains per kmol/h are those per mol/s over 3.6; the linear model's
/// gain table names its input's unit (kmol/h), the gain 0.8754 per kmol/min being 0.01459 per kmol/h.
#[test]
fn sensors_and_linearize_show_the_chosen_system() {
    let file = flowsheet("column_a.json");
    let si = stdout_of(&["sensors", &file, "--column", "column", "--inputs", "column.reflux,column.boilup"]);
    let metric = stdout_of(&[
        "--units",
        "metric",
        "sensors",
        &file,
        "--column",
        "column",
        "--inputs",
        "column.reflux,column.boilup",
    ]);
    let stage1 = |text: &str| -> Vec<f64> {
        let line = text.lines().find(|l| l.trim_start().starts_with("1 ")).unwrap().to_string();
        line.split_whitespace().skip(1).take(4).map(|v| v.parse().unwrap()).collect()
    };
    let (s, m) = (stage1(&si), stage1(&metric));
    assert!(metric.contains("T [degC]") && metric.contains("dT/d(column.reflux) [degC per kmol/h]"), "{metric}");
    assert!((m[0] - (s[0] - 273.15)).abs() < 1e-4, "{m:?} vs {s:?}");
    assert!((m[1] - s[1]).abs() < 1e-4);
    assert!(((m[2] - s[2] / 3.6) / m[2]).abs() < 1e-5, "{m:?} vs {s:?}");
    let lin = stdout_of(&[
        "--units",
        "metric",
        "linearize",
        &file,
        "--inputs",
        "column.reflux",
        "--outputs",
        "distillate.x[light]",
    ]);
    assert!(lin.contains("column.reflux [kmol/h]"), "{lin}");
    let g: f64 = lin
        .lines()
        .find(|l| l.contains("distillate.x[light] [-]"))
        .unwrap()
        .split_whitespace()
        .last()
        .unwrap()
        .parse()
        .unwrap();
    assert!((g - 0.8754 / 60.0).abs() < 1e-4, "{g}");
}
