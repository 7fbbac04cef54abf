//! Reverse mode on the tape: the adjoint pass that gives a whole gradient row.

use std::convert::Infallible;

use num_dual::Dual64;

use super::{Hook, Instr, Load, Op, Slot, Source, Tape, Val};
use crate::ast::Func;

/// Reusable buffers for [`Tape::gradient_in`], so that repeated gradients do not allocate.
#[derive(Debug, Clone, Default)]
pub struct Workspace {
    values: Vec<f64>,
    adjoints: Vec<f64>,
    trace: Vec<u32>,
}

impl Workspace {
    /// Empty buffers; they grow to the largest tape used with them.
    pub fn new() -> Self {
        Self::default()
    }
}

impl Tape {
    /// The value and its exact gradient by reverse mode (the adjoint of the tape): one `f64`
    /// pass forward that records the instructions executed, one pass back over them that
    /// accumulates `∂value/∂slot` (Griewank & Walther, *Evaluating Derivatives*, 2nd ed., SIAM
    /// 2008, §3.2). Costs a few forward passes however many variables the expression reads,
    /// where forward-mode duals cost one pass per variable. The partials are **added** to
    /// `d_x[i]` and `d_dx[i]` at the indices of [`Tape::variables`] and [`Tape::derivatives`]
    /// (zero them first, or accumulate `∂F/∂x + cj·∂F/∂ẋ` by pre-scaling is up to the caller).
    ///
    /// The derivatives are those of the branch taken by `if`, `min` and `max`, and of the
    /// interval a table lookup falls in, as with dual numbers.
    ///
    /// # Panics
    /// If `x`, `dx`, `d_x` or `d_dx` is shorter than [`Tape::required_lengths`].
    pub fn gradient_in(&self, x: &[f64], dx: &[f64], ws: &mut Workspace, d_x: &mut [f64], d_dx: &mut [f64]) -> f64 {
        ws.values.clear();
        ws.values.resize(self.n_slots, 0.0);
        ws.trace.clear();
        let value = match self.run(x, dx, &mut ws.values, &mut Trace(&mut ws.trace)) {
            Ok(v) => v,
            Err(never) => match never {},
        };
        let Val::Slot(out) = self.out else { return value };
        ws.adjoints.clear();
        ws.adjoints.resize(self.n_slots, 0.0);
        ws.adjoints[out as usize] = 1.0;
        for &k in ws.trace.iter().rev() {
            let ins = self.code[k as usize];
            let g = ws.adjoints[ins.dst as usize];
            if g != 0.0 {
                self.adjoint(ins, g, &ws.values, &mut ws.adjoints);
            }
        }
        for load in &self.loads {
            let g = ws.adjoints[load.slot as usize];
            match load.src {
                Source::X(i) => d_x[i as usize] += g,
                Source::Dx(i) => d_dx[i as usize] += g,
            }
        }
        value
    }

    /// Adds `g · ∂(ins)/∂(operand)` to each operand's adjoint.
    fn adjoint(&self, ins: Instr, g: f64, v: &[f64], adj: &mut [f64]) {
        let at = |s: Slot| v[s as usize];
        let out = v[ins.dst as usize];
        let mut add = |s: Slot, d: f64| adj[s as usize] += d;
        match ins.op {
            Op::Add(a, b) => {
                add(a, g);
                add(b, g);
            }
            Op::Sub(a, b) => {
                add(a, g);
                add(b, -g);
            }
            Op::Mul(a, b) => {
                add(a, g * at(b));
                add(b, g * at(a));
            }
            Op::Div(a, b) => {
                add(a, g / at(b));
                add(b, -g * out / at(b));
            }
            Op::AddC(a, _) | Op::Mov(a) => add(a, g),
            Op::CSub(_, a) | Op::Neg(a) => add(a, -g),
            Op::MulC(a, c) => add(a, g * c),
            Op::DivC(a, c) => add(a, g / c),
            Op::CDiv(_, a) => add(a, -g * out / at(a)),
            Op::Powi(a, n) => add(a, if n == 0 { 0.0 } else { g * f64::from(n) * at(a).powi(n - 1) }),
            Op::Powf(a, p) => add(a, g * p * at(a).powf(p - 1.0)),
            Op::Pow(a, b) => {
                add(a, g * out * at(b) / at(a));
                add(b, g * out * at(a).ln());
            }
            Op::Func1(f, a) => add(a, g * func1_derivative(f, at(a), out)),
            Op::Func2(Func::Min | Func::Max, a, b) => {
                let first = if matches!(ins.op, Op::Func2(Func::Min, ..)) { at(a) <= at(b) } else { at(a) >= at(b) };
                add(if first { a } else { b }, g);
            }
            Op::Func2(_, a, b) => {
                add(a, g * at(a) / out);
                add(b, g * at(b) / out);
            }
            Op::Func3(f, a, b, e) => {
                let (d, eps) = (at(a) - at(b), at(e));
                let root = (d * d + eps * eps).sqrt();
                let sign = if f == Func::SmoothMax { 1.0 } else { -1.0 };
                add(a, g * 0.5 * (1.0 + sign * d / root));
                add(b, g * 0.5 * (1.0 - sign * d / root));
                add(e, g * 0.5 * sign * eps / root);
            }
            Op::Table(t, a) => add(a, g * self.tables[t as usize].eval(Dual64::new(at(a), 1.0)).eps),
            Op::External(e) => {
                let node = &self.externals[e as usize];
                let inputs: Vec<f64> = node.args.iter().map(|&s| at(s)).collect();
                let mut d = vec![0.0; inputs.len()];
                node.eval.value_and_partials(&inputs, &mut d);
                for (&s, dk) in node.args.iter().zip(d) {
                    add(s, g * dk);
                }
            }
            Op::Const(_) | Op::Cmp(..) | Op::And(..) | Op::Or(..) | Op::Not(_) | Op::JumpIfFalse(..) | Op::Jump(_) => {}
        }
    }
}

/// d f(a)/da for the one-argument built-ins, given `a` and `out = f(a)`.
fn func1_derivative(f: Func, a: f64, out: f64) -> f64 {
    match f {
        Func::Exp => out,
        Func::Ln => 1.0 / a,
        Func::Log10 => 1.0 / (a * std::f64::consts::LN_10),
        Func::Sqrt => 0.5 / out,
        // As num-dual's `abs`: +1 for +0.0 and positive numbers, −1 otherwise.
        Func::Abs => {
            if a.is_sign_positive() {
                1.0
            } else {
                -1.0
            }
        }
        _ => f64::NAN,
    }
}

/// Records the instructions executed, for the reverse pass.
struct Trace<'a>(&'a mut Vec<u32>);

impl<S> Hook<S> for Trace<'_> {
    type Err = Infallible;
    #[inline(always)]
    fn load(&mut self, _: &Load, _: S) -> Result<(), Infallible> {
        Ok(())
    }
    #[inline(always)]
    fn before(&mut self, _: usize, _: &Op, _: &[S]) -> Result<(), Infallible> {
        Ok(())
    }
    #[inline(always)]
    fn after(&mut self, k: usize, _: S) -> Result<(), Infallible> {
        self.0.push(k as u32);
        Ok(())
    }
}
