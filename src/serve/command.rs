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

/// Parse a command body.
///
/// # Errors
/// The message for HTTP 400: malformed JSON, a key given twice in one object (JSON readers keep
/// one of them silently), not one key, an unknown key, a value of the wrong type.
pub fn parse_command(body: &[u8]) -> Result<Command, String> {
    let v: Value = serde_json::from_slice(body).map_err(|e| format!("malformed JSON: {e}"))?;
    let text = std::str::from_utf8(body).map_err(|e| format!("malformed JSON: {e}"))?;
    let found = walk_diagnostics(text);
    if !found.is_empty() {
        let each = found.iter().map(|d| format!("`{}`: {}", d.path, d.message));
        return Err(each.collect::<Vec<_>>().join("; "));
    }
    let Value::Object(map) = v else { return Err(format!("give one JSON object with one of the keys {KEYS}")) };
    let mut it = map.into_iter();
    let (Some((key, value)), None) = (it.next(), it.next()) else {
        return Err(format!("give exactly one of the keys {KEYS}"));
    };
    match key.as_str() {
        "set" => Ok(Command::Set(pairs(&key, value)?)),
        "mode" => {
            let modes = pairs(&key, value)?
                .into_iter()
                .map(|(c, m)| match m.as_str() {
                    "auto" => Ok((c, Mode::Auto)),
                    "manual" => Ok((c, Mode::Manual)),
                    other => Err(format!("mode of `{c}`: `{other}` is not a mode; give \"auto\" or \"manual\"")),
                })
                .collect::<Result<Vec<_>, _>>()?;
            Ok(Command::Mode(modes))
        }
        "speed" => {
            value.as_f64().map(Command::Speed).ok_or_else(|| "speed: give a number, e.g. {\"speed\": 60}".into())
        }
        "pause" => yes(&key, &value).map(|()| Command::Pause),
        "resume" => yes(&key, &value).map(|()| Command::Resume),
        "step" => yes(&key, &value).map(|()| Command::Step),
        "snapshot" => name(&key, value).map(Command::Snapshot),
        "load" => name(&key, value).map(Command::Load),
        "event" => event(value).map(|e| Command::Event(Box::new(e))),
        other => Err(format!("unknown command `{other}`; give one of {KEYS}")),
    }
}

/// A non-empty object of strings, in order.
fn pairs(key: &str, value: Value) -> Result<Vec<(String, String)>, String> {
    let Value::Object(map) = value else {
        return Err(format!("{key}: give an object, e.g. {{\"{key}\": {{\"feed_source.F\": \"1.01 kmol/min\"}}}}"));
    };
    if map.is_empty() {
        return Err(format!("{key}: the object is empty"));
    }
    map.into_iter()
        .map(|(k, v)| match v {
            Value::String(s) => Ok((k, s)),
            other => Err(format!("{key}.{k}: give a string (\"value unit\" or a mode), not {other}")),
        })
        .collect()
}

fn yes(key: &str, value: &Value) -> Result<(), String> {
    if value == &Value::Bool(true) { Ok(()) } else { Err(format!("{key}: give true")) }
}

fn name(key: &str, value: Value) -> Result<String, String> {
    match value {
        Value::String(s) => Ok(s),
        other => Err(format!("{key}: give a name (a string), not {other}")),
    }
}

/// A scenario event; its `at` (the sync point's time replaces it) may be left out.
fn event(value: Value) -> Result<EventSpec, String> {
    let Value::Object(mut map) = value else {
        return Err("event: give a scenario event object, e.g. {\"type\": \"feed_lost\", \"unit\": \"feed\"}".into());
    };
    map.entry("at").or_insert(Value::from(0.0));
    serde_json::from_value(Value::Object(map)).map_err(|e| format!("event: {e}"))
}
