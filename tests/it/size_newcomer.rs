//! `plantwide size` on plants it was not written with: the newcomer's flash → surge tank → column
//! train (issue 53 D3, D9, D10; `tests/data/newcomer3/flash_tank_column.json`) and a reactor inside
//! a recycle (issue 53 #14; `flowsheets/reactor_column_recycle.json`, Luyben's reactor–column
//! plant). The expected numbers come from conservation and closed forms, their inputs read from
//! `steady`, never from `size` itself; a part that has no answer must say so and exit 2.

use approx::abs_diff_eq;
use serde_json::Value;

use crate::harness::{fixture, flowsheet, plantwide};

const E: f64 = std::f64::consts::E;

/// The newcomer's train.
fn train() -> String {
    fixture("data/newcomer3/flash_tank_column.json")
}

/// Run `plantwide ARGS`: its exit code, stdout and stderr.
fn run(args: &[&str]) -> (Option<i32>, String, String) {
    let out = plantwide(args);
    (out.status.code(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

/// `steady --json FILE SET…`: the converged values by path.
fn steady(file: &str, set: &[&str]) -> Value {
    let (code, out, err) = run(&[&["steady", file, "--json"][..], set].concat());
    assert_eq!(code, Some(0), "{err}");
    serde_json::from_str::<Value>(&out).unwrap()["values"].clone()
}

fn num(v: &Value, key: &str) -> f64 {
    v[key].as_f64().unwrap_or_else(|| panic!("no number `{key}` in {v}"))
}

/// 0.5 kmol/h/min in mol/s².
const RATE: f64 = 0.5 / 3.6 / 60.0;

/// The newcomer's D3 request on the surge tank: ±0.5 m, 0.5 kmol/h/min, a +10 % feed step.
const SURGE: [&str; 8] = [
    "--vessel",
    "surge",
    "--disturbance",
    "feed_source.F=+10%",
    "--level-band",
    "0.5 m",
    "--max-outflow-rate",
    "0.5 kmol/h/min",
];

/// D3: every design of the surge tank between the flash and the column has its figures, each
/// verified within the limits, with the closed-form areas of the flow change that conservation
/// gives; the file's P loop is judged on its own offset. The preheater fixes the flash's
/// temperature and the flash its pressure, so the flash splits a feed of the same composition in
/// the same ratio: its liquid, the tank's inflow and at steady state its outflow, moves by 10 % of
/// itself. `--progress` reports each part on stderr (not a terminal here).
#[test]
fn the_newcomers_surge_tank_is_sized_on_the_flow_conservation_gives() {
    let plot = std::env::temp_dir().join(format!("plantwide_size_d3_{}.png", std::process::id()));
    let file = train();
    let args = [&["size", &file][..], &SURGE, &["--json", "--progress", "--plot", plot.to_str().unwrap()]].concat();
    let (code, out, err) = run(&args);
    assert_eq!(code, Some(0), "{err}");
    let s: Value = serde_json::from_str(&out).unwrap();
    let v = steady(&file, &[]);
    let du = 0.1 * num(&v, "flash_liquid.F");
    assert!(abs_diff_eq!(num(&s, "flow_change"), du, epsilon = 1e-6 * du.abs()), "{} vs {du}", s["flow_change"]);
    // The liquid's molar volume from the file's tank: π (1 m)² times its level over its holdup.
    let v_l = std::f64::consts::PI * num(&v, "surge.level") / num(&v, "surge.M");
    assert!(abs_diff_eq!(num(&s, "liquid_molar_volume"), v_l, epsilon = 1e-6 * v_l.abs()));
    for (d, c) in s["designs"].as_array().unwrap().iter().zip([1.0, 2.0 / E, 0.5]) {
        let area = c * v_l * du * du / (RATE * 0.5);
        assert!(abs_diff_eq!(num(d, "closed_form_area"), area, epsilon = 1e-6 * area.abs()), "{d}");
        let r = &d["verified"];
        assert!(r["meets"] == true && r["failure"].is_null(), "{d}");
        assert!(num(r, "max_level_deviation") <= 0.5 * 1.001 && num(r, "max_outflow_rate") <= RATE * 1.001, "{r}");
    }
    assert_eq!(s["failed"], Value::Array(vec![]));
    // The file's P loop, 20 kmol/h/m, settles at the offset Δu/Kc: 0.80 m, beyond the band.
    let c = &s["current"];
    let deviation = du / (20_000.0 / 3600.0);
    assert!(abs_diff_eq!(num(c, "max_deviation"), deviation, epsilon = 1e-3 * deviation.abs()), "{c}");
    assert_eq!(c["meets"], false);
    assert!(std::fs::metadata(&plot).is_ok_and(|m| m.len() > 1000));
    std::fs::remove_file(&plot).ok();
    for part in ["1/4 `surge`: p design done", "4/4 `surge`: file's vessel done"] {
        assert!(err.contains(part), "{err}");
    }
}

/// `--units metric`: the same sizing in kmol/h, kmol/h per minute, kmol and m³.
#[test]
fn the_surge_sizing_is_shown_in_the_units_asked() {
    let file = train();
    let (code, out, err) = run(&[&["--units", "metric", "size", &file][..], &SURGE].concat());
    assert_eq!(code, Some(0), "{err}");
    let du = 0.1 * num(&steady(&file, &[]), "flash_liquid.F") * 3.6;
    let head = out.lines().next().unwrap();
    assert!(head.contains(&format!("outflow change {du:.4e} kmol/h")), "{head}");
    assert!(head.contains("feed_source.F +1.650000e1 kmol/h, step"), "{head}");
    assert!(head.contains("rate limit 5.0000e-1 kmol/h/min"), "{head}");
    assert!(out.contains("| kc [kmol/h/m] |") && !out.contains("mol/s"), "{out}");
}

/// D9: the column model gives its drum a holdup, not a level, so the file's drum is reported in
/// mol and not judged against a band in metres. Its P loop (0.5 kmol/min per kmol) settles at the
/// offset ΔD/Kc, ΔD the distillate's steady change at the two feeds.
#[test]
fn a_column_drums_holdup_is_not_passed_off_as_a_level() {
    let file = train();
    let args = [
        "size",
        &file,
        "--vessel",
        "column.drum",
        "--disturbance",
        "feed_source.F=+10%",
        "--ramp",
        "2 min",
        "--level-band",
        "0.5 m",
        "--max-outflow-rate",
        "0.5 kmol/h/min",
    ];
    let (code, out, err) = run(&[&args[..], &["--json"]].concat());
    assert_eq!(code, Some(0), "{err}");
    let s: Value = serde_json::from_str(&out).unwrap();
    let d = |set: &[&str]| num(&steady(&file, set), "distillate.F");
    let dd = d(&["--set", "feed_source.F=181.5 kmol/h"]) - d(&[]);
    assert!(abs_diff_eq!(num(&s, "flow_change"), dd, epsilon = 1e-6 * dd.abs()), "{} vs {dd}", s["flow_change"]);
    let c = &s["current"];
    assert!(c["max_deviation"].is_null() && c["meets"].is_null(), "{c}");
    let deviation = dd * 120.0;
    assert!(
        abs_diff_eq!(num(c, "max_holdup_deviation"), deviation, epsilon = 2e-3 * deviation.abs()),
        "{c} vs {deviation}"
    );
    for d in s["designs"].as_array().unwrap() {
        let r = &d["verified"];
        assert!(r["meets"] == true && num(r, "max_level_deviation") <= 0.5 * 1.001, "{d}");
    }
    let (code, text, err) = run(&args);
    assert_eq!(code, Some(0), "{err}");
    let current = text.lines().find(|l| l.starts_with("as the file has it")).unwrap();
    assert!(current.contains(&format!("max holdup deviation {:.1}", dd * 120.0)), "{current}");
    assert!(current.contains("mol (the column model has no drum geometry") && !current.contains(" m,"), "{current}");
    assert!(current.ends_with("the band not judged"), "{current}");
    assert!(text.contains("kc [mol/s/mol]"), "{text}");
}

/// Luyben's reactor–column recycle: the reactor converts A → B at `k M x_R`, the column returns
/// its distillate at `x_D` and sends the bottoms at `x_B` (both held by PI loops); all A fed
/// leaves converted or in the bottoms, so `k M x_R = F0 (1 − x_B)` and the A balance of the column
/// gives the recycle `D = F0 (x_R − x_B)/(x_D − x_R)`. The reactor's outflow is `F0 + D`.
struct Recycle {
    f0: f64,
    k: f64,
    x_d: f64,
    x_b: f64,
    /// The reactor's holdup at its level setpoint and its liquid's molar volume.
    m: f64,
    v_l: f64,
}

impl Recycle {
    /// From the file's steady state (k and the setpoints as the file gives them).
    fn of_file() -> Recycle {
        let v = steady(&flowsheet("reactor_column_recycle.json"), &[]);
        let m = num(&v, "reactor.M");
        Recycle {
            f0: num(&v, "fresh.F"),
            k: 0.3583157 / 3600.0,
            x_d: 0.95,
            x_b: 0.0105,
            m,
            v_l: num(&v, "reactor.V") / m,
        }
    }

    /// The reactor's outflow at fresh feed `f0`.
    fn outflow(&self, f0: f64) -> f64 {
        let x_r = f0 * (1.0 - self.x_b) / (self.k * self.m);
        f0 + f0 * (x_r - self.x_b) / (self.x_d - x_r)
    }

    /// The least reactor area at a 3 m level: the recycle grows without bound as `x_R → x_D`
    /// (Luyben's snowball), at a holdup `F0 (1 − x_B)/(k x_D)`.
    fn least_area(&self) -> f64 {
        self.f0 * (1.0 - self.x_b) / (self.k * self.x_d) * self.v_l / 3.0
    }
}

/// The reactor for a +10 % fresh feed, ±0.5 m, at `rate`.
fn size_reactor(rate: &str) -> (Option<i32>, Value, String) {
    let file = flowsheet("reactor_column_recycle.json");
    let args = ["size", &file, "--vessel", "reactor", "--disturbance", "fresh.F=+10%", "--level-band", "0.5 m"];
    let (code, out, err) = run(&[&args[..], &["--max-outflow-rate", rate, "--json"]].concat());
    (code, serde_json::from_str(&out).unwrap_or(Value::Null), err)
}

/// #14: a vessel inside a recycle. Its designs change the plant they sit in (a larger reactor
/// converts more, so the recycle and the reactor's outflow move less), and each run settles at the
/// steady state of the plant with its design, not at the file's: all three verified. The flow
/// change checks against the recycle's closed form.
#[test]
fn a_reactor_inside_its_recycle_is_verified_to_its_own_steady_state() {
    let p = Recycle::of_file();
    let outflow = p.f0 + 32.8253;
    assert!(
        abs_diff_eq!(p.outflow(p.f0), outflow, epsilon = 1e-4 * outflow.abs()),
        "the closed form misses the file's recycle"
    );
    let (code, s, err) = size_reactor("0.2 kmol/h/min");
    assert_eq!(code, Some(0), "{err}");
    let du = p.outflow(1.1 * p.f0) - p.outflow(p.f0);
    assert!(abs_diff_eq!(num(&s, "flow_change"), du, epsilon = 1e-5 * du.abs()), "{} vs {du}", s["flow_change"]);
    let r = 0.2 / 3.6 / 60.0;
    for (d, c) in s["designs"].as_array().unwrap().iter().zip([1.0, 2.0 / E, 0.5]) {
        let area = c * p.v_l * du * du / (r * 0.5);
        assert!(abs_diff_eq!(num(d, "closed_form_area"), area, epsilon = 1e-5 * area.abs()), "{d}");
        let v = &d["verified"];
        assert!(v["failure"].is_null() && v["meets"] == true, "{d}");
        assert!(num(v, "max_level_deviation") <= 0.5 * 1.001 && num(v, "max_outflow_rate") <= r * 1.001, "{v}");
    }
    assert_eq!(s["failed"], Value::Array(vec![]));
}

/// #14 at 1 kmol/h/min: the PI and optimal closed forms ask for reactors smaller than Luyben's
/// snowball limit at the file's 3 m level (`F0 (1 − x_B) v_L/(k x_D h)`: no recycle can carry
/// the unconverted A below it), where a design sized at the file's level had no steady state. A
/// reactor's design keeps its liquid volume instead (its level setpoint `3 m × A_file / A`), so its
/// conversion, and every design holds.
#[test]
fn a_reactors_designs_keep_its_volume_below_the_snowball_limit() {
    let p = Recycle::of_file();
    let (code, s, err) = size_reactor("1 kmol/h/min");
    assert_eq!(code, Some(0), "{err}");
    let designs = s["designs"].as_array().unwrap();
    let volume = p.m * p.v_l;
    for d in designs {
        let kept = num(d, "area") * num(d, "normal_level");
        assert!(abs_diff_eq!(kept, volume, epsilon = 1e-6 * volume), "{kept} m³ against {volume} m³: {d}");
        let v = &d["verified"];
        assert!(v["failure"].is_null() && v["meets"] == true, "{d}");
    }
    assert!(designs[1..].iter().all(|d| num(d, "area") < p.least_area()), "{designs:?}");
    assert_eq!(s["failed"], Value::Array(vec![]));
}

/// D10: the surge tank and a new tank on the stream after it see the same outflow and its rate,
/// yet only the tank has a level: the file's P loop holds it 0.80 m off (Δu/Kc), beyond the band,
/// so the tank needs surge and the bare stream, within the rate limit, does not. The table shows
/// the level beside the verdict, and the plot's labels say what the table says.
#[test]
fn candidates_with_the_same_outflow_are_told_apart_by_their_level() {
    let file = train();
    let plot = std::env::temp_dir().join(format!("plantwide_size_d10_{}.svg", std::process::id()));
    let request = &SURGE[2..];
    let args = [&["size", &file, "--candidates", "surge,column_feed", "--plot", plot.to_str().unwrap()][..], request];
    let (code, out, err) = run(&args.concat());
    assert_eq!(code, Some(0), "{err}");
    let du = 0.1 * num(&steady(&file, &[]), "flash_liquid.F");
    let row = |name: &str| out.lines().find(|l| l.contains(&format!("| {name} |"))).unwrap().to_string();
    let cells = |name: &str| row(name).split('|').map(|c| c.trim().to_string()).collect::<Vec<_>>();
    let (tank, stream) = (cells("surge"), cells("column_feed"));
    assert_eq!(tank[4], stream[4], "the same outflow change");
    let deviation = du / (20_000.0 / 3600.0);
    assert!(
        abs_diff_eq!(tank[5].parse::<f64>().unwrap(), deviation, epsilon = 1e-3 * deviation.abs()),
        "{}",
        row("surge")
    );
    assert_eq!(stream[5], "– (no vessel)");
    let rate = |c: &[String]| c[6].parse::<f64>().unwrap();
    let (tank_rate, stream_rate) = (rate(&tank), rate(&stream));
    assert!(
        abs_diff_eq!(tank_rate, stream_rate, epsilon = 1e-2 * stream_rate.abs()) && tank_rate < RATE * 60.0,
        "{out}"
    );
    assert_eq!((tank[7].as_str(), stream[7].as_str()), ("yes", "no"), "{out}");
    let svg = std::fs::read_to_string(&plot).unwrap();
    std::fs::remove_file(&plot).ok();
    for (c, name) in [(&tank, "surge"), (&stream, "column_feed")] {
        let label = format!("{} {name} (needs surge: {}; optimal: {})", c[1], c[7], c[9]);
        assert!(svg.contains(&label), "{label} not in the plot");
    }
}

/// A plot that could not be written is refused before the runs (D11 for `size`), by its path.
#[test]
fn a_plot_into_a_missing_folder_is_refused_before_the_runs() {
    let missing = std::env::temp_dir().join(format!("plantwide_no_such_folder_{}", std::process::id()));
    let plot = missing.join("d3.png");
    let file = train();
    let (code, _, err) = run(&[&["size", &file][..], &SURGE, &["--plot", plot.to_str().unwrap()]].concat());
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains(&format!("the folder {} does not exist", missing.display())), "{err}");
}

/// D3 where nothing holds: the newcomer's surge tank with each design's run cut at 1 min (a
/// length asked, far short of settling). The report shows no figures for any design, only why
/// each failed; no plot stands in for them; the command exits 2.
#[test]
fn when_no_design_has_a_run_the_report_has_no_figures_and_no_plot() {
    let file = train();
    let plot = std::env::temp_dir().join(format!("plantwide_size_none_{}.png", std::process::id()));
    let cut = ["--duration", "1 min", "--plot", plot.to_str().unwrap()];
    let (code, out, err) = run(&[&["size", &file][..], &SURGE, &cut].concat());
    assert_eq!(code, Some(2), "{err}");
    assert!(!plot.exists(), "a plot of failed runs was written");
    assert!(err.contains("no design of `surge` has a verified run"), "{err}");
    for name in ["p", "pi", "optimal"] {
        let row = out.lines().find(|l| l.starts_with(&format!("| {name} |"))).unwrap();
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        assert_eq!(&cells[cells.len() - 4..cells.len() - 2], ["–", "–"], "{row}");
        assert!(cells[cells.len() - 2].starts_with("failed: ") && row.contains("not settled after 60 s"), "{row}");
    }
}

/// The file's tank through a +60 % feed: its P loop would hold the level Δu/Kc = 4.8 m above its
/// 2 m setpoint, past the 4 m top. The model has no overflow, so the report says the vessel cannot
/// take the disturbance rather than quote a level no tank of that height can have.
#[test]
fn a_file_vessel_whose_level_would_pass_its_top_is_said_to_overflow() {
    let file = train();
    let mut args = [&["size", &file][..], &SURGE, &["--json"]].concat();
    args[5] = "feed_source.F=+60%";
    let (code, out, err) = run(&args);
    assert_eq!(code, Some(0), "{err}");
    let s: Value = serde_json::from_str(&out).unwrap();
    let top = 2.0 + 0.6 * num(&steady(&file, &[]), "flash_liquid.F") / (20_000.0 / 3600.0);
    let c = &s["current"];
    assert!(c["meets"] == false && abs_diff_eq!(num(c, "max_deviation") + 2.0, top, epsilon = 1e-3 * top.abs()), "{c}");
    let outside = c["outside"].as_str().unwrap();
    assert!(outside.contains(&format!("reaches {top:.2}")) && outside.ends_with("above its top at 4 m"), "{outside}");
}
