//! Mutations aimed at the defect classes random node choice rarely reaches: huge counts on the
//! fields that size allocations, compositions, stream endpoints, duplicate unit names; scenario
//! timing (events at one time or after the end, huge steps, tiny record intervals and sampling
//! periods, huge durations, event floods); and `--set` overrides that bypass the file loader.

use serde_json::{Value, json};

use super::doc::{Doc, Site, brief};
use super::mutate::{Names, flood_len, mutate, set};
use super::rng::Rng;
use plantwide::flowsheet::Plant;

/// Sites of `doc` whose node satisfies `keep`.
fn sites_where(doc: &Doc, keep: impl Fn(&Site, &Value) -> bool) -> Vec<Site> {
    doc.sites().into_iter().filter(|s| doc.value.pointer(&s.pointer).is_some_and(|v| keep(s, v))).collect()
}

/// A flowsheet mutation aimed at a known defect class; falls back to a random one.
pub fn flowsheet(rng: &mut Rng, doc: &mut Doc, names: &Names) -> String {
    let kind = rng.below(4);
    let candidates = match kind {
        0 => sites_where(doc, |s, v| v.is_number() && ["stages", "stage", "inlets"].contains(&s.key.as_str())),
        1 => sites_where(doc, |s, v| s.key == "z" && v.is_object()),
        2 => sites_where(doc, |_, v| v.get("from").is_some() && v.get("to").is_some()),
        _ => sites_where(doc, |s, v| ["units", "controllers", "streams"].contains(&s.path.as_str()) && v.is_object()),
    };
    if candidates.is_empty() {
        return mutate(rng, doc, names);
    }
    let site = rng.pick(&candidates).clone();
    let old = doc.value.pointer(&site.pointer).cloned().unwrap_or(Value::Null);
    match kind {
        0 => set(
            doc,
            &site,
            &old,
            json!(*rng.pick(&[1_000_000_000u64, 1 << 31, 1 << 63, 1_000_000, 5000])),
            "count_huge",
        ),
        1 => {
            let mut z = old.as_object().cloned().unwrap_or_default();
            let keys: Vec<String> = z.keys().cloned().collect();
            let k = if keys.is_empty() { "nosuch_component".to_string() } else { rng.pick(&keys).clone() };
            z.insert(k, json!(*rng.pick(&[1.5, -0.1, 0.0, 0.3])));
            set(doc, &site, &old, Value::Object(z), "comp_entry")
        }
        2 => {
            let mut s = old.as_object().cloned().unwrap_or_default();
            let (f, t) = (s["from"].clone(), s["to"].clone());
            s.insert("from".into(), t);
            s.insert("to".into(), f);
            set(doc, &site, &old, Value::Object(s), "stream_swap")
        }
        _ => duplicate_member(rng, doc, &site, &old),
    }
}

/// Raw text of `units` (or `controllers`, `streams`) with one member defined twice, the second
/// definition a copy of another member: the first must not be dropped silently.
fn duplicate_member(rng: &mut Rng, doc: &mut Doc, site: &Site, old: &Value) -> String {
    let m = old.as_object().cloned().unwrap_or_default();
    let keys: Vec<&String> = m.keys().collect();
    if keys.is_empty() {
        return set(doc, site, old, json!({"fuzz_unknown": {}}), "key_unknown");
    }
    let (a, b) = (keys[rng.below(keys.len())].clone(), keys[rng.below(keys.len())].clone());
    let mut parts: Vec<String> = m.iter().map(|(k, v)| format!("{}: {v}", json!(k))).collect();
    parts.push(format!("{}: {}", json!(a), m[&b]));
    let marker = doc.raw_marker(format!("{{{}}}", parts.join(", ")));
    if let Some(slot) = doc.value.pointer_mut(&site.pointer) {
        *slot = marker;
    }
    format!("{}: `{a}` defined twice, second as `{b}` [key_duplicate_raw]", site.path)
}

