//! The compiled form: a flat tape of operations over value slots, evaluated over any
//! [`Scalar`] (`f64`, or `num_dual::Dual64` for exact derivatives).
//!
//! Each instruction writes one slot; operands are earlier slots or immediate constants.
//! Constant sub-expressions (numbers, parameters and anything computed only from them) are
//! folded at compile time, and `x + 0`, `x*1`, `x/1` vanish. `if` compiles to a conditional jump
//! over the branch not taken, so the branch not taken is not evaluated (a `sqrt` of a negative
//! there is harmless), and both branches count in the sparsity pattern (a constant condition
//! keeps only its branch). Variables and derivatives are loaded into their slots once, before
//! the instructions run.
//!
//! Two ways to differentiate: evaluate over `Dual64` with one seeded direction per pass (how
//! the engine differentiates its built-in units), or [`Tape::gradient_in`], reverse mode, which
//! gives a whole row of the Jacobian in about three `f64` passes.

use std::convert::Infallible;

use crate::Scalar;

mod compile;
mod reverse;

pub(crate) use compile::{compile, compile_residual};
pub use reverse::Workspace;

use crate::ast::{CmpOp, Func};
use crate::error::{ErrorKind, ExprError};
use crate::external::ExternalNode;
use crate::span::Span;
use crate::table::Table;

/// A slot index.
type Slot = u32;

/// One operation; the destination slot is in [`Instr`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Op {
    /// A constant materialised in a slot (for operations without an immediate form).
    Const(f64),
    Add(Slot, Slot),
    Sub(Slot, Slot),
    Mul(Slot, Slot),
    Div(Slot, Slot),
    /// `a + c` (also `a − c` as `a + (−c)`, which IEEE 754 defines to be the same).
    AddC(Slot, f64),
    /// `c − a`
    CSub(f64, Slot),
    /// `a·c`
    MulC(Slot, f64),
    /// `a/c`
    DivC(Slot, f64),
    /// `c/a`
    CDiv(f64, Slot),
    Neg(Slot),
    Powi(Slot, i32),
    Powf(Slot, f64),
    Pow(Slot, Slot),
    Func1(Func, Slot),
    Func2(Func, Slot, Slot),
    Func3(Func, Slot, Slot, Slot),
    /// `tables[t](a)`
    Table(u32, Slot),
    /// `externals[e]` of its argument slots.
    External(u32),
    /// 1 if the comparison holds, else 0.
    Cmp(CmpOp, Slot, Slot),
    And(Slot, Slot),
    Or(Slot, Slot),
    Not(Slot),
    /// Copy a slot (the merge of an `if`'s branches).
    Mov(Slot),
    /// Jump to the instruction index when the condition slot is 0.
    JumpIfFalse(Slot, u32),
    /// Jump to the instruction index.
    Jump(u32),
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Instr {
    dst: Slot,
    op: Op,
}

/// Spans of an instruction, for errors found when evaluating at the guess.
#[derive(Debug, Clone, Copy, PartialEq)]
struct InstrSpans {
    /// The node the instruction computes.
    node: Span,
    /// The operand a domain check concerns: a division's denominator, a function's argument.
    operand: Span,
}

/// Where a variable slot is loaded from before the instructions run.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Source {
    /// `x[i]`
    X(u32),
    /// `dx[i]`
    Dx(u32),
}

/// A slot filled from `x` or `dx` by the prologue (each variable once, however often it is
/// named), so that the instruction loop only computes.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Load {
    slot: Slot,
    src: Source,
    /// The first place the name appears, for a non-finite guess value.
    span: Span,
}

/// A value during compilation: a folded constant or a slot.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Val {
    Const(f64),
    Slot(Slot),
}

/// Tapes of at most this many slots evaluate on the stack, without allocating.
pub const INLINE_SLOTS: usize = 48;

