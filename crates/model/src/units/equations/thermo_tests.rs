//! The thermodynamic functions in equations: exact Jacobians (against the package's own
//! functions over dual numbers, and central differences), sparsity, and load errors.

use num_dual::{Dual64, DualNum};
use plantwide_thermo::{ActivityModel, Component, ThermoPackage, VleModel};

use super::super::outflow::test_support::{at_guess, build_unit};
use super::*;
use crate::testing::jacobian_error;
use crate::{BuildCx, FieldError, Unit};

/// `light`/`heavy` with NRTL, so that K depends on T, P and x.
fn nrtl_package() -> ThermoPackage {
    ThermoPackage {
        components: vec![
            Component::hypothetical("light", 2.0, 0.05, 3.0e4, 350.0, 150.0, 1.0e-4),
            Component::hypothetical("heavy", 1.0, 0.08, 3.2e4, 350.0, 160.0, 1.2e-4),
        ],
        vle: VleModel::Activity(ActivityModel::Nrtl {
            a: vec![vec![0.0, 0.3], vec![-0.2, 0.0]],
            b: vec![vec![0.0, 150.0], vec![-80.0, 0.0]],
            alpha: vec![vec![0.0, 0.3], vec![0.3, 0.0]],
        }),
    }
}

/// Each function of the inlet's state as a variable; the outlet copies the inlet. Own layout:
/// out `[F, T, P, h, x_l, x_h]` = 0..6, then hl, hv, kh, kl, kp, mwv, rho, tb = 6..14 (by name);
/// inlet 14..20, input `Pd` 20.
const UNIT: &str = r#"{
    "inputs": {"Pd": "1.5 bar"},
    "variables": {"kl": {"kind": "algebraic"}, "kh": {"kind": "algebraic"}, "kp": {"kind": "algebraic"},
                  "hl": {"kind": "algebraic", "unit": "J/mol"}, "hv": {"kind": "algebraic", "unit": "J/mol"},
                  "rho": {"kind": "algebraic", "unit": "mol/m3", "guess": 1e4},
                  "tb": {"kind": "algebraic", "unit": "K", "guess": 350},
                  "mwv": {"kind": "algebraic", "unit": "kg/mol", "guess": 0.05}},
    "equations": ["kl = K(in, light)", "kh = K(in, heavy)", "kp = K(in, light, Pd)", "hl = h_L(in)",
                  "hv = h_V(in)", "rho = rho_L(in)", "tb = T_bubble(in)", "mwv = mw(in)"],
    "ports": {"inlets": ["in"],
              "outlets": {"out": {"F": "in.F", "T": "in.T", "P": "in.P", "x[light]": "in.x[light]",
                                  "x[heavy]": "in.x[heavy]"}}}
}"#;

const IN: usize = 14;

/// Partials of `f(T, P, x)` by the package's own functions over dual numbers, seeded one at a
/// time: `[∂/∂T, ∂/∂P, ∂/∂x_l, ∂/∂x_h]`.
fn dual_partials(f: impl Fn(Dual64, Dual64, &[Dual64]) -> Dual64, t: f64, p: f64, x: &[f64]) -> [f64; 4] {
    let mut res = [0.0; 4];
    for (k, d) in res.iter_mut().enumerate() {
        let seed = |j: usize, v: f64| Dual64::new(v, if j == k { 1.0 } else { 0.0 });
        *d = f(seed(0, t), seed(1, p), &[seed(2, x[0]), seed(3, x[1])]).eps;
    }
    res
}

