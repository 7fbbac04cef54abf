//! Control analysis against published numbers and independent closed forms: column A gains by
//! linearization and by perturbation, its dominant time constant, the surge tank's eigenvalues,
//! Wood–Berry from its transfer-function file, sensitivity sweeps and the CLI.

use crate::harness::{self, converge, flowsheet, plantwide, value};
use plantwide::analysis::AnalysisError;
use plantwide::analysis::faer::linalg::solvers::Solve;
use plantwide::analysis::faer::{Mat, c64};
use plantwide::analysis::linear::Linearization;
use plantwide::analysis::measures::{niederlinski, rga};
use plantwide::analysis::perturb::{PerturbSettings, perturb_gains};
use plantwide::analysis::select::{Signal, select_inputs, select_outputs};
use plantwide::analysis::sensitivity::{Disturbance, SweepSettings, sweep};
use plantwide::analysis::sensors::select_temperature_sensors;
use plantwide::io::tf;
use plantwide::solve::{NewtonSettings, steady_state};

fn strings(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

fn indices(s: &[Signal]) -> Vec<usize> {
    s.iter().map(|s| s.index).collect()
}

/// SI gains in the signals' display units.
fn display(g: &Mat<f64>, inputs: &[Signal], outputs: &[Signal]) -> Mat<f64> {
    Mat::from_fn(g.nrows(), g.ncols(), |i, j| g[(i, j)] * inputs[j].factor / outputs[i].factor)
}

fn max_rel_diff(a: &Mat<f64>, b: &Mat<f64>) -> f64 {
    let mut worst: f64 = 0.0;
    for i in 0..a.nrows() {
        for j in 0..a.ncols() {
            worst = worst.max((a[(i, j)] - b[(i, j)]).abs() / b[(i, j)].abs());
        }
    }
    worst
}

const LV_INPUTS: [&str; 2] = ["column.reflux@kmol/min", "column.boilup@kmol/min"];
const LV_OUTPUTS: [&str; 2] = ["distillate.x[light]", "bottoms.x[light]"];

/// Column A (S&P 2005 §12.4), LV configuration with P level loops. Published idealized LV model
/// (eq. 12.17): G(0) = [0.878 −0.864; 1.082 −1.096], λ11 = 35.1; MATLAB `cola` linearization of
/// the same nonlinear column: about [0.8780 −0.8644; 1.0819 −1.0958].
#[test]
fn column_a_gains_by_linearization_and_by_perturbation_agree() {
    let (plant, ss) = converge("column_a.json");
    let inputs = select_inputs(&plant, &strings(&LV_INPUTS)).unwrap();
    let outputs = select_outputs(&plant, &strings(&LV_OUTPUTS)).unwrap();
    let (ii, oo) = (indices(&inputs), indices(&outputs));
    let lin = Linearization::new(&plant, &ss.x, &ss.u);
    let g_lin = display(&lin.steady_gain(&ii, &oo).unwrap(), &inputs, &outputs);
    let p = perturb_gains(&plant, &ss.x, &ss.u, &ii, &oo, &PerturbSettings::default()).unwrap();
    let g_pert = display(&p.gain, &inputs, &outputs);
    // Two independent routes: exact Jacobians + one sparse LU, and re-converged nonlinear steady
    // states. Central differences err by ~1e4·step² here (1.5e-6 at step 1e-5).
    assert!(
        max_rel_diff(&g_pert, &g_lin) < 1e-5,
        "the default step should agree to 1e-5: linear {g_lin:?} vs perturb {g_pert:?}"
    );
    assert!(p.error_ratio < 1e-6);
    let cola = Mat::from_fn(2, 2, |i, j| [[0.8780, -0.8644], [1.0819, -1.0958]][i][j]);
    let published = Mat::from_fn(2, 2, |i, j| [[0.878, -0.864], [1.082, -1.096]][i][j]);
    assert!(max_rel_diff(&g_lin, &cola) < 0.01, "{g_lin:?}");
    assert!(max_rel_diff(&g_lin, &published) < 0.03, "{g_lin:?}");
    let l11 = rga(g_lin.as_ref()).unwrap()[(0, 0)];
    assert!((l11 - 35.1).abs() < 0.05 * 35.1, "λ11 = {l11}");
}

/// A shipped (or test) column, its two inputs and its two end-quality outputs.
struct ColumnCase {
    file: &'static str,
    inputs: [&'static str; 2],
    outputs: [&'static str; 2],
}

const COLUMNS: [ColumnCase; 5] = [
    ColumnCase { file: "flowsheets/column_a.json", inputs: LV_INPUTS, outputs: LV_OUTPUTS },
    // Column A with α = 2, L = 2.0, V = 2.5 kmol/min: yD ≈ 0.99993, λ11 ≈ 3684 (issue 13). The
    // old fixed step 1e-5 gave gains 2.8 % off and λ11 ≈ −68.
    ColumnCase { file: "tests/data/column_a_alpha2.json", inputs: LV_INPUTS, outputs: LV_OUTPUTS },
    ColumnCase { file: "flowsheets/example_4_1.json", inputs: LV_INPUTS, outputs: LV_OUTPUTS },
    ColumnCase {
        file: "flowsheets/btx_column.json",
        inputs: ["column.reflux@kmol/h", "column.reboiler_duty@MW"],
        outputs: ["distillate.x[toluene]", "bottoms.x[benzene]"],
    },
    ColumnCase {
        file: "flowsheets/ethanol_water.json",
        inputs: ["column.reflux@kmol/h", "column.reboiler_duty@MW"],
        outputs: ["distillate.x[ethanol]", "bottoms.x[ethanol]"],
    },
];

/// The check every column must pass: perturbation gains with the default settings agree with
/// the exact linearization (an independent route: exact Jacobians, one sparse LU) to 0.5 %
/// element by element, and so does λ11, sign and magnitude. Returns the linear λ11.
fn perturbation_agrees_with_linearization(case: &ColumnCase) -> f64 {
    let path = format!("{}/{}", harness::ROOT, case.file);
    let plant = plantwide::flowsheet::load_file(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
    let ss = steady_state(&plant, &plant.input_values(), None, &NewtonSettings::default()).unwrap();
    let inputs = select_inputs(&plant, &strings(&case.inputs)).unwrap();
    let outputs = select_outputs(&plant, &strings(&case.outputs)).unwrap();
    let (ii, oo) = (indices(&inputs), indices(&outputs));
    let g_lin = Linearization::new(&plant, &ss.x, &ss.u).steady_gain(&ii, &oo).unwrap();
    let p = perturb_gains(&plant, &ss.x, &ss.u, &ii, &oo, &PerturbSettings::default())
        .unwrap_or_else(|e| panic!("{}: {e}", case.file));
    let d = max_rel_diff(&p.gain, &g_lin);
    assert!(d < 5e-3, "{}: perturbation {:?} vs linearization {g_lin:?}: {d:e}", case.file, p.gain);
    let (l_lin, l_pert) = (rga(g_lin.as_ref()).unwrap()[(0, 0)], rga(p.gain.as_ref()).unwrap()[(0, 0)]);
    assert!((l_pert - l_lin).abs() < 5e-3 * l_lin.abs(), "{}: λ11 {l_pert} vs {l_lin}", case.file);
    // The figures reported are the ones the returned gains passed.
    assert!(p.check.max_relative_difference <= PerturbSettings::default().tolerance, "{}: {:?}", case.file, p.check);
    assert!(p.check.linear_relative_difference.is_some_and(|d| d <= 1e-3), "{}: {:?}", case.file, p.check);
    l_lin
}

#[test]
fn perturbation_gains_verify_themselves_on_every_shipped_column() {
    let lambdas: Vec<f64> = COLUMNS.iter().map(perturbation_agrees_with_linearization).collect();
    // The α = 2 column is the hard case: a nearly singular gain with a large positive λ11.
    assert!(lambdas[1] > 1000.0, "λ11 of the α = 2 column: {}", lambdas[1]);
}

/// The two-column plant's columns inside the whole plant (quality loops open), as the chapter-6
/// study analyses them; the study itself (`tests/two_column_study.rs`) covers all six structures.
#[test]
fn perturbation_gains_verify_themselves_on_the_two_column_plant() {
    let cases = [
        ColumnCase {
            file: "docs/two_column_plant/inputs/column1_LV_open.json",
            inputs: ["column1.reflux@kmol/h", "column1.boilup@kmol/h"],
            outputs: ["column1.T[21]", "column1.T[11]"],
        },
        ColumnCase {
            file: "docs/two_column_plant/inputs/column2_LV_open.json",
            inputs: ["column2.reflux@kmol/h", "column2.boilup@kmol/h"],
            outputs: ["product.x[S]", "column2.T[6]"],
        },
    ];
    for case in &cases {
        perturbation_agrees_with_linearization(case);
    }
}

/// A deliberately bad explicit step (1e-1 on the α = 2 column: L ± 0.2 kmol/min, a hundred times
/// the distillate impurity's room) is corrected (the step shrunk until h and h/2 agree) or
/// reported; never returned as if it were right.
#[test]
fn a_bad_explicit_step_is_corrected_or_reported() {
    let path = harness::fixture("data/column_a_alpha2.json");
    let base = [
        "gains",
        path.as_str(),
        "--inputs",
        "column.reflux@kmol/min,column.boilup@kmol/min",
        "--outputs",
        "distillate.x[light],bottoms.x[light]",
        "--json",
    ];
    let lin = plantwide(&base);
    assert!(lin.status.success(), "{}", String::from_utf8_lossy(&lin.stderr));
    let lin: serde_json::Value = serde_json::from_slice(&lin.stdout).unwrap();
    let l_lin = lin["rga"][0][0].as_f64().unwrap();
    let out = plantwide(&[&base[..], &["--method", "perturb", "--step", "1e-1"]].concat());
    match out.status.code() {
        Some(0) => {
            let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
            for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                let (a, b) = (v["gain"][i][j].as_f64().unwrap(), lin["gain"][i][j].as_f64().unwrap());
                assert!((a - b).abs() < 5e-3 * b.abs(), "G{i}{j}: {a} vs {b}");
            }
            let l = v["rga"][0][0].as_f64().unwrap();
            assert!((l - l_lin).abs() < 5e-3 * l_lin, "λ11 {l} vs {l_lin}");
            assert!(v["perturbation"]["step"].as_f64().unwrap() < 1e-3, "{}", v["perturbation"]);
            assert!(v["perturbation"]["attempts"].as_u64().unwrap() > 1, "{}", v["perturbation"]);
        }
        code => {
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(code, Some(2), "{stderr}");
            assert!(stderr.contains("--step"), "{stderr}");
        }
    }
    // With no room to shrink the step, the same request is refused with a typed error that names
    // the pair, the two estimates and what to try.
    let plant = plantwide::flowsheet::load_file(std::path::Path::new(&path)).unwrap();
    let ss = steady_state(&plant, &plant.input_values(), None, &NewtonSettings::default()).unwrap();
    let inputs = select_inputs(&plant, &strings(&LV_INPUTS)).unwrap();
    let outputs = select_outputs(&plant, &strings(&LV_OUTPUTS)).unwrap();
    let once = PerturbSettings { step: Some(1e-1), max_attempts: 1, ..PerturbSettings::default() };
    let e = perturb_gains(&plant, &ss.x, &ss.u, &indices(&inputs), &indices(&outputs), &once).unwrap_err();
    assert!(matches!(e, AnalysisError::PerturbationUnverified(_) | AnalysisError::NotConverged(_)), "{e:?}");
    assert!(!e.is_user_error(), "a numerical failure (exit 2)");
    // The library names the request's field; the command line names it by its flag (above).
    let text = e.to_string();
    assert!(text.contains("try `step` ") && !text.contains("--"), "{text}");
    if let AnalysisError::PerturbationUnverified(u) = &e {
        assert!(u.input.starts_with("column.") && u.output.ends_with("x[light]"), "{text}");
        assert!(u.first.is_finite() && u.second.is_finite() && u.first != u.second, "{text}");
    }
}

/// Three routes to G(0) on the full column must agree to round-off: −C J⁻¹ B, D − C A⁻¹ B of the
/// eliminated state-space model, and the sparse complex solve of (jωM − J) at ω = 0; and the
/// sparse G(jω) of the whole DAE equals the dense D + C (jωI − A)⁻¹ B.
#[test]
fn column_a_state_space_agrees_with_the_full_jacobian() {
    let (plant, ss) = converge("column_a.json");
    let inputs = select_inputs(&plant, &strings(&LV_INPUTS)).unwrap();
    let outputs = select_outputs(&plant, &strings(&LV_OUTPUTS)).unwrap();
    let (ii, oo) = (indices(&inputs), indices(&outputs));
    let lin = Linearization::new(&plant, &ss.x, &ss.u);
    let model = lin.state_space(&ii, &oo).unwrap();
    assert_eq!(model.states.len(), 82, "41 stages × 2 component holdups");
    let g = lin.steady_gain(&ii, &oo).unwrap();
    assert!(max_rel_diff(&model.steady_gain().unwrap(), &g) < 1e-9);
    let omegas = [0.0, 1e-4, 1e-2];
    let responses = lin.frequency_response(&ii, &oo, &omegas).unwrap();
    for (w, gw) in omegas.iter().zip(&responses) {
        let dense = model.frequency_response(*w);
        for i in 0..2 {
            for j in 0..2 {
                assert!((gw[(i, j)] - dense[(i, j)]).norm() < 1e-9 * dense[(i, j)].norm(), "ω = {w}");
            }
        }
    }
    assert!(max_rel_diff(&Mat::from_fn(2, 2, |i, j| responses[0][(i, j)].re), &g) < 1e-9);
}

/// The slowest mode of column A: S&P report a dominant time constant of 194 min for this column.
#[test]
fn column_a_slowest_time_constant_is_194_minutes() {
    let (plant, ss) = converge("column_a.json");
    let inputs = select_inputs(&plant, &strings(&LV_INPUTS)).unwrap();
    let outputs = select_outputs(&plant, &strings(&LV_OUTPUTS)).unwrap();
    let model = Linearization::new(&plant, &ss.x, &ss.u).state_space(&indices(&inputs), &indices(&outputs)).unwrap();
    let tau = model.time_constants().unwrap();
    assert!(model.unstable(1e-12).unwrap().is_empty());
    let slowest_min = tau[0] / 60.0;
    assert!((slowest_min - 194.0).abs() < 0.01 * 194.0, "τ = {slowest_min} min");
    assert!(tau[1] / 60.0 < 20.0, "the second mode is much faster: {} min", tau[1] / 60.0);
}

/// Surge tank under PI level control (flowsheets/surge_tank.json), a closed form: with
/// `a = Kc v_L / A` the level loop's poles are the roots of `s² + a s + a/τ_I`, the mixing mode
/// (enthalpy) is `−F/M`; all inflow leaves (gain 1) and the level returns to its setpoint (gain 0).
#[test]
fn surge_tank_eigenvalues_and_gains_match_the_closed_form() {
    let (plant, ss) = converge("surge_tank.json");
    let inputs = select_inputs(&plant, &strings(&["inflow.F"])).unwrap();
    let outputs = select_outputs(&plant, &strings(&["tank.level", "out.F"])).unwrap();
    let lin = Linearization::new(&plant, &ss.x, &ss.u);
    let g = lin.steady_gain(&indices(&inputs), &indices(&outputs)).unwrap();
    assert!(g[(0, 0)].abs() < 1e-12 && (g[(1, 0)] - 1.0).abs() < 1e-12, "{g:?}");
    let model = lin.state_space(&indices(&inputs), &indices(&outputs)).unwrap();
    let (m, v, f) = (value(&plant, &ss.x, "tank.M"), value(&plant, &ss.x, "tank.V"), value(&plant, &ss.x, "out.F"));
    // Parameters as the file gives them (vertical cylinder; PI gain and reset time).
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(flowsheet("surge_tank.json")).unwrap()).unwrap();
    let si = |v: &serde_json::Value| plantwide::units::parse_quantity(v.as_str().unwrap()).unwrap().value_si;
    let diameter = si(&doc["units"]["tank"]["diameter"]);
    let area = std::f64::consts::PI * diameter * diameter / 4.0;
    let (kc, tau_i) =
        (si(&doc["controllers"]["level_control"]["kc"]), si(&doc["controllers"]["level_control"]["tau_i"]));
    let a = kc * (v / m) / area;
    let disc = c64::new(a * a - 4.0 * a / tau_i, 0.0).sqrt();
    let mut expected =
        [(c64::new(-a, 0.0) + disc) / 2.0, (c64::new(-a, 0.0) - disc) / 2.0, c64::new(-f / m, 0.0)].to_vec();
    let mut got = model.eigenvalues().unwrap();
    assert_eq!(got.len(), 3, "states: water holdup, internal energy, controller integral");
    let key = |l: &c64| (l.re, l.im);
    expected.sort_by(|p, q| key(p).partial_cmp(&key(q)).unwrap());
    got.sort_by(|p, q| key(p).partial_cmp(&key(q)).unwrap());
    for (e, g) in expected.iter().zip(&got) {
        assert!((e - g).norm() < 1e-9 * e.norm(), "expected {expected:?}, got {got:?}");
    }
}

/// Wood & Berry (1973) from flowsheets/transfer_functions/wood_berry.tf.json: λ11 ≈ 2.01 (validation-cases.md §3),
/// and the Niederlinski index by hand: NI = det G(0) / (g11 g22).
#[test]
fn wood_berry_relative_gain_and_niederlinski_index() {
    let text = std::fs::read_to_string(flowsheet("transfer_functions/wood_berry.tf.json")).unwrap();
    let model = tf::parse(&text, "wood_berry.tf.json").unwrap();
    let g = model.gain();
    let l = rga(g.as_ref()).unwrap();
    assert!((l[(0, 0)] - 2.01).abs() < 0.005, "λ11 = {}", l[(0, 0)]);
    let hand = (12.8 * -19.4 - -18.9 * 6.6) / (12.8 * -19.4);
    assert!((niederlinski(g.as_ref(), &[0, 1]).unwrap() - hand).abs() < 1e-14);
    assert!((hand - 0.4977).abs() < 1e-4);
    // The off-diagonal pairing is the one with negative relative gains: NI < 0.
    assert!(niederlinski(g.as_ref(), &[1, 0]).unwrap() < 0.0);
    // Dead times only rotate phases: |g12(jω)| = 18.9/|1 + 21jω| (ω in rad/min).
    let w = 0.05 / 60.0;
    assert!((model.response(w)[(0, 1)].norm() - 18.9 / c64::new(1.0, 21.0 * 60.0 * w).norm()).abs() < 1e-12);
}

/// A sweep by continuation lands on the same steady states as independent cold starts.
#[test]
fn column_a_sensitivity_sweep_matches_cold_starts() {
    let (plant, ss) = converge("column_a.json");
    let d = Disturbance::parse(&plant, &ss.u, "feed_source.F=-10%:+10%").unwrap();
    assert!((d.low - 0.9 * 1000.0 / 60.0).abs() < 1e-9 && (d.high - 1.1 * 1000.0 / 60.0).abs() < 1e-9);
    let out = select_outputs(&plant, &strings(&["bottoms.x[light]"])).unwrap();
    let curves =
        sweep(&plant, &ss.x, &ss.u, &[d], &indices(&out), &SweepSettings { points: 3, ..SweepSettings::default() })
            .unwrap();
    let c = &curves[0];
    assert!(c.failures.is_empty());
    assert_eq!(c.values.len(), 3, "−10 %, base, +10 %");
    for (v, y) in c.values.iter().zip(&c.outputs) {
        let mut u = ss.u.clone();
        u[c.disturbance.signal.index] = *v;
        let cold = steady_state(&plant, &u, None, &NewtonSettings::default()).unwrap();
        let yc = value(&plant, &cold.x, "bottoms.x[light]");
        assert!((y.as_ref().unwrap()[0] - yc).abs() < 1e-9 * yc, "F = {v}: {y:?} vs {yc}");
    }
    // More feed with L and V fixed sends light component down: xB rises.
    assert!(c.outputs[2].as_ref().unwrap()[0] > c.outputs[1].as_ref().unwrap()[0]);
}

/// Stage-temperature gains from the linearization agree with perturbation gains, and the slope
/// criterion finds the steepest step of the profile.
#[test]
fn column_a_temperature_sensor_selection() {
    let (plant, ss) = converge("column_a.json");
    let inputs = select_inputs(&plant, &strings(&LV_INPUTS)).unwrap();
    let s = select_temperature_sensors(&plant, &ss.x, &ss.u, "column", &inputs).unwrap();
    assert_eq!(s.stages, (1..=41).collect::<Vec<_>>());
    let stages = ["column.T[10]", "column.T[15]", "column.T[30]"];
    let outs = select_outputs(&plant, &strings(&stages)).unwrap();
    let p =
        perturb_gains(&plant, &ss.x, &ss.u, &indices(&inputs), &indices(&outs), &PerturbSettings::default()).unwrap();
    let p = display(&p.gain, &inputs, &outs);
    for (k, stage) in [10usize, 15, 30].iter().enumerate() {
        for j in 0..2 {
            let lin = s.gains[(stage - 1, j)];
            assert!((lin - p[(k, j)]).abs() < 1e-4 * lin.abs(), "stage {stage}: {lin} vs {}", p[(k, j)]);
        }
    }
    let steepest = (1..41).max_by(|&a, &b| {
        let d = |i: usize| (s.temperatures[i] - s.temperatures[i - 1]).abs();
        d(a).total_cmp(&d(b))
    });
    assert_eq!(Some(s.slope.0.1), steepest.map(|i| i + 1));
    assert_eq!(s.svd_stages.len(), 2);
    assert_ne!(s.svd_stages[0], s.svd_stages[1]);
    // The first singular direction (both inputs moving together, the "large gain" direction) sits
    // in the stripping section below the feed (stage 21), the second above it.
    assert!(s.svd_stages[0] < 21 && s.svd_stages[1] > 21, "{:?}", s.svd_stages);
}

#[test]
fn gains_json_has_exactly_the_documented_shape() {
    let file = flowsheet("column_a.json");
    for method in ["linear", "perturb"] {
        let out = plantwide(&[
            "gains",
            &file,
            "--inputs",
            &LV_INPUTS.join(","),
            "--outputs",
            &LV_OUTPUTS.join(","),
            "--method",
            method,
            "--json",
        ]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
        let mut sorted = keys.clone();
        sorted.sort_unstable();
        let mut documented =
            vec!["condition_number", "gain", "inputs", "method", "niederlinski", "outputs", "rga", "singular_values"];
        if method == "perturb" {
            // The one key added for perturbation gains: how they were verified.
            documented.insert(6, "perturbation");
            assert_eq!(v["perturbation"]["check"], "richardson");
            assert!(v["perturbation"]["step"].as_f64().unwrap() > 0.0);
            assert!(v["perturbation"]["max_relative_difference"].as_f64().unwrap() < 1e-3);
        }
        assert_eq!(sorted, documented);
        assert_eq!(v["method"], method);
        assert_eq!(v["inputs"][0]["path"], "column.reflux");
        assert_eq!(v["inputs"][0]["unit"], "kmol/min");
        assert_eq!(v["outputs"][1]["path"], "bottoms.x[light]");
        let g11 = v["gain"][0][0].as_f64().unwrap();
        assert!((g11 - 0.8754).abs() < 1e-3, "g11 = {g11} (kmol/min units)");
        let l11 = v["rga"][0][0].as_f64().unwrap();
        let ni = v["niederlinski"].as_f64().unwrap();
        assert!((ni * l11 - 1.0).abs() < 1e-9, "for 2×2, NI = 1/λ11");
        assert_eq!(v["singular_values"].as_array().unwrap().len(), 2);
        assert!(v["condition_number"].as_f64().unwrap() > 100.0);
    }
    let text = String::from_utf8(
        plantwide(&["gains", "--tf", &flowsheet("transfer_functions/wood_berry.tf.json"), "--json"]).stdout,
    )
    .unwrap();
    let order = [
        "\"method\"",
        "\"inputs\"",
        "\"outputs\"",
        "\"gain\"",
        "\"rga\"",
        "\"singular_values\"",
        "\"condition_number\"",
        "\"niederlinski\"",
    ];
    let at: Vec<usize> = order.iter().map(|k| text.find(k).unwrap()).collect();
    assert!(at.windows(2).all(|w| w[0] < w[1]), "keys in the documented order:\n{text}");
}

#[test]
fn gains_requests_that_cannot_work_are_user_errors() {
    let file = flowsheet("column_a.json");
    let cases: [(&[&str], &[&str]); 4] = [
        (
            &["--inputs", "column.reflx", "--outputs", "distillate.x[light]"],
            &["no input `column.reflx`", "did you mean `column.reflux`"],
        ),
        (
            &["--inputs", "column.distillate", "--outputs", "distillate.x[light]"],
            &["driven by controller `condenser_level`", "condenser_level.sp"],
        ),
        (
            &["--inputs", "column.reflux@degC", "--outputs", "distillate.x[light]"],
            &["column.reflux@degC", "is a molar flow"],
        ),
        (
            &["--inputs", "column.reflux", "--outputs", "distillate.x[lite]"],
            &["no variable `distillate.x[lite]`", "did you mean"],
        ),
    ];
    for (args, fragments) in cases {
        let mut all = vec!["gains", file.as_str()];
        all.extend_from_slice(args);
        let out = plantwide(&all);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        for f in fragments {
            assert!(stderr.contains(f), "{args:?}: missing `{f}` in {stderr}");
        }
    }
}

#[test]
fn linearize_exports_a_model_python_control_can_read() {
    let dir = std::env::temp_dir().join(format!("plantwide-linearize-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("model.json");
    let out = plantwide(&[
        "linearize",
        &flowsheet("column_a.json"),
        "--inputs",
        &LV_INPUTS.join(","),
        "--outputs",
        &LV_OUTPUTS.join(","),
        "--out",
        path.to_str().unwrap(),
        "--time-unit",
        "min",
        "--frequencies",
        "0.01:0.1:2",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let m: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let mat = |k: &str| {
        let rows = m[k].as_array().unwrap();
        let ncols = rows[0].as_array().unwrap().len();
        Mat::from_fn(rows.len(), ncols, |i, j| rows[i][j].as_f64().unwrap())
    };
    let (a, b, c, d) = (mat("A"), mat("B"), mat("C"), mat("D"));
    assert_eq!((a.nrows(), b.ncols(), c.nrows(), d.ncols()), (82, 2, 2, 2));
    assert_eq!(m["states"].as_array().unwrap().len(), 82);
    // The exported frequency response (from the sparse DAE) equals D + C (jωI − A)⁻¹ B of the
    // exported matrices, in the exported units (ω in rad/min).
    for r in m["frequency_response"].as_array().unwrap() {
        let w = r["omega"].as_f64().unwrap();
        let lhs = Mat::from_fn(82, 82, |i, j| c64::new(-a[(i, j)], if i == j { w } else { 0.0 }));
        let rhs = Mat::from_fn(82, 2, |i, j| c64::new(b[(i, j)], 0.0));
        let x = lhs.partial_piv_lu().solve(&rhs);
        for i in 0..2 {
            for j in 0..2 {
                let g: c64 = (0..82).map(|k| x[(k, j)] * c[(i, k)]).sum::<c64>() + c64::new(d[(i, j)], 0.0);
                let exported = c64::new(r["re"][i][j].as_f64().unwrap(), r["im"][i][j].as_f64().unwrap());
                assert!((g - exported).norm() < 1e-8 * g.norm(), "ω = {w} rad/min: {g:?} vs {exported:?}");
            }
        }
    }
    let tc = m["time_constants"][0].as_f64().unwrap();
    assert!((tc - 194.0).abs() < 2.0, "slowest time constant {tc} min");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn sensitivity_writes_csv_and_plots() {
    let dir = std::env::temp_dir().join(format!("plantwide-sensitivity-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("s.csv");
    for ext in ["png", "svg"] {
        let plot = dir.join(format!("s.{ext}"));
        let out = plantwide(&[
            "sensitivity",
            &flowsheet("column_a.json"),
            "--disturb",
            "feed_source.F=-5%:+5%",
            "--disturb",
            "feed_source.z[light]=0.48:0.52",
            "--outputs",
            "bottoms.x[light],distillate.x[light]",
            "--points",
            "3",
            "--csv",
            csv.to_str().unwrap(),
            "--plot",
            plot.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let bytes = std::fs::read(&plot).unwrap();
        match ext {
            "png" => assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n"),
            _ => assert!(
                String::from_utf8_lossy(&bytes).contains("<svg")
                    && String::from_utf8_lossy(&bytes).contains("feed_source.F")
            ),
        }
    }
    let text = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "disturbance,unit,value,change_percent,bottoms.x[light] [-],distillate.x[light] [-]");
    assert_eq!(lines.len(), 1 + 3 + 3, "header, 3 points per disturbance (the base is one of them)");
    let base: Vec<&str> = lines[2].split(',').collect();
    assert_eq!(base[0], "feed_source.F");
    assert_eq!(base[3].parse::<f64>().unwrap(), 0.0);
    assert!((base[4].parse::<f64>().unwrap() - 0.01).abs() < 1e-6, "xB at the base case");
    let bad = plantwide(&[
        "sensitivity",
        &flowsheet("column_a.json"),
        "--disturb",
        "feed_source.F=10%",
        "--outputs",
        "bottoms.x[light]",
    ]);
    assert_eq!(bad.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("LOW:HIGH"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `gains --tf … --frequencies … --json` carries G(jω) element by element, its RGA and RGA number:
/// Wood–Berry's elements K e^(−θs)/(τs + 1) at ω = 0.1 rad/min and the 2×2 closed form
/// λ11 = 1/(1 − g12 g21/(g11 g22)) evaluated by hand, to 1e-12; `--inputs/--outputs` select and
/// order channels.
#[test]
fn transfer_function_frequency_results_are_complete_in_json_and_channels_select() {
    let tf = flowsheet("transfer_functions/wood_berry.tf.json");
    let out = plantwide(&["gains", "--tf", &tf, "--frequencies", "0.1:1:2", "--time-unit", "min", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let f = &v["frequency"];
    assert_eq!(f["time_unit"], "min");
    let p = &f["points"][0];
    assert_eq!(p["omega"].as_f64(), Some(0.1));
    let w = 0.1;
    let g = |k: f64, tau: f64, theta: f64| c64::new(0.0, -theta * w).exp() * k / c64::new(1.0, tau * w);
    let exact = [[g(12.8, 16.7, 1.0), g(-18.9, 21.0, 3.0)], [g(6.6, 10.9, 7.0), g(-19.4, 14.4, 3.0)]];
    for i in 0..2 {
        for j in 0..2 {
            let e = &p["g"][i][j];
            let z = c64::new(e["re"].as_f64().unwrap(), e["im"].as_f64().unwrap());
            assert!(
                (z - exact[i][j]).norm() < 1e-12 * exact[i][j].norm(),
                "g{}{}: {z} vs {}",
                i + 1,
                j + 1,
                exact[i][j]
            );
            assert!((e["magnitude"].as_f64().unwrap() - exact[i][j].norm()).abs() < 1e-12);
            let phase = exact[i][j].im.atan2(exact[i][j].re).to_degrees();
            assert!((e["phase_deg"].as_f64().unwrap() - phase).abs() < 1e-9);
        }
    }
    let lambda = c64::new(1.0, 0.0) / (c64::new(1.0, 0.0) - exact[0][1] * exact[1][0] / (exact[0][0] * exact[1][1]));
    let l11 = c64::new(p["rga"][0][0]["re"].as_f64().unwrap(), p["rga"][0][0]["im"].as_f64().unwrap());
    assert!((l11 - lambda).norm() < 1e-12 * lambda.norm(), "{l11} vs {lambda}");
    // RGA number of the diagonal pairing: Σ|Λ − I| = 2|λ11 − 1| + 2|1 − λ11| for a 2×2.
    assert!((p["rga_number"].as_f64().unwrap() - 4.0 * (lambda - 1.0).norm()).abs() < 1e-10);

    let out = plantwide(&["gains", "--tf", &tf, "--inputs", "S", "--outputs", "xB,xD", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["gain"], serde_json::json!([[-19.4], [-18.9]]));
    assert!(v.get("frequency").is_none());
    let bad = plantwide(&["gains", "--tf", &tf, "--inputs", "Q"]);
    assert_eq!(bad.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("no input `Q`"));
}

/// A flowsheet's `gains --frequencies --json` carries the same block: at a frequency far below the
/// slowest mode G(jω) is G(0), the `gain` the same command prints.
#[test]
fn flowsheet_frequency_results_tend_to_the_steady_state_gains() {
    let out = plantwide(&[
        "gains",
        &flowsheet("column_a.json"),
        "--inputs",
        "L,V",
        "--outputs",
        "distillate.x[light],bottoms.x[light]",
        "--frequencies",
        "1e-9:1e-8:2",
        "--json",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for i in 0..2 {
        for j in 0..2 {
            let g0 = v["gain"][i][j].as_f64().unwrap();
            let z = &v["frequency"]["points"][0]["g"][i][j];
            assert!((z["re"].as_f64().unwrap() - g0).abs() < 1e-6 * g0.abs(), "{i}{j}");
            assert!(z["im"].as_f64().unwrap().abs() < 1e-3 * g0.abs(), "{i}{j}");
        }
    }
}

/// `linearize --tf` writes each element as python-control's `tf(num, den)` times `e^(−θ s)`: the
/// polynomials evaluated at s = jω by Horner and delayed reproduce the model's G(jω) to 1e-12 at
/// every frequency written, num/den at s = 0 is the element's gain, and the poles are −1/τ.
#[test]
fn linearize_tf_exports_elements_as_numerator_denominator_and_dead_time() {
    let dir = std::env::temp_dir().join(format!("plantwide_linearize_tf_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out_file = dir.join("wb.json");
    let tf = flowsheet("transfer_functions/wood_berry.tf.json");
    let args = ["linearize", "--tf", &tf, "--time-unit", "min", "--frequencies", "0.01:1:5", "--out"];
    let out = plantwide(&[&args[..], &[out_file.to_str().unwrap()]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let m: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&out_file).unwrap()).unwrap();
    let poly = |c: &serde_json::Value, s: c64| {
        c.as_array().unwrap().iter().fold(c64::new(0.0, 0.0), |acc, a| acc * s + a.as_f64().unwrap())
    };
    let taus = [[16.7, 21.0], [10.9, 14.4]];
    for i in 0..2 {
        for j in 0..2 {
            let e = &m["elements"][i][j];
            let dc = poly(&e["num"], c64::new(0.0, 0.0)) / poly(&e["den"], c64::new(0.0, 0.0));
            assert!((dc.re - m["steady_state_gain"][i][j].as_f64().unwrap()).abs() < 1e-12);
            assert!((e["poles"][0].as_f64().unwrap() + 1.0 / taus[i][j]).abs() < 1e-12);
            for p in m["frequency"]["points"].as_array().unwrap() {
                let w = p["omega"].as_f64().unwrap();
                let s = c64::new(0.0, w);
                let delay = c64::new(0.0, -w * e["dead_time"].as_f64().unwrap()).exp();
                let g = poly(&e["num"], s) / poly(&e["den"], s) * delay;
                let z = c64::new(p["g"][i][j]["re"].as_f64().unwrap(), p["g"][i][j]["im"].as_f64().unwrap());
                assert!((g - z).norm() < 1e-12 * z.norm(), "g{}{} at {w}: {g} vs {z}", i + 1, j + 1);
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A high-purity recycle (generated plant 0x4f68f799dcee2e64, its design run): at the default
/// step the reflux moves the outputs by 1.3e-6 against a re-convergence accuracy of 4.9e-12, and
/// perturbation refused with "increase --step" though no step was given. The automatic step now
/// grows for that input; the gains agree with the exact linearization's (an independent route).
#[test]
fn perturbation_grows_an_automatic_step_the_convergence_noise_swamps() {
    let path = harness::fixture("data/generated/recycle_open_4f68f799.json");
    let plant = plantwide::flowsheet::load_file(std::path::Path::new(&path)).unwrap();
    let ss = plantwide::solve::steady_state(&plant, &plant.input_values(), None, &Default::default()).unwrap();
    let inputs = select_inputs(&plant, &strings(&["column.reflux", "column.boilup", "fresh.F"])).unwrap();
    let outputs = select_outputs(&plant, &strings(&["recycle.x[A]", "bottoms.x[A]", "bottoms.F"])).unwrap();
    let (ii, oo) = (indices(&inputs), indices(&outputs));
    let g_lin = Linearization::new(&plant, &ss.x, &ss.u).steady_gain(&ii, &oo).unwrap();
    let p = perturb_gains(&plant, &ss.x, &ss.u, &ii, &oo, &PerturbSettings::default()).unwrap();
    let scale = plant.inputs()[ii[0]].value.abs();
    assert!(p.steps[0] > 1e-5 * scale, "the reflux's step did not grow: {:?}", p.steps);
    for i in 0..3 {
        let row = (0..3).map(|j| g_lin[(i, j)].abs()).fold(0.0, f64::max);
        for j in 0..3 {
            let d = (p.gain[(i, j)] - g_lin[(i, j)]).abs();
            assert!(d <= 1e-6 * row, "G[{i}][{j}]: perturbation {:e}, exact {:e}", p.gain[(i, j)], g_lin[(i, j)]);
        }
    }
}

/// Generated ppm-purity column 0x8121b93bf5d319a7 with its feed as a third input: the gain matrix
/// has condition number 3.2e7 and relative gains near 4e4, which magnify the perturbation gains'
/// remaining error into relative gains 42 % off the exact ones. The refusal said "try --step
/// 4e-9", a step it had tried and found below what the re-converged steady states resolve (which
/// then said "increase --step"): advice that went round in a circle. Now it says no step is left.
#[test]
fn an_ill_conditioned_plant_whose_relative_gains_perturbation_cannot_verify_is_sent_to_the_linearization() {
    let fs = harness::fixture("data/generated/simple_8121b93b_open.json");
    let args = ["gains", &fs, "--inputs", "column.reflux,column.boilup,supply.F"];
    let outputs = ["--outputs", "distillate.x[light],bottoms.x[light],bottoms.F", "--method", "perturb"];
    let out = plantwide(&[&args[..], &outputs[..]].concat());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("did not verify") && err.contains("use --method linear"), "{err}");
    assert!(!err.contains("try --step"), "{err}");
    let exact = plantwide(&[&args[..], &["--outputs", "distillate.x[light],bottoms.x[light],bottoms.F"][..]].concat());
    assert!(exact.status.success(), "{}", String::from_utf8_lossy(&exact.stderr));
}

/// Jacobian-vector product `J(x, u)·(a_x, a_u)` (all equations).
fn jacobian_times(
    plant: &plantwide::flowsheet::Plant,
    (x, u): (&[f64], &[f64]),
    (ax, au): (&[f64], &[f64]),
) -> Vec<f64> {
    let mut r = vec![0.0; plant.n_eqs()];
    let (mut jx, mut ju) = (Vec::new(), Vec::new());
    plant.jacobian(x, u, 0.0, &mut r, &mut jx, &mut ju);
    let mut out = vec![0.0; plant.n_eqs()];
    jx.iter().for_each(|&(i, j, v)| out[i] += v * ax[j]);
    ju.iter().for_each(|&(i, j, v)| out[i] += v * au[j]);
    out
}

/// Central differences of `f` at steps `h` and `h/2`, Richardson-extrapolated (error O(h⁴)).
fn richardson(f: impl Fn(f64) -> Vec<f64>, h: f64) -> Vec<f64> {
    let d = |h: f64| -> Vec<f64> { f(h).iter().zip(f(-h)).map(|(p, m)| (p - m) / (2.0 * h)).collect() };
    let (d1, d2) = (d(h), d(h / 2.0));
    d1.iter().zip(&d2).map(|(a, b)| (4.0 * b - a) / 3.0).collect()
}

#[test]
fn the_plants_curvature_is_the_derivative_of_its_jacobian() {
    // Hyper-dual second derivatives against Richardson-extrapolated central differences of the
    // dual-number Jacobian, along two directions that move every variable and input.
    let (plant, ss) = converge("column_a.json");
    let (n, m) = (plant.n_vars(), ss.u.len());
    let wave = |k: usize, s: f64| ((k as f64 + s) * 0.7).sin();
    let a: (Vec<f64>, Vec<f64>) = (
        (0..n).map(|k| wave(k, 0.0) * (1e-3 + ss.x[k].abs())).collect(),
        (0..m).map(|k| wave(k, 0.0) * ss.u[k]).collect(),
    );
    let b: (Vec<f64>, Vec<f64>) = (
        (0..n).map(|k| wave(k, 2.0) * (1e-3 + ss.x[k].abs())).collect(),
        (0..m).map(|k| wave(k, 2.0) * ss.u[k]).collect(),
    );
    let mut exact = vec![0.0; plant.n_eqs()];
    plant.curvature((&ss.x, &ss.u), (&a.0, &a.1), (&b.0, &b.1), &mut exact);
    let numeric = richardson(
        |h| {
            let x: Vec<f64> = ss.x.iter().zip(&b.0).map(|(v, d)| v + h * d).collect();
            let u: Vec<f64> = ss.u.iter().zip(&b.1).map(|(v, d)| v + h * d).collect();
            jacobian_times(&plant, (&x, &u), (&a.0, &a.1))
        },
        1e-4,
    );
    let scale = numeric.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
    assert!(scale > 0.0);
    let worst = exact.iter().zip(&numeric).map(|(e, d)| (e - d).abs()).fold(0.0_f64, f64::max) / scale;
    assert!(worst < 1e-8, "hyper-dual curvature vs differences of the Jacobian: {worst:e} of the largest entry");
}

#[test]
fn a_steady_states_second_derivatives_follow_from_the_adjoint_and_the_curvature() {
    // ∂²xD/∂u_a∂u_b = −λᵀ f''[(δx_a, δu_a), (δx_b, δu_b)] with Jᵀλ = e_xD, against Richardson
    // differences of exact gains at re-converged steady states (reflux and boilup moved). The
    // high-purity column curves fast: the differences' error falls as h⁴ (2e-3 at h = 1e-3 of
    // the input, 2e-7 at 1e-4), so h = 5e-5.
    let (plant, ss) = converge("column_a.json");
    let inputs = indices(&select_inputs(&plant, &strings(&LV_INPUTS)).unwrap());
    let y = plant.var("distillate.x[light]").unwrap();
    let lin = Linearization::new(&plant, &ss.x, &ss.u);
    let mut w = vec![0.0; plant.n_vars()];
    w[y] = 1.0;
    let lambda = lin.adjoint(&w).unwrap();
    let du = Mat::from_fn(ss.u.len(), 2, |i, k| f64::from(u8::from(i == inputs[k])));
    let dx = lin.state_moves(&du).unwrap();
    let column = |k: usize| -> (Vec<f64>, Vec<f64>) {
        (dx.col(k).iter().copied().collect(), du.col(k).iter().copied().collect())
    };
    let (m0, m1) = (column(0), column(1));
    let exact = |a: &(Vec<f64>, Vec<f64>), b: &(Vec<f64>, Vec<f64>)| -> f64 {
        let mut f2 = vec![0.0; plant.n_eqs()];
        plant.curvature((&ss.x, &ss.u), (&a.0, &a.1), (&b.0, &b.1), &mut f2);
        -lambda.iter().zip(&f2).map(|(l, f)| l * f).sum::<f64>()
    };
    let hessian = [[exact(&m0, &m0), exact(&m0, &m1)], [exact(&m1, &m0), exact(&m1, &m1)]];
    let tight = NewtonSettings { tol: 1e-13, ..NewtonSettings::default() };
    for b in 0..2 {
        let column_b = richardson(
            |h| {
                let mut u = ss.u.clone();
                u[inputs[b]] += h;
                let s = steady_state(&plant, &u, Some(&ss.x), &tight).unwrap();
                let g = Linearization::new(&plant, &s.x, &s.u).steady_gain(&inputs, &[y]).unwrap();
                vec![g[(0, 0)], g[(0, 1)]]
            },
            5e-5 * ss.u[inputs[b]],
        );
        for a in 0..2 {
            let (e, d) = (hessian[a][b], column_b[a]);
            assert!((e - d).abs() < 1e-6 * e.abs().max(1e-12), "∂²xD/∂u{a}∂u{b}: adjoint {e:e} vs differences {d:e}");
        }
    }
    assert!((hessian[0][1] - hessian[1][0]).abs() <= 1e-12 * hessian[0][1].abs(), "{hessian:?}");
}