/// A scenario mutation aimed at timing and size limits; falls back to a random one.
pub fn scenario(rng: &mut Rng, doc: &mut Doc, names: &Names) -> String {
    let events = doc.value.get("events").and_then(Value::as_array).cloned().unwrap_or_default();
    let v = &mut doc.value;
    let (path, old, new, class) = match rng.below(8) {
        0 if !events.is_empty() => {
            let at = events[0].get("at").cloned().unwrap_or(json!("0 s"));
            let new: Vec<Value> = events.iter().map(|e| with(e, "at", at.clone())).collect();
            ("events", json!(events), Value::Array(new), "scen_same_time")
        }
        1 if !events.is_empty() => {
            let i = rng.below(events.len());
            let new = with(&events[i], "at", json!(*rng.pick(&["1e9 s", "1e308 s", "-1 s", "NaN s"])));
            return set_path(v, &format!("events[{i}]"), &format!("/events/{i}"), new, "scen_after_end");
        }
        2 if !events.is_empty() => {
            let i = rng.below(events.len());
            let e = &events[i];
            let key = ["to", "by", "amplitude"].into_iter().find(|k| e.get(*k).is_some()).unwrap_or("to");
            let unit = e.get(key).and_then(Value::as_str).and_then(|s| s.split_once(' ')).map_or("mol/s", |p| p.1);
            let big = rng.pick(&["1e200", "1e100", "-1e200", "1e308", "1e-300"]);
            let new = with(e, key, json!(format!("{big} {unit}")));
            return set_path(v, &format!("events[{i}]"), &format!("/events/{i}"), new, "scen_huge_step");
        }
        3 => {
            // An earlier mutation may have made `record` something other than an object.
            let old = v.get("record").cloned().unwrap_or(json!({"paths": []}));
            let mut rec = if old.is_object() { old.clone() } else { json!({"paths": []}) };
            rec["interval"] = json!(*rng.pick(&["1e-6 s", "0 s", "-5 s", "1e-300 s", "1e-3 s"]));
            ("record", old, rec, "scen_tiny_record")
        }
        4 => {
            let ctrl = rng.pick(&names.all).clone();
            let old = v.get("sampling").cloned().unwrap_or(json!({}));
            let mut s = old.as_object().cloned().unwrap_or_default();
            let k = s.keys().next().cloned().unwrap_or(ctrl);
            s.insert(k, json!(*rng.pick(&["1e-9 s", "0 s", "-2 s", "1e-4 s"])));
            ("sampling", old, Value::Object(s), "scen_tiny_sampling")
        }
        5 => {
            let old = v.get("duration").cloned().unwrap_or(Value::Null);
            (
                "duration",
                old,
                json!(*rng.pick(&["1e12 s", "1e308 s", "0 s", "-1 min", "1e-300 s"])),
                "scen_huge_duration",
            )
        }
        6 if !events.is_empty() => {
            let n = flood_len(&events, *rng.pick(&[1000, 100_000]));
            let new: Vec<Value> = events.iter().cycle().take(n).cloned().collect();
            ("events", json!(events), Value::Array(new), "scen_event_flood")
        }
        7 => {
            let old = v.get("integrator").cloned().unwrap_or(json!({}));
            let mut i = old.as_object().cloned().unwrap_or_default();
            let key = *rng.pick(&["rtol", "atol"]);
            i.insert(key.into(), json!(*rng.pick(&[1e-300, 0.0, 1.0, -1.0, 1e300])));
            ("integrator", old, Value::Object(i), "scen_tolerance")
        }
        _ => return mutate(rng, doc, names),
    };
    let line = format!("{path}: {} -> {} [{class}]", brief(&old), brief(&new));
    v[path] = new;
    line
}

/// A copy of object `e` with `key` set to `value`.
fn with(e: &Value, key: &str, value: Value) -> Value {
    let mut e = e.clone();
    if let Some(o) = e.as_object_mut() {
        o.insert(key.to_string(), value);
    }
    e
}

