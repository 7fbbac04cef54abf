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

    /// Setpoint input `<ctrl>.sp` of a loop (a PID with a local setpoint).
    pub fn setpoint(ctrl: &str) -> VarPath {
        VarPath::new(ctrl, "sp")
    }

    /// Mode input `<ctrl>.auto` of a PID (1 = auto, 0 = manual).
    pub fn auto(ctrl: &str) -> VarPath {
        VarPath::new(ctrl, "auto")
    }

    /// Manual output input `<ctrl>.op_manual` of a PID (its output while in manual).
    pub fn manual_output(ctrl: &str) -> VarPath {
        VarPath::new(ctrl, "op_manual")
    }

    /// Setpoint input of CV `k` (0-based) of a model predictive controller: `<ctrl>.sp{k+1}`.
    pub fn cv_setpoint(ctrl: &str, k: usize) -> VarPath {
        VarPath::new(ctrl, &format!("sp{}", k + 1))
    }

    /// Input holding MV `k` (0-based) of a model predictive controller: `<ctrl>.mv{k+1}`.
    pub fn mv(ctrl: &str, k: usize) -> VarPath {
        VarPath::new(ctrl, &format!("mv{}", k + 1))
    }

    /// This path with the index `i` appended: `column.M` → `column.M[3]`; twice for a stage's
    /// component, `column.x` → `column.x[3][light]`; a stream's or feed's `s.z` → `s.z[light]`.
    pub fn index(mut self, i: impl fmt::Display) -> VarPath {
        use fmt::Write;
        write!(self.text, "[{i}]").expect("writing to a String");
        self
    }

    /// Whether `path` names an element of this (indexed) field: this path followed by `[`
    /// (`feed.z` has `feed.z[light]`, `column.n[3]` has `column.n[3][light]`).
    pub fn has_element(&self, path: &str) -> bool {
        path.strip_prefix(self.text.as_str()).is_some_and(|rest| rest.starts_with('['))
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

impl AsRef<str> for VarPath {
    fn as_ref(&self) -> &str {
        &self.text
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

    /// Each constructor spells the text the code built by hand before it.
    #[test]
    fn constructors_spell_the_paths() {
        let (ctrl, unit, stage, c) = ("lc", "column", 3_usize, "light");
        assert_eq!(VarPath::setpoint(ctrl).as_str(), format!("{ctrl}.sp"));
        assert_eq!(VarPath::auto(ctrl).as_str(), format!("{ctrl}.auto"));
        assert_eq!(VarPath::manual_output(ctrl).as_str(), format!("{ctrl}.op_manual"));
        for k in 0..3 {
            if k > 0 {
                assert_eq!(VarPath::controller_output(ctrl, k).as_str(), format!("{ctrl}.op{}", k + 1));
            }
            assert_eq!(VarPath::cv_setpoint(ctrl, k).as_str(), format!("{ctrl}.sp{}", k + 1));
            assert_eq!(VarPath::mv(ctrl, k).as_str(), format!("{ctrl}.mv{}", k + 1));
        }
        assert_eq!(VarPath::cv_setpoint(ctrl, 1).as_str(), "lc.sp2");
        assert_eq!(VarPath::mv(ctrl, 2).as_str(), "lc.mv3");
        assert_eq!(VarPath::new(unit, "M").index(stage).as_str(), format!("{unit}.M[{}]", stage));
        assert_eq!(VarPath::new(unit, "T").index("21").as_str(), "column.T[21]");
        assert_eq!(VarPath::new(unit, "x").index(stage).index(c).as_str(), format!("{unit}.x[{stage}][{c}]"));
        assert_eq!(VarPath::new("feed", "z").index(c).as_str(), "feed.z[light]");
        assert_eq!(VarPath::new("s1", "total").index(c).as_str(), "s1.total[light]");
        let x = VarPath::new(unit, "x").index(stage).index(c);
        assert_eq!((x.owner(), x.field()), ("column", Some("x[3][light]")));
        assert_eq!(VarPath::new(unit, "M").index("N").as_str(), "column.M[N]");
    }

    #[test]
    fn elements_of_an_indexed_field() {
        let z = VarPath::new("feed", "z");
        assert!(z.has_element("feed.z[light]"));
        assert!(!z.has_element("feed.z"));
        assert!(!z.has_element("feed.zeta[light]"));
        assert!(!z.has_element("feed2.z[light]"));
        let n3 = VarPath::new("column", "n").index(3);
        assert!(n3.has_element("column.n[3][light]"));
        assert!(!n3.has_element("column.n[31][light]"));
        assert!(VarPath::new("column", "M").has_element("column.M[41]"));
    }

    #[test]
    fn a_path_is_its_text() {
        let p = VarPath::new("tank", "level");
        assert_eq!(p.as_ref(), "tank.level");
        assert_eq!(p.to_string(), "tank.level");
        assert_eq!(String::from(p), "tank.level");
    }
}
