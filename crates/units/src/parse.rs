//! The unit-expression parser.
//!
//! Grammar (whitespace allowed around operators and parentheses):
//!
//! ```text
//! unit     := "-" | product
//! product  := factor (("*" | "·") factor)* ("/" factor)*
//! factor   := primary exponent?
//! primary  := symbol | "(" product ")" | "1"
//! exponent := "^" [+-]? digits | superscript digits (³, ⁻¹) | digits right after a symbol (m3)
//! ```
//!
//! `/` is left-associative and binds one factor: `kmol/min/kmol` is kmol·min⁻¹·kmol⁻¹. A `*` after a
//! `/` is rejected as ambiguous (`J/mol*K`): write `J/(mol*K)`.

use crate::table::{self, Resolved, UnitKind};
use crate::{Dimension, Unit, UnitError, suggest};

/// Whether offset units (degC, degF, psig, barg) standing alone keep their offset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Mode {
    /// An absolute value: `80 degC` is 353.15 K.
    Absolute,
    /// A difference: `10 degC` is 10 K.
    Difference,
}

/// One unit symbol with its net exponent.
struct Term<'a> {
    symbol: &'a str,
    unit: Resolved,
    exp: i32,
}

struct Parser<'a> {
    src: &'a str,
    pos: usize,
    /// The whole user input, quoted in errors.
    text: &'a str,
    /// Whether an operator, exponent or `1` was seen: the expression is not a lone symbol.
    compound: bool,
}

fn is_symbol_char(c: char) -> bool {
    c.is_alphabetic() || c.is_ascii_digit() || matches!(c, '%' | '°' | '℃' | '℉' | '_' | '$')
}

fn superscript_digit(c: char) -> Option<u32> {
    match c {
        '⁰' => Some(0),
        '¹' => Some(1),
        '²' => Some(2),
        '³' => Some(3),
        '⁴'..='⁹' => Some(c as u32 - '⁴' as u32 + 4),
        _ => None,
    }
}

impl<'a> Parser<'a> {
    fn peek(&self) -> Option<char> {
        self.src[self.pos..].chars().next()
    }

    fn bump(&mut self) -> Option<char> {
        let c = self.peek()?;
        self.pos += c.len_utf8();
        Some(c)
    }

    fn eat(&mut self, c: char) -> bool {
        let found = self.peek() == Some(c);
        if found {
            self.bump();
        }
        found
    }

    fn skip_ws(&mut self) {
        while self.peek().is_some_and(char::is_whitespace) {
            self.bump();
        }
    }

    fn syntax(&self, message: impl Into<String>) -> UnitError {
        UnitError::Syntax { text: self.text.to_owned(), message: message.into() }
    }

