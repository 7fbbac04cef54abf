//! Structure-aware mutations of a flowsheet or scenario document. Every mutation returns a line
//! `path: before -> after [class]`; the class names are what `PLANTWIDE_FUZZ_SKIP` matches.

use serde_json::{Map, Value, json};

use super::doc::{Doc, Site, Tail, brief};
use super::rng::Rng;
use plantwide::units::{Dimension, unit_dimension};

/// Keys whose values are counts or indices (integers the builders allocate by).
const COUNT_KEYS: &[&str] = &["stages", "stage", "inlets", "outlets", "order", "format_version"];
/// Counts that overflow, exhaust memory, or take very long to build.
const HUGE_COUNTS: &[u64] = &[1_000_000_000, 1 << 31, 1 << 63, 1_000_000, 5000, 100_000, 0, u64::MAX];
/// Units tried as replacements; their dimensions are looked up once.
const UNITS: &[&str] = &[
    "mol/s",
    "kmol/h",
    "kmol/min",
    "lbmol/h",
    "kg/s",
    "kg/h",
    "mol",
    "kmol",
    "kg",
    "K",
    "degC",
    "degF",
    "Pa",
    "kPa",
    "bar",
    "atm",
    "psi",
    "s",
    "min",
    "h",
    "m",
    "cm",
    "ft",
    "m2",
    "m3",
    "L",
    "J/mol",
    "kJ/mol",
    "W",
    "kW",
    "MW",
    "kW/K",
    "J/(mol*K)",
    "kg/kmol",
    "1/s",
    "kmol/min/kmol",
    "mol/s/m",
    "%",
];
/// Unit texts that must be rejected.
const GARBAGE_UNITS: &[&str] = &["furlong", "kmol//min", "kmol/min/", "1 1", "mol/s/s/s", "kmol^2", "°C", "(", "e5"];

/// Most bytes of JSON text one flood may make. Mutations compose: a flood of a value an earlier
/// mutation made long (a 100 000-character string) would otherwise be 10 GB, and exhaust the
/// harness's own memory before the engine ever reads it. A flood of the shipped values' size
/// (100 000 events of about 100 bytes) stays whole.
pub const FLOOD_BYTES: usize = 32 << 20;

/// How many copies of `items` (cycled) a flood asked for `wanted` elements makes: `wanted`, or
/// fewer so that the copies stay within [`FLOOD_BYTES`] (at least one).
pub fn flood_len(items: &[Value], wanted: usize) -> usize {
    let bytes: usize = items.iter().map(|v| v.to_string().len() + 1).sum();
    let each = bytes.div_ceil(items.len().max(1)).max(1);
    wanted.min(FLOOD_BYTES / each).max(1)
}

