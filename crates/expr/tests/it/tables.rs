//! Tables and external functions in expressions: values at the knots and between them, the
//! natural spline against SciPy, and exact derivatives over f64, dual numbers and reverse mode.

use std::sync::Arc;

use num_dual::Dual64;
use plantwide_expr::{
    BindError, Equation, ErrorKind, ExternalCall, ExternalEval, ExternalFunction, Interpolation, SymbolTable, Table,
    VarKind,
};
use plantwide_units::Dimension;

use crate::close;

/// Knots and values of `tools/spline_reference.py`.
const X: [f64; 6] = [300.0, 310.0, 325.0, 345.0, 350.0, 380.0];
const Y: [f64; 6] = [0.35, 0.52, 0.91, 1.73, 2.01, 4.12];

// Output of `/work/main/target/ci-venv/bin/python tools/spline_reference.py`:
// scipy 1.17.1, numpy 2.4.6: CubicSpline(x, y, bc_type="natural")
const SPLINE_REFERENCE: [(f64, f64, f64); 13] = [
    (301.0, 0.36556282923163624, 0.015591862984532532),
    (305.0, 0.4295561713319556, 0.01663707808879705),
    (309.5, 0.510155374318993, 0.0194787566535162),
    (312.0, 0.5615332746084428, 0.021622148746529745),
    (317.5, 0.6929551005072329, 0.026108992422819215),
    (324.0, 0.878689594979161, 0.030958217379506124),
    (330.0, 1.0777526770618073, 0.03558873442294446),
    (340.0, 1.4833031185421757, 0.046114628342413415),
    (346.0, 1.783407366773123, 0.05409293756653512),
    (348.5, 1.922719928611685, 0.057298654893856805),
    (351.0, 2.069611442864995, 0.060162890183062985),
    (365.0, 3.0015522261882395, 0.07174328386248358),
    (379.0, 4.044033130996862, 0.0759543361095456),
];

/// `tab(T)` with `T` a temperature at slot 0, the table in K → bar.
fn table_equation(i: Interpolation) -> Equation {
    let mut s = SymbolTable::new();
    s.add_variable("T", 0, Dimension::TEMPERATURE, VarKind::Algebraic).unwrap();
    s.add_variable("p", 1, Dimension::PRESSURE, VarKind::Algebraic).unwrap();
    let y: Vec<f64> = Y.iter().map(|v| v * 1e5).collect();
    s.add_table("tab", Table::new(X.to_vec(), y, i, Dimension::TEMPERATURE, Dimension::PRESSURE).unwrap()).unwrap();
    Equation::new("p = tab(T)", &s).unwrap()
}

/// `(value, d value/dT)` of the table through the equation `p = tab(T)` (residual p − tab(T)),
/// by f64, by a dual number and by reverse mode; the three must agree.
fn through_equation(eq: &Equation, t: f64) -> (f64, f64) {
    let value = -eq.residual(&[t, 0.0], &[]);
    let dual = -eq.residual(&[Dual64::new(t, 1.0), Dual64::from(0.0)], &[]);
    let grad = eq.gradient(&[t, 0.0], &[]);
    assert_eq!(dual.re, value);
    assert_eq!(-grad.d_x[0], dual.eps, "reverse mode and dual numbers at {t}");
    assert_eq!(grad.d_x[1], 1.0);
    (value, dual.eps)
}

#[test]
fn linear_table_is_exact_at_knots_and_midpoints() {
    let eq = table_equation(Interpolation::Linear);
    for k in 0..X.len() {
        assert_eq!(through_equation(&eq, X[k]).0, Y[k] * 1e5, "knot {k}");
        if k + 1 < X.len() {
            let mid = 0.5 * (X[k] + X[k + 1]);
            let (v, d) = through_equation(&eq, mid);
            close(v, 0.5 * (Y[k] + Y[k + 1]) * 1e5, 1e-15);
            close(d, (Y[k + 1] - Y[k]) * 1e5 / (X[k + 1] - X[k]), 1e-14);
        }
    }
}