/// A compiled expression: instructions over slots, the tables it calls, and the variable and
/// derivative indices it reads (its sparsity).
#[derive(Debug, Clone, PartialEq)]
pub struct Tape {
    loads: Vec<Load>,
    code: Vec<Instr>,
    spans: Vec<InstrSpans>,
    n_slots: usize,
    out: Val,
    out_span: Span,
    tables: Vec<Table>,
    externals: Vec<ExternalNode>,
    vars: Vec<usize>,
    ders: Vec<usize>,
}

impl Tape {
    /// Number of instructions, not counting the loads of variables and derivatives (each
    /// loaded once before the instructions run).
    pub fn len(&self) -> usize {
        self.code.len()
    }

    /// Whether the tape has no instructions (a constant, or a lone variable).
    pub fn is_empty(&self) -> bool {
        self.code.is_empty()
    }

    /// Whether the expression folded to a constant (it reads no variable).
    pub fn is_constant(&self) -> bool {
        matches!(self.out, Val::Const(_))
    }

    /// Indices into `x` that the expression reads, sorted, each once.
    pub fn variables(&self) -> &[usize] {
        &self.vars
    }

    /// Indices into `dx` (derivatives `der(x)`) that the expression reads, sorted, each once.
    pub fn derivatives(&self) -> &[usize] {
        &self.ders
    }

    /// The smallest lengths of `x` and `dx` that evaluation accepts.
    pub fn required_lengths(&self) -> (usize, usize) {
        (self.vars.last().map_or(0, |i| i + 1), self.ders.last().map_or(0, |i| i + 1))
    }

    /// The value at `x` (variables) and `dx` (their time derivatives).
    ///
    /// # Panics
    /// If `x` or `dx` is shorter than [`Tape::required_lengths`].
    pub fn eval<S: Scalar>(&self, x: &[S], dx: &[S]) -> S {
        if self.n_slots <= INLINE_SLOTS {
            let mut slots = [S::from(0.0); INLINE_SLOTS];
            self.eval_in(x, dx, &mut slots)
        } else {
            let mut slots = vec![S::from(0.0); self.n_slots];
            self.eval_in(x, dx, &mut slots)
        }
    }

    /// As [`Tape::eval`] with caller-owned scratch of at least `n_slots` values.
    fn eval_in<S: Scalar>(&self, x: &[S], dx: &[S], slots: &mut [S]) -> S {
        match self.run(x, dx, slots, &mut Unchecked) {
            Ok(v) => v,
            Err(never) => match never {},
        }
    }

    /// Evaluates in `f64` at the guess, stopping at the first division by zero, logarithm or
    /// root outside its domain, or non-finite intermediate value, located in `text`.
    pub(crate) fn eval_checked(&self, text: &str, x: &[f64], dx: &[f64]) -> Result<f64, ExprError> {
        let mut slots = vec![0.0; self.n_slots];
        let mut hook = GuessCheck { spans: &self.spans, text };
        let value = self.run(x, dx, &mut slots, &mut hook)?;
        if value.is_finite() {
            Ok(value)
        } else {
            Err(ExprError::new(text, self.out_span, ErrorKind::NonFinite { value }))
        }
    }

    fn run<S: Scalar, H: Hook<S>>(&self, x: &[S], dx: &[S], v: &mut [S], hook: &mut H) -> Result<S, H::Err> {
        for load in &self.loads {
            let val = match load.src {
                Source::X(i) => x[i as usize],
                Source::Dx(i) => dx[i as usize],
            };
            hook.load(load, val)?;
            v[load.slot as usize] = val;
        }
        let mut pc = 0;
        while let Some(ins) = self.code.get(pc) {
            let k = pc;
            pc += 1;
            let val = match ins.op {
                Op::JumpIfFalse(c, target) => {
                    if v[c as usize].re() == 0.0 {
                        pc = target as usize;
                    }
                    continue;
                }
                Op::Jump(target) => {
                    pc = target as usize;
                    continue;
                }
                op => {
                    hook.before(k, &op, v)?;
                    self.apply(op, v)
                }
            };
            hook.after(k, val)?;
            v[ins.dst as usize] = val;
        }
        Ok(match self.out {
            Val::Const(c) => S::from(c),
            Val::Slot(s) => v[s as usize],
        })
    }

