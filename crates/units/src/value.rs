//! A flowsheet field that is either a bare SI number or a string with units.

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::quantity::{parse_difference_as, parse_quantity_as};
use crate::{Dimension, UnitError};

/// A quantity as written in a flowsheet file: a JSON number, taken as already in SI units, or a
/// string with units such as `"1 kmol/min"` or `"80 degC"`. (De)serializes untagged: `12.6` or
/// `"100 lbmol/h"`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(untagged)]
pub enum QuantityValue {
    /// A value already in coherent SI units of the field's dimension (mol/s, Pa, K, …).
    Number(f64),
    /// A number with an optional unit, parsed by [`parse_quantity_as`](crate::parse_quantity_as).
    Text(String),
}

impl QuantityValue {
    /// The number if this is a bare number (JSON `150` or text `"150"`): a value read in SI
    /// units, which a user may not have meant.
    pub fn bare(&self) -> Option<f64> {
        match self {
            QuantityValue::Number(x) => Some(*x),
            QuantityValue::Text(s) => s.trim().parse().ok(),
        }
    }

    /// The SI value, checking that a text value has dimension `expected`. Offset units standing
    /// alone are absolute values (`"80 degC"` is 353.15 K).
    pub fn to_si(&self, expected: Dimension) -> Result<f64, UnitError> {
        match self {
            QuantityValue::Number(x) => finite(*x),
            QuantityValue::Text(s) => parse_quantity_as(s, expected),
        }
    }

    /// Like [`QuantityValue::to_si`] for a difference (temperature approach, pressure drop): offsets
    /// are dropped, so `"10 degC"` is 10 K.
    pub fn to_si_difference(&self, expected: Dimension) -> Result<f64, UnitError> {
        match self {
            QuantityValue::Number(x) => finite(*x),
            QuantityValue::Text(s) => parse_difference_as(s, expected),
        }
    }
}

fn finite(x: f64) -> Result<f64, UnitError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(UnitError::BadNumber { text: x.to_string(), reason: format!("{x} is not a finite number") })
    }
}

impl From<f64> for QuantityValue {
    fn from(x: f64) -> Self {
        QuantityValue::Number(x)
    }
}

impl From<&str> for QuantityValue {
    fn from(s: &str) -> Self {
        QuantityValue::Text(s.to_owned())
    }
}

impl From<String> for QuantityValue {
    fn from(s: String) -> Self {
        QuantityValue::Text(s)
    }
}

impl fmt::Display for QuantityValue {
    /// The number, or the text as written.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            QuantityValue::Number(x) => write!(f, "{x}"),
            QuantityValue::Text(s) => f.write_str(s),
        }
    }
}
