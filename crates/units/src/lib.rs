//! Quantities with units of measure for plantwide: parsing flowsheet inputs such as
//! `"1 kmol/min"`, `"100 lbmol/h"`, `"80 degC"`, `"30 psia"` or `"8000 J/(mol*K)"` into coherent SI
//! values (mol/s, K, Pa, J/(mol·K), …), and converting SI results back to user units.
//!
//! - [`parse_quantity`] / [`parse_quantity_as`] read `"<number> [unit]"`; the latter checks the
//!   [`Dimension`] and explains mismatches with examples.
//! - [`QuantityValue`] is the serde type of flowsheet fields: a bare number (SI) or a string.
//! - [`convert_from_si`], [`Unit`] and [`unit_dimension`] display results in user units.
//!
//! ```
//! use plantwide_units::{Dimension, QuantityValue, convert_from_si, parse_quantity_as};
//!
//! let feed = parse_quantity_as("100 lbmol/h", Dimension::MOLAR_FLOW)?; // mol/s
//! assert!((feed - 12.599_788).abs() < 1e-6);
//! assert!((convert_from_si(feed, "kmol/min")? - 0.755_987).abs() < 1e-6);
//!
//! let t = QuantityValue::from("80 degC").to_si(Dimension::TEMPERATURE)?; // K
//! assert!((t - 353.15).abs() < 1e-12);
//! assert!((convert_from_si(t, "degF")? - 176.0).abs() < 1e-12);
//!
//! let err = parse_quantity_as("5 K", Dimension::MOLAR_FLOW).unwrap_err();
//! assert!(err.to_string().starts_with("`5 K` is a temperature but a molar flow is expected"));
//! # Ok::<(), plantwide_units::UnitError>(())
//! ```
//!
//! # Unit expressions
//! Symbols from the [`units`] table, SI prefixes on mol, g, m, s, L, Pa, bar, J, cal, Wh, W and N
//! (`kmol`, `kPa`, `mL`, `kWh`), products `*` (or `·`), left-associative quotients
//! (`kmol/min/kmol` is kmol·min⁻¹·kmol⁻¹), parentheses (`J/(mol*K)`), and integer powers written
//! `m3`, `m^3`, `m³`, `s^-1`, `s⁻¹` or `1/s`. `"-"` alone means dimensionless. Symbols are
//! case-sensitive (`mW` is not `MW`); unknown symbols get a "did you mean" suggestion.
//!
//! # Offset units
//! degC and degF (offset temperature scales) and psig and barg (gauge pressures) carry an offset
//! only when they are the whole unit of an absolute value: `"80 degC"` = 353.15 K,
//! `"176 degF"` = 353.15 K, `"30 psig"` = 30 psi + 101325 Pa. In a compound unit degC acts as K and
//! degF as degR, and only per degree in a denominator (`"kJ/(kmol*degC)"`, `"1/degF"`); a numerator
//! such as `"80 degC/min"` is rejected with [`UnitError::AffineInCompound`] (write `K/min`), and
//! gauge pressures are rejected in any compound. For differences (approach temperatures, pressure
//! drops) use [`parse_difference_as`] or [`QuantityValue::to_si_difference`], which drop offsets.
//!
//! # Conventions
//! `lb` is the avoirdupois pound, `lbmol` = 453.59237 mol, `ton` the US short ton (2000 lb), `t` the
//! tonne, `gal`/`gpm` the US gallon, `Btu` the International Table Btu, `cal` the thermochemical
//! calorie (4.184 J), `hp` mechanical horsepower, `R`/`degR` the Rankine degree, `psi` and `psia`
//! absolute. Factors follow NIST SP 811 (2008), Appendix B.

#![warn(missing_docs)]

mod dimension;
mod error;
mod named;
mod parse;
mod preset;
mod quantity;
mod suggest;
mod table;
mod unit;
mod value;

pub use dimension::Dimension;
pub use error::UnitError;
/// The crate-level error: every public fallible function of this crate returns a [`UnitError`].
pub use error::UnitError as Error;
pub use named::{NamedDimension, named_dimensions};
pub use preset::{Display, UnitSystem};
pub use quantity::{
    Quantity, convert_from_si, convert_to_si, parse_difference, parse_difference_as, parse_quantity, parse_quantity_as,
    unit_dimension,
};
pub use table::{Prefix, UnitDef, UnitKind, prefixes, units};
pub use unit::Unit;
pub use value::QuantityValue;

/// Exact and NIST SP 811 conversion constants used by the unit table, in SI units.
pub mod constants {
    pub use crate::table::{
        ATM, BTU, CALORIE, FOOT, HORSEPOWER, INCH, MM_HG, POUND, POUND_FORCE, POUND_MOLE, PSI, RANKINE,
        STANDARD_GRAVITY, US_GALLON,
    };
}