    #[inline(always)]
    fn apply<S: Scalar>(&self, op: Op, v: &[S]) -> S {
        let at = |s: Slot| v[s as usize];
        match op {
            Op::Const(c) => S::from(c),
            Op::Add(a, b) => at(a) + at(b),
            Op::Sub(a, b) => at(a) - at(b),
            Op::Mul(a, b) => at(a) * at(b),
            Op::Div(a, b) => at(a) / at(b),
            Op::AddC(a, c) => at(a) + c,
            Op::CSub(c, a) => -at(a) + c,
            Op::MulC(a, c) => at(a) * c,
            Op::DivC(a, c) => at(a) / c,
            Op::CDiv(c, a) => S::from(c) / at(a),
            Op::Neg(a) => -at(a),
            Op::Powi(a, n) => at(a).powi(n),
            Op::Powf(a, p) => at(a).powf(p),
            Op::Pow(a, b) => at(a).powd(at(b)),
            Op::Func1(f, a) => func1(f, at(a)),
            Op::Func2(f, a, b) => func2(f, at(a), at(b)),
            Op::Func3(f, a, b, c) => func3(f, at(a), at(b), at(c)),
            Op::Table(t, a) => self.tables[t as usize].eval(at(a)),
            Op::External(e) => self.external(e as usize, v),
            Op::Cmp(op, a, b) => truth(op.holds(at(a).re(), at(b).re())),
            Op::And(a, b) => truth(at(a).re() != 0.0 && at(b).re() != 0.0),
            Op::Or(a, b) => truth(at(a).re() != 0.0 || at(b).re() != 0.0),
            Op::Not(a) => truth(at(a).re() == 0.0),
            Op::Mov(a) => at(a),
            Op::JumpIfFalse(..) | Op::Jump(_) => S::from(0.0),
        }
    }
}

/// External calls with at most this many inputs gather them on the stack.
const INLINE_ARGS: usize = 32;

impl Tape {
    /// External call `e` over the slots `v`: the callback's value over `f64`; over a dual type
    /// the first-order expansion `f(re) + Σ_k ∂f/∂a_k · (a_k − re(a_k))` from the callback's exact
    /// partials, which carries every derivative direction the dual type holds.
    fn external<S: Scalar>(&self, e: usize, v: &[S]) -> S {
        let node = &self.externals[e];
        let n = node.args.len();
        let (mut a_buf, mut d_buf) = ([0.0; INLINE_ARGS], [0.0; INLINE_ARGS]);
        let (mut a_vec, mut d_vec);
        let (a, d): (&mut [f64], &mut [f64]) = if n <= INLINE_ARGS {
            (&mut a_buf[..n], &mut d_buf[..n])
        } else {
            a_vec = vec![0.0; n];
            d_vec = vec![0.0; n];
            (&mut a_vec, &mut d_vec)
        };
        for (ak, &s) in a.iter_mut().zip(&node.args) {
            *ak = v[s as usize].re();
        }
        if std::any::TypeId::of::<S>() == std::any::TypeId::of::<f64>() {
            return S::from(node.eval.value(a));
        }
        let value = node.eval.value_and_partials(a, d);
        let mut res = S::from(value);
        for (&dk, &s) in d.iter().zip(&node.args) {
            if dk != 0.0 {
                let ak = v[s as usize];
                res += (ak - S::from(ak.re())) * dk;
            }
        }
        res
    }
}

fn truth<S: Scalar>(b: bool) -> S {
    S::from(if b { 1.0 } else { 0.0 })
}

