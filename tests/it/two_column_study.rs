//! The chapter-6 study of `flowsheets/two_column_plant.json` (`tools/two_column_study.py`, the
//! script that writes `docs/two_column_plant.md`).
//!
//! By default its conclusions are pinned in process, fast, from one converged base case and its
//! linearization, against independent expectations (relative-gain rules, stoichiometry, the
//! first-order filter, the reactor's open-loop instability): which inventory structure each
//! column takes, what sets production, which disturbance moves column 1's bottoms most, what a
//! surge tank passes. `cargo test -- --include-ignored` also runs the script end to end on short horizons
//! (about 150 s) and pins its numbers, its conservation and its dynamic conclusions.

use std::f64::consts::PI;
use std::path::Path;
use std::process::Command;
use std::sync::OnceLock;

use approx::assert_abs_diff_eq;

use crate::harness;
use plantwide::analysis::faer::{Mat, c64};
use plantwide::analysis::linear::Linearization;
use plantwide::analysis::measures::{niederlinski, rga};
use plantwide::analysis::select::{Signal, select_input, select_output};
use plantwide::flowsheet::scenario::{parse_scenario, resolve};
use plantwide::flowsheet::{Plant, load_file, load_str};
use plantwide::solve::dynamic::{Start, simulate};
use plantwide::solve::sequential::{StrategySettings, steady_state_by};
use serde_json::{Value, json};

fn num(v: &Value, path: &str) -> f64 {
    let mut cur = v;
    for key in path.split('.') {
        cur = &cur[key];
    }
    cur.as_f64().unwrap_or_else(|| panic!("{path} is not a number: {cur}"))
}

/// The full study (run with `-- --include-ignored`): the script end to end on short horizons,
/// its conservation and its conclusions pinned.
#[test]
#[ignore = "slow: the two-column study script end to end, about 5 min in the test profile"]
fn two_column_study_runs_and_reaches_its_conclusions() {
    let root = Path::new(harness::ROOT);
    let out = std::env::temp_dir().join(format!("plantwide_two_column_{}", std::process::id()));
    let status = Command::new("python3")
        .arg(root.join("tools/two_column_study.py"))
        .args(["--short", "--plantwide", env!("CARGO_BIN_EXE_plantwide"), "--out"])
        .arg(&out)
        .status()
        .expect("python3 runs the study script");
    assert!(status.success(), "the study script failed");
    let text = std::fs::read_to_string(out.join("two_column_plant/results.json")).expect("results.json");
    let r: Value = serde_json::from_str(&text).expect("results are JSON");
    let report = std::fs::read_to_string(out.join("two_column_plant.md")).expect("the report");
    assert!(report.contains("## 8. Reactor safety") && report.contains("## Appendix: the commands"));
    pin_base_and_structures(&r);
    pin_production_and_sensitivity(&r);
    pin_dynamics_and_safety(&r);
    pin_sizing(&r);
    let _ = std::fs::remove_dir_all(&out);
}

/// §6b of the full study: `size --candidates` for a production step. No tank is needed between the
/// columns (the bare stream already meets the rate limit); the reflux drum does not meet it with
/// its file controller, and its three designs, verified on the plant, do; the base under LB cannot
/// be a surge volume (every design's run stops). The drum's closed-form areas stand in the ratio
/// 1 : 2/e : 1/2 (P, PI, optimal).
fn pin_sizing(r: &Value) {
    let s = &r["sizing"];
    assert_eq!(s["bottoms1"]["needs_surge"], false, "{}", s["bottoms1"]);
    assert_eq!(s["column1.drum"]["needs_surge"], true, "{}", s["column1.drum"]);
    for d in ["p", "pi", "optimal"] {
        assert_eq!(s["column1.drum"]["designs"][d]["meets"], true, "{d}: {}", s["column1.drum"]);
        assert_eq!(s["bottoms1"]["designs"][d]["meets"], true, "{d}: {}", s["bottoms1"]);
        assert_eq!(s["column1.sump"]["designs"][d]["meets"], false, "{d}: {}", s["column1.sump"]);
    }
    let drum = &s["column1.drum"]["designs"];
    let a = |d: &str| drum[d]["closed_form_area"].as_f64().unwrap();
    assert!((a("pi") / a("p") - 2.0 / std::f64::consts::E).abs() < 1e-9 && (a("optimal") / a("p") - 0.5).abs() < 1e-9);
    // The recycle moves by more than column 2's feed (the snowball): the drum needs more band.
    let flow = |c: &str| s[c]["flow_change_kmol_h"].as_f64().unwrap();
    assert!(flow("column1.drum") > 3.0 * flow("bottoms1"), "{s}");
}