fn set_path(v: &mut Value, path: &str, pointer: &str, new: Value, class: &str) -> String {
    let old = v.pointer(pointer).cloned().unwrap_or(Value::Null);
    let line = format!("{path}: {} -> {} [{class}]", brief(&old), brief(&new));
    if let Some(slot) = v.pointer_mut(pointer) {
        *slot = new;
    }
    line
}

/// Values for `--set` of an input: negative, zero, huge, tiny, NaN, fractions off 1, wrong units.
const SET_VALUES: &[&str] = &["-1", "0", "1e308", "1e-300", "NaN", "1.5", "-0.1", "1e9", "inf", "1e200"];

/// A `--set PATH=VALUE` assignment: a free input with a bad value in its own unit (or a wrong
/// one), a unit field set to a mutated value, or a malformed path.
pub fn assignment(rng: &mut Rng, plant: &Plant, spec: &Value, names: &Names) -> (String, String) {
    let free: Vec<_> = plant.inputs().iter().filter(|i| i.driven_by.is_none()).collect();
    match rng.below(5) {
        0..=1 if !free.is_empty() => {
            let inp = rng.pick(&free);
            let units: Vec<&str> = names.units.iter().filter(|(_, d)| *d == inp.dim).map(|(u, _)| *u).collect();
            let unit = if units.is_empty() || rng.chance(0.1) { "furlong" } else { rng.pick(&units) };
            (format!("{}={} {unit}", inp.path, rng.pick(SET_VALUES)), "set_input".into())
        }
        2..=3 => {
            let doc = Doc::new(spec.clone());
            let fields = sites_where(&doc, |s, _| s.path.matches('.').count() == 2 && !s.path.starts_with("streams"));
            if fields.is_empty() {
                return ("nosuch.F=1 mol/s".into(), "set_unknown".into());
            }
            let site = rng.pick(&fields);
            let (_, field) = site.path.split_once('.').unwrap_or_default();
            let old = doc.value.pointer(&site.pointer).cloned().unwrap_or(Value::Null);
            let mut sub = Doc::new(json!({ "v": old }));
            let line = mutate(rng, &mut sub, names);
            let value = match sub.value.get("v") {
                Some(Value::String(s)) if sub.raw.is_empty() => s.clone(),
                Some(v) if sub.raw.is_empty() => v.to_string(),
                _ => sub.render(),
            };
            (format!("{field}={value}"), format!("set_field ({line})"))
        }
        _ => {
            let bad = ["nosuch.F=1 mol/s", "F", "=1", "column.=3", "a.b.c=1", "feed_source.F=", "x=1e400 mol/s"];
            (rng.pick(&bad).to_string(), "set_unknown".into())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fuzz::mutate::FLOOD_BYTES;

    /// An event flood of events an earlier mutation made long stays within the flood budget: the
    /// mutant of seed 0xcc87ee2a81025caf (campaign 20261210, mutant 14 961) flooded an event
    /// holding a 100 kB string 100 000 times, 10 GB, and the harness crossed its 2 GiB limit.
    #[test]
    fn an_event_flood_of_long_events_stays_within_the_budget() {
        let value = json!({"events": [{"type": "step".repeat(25_000), "at": "0 s"}]});
        let names = Names::of(&value);
        let flooded = (0..256u64)
            .find_map(|seed| {
                let mut doc = Doc::new(value.clone());
                scenario(&mut Rng::new(seed), &mut doc, &names).contains("scen_event_flood").then_some(doc)
            })
            .expect("one of the seeds floods the events");
        let text = flooded.render();
        assert!(text.len() <= FLOOD_BYTES + (1 << 20), "{} bytes", text.len());
        assert!(text.len() >= FLOOD_BYTES / 2, "{} bytes: the budget is used", text.len());
    }
}
