//! `plantwide select --matrices`: the JSON contract of issue 58, the text, and bad data or
//! requests refused with exit 1 naming the field or flag, a search out of budget with exit 2.
//! The numbers themselves are tested in crates/soc/tests against pySOC's fixtures.

use serde_json::Value;

use crate::harness::{ROOT, plantwide};

fn data(name: &str) -> String {
    format!("{ROOT}/crates/soc/tests/data/{name}")
}

fn scratch(name: &str, text: &str) -> String {
    let dir = std::env::temp_dir().join(format!("plantwide-select-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// Run, expect the exit code, and return stderr (checked to contain each fragment).
fn refused(args: &[&str], code: i32, fragments: &[&str]) {
    let out = plantwide(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
    for f in fragments {
        assert!(err.contains(f), "{args:?}: `{f}` not in: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn the_json_has_the_keys_of_the_contract_best_first() {
    let out = plantwide(&["select", "--matrices", &data("evaporator.json"), "--size", "3", "--best", "4", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in ["criterion", "size", "subsets", "nodes"] {
        assert!(v.get(key).is_some(), "no `{key}` in {v}");
    }
    assert_eq!((v["criterion"].as_str(), v["size"].as_u64()), (Some("worst"), Some(3)));
    assert!(v["nodes"].as_u64().unwrap() > 0);
    let subsets = v["subsets"].as_array().unwrap();
    assert_eq!(subsets.len(), 4);
    // The best: F2, F100, F200 at 12.700492080350088 (the 60-digit value of the fixture file).
    let best = &subsets[0];
    let names: Vec<&str> = best["measurements"].as_array().unwrap().iter().map(|m| m.as_str().unwrap()).collect();
    assert_eq!(names, ["F2", "F100", "F200"]);
    assert!((best["worst_case_loss"].as_f64().unwrap() / 12.700492080350088 - 1.0).abs() < 1e-8);
    let losses: Vec<f64> = subsets.iter().map(|s| s["worst_case_loss"].as_f64().unwrap()).collect();
    assert!(losses.windows(2).all(|w| w[0] <= w[1]), "{losses:?}");
    for s in subsets {
        assert!(s["average_loss"].as_f64().unwrap() > 0.0);
        let h = s["H"].as_array().unwrap();
        assert_eq!(h.len(), 2, "H has a row per input");
        assert!(h.iter().all(|r| r.as_array().unwrap().len() == 3), "and a column per measurement");
        assert!(s.get("null_space").is_none(), "3 < nu + nd = 5: no null-space combination");
    }
}

#[test]
fn the_average_criterion_and_the_null_space_combination_where_it_exists() {
    let out = plantwide(&[
        "select",
        "--matrices",
        &data("evaporator.json"),
        "--size",
        "6",
        "--criterion",
        "average",
        "--json",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["criterion"], "average");
    let subsets = v["subsets"].as_array().unwrap();
    assert_eq!(subsets.len(), 5, "the default is the 5 best");
    let averages: Vec<f64> = subsets.iter().map(|s| s["average_loss"].as_f64().unwrap()).collect();
    assert!(averages.windows(2).all(|w| w[0] <= w[1]), "{averages:?}");
    for s in subsets {
        // The null-space combination loses more than the exact local method's best (noise counts).
        let null = &s["null_space"];
        assert!(null["average_loss"].as_f64().unwrap() >= s["average_loss"].as_f64().unwrap() * (1.0 - 1e-12));
        assert_eq!(null["H"].as_array().unwrap().len(), 2);
    }
}

#[test]
fn the_text_names_the_best_subset_and_its_combination() {
    let out = plantwide(&["select", "--matrices", &data("evaporator.json"), "--size", "2"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(text.contains("F3, F200"), "{text}");
    assert!(text.contains("c = H y for the best subset"), "{text}");
    assert!(text.contains("nodes evaluated"), "{text}");
}

#[test]
fn bad_data_and_requests_are_refused_by_field_or_flag() {
    let evaporator = data("evaporator.json");
    refused(
        &["select", "--matrices", &evaporator, "--size", "1"],
        1,
        &["--size 1", "at least as many measurements as inputs (2)"],
    );
    refused(&["select", "--matrices", &evaporator, "--size", "11"], 1, &["--size 11", "candidates (10)"]);
    refused(&["select", "--matrices", &evaporator, "--size", "2", "--best", "0"], 1, &["--best 0"]);
    refused(&["select", "--matrices", &evaporator, "--size", "2", "--max-nodes", "0"], 1, &["--max-nodes 0"]);
    refused(
        &["select", "--matrices", "/no/such/file.json", "--size", "2"],
        1,
        &["/no/such/file.json", "cannot be read"],
    );
    let original: Value = serde_json::from_str(&std::fs::read_to_string(&evaporator).unwrap()).unwrap();
    let edit = |f: &dyn Fn(&mut Value)| {
        let mut v = original.clone();
        f(&mut v);
        v.to_string()
    };
    let cases: Vec<(String, Vec<&str>)> = vec![
        (edit(&|v| v["Gyd"][3] = serde_json::json!([1.0])), vec!["`Gyd`", "row 3 has 1 entries"]),
        (edit(&|v| v["Juu"][0][1] = serde_json::json!(5.0)), vec!["`Juu`", "not symmetric"]),
        (edit(&|v| v["Juu"] = serde_json::json!([[-1.0, 0.0], [0.0, 1.0]])), vec!["`Juu`", "not positive definite"]),
        (edit(&|v| v["Wn"] = serde_json::json!([1.0, 2.0])), vec!["`Wn`", "has 2 magnitudes; it needs 10"]),
        (edit(&|v| v["Wn"][4] = serde_json::json!(-1.0)), vec!["`Wn`", "negative"]),
        (edit(&|v| v["Wd"] = serde_json::json!("big")), vec!["Wd", "a list (the diagonal) or as a list of rows"]),
        (edit(&|v| v["measurements"][3] = serde_json::json!("P2")), vec!["`measurements`", "`P2` is given twice"]),
        (edit(&|v| v["gain"] = serde_json::json!(1)), vec!["unknown field `gain`"]),
        (edit(&|v| v["measurements"][6] = serde_json::json!("F3, F200")), vec!["`measurements`", "without commas"]),
        (edit(&|v| v["inputs"][0] = serde_json::json!("")), vec!["`inputs`", "entry 0"]),
        (format!("{original} {original}"), vec!["more than one JSON value"]),
        // A perfect measurement is allowed while the disturbances still move it; none at all is not.
        (edit(&|v| v["Wn"] = serde_json::json!(vec![0.0; 10])), vec!["`Wn`", "errors of a size that counts"]),
    ];
    for (k, (text, fragments)) in cases.iter().enumerate() {
        let file = scratch(&format!("bad{k}.json"), text);
        refused(&["select", "--matrices", &file, "--size", "2"], 1, fragments);
    }
}

#[test]
fn a_search_out_of_its_node_budget_exits_2_with_the_best_so_far() {
    refused(
        &["select", "--matrices", &data("cao_ny40_nu15_nd5.json"), "--size", "15", "--max-nodes", "50"],
        2,
        &["stopped after 50 nodes", "--max-nodes", "the best found so far: y"],
    );
}

#[test]
fn long_names_are_printed_whole_in_the_combination() {
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(data("evaporator.json")).unwrap()).unwrap();
    v["measurements"][6] = "Temperature_tray_07".into();
    v["measurements"][8] = "Temperature_tray_08".into();
    v["inputs"] = serde_json::json!(["Reflux_flow_rate_A", "Reflux_flow_rate_B"]);
    let file = scratch("long_names.json", &v.to_string());
    let out = plantwide(&["select", "--matrices", &file, "--size", "2", "--best", "1"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    for name in ["Temperature_tray_07", "Temperature_tray_08", "c[Reflux_flow_rate_A]", "c[Reflux_flow_rate_B]"] {
        assert!(text.contains(name), "{name} not in {text}");
    }
    // All 45 pairs asked for: every one is listed and none is said to be missing.
    let out = plantwide(&["select", "--matrices", &data("evaporator.json"), "--size", "2", "--best", "100"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("these are all 45 subsets of 2") && !text.contains("rank-deficient"), "{text}");
}

/// Output to a full disk is a failure with its reason, not a silent exit 0 (a closed pipe, as
/// under `head`, still ends quietly).
#[test]
fn output_to_a_full_disk_exits_1_with_the_reason() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else { return };
    let out = crate::harness::command()
        .args(["select", "--matrices", &data("evaporator.json"), "--size", "2"])
        .stdout(full)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("cannot write the output"), "{err}");
}