/// §1–2 of the full study: the base case's conservation and design, the column structures' gains.
fn pin_base_and_structures(r: &Value) {
    // Conservation of the base case: A atoms, B atoms, mass, reactor energy.
    for b in ["A + R", "B + R + 2S", "mass", "reactor energy"] {
        let e = r["base"]["balances"][b].as_f64().expect("balance");
        assert!(e < 1e-9, "{b}: relative imbalance {e:e}");
    }
    // The base case as designed (flowsheets/README.md).
    assert_abs_diff_eq!(num(r, "base.product_kmol_h"), 100.146, epsilon = 1e-3 * 100.146);
    assert_abs_diff_eq!(num(r, "base.recycle_kmol_h"), 197.60, epsilon = 1e-3 * 197.60);
    assert_abs_diff_eq!(num(r, "base.reactor_T"), 350.0, epsilon = 1e-9 * 350.0);
    assert_abs_diff_eq!(num(r, "base.residence_min"), 19.81, epsilon = 1e-3 * 19.81);

    // Column structures: LV interactive on both columns, LB decoupled; the book's perturbation
    // gains re-converge for every structure and agree with the linearization.
    assert_abs_diff_eq!(num(r, "column1.LV.rga11"), 5.2216, epsilon = 1e-3 * 5.2216);
    assert_abs_diff_eq!(num(r, "column1.LV.niederlinski"), 0.19151, epsilon = 1e-3 * 0.19151);
    assert_abs_diff_eq!(num(r, "column1.DV.rga11"), 1.2401, epsilon = 1e-3 * 1.2401);
    assert_abs_diff_eq!(num(r, "column1.LB.rga11"), 1.1480, epsilon = 1e-3 * 1.1480);
    assert_abs_diff_eq!(num(r, "column2.LV.rga11"), 11.98, epsilon = 1e-2 * 11.98);
    assert_abs_diff_eq!(num(r, "column2.LB.rga11"), 0.9762, epsilon = 1e-3 * 0.9762);
    assert_abs_diff_eq!(num(r, "column2.DV.rga11"), 0.02403, epsilon = 1e-2 * 0.02403);
    for col in ["column1", "column2"] {
        for st in ["LV", "DV", "LB"] {
            let d = num(r, &format!("{col}.{st}.perturb_vs_linear"));
            assert!(d < 1e-3, "{col} {st}: perturbation and linearization differ by {d:e}");
        }
    }
    // An explicit step is only the first attempt: 1e-4 is too large for column 2's curvature (plain
    // central differences there are 2 % off the linearization), so the gains at h and h/2 disagree
    // and the step is shrunk; every step requested ends in gains that agree with the linearization.
    for h in ["1e-4", "1e-5", "1e-6"] {
        let d = num(r, &format!("column2.LV_explicit_steps.{h}.perturb_vs_linear"));
        assert!(d < 1e-5, "--step {h}: perturbation and linearization differ by {d:e}");
    }
    assert!(num(r, "column2.LV_explicit_steps.1e-4.step") < 1e-4);
    assert!(num(r, "column2.LV_explicit_steps.1e-4.attempts") > 1.0);
    assert!(r["column2"]["DB_error"].as_str().is_some_and(|e| e.contains("not determined")));
    assert_eq!(r["sensors_column1"], serde_json::json!([21, 11]));
    // §2b, by `plantwide screen`: column 2's LB ranked first of its seven configurations, and the plantwide
    // pairing with the throughput choices reaching §2–3's choice: fresh A, LB on both columns.
    assert_eq!(r["screen"]["column2"]["LB"]["rank"], 1);
    assert_eq!(r["screen"]["pairings"]["best_throughput"], "fresh_A.F");
    let best = serde_json::json!(["column1.reflux", "column1.bottoms", "column2.reflux", "column2.bottoms"]);
    assert_eq!(r["screen"]["pairings"]["best_mvs"], best);
}

