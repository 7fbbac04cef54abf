//! Evaluation over f64 and over dual numbers, checked against values and derivatives worked
//! by hand.

use num_dual::Dual64;
use plantwide_expr::testing::{CSTR, CSTR_EQUATIONS, cstr_hand, cstr_symbols, slot};
use plantwide_expr::{Equation, Expression, Interpolation, Table};
use plantwide_units::Dimension;

use crate::{close, small_symbols};

/// A CSTR state: CA = 500 mol/m³, T = 350 K, F = 100 L/min, Tj = 300 K; derivatives 0.1, 0.2.
const X: [f64; 4] = [500.0, 350.0, 0.1 / 60.0, 300.0];
const DX: [f64; 4] = [0.1, 0.2, 0.0, 0.0];

/// The CSTR's residuals and their partial derivatives, derived by hand:
/// with k = k0·exp(−E/(R·T)) and dk/dT = k·E/(R·T²),
/// r1 = dCA − F/V·(CAf − CA) + k·CA
///   ∂r1/∂CA = F/V + k, ∂r1/∂T = CA·k·E/(R·T²), ∂r1/∂F = −(CAf − CA)/V, ∂r1/∂dCA = 1;
/// r2 = dT − F/V·(Tf − T) − (−ΔH)·k·CA/(ρ·cp) − UA·(Tj − T)/(V·ρ·cp)
///   ∂r2/∂T = F/V − (−ΔH)·CA/(ρ·cp)·k·E/(R·T²) + UA/(V·ρ·cp), ∂r2/∂CA = −(−ΔH)·k/(ρ·cp),
///   ∂r2/∂F = −(Tf − T)/V, ∂r2/∂Tj = −UA/(V·ρ·cp), ∂r2/∂dT = 1.
struct Hand {
    r: [f64; 2],
    /// d[i][j]: ∂r_i/∂x_j.
    d: [[f64; 4]; 2],
}

fn hand() -> Hand {
    let p = CSTR;
    let [ca, t, f, tj] = X;
    let k = p.k0 * (-p.e / (p.r * t)).exp();
    let dk_dt = k * p.e / (p.r * t * t);
    let rcp = p.rho * p.cp;
    let r1 = DX[0] - f / p.v * (p.caf - ca) + k * ca;
    let r2 = DX[1] - f / p.v * (p.tf - t) - (-p.dh) * k * ca / rcp - p.ua * (tj - t) / (p.v * rcp);
    let d1 = [f / p.v + k, ca * dk_dt, -(p.caf - ca) / p.v, 0.0];
    let d2 = [
        -(-p.dh) * k / rcp,
        f / p.v - (-p.dh) * ca / rcp * dk_dt + p.ua / (p.v * rcp),
        -(p.tf - t) / p.v,
        -p.ua / (p.v * rcp),
    ];
    Hand { r: [r1, r2], d: [d1, d2] }
}

fn cstr_equations() -> Vec<Equation> {
    let s = cstr_symbols(&CSTR);
    CSTR_EQUATIONS.iter().map(|t| Equation::new(t, &s).unwrap_or_else(|e| panic!("{}", e.render()))).collect()
}

#[test]
fn cstr_residuals_match_the_hand_formulas() {
    // The residuals are differences of terms near 10 (F/V·(CAf − CA) ≈ 8.3 mol/(m³·s)), so
    // the tolerance is absolute: a few ulps of the terms.
    let h = hand();
    let hand_rust = cstr_hand(&CSTR, &X, &DX);
    for (i, eq) in cstr_equations().iter().enumerate() {
        assert!((eq.residual(&X, &DX) - h.r[i]).abs() < 1e-13, "r{i}");
        assert!((hand_rust[i] - h.r[i]).abs() < 1e-13, "hand r{i}");
    }
}

#[test]
fn cstr_jacobian_over_duals_matches_hand_derivatives() {
    let h = hand();
    let eqs = cstr_equations();
    for j in 0..4 {
        let mut x: Vec<Dual64> = X.iter().map(|&v| Dual64::from(v)).collect();
        let dx: Vec<Dual64> = DX.iter().map(|&v| Dual64::from(v)).collect();
        x[j].eps = 1.0;
        for (i, eq) in eqs.iter().enumerate() {
            let got = eq.residual(&x, &dx).eps;
            let want = h.d[i][j];
            assert!((got - want).abs() <= 1e-12 * want.abs().max(1e-30), "∂r{i}/∂x{j}: {got} vs {want}");
        }
    }
    // Derivative columns: ∂r_i/∂dx_i = 1 and nothing else.
    let g = eqs[1].gradient(&X, &DX);
    assert_eq!(eqs[1].derivatives(), &[slot::T]);
    assert_eq!(g.d_dx, vec![1.0]);
    close(g.value, h.r[1], 1e-13);
    for (k, &j) in eqs[1].variables().iter().enumerate() {
        close(g.d_x[k], h.d[1][j], 1e-12);
    }
}

