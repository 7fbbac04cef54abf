//! The serde type of flowsheet fields.

mod common;

use common::assert_close;
use plantwide_units::{Dimension as D, QuantityValue, UnitError};
use serde::Deserialize;
use serde::de::IntoDeserializer;
use serde::de::value::Error as DeError;

fn from<'de, I: IntoDeserializer<'de, DeError>>(input: I) -> Result<QuantityValue, DeError> {
    QuantityValue::deserialize(input.into_deserializer())
}

#[test]
fn deserializes_numbers_and_strings_untagged() {
    assert_eq!(from(12.5_f64).unwrap(), QuantityValue::Number(12.5));
    // JSON integers arrive as u64 or i64.
    assert_eq!(from(5_u64).unwrap(), QuantityValue::Number(5.0));
    assert_eq!(from(-3_i64).unwrap(), QuantityValue::Number(-3.0));
    assert_eq!(from("1 kmol/min").unwrap(), QuantityValue::Text("1 kmol/min".into()));
    assert_eq!(from(String::from("80 degC")).unwrap(), QuantityValue::Text("80 degC".into()));
    assert!(from(true).is_err());
}

#[test]
fn is_serialize() {
    fn assert_serialize<T: serde::Serialize>() {}
    assert_serialize::<QuantityValue>();
}

#[test]
fn to_si() {
    assert_close(QuantityValue::Number(12.5).to_si(D::MOLAR_FLOW).unwrap(), 12.5, 0.0, "number is SI");
    assert_close(QuantityValue::from("1 kmol/min").to_si(D::MOLAR_FLOW).unwrap(), 1000.0 / 60.0, 1e-15, "text");
    assert_close(QuantityValue::from("80 degC").to_si(D::TEMPERATURE).unwrap(), 353.15, 1e-15, "absolute");
    assert_close(QuantityValue::from("12.6").to_si(D::MOLAR_FLOW).unwrap(), 12.6, 0.0, "bare text is SI");
    assert_close(QuantityValue::from(0.25).to_si(D::DIMENSIONLESS).unwrap(), 0.25, 0.0, "fraction");
    assert!(matches!(
        QuantityValue::from("5 K").to_si(D::MOLAR_FLOW),
        Err(UnitError::WrongDimension { found: D::TEMPERATURE, expected: D::MOLAR_FLOW, .. })
    ));
    assert!(matches!(QuantityValue::Number(f64::NAN).to_si(D::TIME), Err(UnitError::BadNumber { .. })));
    assert!(matches!(QuantityValue::Number(f64::INFINITY).to_si(D::TIME), Err(UnitError::BadNumber { .. })));
}

#[test]
fn to_si_difference() {
    let approach = QuantityValue::from("10 degC");
    assert_close(approach.to_si_difference(D::TEMPERATURE).unwrap(), 10.0, 1e-15, "delta degC");
    assert_close(approach.to_si(D::TEMPERATURE).unwrap(), 283.15, 1e-15, "absolute degC");
    assert_close(QuantityValue::from("9 degF").to_si_difference(D::TEMPERATURE).unwrap(), 5.0, 1e-15, "delta degF");
    assert_close(QuantityValue::Number(3.0).to_si_difference(D::TEMPERATURE).unwrap(), 3.0, 0.0, "number");
}

#[test]
fn display_and_conversions() {
    assert_eq!(QuantityValue::from("100 lbmol/h").to_string(), "100 lbmol/h");
    assert_eq!(QuantityValue::from(2.5).to_string(), "2.5");
    assert_eq!(QuantityValue::from(String::from("x")), QuantityValue::Text("x".into()));
}