#[test]
fn thermo_calls_have_exact_jacobians_and_their_port_sparsity() {
    let thermo = nrtl_package();
    let u = build_unit(UNIT, &thermo, Equations::build);
    let (t, p, x) = (345.0, 1.2e5, [0.4, 0.6]);
    let inlet = [10.0, t, p, thermo.h_liq(t, &x), x[0], x[1]];
    let (lay, local) = at_guess(&u, &thermo, &inlet);
    let (n, m) = (local.len(), lay.n_own());
    let (mut r, mut jac) = (vec![0.0; m], vec![0.0; m * n]);
    let io = UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 };
    u.jacobian(&io, &mut r, &mut jac);
    // The row of each equation (the matching gives each its own variable's row).
    let row_of = |text: &str| {
        let i = u.rows.iter().position(|r| matches!(r, Row::Algebraic { eq, .. } if eq.text() == text)).unwrap();
        match &u.rows[i] {
            Row::Algebraic { row, eq } => (*row, eq.clone()),
            Row::Derivative { .. } => unreachable!(),
        }
    };
    let k = |i: usize| {
        move |t: Dual64, p: Dual64, x: &[Dual64]| {
            let mut k = [Dual64::from(0.0); 2];
            nrtl_package().k_values(t, p, x, &mut k);
            k[i]
        }
    };
    let th = &thermo;
    let cases: [(&str, [f64; 4], [bool; 4]); 6] = [
        ("kl = K(in, light)", dual_partials(k(0), t, p, &x), [true; 4]),
        ("kh = K(in, heavy)", dual_partials(k(1), t, p, &x), [true; 4]),
        ("hl = h_L(in)", dual_partials(|t, _, x| th.h_liq(t, x), t, p, &x), [true, false, true, true]),
        ("hv = h_V(in)", dual_partials(|t, _, x| th.h_vap(t, x), t, p, &x), [true, false, true, true]),
        ("rho = rho_L(in)", dual_partials(|t, _, x| th.v_liq(t, x).recip(), t, p, &x), [true, false, true, true]),
        ("mwv = mw(in)", dual_partials(|_, _, x| th.mw(x), t, p, &x), [false, false, true, true]),
    ];
    let pattern = UnitModel::pattern(&u, &lay).unwrap();
    let mut worst: f64 = 0.0;
    for (text, want, reads) in cases {
        let (row, eq) = row_of(text);
        let grad = eq.gradient(&local, &[]);
        for (j, (&w, &read)) in want.iter().zip(&reads).enumerate() {
            let col = IN + [T, P, Z0, Z0 + 1][j];
            assert_eq!(pattern.contains(&(row, col)), read, "{text}: column {col} in the pattern");
            // The residual is `v − f(in)`: its partial is −∂f.
            let (fwd, rev) = (
                jac[row * n + col],
                grad.d_x
                    .get(eq.variables().iter().position(|&c| c == col).unwrap_or(usize::MAX))
                    .copied()
                    .unwrap_or(0.0),
            );
            for got in [fwd, rev] {
                let rel = (got + w).abs() / w.abs().max(1e-300);
                assert!(rel < 1e-12 || (w == 0.0 && got == 0.0), "{text} ∂/∂{col}: {got} vs {}", -w);
                if w != 0.0 {
                    worst = worst.max(rel);
                }
            }
        }
    }
    eprintln!("thermo calls: worst relative difference from the package's dual numbers {worst:.1e}");
    // K at the input Pd reads Pd (index 20), not in.P.
    let (row, _) = row_of("kp = K(in, light, Pd)");
    assert!(pattern.contains(&(row, 20)) && !pattern.contains(&(row, IN + P)));
    // T_bubble reads P and x, not T; its partials match central differences of bubble_t.
    let (row, _) = row_of("tb = T_bubble(in)");
    assert!(!pattern.contains(&(row, IN + T)) && pattern.contains(&(row, IN + P)));
    let tb = |p: f64, x: &[f64]| {
        let s: f64 = x.iter().sum();
        thermo.bubble_t(p, &[x[0] / s, x[1] / s]).unwrap().t
    };
    for (col, fd) in [
        (IN + P, (tb(p * (1.0 + 1e-6), &x) - tb(p * (1.0 - 1e-6), &x)) / (2e-6 * p)),
        (IN + Z0, (tb(p, &[x[0] + 1e-6, x[1]]) - tb(p, &[x[0] - 1e-6, x[1]])) / 2e-6),
    ] {
        let got = -jac[row * n + col];
        assert!((got - fd).abs() < 1e-6 * fd.abs(), "∂T_bubble/∂{col}: {got} vs {fd}");
    }
    let err = jacobian_error(&u, &lay, &thermo, &local, m);
    eprintln!("thermo calls: largest mismatch against central differences {err:.1e}");
    assert!(err < 1e-6, "{err}");
}

fn build_err(patch: &str) -> Vec<FieldError> {
    let thermo = nrtl_package();
    let names = ["light".to_string(), "heavy".to_string()];
    let mut v: serde_json::Value = serde_json::from_str(UNIT).unwrap();
    for (k, x) in serde_json::from_str::<serde_json::Value>(patch).unwrap().as_object().unwrap() {
        v[k] = x.clone();
    }
    let c: EquationsConfig = serde_json::from_value(v).unwrap();
    Equations::build(&c, BuildCx::new(&names, &thermo, "units.u"), ()).unwrap_err()
}

