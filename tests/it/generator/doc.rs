//! A flowsheet as a user writes it: JSON objects keep the order they were written in (feeds
//! first, products last), numbers print as typed, quantities are strings with units. `serde_json`
//! without `preserve_order` would sort every object, so the generator keeps its own small tree.

use plantwide::units::{convert_from_si, convert_to_si};

/// A JSON value whose objects keep their key order.
#[derive(Debug, Clone, PartialEq)]
pub enum J {
    /// A string (a quantity with its unit, a name, a path).
    S(String),
    /// A number.
    N(f64),
    /// An integer (stage numbers, counts).
    I(i64),
    /// A boolean.
    B(bool),
    /// An array.
    A(Vec<J>),
    /// An object, in the order written.
    O(Vec<(String, J)>),
}

impl From<&str> for J {
    fn from(s: &str) -> J {
        J::S(s.to_string())
    }
}

impl From<String> for J {
    fn from(s: String) -> J {
        J::S(s)
    }
}

impl From<f64> for J {
    fn from(v: f64) -> J {
        J::N(v)
    }
}

impl From<usize> for J {
    fn from(v: usize) -> J {
        J::I(v as i64)
    }
}

impl From<bool> for J {
    fn from(v: bool) -> J {
        J::B(v)
    }
}

impl From<Vec<J>> for J {
    fn from(v: Vec<J>) -> J {
        J::A(v)
    }
}

/// An object from `(key, value)` pairs, in this order.
pub fn obj<const N: usize>(pairs: [(&str, J); N]) -> J {
    J::O(pairs.into_iter().map(|(k, v)| (k.to_string(), v)).collect())
}

impl J {
    /// The member `key` of an object (or element `key` of an array).
    pub fn get(&self, key: &str) -> Option<&J> {
        match self {
            J::O(m) => m.iter().find(|(k, _)| k == key).map(|(_, v)| v),
            J::A(a) => a.get(key.parse::<usize>().ok()?),
            _ => None,
        }
    }

    fn get_mut(&mut self, key: &str) -> Option<&mut J> {
        match self {
            J::O(m) => m.iter_mut().find(|(k, _)| k == key).map(|(_, v)| v),
            J::A(a) => a.get_mut(key.parse::<usize>().ok()?),
            _ => None,
        }
    }

    /// The value at `path` (object keys and array indices).
    pub fn at(&self, path: &[&str]) -> Option<&J> {
        path.iter().try_fold(self, |j, k| j.get(k))
    }

    /// Set the value at `path`: an existing member is replaced in place, a new one appended to
    /// its object. Panics when the parent does not exist (a generator bug).
    pub fn set(&mut self, path: &[&str], value: J) {
        let (last, parent) = path.split_last().expect("a non-empty path");
        let mut j = self;
        for k in parent {
            j = j.get_mut(k).unwrap_or_else(|| panic!("generator: no `{k}` on the way to {path:?}"));
        }
        match j.get_mut(last) {
            Some(slot) => *slot = value,
            None => match j {
                J::O(m) => m.push((last.to_string(), value)),
                _ => panic!("generator: cannot add `{last}` to a non-object at {path:?}"),
            },
        }
    }

    /// Remove the member at `path` if it is there.
    pub fn remove(&mut self, path: &[&str]) {
        let (last, parent) = path.split_last().expect("a non-empty path");
        let mut j = self;
        for k in parent {
            match j.get_mut(k) {
                Some(next) => j = next,
                None => return,
            }
        }
        if let J::O(m) = j {
            m.retain(|(k, _)| k != last);
        }
    }

    /// The file text: one member per line up to the units' and controllers' level, each unit,
    /// stream and controller on its own line (as the shipped flowsheets are written).
    pub fn render(&self) -> String {
        let mut out = String::new();
        self.write(&mut out, 0);
        out.push('\n');
        out
    }

    fn write(&self, out: &mut String, depth: usize) {
        match self {
            J::O(m) if depth < 2 && !m.is_empty() => {
                out.push_str("{\n");
                for (i, (k, v)) in m.iter().enumerate() {
                    out.push_str(&"  ".repeat(depth + 1));
                    out.push_str(&format!("{}: ", string(k)));
                    v.write(out, depth + 1);
                    out.push_str(if i + 1 < m.len() { ",\n" } else { "\n" });
                }
                out.push_str(&"  ".repeat(depth));
                out.push('}');
            }
            _ => out.push_str(&self.inline()),
        }
    }

    fn inline(&self) -> String {
        match self {
            J::S(s) => string(s),
            J::N(v) => number(*v),
            J::I(v) => v.to_string(),
            J::B(b) => b.to_string(),
            J::A(a) => format!("[{}]", a.iter().map(J::inline).collect::<Vec<_>>().join(", ")),
            J::O(m) => {
                let members: Vec<String> = m.iter().map(|(k, v)| format!("{}: {}", string(k), v.inline())).collect();
                format!("{{{}}}", members.join(", "))
            }
        }
    }
}

fn string(s: &str) -> String {
    serde_json::to_string(s).expect("a string serializes")
}

/// A number as a person types it (shortest round trip; no `1e-5` surprises for JSON).
fn number(v: f64) -> String {
    assert!(v.is_finite(), "generator: a non-finite number {v}");
    if v == v.trunc() && v.abs() < 1e15 { format!("{v:.1}") } else { format!("{v}") }
}

/// `v` rounded to `digits` significant digits (what a person copies from a printout).
pub fn round_sig(v: f64, digits: i32) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let scale = 10f64.powi(digits - 1 - v.abs().log10().floor() as i32);
    let r = (v * scale).round() / scale;
    // Printing `r` must give back the digits, not 0.30000000000000004.
    format!("{r:.*e}", (digits - 1).max(0) as usize).parse().unwrap_or(r)
}

/// A quantity of SI value `si` written in `unit` to `digits` significant digits, and the SI value
/// that string stands for (what the engine will read).
pub fn quantity(si: f64, unit: &str, digits: i32) -> (String, f64) {
    let shown = round_sig(convert_from_si(si, unit).expect("a known unit"), digits);
    let text = format!("{} {unit}", number(shown).trim_end_matches(".0"));
    let back = convert_to_si(shown, unit).expect("a known unit");
    (text, back)
}

/// [`quantity`]'s string only.
pub fn q(si: f64, unit: &str, digits: i32) -> J {
    J::S(quantity(si, unit, digits).0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_in_order_and_edits_in_place() {
        let mut d = obj([("b", J::I(1)), ("a", obj([("x", "1 kmol/h".into()), ("y", J::N(0.5))]))]);
        d.set(&["a", "y"], J::N(0.25));
        d.set(&["a", "z"], J::B(true));
        d.remove(&["a", "x"]);
        assert_eq!(d.render(), "{\n  \"b\": 1,\n  \"a\": {\n    \"y\": 0.25,\n    \"z\": true\n  }\n}\n");
        let back: serde_json::Value = serde_json::from_str(&d.render()).unwrap();
        assert_eq!(back["a"]["y"], 0.25);
    }

    #[test]
    fn quantities_round_trip_through_their_units() {
        let (text, si) = quantity(100_000.0 / 3600.0, "kmol/h", 6);
        assert_eq!(text, "100 kmol/h");
        assert!((si - 27.777_777_777_777_78).abs() < 1e-12);
        assert_eq!(round_sig(0.123_456_789, 4), 0.1235);
        assert_eq!(quantity(373.15, "degC", 5).0, "100 degC");
    }
}
