//! Reading a flowsheet file into a [`FlowsheetSpec`], section by section so that every structural
//! problem is reported at once with its JSON path.

use std::collections::HashSet;
use std::path::Path;

use indexmap::IndexMap;
use plantwide_model::limits::{Limits, clip};
use plantwide_model::{ControllerSpec, UnitSpec};
use plantwide_units::QuantityValue;
use serde::de::{DeserializeOwned, DeserializeSeed, MapAccess, SeqAccess, Visitor};
use serde_json::Value;

use crate::error::{Diagnostic, LoadError, did_you_mean};
use crate::spec::{ComponentSpec, FORMAT_VERSION, FlowsheetSpec, StreamSpec, ThermoSpec};

const TOP_LEVEL: &[&str] = &[
    "format_version",
    "name",
    "description",
    "components",
    "thermo",
    "units",
    "streams",
    "controllers",
    "inputs",
    "specs",
    "parameters",
    "tags",
    "optimization",
];

/// Read a file the engine is given (flowsheet, scenario, model, matrices) as text: at most
/// [`Limits::max_file_bytes`] bytes, valid UTF-8 (an invalid byte is reported with its offset,
/// line and column).
///
/// The limit holds for what is read, not for what the file system says: `/dev/zero`, a pipe or a
/// file still growing report a length of 0 and would otherwise be read without end. One byte past
/// the limit is read at most.
pub fn read_text(path: &Path) -> Result<String, LoadError> {
    use std::io::Read;
    let file = path.display().to_string();
    let io = |e: std::io::Error| LoadError::Io { file: file.clone(), reason: e.to_string() };
    let limit = Limits::get().file_bytes();
    let len = std::fs::metadata(path).map_err(io)?.len();
    if let Some(msg) = limit.check(usize::try_from(len).unwrap_or(usize::MAX), "the file size in bytes") {
        return Err(LoadError::Io { file, reason: msg });
    }
    let mut bytes = Vec::new();
    let cap = u64::try_from(limit.max).unwrap_or(u64::MAX).saturating_add(1);
    std::fs::File::open(path).map_err(io)?.take(cap).read_to_end(&mut bytes).map_err(io)?;
    if bytes.len() > limit.max {
        let reason = format!(
            "more than {} bytes and still going (the size it reports: {len}); the limit is set by the environment \
             variable {}",
            limit.max, limit.var
        );
        return Err(LoadError::Io { file, reason });
    }
    String::from_utf8(bytes).map_err(|e| {
        let offset = e.utf8_error().valid_up_to();
        let good = &e.as_bytes()[..offset];
        let line = good.iter().filter(|&&b| b == b'\n').count() + 1;
        let line_start = good.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        let column = String::from_utf8_lossy(&good[line_start..]).chars().count() + 1;
        LoadError::Encoding { file, offset, line, column, byte: e.as_bytes()[offset] }
    })
}