/// §3–4 of the full study: what sets production, figure 6-6.
fn pin_production_and_sensitivity(r: &Value) {
    // Production rate: the fresh-A flow sets it (all A leaves as R) and snowballs the recycle; the
    // reactor temperature does not move it.
    assert_abs_diff_eq!(num(r, "production.P1.product"), 0.99922, epsilon = 1e-3 * 0.99922);
    assert_abs_diff_eq!(num(r, "production.P1.recycle_per_product"), 4.615, epsilon = 1e-3 * 4.615);
    assert!(num(r, "production.P2.product").abs() < 0.02);
    // P3 (effluent flow fixed, fresh A on the reactor level) reaches P1's steady states.
    assert_abs_diff_eq!(num(r, "production.P3.product"), 0.17814, epsilon = 1e-3 * 0.17814);
    let per_product = num(r, "production.P1.recycle_per_product");
    assert_abs_diff_eq!(num(r, "production.P3.recycle_per_product"), per_product, epsilon = 1e-3 * per_product.abs());

    // Figure 6-6: the bottoms impurity over ±10 % of each disturbance; the feed rate moves it most.
    let band = |d: &str| -> (f64, f64) {
        let v = &r["sensitivity"][d];
        (v[0].as_f64().expect("low"), v[1].as_f64().expect("high"))
    };
    let (lo, hi) = band("fresh_A.F");
    assert!((lo - 0.0016988).abs() < 2e-6 && (hi - 0.0023444).abs() < 2e-6, "feed rate: {lo} … {hi}");
    for d in ["feed_cooler.T_out", "reactor_B.sp"] {
        let (l, h) = band(d);
        assert!(h - l < hi - lo, "{d}: {l} … {h} wider than the feed-rate band");
    }
}