    fn product(&mut self) -> Result<Vec<Term<'a>>, UnitError> {
        let mut terms = self.factor()?;
        let mut divided = false;
        loop {
            self.skip_ws();
            match self.peek() {
                Some('*' | '·' | '⋅') => {
                    if divided {
                        return Err(self.syntax(
                            "`*` after `/` is ambiguous: put the whole denominator in parentheses, e.g. J/(mol*K)",
                        ));
                    }
                    self.bump();
                    self.compound = true;
                    terms.extend(self.factor()?);
                }
                Some('/') => {
                    self.bump();
                    self.compound = true;
                    divided = true;
                    for mut t in self.factor()? {
                        t.exp = -t.exp;
                        terms.push(t);
                    }
                }
                _ => return Ok(terms),
            }
        }
    }

    fn factor(&mut self) -> Result<Vec<Term<'a>>, UnitError> {
        self.skip_ws();
        let (mut terms, has_exponent) = match self.peek() {
            Some('(') => {
                self.bump();
                let terms = self.product()?;
                self.skip_ws();
                if !self.eat(')') {
                    return Err(self.syntax("missing `)`"));
                }
                (terms, false)
            }
            Some('1') => {
                self.bump();
                self.compound = true;
                if self.peek().is_some_and(|c| c.is_ascii_digit() || c == '.') {
                    return Err(self.syntax("the only number allowed in a unit is 1, as in 1/min"));
                }
                (Vec::new(), false)
            }
            Some(c) if is_symbol_char(c) && !c.is_ascii_digit() => self.symbol()?,
            Some(c) => {
                return Err(self.syntax(format!("unexpected `{c}` where a unit is expected")));
            }
            None => return Err(self.syntax("a unit is missing at the end")),
        };
        if has_exponent {
            self.compound = true;
        }
        if let Some(n) = self.exponent()? {
            self.compound = true;
            if has_exponent {
                return Err(self.syntax("two exponents on one unit"));
            }
            for t in &mut terms {
                t.exp = t.exp.checked_mul(n).ok_or_else(|| self.syntax("exponent out of range"))?;
            }
        }
        Ok(terms)
    }

    /// A unit symbol, possibly with trailing exponent digits (`m3`); returns whether it had them.
    fn symbol(&mut self) -> Result<(Vec<Term<'a>>, bool), UnitError> {
        let start = self.pos;
        while self.peek().is_some_and(is_symbol_char) {
            self.bump();
        }
        let word = &self.src[start..self.pos];
        if let Some(unit) = table::lookup(word) {
            return Ok((vec![Term { symbol: word, unit, exp: 1 }], false));
        }
        let base = word.trim_end_matches(|c: char| c.is_ascii_digit());
        if base != word
            && let Some(unit) = table::lookup(base)
        {
            let exp = word[base.len()..].parse().map_err(|_| self.syntax("exponent out of range"))?;
            return Ok((vec![Term { symbol: base, unit, exp }], true));
        }
        let unit = if base.is_empty() { word } else { base };
        Err(UnitError::UnknownUnit {
            unit: unit.to_owned(),
            text: self.text.to_owned(),
            suggestion: suggest::suggest(unit),
        })
    }

    fn exponent(&mut self) -> Result<Option<i32>, UnitError> {
        let save = self.pos;
        self.skip_ws();
        if self.eat('^') {
            self.skip_ws();
            let negative = match self.peek() {
                Some('-' | '−') => {
                    self.bump();
                    true
                }
                Some('+') => {
                    self.bump();
                    false
                }
                _ => false,
            };
            let start = self.pos;
            while self.peek().is_some_and(|c| c.is_ascii_digit()) {
                self.bump();
            }
            let digits = &self.src[start..self.pos];
            if digits.is_empty() {
                return Err(self.syntax("`^` must be followed by an integer exponent, e.g. m^3 or s^-1"));
            }
            let n: i32 = digits.parse().map_err(|_| self.syntax("exponent out of range"))?;
            return Ok(Some(if negative { -n } else { n }));
        }
        self.pos = save;
        let negative = self.eat('⁻');
        let mut n: Option<i32> = None;
        while let Some(d) = self.peek().and_then(superscript_digit) {
            self.bump();
            let next = n.unwrap_or(0).checked_mul(10).and_then(|v| v.checked_add(d as i32));
            n = Some(next.ok_or_else(|| self.syntax("exponent out of range"))?);
        }
        match n {
            Some(n) => Ok(Some(if negative { -n } else { n })),
            None if negative => Err(self.syntax("`⁻` must be followed by superscript digits, e.g. s⁻¹")),
            None => Ok(None),
        }
    }
}

