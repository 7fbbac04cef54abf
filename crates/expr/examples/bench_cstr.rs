//! Times residual + Jacobian of the CSTR written as equations (the tape) against the same
//! model written by hand in Rust, both over `f64` and `num_dual::Dual64`, the way the engine
//! builds a unit's Jacobian: one `f64` pass, then one `Dual64` pass per seeded column (the four
//! variables and the two derivatives).
//!
//! Run with `cargo run --release -p plantwide-expr --example bench_cstr`.

use std::hint::black_box;
use std::time::Instant;

use num_dual::Dual64;
use plantwide_expr::testing::{CSTR, CSTR_EQUATIONS, cstr_hand, cstr_symbols};
use plantwide_expr::{Equation, Workspace};

/// The state of the tests: CA = 500 mol/m³, T = 350 K, F = 100 L/min, Tj = 300 K.
const X: [f64; 4] = [500.0, 350.0, 0.1 / 60.0, 300.0];
const DX: [f64; 4] = [0.1, 0.2, 0.0, 0.0];
const N_ITER: usize = 200_000;
const N_REPEAT: usize = 7;

/// Residuals and the 2×8 Jacobian [∂r/∂x | ∂r/∂ẋ], from `eval(x, dx) -> [r0, r1]`.
fn res_and_jac(eval: impl Fn(&[Dual64], &[Dual64]) -> [Dual64; 2], r: &mut [f64; 2], jac: &mut [[f64; 8]; 2]) {
    let mut x: [Dual64; 4] = X.map(Dual64::from);
    let mut dx: [Dual64; 4] = DX.map(Dual64::from);
    for j in 0..4 {
        x[j].eps = 1.0;
        let out = eval(&x, &dx);
        x[j].eps = 0.0;
        jac[0][j] = out[0].eps;
        jac[1][j] = out[1].eps;
    }
    for j in 0..2 {
        dx[j].eps = 1.0;
        let out = eval(&x, &dx);
        dx[j].eps = 0.0;
        jac[0][4 + j] = out[0].eps;
        jac[1][4 + j] = out[1].eps;
    }
    let out = eval(&x, &dx);
    *r = [out[0].re, out[1].re];
}

/// Best-of-`N_REPEAT` nanoseconds per call of `f`.
fn time(mut f: impl FnMut()) -> f64 {
    (0..N_REPEAT)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..N_ITER {
                f();
            }
            start.elapsed().as_nanos() as f64 / N_ITER as f64
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let symbols = cstr_symbols(&CSTR);
    let eqs: Vec<Equation> = CSTR_EQUATIONS.iter().map(|t| Equation::new(t, &symbols).expect("valid")).collect();
    let p = CSTR;
    let tape = |x: &[Dual64], dx: &[Dual64]| [eqs[0].residual(x, dx), eqs[1].residual(x, dx)];
    let hand = |x: &[Dual64], dx: &[Dual64]| cstr_hand(&p, x, dx);

    // Same numbers first.
    let (mut r_t, mut j_t, mut r_h, mut j_h) = ([0.0; 2], [[0.0; 8]; 2], [0.0; 2], [[0.0; 8]; 2]);
    res_and_jac(tape, &mut r_t, &mut j_t);
    res_and_jac(hand, &mut r_h, &mut j_h);
    for i in 0..2 {
        assert!((r_t[i] - r_h[i]).abs() <= 1e-12, "residual {i}");
        for j in 0..8 {
            assert!((j_t[i][j] - j_h[i][j]).abs() <= 1e-12 * j_h[i][j].abs().max(1.0), "jac[{i}][{j}]");
        }
    }

    let t_tape = time(|| {
        let (mut r, mut j) = ([0.0; 2], [[0.0; 8]; 2]);
        res_and_jac(|x, dx| tape(black_box(x), black_box(dx)), &mut r, &mut j);
        black_box((r, j));
    });
    let t_hand = time(|| {
        let (mut r, mut j) = ([0.0; 2], [[0.0; 8]; 2]);
        res_and_jac(|x, dx| hand(black_box(x), black_box(dx)), &mut r, &mut j);
        black_box((r, j));
    });
    // Reverse mode: one recorded f64 pass and one adjoint pass per equation.
    let mut ws = Workspace::new();
    let mut rev = |r: &mut [f64; 2], jac: &mut [[f64; 8]; 2]| {
        for (i, eq) in eqs.iter().enumerate() {
            let (mut d_x, mut d_dx) = ([0.0; 4], [0.0; 4]);
            r[i] = eq.gradient_in(black_box(&X), black_box(&DX), &mut ws, &mut d_x, &mut d_dx);
            jac[i][..4].copy_from_slice(&d_x);
            jac[i][4..].copy_from_slice(&d_dx[..4]);
        }
    };
    let (mut r_r, mut j_r) = ([0.0; 2], [[0.0; 4 + 4]; 2]);
    rev(&mut r_r, &mut j_r);
    for i in 0..2 {
        assert!((r_r[i] - r_h[i]).abs() <= 1e-12, "reverse residual {i}");
        for j in 0..6 {
            assert!((j_r[i][j] - j_h[i][j]).abs() <= 1e-12 * j_h[i][j].abs().max(1.0), "reverse jac[{i}][{j}]");
        }
    }
    let t_rev = time(|| {
        let (mut r, mut j) = ([0.0; 2], [[0.0; 8]; 2]);
        rev(&mut r, &mut j);
        black_box((r, j));
    });
    let f_tape = time(|| {
        let (x, dx) = (black_box(&X), black_box(&DX));
        black_box([eqs[0].residual(x, dx), eqs[1].residual(x, dx)]);
    });
    let f_hand = time(|| {
        let (x, dx) = (black_box(&X), black_box(&DX));
        black_box(cstr_hand(&p, x, dx));
    });
    println!("CSTR, 2 equations, Jacobian 2x8 by 7 Dual64 passes (best of {N_REPEAT} x {N_ITER}):");
    println!("  residual + Jacobian: tape {t_tape:7.1} ns, hand {t_hand:7.1} ns, ratio {:.2}", t_tape / t_hand);
    println!("  tape reverse mode  : tape {t_rev:7.1} ns, hand {t_hand:7.1} ns, ratio {:.2}", t_rev / t_hand);
    println!("  residual (f64)     : tape {f_tape:7.1} ns, hand {f_hand:7.1} ns, ratio {:.2}", f_tape / f_hand);
    for eq in &eqs {
        println!("  tape of `{}`: {} instructions", eq.text(), eq.tape().len());
    }
}
