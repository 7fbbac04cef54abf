//! The JSON Schemas of flowsheet and scenario files (`plantwide schema [--scenario]`, shipped as
//! `flowsheets/plantwide.schema.json` and `flowsheets/scenario.schema.json`), derived from the
//! same types the loader reads, so the two cannot disagree on structure; each unit type's entry
//! also names its ports, which a stream's `from` and `to` refer to.

use plantwide_model::UnitSpec;
use serde_json::Value;

use crate::FlowsheetSpec;
use crate::scenario::ScenarioSpec;

/// The JSON Schema (draft 2020-12) of flowsheet files, every unit type described with its ports.
pub fn flowsheet_schema() -> Value {
    let mut schema = schemars::schema_for!(FlowsheetSpec).to_value();
    let variants = schema.pointer_mut("/$defs/UnitSpec/oneOf").and_then(Value::as_array_mut);
    for variant in variants.into_iter().flatten() {
        let tag = variant.pointer("/properties/type/const").and_then(Value::as_str).map(str::to_string);
        let Some(ports) = tag.as_deref().and_then(UnitSpec::ports_of) else { continue };
        let text = match variant.get("description").and_then(Value::as_str) {
            Some(d) => format!("{d}. Ports: {ports}."),
            None => format!("Ports: {ports}."),
        };
        variant["description"] = Value::String(text);
    }
    schema
}

/// The JSON Schema (draft 2020-12) of scenario files.
pub fn scenario_schema() -> Value {
    schemars::schema_for!(ScenarioSpec).to_value()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_unit_type_names_its_ports_in_the_schema() {
        let schema = flowsheet_schema();
        let variants = schema.pointer("/$defs/UnitSpec/oneOf").and_then(Value::as_array).unwrap();
        assert_eq!(variants.len(), UnitSpec::TYPES.len());
        for v in variants {
            let d = v["description"].as_str().unwrap();
            assert!(d.contains("Ports: ") && d.contains('`'), "{d}");
        }
        let hx = variants.iter().find(|v| v.pointer("/properties/type/const") == Some(&"heat_exchanger".into()));
        let d = hx.unwrap()["description"].as_str().unwrap();
        for p in ["hot_in", "cold_in", "hot_out", "cold_out"] {
            assert!(d.contains(&format!("`{p}`")), "{d}");
        }
    }
}