/// Parse the text of a flowsheet file named `file` (the name is only used in messages).
pub fn parse_spec(text: &str, file: &str) -> Result<FlowsheetSpec, LoadError> {
    let root: Value = serde_json::from_str(text).map_err(|e| LoadError::Syntax {
        file: file.to_string(),
        line: e.line(),
        column: e.column(),
        reason: strip_position(&e.to_string()),
    })?;
    let mut diags = walk_diagnostics(text);
    if !diags.is_empty() {
        // A duplicate key or an overlong string: what serde would say next would quote them.
        return Err(LoadError::Invalid { file: file.into(), diagnostics: diags });
    }
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
    let units =
        tagged_map(obj.get("units"), "units", (UnitSpec::TYPES, UnitSpec::from_tagged), "unit", true, &mut diags);
    let controllers = tagged_map(
        obj.get("controllers"),
        "controllers",
        (ControllerSpec::TYPES, ControllerSpec::from_tagged),
        "controller",
        false,
        &mut diags,
    );
    let parameters = plain_map::<QuantityValue>(obj.get("parameters"), "parameters", false, &mut diags);
    let tags = plain_map::<crate::spec::TagSpec>(obj.get("tags"), "tags", false, &mut diags);
    let n_blocks = units.len() + controllers.len() + tags.len();
    if let Some(msg) = Limits::get().units().check(n_blocks, "the number of units, controllers and tags") {
        diags.push(Diagnostic::new("units", msg));
    }
    let streams = plain_map::<StreamSpec>(obj.get("streams"), "streams", true, &mut diags);
    let inputs = plain_map::<String>(obj.get("inputs"), "inputs", false, &mut diags);
    let specs: Vec<crate::design::SpecEntry> = field(obj, "specs", &mut diags, false).unwrap_or_default();
    let optimization: Option<crate::optimization::OptimizationSpec> = field(obj, "optimization", &mut diags, false);
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
            specs,
            parameters,
            tags,
            optimization,
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
    for int in ["usize", "u32", "u64", "u8"] {
        if let Some(head) = msg.strip_suffix(&format!("expected {int}")) {
            return format!("{head}expected a whole number ≥ 0");
        }
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

/// The type names of a registry and its deserializer of one tagged description.
type Registry<T> = (&'static [&'static str], fn(&str, &Value) -> Result<T, plantwide_model::SpecError>);

fn tagged_map<T>(
    value: Option<&Value>,
    section: &str,
    (types, from_tagged): Registry<T>,
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
                            "unknown {what} type `{}`{}; known types: {}",
                            clip(t),
                            did_you_mean(t, types.iter().copied()),
                            types.join(", ")
                        ),
                    )),
                    Some(t) => match from_tagged(t, v) {
                        Ok(spec) => {
                            out.insert(name.clone(), spec);
                        }
                        Err(plantwide_model::SpecError { path: inner, message: msg }) => {
                            let path = if inner.is_empty() { path } else { format!("{path}.{inner}") };
                            diags.push(Diagnostic::new(path, explain(&msg)));
                        }
                    },
                }
            }
        }
        Some(_) => diags.push(Diagnostic::new(section, "must be an object keyed by name")),
    }
    out
}

/// Problems only the raw text shows (at most 20): keys that appear twice in one object —
/// serde_json, like most JSON readers, silently keeps one of them, which would drop a whole unit
/// definition unseen — and strings or keys longer than [`Limits::max_string_len`], which no field
/// needs and which would make every message and search that quotes them slow.
pub fn walk_diagnostics(text: &str) -> Vec<Diagnostic> {
    let mut found = Vec::new();
    let mut de = serde_json::Deserializer::from_str(text);
    // The text already parsed as JSON; a failure here only ends the search early.
    let _ = Walk { path: String::new(), found: &mut found }.deserialize(&mut de);
    found
}

/// A walk over a JSON document that records duplicate keys and overlong strings with their paths.
struct Walk<'a> {
    path: String,
    found: &'a mut Vec<Diagnostic>,
}

impl Walk<'_> {
    fn long(&mut self, s: &str) {
        let limit = Limits::get().string_len();
        if let Some(msg) = limit.check(s.chars().count(), "the length of this string")
            && self.found.len() < 20
        {
            self.found.push(Diagnostic::new(clip(&self.path), format!("`{}`: {msg}", clip(s))));
        }
    }
}

impl<'de> DeserializeSeed<'de> for Walk<'_> {
    type Value = ();
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for Walk<'_> {
    type Value = ();
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("any JSON value")
    }
    fn visit_bool<E>(self, _: bool) -> Result<(), E> {
        Ok(())
    }
    fn visit_i64<E>(self, _: i64) -> Result<(), E> {
        Ok(())
    }
    fn visit_u64<E>(self, _: u64) -> Result<(), E> {
        Ok(())
    }
    fn visit_f64<E>(self, _: f64) -> Result<(), E> {
        Ok(())
    }
    fn visit_str<E>(mut self, v: &str) -> Result<(), E> {
        self.long(v);
        Ok(())
    }
    fn visit_unit<E>(self) -> Result<(), E> {
        Ok(())
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let Walk { path, found } = self;
        let mut i = 0;
        while seq.next_element_seed(Walk { path: format!("{path}[{i}]"), found: &mut *found })?.is_some() {
            i += 1;
        }
        Ok(())
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        let Walk { path, found } = self;
        let mut seen = HashSet::new();
        while let Some(key) = map.next_key::<String>()? {
            let child = if path.is_empty() { key.clone() } else { format!("{path}.{}", clip(&key)) };
            Walk { path: child.clone(), found: &mut *found }.long(&key);
            if !seen.insert(key) && found.len() < 20 {
                found.push(Diagnostic::new(
                    child.clone(),
                    "this key appears twice in the same object (JSON readers keep only one): remove or rename one",
                ));
            }
            map.next_value_seed(Walk { path: child, found: &mut *found })?;
        }
        Ok(())
    }
}
