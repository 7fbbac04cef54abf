//! Plots people read: a run's panels grouped as the scenario asks, each path's setpoint dashed,
//! its controller's output limits, an earlier run overlaid (`--compare`), the events marked; RGA
//! heat maps with their inputs and outputs; study reports as HTML pages beside their markdown.

use crate::harness::{flowsheet, plantwide};

fn temp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("plantwide_plots_{name}_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The FEHE reactor's feed step with two temperatures on one panel, the trim duty (PI output with
/// limits) on another, and the run without the exchanger's loop tuned twice as hard overlaid.
#[test]
fn a_run_plot_groups_panels_and_draws_setpoints_limits_overlays_and_events() {
    let dir = temp("run");
    let sc = serde_json::json!({
        "format_version": 1, "name": "feed step", "duration": "2400 s",
        "events": [{"type": "step", "at": "60 s", "path": "feed_T", "to": "300.2 K"}],
        "record": {"interval": "10 s", "time_unit": "s", "paths": [
            {"path": "effluent.T", "unit": "degC", "panel": "reactor temperatures"},
            {"path": "heated.T", "unit": "degC", "panel": "reactor temperatures"},
            {"path": "trim.duty", "unit": "kW"}]}
    });
    let sc_file = dir.join("s.json");
    std::fs::write(&sc_file, sc.to_string()).unwrap();
    let (sc_path, file) = (sc_file.to_str().unwrap().to_string(), flowsheet("fehe_reactor.json"));
    let other = dir.join("harder.csv");
    let first = ["run", &file, "--scenario", &sc_path, "--set", "temperature_control.kc=6kW/K", "--csv"];
    let out = plantwide(&[&first[..], &[other.to_str().unwrap()]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (csv, svg) = (dir.join("run.csv"), dir.join("run.svg"));
    let out = plantwide(&[
        "run",
        &file,
        "--scenario",
        &sc_path,
        "--csv",
        csv.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
        "--compare",
        other.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&svg).unwrap();
    for drawn in [
        "reactor temperatures [degC]",
        "effluent.T setpoint",
        "effluent.T harder",
        "heated.T",
        "trim.duty [kW]",
        "op_max",
        "this run",
        "step feed_T",
    ] {
        assert!(text.contains(drawn), "`{drawn}` not drawn");
    }
    // Two units on one panel: refused, naming the entry.
    let mut bad = sc.clone();
    bad["record"]["paths"][2]["panel"] = "reactor temperatures".into();
    std::fs::write(&sc_file, bad.to_string()).unwrap();
    let out = plantwide(&[
        "run",
        &file,
        "--scenario",
        &sc_path,
        "--csv",
        csv.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("record.paths[2].panel") && err.contains("one axis"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_rga_heat_map_names_its_inputs_and_outputs() {
    let dir = temp("rga");
    let svg = dir.join("rga.svg");
    let tf = flowsheet("transfer_functions/wood_berry.tf.json");
    let out = plantwide(&["gains", "--tf", &tf, "--plot", svg.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&svg).unwrap();
    // Wood–Berry's λ11 = 2.009 (published 2.01), with its signals' names.
    for drawn in ["2.009", "-1.009", "xD", "xB", "Λ(0)"] {
        assert!(text.contains(drawn), "`{drawn}` not drawn");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_compare_report_is_also_an_html_page_with_its_tables_and_figures() {
    let dir = temp("compare");
    let out = plantwide(&[
        "compare",
        &flowsheet("fehe_reactor.json"),
        &flowsheet("fehe_reactor_without_fehe.json"),
        "--disturbances",
        "feed_T=+3 K",
        "--outputs",
        "effluent.T",
        "--tuning",
        "file",
        "--report",
        dir.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let html = std::fs::read_to_string(dir.join("compare.html")).unwrap();
    for part in [
        "<h1>Schemes compared</h1>",
        "<table>",
        "<th>scheme</th>",
        "src=\"energy.png\"",
        "src=\"rga.png\"",
        "src=\"responses_1.png\"",
    ] {
        assert!(html.contains(part), "`{part}` not in compare.html");
    }
    assert!(std::fs::metadata(dir.join("rga.png")).unwrap().len() > 1000);
    std::fs::remove_dir_all(&dir).ok();
}

/// A `--compare` file that is not a run's CSV (no time column, ragged rows) exits 1 naming it.
#[test]
fn a_compare_file_that_is_not_a_run_csv_is_named() {
    let dir = temp("bad_compare");
    let (csv, svg) = (dir.join("run.csv"), dir.join("run.svg"));
    let file = flowsheet("fehe_reactor.json");
    let sc = flowsheet("scenarios/fehe_reactor_feed_temperature.json");
    for (text, why) in [("a,b\n1,2\n", "not a `plantwide run` CSV"), ("time [s],x [K]\n0,1,2\n", "line 2 has 3 fields")]
    {
        let other = dir.join("other.csv");
        std::fs::write(&other, text).unwrap();
        let out = plantwide(&[
            "run",
            &file,
            "--scenario",
            &sc,
            "--csv",
            csv.to_str().unwrap(),
            "--plot",
            svg.to_str().unwrap(),
            "--compare",
            other.to_str().unwrap(),
        ]);
        assert_eq!(out.status.code(), Some(1));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("--compare") && err.contains(why), "{err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