/// §5–8 of the full study: the surge tank, the reflux drum, reactor safety, the dynamic responses.
fn pin_dynamics_and_safety(r: &Value) {
    // Surge tank: the measured attenuation of a 1 h flow cycle is the first-order filter's.
    let att = num(r, "surge.attenuation");
    let closed = num(r, "surge.first_order_closed_form");
    assert!((att / closed - 1.0).abs() < 0.02, "attenuation {att} vs closed form {closed}");
    assert_abs_diff_eq!(num(r, "surge.first_order_closed_form"), 0.3033, epsilon = 1e-3 * 0.3033);

    // Reflux drum: a bigger drum lets less of a column upset into the reactor.
    let through = |m: &str| num(r, &format!("drum.{m}.recycle_max_dev_kmol_h"));
    assert!(through("1min") > 2.0 * through("5min") && through("5min") > 2.0 * through("15min"));

    // Safety: open-loop unstable reactor; the trip holds it near the trip point; recycle upsets
    // start an excursion only with the temperature loop in manual.
    assert!(num(r, "safety.peak_no_action") > 390.0, "{}", r["safety"]);
    assert!(num(r, "safety.peak_trip") < 362.0, "{}", r["safety"]);
    // Maximum cooling with the feeds kept stops the excursion but quenches the reactor, and the
    // unreacted A and B drive the recycle to the distillate valve's limit and column 1's reflux to ~0.
    assert!(num(r, "safety.peak_cooling_only") < 362.0, "{}", r["safety"]);
    assert!(num(r, "safety.min_cooling_only") < 320.0, "{}", r["safety"]);
    assert_abs_diff_eq!(num(r, "safety.cooling_only_recycle_max"), 400.0, epsilon = 1e-6 * 400.0);
    assert!(num(r, "safety.cooling_only_reflux_end") < 10.0, "{}", r["safety"]);
    let rec = &r["safety"]["recycle"];
    for k in ["recycle_flow_auto", "recycle_composition_auto"] {
        assert!(rec[k]["peak"].as_f64().expect("peak") < 351.0, "{k}: {}", rec[k]);
    }
    for k in ["recycle_flow_manual", "recycle_composition_manual"] {
        assert!(rec[k]["peak"].as_f64().expect("peak") > 355.0, "{k}: {}", rec[k]);
    }

    // Dynamics: both column-1 structures settle the production step; DV passes more to the recycle.
    let dy = &r["dynamics"];
    let rec_dev = |k: &str| dy[k]["recycle_max_dev_kmol_h"].as_f64().expect("recycle").abs();
    assert!(rec_dev("DV_production") > rec_dev("LB_production"));
}

/// The base case converged once, shared by the checks below: the plant, its state and inputs.
fn base() -> &'static (Plant, Vec<f64>, Vec<f64>) {
    static BASE: OnceLock<(Plant, Vec<f64>, Vec<f64>)> = OnceLock::new();
    BASE.get_or_init(|| {
        let plant =
            load_file(Path::new(&harness::flowsheet("two_column_plant.json"))).unwrap_or_else(|e| panic!("{e}"));
        let u = plant.input_values();
        let sol =
            steady_state_by(&plant, &u, &StrategySettings::default(), &mut |_| {}).unwrap_or_else(|e| panic!("{e}"));
        (plant, sol.x, sol.u)
    })
}

/// Steady-state gains `−C J⁻¹ B` of `outputs` to `inputs` (each `PATH[@unit]`) of `plant` at
/// `(x, u)`, in the signals' display units.
fn gains(plant: &Plant, x: &[f64], u: &[f64], inputs: &[&str], outputs: &[&str]) -> Mat<f64> {
    let ins: Vec<Signal> = inputs.iter().map(|t| select_input(plant, t).unwrap_or_else(|e| panic!("{e}"))).collect();
    let outs: Vec<Signal> = outputs.iter().map(|t| select_output(plant, t).unwrap_or_else(|e| panic!("{e}"))).collect();
    let (ii, oo): (Vec<usize>, Vec<usize>) =
        (ins.iter().map(|s| s.index).collect(), outs.iter().map(|s| s.index).collect());
    let g = Linearization::new(plant, x, u).steady_gain(&ii, &oo).unwrap_or_else(|e| panic!("{e}"));
    Mat::from_fn(g.nrows(), g.ncols(), |i, j| g[(i, j)] * ins[j].factor / outs[i].factor)
}

/// The base inputs with the `loops` switched to manual at the base steady state (each PID's `auto`
/// input 0, its `op_manual` the output it had): the state stays a steady state, every integrator
/// tracks its manual output, and `<loop>.op_manual` is the free input in place of the loop.
fn manual(loops: &[&str]) -> Vec<f64> {
    let (plant, x, u) = base();
    let mut u = u.clone();
    let input = |p: String| plant.input(&p).unwrap_or_else(|| panic!("no input {p}"));
    for name in loops {
        u[input(format!("{name}.auto"))] = 0.0;
        u[input(format!("{name}.op_manual"))] = harness::value(plant, x, &format!("{name}.op"));
    }
    u
}

