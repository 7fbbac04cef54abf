//! `plantwide identify`: a plant test on the nonlinear model of Skogestad's column A, the
//! identified steady-state gains and RGA against the exact linearization computed independently by
//! `plantwide gains` (and, as an anchor, the published S&P numbers), the test design's JSON against
//! the equations of the reference book's chapter 7, the report files, and bad requests (exit 1
//! with the message).

use approx::abs_diff_eq;

use crate::harness::{fixture, flowsheet, plantwide};

/// Reflux and boilup in kmol/min (the LV configuration's manipulated variables).
const INPUTS: &str = "column.reflux@kmol/min,column.boilup@kmol/min";
/// Top and bottom compositions: stage 41 is the total condenser (x = yD), stage 1 the reboiler (xB).
const OUTPUTS: &str = "column.x[41][light],column.x[1][light]";
/// The issue's "done when": every element of G(0) within 5 % of the exact linearization.
const GAIN_TOLERANCE: f64 = 0.05;
/// … and the RGA's (1,1) element within 17 %.
const RGA11_TOLERANCE: f64 = 0.17;

/// Run `plantwide ARGS`, assert success and parse its JSON output.
fn stdout_json(args: &[&str]) -> serde_json::Value {
    let out = plantwide(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("--json prints JSON")
}

/// Run `plantwide ARGS`, assert exit 1 without a panic and return its standard error.
fn refused(args: &[&str]) -> String {
    let out = plantwide(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    err
}

fn number(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// A JSON matrix (array of arrays of numbers).
fn matrix(v: &serde_json::Value) -> Vec<Vec<f64>> {
    v.as_array()
        .unwrap_or_else(|| panic!("not a matrix: {v}"))
        .iter()
        .map(|r| r.as_array().unwrap_or_else(|| panic!("not a row: {r}")).iter().map(number).collect())
        .collect()
}

/// `|a − b| / |b|`: the error of an identified figure against the exact one, as `identify` reports
/// it (`gain_relative_error`, `rga11_relative_error`). A measured quantity, set against the
/// verdict's thresholds and the reported figures; closeness checks use `approx`.
fn relative_error(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

/// The exact linearization of column A from `plantwide gains` (independent of `identify`): its
/// gain matrix and λ11. Anchored to S&P 2005 eq. 12.17, G(0) = [[0.878, −0.864], [1.082, −1.096]]
/// (three figures) and λ11 = 35.1: the elements within 1 % and λ11 within 3 % (this model gives
/// 35.9; the published matrix's λ11 is sensitive to its rounding).
fn exact_gains() -> (Vec<Vec<f64>>, f64) {
    let v = stdout_json(&["gains", &flowsheet("column_a.json"), "--inputs", INPUTS, "--outputs", OUTPUTS, "--json"]);
    let g = matrix(&v["gain"]);
    let l11 = number(&v["rga"][0][0]);
    let published: [[f64; 2]; 2] = [[0.878, -0.864], [1.082, -1.096]];
    for (i, row) in published.iter().enumerate() {
        for (j, p) in row.iter().enumerate() {
            assert!(
                abs_diff_eq!(g[i][j], *p, epsilon = 0.01 * p.abs()),
                "exact G{i}{j} = {} vs published {p}",
                g[i][j]
            );
        }
    }
    assert!(abs_diff_eq!(l11, 35.1, epsilon = 0.03 * 35.1), "exact λ11 = {l11} vs published 35.1");
    (g, l11)
}

/// The identify arguments of the column A test: σ = 1e-4 on both compositions, moves of
/// ±`amplitude` kmol/min, 16300 min (four PRBS periods of this τ_dom), then `extra`. (`--amplitude`
/// given twice appends: one value per occurrence, so it is an argument here, not an extra.)
fn column_a_args(file: &str, seed: &str, amplitude: &str, extra: &[&str]) -> Vec<String> {
    let base = [
        "identify",
        &flowsheet(file),
        "--inputs",
        INPUTS,
        "--outputs",
        OUTPUTS,
        "--noise",
        "1e-4",
        "--amplitude",
        amplitude,
        "--duration",
        "16300 min",
        "--seed",
        seed,
        "--json",
    ]
    .map(str::to_string);
    base.into_iter().chain(extra.iter().map(|e| e.to_string())).collect()
}

/// The column A test ([`column_a_args`]), which must succeed: its JSON.
fn column_a_test(file: &str, seed: &str, amplitude: &str, extra: &[&str]) -> serde_json::Value {
    let args = column_a_args(file, seed, amplitude, extra);
    stdout_json(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

/// Run `plantwide ARGS` (with `--json`) whatever its exit: the exit code, the JSON it printed
/// and its standard error.
fn judged(args: &[&str]) -> (Option<i32>, serde_json::Value, String) {
    let out = plantwide(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    let v = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{args:?}: {e}: {err}"));
    (out.status.code(), v, err)
}

/// The verdict's criterion `name` (the first of that name).
fn criterion<'a>(v: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    let all = v["verdict"]["criteria"].as_array().unwrap_or_else(|| panic!("no verdict in {v}"));
    all.iter().find(|c| c["criterion"] == name).unwrap_or_else(|| panic!("no {name} in {}", v["verdict"]))
}

/// Largest element error of `identified` against `exact`, and λ11's error.
fn errors(identified: &serde_json::Value, exact: &[Vec<f64>], l11: f64) -> (f64, f64) {
    let g = matrix(&identified["gain"]);
    let worst = (0..2).flat_map(|i| (0..2).map(move |j| (i, j))).map(|(i, j)| relative_error(g[i][j], exact[i][j]));
    let worst = worst.fold(0.0, f64::max);
    let l = number(&identified["rga"][0][0]);
    (worst, relative_error(l, l11))
}

/// The issue's "done when", on column A (κ ≈ 142, λ11 ≈ 36: the low-gain direction is ~1/140 of
/// the high-gain one) with σ = 1e-4 measurement noise and the default directional design: the
/// identified G(0) within 5 % of the exact linearization element by element and λ11 within 17 %,
/// for three seeds. The reference is `plantwide gains` (the exact linearization, computed by
/// another command); `identify`'s own "exact" field must equal it to 1e-9.
#[test]
fn directional_test_identifies_column_a_gains_and_rga_within_the_issue_tolerances() {
    let (exact, l11) = exact_gains();
    for seed in ["1", "2", "3"] {
        let v = column_a_test("column_a.json", seed, "0.02", &[]);
        assert_eq!(v["design"]["design"], "directional", "the default design");
        let own = matrix(&v["exact"]["gain"]);
        for i in 0..2 {
            for j in 0..2 {
                assert!(
                    (own[i][j] - exact[i][j]).abs() < 1e-9 * exact[i][j].abs(),
                    "exact G{i}{j}: identify {} vs gains {}",
                    own[i][j],
                    exact[i][j]
                );
            }
        }
        assert!(abs_diff_eq!(number(&v["exact"]["rga"][0][0]), l11, epsilon = 1e-9 * l11.abs()), "{}", v["exact"]);
        let (gain_error, rga_error) = errors(&v, &exact, l11);
        println!(
            "seed {seed}: G = {:?}, λ11 = {:.3} (exact {l11:.3}); largest gain error {:.2} %, λ11 error {:.2} %",
            matrix(&v["gain"]),
            number(&v["rga"][0][0]),
            100.0 * gain_error,
            100.0 * rga_error
        );
        assert!(gain_error < GAIN_TOLERANCE, "seed {seed}: largest gain error {:.2} %", 100.0 * gain_error);
        assert!(rga_error < RGA11_TOLERANCE, "seed {seed}: λ11 error {:.2} %", 100.0 * rga_error);
        // The reported errors are those against the same exact gains.
        let reported = matrix(&v["exact"]["gain_relative_error"]);
        let worst = reported.iter().flatten().copied().fold(0.0, f64::max);
        assert!((worst - gain_error).abs() < 1e-9, "reported {worst} vs {gain_error}");
        assert!((number(&v["exact"]["rga11_relative_error"]) - rga_error).abs() < 1e-6);
    }
}

/// Why the directional design exists: delayed copies of one PRBS (independent moves of L and V,
/// ±0.002 kmol/min, the same noise and length) excite mainly the high-gain direction, so the
/// low-gain one, and with it λ11, is lost in the noise: λ11 off by more than the 17 % the
/// directional design meets (measured: ~65 %) while every element is within 10 %, against the
/// exact `plantwide gains` value.
#[test]
fn independent_prbs_misses_the_low_gain_direction_of_column_a() {
    let (exact, l11) = exact_gains();
    let args = column_a_args("column_a.json", "1", "0.002", &["--design", "prbs"]);
    let (code, prbs, err) = judged(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let directional = column_a_test("column_a.json", "1", "0.02", &[]);
    assert_eq!(prbs["design"]["design"], "prbs");
    assert!(prbs["design"]["directions"].is_null(), "{}", prbs["design"]);
    let (prbs_gain, prbs_rga) = errors(&prbs, &exact, l11);
    let (dir_gain, dir_rga) = errors(&directional, &exact, l11);
    println!(
        "exact λ11 = {l11:.3}; prbs: λ11 = {:.3} ({:.1} % off, largest gain error {:.1} %); \
         directional: λ11 = {:.3} ({:.1} % off, largest gain error {:.1} %)",
        number(&prbs["rga"][0][0]),
        100.0 * prbs_rga,
        100.0 * prbs_gain,
        number(&directional["rga"][0][0]),
        100.0 * dir_rga,
        100.0 * dir_gain
    );
    let amplitude: Vec<f64> = prbs["design"]["amplitude"].as_array().unwrap().iter().map(number).collect();
    assert!(amplitude.iter().all(|a| abs_diff_eq!(*a, 0.002, epsilon = 1e-9 * 0.002)), "{amplitude:?}");
    assert!(prbs_rga > RGA11_TOLERANCE, "independent PRBS: λ11 error only {:.1} %", 100.0 * prbs_rga);
    // The elements themselves are near (measured: ~6 %): what is lost is the small difference
    // between them that sets the low-gain direction, λ11 ≈ 1/(1 − g12 g21/(g11 g22)).
    assert!(prbs_gain < 0.1, "independent PRBS: largest gain error {:.1} %", 100.0 * prbs_gain);
    assert!(dir_rga < RGA11_TOLERANCE, "directional: λ11 error {:.1} %", 100.0 * dir_rga);
    // The verdict sees what the elements hide: the RGA error fails, the model is not usable (exit 2).
    assert_eq!(code, Some(2), "{err}");
    assert_eq!(prbs["verdict"]["reliable"], false);
    assert_eq!(criterion(&prbs, "gain_error")["pass"], true, "{}", prbs["verdict"]);
    assert_eq!(criterion(&prbs, "rga_error")["pass"], false, "{}", prbs["verdict"]);
    assert!(err.contains("rga_error") && err.contains("not usable"), "{err}");
    assert_eq!(directional["verdict"]["reliable"], true, "{}", directional["verdict"]);
}

/// Closed loop by setpoint injection on `column_a_lv.json` (column A with PI composition loops at
/// yD = 0.99, xB = 0.01, the published operating point of `column_a.json`): the loops drive reflux
/// and boilup, the test moves their setpoints, the fits read the controller outputs. The
/// identified open-loop G(0) within 5 % and λ11 within 17 % of the exact linearization of the
/// same column without the loops (`plantwide gains` on `column_a.json`).
#[test]
fn closed_loop_setpoint_injection_identifies_the_open_loop_gains_of_column_a() {
    let (exact, l11) = exact_gains();
    let v = column_a_test("column_a_lv.json", "1", "0.02", &["--closed-loop"]);
    let own = matrix(&v["exact"]["gain"]);
    for i in 0..2 {
        for j in 0..2 {
            // The same steady state reached through the PI loops' integral action (Newton tolerance).
            assert!(
                abs_diff_eq!(own[i][j], exact[i][j], epsilon = 1e-5 * exact[i][j].abs()),
                "exact G{i}{j}: {} vs {}",
                own[i][j],
                exact[i][j]
            );
        }
    }
    let (gain_error, rga_error) = errors(&v, &exact, l11);
    println!(
        "closed loop: G = {:?}, λ11 = {:.3} (exact {l11:.3}); largest gain error {:.2} %, λ11 error {:.2} %",
        matrix(&v["gain"]),
        number(&v["rga"][0][0]),
        100.0 * gain_error,
        100.0 * rga_error
    );
    assert!(gain_error < GAIN_TOLERANCE, "largest gain error {:.2} %", 100.0 * gain_error);
    assert!(rga_error < RGA11_TOLERANCE, "λ11 error {:.2} %", 100.0 * rga_error);
}

/// The JSON document: its top-level keys, and the design against the reference book's equations:
/// `N = 2^n − 1` clocks per period, the band `[2π/(N T_cl), 2.8/T_cl]` (Eq. 7-6), and the clock
/// period `T_cl = 2.8 τ_dom/α` rounded down to a whole number of samples (Eq. 7-8), from the
/// design's own τ_dom and α; the amplitudes in the display unit asked for.
#[test]
fn json_contract_and_test_design_follow_chapter_7() {
    let v = column_a_test("column_a.json", "1", "0.02", &["--alpha", "3"]);
    let keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    for key in ["inputs", "outputs", "gain", "rga", "models", "validation", "design", "exact"] {
        assert!(keys.contains(&key), "no `{key}` in {keys:?}");
    }
    for key in ["gain", "rga", "gain_relative_error", "rga11_relative_error"] {
        assert!(v["exact"].get(key).is_some(), "no exact.{key} in {}", v["exact"]);
    }
    assert_eq!(v["inputs"][0]["path"], "column.reflux");
    assert_eq!(v["inputs"][0]["unit"], "kmol/min");
    assert_eq!(v["outputs"][1]["path"], "column.x[1][light]");
    let models = v["models"].as_array().unwrap();
    assert_eq!(models.len(), 2 * 3, "FIR, ARX and OE per output");
    let chosen = v["validation"]["model"].as_str().unwrap();
    assert!(["fir", "arx", "oe"].contains(&chosen), "{chosen}");
    assert_eq!(v["validation"]["outputs"].as_array().unwrap().len(), 2);

    let d = &v["design"];
    let (ts, t_cl, tau, alpha) =
        (number(&d["sample_time"]), number(&d["clock_period"]), number(&d["tau_dom"]), number(&d["alpha"]));
    assert_eq!(alpha, 3.0, "--alpha is the design's α");
    let registers = d["registers"].as_u64().unwrap();
    let n = d["period_clocks"].as_u64().unwrap();
    assert_eq!(n, (1 << registers) - 1, "N = 2^n − 1");
    let period = number(&d["period"]);
    let n_t_cl = n as f64 * t_cl;
    assert!(abs_diff_eq!(period, n_t_cl, epsilon = 1e-9 * n_t_cl.abs()), "period {period} vs N T_cl");
    let band = matrix(&serde_json::json!([d["band"]]))[0].clone();
    let (low, high) = (2.0 * std::f64::consts::PI / n_t_cl, 2.8 / t_cl);
    assert!(abs_diff_eq!(band[0], low, epsilon = 1e-9 * low.abs()), "{band:?}");
    assert!(abs_diff_eq!(band[1], high, epsilon = 1e-9 * high.abs()), "{band:?}");
    // Eq. 7-8 rounded down to a multiple of the sample time.
    let clocks = t_cl / ts;
    assert!((clocks - clocks.round()).abs() < 1e-9 && clocks.round() >= 1.0, "T_cl = {t_cl}, T_s = {ts}");
    let ideal = 2.8 * tau / alpha;
    assert!(t_cl <= ideal * (1.0 + 1e-9) && t_cl + ts > ideal, "T_cl = {t_cl} for 2.8 τ/α = {ideal}, T_s = {ts}");
    // The amplitudes come back in the unit they were given in (kmol/min), and the directional
    // design's largest move is the amplitude.
    let amplitude: Vec<f64> = d["amplitude"].as_array().unwrap().iter().map(number).collect();
    assert_eq!(amplitude.len(), 2);
    for a in &amplitude {
        assert!(abs_diff_eq!(*a, 0.02, epsilon = 1e-9 * 0.02), "{amplitude:?}");
    }
    assert!(number(&d["duration"]) >= period, "{d}");
}

/// `--report DIR` writes the markdown, the HTML, the JSON and the validation plot, each non-empty,
/// the JSON the same document `--json` prints.
#[test]
fn report_writes_markdown_html_json_and_validation_plot() {
    let dir = std::env::temp_dir().join(format!("plantwide-identify-report-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    let v = column_a_test("column_a.json", "1", "0.02", &["--report", dir.to_str().unwrap()]);
    for name in ["identify.md", "identify.html", "identify.json", "validation.png"] {
        let len = std::fs::metadata(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}")).len();
        assert!(len > 0, "{name} is empty");
    }
    let written: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("identify.json")).unwrap()).unwrap();
    assert_eq!(written, v);
    let md = std::fs::read_to_string(dir.join("identify.md")).unwrap();
    assert!(md.contains("validation.png") && md.contains("column.reflux"), "{md}");
    let png = std::fs::read(dir.join("validation.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG"), "validation.png is no PNG");
    std::fs::remove_dir_all(&dir).ok();
}

/// Bad requests exit 1 with a message naming the problem, never a panic: a test shorter than one
/// PRBS period, a σ count that matches neither one nor the outputs, an unknown input, a
/// closed-loop test of an input no controller drives, an amplitude that would push the feed's
/// mole fraction (0.5) out of [0, 1], and a directional design on a singular gain (the same
/// output twice).
#[test]
fn bad_requests_exit_1_naming_the_problem() {
    let file = flowsheet("column_a.json");
    let run = |inputs: &str, outputs: &str, extra: &[&str]| {
        refused(&[&["identify", file.as_str(), "--inputs", inputs, "--outputs", outputs][..], extra].concat())
    };
    let err = run(INPUTS, OUTPUTS, &["--duration", "100 min"]);
    assert!(err.contains("period") && err.contains("--duration"), "{err}");
    let err = run(INPUTS, OUTPUTS, &["--noise", "1e-4,1e-4,1e-4"]);
    assert!(err.contains("--noise") && err.contains("3 values for 2 outputs"), "{err}");
    let err = run("column.nothing@kmol/min,column.boilup@kmol/min", OUTPUTS, &[]);
    assert!(err.contains("column.nothing"), "{err}");
    let err = run(INPUTS, OUTPUTS, &["--closed-loop"]);
    assert!(err.contains("column.reflux") && err.contains("not driven by a controller"), "{err}");
    let err = run("feed_source.z[light],column.boilup@kmol/min", OUTPUTS, &["--amplitude", "0.6,0.02"]);
    assert!(err.contains("feed_source.z[light]") && err.contains("cannot move"), "{err}");
    let err = run(INPUTS, "column.x[41][light],column.x[41][light]", &[]);
    assert!(err.contains("singular"), "{err}");
    // A list flag given twice is refused, not appended to (0.02 then 0.002 would move the inputs by both).
    let err = run(INPUTS, OUTPUTS, &["--amplitude", "0.02", "--amplitude", "0.002"]);
    assert!(err.contains("--amplitude") && err.contains("multiple times"), "{err}");
}

/// The newcomer's benzene–toluene column (`tests/data/newcomer3/`): reflux and reboiler duty to
/// the distillate and bottoms benzene fractions.
const BT_INPUTS: &str = "column.reflux,column.reboiler_duty";
const BT_OUTPUTS: &str = "distillate.x[benzene],bottoms.x[benzene]";

/// The exact G(0) of the newcomer's column from `plantwide gains` (its levels held by D and B, no
/// composition loops): independent of `identify`.
fn bt_exact_gains() -> Vec<Vec<f64>> {
    let file = fixture("data/newcomer3/bt_column.json");
    matrix(&stdout_json(&["gains", &file, "--inputs", BT_INPUTS, "--outputs", BT_OUTPUTS, "--json"])["gain"])
}

/// Each row of `models` (display units equal SI here) against `exact`: its worst relative element
/// error and whether an element has the wrong sign.
fn model_errors(models: &serde_json::Value, outputs: &[&str], exact: &[Vec<f64>]) -> Vec<(f64, bool, bool)> {
    let rows = models.as_array().unwrap();
    rows.iter()
        .map(|m| {
            let i = outputs.iter().position(|o| m["output"] == *o).unwrap_or_else(|| panic!("{m}"));
            let g: Vec<f64> = m["gain"].as_array().unwrap().iter().map(number).collect();
            let worst = g.iter().zip(&exact[i]).map(|(g, e)| relative_error(*g, *e)).fold(0.0, f64::max);
            let wrong_sign = g.iter().zip(&exact[i]).any(|(g, e)| g.signum() != e.signum());
            (worst, wrong_sign, m["reliable"].as_bool().unwrap())
        })
        .collect()
}

/// Issue 53 D13: closed loop, the newcomer's column gave a model whose bottoms gains are half the
/// exact ones (43 % fit, 31 % gain error in the newcomer's run) with no verdict and exit 0. The
/// verdict now fails on the gain error it prints beside the exact gain, exit 2 naming it; no model
/// row whose gains are over 20 % off the exact ones (computed here against `plantwide gains`) or of
/// the wrong sign is marked reliable.
#[test]
fn verdict_refuses_the_newcomer_closed_loop_model_whose_bottoms_gains_are_off() {
    let exact = bt_exact_gains();
    let file = fixture("data/newcomer3/bt_column_lv.json");
    let args = ["identify", &file, "--closed-loop", "--inputs", BT_INPUTS, "--outputs", BT_OUTPUTS, "--json"];
    let (code, v, err) = judged(&args);
    assert_eq!(code, Some(2), "{err}");
    assert_eq!(v["verdict"]["reliable"], false);
    let g = matrix(&v["gain"]);
    let bottoms = (0..2).map(|j| relative_error(g[1][j], exact[1][j])).fold(0.0, f64::max);
    println!("closed-loop newcomer column: G = {g:?} vs exact {exact:?}; bottoms error {:.1} %", 100.0 * bottoms);
    assert!(bottoms > 0.2, "bottoms gains within {:.1} % of plantwide gains", 100.0 * bottoms);
    let gain_error = criterion(&v, "gain_error");
    assert_eq!(gain_error["pass"], false, "{gain_error}");
    assert!(gain_error["at"].as_str().unwrap().starts_with("`bottoms.x[benzene]`"), "{gain_error}");
    assert!((number(&gain_error["value"]) - bottoms).abs() < 1e-3, "{gain_error} vs {bottoms}");
    assert!(err.contains("gain_error") && err.contains("`bottoms.x[benzene]`") && err.contains("exact"), "{err}");
    for (worst, wrong_sign, reliable) in
        model_errors(&v["models"], &["distillate.x[benzene]", "bottoms.x[benzene]"], &exact)
    {
        assert!(!reliable || (worst <= 0.2 && !wrong_sign), "reliable with a {:.1} % gain error", 100.0 * worst);
    }
}

/// The same column open loop: the verdict passes, and the chosen model's gains are within the
/// verdict's 20 % of `plantwide gains` (measured: within 3 %), every model row marked reliable
/// within 20 % and of the right sign.
#[test]
fn verdict_accepts_the_newcomer_open_loop_model_with_gains_near_the_exact_ones() {
    let exact = bt_exact_gains();
    let file = fixture("data/newcomer3/bt_column.json");
    let v = stdout_json(&["identify", &file, "--inputs", BT_INPUTS, "--outputs", BT_OUTPUTS, "--json"]);
    assert_eq!(v["verdict"]["reliable"], true, "{}", v["verdict"]);
    let g = matrix(&v["gain"]);
    let worst = (0..2).flat_map(|i| (0..2).map(move |j| (i, j))).map(|(i, j)| relative_error(g[i][j], exact[i][j]));
    let worst = worst.fold(0.0, f64::max);
    println!("open-loop newcomer column: G = {g:?} vs exact {exact:?}; worst error {:.1} %", 100.0 * worst);
    assert!(worst < 0.2, "largest gain error {:.1} %", 100.0 * worst);
    for (worst, wrong_sign, reliable) in
        model_errors(&v["models"], &["distillate.x[benzene]", "bottoms.x[benzene]"], &exact)
    {
        assert!(!reliable || (worst <= 0.2 && !wrong_sign), "reliable with a {:.1} % gain error", 100.0 * worst);
    }
}

/// Issue 54 D6 (`../shared/cases/fuzz3/README.txt`): `--noise 1000` on column A returned a −1 % fit
/// model with gains 7e4× off, exit 0, and wrote step_model.json. Now exit 2 naming the fit and the
/// wrong signs, the report written without step_model.json; `--force` writes it, still exit 2.
/// The signs are checked here against `plantwide gains`.
#[test]
fn a_model_lost_in_noise_exits_2_and_writes_no_mpc_model() {
    let (exact, _) = exact_gains();
    let dir = std::env::temp_dir().join(format!("plantwide-identify-noise-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    let file = flowsheet("column_a.json");
    let report = dir.to_str().unwrap();
    let args =
        ["identify", &file, "--inputs", INPUTS, "--outputs", OUTPUTS, "--noise", "1000", "--json", "--report", report];
    let (code, v, err) = judged(&args);
    assert_eq!(code, Some(2), "{err}");
    assert_eq!(v["verdict"]["reliable"], false);
    let g = matrix(&v["gain"]);
    let wrong =
        (0..2).flat_map(|i| (0..2).map(move |j| (i, j))).filter(|&(i, j)| g[i][j].signum() != exact[i][j].signum());
    assert!(wrong.count() >= 1, "G = {g:?} vs exact {exact:?}");
    for name in ["fit", "gain_sign", "gain_error"] {
        assert_eq!(criterion(&v, name)["pass"], false, "{name}: {}", v["verdict"]);
        assert!(err.contains(name), "{name}: {err}");
    }
    assert!(number(&criterion(&v, "fit")["value"]) < 50.0);
    assert!(dir.join("identify.md").exists() && !dir.join("step_model.json").exists());
    assert!(err.contains("step_model.json not written"), "{err}");
    let forced = plantwide(&[&args[..], &["--force"]].concat());
    assert_eq!(forced.status.code(), Some(2));
    assert!(dir.join("step_model.json").exists());
    std::fs::remove_dir_all(&dir).ok();
}
