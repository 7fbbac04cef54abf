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
    // With the colour key under the tiles.
    for drawn in ["2.009", "-1.009", "xD", "xB", "Λ(0)", "colour of λ:", "10 or 0.1", "λ ≤ 0"] {
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

/// A manipulated variable's panel follows its moves: reflux moving 2.70 → 2.93 kmol/min under
/// limits 0 … 6 is not drawn flat at the bottom of a 0 … 6 axis; the far limits are named at the
/// panel's edges, and a limit the output reaches (a saturated boilup) is drawn across it.
#[test]
fn an_mv_axis_follows_the_moves_and_names_far_limits_at_its_edge() {
    use plantwide::io::plot::{Overlay, y_scale};
    let moves: Vec<f64> = (0..100).map(|k| 2.70 + 0.23 * (1.0 - (-f64::from(k) / 10.0).exp())).collect();
    let limits = vec![("op_min".to_string(), 0.0), ("op_max".to_string(), 6.0)];
    let reflux = Overlay { label: "reflux".into(), curves: vec![(String::new(), moves)], limits, ..Overlay::default() };
    let s = y_scale(&reflux);
    assert!(s.lo < 2.70 && s.lo > 2.65 && s.hi > 2.93 && s.hi < 2.98, "{s:?}");
    assert_eq!((s.above[0].0.as_str(), s.below[0].0.as_str(), s.inside.len()), ("op_max", "op_min", 0));
    let boilup: Vec<f64> = (0..100).map(|k| (3.2 + 0.05 * f64::from(k)).min(3.5)).collect();
    let limits = vec![("op_max".to_string(), 3.5)];
    let boilup = Overlay { curves: vec![(String::new(), boilup)], limits, ..Overlay::default() };
    let s = y_scale(&boilup);
    assert!(s.inside.len() == 1 && s.hi > 3.5 && s.lo < 3.2 && s.lo > 3.1, "{s:?}");
}

/// Each panel's legend stands in a column right of the data (which ends 25 px short of x =
/// 1000), whatever the names' length.
#[test]
fn legends_stand_beside_the_data() {
    use plantwide::io::plot::{Overlay, legend_width, write_overlays};
    let dir = temp("legend");
    let times: Vec<f64> = (0..50).map(f64::from).collect();
    let curve = |a: f64| times.iter().map(|t| a * (1.0 - (-t / 8.0).exp())).collect::<Vec<f64>>();
    let names = ["fehe_reactor", "fehe_reactor_without_fehe, a scheme with a long name"];
    let panel = Overlay {
        label: "T [K]".into(),
        curves: names.iter().zip([1.0, 2.0]).map(|(n, a)| (n.to_string(), curve(a))).collect(),
        limits: vec![("op_max".into(), 2.1)],
        ..Overlay::default()
    };
    let file = dir.join("o.svg");
    write_overlays(&file, "overlay", "time [h]", &times, &[panel], &[]).unwrap();
    let svg = std::fs::read_to_string(&file).unwrap();
    for name in names.iter().chain(&["op_max"]) {
        let at = svg.find(&format!("\n{name}\n</text>")).unwrap_or_else(|| panic!("{name} drawn"));
        let tag = &svg[svg[..at].rfind("<text").unwrap()..at];
        let x: f64 = tag.split("x=\"").nth(1).and_then(|r| r.split('"').next()).unwrap().parse().unwrap();
        assert!(x >= 975.0, "`{name}` at x = {x}, on the data");
    }
    assert!(legend_width([names[1]]) > legend_width([names[0]]));
    assert!(svg.contains("width=\"") && !svg.starts_with("<svg width=\"1000\""), "the figure widened for its legend");
    std::fs::remove_dir_all(&dir).ok();
}

/// Overlaid curves differ in colour, line pattern and marker, and their markers do not fall on
/// one another, so a scheme drawn over another leaves it showing.
#[test]
fn overlaid_curves_are_told_apart() {
    use plantwide::io::plot::{curve_style, marker_indices};
    let styles: Vec<_> = (0..4).map(|k| curve_style(k, true)).collect();
    for (i, a) in styles.iter().enumerate() {
        for b in &styles[i + 1..] {
            assert!(a.colour != b.colour && a.dash != b.dash && a.marker != b.marker, "{a:?} {b:?}");
        }
    }
    assert!(styles[1].width < styles[0].width, "the first curve shows under the second");
    let (first, second) = (marker_indices(0, 2, 1000), marker_indices(1, 2, 1000));
    assert_eq!((first.len(), second.len()), (10, 10));
    assert!(first.iter().all(|i| !second.contains(i)), "{first:?} {second:?}");
    // With setpoints or other runs dashed in the panel, the curves stay solid.
    assert_eq!(curve_style(1, false).dash, None);
}

/// A response that settles within 3 h of a 25 h run is shown over about 4 h, not 25.
#[test]
fn a_response_axis_ends_after_the_response_settles() {
    use plantwide::io::plot::{Overlay, settled_end};
    let times: Vec<f64> = (0..=2500).map(|k| f64::from(k) / 100.0).collect();
    let response = |t: f64| if t < 0.5 { 0.0 } else { (-(t - 0.5) / 0.5).exp() * (t - 0.5) };
    let panel = Overlay {
        curves: vec![("A".into(), times.iter().map(|&t| response(t)).collect()), ("B".into(), vec![1.0; 2501])],
        ..Overlay::default()
    };
    let end = settled_end(&times, &[panel], &[(0.5, "step".into())]);
    assert!(end > 3.0 && end < 6.0, "{end}");
    // A response still moving at the end keeps the whole run.
    let ramp = Overlay { curves: vec![(String::new(), times.clone())], ..Overlay::default() };
    assert_eq!(settled_end(&times, &[ramp], &[]), 25.0);
}

/// Titles shrink to fit their figure; short ones keep their size.
#[test]
fn a_long_title_is_shrunk_to_fit() {
    use plantwide::io::plot::title_font_size;
    let long =
        "surge designs of `column1.drum` for fresh_A.F +2.777778e0 (SI), step (band ±0.3 m); failed, not drawn: p, pi";
    assert_eq!(title_font_size("column_a: feed rate +20 %", 1000, 24.0), 24.0);
    let size = title_font_size(long, 1000, 24.0);
    assert!((11.0..24.0).contains(&size) && size < title_font_size(long, 2000, 24.0), "{size}");
}

/// The surge plot shades the level band the designs are sized for.
#[test]
fn the_size_plot_shades_the_level_band() {
    let dir = temp("size");
    let svg = dir.join("size.svg");
    let out = plantwide(&[
        "size",
        &format!("{}/docs/tutorial/bt_column.json", env!("CARGO_MANIFEST_DIR")),
        "--vessel",
        "bottoms",
        "--disturbance",
        "feed_source.F=+10%",
        "--level-band",
        "0.5 m",
        "--max-outflow-rate",
        "0.1 kmol/h/min",
        "--units",
        "metric",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("band ±0.500 m") && text.contains("optimal"), "the band is named");
    // The band: one filled rectangle in its green, at 15 % opacity.
    assert!(text.contains("opacity=\"0.15\" fill=\"#00963C\""), "the band is shaded");
    std::fs::remove_dir_all(&dir).ok();
}

/// The MPC's own limits are drawn on its CVs (soft) and MVs (hard), named by the controller.
#[test]
fn an_mpc_run_plot_draws_the_controllers_limits() {
    let dir = temp("mpc");
    let sc = serde_json::json!({
        "format_version": 1, "name": "feed step", "duration": "60 min",
        "events": [{"type": "step", "at": "10 min", "path": "feed_source.F", "to": "1.2 kmol/min"}],
        "record": {"interval": "1 min", "time_unit": "min", "paths": [
            "distillate.x[light]", "bottoms.x[light]",
            {"path": "column.reflux", "unit": "kmol/min"}, {"path": "column.boilup", "unit": "kmol/min"}]}
    });
    let sc_file = dir.join("s.json");
    std::fs::write(&sc_file, sc.to_string()).unwrap();
    let (csv, svg) = (dir.join("run.csv"), dir.join("run.svg"));
    let out = plantwide(&[
        "run",
        &flowsheet("column_a_mpc.json"),
        "--scenario",
        sc_file.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&svg).unwrap();
    // yD ≥ 0.985 and xB ≤ 0.019 (soft); reflux ≤ 6 far above its moves, named at the edge.
    for drawn in ["quality_mpc min (soft)", "quality_mpc max (soft)", "↑ quality_mpc max 6.", "quality_mpc max"] {
        assert!(text.contains(drawn), "`{drawn}` not drawn");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `tune --plot` draws each loop's Bode diagram, its crossovers marked with the margins `tune`
/// reports.
#[test]
fn a_bode_plot_marks_the_margins_tune_reports() {
    let dir = temp("bode");
    let svg = dir.join("bode.svg");
    let tf = flowsheet("transfer_functions/wood_berry.tf.json");
    let out = plantwide(&[
        "tune",
        "--tf",
        &tf,
        "--method",
        "blt",
        "--time-unit",
        "min",
        "--json",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    for l in json["loops"].as_array().unwrap() {
        let m = &l["margins"];
        let (gm, pm) = (m["gain_margin"].as_f64().unwrap(), m["phase_margin"].as_f64().unwrap());
        let wc = m["gain_crossover"].as_f64().unwrap();
        for drawn in [
            format!("{} ← {}", l["output"].as_str().unwrap(), l["input"].as_str().unwrap()),
            format!("PM {pm:.1}°"),
            format!("({:.1} dB)", 20.0 * gm.log10()),
            format!("gain crossover ω = {}", &format!("{wc:.4}")[..5]),
        ] {
            assert!(text.contains(&drawn), "`{drawn}` not drawn");
        }
    }
    assert!(text.contains("ω [rad/min]") && text.contains("∠L [deg]") && text.contains("|L| [dB]"));
    std::fs::remove_dir_all(&dir).ok();
}