/// λ11 of each inventory structure of `col`, from one linearization.
///
/// The base plant holds the drum level by the distillate and the sump level by the boilup (LB).
/// With the column's quality loops in manual, the gains of its end temperatures (or analyzer)
/// `y` and of its four flows to the two free inputs (L, B) give every other structure at steady
/// state, because drum and sump holdups do not enter the steady state: a structure whose free
/// inputs are `(u1, u2)` has `G = G_y,LB · M⁻¹` with `M` the gains of `(u1, u2)` to `(L, B)`
/// (Häggblom & Waller 1988, consistency relations between configurations).
fn structures(col: &str, ends: [&str; 2], quality: [&str; 2]) -> Vec<(&'static str, Mat<f64>)> {
    let (plant, x, _) = base();
    let u = manual(&quality);
    let kmolh = |p: &str| format!("{p}@kmol/h");
    // The quality loops drive the reflux (top) and the bottoms flow (bottom).
    let (l, b) = (kmolh(&format!("{}.op_manual", quality[0])), kmolh(&format!("{}.op_manual", quality[1])));
    let (d, v) = (kmolh(&format!("{col}_drum.op")), kmolh(&format!("{col}_sump.op")));
    let g = gains(plant, x, &u, &[&l, &b], &[ends[0], ends[1], &d, &v]);
    // Rows of (L, B, D, V) as functions of (ΔL, ΔB).
    let flow = |k: &str| -> [f64; 2] {
        match k {
            "L" => [1.0, 0.0],
            "B" => [0.0, 1.0],
            "D" => [g[(2, 0)], g[(2, 1)]],
            _ => [g[(3, 0)], g[(3, 1)]],
        }
    };
    [("LV", ["L", "V"]), ("DV", ["D", "V"]), ("LB", ["L", "B"])]
        .into_iter()
        .map(|(name, [u1, u2])| {
            let (m1, m2) = (flow(u1), flow(u2));
            let det = m1[0] * m2[1] - m1[1] * m2[0];
            let inv = [[m2[1] / det, -m1[1] / det], [-m2[0] / det, m1[0] / det]];
            (name, Mat::from_fn(2, 2, |i, j| g[(i, 0)] * inv[0][j] + g[(i, 1)] * inv[1][j]))
        })
        .collect()
}

/// The rows of `g`, for messages.
fn rows(g: &Mat<f64>) -> Vec<Vec<f64>> {
    (0..g.nrows()).map(|i| (0..g.ncols()).map(|j| g[(i, j)]).collect()).collect()
}

/// The (1, 1) relative gain of a 2 × 2 gain matrix.
fn lambda11(g: &Mat<f64>) -> f64 {
    rga(g.as_ref()).unwrap_or_else(|e| panic!("{e}"))[(0, 0)]
}

