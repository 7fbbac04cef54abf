//! A parsed unit expression: SI factor, offset and dimension.

use std::fmt;
use std::str::FromStr;

use crate::parse::{Mode, parse_unit};
use crate::{Dimension, UnitError};

/// A parsed unit expression such as `"kmol/min"`, `"degC"` or `"J/(mol*K)"`, mapping values in that
/// unit to coherent SI units: `si = value * factor + offset`.
///
/// The offset is nonzero only for an offset temperature scale (degC, degF) or a gauge pressure
/// (psig, barg) standing alone and parsed with [`Unit::parse`]. Inside a compound unit degC acts as
/// K and degF as degR (allowed only per degree, in a denominator: `"kJ/(kmol*degC)"`); gauge
/// pressures are not allowed in compound units at all.
#[derive(Debug, Clone, PartialEq)]
pub struct Unit {
    expr: String,
    factor: f64,
    offset: f64,
    dim: Dimension,
}

impl Unit {
    pub(crate) fn new(expr: &str, factor: f64, offset: f64, dim: Dimension) -> Self {
        Unit { expr: expr.to_owned(), factor, offset, dim }
    }

    /// Parses a unit expression for absolute values: `"degC"` alone has its offset (0 degC is
    /// 273.15 K), `"psig"` alone adds one standard atmosphere (101325 Pa).
    pub fn parse(expr: &str) -> Result<Unit, UnitError> {
        parse_unit(expr, expr, Mode::Absolute)
    }

    /// Parses a unit expression for differences: offsets are dropped, so `"degC"` is the same as
    /// `"K"`, `"degF"` as `"degR"` and `"psig"` as `"psi"`.
    pub fn parse_difference(expr: &str) -> Result<Unit, UnitError> {
        parse_unit(expr, expr, Mode::Difference)
    }

    /// The expression as given (trimmed).
    pub fn expression(&self) -> &str {
        &self.expr
    }

    /// The size of one unit in coherent SI units of [`Unit::dimension`] (60 for `"min"`, in s).
    pub fn factor(&self) -> f64 {
        self.factor
    }

    /// The SI value of the unit's zero (273.15 K for a standalone `"degC"`); 0 for linear units.
    pub fn offset(&self) -> f64 {
        self.offset
    }

    /// The dimension.
    pub fn dimension(&self) -> Dimension {
        self.dim
    }

    /// Whether the unit has an offset zero (a standalone degC, degF, psig or barg).
    pub fn is_affine(&self) -> bool {
        self.offset != 0.0
    }

    /// A value in this unit converted to coherent SI units.
    pub fn to_si(&self, value: f64) -> f64 {
        value * self.factor + self.offset
    }

    /// A value in coherent SI units converted to this unit.
    pub fn from_si(&self, value_si: f64) -> f64 {
        (value_si - self.offset) / self.factor
    }
}

impl FromStr for Unit {
    type Err = UnitError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Unit::parse(s)
    }
}

impl fmt::Display for Unit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.expr)
    }
}
