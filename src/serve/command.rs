//! The body of `POST /api/command`: one JSON object with one key.
//!
//! `{"set": {path: "value unit"}}`, `{"speed": k}`, `{"pause": true}`, `{"resume": true}`,
//! `{"mode": {ctrl: "auto"|"manual"}}`, `{"snapshot": name}`, `{"load": name}`, and
//! `{"step": true}` (one integrator step), `{"event": {scenario event without "at"}}` (a
//! disturbance or failure from the scenario vocabulary). Shape errors are reported here; what
//! the plant makes of a path, unit or value is the library's to say.

use plantwide::flowsheet::parse::walk_diagnostics;
use plantwide::flowsheet::scenario::EventSpec;
use plantwide::model::controllers::Mode;
use serde_json::Value;

use super::sim::Command;

/// The keys a command may have.
const KEYS: &str = "set, speed, pause, resume, step, mode, event, snapshot, load";

/// Why a command body is refused (the message of an HTTP 400).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CommandError {
    /// Not JSON, or not UTF-8.
    #[error("malformed JSON: {0}")]
    Malformed(String),
    /// Keys given twice in one object, overlong strings: each `` `path`: message ``.
    #[error("{0}")]
    Text(String),
    /// Not an object.
    #[error("give one JSON object with one of the keys {KEYS}")]
    NotAnObject,
    /// Not exactly one key.
    #[error("give exactly one of the keys {KEYS}")]
    NotOneKey,
    /// A key that is no command.
    #[error("unknown command `{0}`; give one of {KEYS}")]
    Unknown(String),
    /// A command's value of the wrong shape.
    #[error("{key}: {why}")]
    Value {
        /// The command's key (`set`, `speed`) or the member of it (`set.feed.F`, ``mode of `lc` ``).
        key: String,
        /// What is wrong and what to give.
        why: String,
    },
}

fn bad(key: impl Into<String>, why: impl Into<String>) -> CommandError {
    CommandError::Value { key: key.into(), why: why.into() }
}

/// Parse a command body.
///
/// # Errors
/// The message for HTTP 400: malformed JSON, a key given twice in one object (JSON readers keep
/// one of them silently), not one key, an unknown key, a value of the wrong type.
pub fn parse_command(body: &[u8]) -> Result<Command, CommandError> {
    let v: Value = serde_json::from_slice(body).map_err(|e| CommandError::Malformed(e.to_string()))?;
    let text = std::str::from_utf8(body).map_err(|e| CommandError::Malformed(e.to_string()))?;
    let found = walk_diagnostics(text);
    if !found.is_empty() {
        let each = found.iter().map(|d| format!("`{}`: {}", d.path, d.message));
        return Err(CommandError::Text(each.collect::<Vec<_>>().join("; ")));
    }
    let Value::Object(map) = v else { return Err(CommandError::NotAnObject) };
    let mut it = map.into_iter();
    let (Some((key, value)), None) = (it.next(), it.next()) else {
        return Err(CommandError::NotOneKey);
    };
    match key.as_str() {
        "set" => Ok(Command::Set(pairs(&key, value)?)),
        "mode" => {
            let modes = pairs(&key, value)?
                .into_iter()
                .map(|(c, m)| match m.as_str() {
                    "auto" => Ok((c, Mode::Auto)),
                    "manual" => Ok((c, Mode::Manual)),
                    other => Err(bad(
                        format!("mode of `{c}`"),
                        format!("`{other}` is not a mode; give \"auto\" or \"manual\""),
                    )),
                })
                .collect::<Result<Vec<_>, _>>()?;
            Ok(Command::Mode(modes))
        }
        "speed" => value.as_f64().map(Command::Speed).ok_or_else(|| bad(&key, "give a number, e.g. {\"speed\": 60}")),
        "pause" => yes(&key, &value).map(|()| Command::Pause),
        "resume" => yes(&key, &value).map(|()| Command::Resume),
        "step" => yes(&key, &value).map(|()| Command::Step),
        "snapshot" => name(&key, value).map(Command::Snapshot),
        "load" => name(&key, value).map(Command::Load),
        "event" => event(value).map(|e| Command::Event(Box::new(e))),
        other => Err(CommandError::Unknown(other.to_string())),
    }
}

/// A non-empty object of strings, in order.
fn pairs(key: &str, value: Value) -> Result<Vec<(String, String)>, CommandError> {
    let Value::Object(map) = value else {
        return Err(bad(key, format!("give an object, e.g. {{\"{key}\": {{\"feed_source.F\": \"1.01 kmol/min\"}}}}")));
    };
    if map.is_empty() {
        return Err(bad(key, "the object is empty"));
    }
    map.into_iter()
        .map(|(k, v)| match v {
            Value::String(s) => Ok((k, s)),
            other => Err(bad(format!("{key}.{k}"), format!("give a string (\"value unit\" or a mode), not {other}"))),
        })
        .collect()
}

fn yes(key: &str, value: &Value) -> Result<(), CommandError> {
    if value == &Value::Bool(true) { Ok(()) } else { Err(bad(key, "give true")) }
}

fn name(key: &str, value: Value) -> Result<String, CommandError> {
    match value {
        Value::String(s) => Ok(s),
        other => Err(bad(key, format!("give a name (a string), not {other}"))),
    }
}

/// A scenario event; its `at` (the sync point's time replaces it) may be left out.
fn event(value: Value) -> Result<EventSpec, CommandError> {
    let Value::Object(mut map) = value else {
        return Err(bad("event", "give a scenario event object, e.g. {\"type\": \"feed_lost\", \"unit\": \"feed\"}"));
    };
    map.entry("at").or_insert(Value::from(0.0));
    serde_json::from_value(Value::Object(map)).map_err(|e| bad("event", e.to_string()))
}
