//! Quantities: a number with an optional unit, parsed to SI.

use std::fmt;
use std::str::FromStr;

use crate::parse::{Mode, parse_unit};
use crate::{Dimension, Unit, UnitError};

/// A value in coherent SI units (mol/s, Pa, K, J, …) with its dimension.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quantity {
    /// The value in the coherent SI unit of `dim` (the unit shown by `dim`'s `Display`).
    pub value_si: f64,
    /// The dimension.
    pub dim: Dimension,
}

impl Quantity {
    /// A quantity from an SI value.
    pub const fn new(value_si: f64, dim: Dimension) -> Self {
        Quantity { value_si, dim }
    }

    /// The value expressed in `unit`, which must have the same dimension (offset units such as
    /// degC are converted as absolute values).
    pub fn in_unit(&self, unit: &str) -> Result<f64, UnitError> {
        let u = Unit::parse(unit)?;
        if u.dimension() != self.dim {
            return Err(wrong_dimension(unit, u.dimension(), self.dim));
        }
        Ok(u.from_si(self.value_si))
    }
}

impl fmt::Display for Quantity {
    /// `"12.6 mol/s"`; a dimensionless quantity shows the bare number.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(&self.value_si, f)?;
        if !self.dim.is_dimensionless() {
            write!(f, " {}", self.dim)?;
        }
        Ok(())
    }
}

impl FromStr for Quantity {
    type Err = UnitError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        parse_quantity(s)
    }
}

fn wrong_dimension(text: &str, found: Dimension, expected: Dimension) -> UnitError {
    UnitError::WrongDimension { text: text.to_owned(), found, expected, example: expected.example_hint() }
}

/// Byte length of the number literal at the start of `s`: `[+-]? digits [. digits] [e [+-] digits]`
/// with at least one mantissa digit; the exponent is only taken if it has digits.
fn number_len(s: &str) -> Option<usize> {
    let b = s.as_bytes();
    let digits = |mut i: usize| {
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        i
    };
    let mut i = usize::from(matches!(b.first(), Some(b'+' | b'-')));
    let int_end = digits(i);
    let mut mantissa_digits = int_end - i;
    i = int_end;
    if b.get(i) == Some(&b'.') {
        let frac_end = digits(i + 1);
        mantissa_digits += frac_end - (i + 1);
        i = frac_end;
    }
    if mantissa_digits == 0 {
        return None;
    }
    if matches!(b.get(i), Some(b'e' | b'E')) {
        let sign = usize::from(matches!(b.get(i + 1), Some(b'+' | b'-')));
        let exp_end = digits(i + 1 + sign);
        if exp_end > i + 1 + sign {
            i = exp_end;
        }
    }
    Some(i)
}

/// The number as written and its unit (`None` for a bare number).
/// Longest quantity text read (bytes): far above any real quantity, and it bounds the cost of
/// parsing and of the "did you mean" search.
pub const MAX_QUANTITY_LEN: usize = 200;

fn split(text: &str, mode: Mode) -> Result<(f64, Option<Unit>), UnitError> {
    let t = text.trim();
    if t.is_empty() {
        return Err(UnitError::Empty);
    }
    if t.len() > MAX_QUANTITY_LEN {
        let head: String = t.chars().take(24).collect();
        return Err(UnitError::BadNumber {
            text: format!("{head}…"),
            reason: format!("{} characters is not a quantity (at most {MAX_QUANTITY_LEN})", t.len()),
        });
    }
    let bad = |reason: String| UnitError::BadNumber { text: text.to_owned(), reason };
    let n = number_len(t).ok_or_else(|| bad("expected a number first, e.g. \"1 kmol/min\"".to_owned()))?;
    let literal = &t[..n];
    let value: f64 = literal.parse().map_err(|_| bad(format!("`{literal}` is not a number")))?;
    if !value.is_finite() {
        return Err(bad(format!("{literal} is not a finite number")));
    }
    let rest = t[n..].trim();
    let unit = if rest.is_empty() { None } else { Some(parse_unit(rest, text, mode)?) };
    Ok((value, unit))
}

fn to_si(text: &str, value: f64, unit: &Unit) -> Result<f64, UnitError> {
    let si = unit.to_si(value);
    if si.is_finite() {
        Ok(si)
    } else {
        Err(UnitError::BadNumber { text: text.to_owned(), reason: "the value is out of range in SI units".to_owned() })
    }
}

fn parse_with(text: &str, mode: Mode) -> Result<Quantity, UnitError> {
    match split(text, mode)? {
        (value, None) => Ok(Quantity::new(value, Dimension::DIMENSIONLESS)),
        (value, Some(unit)) => Ok(Quantity::new(to_si(text, value, &unit)?, unit.dimension())),
    }
}

fn parse_as_with(text: &str, expected: Dimension, mode: Mode) -> Result<f64, UnitError> {
    match split(text, mode)? {
        (value, None) => Ok(value),
        (value, Some(unit)) if unit.dimension() == expected => to_si(text, value, &unit),
        (_, Some(unit)) => Err(wrong_dimension(text, unit.dimension(), expected)),
    }
}