#[test]
fn natural_spline_matches_scipy() {
    let eq = table_equation(Interpolation::CubicSpline);
    let mut worst: f64 = 0.0;
    for (x, y, dy) in SPLINE_REFERENCE {
        let (v, d) = through_equation(&eq, x);
        worst = worst.max(((v - y * 1e5) / (y * 1e5)).abs()).max(((d - dy * 1e5) / (dy * 1e5)).abs());
        // Central difference of the value, as an independent check of the derivative.
        let h = 1e-4;
        let fd = (through_equation(&eq, x + h).0 - through_equation(&eq, x - h).0) / (2.0 * h);
        close(d, fd, 1e-7);
    }
    eprintln!("natural spline against SciPy CubicSpline: worst relative difference {worst:.1e}");
    assert!(worst < 1e-12, "{worst:.2e}");
    for k in 0..X.len() {
        close(through_equation(&eq, X[k]).0, Y[k] * 1e5, 1e-14);
    }
}

/// `f(a, b) = a²·b` over the named variables, with exact partials: a stand-in for a thermo call.
#[derive(Debug)]
struct Product;
#[derive(Debug)]
struct ProductEval;

impl ExternalEval for ProductEval {
    fn value(&self, v: &[f64]) -> f64 {
        v[0] * v[0] * v[1]
    }
    fn value_and_partials(&self, v: &[f64], d: &mut [f64]) -> f64 {
        d[0] = 2.0 * v[0] * v[1];
        d[1] = v[0] * v[0];
        self.value(v)
    }
}

impl ExternalFunction for Product {
    fn bind(&self, args: &[&str]) -> Result<ExternalCall, BindError> {
        let slot = |k: usize| match args[k] {
            "a" => Ok(0),
            "b" => Ok(1),
            "c" => Ok(2),
            other => Err(BindError::at(k, format!("`{other}` is not a or b"))),
        };
        if args.len() != 2 {
            return Err(BindError::call("takes two names"));
        }
        Ok(ExternalCall { reads: vec![slot(0)?, slot(1)?], dim: Dimension::DIMENSIONLESS, eval: Arc::new(ProductEval) })
    }
}

fn external_symbols() -> SymbolTable {
    let mut s = SymbolTable::new();
    for (i, n) in ["a", "b", "c", "d"].iter().enumerate() {
        s.add_variable(n, i, Dimension::DIMENSIONLESS, VarKind::Algebraic).unwrap();
    }
    s.add_function("prod", Arc::new(Product)).unwrap();
    s
}

#[test]
fn external_calls_are_exact_in_every_mode_and_read_their_variables() {
    let s = external_symbols();
    let eq = Equation::new("d = exp(prod(a, b)) + prod(c, b)*a", &s).unwrap();
    assert_eq!(eq.variables(), &[0, 1, 2, 3]);
    let x: [f64; 4] = [0.7, 1.3, -0.4, 2.0];
    let (a, b, c) = (x[0], x[1], x[2]);
    let e = (a * a * b).exp();
    let want = [-(e * 2.0 * a * b + c * c * b), -(e * a * a + c * c * a), -(2.0 * c * b * a), 1.0];
    let grad = eq.gradient(&x, &[]);
    close(grad.value, x[3] - e - c * c * b * a, 1e-13);
    for (j, &w) in want.iter().enumerate() {
        close(grad.d_x[j], w, 1e-14);
        let xd: Vec<Dual64> =
            x.iter().enumerate().map(|(i, &v)| Dual64::new(v, if i == j { 1.0 } else { 0.0 })).collect();
        let r = eq.residual(&xd, &[]);
        close(r.re, grad.value, 0.0);
        close(r.eps, w, 1e-14);
    }
    // Refusals are located at the argument, or at the call.
    let err = Equation::new("d = prod(a, q)", &s).unwrap_err();
    assert_eq!(err.render(), "`prod`: `q` is not a or b\nd = prod(a, q)\n            ^");
    let err = Equation::new("d = prod(a)", &s).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::BadCall { .. }) && err.span.start == 4, "{err}");
    let err = Equation::new("d = prod", &s).unwrap_err();
    assert!(err.render().starts_with("`prod` is a function, but a value"), "{}", err.render());
    // A non-finite value at the guess is refused at the call.
    let eq = Equation::new("d = 1/prod(a, b)", &s).unwrap();
    let err = eq.check_at(&[0.0, 1.0, 0.0, 0.0], &[]).unwrap_err();
    assert_eq!(err.kind, ErrorKind::ZeroDenominator);
}