#[test]
fn sparsity_comes_from_the_expression() {
    let eqs = cstr_equations();
    assert_eq!(eqs[0].variables(), &[slot::CA, slot::T, slot::F]);
    assert_eq!(eqs[0].derivatives(), &[slot::CA]);
    assert_eq!(eqs[1].variables(), &[slot::CA, slot::T, slot::F, slot::TJ]);
    // Both branches of a variable condition count; a constant condition keeps its branch.
    let s = small_symbols();
    let e = Expression::new("if a > b then c*F else der(M)", &s).unwrap();
    assert_eq!((e.variables(), e.derivatives()), (&[0, 1, 2, 4][..], &[5][..]));
    let e = Expression::new("if two > 1 then c else F/F", &s).unwrap();
    assert_eq!((e.variables(), e.derivatives()), (&[2][..], &[][..]));
    // A name that cancels numerically still appears: the pattern is structural.
    assert_eq!(Expression::new("a - a", &s).unwrap().variables(), &[0]);
}

#[test]
fn constants_are_folded() {
    let s = cstr_symbols(&CSTR);
    // Only parameters: a constant, no instructions.
    let e = Expression::new("k0*exp(-E/(R*Tf))", &s).unwrap();
    assert!(e.tape().is_constant() && e.tape().is_empty());
    close(e.value::<f64>(&[], &[]), CSTR.k0 * (-CSTR.e / (CSTR.r * CSTR.tf)).exp(), 1e-15);
    // `F/V*(CAf - CA)`: F/V, CAf − CA and the product (F and CA are loaded before).
    let e = Expression::new("F/V*(CAf - CA)", &s).unwrap();
    assert_eq!((e.tape().len(), e.tape().is_constant()), (3, false));
}

