//! Edits of a flowsheet file's text that change only the fields asked for: every other byte —
//! order, spacing, comments-free formatting, number spelling — stays as written (what
//! `plantwide tune --write` needs: a reviewer's diff shows the new settings and nothing else).
//!
//! The fields are located with `serde_json::value::RawValue`, which borrows each value's exact
//! text from the input, so its byte span is found without a second parser.

use serde_json::value::RawValue;
use std::collections::BTreeMap;

/// Why a field could not be edited.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EditError {
    /// The text is not JSON, or the path leads through something that is not an object.
    #[error("{file}: cannot edit `{path}`: {why}")]
    Path {
        /// Flowsheet file.
        file: String,
        /// The dotted path.
        path: String,
        /// What is wrong.
        why: String,
    },
}

/// One field to set: its path of object keys (`["controllers", "tc1", "kc"]`) and the JSON text
/// of its new value (`"\"2.5 kmol/h/K\""`).
#[derive(Debug, Clone, PartialEq)]
pub struct FieldEdit {
    /// Object keys from the top.
    pub path: Vec<String>,
    /// The new value as JSON text.
    pub value: String,
}

/// `text` with each edit applied: a field present is replaced in place; an absent field is added
/// as the last member of its object, on a line of its own indented like the object's members.
///
/// # Errors
/// [`EditError::Path`] when the text is not JSON or a path does not lead to an object.
pub fn edit_fields(text: &str, file: &str, edits: &[FieldEdit]) -> Result<String, EditError> {
    let mut out = text.to_string();
    for e in edits {
        out = edit_one(&out, file, e)?;
    }
    Ok(out)
}

fn edit_one(text: &str, file: &str, e: &FieldEdit) -> Result<String, EditError> {
    let fail = |why: String| EditError::Path { file: file.to_string(), path: e.path.join("."), why };
    let (last, parents) = e.path.split_last().ok_or_else(|| fail("empty path".into()))?;
    let mut span = (0, text.len());
    for key in parents {
        let members = members(&text[span.0..span.1]).map_err(&fail)?;
        let raw = members.get(key.as_str()).ok_or_else(|| fail(format!("no member `{key}`")))?;
        span = offset_of(text, raw);
    }
    let object = &text[span.0..span.1];
    let members = members(object).map_err(&fail)?;
    if let Some(raw) = members.get(last.as_str()) {
        let (a, b) = offset_of(text, raw);
        return Ok(format!("{}{}{}", &text[..a], e.value, &text[b..]));
    }
    let close = span.0 + object.rfind('}').ok_or_else(|| fail("not an object".into()))?;
    let indent = member_indent(object);
    let body_end = text[..close].trim_end().len();
    let comma = if members.is_empty() { "" } else { "," };
    let closing_indent = &text[text[..close].rfind('\n').map_or(close, |n| n + 1)..close];
    let closing_indent = if closing_indent.trim().is_empty() { closing_indent } else { "" };
    Ok(format!("{}{comma}\n{indent}\"{last}\": {}\n{closing_indent}{}", &text[..body_end], e.value, &text[close..]))
}

/// The members of the JSON object `text`, each value's raw text borrowed from it.
fn members(text: &str) -> Result<BTreeMap<&str, &RawValue>, String> {
    serde_json::from_str(text).map_err(|e| format!("not an object ({e})"))
}

/// Byte span of `raw` inside `text` (it borrows from it).
fn offset_of(text: &str, raw: &RawValue) -> (usize, usize) {
    let a = raw.get().as_ptr() as usize - text.as_ptr() as usize;
    (a, a + raw.get().len())
}

/// The indentation of the first member line of an object's text (four spaces if it is on one line).
fn member_indent(object: &str) -> String {
    object
        .lines()
        .skip(1)
        .find(|l| l.trim_start().starts_with('"'))
        .map(|l| l[..l.len() - l.trim_start().len()].to_string())
        .unwrap_or_else(|| "    ".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILE: &str = r#"{
  "name": "x",
  "controllers": {
    "tc": {"type": "pid", "kc": "2 kmol/h/K",   "tau_i": 600},
    "lc": {
      "type": "pid",
      "kc": 10
    }
  }
}
"#;

    fn edit(path: &[&str], value: &str) -> FieldEdit {
        FieldEdit { path: path.iter().map(|s| s.to_string()).collect(), value: value.to_string() }
    }

    #[test]
    fn present_fields_change_in_place_and_nothing_else() {
        let out = edit_fields(
            FILE,
            "f.json",
            &[edit(&["controllers", "tc", "kc"], "\"3.5 kmol/h/K\""), edit(&["controllers", "tc", "tau_i"], "720")],
        )
        .unwrap();
        assert_eq!(out, FILE.replace("\"2 kmol/h/K\"", "\"3.5 kmol/h/K\"").replace("600", "720"));
    }

    #[test]
    fn an_absent_field_is_added_as_the_last_member() {
        let out = edit_fields(FILE, "f.json", &[edit(&["controllers", "lc", "tau_i"], "\"20 min\"")]).unwrap();
        assert!(out.contains("\"kc\": 10,\n      \"tau_i\": \"20 min\"\n    }"), "{out}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert_eq!(v["controllers"]["lc"]["tau_i"], "20 min");
        assert_eq!(v["controllers"]["tc"]["kc"], "2 kmol/h/K");
    }

    #[test]
    fn a_missing_object_is_named() {
        let err = edit_fields(FILE, "f.json", &[edit(&["controllers", "pc", "kc"], "1")]).unwrap_err();
        assert!(err.to_string().contains("controllers.pc.kc") && err.to_string().contains("no member `pc`"), "{err}");
    }
}
