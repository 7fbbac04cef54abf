//! Reading a flowsheet file into a [`FlowsheetSpec`], section by section so that every structural
//! problem is reported at once with its JSON path.

use indexmap::IndexMap;
use plantwide_model::{ControllerSpec, UnitSpec};
use serde::de::DeserializeOwned;
use serde_json::Value;

use crate::error::{Diagnostic, LoadError, did_you_mean};
use crate::spec::{ComponentSpec, FORMAT_VERSION, FlowsheetSpec, StreamSpec, ThermoSpec};

const TOP_LEVEL: &[&str] =
    &["format_version", "name", "description", "components", "thermo", "units", "streams", "controllers", "inputs"];

/// Parse the text of a flowsheet file named `file` (the name is only used in messages).
pub fn parse_spec(text: &str, file: &str) -> Result<FlowsheetSpec, LoadError> {
    let root: Value = serde_json::from_str(text).map_err(|e| LoadError::Syntax {
        file: file.to_string(),
        line: e.line(),
        column: e.column(),
        reason: strip_position(&e.to_string()),
    })?;
    let mut diags = Vec::new();
    let Some(obj) = root.as_object() else {
        return Err(LoadError::Invalid {
            file: file.into(),
            diagnostics: vec![Diagnostic::new(
                "",
                "the file must hold a JSON object with format_version, components, thermo, units and streams",
            )],
        });
    };
    for key in obj.keys() {
        if !TOP_LEVEL.contains(&key.as_str()) {
            diags.push(Diagnostic::new(
                key.clone(),
                format!(
                    "unknown field{}; the top level has: {}",
                    did_you_mean(key, TOP_LEVEL.iter().copied()),
                    TOP_LEVEL.join(", ")
                ),
            ));
        }
    }
    let format_version: u32 = field(obj, "format_version", &mut diags, true).unwrap_or(FORMAT_VERSION);
    if format_version != FORMAT_VERSION {
        diags.push(Diagnostic::new(
            "format_version",
            format!("this build reads format_version {FORMAT_VERSION}, the file has {format_version}"),
        ));
    }
    let name: String = field(obj, "name", &mut diags, false).unwrap_or_default();
    let description: String = field(obj, "description", &mut diags, false).unwrap_or_default();
    let components = components(obj.get("components"), &mut diags);
    let thermo: Option<ThermoSpec> = field(obj, "thermo", &mut diags, true);
    let units = tagged_map::<UnitSpec>(obj.get("units"), "units", UnitSpec::TYPES, "unit", true, &mut diags);
    let controllers = tagged_map::<ControllerSpec>(
        obj.get("controllers"),
        "controllers",
        ControllerSpec::TYPES,
        "controller",
        false,
        &mut diags,
    );
    let streams = plain_map::<StreamSpec>(obj.get("streams"), "streams", true, &mut diags);
    let inputs = plain_map::<String>(obj.get("inputs"), "inputs", false, &mut diags);
    match thermo {
        Some(thermo) if diags.is_empty() => Ok(FlowsheetSpec {
            format_version,
            name,
            description,
            components,
            thermo,
            units,
            streams,
            controllers,
            inputs,
        }),
        _ => Err(LoadError::Invalid { file: file.into(), diagnostics: diags }),
    }
}

fn strip_position(msg: &str) -> String {
    match msg.rfind(" at line ") {
        Some(i) => msg[..i].to_string(),
        None => msg.to_string(),
    }
}

/// Deserialize `value` reporting the path of the first problem below `base`.
fn typed<T: DeserializeOwned>(value: &Value, base: &str, diags: &mut Vec<Diagnostic>) -> Option<T> {
    match serde_path_to_error::deserialize::<_, T>(value) {
        Ok(v) => Some(v),
        Err(e) => {
            let inner = e.path().to_string();
            let path = if inner == "." || inner.is_empty() { base.to_string() } else { format!("{base}.{inner}") };
            diags.push(Diagnostic::new(path, explain(&e.into_inner().to_string())));
            None
        }
    }
}