/// §2 of the study: on both columns LV is interactive and LB decoupled; column 2's DV pairs the
/// wrong way round; LB is the one structure to pair diagonally on both columns. The bounds are
/// the relative-gain rules (pair on λ11 near 1; λ11 ≫ 1 interactive; λ11 → 0 the other pairing),
/// not the study's numbers (the ignored full study pins those).
#[test]
fn lb_is_the_structure_for_both_columns() {
    let decoupled = |l: f64| (0.67..1.5).contains(&l);
    let c1 = structures("column1", ["column1.T[21]", "column1.T[11]"], ["column1_top_T", "column1_bottom_T"]);
    let c2 = structures("column2", ["product.x[S]", "column2.T[6]"], ["column2_top_S", "column2_bottom_T"]);
    for (col, s) in [("column1", &c1), ("column2", &c2)] {
        for (name, g) in s.iter() {
            eprintln!("{col} {name}: G = {:?}, λ11 = {:.4}", rows(g), lambda11(g));
            // For 2 × 2, NI = det G / (g11 g22) = 1/λ11.
            let ni = niederlinski(g.as_ref(), &[0, 1]).unwrap_or_else(|e| panic!("{e}"));
            assert!((ni * lambda11(g) - 1.0).abs() < 1e-9, "{col} {name}: NI {ni} vs λ11 {}", lambda11(g));
        }
    }
    let l = |s: &[(&str, Mat<f64>)], name: &str| lambda11(&s.iter().find(|(n, _)| *n == name).expect("structure").1);
    // Column 1 LV: more reflux cools both temperatures, more boilup heats both, so the loops fight.
    let lv1 = &c1[0].1;
    assert!(lv1[(0, 0)] < 0.0 && lv1[(1, 0)] < 0.0 && lv1[(0, 1)] > 0.0 && lv1[(1, 1)] > 0.0, "{:?}", rows(lv1));
    assert!(l(&c1, "LV") > 3.0, "column 1 LV λ11 = {}", l(&c1, "LV"));
    assert!(decoupled(l(&c1, "DV")) && decoupled(l(&c1, "LB")), "column 1: DV {} LB {}", l(&c1, "DV"), l(&c1, "LB"));
    // Column 2: 5 kmol/h of bottoms under 250 kmol/h of boilup (Richardson's rule).
    assert!(l(&c2, "LV") > 5.0, "column 2 LV λ11 = {}", l(&c2, "LV"));
    assert!(decoupled(l(&c2, "LB")), "column 2 LB λ11 = {}", l(&c2, "LB"));
    assert!((0.0..0.1).contains(&l(&c2, "DV")), "column 2 DV λ11 = {}", l(&c2, "DV"));
    let both: Vec<&str> =
        ["LV", "DV", "LB"].into_iter().filter(|s| decoupled(l(&c1, s)) && decoupled(l(&c2, s))).collect();
    assert_eq!(both, ["LB"]);
}

/// §3: the fresh-A flow sets production (every mole of A leaves as R: ∂R/∂F_A = 1 to the
/// product's purity) and snowballs the recycle (with the reactor's holdup and temperature held,
/// more R needs richer reactor contents: the recycle grows faster than the feed, elasticity > 1);
/// the reactor temperature cannot move production with the fresh A fixed.
#[test]
fn fresh_a_sets_production_and_snowballs_the_recycle() {
    let (plant, x, u) = base();
    let g =
        gains(plant, x, u, &["fresh_A.F@kmol/h", "reactor_temperature.sp"], &["product.F@kmol/h", "recycle.F@kmol/h"]);
    eprintln!("production gains (∂/∂F_A, ∂/∂T_sp): product {:?}, recycle {:?}", rows(&g)[0], rows(&g)[1]);
    assert!((g[(0, 0)] - 1.0).abs() < 0.01, "∂R/∂F_A = {}", g[(0, 0)]);
    let (fa, rec) = (harness::value(plant, x, "feed_A.F"), harness::value(plant, x, "recycle.F"));
    assert!(g[(1, 0)] * fa / rec > 1.0, "recycle elasticity {}", g[(1, 0)] * fa / rec);
    assert!(g[(0, 1)].abs() < 0.02, "∂R/∂T_sp = {} kmol/h/K", g[(0, 1)]);
}

/// §4 (book figure 6-6): with the chosen structure holding its temperatures, ±10 % of the feed
/// rate moves column 1's bottoms impurity more than ±10 % of the feed temperature (in °C) or of
/// the reactor's B content do (linear estimate of each band: |∂x_B/∂d| · 20 % of d).
#[test]
fn feed_rate_moves_column_1_bottoms_most() {
    let (plant, x, u) = base();
    let ds = ["fresh_A.F", "feed_cooler.T_out", "reactor_B.sp"];
    let g = gains(plant, x, u, &ds, &["bottoms1.x[B]"]);
    let nominal = |d: &str| {
        let v = u[select_input(plant, d).unwrap_or_else(|e| panic!("{e}")).index];
        if d.ends_with(".T_out") { v - 273.15 } else { v }
    };
    let band: Vec<f64> = ds.iter().enumerate().map(|(j, d)| (g[(0, j)] * 0.2 * nominal(d)).abs()).collect();
    eprintln!("bottoms x_B bands: {band:?}");
    assert!(band[0] > band[1] && band[0] > band[2], "{band:?}");
}

