//! Load-time checks at the guess values: each error names the span of the offending operand.

use plantwide_expr::{Equation, ErrorKind, Expression};

use crate::small_symbols;

/// x = [a, b, c, T, F, M, P, A] at the guess.
const GUESS: [f64; 8] = [1.0, 1.0, -4.0, 350.0, 10.0, 100.0, 1.0e5, 2.0];

fn check(text: &str) -> Result<f64, plantwide_expr::ExprError> {
    Equation::new(text, &small_symbols()).unwrap_or_else(|e| panic!("{}", e.render())).check_at(&GUESS, &[0.0; 8])
}

#[test]
fn zero_denominator_names_the_denominator() {
    let text = "der(M) = F/(a - b)";
    let e = check(text).unwrap_err();
    assert_eq!(e.kind, ErrorKind::ZeroDenominator);
    assert_eq!(e.span.slice(text), "(a - b)");
    assert_eq!(e.render(), "the denominator is zero at the guess values\nder(M) = F/(a - b)\n           ^^^^^^^");
    // A constant over a zero variable, too.
    let e = check("a = 1/(b - 1)").unwrap_err();
    assert_eq!(e.span.slice(&e.text), "(b - 1)");
    // Nonzero denominators pass and the residual is returned: 10/(1 + 1) − 0 = 5.
    assert_eq!(check("der(M) = F/(a + b)").unwrap(), -5.0);
}

#[test]
fn logarithms_and_roots_outside_their_domain() {
    let e = check("a = ln(c)").unwrap_err();
    assert_eq!(e.kind, ErrorKind::OutOfDomain { func: "ln", value: -4.0 });
    assert_eq!(e.span.slice(&e.text), "c");
    let e = check("a = log10(a - b)").unwrap_err();
    assert_eq!(e.kind, ErrorKind::OutOfDomain { func: "log10", value: 0.0 });
    let e = check("a = sqrt(c + b)").unwrap_err();
    assert_eq!(e.kind, ErrorKind::OutOfDomain { func: "sqrt", value: -3.0 });
    assert_eq!(e.span.slice(&e.text), "c + b");
    let e = check("a = c^0.5").unwrap_err();
    assert_eq!(e.kind, ErrorKind::OutOfDomain { func: "^", value: -4.0 });
    // sqrt(0) and ln of a positive are fine: sqrt(0) − 1 and ln(1) − 1.
    assert_eq!(check("a = sqrt(a - b)").unwrap(), 1.0);
    assert_eq!(check("a = ln(b)").unwrap(), 1.0);
}

#[test]
fn non_finite_values_are_located() {
    // exp(1000) overflows at the exp, before the sum.
    let e = check("a = exp(1000*b) - c").unwrap_err();
    assert_eq!(e.kind, ErrorKind::NonFinite { value: f64::INFINITY });
    assert_eq!(e.span.slice(&e.text), "exp(1000*b)");
}

#[test]
fn the_branch_not_taken_is_not_checked() {
    // c < 0 at the guess, so sqrt(c) is never evaluated.
    assert_eq!(check("a = if c > 0 then sqrt(c) else -c").unwrap(), 1.0 - 4.0);
}

#[test]
fn constant_trouble_is_refused_at_compile_time() {
    let s = small_symbols();
    let e = Expression::new("F/(two - 2)", &s).unwrap_err();
    assert_eq!(e.kind, ErrorKind::DivisionByZero);
    assert_eq!(e.span.slice(&e.text), "(two - 2)");
    let e = Expression::new("a + ln(two - 2)", &s).unwrap_err();
    assert_eq!(e.kind, ErrorKind::NonFiniteConstant { value: f64::NEG_INFINITY });
    assert_eq!(e.span.slice(&e.text), "ln(two - 2)");
}
