//! Error cases and their messages.

use plantwide_units::{
    Dimension as D, Quantity, UnitError, convert_from_si, parse_quantity, parse_quantity_as, unit_dimension,
};

fn err(text: &str) -> UnitError {
    parse_quantity(text).expect_err(text)
}

#[test]
fn wrong_dimension_explains_with_examples() {
    let e = parse_quantity_as("5 K", D::MOLAR_FLOW).unwrap_err();
    assert_eq!(
        e,
        UnitError::WrongDimension {
            text: "5 K".into(),
            found: D::TEMPERATURE,
            expected: D::MOLAR_FLOW,
            example: "\"1 kmol/min\", \"100 lbmol/h\" or a bare number in mol/s".into(),
        }
    );
    assert_eq!(
        e.to_string(),
        "`5 K` is a temperature but a molar flow is expected here \
         (e.g. \"1 kmol/min\", \"100 lbmol/h\" or a bare number in mol/s)"
    );
    let e = parse_quantity_as("50 %", D::TEMPERATURE).unwrap_err();
    assert_eq!(
        e.to_string(),
        "`50 %` is a dimensionless number but a temperature is expected here \
         (e.g. \"350 K\", \"80 degC\" or a bare number in K)"
    );
    let e = parse_quantity_as("3 kg*m/s3", D::ENERGY).unwrap_err();
    assert_eq!(
        e.to_string(),
        "`3 kg*m/s3` is a quantity in kg*m/s3 but an energy is expected here \
         (e.g. \"2500 kJ\", \"1 MMBtu\" or a bare number in J)"
    );
    // A rate per amount is not a molar flow.
    assert!(matches!(parse_quantity_as("10 kmol/min/kmol", D::MOLAR_FLOW), Err(UnitError::WrongDimension { .. })));
    assert!(matches!(parse_quantity_as("1 kW", D::ENERGY), Err(UnitError::WrongDimension { .. })));
}

#[test]
fn unknown_units_with_suggestions() {
    let e = err("3 furlongs");
    assert_eq!(e, UnitError::UnknownUnit { unit: "furlongs".into(), text: "3 furlongs".into(), suggestion: None });
    assert_eq!(e.to_string(), "unknown unit `furlongs` in `3 furlongs`");

    let e = err("1 kmols/h");
    assert_eq!(e.to_string(), "unknown unit `kmols` in `1 kmols/h` (did you mean `kmol`?)");
    let suggestion = |t: &str| match err(t) {
        UnitError::UnknownUnit { suggestion, .. } => suggestion,
        other => panic!("{t}: {other:?}"),
    };
    assert_eq!(suggestion("80 C").as_deref(), Some("degC"));
    assert_eq!(suggestion("176 F").as_deref(), Some("degF"));
    assert_eq!(suggestion("10 KW").as_deref(), Some("kW"));
    assert_eq!(suggestion("1e6 BTU/h").as_deref(), Some("Btu"));
    assert_eq!(suggestion("2 hours").as_deref(), Some("h"));
    assert_eq!(suggestion("1 Kmol/min").as_deref(), Some("kmol"));
    assert_eq!(suggestion("4 m3/furlong").as_deref(), None);
}

#[test]
fn bad_numbers() {
    for text in ["1e400 K", "-1e400 K", "inf K", "NaN", "infinity", "abc", "kmol/min", "K", ". m", "- 5 K"] {
        assert!(matches!(err(text), UnitError::BadNumber { .. }), "{text}: {:?}", err(text));
    }
    assert_eq!(err("1e400 K").to_string(), "`1e400 K`: 1e400 is not a finite number");
    assert_eq!(err("abc").to_string(), "`abc`: expected a number first, e.g. \"1 kmol/min\"");
    // Finite as written but overflows in SI.
    assert_eq!(err("1e306 MMBtu").to_string(), "`1e306 MMBtu`: the value is out of range in SI units");
}

#[test]
fn empty() {
    assert_eq!(err(""), UnitError::Empty);
    assert_eq!(err("  \t "), UnitError::Empty);
    assert_eq!(parse_quantity_as("", D::TIME).unwrap_err(), UnitError::Empty);
}

