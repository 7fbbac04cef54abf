//! A JSON document under mutation: the parsed value, raw-text pieces spliced in at render time
//! (for what a `serde_json::Value` cannot hold: duplicate keys, out-of-range literals), and the
//! sites (every node with its JSON pointer, readable path and key).

use serde_json::Value;

/// One node of a document.
#[derive(Debug, Clone)]
pub struct Site {
    /// JSON pointer (RFC 6901).
    pub pointer: String,
    /// Readable path (`units.column.stages`, `events[0].at`).
    pub path: String,
    /// The object key it sits under (the array's key for array elements; empty at the root).
    pub key: String,
}

/// A document being mutated.
#[derive(Debug, Clone)]
pub struct Doc {
    /// The value.
    pub value: Value,
    /// Raw JSON text for the markers `"@@fuzz-raw-<i>@@"` in the value.
    pub raw: Vec<String>,
    /// Text to put after (`Some`) or in place of a truncated end of the rendered document.
    pub tail: Option<Tail>,
}

/// A whole-text mutation applied after rendering.
#[derive(Debug, Clone)]
pub enum Tail {
    /// Keep only the first fraction of the text.
    Truncate(f64),
    /// Append this text.
    Append(String),
}

impl Doc {
    /// A document holding `value`.
    pub fn new(value: Value) -> Doc {
        Doc { value, raw: Vec::new(), tail: None }
    }

    /// A marker value that renders as the raw JSON `text`.
    pub fn raw_marker(&mut self, text: String) -> Value {
        self.raw.push(text);
        Value::String(format!("@@fuzz-raw-{}@@", self.raw.len() - 1))
    }

    /// The document as JSON text.
    pub fn render(&self) -> String {
        let mut text = serde_json::to_string_pretty(&self.value).expect("a Value always serializes");
        for (i, raw) in self.raw.iter().enumerate() {
            text = text.replacen(&format!("\"@@fuzz-raw-{i}@@\""), raw, 1);
        }
        match &self.tail {
            None => text,
            Some(Tail::Truncate(f)) => {
                let mut cut = (text.len() as f64 * f) as usize;
                while !text.is_char_boundary(cut) {
                    cut -= 1;
                }
                text[..cut].to_string()
            }
            Some(Tail::Append(s)) => text + s,
        }
    }

    /// Every node below the root.
    pub fn sites(&self) -> Vec<Site> {
        let mut out = Vec::new();
        walk(&self.value, "", "", "", &mut out);
        out
    }
}

fn walk(v: &Value, pointer: &str, path: &str, key: &str, out: &mut Vec<Site>) {
    if !pointer.is_empty() {
        out.push(Site { pointer: pointer.to_string(), path: path.to_string(), key: key.to_string() });
    }
    match v {
        Value::Object(m) => {
            for (k, child) in m {
                let p = format!("{pointer}/{}", k.replace('~', "~0").replace('/', "~1"));
                let readable = if path.is_empty() { k.clone() } else { format!("{path}.{k}") };
                walk(child, &p, &readable, k, out);
            }
        }
        Value::Array(a) => {
            for (i, child) in a.iter().enumerate() {
                walk(child, &format!("{pointer}/{i}"), &format!("{path}[{i}]"), key, out);
            }
        }
        _ => {}
    }
}

/// A short rendering of a value for descriptions (long strings are cut).
pub fn brief(v: &Value) -> String {
    let s = v.to_string();
    if s.chars().count() > 60 {
        format!("{}… ({} chars)", s.chars().take(40).collect::<String>(), s.len())
    } else {
        s
    }
}
