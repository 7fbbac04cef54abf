//! Every shipped flowsheet validates, and the shipped JSON Schema is the one the types generate.

use crate::harness;

/// The shipped flowsheets: every JSON file in flowsheets/ but the schemas.
fn shipped() -> Vec<std::path::PathBuf> {
    json_files(std::path::Path::new(&harness::flowsheet("")))
}

/// The JSON files of `dir` (not its subfolders) but the schemas, sorted.
fn json_files(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
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

#[test]
fn shipped_scenario_schema_matches_the_types() {
    let out = harness::plantwide(&["schema", "--scenario"]);
    assert!(out.status.success());
    let generated: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let path = harness::flowsheet("scenario.schema.json");
    let shipped: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    assert!(
        generated == shipped,
        "flowsheets/scenario.schema.json is stale: regenerate it with `plantwide schema --scenario > flowsheets/scenario.schema.json`"
    );
}

/// A validator built from a shipped schema file.
fn validator(name: &str) -> jsonschema::Validator {
    let text = std::fs::read_to_string(harness::flowsheet(name)).unwrap();
    jsonschema::validator_for(&serde_json::from_str(&text).unwrap()).unwrap()
}

/// An independent JSON Schema validator (the `jsonschema` crate, draft 2020-12) accepts every
/// flowsheet and scenario the loader accepts: the shipped ones and the test data.
#[test]
fn the_schemas_accept_every_file_the_loader_accepts() {
    let flowsheet_schema = validator("plantwide.schema.json");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let flowsheets = shipped().into_iter().chain(json_files(&root.join("tests/data")));
    for f in flowsheets {
        let text = std::fs::read_to_string(&f).unwrap();
        plantwide::flowsheet::load_str(&text, &f.display().to_string()).unwrap();
        let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
        let errors: Vec<String> =
            flowsheet_schema.iter_errors(&doc).map(|e| format!("{e} at {}", e.instance_path)).collect();
        assert!(errors.is_empty(), "{}: {errors:?}", f.display());
    }
    let scenario_schema = validator("scenario.schema.json");
    let scenarios = json_files(&root.join("flowsheets/scenarios"));
    assert!(scenarios.len() >= 5);
    for f in scenarios {
        let text = std::fs::read_to_string(&f).unwrap();
        plantwide::flowsheet::scenario::parse_scenario(&text, &f.display().to_string()).unwrap();
        let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
        let errors: Vec<String> =
            scenario_schema.iter_errors(&doc).map(|e| format!("{e} at {}", e.instance_path)).collect();
        assert!(errors.is_empty(), "{}: {errors:?}", f.display());
    }
}

/// An edit breaking a document.
type Edit = Box<dyn Fn(&mut serde_json::Value)>;

/// Files broken in their structure (an unknown key, a misspelt or unknown type, a wrong JSON type,
/// a missing required field) are rejected by the loader and by the schema alike.
#[test]
fn the_schemas_reject_what_the_loader_rejects() {
    let base: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(harness::flowsheet("surge_tank_pi.json")).unwrap()).unwrap();
    let tank = base["units"].as_object().unwrap().iter().find(|(_, u)| u["type"] == "tank").unwrap().0.clone();
    let feed = base["units"].as_object().unwrap().iter().find(|(_, u)| u["type"] == "feed").unwrap().0.clone();
    let broken: Vec<(&str, Edit)> = vec![
        ("unknown top-level key", Box::new(|d| d["colour"] = "red".into())),
        ("unknown unit field", Box::new(move |d| d["units"][&tank]["colour"] = "red".into())),
        ("unknown unit type", Box::new(|d| d["units"]["x"] = serde_json::json!({"type": "reactorr"}))),
        ("flow as an object", Box::new(move |d| d["units"][&feed]["F"] = serde_json::json!({"value": 1}))),
        ("missing units", Box::new(|d| drop(d.as_object_mut().unwrap().remove("units")))),
        ("components not a list", Box::new(|d| d["components"] = "water".into())),
        ("stream without `to`", Box::new(|d| d["streams"] = serde_json::json!({"s": {"from": "a"}}))),
    ];
    let schema = validator("plantwide.schema.json");
    for (what, edit) in &broken {
        let mut doc = base.clone();
        edit(&mut doc);
        assert!(!schema.is_valid(&doc), "schema accepts: {what}");
        assert!(plantwide::flowsheet::load_str(&doc.to_string(), "broken.json").is_err(), "loader accepts: {what}");
    }
    let scenario: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(harness::flowsheet("scenarios/surge_tank_inflow_step.json")).unwrap(),
    )
    .unwrap();
    let broken: Vec<(&str, Edit)> = vec![
        ("no duration", Box::new(|d| drop(d.as_object_mut().unwrap().remove("duration")))),
        ("unknown event type", Box::new(|d| d["events"] = serde_json::json!([{"type": "jump", "at": "1 min"}]))),
        (
            "step without a path",
            Box::new(|d| d["events"] = serde_json::json!([{"type": "step", "at": "1 min", "to": 1}])),
        ),
        ("unknown key", Box::new(|d| d["colour"] = "red".into())),
        ("record paths not a list", Box::new(|d| d["record"] = serde_json::json!({"paths": "tank.level"}))),
    ];
    let schema = validator("scenario.schema.json");
    for (what, edit) in &broken {
        let mut doc = scenario.clone();
        edit(&mut doc);
        assert!(!schema.is_valid(&doc), "scenario schema accepts: {what}");
        let parsed = plantwide::flowsheet::scenario::parse_scenario(&doc.to_string(), "broken.json");
        assert!(parsed.is_err(), "scenario loader accepts: {what}");
    }
}

/// Every port of every unit in the shipped flowsheets is named in its type's schema entry (a
/// numbered port `in3` as its first, `in1`; a port the file itself names, as a column's feed, by the
/// field that names it).
#[test]
fn the_schema_names_every_port_of_every_shipped_unit() {
    let schema = plantwide::flowsheet::schema::flowsheet_schema();
    let variants = schema.pointer("/$defs/UnitSpec/oneOf").and_then(|v| v.as_array()).unwrap().clone();
    let describe = |tag: &str| {
        let v = variants.iter().find(|v| v.pointer("/properties/type/const").and_then(|c| c.as_str()) == Some(tag));
        v.and_then(|v| v["description"].as_str()).unwrap_or_else(|| panic!("no schema entry for {tag}")).to_string()
    };
    for f in shipped() {
        let plant = plantwide::flowsheet::load_file(&f).unwrap();
        for (name, unit) in &plant.spec().units {
            let block = &plant.blocks()[plant.block_index(name).unwrap()];
            let text = describe(unit.type_name());
            let own = serde_json::to_string(unit).unwrap();
            for port in block.unit.inlet_ports().into_iter().chain(block.unit.outlet_ports()) {
                let base = port.trim_end_matches(|c: char| c.is_ascii_digit());
                let named = if base.len() < port.len() { format!("`{base}1`") } else { format!("`{port}`") };
                let by_file = own.contains(&format!("\"port\":\"{port}\""));
                assert!(text.contains(&named) || by_file, "{}: {name}.{port} not in `{text}`", f.display());
            }
        }
    }
}