/// Parses `"<number> [unit]"` (`"100 lbmol/h"`, `"80 degC"`, `"2.3e-4 m3/mol"`, `"1.5"`) into SI.
///
/// The number is a decimal literal with optional sign, fraction and exponent; `inf` and `NaN` are
/// rejected, as are values that overflow. Whitespace between number and unit is optional. A bare
/// number is dimensionless. An offset unit standing alone is an absolute value: `"80 degC"` is
/// 353.15 K and `"30 psig"` is 30 psi + 101325 Pa.
pub fn parse_quantity(text: &str) -> Result<Quantity, UnitError> {
    parse_with(text, Mode::Absolute)
}

/// Parses a quantity that must have dimension `expected` and returns its SI value. A bare number
/// (no unit) is taken as already in SI units of `expected`, like a JSON number.
pub fn parse_quantity_as(text: &str, expected: Dimension) -> Result<f64, UnitError> {
    parse_as_with(text, expected, Mode::Absolute)
}

/// Like [`parse_quantity`] for a difference: offsets are dropped, so `"10 degC"` is 10 K and
/// `"5 psig"` is 5 psi.
pub fn parse_difference(text: &str) -> Result<Quantity, UnitError> {
    parse_with(text, Mode::Difference)
}

/// Like [`parse_quantity_as`] for a difference (a temperature approach, a pressure drop): offsets
/// are dropped, so `"10 degF"` is 50/9 K.
pub fn parse_difference_as(text: &str, expected: Dimension) -> Result<f64, UnitError> {
    parse_as_with(text, expected, Mode::Difference)
}

/// Converts an SI value to `unit` for display (`"kmol/min"`, `"degC"`). An offset unit standing
/// alone converts an absolute value (353.15 → 80 for `"degC"`). The dimension is not checked (see
/// [`Quantity::in_unit`]); non-finite values pass through.
pub fn convert_from_si(value_si: f64, unit: &str) -> Result<f64, UnitError> {
    Ok(Unit::parse(unit)?.from_si(value_si))
}

/// Converts a value in `unit` to SI; the inverse of [`convert_from_si`].
pub fn convert_to_si(value: f64, unit: &str) -> Result<f64, UnitError> {
    Ok(Unit::parse(unit)?.to_si(value))
}

/// The dimension of a unit expression (`"kmol/min"` → [`Dimension::MOLAR_FLOW`]).
pub fn unit_dimension(unit: &str) -> Result<Dimension, UnitError> {
    Ok(Unit::parse(unit)?.dimension())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn number_literals() {
        let cases = [
            ("1", Some(1)),
            ("-2.5e-3 K", Some(7)),
            ("+.5m", Some(3)),
            ("1.", Some(2)),
            ("1e6 Btu/h", Some(3)),
            ("2eV", Some(1)),
            ("3E+2", Some(4)),
            ("7e", Some(1)),
            (".", None),
            ("-", None),
            ("abc", None),
            ("e5", None),
        ];
        for (s, n) in cases {
            assert_eq!(number_len(s), n, "{s}");
        }
    }

    #[test]
    fn display() {
        assert_eq!(Quantity::new(12.5, Dimension::MOLAR_FLOW).to_string(), "12.5 mol/s");
        assert_eq!(Quantity::new(0.5, Dimension::DIMENSIONLESS).to_string(), "0.5");
        assert_eq!(format!("{:.1}", Quantity::new(351.26, Dimension::TEMPERATURE)), "351.3 K");
    }
}

#[cfg(test)]
mod currency_tests {
    use super::*;

    #[test]
    fn prices_and_cost_rates_carry_the_currency_dimension() {
        // 36 $/h = 0.01 $/s; 2 k$/d = 2000/86400 $/s; 31.8 $/kmol = 0.0318 $/mol.
        assert!((parse_quantity_as("36 $/h", Dimension::COST_RATE).unwrap() - 0.01).abs() < 1e-15);
        assert!((parse_quantity_as("2 k$/d", Dimension::COST_RATE).unwrap() - 2000.0 / 86400.0).abs() < 1e-15);
        let price = parse_quantity("31.8 $/kmol").unwrap();
        assert_eq!(price.dim, Dimension::CURRENCY / Dimension::AMOUNT);
        assert!((price.value_si - 0.0318).abs() < 1e-15);
        assert_eq!(price.dim.to_string(), "$/mol");
        // Money is not a mass flow: the dimension check sees the difference.
        assert!(parse_quantity_as("36 $/h", Dimension::MASS_FLOW).is_err());
        assert_eq!(Dimension::COST_RATE.to_string(), "$/s");
        assert!(!Dimension::CURRENCY.is_dimensionless());
        assert_eq!(crate::UnitSystem::Metric.unit_for(Dimension::COST_RATE), "$/h");
    }
}
