//! Name resolution and dimensional checking, with the messages a user reads.

use plantwide_expr::{Equation, ErrorKind, Expression, Interpolation, Span, SymbolTable, Table, VarKind};
use plantwide_units::Dimension;

use crate::{expr_error, small_symbols};

fn dim_of(text: &str) -> Dimension {
    Expression::new(text, &small_symbols()).unwrap_or_else(|e| panic!("{}", e.render())).dimension()
}

#[test]
fn dimensions_of_accepted_expressions() {
    let m_per_s = Dimension::new(0, 0, -1, 0, 1);
    let cases = [
        ("F", Dimension::MOLAR_FLOW),
        ("2*F", Dimension::MOLAR_FLOW), // a bare factor scales
        ("F/2", Dimension::MOLAR_FLOW),
        ("M/F", Dimension::TIME),
        ("der(M)", m_per_s), // dim(M)/time
        ("der(T)*M", Dimension::new(0, 0, -1, 1, 1)),
        ("sqrt(A)", Dimension::LENGTH), // halves the exponents
        ("V^(1/3)", Dimension::LENGTH), // constant fractional power that divides evenly
        ("A^1.5", Dimension::VOLUME),
        ("V^-1", Dimension::new(0, -3, 0, 0, 0)),
        ("A^two", Dimension::new(0, 4, 0, 0, 0)), // a dimensionless parameter is a constant
        ("a^b", Dimension::DIMENSIONLESS),        // variable exponent of a dimensionless base
        ("exp(a) + ln(b) + log10(2)", Dimension::DIMENSIONLESS),
        ("exp(T/Tmin)", Dimension::DIMENSIONLESS),
        ("abs(P)", Dimension::PRESSURE),
        ("max(F, 0) + min(F, 0)", Dimension::MOLAR_FLOW), // the literal 0 takes any dimension
        ("if T > Tmin then T else Tmin", Dimension::TEMPERATURE),
        ("if T > Tmin then T else 0", Dimension::TEMPERATURE),
        ("-T", Dimension::TEMPERATURE),
        ("a + 1", Dimension::DIMENSIONLESS), // bare numbers are fine with dimensionless
    ];
    for (text, want) in cases {
        assert_eq!(dim_of(text), want, "{text}");
    }
}

#[test]
fn mismatch_names_both_dimensions_and_the_span() {
    let e = expr_error("T + F");
    assert_eq!(
        e.kind,
        ErrorKind::DimensionMismatch {
            what: "the operands of `+`".into(),
            left: Dimension::TEMPERATURE,
            right: Dimension::MOLAR_FLOW
        }
    );
    assert_eq!(e.span, Span::new(0, 5));
    assert_eq!(e.kind.to_string(), "the operands of `+` must have the same dimension, found K and mol/s");
    assert_eq!(e.render(), "the operands of `+` must have the same dimension, found K and mol/s\nT + F\n^^^^^");

    let text = "der(M) = F*T";
    let e = Equation::new(text, &small_symbols()).unwrap_err();
    assert_eq!(
        e.kind.to_string(),
        "the two sides of the equation must have the same dimension, found mol/s and K*mol/s"
    );
    assert_eq!(e.span, Span::new(0, text.len()));
    // Display carries the position and the text for logs.
    assert_eq!(
        e.to_string(),
        "the two sides of the equation must have the same dimension, found mol/s and K*mol/s \
         (at bytes 0..12 of `der(M) = F*T`)"
    );
}

#[test]
fn bare_numbers_next_to_dimensions_are_refused() {
    let e = expr_error("T + 273.15");
    assert_eq!(e.kind, ErrorKind::BareNumber { literal: "273.15".into(), dim: Dimension::TEMPERATURE });
    assert_eq!(e.span, Span::new(4, 10));
    assert!(e.kind.to_string().contains("declare it as a parameter with units"));
    // Comparisons, min/max and equation sides follow the same rule.
    assert!(matches!(expr_error("if T > 300 then a else b").kind, ErrorKind::BareNumber { .. }));
    assert!(matches!(expr_error("max(F, 1)").kind, ErrorKind::BareNumber { .. }));
    assert!(
        matches!(expr_error("(2 + 3) - F").kind, ErrorKind::BareNumber { ref literal, .. } if literal == "(2 + 3)")
    );
    let e = Equation::new("F = 5", &small_symbols()).unwrap_err();
    assert_eq!(e.kind, ErrorKind::BareNumber { literal: "5".into(), dim: Dimension::MOLAR_FLOW });
    // But zero is zero in any unit.
    assert!(Equation::new("der(M) = 0", &small_symbols()).is_ok());
}