/// One-argument built-ins (see [`Func`] for the formulas).
#[inline(always)]
pub(crate) fn func1<S: Scalar>(f: Func, a: S) -> S {
    match f {
        Func::Exp => a.exp(),
        Func::Ln => a.ln(),
        Func::Log10 => a.log10(),
        Func::Sqrt => a.sqrt(),
        Func::Abs => a.abs(),
        _ => S::from(f64::NAN),
    }
}

/// Two-argument built-ins: `min`, `max` (the argument with the smaller/larger real part, ties to
/// the first) and `smooth_abs(x, eps) = sqrt(x² + eps²)`.
#[inline(always)]
pub(crate) fn func2<S: Scalar>(f: Func, a: S, b: S) -> S {
    match f {
        Func::Min => {
            if a.re() <= b.re() {
                a
            } else {
                b
            }
        }
        Func::Max => {
            if a.re() >= b.re() {
                a
            } else {
                b
            }
        }
        Func::SmoothAbs => (a * a + b * b).sqrt(),
        _ => S::from(f64::NAN),
    }
}

/// `smooth_max(a, b, eps) = (a + b + sqrt((a − b)² + eps²))/2`, `smooth_min` with `−`.
#[inline(always)]
pub(crate) fn func3<S: Scalar>(f: Func, a: S, b: S, eps: S) -> S {
    let d = a - b;
    let root = (d * d + eps * eps).sqrt();
    match f {
        Func::SmoothMax => (a + b + root) * 0.5,
        Func::SmoothMin => (a + b - root) * 0.5,
        _ => S::from(f64::NAN),
    }
}

/// Observes evaluation; the unchecked path compiles to nothing.
trait Hook<S> {
    type Err;
    fn load(&mut self, load: &Load, val: S) -> Result<(), Self::Err>;
    fn before(&mut self, k: usize, op: &Op, v: &[S]) -> Result<(), Self::Err>;
    fn after(&mut self, k: usize, val: S) -> Result<(), Self::Err>;
}

struct Unchecked;

impl<S> Hook<S> for Unchecked {
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
    fn after(&mut self, _: usize, _: S) -> Result<(), Infallible> {
        Ok(())
    }
}

/// The load-time checks at the guess values.
struct GuessCheck<'a> {
    spans: &'a [InstrSpans],
    text: &'a str,
}

impl Hook<f64> for GuessCheck<'_> {
    type Err = ExprError;

    fn load(&mut self, load: &Load, val: f64) -> Result<(), ExprError> {
        if val.is_finite() {
            Ok(())
        } else {
            Err(ExprError::new(self.text, load.span, ErrorKind::NonFinite { value: val }))
        }
    }

    fn before(&mut self, k: usize, op: &Op, v: &[f64]) -> Result<(), ExprError> {
        let at = |s: &Slot| v[*s as usize];
        let kind = match op {
            Op::Div(_, b) | Op::CDiv(_, b) if at(b) == 0.0 => Some(ErrorKind::ZeroDenominator),
            Op::Func1(f @ (Func::Ln | Func::Log10), a) if at(a) <= 0.0 => {
                Some(ErrorKind::OutOfDomain { func: f.name(), value: at(a) })
            }
            Op::Func1(Func::Sqrt, a) if at(a) < 0.0 => Some(ErrorKind::OutOfDomain { func: "sqrt", value: at(a) }),
            Op::Powf(a, _) | Op::Pow(a, _) if at(a) < 0.0 => Some(ErrorKind::OutOfDomain { func: "^", value: at(a) }),
            _ => None,
        };
        match kind {
            Some(kind) => Err(ExprError::new(self.text, self.spans[k].operand, kind)),
            None => Ok(()),
        }
    }

    fn after(&mut self, k: usize, val: f64) -> Result<(), ExprError> {
        if val.is_finite() {
            Ok(())
        } else {
            Err(ExprError::new(self.text, self.spans[k].node, ErrorKind::NonFinite { value: val }))
        }
    }
}