#[test]
fn affine_in_compound() {
    let e = err("80 degC/min");
    assert_eq!(e, UnitError::AffineInCompound { unit: "degC".into(), text: "80 degC/min".into(), linear: "K".into() });
    assert_eq!(
        e.to_string(),
        "`80 degC/min`: `degC` has an offset zero, so it may only stand alone as an absolute temperature \
         (\"80 degC\") or be per degree in a denominator (\"kJ/(kmol*degC)\"); \
         for a temperature change write `K` (e.g. \"K/min\")"
    );
    for (text, unit, linear) in [
        ("2 degF/h", "degF", "degR"),
        ("3 °C*h", "°C", "K"),
        ("1 degC^2", "degC", "K"),
        ("30 psig/s", "psig", "psi"),
        ("1 kJ/(kmol*psig)", "psig", "psi"),
        ("1 barg*m3", "barg", "bar"),
    ] {
        assert_eq!(
            err(text),
            UnitError::AffineInCompound { unit: unit.into(), text: text.into(), linear: linear.into() },
            "{text}"
        );
    }
    assert_eq!(
        err("30 psig/s").to_string(),
        "`30 psig/s`: `psig` is a gauge pressure, so it may only stand alone (\"30 psig\"); \
         inside a compound unit write `psi`"
    );
}

#[test]
fn syntax_errors() {
    let cases = [
        (
            "8000 J/mol*K",
            "`8000 J/mol*K`: `*` after `/` is ambiguous: put the whole denominator in parentheses, e.g. J/(mol*K)",
        ),
        (
            "1 kJ/kmol K",
            "`1 kJ/kmol K`: expected `*` or `/` between units (units written side by side are not supported)",
        ),
        ("1 J/(mol*K", "`1 J/(mol*K`: missing `)`"),
        ("1 m)", "`1 m)`: unmatched `)`"),
        ("1 m^", "`1 m^`: `^` must be followed by an integer exponent, e.g. m^3 or s^-1"),
        ("1 kmol/", "`1 kmol/`: a unit is missing at the end"),
        ("5 10/min", "`5 10/min`: the only number allowed in a unit is 1, as in 1/min"),
        ("1.5.2", "`1.5.2`: unexpected `.` where a unit is expected"),
        ("1 m3^2", "`1 m3^2`: two exponents on one unit"),
        ("1 m^200", "`1 m^200`: exponent out of range"),
        ("1, 2", "`1, 2`: unexpected `,` where a unit is expected"),
    ];
    for (text, message) in cases {
        let e = err(text);
        assert!(matches!(e, UnitError::Syntax { .. }), "{text}: {e:?}");
        assert_eq!(e.to_string(), message);
    }
}

#[test]
fn conversion_errors() {
    assert!(matches!(convert_from_si(1.0, "furlong"), Err(UnitError::UnknownUnit { .. })));
    assert!(matches!(convert_from_si(1.0, ""), Err(UnitError::Syntax { .. })));
    assert!(matches!(unit_dimension("degC/min"), Err(UnitError::AffineInCompound { .. })));
    let e = Quantity::new(12.6, D::MOLAR_FLOW).in_unit("K").unwrap_err();
    assert_eq!(
        e.to_string(),
        "`K` is a temperature but a molar flow is expected here \
         (e.g. \"1 kmol/min\", \"100 lbmol/h\" or a bare number in mol/s)"
    );
}

#[test]
fn messages_are_lowercase_without_trailing_period() {
    let texts = ["", "abc", "1e400 K", "3 furlongs", "80 degC/min", "1 J/(mol", "1 kmols"];
    for t in texts {
        let m = err(t).to_string();
        assert!(!m.ends_with('.'), "{m}");
        assert!(!m.starts_with(char::is_uppercase), "{m}");
    }
    let m = parse_quantity_as("5 K", D::PRESSURE).unwrap_err().to_string();
    assert!(!m.ends_with('.') && !m.starts_with(char::is_uppercase), "{m}");
}
