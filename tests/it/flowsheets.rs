//! Every shipped flowsheet validates, and the shipped JSON Schema is the one the types generate.

use crate::harness;

fn shipped() -> Vec<std::path::PathBuf> {
    let dir = harness::flowsheet("");
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json") && !p.to_string_lossy().ends_with(".schema.json"))
        .collect();
    v.sort();
    v
}

#[test]
fn every_shipped_flowsheet_passes_check() {
    let files = shipped();
    assert!(files.len() >= 2);
    for f in files {
        let out = harness::command().arg("check").arg(&f).output().unwrap();
        assert!(out.status.success(), "{}: {}", f.display(), String::from_utf8_lossy(&out.stderr));
        assert!(String::from_utf8_lossy(&out.stdout).contains("degrees of freedom: 0"));
    }
}

#[test]
fn shipped_schema_matches_the_types() {
    let out = harness::plantwide(&["schema"]);
    assert!(out.status.success());
    let generated: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let path = harness::flowsheet("plantwide.schema.json");
    let shipped: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    assert!(
        generated == shipped,
        "flowsheets/plantwide.schema.json is stale: regenerate it with `plantwide schema > flowsheets/plantwide.schema.json`"
    );
}

#[test]
fn every_shipped_flowsheet_round_trips_through_the_types() {
    for f in shipped() {
        let text = std::fs::read_to_string(&f).unwrap();
        let spec = plantwide::flowsheet::parse_spec(&text, &f.display().to_string()).unwrap();
        let again = serde_json::to_string(&spec).unwrap();
        let spec2 = plantwide::flowsheet::parse_spec(&again, "round trip").unwrap();
        assert_eq!(spec, spec2, "{}", f.display());
    }
}