#[test]
fn functions_and_powers() {
    let e = expr_error("exp(T)");
    assert_eq!(
        e.kind,
        ErrorKind::NotDimensionless { what: "the argument of `exp`".into(), dim: Dimension::TEMPERATURE }
    );
    assert_eq!(e.span, Span::new(4, 5));
    assert!(matches!(expr_error("ln(P)").kind, ErrorKind::NotDimensionless { .. }));
    assert_eq!(expr_error("sqrt(T)").kind, ErrorKind::OddRoot { dim: Dimension::TEMPERATURE });
    assert_eq!(expr_error("T^0.5").kind, ErrorKind::FractionalPower { dim: Dimension::TEMPERATURE, exponent: 0.5 });
    assert_eq!(expr_error("T^a").kind, ErrorKind::NonConstantExponent { dim: Dimension::TEMPERATURE });
    assert!(matches!(expr_error("a^T").kind, ErrorKind::NotDimensionless { .. }));
    assert!(matches!(expr_error("min(T, F)").kind, ErrorKind::DimensionMismatch { .. }));
    assert!(matches!(expr_error("smooth_abs(F, T)").kind, ErrorKind::DimensionMismatch { .. }));
    assert_eq!(expr_error("min(a)").kind, ErrorKind::Arity { func: "min".into(), expected: 2, found: 1 });
    assert_eq!(dim_of("smooth_max(T, Tmin, Tmin)"), Dimension::TEMPERATURE);
}

#[test]
fn names_resolve_with_suggestions() {
    let e = expr_error("Tmn + T");
    assert_eq!(e.kind, ErrorKind::UnknownName { name: "Tmn".into(), suggestion: Some("Tmin".into()) });
    assert_eq!(e.span, Span::new(0, 3));
    assert_eq!(e.kind.to_string(), "unknown name `Tmn`; did you mean `Tmin`?");
    assert_eq!(expr_error("zzz").kind, ErrorKind::UnknownName { name: "zzz".into(), suggestion: None });
    // der() only of differential variables.
    assert_eq!(expr_error("der(F)").kind, ErrorKind::NotDifferential { name: "F".into() });
    assert!(matches!(expr_error("der(Tmin)").kind, ErrorKind::WrongKind { found: "a parameter", .. }));
    let e = expr_error("der(Tt)");
    assert_eq!(e.span.slice(&e.text), "Tt");
    assert!(matches!(e.kind, ErrorKind::UnknownName { suggestion: Some(ref s), .. } if s == "T"));
}

#[test]
fn conditions_and_numbers_do_not_mix() {
    assert_eq!(expr_error("a + (b > c)").kind, ErrorKind::ConditionAsNumber);
    assert_eq!(expr_error("if a then b else c").kind, ErrorKind::NumberAsCondition);
    let e = expr_error("if a > b then T else F");
    assert!(matches!(e.kind, ErrorKind::DimensionMismatch { ref what, .. } if what == "the two branches of `if`"));
}

#[test]
fn tables_check_their_input_and_give_their_output() {
    let mut s = small_symbols();
    let t = Table::new(
        vec![300.0, 400.0],
        vec![1.0e5, 3.0e5],
        Interpolation::Linear,
        Dimension::TEMPERATURE,
        Dimension::PRESSURE,
    )
    .unwrap();
    s.add_table("psat", t).unwrap();
    assert_eq!(Expression::new("psat(T) - P", &s).unwrap().dimension(), Dimension::PRESSURE);
    let e = Expression::new("psat(F)", &s).unwrap_err();
    assert!(matches!(
        e.kind,
        ErrorKind::DimensionMismatch { left: Dimension::MOLAR_FLOW, right: Dimension::TEMPERATURE, .. }
    ));
    let e = Expression::new("psat + P", &s).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::WrongKind { found: "a table", .. }));
    let e = Expression::new("psat(T, T)", &s).unwrap_err();
    assert_eq!(e.kind, ErrorKind::Arity { func: "psat".into(), expected: 1, found: 2 });
    let e = Expression::new("F(T)", &s).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::WrongKind { found: "a variable", .. }));
    let e = Expression::new("psatt(T)", &s).unwrap_err();
    assert_eq!(e.span.slice(&e.text), "psatt");
    assert!(matches!(e.kind, ErrorKind::UnknownName { suggestion: Some(ref s), .. } if s == "psat"));
}

#[test]
fn dimension_exponents_that_overflow_are_errors_not_panics() {
    let mut s = SymbolTable::new();
    s.add_variable("L", 0, Dimension::new(0, 100, 0, 0, 0), VarKind::Algebraic).unwrap();
    let e = Expression::new("L*L", &s).unwrap_err();
    assert_eq!(e.kind, ErrorKind::DimensionOverflow);
    assert_eq!(Expression::new("L^2", &s).unwrap_err().kind, ErrorKind::DimensionOverflow);
}
