//! The serde type of flowsheet fields.

use approx::assert_abs_diff_eq;
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
    assert_eq!(QuantityValue::Number(12.5).to_si(D::MOLAR_FLOW).unwrap(), 12.5, "number is SI");
    let text = QuantityValue::from("1 kmol/min").to_si(D::MOLAR_FLOW).unwrap();
    assert_abs_diff_eq!(text, 1000.0 / 60.0, epsilon = 1e-15 * (1000.0 / 60.0));
    assert_abs_diff_eq!(
        QuantityValue::from("80 degC").to_si(D::TEMPERATURE).unwrap(),
        353.15,
        epsilon = 1e-15 * 353.15
    );
    assert_eq!(QuantityValue::from("12.6").to_si(D::MOLAR_FLOW).unwrap(), 12.6, "bare text is SI");
    assert_eq!(QuantityValue::from(0.25).to_si(D::DIMENSIONLESS).unwrap(), 0.25, "fraction");
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
    assert_abs_diff_eq!(approach.to_si_difference(D::TEMPERATURE).unwrap(), 10.0, epsilon = 1e-15 * 10.0);
    assert_abs_diff_eq!(approach.to_si(D::TEMPERATURE).unwrap(), 283.15, epsilon = 1e-15 * 283.15);
    let delta_f = QuantityValue::from("9 degF").to_si_difference(D::TEMPERATURE).unwrap();
    assert_abs_diff_eq!(delta_f, 5.0, epsilon = 1e-15 * 5.0);
    assert_eq!(QuantityValue::Number(3.0).to_si_difference(D::TEMPERATURE).unwrap(), 3.0, "number");
}

#[test]
fn display_and_conversions() {
    assert_eq!(QuantityValue::from("100 lbmol/h").to_string(), "100 lbmol/h");
    assert_eq!(QuantityValue::from(2.5).to_string(), "2.5");
    assert_eq!(QuantityValue::from(String::from("x")), QuantityValue::Text("x".into()));
}