/// §8: at 350 K the reactor is open-loop unstable (eigenvalues in the right half plane with its
/// temperature loop in manual); with the loop in automatic the plant is stable.
#[test]
fn reactor_is_open_loop_unstable_and_stabilized_by_its_loop() {
    let (plant, x, u) = base();
    let rhp = |p: &Plant, u: &[f64]| -> Vec<c64> {
        let ss = Linearization::new(p, x, u).state_space(&[], &[]).unwrap_or_else(|e| panic!("{e}"));
        ss.eigenvalues().unwrap_or_else(|e| panic!("{e}")).into_iter().filter(|l| l.re > 0.0).collect()
    };
    assert!(rhp(plant, u).is_empty(), "closed loop: {:?}", rhp(plant, u));
    let open = rhp(plant, &manual(&["reactor_temperature"]));
    assert!(!open.is_empty(), "the temperature loop in manual leaves the plant stable");
}

/// §6: a 5 m³ tank (2 m² × 5 m) between the columns under a P-only averaging level loop (Kc =
/// 40 kmol/h per m) passes a cycle of column 1's bottoms flow as the first-order filter
/// `1/(τs + 1)` with `τ = A ρ / Kc` (ρ the molar density in the tank): `|G(jω)| = 1/√(1 + (ωτ)²)`,
/// about 30 % of a 1 h cycle.
#[test]
fn surge_tank_passes_a_cycle_as_a_first_order_lag() {
    let text = std::fs::read_to_string(harness::flowsheet("two_column_plant.json")).expect("the flowsheet");
    let mut spec: Value = serde_json::from_str(&text).expect("JSON");
    spec["units"]["surge"] = json!({"type": "tank", "area": "2 m2", "height": "5 m", "P": "1.2 bar",
        "outflow": {"type": "flow", "flow": "105.2 kmol/h"}});
    spec["streams"]["bottoms1"] = json!({"from": "column1.bottoms", "to": "surge"});
    spec["streams"]["column2_feed"] = json!({"from": "surge", "to": "column2.feed"});
    spec["controllers"]["surge_level"] = json!({"type": "pid", "pv": "surge.level", "output": "surge.outflow",
        "sp": "2.5 m", "kc": "40 kmol/h/m", "action": "direct"});
    let plant = load_str(&spec.to_string(), "two_column_plant_surge_tank.json").unwrap_or_else(|e| panic!("{e}"));
    let u = plant.input_values();
    let sol = steady_state_by(&plant, &u, &StrategySettings::default(), &mut |_| {}).unwrap_or_else(|e| panic!("{e}"));
    let omega = 2.0 * PI / 3600.0;
    let ii = [select_input(&plant, "feed_cooler.T_out").unwrap_or_else(|e| panic!("{e}")).index];
    let oo = ["bottoms1.F", "column2_feed.F"].map(|p| plant.var(p).unwrap_or_else(|| panic!("no {p}")));
    let lin = Linearization::new(&plant, &sol.x, &sol.u);
    let g = &lin.frequency_response(&ii, &oo, &[omega]).unwrap_or_else(|e| panic!("{e}"))[0];
    let passed = g[(1, 0)].norm() / g[(0, 0)].norm();
    let rho = harness::value(&plant, &sol.x, "surge.M") / harness::value(&plant, &sol.x, "surge.V");
    let tau = 2.0 * rho / (40e3 / 3600.0);
    let closed = 1.0 / (1.0 + (omega * tau).powi(2)).sqrt();
    eprintln!("surge tank: passes {passed:.5} of a 1 h cycle, first-order closed form {closed:.5} (τ = {tau:.1} s)");
    assert!((passed / closed - 1.0).abs() < 0.01, "passes {passed} vs closed form {closed}");
    assert!(passed < 0.5, "the tank must at least halve a 1 h cycle: {passed}");
}

