//! Paths that name a plant's variables and inputs, and the conventions they follow.
//!
//! A path is `owner.field`: the owner is a unit, a controller or a stream, the field one of its
//! variables or inputs (`tank.level`, `valve.opening`, `feed.F`, `column.x[21][light]`). Owners
//! (units and controllers) may not contain `.`, so the owner is the text before the first `.`.
//!
//! Conventions:
//! - a stream's composition is its `x[c]`; `stream.z[c]` names the same variable (the spelling of
//!   feed compositions);
//! - a controller's outputs are `<ctrl>.op`, `<ctrl>.op2`, `<ctrl>.op3`, …: output `k` (0-based)
//!   drives the controller's `k`-th driven input (split range: `op` and `op2`);
//! - `stream.X` names input `X` of the unit that produces `stream` (a feed's `F`, `z[c]`) in
//!   `--set` overrides and scenario events;
//! - a feed unit's composition inputs are `unit.z[c]`.

use std::collections::HashMap;
use std::fmt;

/// A variable or input path `owner.field`, split once at its first `.`.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct VarPath {
    text: String,
    /// Byte index of the first `.`, if there is one.
    dot: Option<usize>,
}

impl VarPath {
    /// Parse `text` (any string is a path; one without `.` has no field).
    pub fn parse(text: &str) -> VarPath {
        VarPath { text: text.to_string(), dot: text.find('.') }
    }

    /// The path `owner.field`.
    pub fn new(owner: &str, field: &str) -> VarPath {
        VarPath { text: format!("{owner}.{field}"), dot: Some(owner.len()) }
    }

    /// Output `k` (0-based) of controller `ctrl`: `<ctrl>.op` for `k = 0`, `<ctrl>.op{k+1}` after.
    pub fn controller_output(ctrl: &str, k: usize) -> VarPath {
        if k == 0 { VarPath::new(ctrl, "op") } else { VarPath::new(ctrl, &format!("op{}", k + 1)) }
    }

    /// The owner: the text before the first `.` (all of it without a `.`).
    pub fn owner(&self) -> &str {
        self.dot.map_or(&self.text, |d| &self.text[..d])
    }

    /// The field: the text after the first `.`, if there is one.
    pub fn field(&self) -> Option<&str> {
        self.dot.map(|d| &self.text[d + 1..])
    }

    /// The whole path.
    pub fn as_str(&self) -> &str {
        &self.text
    }

    /// Whether this is a controller's first output `<owner>.op`.
    pub fn is_controller_output(&self) -> bool {
        self.field() == Some("op")
    }

    /// Whether the field is a composition `z[c]` (a feed unit's composition input).
    pub fn is_composition(&self) -> bool {
        self.field().is_some_and(|f| f.starts_with("z["))
    }

    /// The entry of `index` under this path, or else under its stream-composition spelling (every
    /// `.z[` read as `.x[`: `stream.z[c]` is the variable `stream.x[c]`).
    pub fn find<V: Copy>(&self, index: &HashMap<String, V>) -> Option<V> {
        index.get(&self.text).or_else(|| index.get(&self.text.replace(".z[", ".x["))).copied()
    }
}

impl fmt::Display for VarPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

impl From<VarPath> for String {
    fn from(p: VarPath) -> String {
        p.text
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn owner_field_and_conventions() {
        let p = VarPath::parse("column.x[21][light]");
        assert_eq!((p.owner(), p.field()), ("column", Some("x[21][light]")));
        assert_eq!(VarPath::parse("tank").field(), None);
        assert_eq!(VarPath::parse("tank").owner(), "tank");
        assert_eq!(VarPath::new("tank", "level").as_str(), "tank.level");
        assert_eq!(VarPath::controller_output("fc", 0).as_str(), "fc.op");
        assert_eq!(VarPath::controller_output("fc", 1).as_str(), "fc.op2");
        assert!(VarPath::controller_output("fc", 0).is_controller_output());
        assert!(!VarPath::controller_output("fc", 1).is_controller_output());
        assert!(VarPath::parse("feed.z[light]").is_composition());
        let index: HashMap<String, usize> = [("s1.x[light]".to_string(), 3), ("s1.z".to_string(), 4)].into();
        assert_eq!(VarPath::parse("s1.z[light]").find(&index), Some(3));
        assert_eq!(VarPath::parse("s1.x[light]").find(&index), Some(3));
        assert_eq!(VarPath::parse("s1.z").find(&index), Some(4));
        assert_eq!(VarPath::parse("s2.z[light]").find(&index), None);
    }
}