#[test]
fn bad_thermo_calls_are_located() {
    let eqs = |first: &str| {
        format!(
            r#"{{"equations": ["{first}", "kh = K(in, heavy)", "kp = K(in, light, Pd)", "hl = h_L(in)", "hv = h_V(in)", "rho = rho_L(in)", "tb = T_bubble(in)", "mwv = mw(in)"]}}"#
        )
    };
    let cases = [
        ("kl = K(inn, light)", "`K`: `inn` is not a port of the unit (ports: out, in)\nkl = K(inn, light)\n       ^^^"),
        (
            "kl = K(in, lite)",
            "`K`: `lite` is not a component (components: light, heavy)\nkl = K(in, lite)\n           ^^^^",
        ),
        ("kl = K(in)", "`K`: called with 1 argument(s), as `K(port, component[, P])`\nkl = K(in)\n     ^^^^^"),
        ("kl = K(in, light, T)", "`K`: `T` is not a pressure of the unit (pressures: Pd, in.P, out.P)"),
        ("kl = K_V(in, light)", "unknown name `K_V`"),
        ("kl = h_L(in)", "the two sides of the equation must have the same dimension, found dimensionless and J/mol"),
        ("kl = K", "`K` is a function, but a value"),
    ];
    for (first, want) in cases {
        let e = build_err(&eqs(first));
        assert_eq!(e[0].path, "units.u.equations[0]", "{first}");
        assert!(e[0].message.contains(want), "{first}: {}", e[0].message);
    }
}

#[test]
fn tables_in_the_file() {
    let thermo = nrtl_package();
    let unit = r#"{
        "tables": {"cp": {"x": [300, 350, 400], "y": [1, 1.5, 3], "x_unit": "K", "y_unit": "kJ/(kg*K)"},
                   "lvl": {"x": [0, 1, 2, 4], "y": [0, 1, 4, 16], "x_unit": "m", "y_unit": "m3",
                           "interpolation": "spline"}},
        "variables": {"c": {"kind": "algebraic", "unit": "J/(kg*K)"}, "v": {"kind": "algebraic", "unit": "m3"}},
        "equations": ["c = cp(in.T)", "v = lvl(in.P/P0)"],
        "parameters": {"P0": "1 bar/m"},
        "ports": {"inlets": ["in"], "outlets": {"out": {"F": "in.F", "T": "in.T", "P": "in.P",
                  "x[light]": "in.x[light]", "x[heavy]": "in.x[heavy]"}}}
    }"#;
    let u = build_unit(unit, &thermo, Equations::build);
    let inlet = [10.0, 325.0, 1.5e5, 0.0, 0.5, 0.5];
    let (lay, local) = at_guess(&u, &thermo, &inlet);
    let mut r = vec![0.0; lay.n_own()];
    u.residual(&UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 }, &mut r);
    // Own: out 0..6, c 6, v 7; c at the midpoint of [300, 350] K is 1.25 kJ/(kg K).
    assert!((local[6] - r[6] - 1250.0).abs() < 1e-12, "{}", local[6] - r[6]);
    assert!(jacobian_error(&u, &lay, &thermo, &local, lay.n_own()) < 1e-7);
    let tables = |t: &str| format!(r#"{{"tables": {{"cp": {t}}}, "equations": ["kl = cp(in.T)"]}}"#);
    let cases = [
        (
            r#"{"x": [300, 350, 340], "y": [1, 2, 3], "x_unit": "K"}"#,
            "units.u.tables.cp.x[2]",
            "x must be strictly increasing",
        ),
        (r#"{"x": [300, 350], "y": [1, 2, 3], "x_unit": "K"}"#, "units.u.tables.cp.y", "2 x values but 3 y values"),
        (r#"{"x": [300], "y": [1], "x_unit": "K"}"#, "units.u.tables.cp.x", "at least 2 points"),
        (
            r#"{"x": [300, 350], "y": [1, 1e306], "x_unit": "K", "y_unit": "kJ/mol"}"#,
            "units.u.tables.cp.y[1]",
            "not finite",
        ),
        (r#"{"x": [300, 350], "y": [1, 2], "x_unit": "kelvinn"}"#, "units.u.tables.cp.x_unit", ""),
    ];
    for (t, path, want) in cases {
        let e = build_err(&tables(t));
        assert_eq!(e[0].path, path, "{t}: {}", e[0].message);
        assert!(e[0].message.contains(want) && e[0].message.contains("cp") || want.is_empty(), "{t}: {}", e[0].message);
    }
    // The argument's dimension is checked against the table's x, located in the text.
    let e = build_err(
        r#"{"tables": {"cp": {"x": [300, 350], "y": [1, 2], "x_unit": "K"}}, "equations": ["kl = cp(in.P)"]}"#,
    );
    assert!(
        e[0].message.contains("the argument of table `cp` and its input must have the same dimension"),
        "{}",
        e[0].message
    );
    assert!(e[0].message.ends_with("kl = cp(in.P)\n        ^^^^"), "{}", e[0].message);
}