#[test]
fn builtins_values_and_derivatives() {
    // (text, a, value, d/da), with the derivative worked by hand.
    let a = 0.3_f64;
    let eps = 0.1_f64;
    let cases: [(&str, f64, f64); 10] = [
        ("exp(2*a)", (2.0 * a).exp(), 2.0 * (2.0 * a).exp()),
        ("ln(a)", a.ln(), 1.0 / a),
        ("log10(a)", a.log10(), 1.0 / (a * 10f64.ln())),
        ("sqrt(a)", a.sqrt(), 0.5 / a.sqrt()),
        ("abs(-a)", a, 1.0),
        ("a^3", a.powi(3), 3.0 * a * a),
        ("a^2.5", a.powf(2.5), 2.5 * a.powf(1.5)),
        ("2^a", 2f64.powf(a), 2f64.powf(a) * 2f64.ln()),
        // smooth_abs(x, e) = sqrt(x² + e²): d/dx = x / sqrt(x² + e²).
        ("smooth_abs(a, 0.1)", (a * a + eps * eps).sqrt(), a / (a * a + eps * eps).sqrt()),
        // smooth_max(a, 0, e) = (a + sqrt(a² + e²))/2: d/da = (1 + a/sqrt(a² + e²))/2.
        ("smooth_max(a, 0, 0.1)", (a + (a * a + eps * eps).sqrt()) / 2.0, (1.0 + a / (a * a + eps * eps).sqrt()) / 2.0),
    ];
    let s = small_symbols();
    for (text, value, deriv) in cases {
        let e = Expression::new(text, &s).unwrap();
        let mut x = [Dual64::from(0.0); 8];
        x[0] = Dual64::new(a, 1.0);
        let got = e.value(&x, &[Dual64::from(0.0); 8]);
        close(got.re, value, 1e-14);
        close(got.eps, deriv, 1e-13);
    }
    // smooth_min(a, 0, e) = (a − sqrt(a² + e²))/2.
    let got = crate::value("smooth_min(a, 0, 0.1)", &[a, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    close(got, (a - (a * a + eps * eps).sqrt()) / 2.0, 1e-14);
    // min and max pick an argument, with its derivative.
    let e = Expression::new("max(a, b) + 10*min(a, b)", &s).unwrap();
    let mut x = [Dual64::from(0.0); 8];
    x[0] = Dual64::new(2.0, 1.0);
    x[1] = Dual64::new(1.0, 0.0);
    let got = e.value(&x, &[Dual64::from(0.0); 8]);
    assert_eq!((got.re, got.eps), (2.0 + 10.0, 1.0));
    // (-2)^3 is an integer power of a negative base: fine.
    close(crate::value("a^3", &[-2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]), -8.0, 1e-15);
}

#[test]
fn if_takes_the_branch_of_its_condition_with_its_derivative() {
    let s = small_symbols();
    let e = Expression::new("if a > 0 then a^2 else -a", &s).unwrap();
    for (a, value, deriv) in [(3.0, 9.0, 6.0), (-3.0, 3.0, -1.0)] {
        let mut x = [Dual64::from(0.0); 8];
        x[0] = Dual64::new(a, 1.0);
        let got = e.value(&x, &[Dual64::from(0.0); 8]);
        assert_eq!((got.re, got.eps), (value, deriv));
    }
}

#[test]
fn table_lookup_inside_an_equation() {
    let mut s = small_symbols();
    // A vapour pressure table psat(T) through (300 K, 1 bar), (350 K, 4 bar), (400 K, 9 bar).
    let t = Table::new(
        vec![300.0, 350.0, 400.0],
        vec![1.0e5, 4.0e5, 9.0e5],
        Interpolation::Linear,
        Dimension::TEMPERATURE,
        Dimension::PRESSURE,
    )
    .unwrap();
    s.add_table("psat", t).unwrap();
    let eq = Equation::new("P = psat(T)", &s).unwrap();
    let mut x = [Dual64::from(0.0); 8];
    x[3] = Dual64::new(375.0, 1.0);
    x[6] = Dual64::from(6.0e5);
    let r = eq.residual(&x, &[Dual64::from(0.0); 8]);
    // psat(375) = 4e5 + 25·(5e5/50) = 6.5e5, slope 1e4 Pa/K.
    assert_eq!((r.re, r.eps), (6.0e5 - 6.5e5, -1.0e4));
}

#[test]
fn reverse_mode_gradient_matches_hand_derivatives() {
    let h = hand();
    let mut ws = plantwide_expr::Workspace::new();
    for (i, eq) in cstr_equations().iter().enumerate() {
        let (mut d_x, mut d_dx) = ([0.0; 4], [0.0; 4]);
        let r = eq.gradient_in(&X, &DX, &mut ws, &mut d_x, &mut d_dx);
        assert!((r - h.r[i]).abs() < 1e-13);
        for (j, (got, want)) in d_x.iter().zip(h.d[i]).enumerate() {
            assert!((got - want).abs() <= 1e-12 * want.abs().max(1e-30), "∂r{i}/∂x{j}: {got} vs {want}");
        }
        // ∂r_i/∂ẋ is the unit vector e_i.
        let mut e_i = [0.0; 4];
        e_i[i] = 1.0;
        assert_eq!(d_dx, e_i);
    }
}

/// Reverse mode and forward duals are two routes to one derivative: every operation, both
/// branches of `if`, both arguments of `min`/`max`, tables of both kinds.
#[test]
fn reverse_mode_agrees_with_forward_duals_on_every_operation() {
    let mut s = small_symbols();
    let spline = Table::new(
        vec![0.0, 1.0, 2.0, 4.0],
        vec![1.0, 2.0, 0.5, 3.0],
        Interpolation::CubicSpline,
        Dimension::DIMENSIONLESS,
        Dimension::DIMENSIONLESS,
    )
    .unwrap();
    s.add_table("spl", spline).unwrap();
    let texts = [
        "a + b - c * a / b",
        "2 - a + 3*b - b/4 + 5/c - (-a)",
        "a^3 + b^-2 + c^2.5 + a^b + 2^c",
        "exp(a*b) + ln(c) + log10(b) + sqrt(c) + abs(a - b)",
        "min(a, b)*max(b, c) + smooth_abs(a - b, 0.1) + smooth_max(a, c, 0.2) - smooth_min(b, c, 0.3)",
        "if a > b and not c < 1 then a*c else b^2 + c",
        "spl(a) * spl(c) + a*a",
        "(if a >= b or c <= 0 then exp(-a) else c) / (1 + b^2)",
    ];
    let points = [[0.7, 1.3, 2.1], [1.9, 0.4, 3.7], [-0.6, 2.2, 0.5]];
    let mut ws = plantwide_expr::Workspace::new();
    for text in texts {
        let e = Expression::new(text, &s).unwrap_or_else(|e| panic!("{}", e.render()));
        for p in points {
            let x = [p[0], p[1], p[2], 0.0, 0.0, 0.0, 0.0, 0.0];
            let (mut d_x, mut d_dx) = ([0.0; 8], [0.0; 8]);
            let v = e.tape().gradient_in(&x, &[0.0; 8], &mut ws, &mut d_x, &mut d_dx);
            if !v.is_finite() {
                continue; // e.g. c^2.5 at c < 0: no derivative to compare
            }
            for j in 0..3 {
                let mut xd = x.map(Dual64::from);
                xd[j].eps = 1.0;
                let want = e.value(&xd, &[Dual64::from(0.0); 8]);
                // Within rounding: num-dual divides through the reciprocal, f64 directly.
                assert!((v - want.re).abs() <= 1e-15 * v.abs().max(1.0), "{text} at {p:?}");
                let tol = 1e-13 * want.eps.abs().max(1.0);
                assert!((d_x[j] - want.eps).abs() <= tol, "{text} at {p:?}, ∂/∂x{j}: {} vs {}", d_x[j], want.eps);
            }
        }
    }
}