/// Parses a unit expression. `text` is the whole user input, quoted in errors.
pub(crate) fn parse_unit(expr: &str, text: &str, mode: Mode) -> Result<Unit, UnitError> {
    let src = expr.trim();
    let syntax = |message: &str| UnitError::Syntax { text: text.to_owned(), message: message.to_owned() };
    if src.is_empty() {
        return Err(syntax("no unit given"));
    }
    if src == "-" {
        return Ok(Unit::new(src, 1.0, 0.0, Dimension::DIMENSIONLESS));
    }
    let mut p = Parser { src, pos: 0, text, compound: false };
    let terms = p.product()?;
    p.skip_ws();
    match p.peek() {
        None => {}
        Some(')') => return Err(syntax("unmatched `)`")),
        Some(c) if is_symbol_char(c) || c == '(' => {
            return Err(syntax("expected `*` or `/` between units (units written side by side are not supported)"));
        }
        Some(c) => return Err(syntax(&format!("unexpected `{c}`"))),
    }

    let standalone = !p.compound && terms.len() == 1;
    let (mut factor, mut offset, mut dim) = (1.0_f64, 0.0_f64, Dimension::DIMENSIONLESS);
    for t in &terms {
        let def = t.unit.def;
        match def.kind {
            UnitKind::Linear => {}
            UnitKind::OffsetTemperature { linear } | UnitKind::GaugePressure { linear } => {
                let gauge = matches!(def.kind, UnitKind::GaugePressure { .. });
                if standalone {
                    if mode == Mode::Absolute {
                        offset = def.offset;
                    }
                } else if gauge || t.exp > 0 {
                    return Err(UnitError::AffineInCompound {
                        unit: t.symbol.to_owned(),
                        text: text.to_owned(),
                        linear: linear.to_owned(),
                    });
                }
            }
        }
        factor *= t.unit.factor().powi(t.exp);
        dim = def
            .dim
            .checked_pow(t.exp)
            .and_then(|d| dim.checked_mul(d))
            .ok_or_else(|| syntax("exponent out of range"))?;
    }
    if !(factor.is_finite() && factor > 0.0) {
        return Err(syntax("the unit's size is out of the floating-point range"));
    }
    Ok(Unit::new(src, factor, offset, dim))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(s: &str) -> Unit {
        parse_unit(s, s, Mode::Absolute).unwrap()
    }

    fn err(s: &str) -> UnitError {
        parse_unit(s, s, Mode::Absolute).unwrap_err()
    }

    #[test]
    fn powers_in_all_spellings() {
        for s in ["m3", "m^3", "m ^ 3", "m³", "(m)^3", "m*m*m", "m2*m", "m^+3"] {
            let u = unit(s);
            assert_eq!(u.dimension(), Dimension::VOLUME, "{s}");
            assert!((u.factor() - 1.0).abs() < 1e-15, "{s}");
        }
        for s in ["s^-1", "s⁻¹", "1/s", "1 / s", "s^−1"] {
            assert_eq!(unit(s).dimension(), Dimension::INVERSE_TIME, "{s}");
        }
        assert!((unit("cm3").factor() - 1e-6).abs() < 1e-21);
        assert!((unit("ft^2").factor() - 0.09290304).abs() < 1e-15);
        assert_eq!(unit("(mol*K)^-1").dimension(), Dimension::new(0, 0, 0, -1, -1));
    }

    #[test]
    fn quotients_are_left_associative() {
        let u = unit("kmol/min/kmol");
        assert_eq!(u.dimension(), Dimension::INVERSE_TIME);
        assert!((u.factor() - 1.0 / 60.0).abs() < 1e-15);
        let u = unit("J/(mol*K)");
        assert_eq!(u.dimension(), Dimension::HEAT_CAPACITY_MOLAR);
        assert_eq!(unit("W/m2/K").dimension(), Dimension::HEAT_TRANSFER_COEFFICIENT);
        assert_eq!(unit("kg·m/s2").dimension(), Dimension::FORCE);
    }

    #[test]
    fn symbols_with_digits_inside() {
        assert_eq!(unit("inH2O").dimension(), Dimension::PRESSURE);
        assert_eq!(unit("inH2O/ft").dimension(), Dimension::new(1, -2, -2, 0, 0));
    }

    #[test]
    fn syntax_errors() {
        for s in ["(m", "m)", "m^", "m^x", "m3^2", "J/mol*K", "kJ/kmol K", "10/min", "m^99999999999", "/s", "m/", "m⁻"]
        {
            assert!(matches!(err(s), UnitError::Syntax { .. }), "{s}: {:?}", err(s));
        }
        assert!(matches!(err("m^200"), UnitError::Syntax { .. }));
        assert!(matches!(err("Tm^30"), UnitError::Syntax { .. }), "1e360 overflows");
    }

    #[test]
    fn affine_rules() {
        assert_eq!(unit("degC").offset(), 273.15);
        assert_eq!(unit("(degC)").offset(), 273.15);
        assert_eq!(parse_unit("degC", "", Mode::Difference).unwrap().offset(), 0.0);
        assert_eq!(unit("kJ/(kmol*degC)").offset(), 0.0);
        assert_eq!(unit("1/degF").offset(), 0.0);
        assert!((unit("1/degF").factor() - 1.8).abs() < 1e-12);
        for s in ["degC/min", "degC^2", "degC*s", "psig/s", "kPag/h", "1/psig", "1/(1/degC)"] {
            assert!(matches!(err(s), UnitError::AffineInCompound { .. }), "{s}");
        }
    }
}
