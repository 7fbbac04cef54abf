//! `plantwide tune --tf`: JSON shape, time units, and bad input (exit 1 with the message).

use crate::harness::{flowsheet, plantwide};

#[test]
fn blt_json_on_wood_berry_in_minutes() {
    let wb = flowsheet("transfer_functions/wood_berry.tf.json");
    let out = plantwide(&["tune", "--tf", &wb, "--method", "blt", "--time-unit", "min", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["method"], "blt");
    // Luyben (1986): F = 2.55, Kc = 0.375 / −0.075, τI = 8.29 / 23.6 min (see crates/studies/tests/tune.rs).
    assert!((v["detuning_factor"].as_f64().unwrap() - 2.55).abs() < 0.006);
    let l = &v["loops"];
    assert!((l[0]["kc"].as_f64().unwrap() - 0.375).abs() < 5e-4 && (l[1]["kc"].as_f64().unwrap() + 0.075).abs() < 5e-4);
    assert!(
        (l[0]["tau_i"].as_f64().unwrap() - 8.29).abs() < 5e-3 && (l[1]["tau_i"].as_f64().unwrap() - 23.6).abs() < 0.05
    );
    // The default time unit is the second; ZN carries no detuning factor.
    let out = plantwide(&["tune", "--tf", &wb, "--method", "zn", "--json"]);
    let z: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(z.get("detuning_factor").is_none() && z["method"] == "zn");
    let ratio = z["loops"][0]["pu"].as_f64().unwrap() / l[0]["pu"].as_f64().unwrap();
    assert!((ratio - 60.0).abs() < 1e-9, "{ratio}");
    let table = String::from_utf8(plantwide(&["tune", "--tf", &wb, "--method", "tl"]).stdout).unwrap();
    assert!(table.contains("Tyreus–Luyben") && table.contains("xB      S"), "{table}");
}

#[test]
fn bad_models_exit_1_naming_the_problem() {
    let dir = std::env::temp_dir().join(format!("plantwide-tune-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases = [
        (
            "wide.tf.json",
            r#"{"format_version": 1, "name": "wide", "inputs": [{"name": "a"}, {"name": "b"}], "outputs": [{"name": "y"}],
               "elements": [{"output": "y", "input": "a", "gain": 1, "lags": [10], "dead_time": 1}]}"#,
            "`wide` is not square (1 outputs × 2 inputs)",
        ),
        (
            "lag.tf.json",
            r#"{"format_version": 1, "name": "lag", "inputs": [{"name": "a"}], "outputs": [{"name": "y"}],
               "elements": [{"output": "y", "input": "a", "gain": 1, "lags": [10]}]}"#,
            "element y ← a has no phase crossover",
        ),
    ];
    for (name, text, message) in cases {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let out = plantwide(&["tune", "--tf", path.to_str().unwrap(), "--method", "blt"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{name}: {err}");
        assert!(err.contains(message) && !err.contains("panicked"), "{name}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
