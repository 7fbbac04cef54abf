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

/// One field to set or remove: its path of object keys (`["controllers", "tc1", "kc"]`) and the
/// JSON text of its new value (`"\"2.5 kmol/h/K\""`), or `None` to remove the member.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldEdit {
    /// Object keys from the top.
    pub path: Vec<String>,
    /// The new value as JSON text; `None` removes the member (nothing happens if it is absent).
    pub value: Option<String>,
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
        let members = members(&text[span.0..span.1]).map_err(|e| fail(format!("not an object ({e})")))?;
        let raw = members.get(key.as_str()).ok_or_else(|| fail(format!("no member `{key}`")))?;
        span = offset_of(text, raw);
    }
    let object = &text[span.0..span.1];
    let members = members(object).map_err(|e| fail(format!("not an object ({e})")))?;
    let Some(value) = &e.value else {
        return Ok(match members.get(last.as_str()) {
            Some(raw) => remove_member(text, span.0, offset_of(text, raw)),
            None => text.to_string(),
        });
    };
    if let Some(raw) = members.get(last.as_str()) {
        let (a, b) = offset_of(text, raw);
        return Ok(format!("{}{value}{}", &text[..a], &text[b..]));
    }
    let close = span.0 + object.rfind('}').ok_or_else(|| fail("not an object".into()))?;
    let indent = member_indent(object);
    let body_end = text[..close].trim_end().len();
    let comma = if members.is_empty() { "" } else { "," };
    let closing_indent = &text[text[..close].rfind('\n').map_or(close, |n| n + 1)..close];
    let closing_indent = if closing_indent.trim().is_empty() { closing_indent } else { "" };
    Ok(format!("{}{comma}\n{indent}\"{last}\": {value}\n{closing_indent}{}", &text[..body_end], &text[close..]))
}

/// `text` without the member whose value spans `value` inside the object starting at `object`:
/// from its key (and the whitespace before it) through its value, with the comma that separated
/// it from the member before it — or, for the first member, from the one after it.
fn remove_member(text: &str, object: usize, (a, b): (usize, usize)) -> String {
    let before = &text[object..a];
    let colon = object + before.rfind(':').unwrap_or(0);
    let key = object + text[object..colon].rfind('"').and_then(|q| text[object..object + q].rfind('"')).unwrap_or(0);
    let prev = text[object..key].trim_end();
    if let Some(stripped) = prev.strip_suffix(',') {
        let cut = object + stripped.len();
        return format!("{}{}", &text[..cut], &text[b..]);
    }
    // The first member: drop it, its trailing comma and the whitespace up to the next key.
    let rest = text[b..].trim_start();
    let rest = rest.strip_prefix(',').map_or(&text[b..], |r| r.trim_start());
    let start = object + prev.len();
    let gap = &text[start..key];
    format!("{}{gap}{rest}", &text[..start])
}

/// The members of the JSON object `text`, each value's raw text borrowed from it.
fn members(text: &str) -> serde_json::Result<BTreeMap<&str, &RawValue>> {
    serde_json::from_str(text)
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
        FieldEdit { path: path.iter().map(|s| s.to_string()).collect(), value: Some(value.to_string()) }
    }

    fn removal(path: &[&str]) -> FieldEdit {
        FieldEdit { path: path.iter().map(|s| s.to_string()).collect(), value: None }
    }

    #[test]
    fn removed_members_take_their_comma_with_them() {
        let out = edit_fields(FILE, "f.json", &[removal(&["controllers", "tc", "tau_i"])]).unwrap();
        assert_eq!(out, FILE.replace(",   \"tau_i\": 600", ""));
        let out = edit_fields(FILE, "f.json", &[removal(&["controllers", "lc", "type"])]).unwrap();
        assert_eq!(out, FILE.replace("\"type\": \"pid\",\n      \"kc\": 10", "\"kc\": 10"), "{out}");
        let out = edit_fields(FILE, "f.json", &[removal(&["controllers", "lc", "kc"])]).unwrap();
        assert_eq!(out, FILE.replace(",\n      \"kc\": 10", ""), "{out}");
        assert_eq!(edit_fields(FILE, "f.json", &[removal(&["controllers", "lc", "tau_d"])]).unwrap(), FILE);
        serde_json::from_str::<serde_json::Value>(&out).unwrap();
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
