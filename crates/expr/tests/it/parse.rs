//! Syntax: precedence, names, spans, and syntax errors located in the text.

use plantwide_expr::ast::{BinOp, ExprKind};
use plantwide_expr::{ErrorKind, MAX_DEPTH, MAX_TEXT_LEN, Span, parse_equation, parse_expression};

use crate::{expr_error, value};

const X: [f64; 8] = [3.0, 2.0, 5.0, 350.0, 10.0, 100.0, 1.0e5, 2.0];

#[test]
fn precedence_and_associativity() {
    // Each pair: text and its value with a = 3, b = 2, c = 5, worked by hand.
    let cases = [
        ("-a^2", -9.0), // unary minus below ^ (Modelica): -(a^2)
        ("(-a)^2", 9.0),
        ("b^c^0", 2.0),           // right-associative: b^(c^0) = b^1
        ("b^b^c", 2f64.powi(32)), // 2^(2^5)
        ("a - b - c", -4.0),      // left-associative
        ("c / b / b", 1.25),
        ("a + b * c", 13.0),
        ("a * b ^ b", 12.0),
        ("b^-1", 0.5), // a signed exponent
        ("-a * -b", 6.0),
        ("1.5e1 + .5 + 2E-1 + 3.", 18.7),
        ("+a", 3.0),
    ];
    for (text, want) in cases {
        let got = value(text, &X);
        assert!((got - want).abs() < 1e-12 * want.abs(), "{text}: {got} vs {want}");
    }
}

#[test]
fn if_expressions_and_conditions() {
    let cases = [
        ("if a > b then a else b", 3.0),
        ("if a < b then a else b", 2.0),
        ("if a >= 3 and not b > 2 then 1 else 0", 1.0),
        ("if a <= 2 or c > 4 then 1 else 0", 1.0),
        ("if (a > 4 or b > 1) and c < 6 then 1 else 0", 1.0),
        ("if a > 4 then 1 elseif b > 1 then 2 else 3", 2.0),
        ("2 * (if a > b then a else b) + 1", 7.0),
        ("if a > b then a else b + 10", 3.0), // the else branch extends to the end
    ];
    for (text, want) in cases {
        assert_eq!(value(text, &X), want, "{text}");
    }
}

#[test]
fn names_are_single_tokens_with_dots_and_indices() {
    for text in ["x[benzene]", "in.F", "column.T[12]", "feed.x[n-butane]", "_a1"] {
        let e = parse_expression(text).unwrap();
        assert_eq!(e.kind, ExprKind::Name(text.to_owned()), "{text}");
        assert_eq!(e.span, Span::new(0, text.len()));
    }
}

#[test]
fn spans_cover_nodes() {
    let text = "der(M) = F/V*(a - b)";
    let eq = parse_equation(text).unwrap();
    assert_eq!(eq.lhs.span.slice(text), "der(M)");
    assert_eq!(eq.span, Span::new(0, text.len()));
    let ExprKind::Binary(BinOp::Mul, l, r) = &eq.rhs.kind else { panic!("{:?}", eq.rhs.kind) };
    assert_eq!(l.span.slice(text), "F/V");
    assert_eq!(r.span.slice(text), "(a - b)");
    let ExprKind::Der { name_span, .. } = &eq.lhs.kind else { panic!() };
    assert_eq!(name_span.slice(text), "M");
}

/// The syntax error's span (as text) and a fragment of its message.
fn syntax(text: &str) -> (String, String) {
    let e = parse_equation(text).unwrap_err();
    let ErrorKind::Syntax { message } = &e.kind else { panic!("{text}: {:?}", e.kind) };
    (e.span.slice(text).to_owned(), message.clone())
}

#[test]
fn syntax_errors_point_at_the_problem() {
    let (at, msg) = syntax("F = (a + b");
    assert_eq!(at, "");
    assert!(msg.contains("expected `)`") && msg.contains("end of the text"), "{msg}");
    let (at, msg) = syntax("F = a + * b");
    assert_eq!(at, "*");
    assert!(msg.contains("a number, a name or `(`"), "{msg}");
    let (at, msg) = syntax("F = a < b < c");
    assert_eq!(at, "<");
    assert!(msg.contains("comparisons do not chain"), "{msg}");
    let (at, msg) = syntax("F + G");
    assert_eq!(at, "");
    assert!(msg.contains("`=`"), "{msg}");
    let (at, _) = syntax("F = G = H");
    assert_eq!(at, "=");
    let (at, msg) = syntax("F = 2*if a > b then a else b");
    assert_eq!(at, "if");
    assert!(msg.contains("parentheses"), "{msg}");
    let (at, msg) = syntax("F = if a > b then a");
    assert_eq!(at, "");
    assert!(msg.contains("`else`"), "{msg}");
    let (at, _) = syntax("F = min(a b)");
    assert_eq!(at, "b");
    let (at, _) = syntax("F = der(2)");
    assert_eq!(at, "2");
    let (at, _) = syntax("F = a then");
    assert_eq!(at, "then");
}

#[test]
fn work_is_bounded() {
    let long = format!("F = {}", "a+".repeat(MAX_TEXT_LEN / 2) + "a");
    let e = parse_equation(&long).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::TooLong { max: MAX_TEXT_LEN, .. }));

    let deep = |open: &str, close: &str| format!("F = {}a{}", open.repeat(MAX_DEPTH + 1), close.repeat(MAX_DEPTH + 1));
    for text in [deep("(", ")"), deep("-", ""), deep("exp(", ")"), deep("a^", ""), deep("not ", "")] {
        let e = parse_equation(&text).unwrap_err();
        assert!(matches!(e.kind, ErrorKind::TooDeep { max: MAX_DEPTH }), "{}: {:?}", &text[..12], e.kind);
    }
    // A flat sum is a left-leaning tree as deep as it has terms.
    let sum = format!("F = {}a", "a+".repeat(MAX_DEPTH + 1));
    assert!(matches!(parse_equation(&sum).unwrap_err().kind, ErrorKind::TooDeep { .. }));
    let ok = format!("F = {}a", "a+".repeat(MAX_DEPTH / 2));
    assert!(parse_equation(&ok).is_ok());
    // Moderately nested text still parses.
    let nested = format!("F = {}a{}", "(".repeat(40), ")".repeat(40));
    assert!(parse_equation(&nested).is_ok());
}

#[test]
fn out_of_range_number() {
    let e = expr_error("a + 1e999");
    assert_eq!(e.kind, ErrorKind::NumberOutOfRange { literal: "1e999".into() });
    assert_eq!(e.span, Span::new(4, 9));
}
