//! The chapter-6 study of `flowsheets/two_column_plant.json`, run end to end on short horizons by
//! `tools/two_column_study.py` (the same script that writes `docs/two_column_plant.md`), with its
//! conservation and its conclusions pinned.

use std::path::Path;
use std::process::Command;

use serde_json::Value;

fn num(v: &Value, path: &str) -> f64 {
    let mut cur = v;
    for key in path.split('.') {
        cur = &cur[key];
    }
    cur.as_f64().unwrap_or_else(|| panic!("{path} is not a number: {cur}"))
}

fn close(v: &Value, path: &str, expected: f64, rel: f64) {
    let got = num(v, path);
    assert!((got - expected).abs() <= rel * expected.abs(), "{path}: {got} vs {expected} (±{rel:e} relative)");
}

#[test]
fn two_column_study_runs_and_reaches_its_conclusions() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
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

    // Conservation of the base case: A atoms, B atoms, mass, reactor energy.
    for b in ["A + R", "B + R + 2S", "mass", "reactor energy"] {
        let e = r["base"]["balances"][b].as_f64().expect("balance");
        assert!(e < 1e-9, "{b}: relative imbalance {e:e}");
    }
    // The base case as designed (flowsheets/README.md).
    close(&r, "base.product_kmol_h", 100.146, 1e-3);
    close(&r, "base.recycle_kmol_h", 197.60, 1e-3);
    close(&r, "base.reactor_T", 350.0, 1e-9);
    close(&r, "base.residence_min", 19.81, 1e-3);

    // Column structures: LV interactive on both columns, LB decoupled; the book's perturbation
    // gains agree with the linearization where they re-converge.
    close(&r, "column1.LV.rga11", 5.2216, 1e-3);
    close(&r, "column1.LV.niederlinski", 0.19151, 1e-3);
    close(&r, "column1.DV.rga11", 1.2401, 1e-3);
    close(&r, "column1.LB.rga11", 1.1480, 1e-3);
    close(&r, "column2.LV.rga11", 11.98, 1e-2);
    close(&r, "column2.LB.rga11", 0.9762, 1e-3);
    close(&r, "column2.DV.rga11", 0.02403, 1e-2);
    for s in ["column1.LV", "column1.DV", "column2.LB"] {
        let d = num(&r, &format!("{s}.perturb_vs_linear"));
        assert!(d < 1e-3, "{s}: perturbation and linearization differ by {d:e}");
    }
    assert!(r["column2"]["DB_error"].as_str().is_some_and(|e| e.contains("not determined")));
    assert_eq!(r["sensors_column1"], serde_json::json!([21, 11]));

    // Production rate: the fresh-A flow sets it (all A leaves as R) and snowballs the recycle; the
    // reactor temperature does not move it.
    close(&r, "production.P1.product", 0.99922, 1e-3);
    close(&r, "production.P1.recycle_per_product", 4.615, 1e-3);
    assert!(num(&r, "production.P2.product").abs() < 0.02);

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

    // Surge tank: the measured attenuation of a 1 h flow cycle is the first-order filter's.
    let att = num(&r, "surge.attenuation");
    let closed = num(&r, "surge.first_order_closed_form");
    assert!((att / closed - 1.0).abs() < 0.02, "attenuation {att} vs closed form {closed}");
    close(&r, "surge.first_order_closed_form", 0.3033, 1e-3);

    // Reflux drum: a bigger drum lets less of a column upset into the reactor.
    let through = |m: &str| num(&r, &format!("drum.{m}.recycle_max_dev_kmol_h"));
    assert!(through("1min") > 2.0 * through("5min") && through("5min") > 2.0 * through("15min"));

    // Safety: open-loop unstable reactor; the trip holds it near the trip point; recycle upsets
    // start an excursion only with the temperature loop in manual.
    assert!(num(&r, "safety.peak_no_action") > 390.0, "{}", r["safety"]);
    assert!(num(&r, "safety.peak_trip") < 362.0, "{}", r["safety"]);
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
    let _ = std::fs::remove_dir_all(&out);
}