/// One hour of the plant after a +10 % production step and a column-1 feed-temperature step (both
/// columns, the reactor and the recycle all move): the A atoms (A + R) and B atoms (B + R + 2 S)
/// held in the reactor and on every stage, drum and sump change by exactly what the boundary
/// streams brought in and took out (`record.totals`), while A + B → R and 2 B → S run.
#[test]
fn two_column_plant_conserves_atoms_through_an_upset() {
    let plant = load_file(Path::new(&harness::flowsheet("two_column_plant.json"))).unwrap_or_else(|e| panic!("{e}"));
    let u = plant.input_values();
    let x0 = steady_state_by(&plant, &u, &StrategySettings::default(), &mut |_| {}).unwrap_or_else(|e| panic!("{e}")).x;
    let scenario = r#"{"format_version": 1, "duration": "1 h",
        "events": [{"type": "step", "at": "5 min", "path": "production_rate", "by": "10 kmol/h"},
                   {"type": "step", "at": "10 min", "path": "feed_cooler.T_out", "by": "5 K"}],
        "record": {"interval": "1 min", "paths": ["effluent.T"], "totals": ["feed_A", "feed_B", "product", "heavies"]}}"#;
    let sc = resolve(&parse_scenario(scenario, "upset.json").unwrap(), &plant, "upset.json").unwrap();
    let res = simulate(&plant, &sc, Start::Steady(&x0), "test", &mut |_| {}).unwrap_or_else(|e| panic!("{e}"));
    let comps = ["A", "B", "R", "S"];
    // Moles of each component held in the plant.
    let held = |x: &[f64]| -> Vec<f64> {
        comps
            .iter()
            .map(|c| {
                let columns: f64 = ["column1", "column2"]
                    .iter()
                    .flat_map(|col| (1..=32).map(move |s| format!("{col}.n[{s}][{c}]")))
                    .map(|p| harness::value(&plant, x, &p))
                    .sum();
                columns + harness::value(&plant, x, &format!("reactor.N[{c}]"))
            })
            .collect()
    };
    let total = |stream: &str, c: &str| {
        let k = res.columns.iter().position(|col| col.path == format!("{stream}.total[{c}]")).expect("total");
        res.rows.last().expect("rows")[k]
    };
    let net: Vec<f64> = comps
        .iter()
        .map(|c| total("feed_A", c) + total("feed_B", c) - total("product", c) - total("heavies", c))
        .collect();
    let (h0, h1) = (held(&x0), held(&res.x));
    let change: Vec<f64> = (0..4).map(|j| h1[j] - h0[j]).collect();
    // Atoms: A in A and R; B in B, R and twice in S.
    let atoms = |v: &[f64]| [v[0] + v[2], v[1] + v[2] + 2.0 * v[3]];
    let (held_change, brought) = (atoms(&change), atoms(&net));
    let fed = [total("feed_A", "A"), total("feed_B", "B")];
    let reacted = change[2] - net[2];
    assert!(reacted > 0.1 * fed[0], "R made in the hour: {reacted} mol of {} mol of A fed", fed[0]);
    for (k, name) in ["A atoms", "B atoms"].iter().enumerate() {
        let gap = (held_change[k] - brought[k]).abs() / fed[k];
        eprintln!(
            "{name}: Δheld {:.6} mol, ∫(in − out) {:.6} mol, fed {:.1} mol: gap {gap:.1e}",
            held_change[k], brought[k], fed[k]
        );
        assert!(gap < 1e-8, "{name}: held changed by {} mol, the boundary brought {} mol", held_change[k], brought[k]);
    }
}