/// What the mutators may refer to: names defined in the document and the unit table.
pub struct Names {
    /// Unit, stream, controller, input and component names of the document.
    pub all: Vec<String>,
    /// Replacement units with their dimensions.
    pub units: Vec<(&'static str, Dimension)>,
}

impl Names {
    /// The names of `v` (a flowsheet or scenario).
    pub fn of(v: &Value) -> Names {
        let mut all = Vec::new();
        for section in ["units", "streams", "controllers", "inputs", "sampling"] {
            if let Some(m) = v.get(section).and_then(Value::as_object) {
                all.extend(m.keys().cloned());
            }
        }
        for c in v.get("components").and_then(Value::as_array).into_iter().flatten() {
            match c {
                Value::String(s) => all.push(s.clone()),
                Value::Object(o) => all.extend(o.get("name").and_then(Value::as_str).map(str::to_string)),
                _ => {}
            }
        }
        if all.is_empty() {
            all.push("feed".into());
        }
        let units = UNITS.iter().filter_map(|u| unit_dimension(u).ok().map(|d| (*u, d))).collect();
        Names { all, units }
    }
}

/// A JSON number, or `null` for a non-finite value (JSON has none).
fn num(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// One random mutation of `doc`: of a random node (by its kind and key), or of the whole text.
pub fn mutate(rng: &mut Rng, doc: &mut Doc, names: &Names) -> String {
    let sites = doc.sites();
    if sites.is_empty() || rng.chance(0.05) {
        return text(rng, doc, &sites);
    }
    let site = rng.pick(&sites).clone();
    let node = doc.value.pointer(&site.pointer).cloned().unwrap_or(Value::Null);
    let (class, new) = match &node {
        Value::Number(n) => number(rng, &site, n.as_f64().unwrap_or(0.0), n.is_i64() || n.is_u64()),
        Value::String(s) => string(rng, s, names),
        Value::Object(m) => return object(rng, doc, &site, m, names),
        Value::Array(a) => array(rng, a),
        Value::Bool(_) | Value::Null => ("type_swap", other_type(rng)),
    };
    set(doc, &site, &node, new, class)
}

/// Put `new` at `site`, describing the change.
pub fn set(doc: &mut Doc, site: &Site, old: &Value, new: Value, class: &str) -> String {
    let line = format!("{}: {} -> {} [{class}]", site.path, brief(old), brief(&new));
    if let Some(slot) = doc.value.pointer_mut(&site.pointer) {
        *slot = new;
    }
    line
}

/// A value of another JSON type (type confusion in the deserializer).
fn other_type(rng: &mut Rng) -> Value {
    rng.pick(&[json!(null), json!(true), json!(1), json!("x"), json!([]), json!({})]).clone()
}

/// Numbers: zero, sign, scale by 1e±k, huge (1e308, 2^63, 1e9), tiny (1e-300, denormal),
/// NaN-like strings, fractions where integers are expected, integers beyond i64, and huge
/// counts for the keys that size allocations (`stages`, `inlets`, …).
fn number(rng: &mut Rng, site: &Site, x: f64, is_int: bool) -> (&'static str, Value) {
    if COUNT_KEYS.contains(&site.key.as_str()) && rng.chance(0.6) {
        return ("count_huge", json!(*rng.pick(HUGE_COUNTS)));
    }
    match rng.below(10) {
        0 => ("num_zero", json!(0)),
        1 => ("num_negate", num(-x)),
        2 => {
            let k = rng.below(25) as i32 - 12;
            ("num_scale", num(x * 10f64.powi(if k == 0 { 3 } else { k })))
        }
        3 => ("num_huge", num(*rng.pick(&[1e308, -1e308, 9.223372036854776e18, 1e9, 1.8e19]))),
        4 => ("num_tiny", num(*rng.pick(&[1e-300, 5e-324, -1e-300, 1e-12]))),
        5 => ("num_nan_string", json!(*rng.pick(&["NaN", "inf", "-Infinity", "1e999", "nan", ""]))),
        6 if is_int => ("int_as_float", num(x + 0.5)),
        7 => ("num_big_int", json!(*rng.pick(&[u64::MAX, 1u64 << 63]))),
        8 => ("num_as_quantity", json!(format!("{x} mol/s"))),
        _ => ("type_swap", other_type(rng)),
    }
}

/// Split a quantity string `"1 kmol/min"` into its number and unit.
fn split_quantity(s: &str) -> Option<(f64, &str)> {
    let s = s.trim();
    let end = s.find(|c: char| c.is_whitespace()).unwrap_or(s.len());
    let x: f64 = s[..end].parse().ok()?;
    Some((x, s[end..].trim()))
}

/// Strings: quantities get other values and units; names and enum words get emptied, made very
/// long (up to 10^5 chars), unknown, swapped for another name of the document, or port-mangled.
fn string(rng: &mut Rng, s: &str, names: &Names) -> (&'static str, Value) {
    if let Some((x, unit)) = split_quantity(s)
        && rng.chance(0.75)
    {
        return quantity(rng, x, unit, names);
    }
    match rng.below(7) {
        0 => ("str_empty", json!("")),
        1 => {
            let n = *rng.pick(&[1000, 100_000]);
            ("str_long", json!(if s.is_empty() { "A".repeat(n) } else { s.repeat(n / s.len() + 1) }))
        }
        2 => ("name_unknown", json!(format!("{s}_nosuch"))),
        3 => ("name_swap", json!(rng.pick(&names.all).clone())),
        4 => ("name_port", json!(if s.contains('.') { s.replace('.', ".no_") } else { format!("{s}.nosuch") })),
        5 => ("str_case", json!(s.to_uppercase())),
        _ => ("type_swap", other_type(rng)),
    }
}

/// Quantity strings: the number (0, negative, huge, tiny, NaN, 1e400), another unit of the same
/// dimension (legal: must still load), a unit of the wrong dimension, garbage units, no unit.
fn quantity(rng: &mut Rng, x: f64, unit: &str, names: &Names) -> (&'static str, Value) {
    let dim = unit_dimension(unit).ok();
    let same: Vec<&str> = names.units.iter().filter(|(_, d)| Some(*d) == dim).map(|(u, _)| *u).collect();
    let other: Vec<&str> = names.units.iter().filter(|(_, d)| Some(*d) != dim).map(|(u, _)| *u).collect();
    match rng.below(6) {
        0 => {
            let v = *rng.pick(&["0", "-1", "1e308", "1e-300", "NaN", "inf", "1e400", "-0", "1e200", "1e9"]);
            let v = if v == "-1" { format!("{}", -x) } else { v.to_string() };
            ("qty_value", json!(format!("{v} {unit}")))
        }
        1 if !same.is_empty() => ("qty_unit_same", json!(format!("{x} {}", rng.pick(&same)))),
        2 if !other.is_empty() => ("qty_unit_wrong", json!(format!("{x} {}", rng.pick(&other)))),
        3 => ("qty_garbage", json!(format!("{x} {}", rng.pick(GARBAGE_UNITS)))),
        4 => ("qty_bare", json!(if rng.chance(0.5) { format!("{x}") } else { unit.to_string() })),
        _ => ("qty_scale", json!(format!("{} {unit}", x * 10f64.powi(rng.below(13) as i32 - 6)))),
    }
}

/// Arrays: empty, an element duplicated, flooded (10^2…10^4 copies), removed, reversed.
fn array(rng: &mut Rng, a: &[Value]) -> (&'static str, Value) {
    if a.is_empty() {
        return ("arr_fill", json!([1, "x", {}]));
    }
    let i = rng.below(a.len());
    let mut b = a.to_vec();
    let class = match rng.below(5) {
        0 => return ("arr_empty", json!([])),
        1 => {
            b.insert(i, a[i].clone());
            "arr_duplicate"
        }
        2 => {
            let n = flood_len(std::slice::from_ref(&a[i]), *rng.pick(&[100, 10_000]));
            b.extend(std::iter::repeat_n(a[i].clone(), n));
            "arr_flood"
        }
        3 => {
            b.remove(i);
            "arr_remove"
        }
        _ => {
            b.reverse();
            "arr_reverse"
        }
    };
    (class, Value::Array(b))
}

/// Objects: a key deleted, renamed (typo), an unknown key added, a raw-text duplicate key, a
/// member copied under a new name, emptied; compositions off 1; stream endpoints swapped.
fn object(rng: &mut Rng, doc: &mut Doc, site: &Site, m: &Map<String, Value>, names: &Names) -> String {
    let old = Value::Object(m.clone());
    let keys: Vec<String> = m.keys().cloned().collect();
    if keys.is_empty() {
        return set(doc, site, &old, json!({"fuzz_unknown": 1}), "key_unknown");
    }
    let k = rng.pick(&keys).clone();
    let mut n = m.clone();
    let class = match rng.below(9) {
        0 => {
            n.remove(&k);
            "key_delete"
        }
        1 => {
            let v = n.remove(&k).unwrap_or(Value::Null);
            n.insert(format!("{k}_"), v);
            "key_rename"
        }
        2 => {
            n.insert("fuzz_unknown".into(), json!(1));
            "key_unknown"
        }
        3 => return duplicate_key(rng, doc, site, m, &k, names),
        4 => {
            n.insert(format!("{k}2"), m[&k].clone());
            "member_copy"
        }
        5 if m.values().all(Value::is_number) => return composition(rng, doc, site, m),
        6 if m.contains_key("from") && m.contains_key("to") => {
            let (f, t) = (m["from"].clone(), m["to"].clone());
            n.insert("from".into(), t);
            n.insert("to".into(), if rng.chance(0.5) { f } else { m["to"].clone() });
            "stream_swap"
        }
        7 => return set(doc, site, &old, json!({}), "obj_empty"),
        _ => return set(doc, site, &old, other_type(rng), "type_swap"),
    };
    set(doc, site, &old, Value::Object(n), class)
}

/// Raw JSON text of an object with member `k` written twice (the second time mutated or not):
/// duplicate keys that `Value` cannot hold and a loader must not silently resolve.
fn duplicate_key(rng: &mut Rng, doc: &mut Doc, site: &Site, m: &Map<String, Value>, k: &str, names: &Names) -> String {
    let mut second = m[k].clone();
    if let Value::String(s) = &second {
        second = string(rng, s, names).1;
    } else if rng.chance(0.5) {
        second = other_type(rng);
    }
    let mut parts: Vec<String> = m.iter().map(|(key, v)| format!("{}: {v}", json!(key))).collect();
    parts.push(format!("{}: {second}", json!(k)));
    let marker = doc.raw_marker(format!("{{{}}}", parts.join(", ")));
    let line = format!("{}: key `{k}` written twice, second {} [key_duplicate_raw]", site.path, brief(&second));
    if let Some(slot) = doc.value.pointer_mut(&site.pointer) {
        *slot = marker;
    }
    line
}

/// Compositions (objects of numbers): scaled off 1, one entry 1.5 or negative, one dropped,
/// an unknown component added.
fn composition(rng: &mut Rng, doc: &mut Doc, site: &Site, m: &Map<String, Value>) -> String {
    let old = Value::Object(m.clone());
    let mut n = m.clone();
    let k = n.keys().next().cloned().unwrap_or_default();
    let class = match rng.below(4) {
        0 => {
            let f = *rng.pick(&[0.9, 1.1, 1.0 + 1e-6, 0.0]);
            n.values_mut().for_each(|v| *v = num(v.as_f64().unwrap_or(0.0) * f));
            "comp_scaled"
        }
        1 => {
            n.insert(k, json!(*rng.pick(&[1.5, -0.1, 1e308])));
            "comp_entry"
        }
        2 => {
            n.remove(&k);
            "comp_drop"
        }
        _ => {
            n.insert("nosuch_component".into(), json!(0.1));
            "comp_unknown"
        }
    };
    set(doc, site, &old, Value::Object(n), class)
}

/// Whole-text mutations: truncation, trailing garbage, deep nesting (recursion limits), number
/// literals that do not fit an f64 (1e400, 400-digit integers).
fn text(rng: &mut Rng, doc: &mut Doc, sites: &[Site]) -> String {
    match rng.below(4) {
        0 => {
            let f = rng.unit();
            doc.tail = Some(Tail::Truncate(f));
            format!("text truncated at {:.0} % [text_truncate]", 100.0 * f)
        }
        1 => {
            let g = *rng.pick(&["}", ",", "\u{0}", " extra", "{\"a\":1}"]);
            doc.tail = Some(Tail::Append(g.to_string()));
            format!("text + {g:?} [text_trailing]")
        }
        _ if sites.is_empty() => "no sites [identity]".to_string(),
        2 => {
            let site = rng.pick(sites).clone();
            let depth = *rng.pick(&[100, 200, 100_000]);
            raw_at(
                doc,
                &site,
                format!("{}1{}", "[".repeat(depth), "]".repeat(depth)),
                &format!("{depth} nested arrays"),
            ) + " [text_deep_nesting]"
        }
        _ => {
            let site = rng.pick(sites).clone();
            let lit = rng.pick(&["1e400", "-1e400", "1e-400"]).to_string();
            let lit = if rng.chance(0.3) { "9".repeat(400) } else { lit };
            let what = format!("literal {}", brief(&Value::String(lit.clone())));
            raw_at(doc, &site, lit, &what) + " [text_huge_literal]"
        }
    }
}

/// Replace the node at `site` by raw JSON `text`, described as `what`.
fn raw_at(doc: &mut Doc, site: &Site, text: String, what: &str) -> String {
    let marker = doc.raw_marker(text);
    if let Some(slot) = doc.value.pointer_mut(&site.pointer) {
        *slot = marker;
    }
    format!("{}: -> {what}", site.path)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flood of short values is made whole; one of long values stops at the byte budget.
    #[test]
    fn a_flood_stays_within_its_byte_budget() {
        assert_eq!(flood_len(&[json!({"at": "0 s", "type": "step"})], 100_000), 100_000);
        let long = json!("step".repeat(25_000));
        let n = flood_len(std::slice::from_ref(&long), 100_000);
        assert!(n * long.to_string().len() <= FLOOD_BYTES, "{n} copies of 100 kB");
        assert!(n >= FLOOD_BYTES / 200_000, "{n} copies: the budget is used");
    }
}
