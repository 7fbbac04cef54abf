//! Integration tests of plantwide-expr through its public API (one binary).

mod dimensions;
mod eval;
mod guess;
mod parse;
mod structure;
mod tables;

use plantwide_expr::{Expression, SymbolTable, VarKind};
use plantwide_units::Dimension;

/// Symbols for small tests: dimensionless variables `a`, `b`, `c` at slots 0..3, a temperature
/// `T` (differential) at 3, a molar flow `F` at 4, a holdup `M` (differential) at 5, a pressure
/// `P` at 6, an area `A` at 7, parameters `Tmin` (K), `two` (dimensionless) and `V` (m³).
pub fn small_symbols() -> SymbolTable {
    let mut s = SymbolTable::new();
    for (i, n) in ["a", "b", "c"].iter().enumerate() {
        s.add_variable(n, i, Dimension::DIMENSIONLESS, VarKind::Algebraic).unwrap();
    }
    s.add_variable("T", 3, Dimension::TEMPERATURE, VarKind::Differential).unwrap();
    s.add_variable("F", 4, Dimension::MOLAR_FLOW, VarKind::Algebraic).unwrap();
    s.add_variable("M", 5, Dimension::AMOUNT, VarKind::Differential).unwrap();
    s.add_variable("P", 6, Dimension::PRESSURE, VarKind::Algebraic).unwrap();
    s.add_variable("A", 7, Dimension::AREA, VarKind::Algebraic).unwrap();
    s.add_parameter("Tmin", 300.0, Dimension::TEMPERATURE).unwrap();
    s.add_parameter("two", 2.0, Dimension::DIMENSIONLESS).unwrap();
    s.add_parameter("V", 0.5, Dimension::VOLUME).unwrap();
    s
}

/// The value of an expression of `small_symbols()` at x = [a, b, c, T, F, M, P, A].
pub fn value(text: &str, x: &[f64; 8]) -> f64 {
    let e = Expression::new(text, &small_symbols()).unwrap_or_else(|e| panic!("{}", e.render()));
    e.value(x, &[0.0; 8])
}

/// The error kind of an expression that must fail.
pub fn expr_error(text: &str) -> plantwide_expr::ExprError {
    match Expression::new(text, &small_symbols()) {
        Ok(_) => panic!("`{text}` was accepted"),
        Err(e) => e,
    }
}

/// Asserts a relative closeness.
pub fn close(got: f64, want: f64, rtol: f64) {
    assert!((got - want).abs() <= rtol * want.abs().max(1e-300), "got {got}, want {want}");
}