/// Reword serde's messages where a user needs more than the raw text.
fn explain(msg: &str) -> String {
    if msg.starts_with("data did not match any variant of untagged enum QuantityValue") {
        return "expected a quantity: a number in SI units or a string with units such as \"1 kmol/min\"".into();
    }
    if let Some(rest) = msg.strip_prefix("missing field ") {
        return format!("missing required field {rest}");
    }
    msg.to_string()
}

fn field<T: DeserializeOwned>(
    obj: &serde_json::Map<String, Value>,
    key: &str,
    diags: &mut Vec<Diagnostic>,
    required: bool,
) -> Option<T> {
    match obj.get(key) {
        Some(v) => typed(v, key, diags),
        None => {
            if required {
                diags.push(Diagnostic::new(key, "missing required field"));
            }
            None
        }
    }
}

fn components(value: Option<&Value>, diags: &mut Vec<Diagnostic>) -> Vec<ComponentSpec> {
    let Some(value) = value else {
        diags.push(Diagnostic::new(
            "components",
            "missing required field: list the components, e.g. [\"benzene\", \"toluene\"]",
        ));
        return Vec::new();
    };
    let Some(items) = value.as_array() else {
        diags.push(Diagnostic::new("components", "must be a list of component names or definitions"));
        return Vec::new();
    };
    let mut out = Vec::new();
    for (i, item) in items.iter().enumerate() {
        let path = format!("components[{i}]");
        let spec = match item {
            Value::String(s) => Some(ComponentSpec::Library(s.clone())),
            Value::Object(o) if o.contains_key("hypothetical") => {
                #[derive(serde::Deserialize)]
                #[serde(deny_unknown_fields)]
                struct Hypo {
                    name: String,
                    hypothetical: crate::spec::HypotheticalSpec,
                }
                typed::<Hypo>(item, &path, diags)
                    .map(|h| ComponentSpec::Hypothetical { name: h.name, hypothetical: h.hypothetical })
            }
            Value::Object(_) => typed(item, &path, diags).map(|c| ComponentSpec::Inline(Box::new(c))),
            _ => {
                diags.push(Diagnostic::new(
                    path,
                    "expected a component name (\"water\") or an object ({\"name\": …, \"hypothetical\": {…}})",
                ));
                None
            }
        };
        out.extend(spec);
    }
    out
}

fn plain_map<T: DeserializeOwned>(
    value: Option<&Value>,
    section: &str,
    required: bool,
    diags: &mut Vec<Diagnostic>,
) -> IndexMap<String, T> {
    let mut out = IndexMap::new();
    match value {
        None if required => diags.push(Diagnostic::new(section, "missing required field")),
        None => {}
        Some(Value::Object(map)) => {
            for (name, v) in map {
                if let Some(t) = typed(v, &format!("{section}.{name}"), diags) {
                    out.insert(name.clone(), t);
                }
            }
        }
        Some(_) => diags.push(Diagnostic::new(section, "must be an object keyed by name")),
    }
    out
}

fn tagged_map<T: DeserializeOwned>(
    value: Option<&Value>,
    section: &str,
    types: &[&str],
    what: &str,
    required: bool,
    diags: &mut Vec<Diagnostic>,
) -> IndexMap<String, T> {
    let mut out = IndexMap::new();
    match value {
        None if required => diags.push(Diagnostic::new(section, "missing required field")),
        None => {}
        Some(Value::Object(map)) => {
            for (name, v) in map {
                let path = format!("{section}.{name}");
                match v.get("type").and_then(Value::as_str) {
                    None => diags.push(Diagnostic::new(
                        format!("{path}.type"),
                        format!("missing {what} type; one of: {}", types.join(", ")),
                    )),
                    Some(t) if !types.contains(&t) => diags.push(Diagnostic::new(
                        format!("{path}.type"),
                        format!(
                            "unknown {what} type `{t}`{}; known types: {}",
                            did_you_mean(t, types.iter().copied()),
                            types.join(", ")
                        ),
                    )),
                    Some(_) => {
                        if let Some(spec) = typed(v, &path, diags) {
                            out.insert(name.clone(), spec);
                        }
                    }
                }
            }
        }
        Some(_) => diags.push(Diagnostic::new(section, "must be an object keyed by name")),
    }
    out
}
