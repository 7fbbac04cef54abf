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

use std::collections::BTreeSet;
use std::convert::Infallible;

use num_dual::Dual64;
use plantwide_thermo::Scalar;

use crate::ast::{BinOp, CmpOp, Expr, ExprKind, Func};
use crate::error::{ErrorKind, ExprError};
use crate::span::Span;
use crate::symbols::{Symbol, SymbolTable};
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
            Op::Cmp(op, a, b) => truth(op.holds(at(a).re(), at(b).re())),
            Op::And(a, b) => truth(at(a).re() != 0.0 && at(b).re() != 0.0),
            Op::Or(a, b) => truth(at(a).re() != 0.0 || at(b).re() != 0.0),
            Op::Not(a) => truth(at(a).re() == 0.0),
            Op::Mov(a) => at(a),
            Op::JumpIfFalse(..) | Op::Jump(_) => S::from(0.0),
        }
    }
}

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

/// Compiles a checked expression (the caller has run the dimension check, so every name
/// resolves to the right kind of symbol).
pub(crate) fn compile(text: &str, symbols: &SymbolTable, e: &Expr) -> Result<Tape, ExprError> {
    let mut c = Compiler::new(text, symbols);
    let out = c.expr(e)?;
    Ok(c.finish(out, e.span))
}

/// Compiles the residual `lhs − rhs` of a checked equation.
pub(crate) fn compile_residual(text: &str, symbols: &SymbolTable, lhs: &Expr, rhs: &Expr) -> Result<Tape, ExprError> {
    let mut c = Compiler::new(text, symbols);
    let (a, b) = (c.expr(lhs)?, c.expr(rhs)?);
    let span = lhs.span.join(rhs.span);
    let out = c.binary(BinOp::Sub, a, b, span, rhs.span)?;
    Ok(c.finish(out, span))
}

struct Compiler<'a> {
    text: &'a str,
    symbols: &'a SymbolTable,
    loads: Vec<Load>,
    code: Vec<Instr>,
    spans: Vec<InstrSpans>,
    n_slots: u32,
    table_names: Vec<String>,
    tables: Vec<Table>,
    vars: BTreeSet<usize>,
    ders: BTreeSet<usize>,
}

impl<'a> Compiler<'a> {
    fn new(text: &'a str, symbols: &'a SymbolTable) -> Self {
        Compiler {
            text,
            symbols,
            loads: Vec::new(),
            code: Vec::new(),
            spans: Vec::new(),
            n_slots: 0,
            table_names: Vec::new(),
            tables: Vec::new(),
            vars: BTreeSet::new(),
            ders: BTreeSet::new(),
        }
    }

    fn finish(self, out: Val, out_span: Span) -> Tape {
        Tape {
            loads: self.loads,
            code: self.code,
            spans: self.spans,
            n_slots: self.n_slots as usize,
            out,
            out_span,
            tables: self.tables,
            vars: self.vars.into_iter().collect(),
            ders: self.ders.into_iter().collect(),
        }
    }

    fn err<T>(&self, span: Span, kind: ErrorKind) -> Result<T, ExprError> {
        Err(ExprError::new(self.text, span, kind))
    }

    fn new_slot(&mut self) -> Slot {
        self.n_slots += 1;
        self.n_slots - 1
    }

    fn push(&mut self, dst: Slot, op: Op, node: Span, operand: Span) -> usize {
        self.code.push(Instr { dst, op });
        self.spans.push(InstrSpans { node, operand });
        self.code.len() - 1
    }

    fn emit(&mut self, op: Op, node: Span, operand: Span) -> Val {
        let dst = self.new_slot();
        self.push(dst, op, node, operand);
        Val::Slot(dst)
    }

    fn slot(&mut self, v: Val, span: Span) -> Slot {
        match v {
            Val::Slot(s) => s,
            Val::Const(c) => match self.emit(Op::Const(c), span, span) {
                Val::Slot(s) => s,
                Val::Const(_) => unreachable!("emit returns a slot"),
            },
        }
    }

    /// A folded constant, refused when not finite (`ln(0)`, `1/0` between constants).
    fn constant(&self, value: f64, span: Span) -> Result<Val, ExprError> {
        if value.is_finite() { Ok(Val::Const(value)) } else { self.err(span, ErrorKind::NonFiniteConstant { value }) }
    }

    fn expr(&mut self, e: &Expr) -> Result<Val, ExprError> {
        match &e.kind {
            ExprKind::Number(v) => self.constant(*v, e.span),
            ExprKind::Name(name) => Ok(self.name(name, e.span)),
            ExprKind::Neg(a) => match self.expr(a)? {
                Val::Const(c) => Ok(Val::Const(-c)),
                Val::Slot(s) => Ok(self.emit(Op::Neg(s), e.span, e.span)),
            },
            ExprKind::Binary(op, a, b) => {
                let (va, vb) = (self.expr(a)?, self.expr(b)?);
                self.binary(*op, va, vb, e.span, b.span)
            }
            ExprKind::Call(func, args) => self.call(*func, args, e.span),
            ExprKind::Der { name, .. } => Ok(self.der(name, e.span)),
            ExprKind::Lookup { name, args, .. } => self.lookup(name, &args[0], e.span),
            ExprKind::If(cond, yes, no) => self.if_else(cond, yes, no, e.span),
            ExprKind::Compare(op, a, b) => {
                let (va, vb) = (self.expr(a)?, self.expr(b)?);
                if let (Val::Const(x), Val::Const(y)) = (va, vb) {
                    return Ok(Val::Const(if op.holds(x, y) { 1.0 } else { 0.0 }));
                }
                let (sa, sb) = (self.slot(va, a.span), self.slot(vb, b.span));
                Ok(self.emit(Op::Cmp(*op, sa, sb), e.span, e.span))
            }
            ExprKind::And(a, b) | ExprKind::Or(a, b) => {
                let is_and = matches!(e.kind, ExprKind::And(..));
                let (va, vb) = (self.expr(a)?, self.expr(b)?);
                if let (Val::Const(x), Val::Const(y)) = (va, vb) {
                    let t = if is_and { x != 0.0 && y != 0.0 } else { x != 0.0 || y != 0.0 };
                    return Ok(Val::Const(if t { 1.0 } else { 0.0 }));
                }
                let (sa, sb) = (self.slot(va, a.span), self.slot(vb, b.span));
                let op = if is_and { Op::And(sa, sb) } else { Op::Or(sa, sb) };
                Ok(self.emit(op, e.span, e.span))
            }
            ExprKind::Not(a) => match self.expr(a)? {
                Val::Const(x) => Ok(Val::Const(if x == 0.0 { 1.0 } else { 0.0 })),
                Val::Slot(s) => Ok(self.emit(Op::Not(s), e.span, e.span)),
            },
        }
    }

    fn name(&mut self, name: &str, span: Span) -> Val {
        match self.symbols.get(name) {
            Some(Symbol::Parameter { value, .. }) => Val::Const(*value),
            Some(Symbol::Variable { index, .. }) => {
                self.vars.insert(*index);
                self.load(Source::X(*index as u32), span)
            }
            // The checker has refused unknown names and tables used as values.
            _ => Val::Const(f64::NAN),
        }
    }

    fn der(&mut self, name: &str, span: Span) -> Val {
        match self.symbols.get(name) {
            Some(Symbol::Variable { index, .. }) => {
                self.ders.insert(*index);
                self.load(Source::Dx(*index as u32), span)
            }
            _ => Val::Const(f64::NAN),
        }
    }

    /// The slot holding `src`, loaded once by the prologue.
    fn load(&mut self, src: Source, span: Span) -> Val {
        if let Some(load) = self.loads.iter().find(|l| l.src == src) {
            return Val::Slot(load.slot);
        }
        let slot = self.new_slot();
        self.loads.push(Load { slot, src, span });
        Val::Slot(slot)
    }

    fn lookup(&mut self, name: &str, arg: &Expr, span: Span) -> Result<Val, ExprError> {
        let Some(Symbol::Table(table)) = self.symbols.get(name) else { return Ok(Val::Const(f64::NAN)) };
        let va = self.expr(arg)?;
        if let Val::Const(x) = va {
            return self.constant(table.eval(x), span);
        }
        let t = match self.table_names.iter().position(|n| n == name) {
            Some(t) => t,
            None => {
                self.table_names.push(name.to_owned());
                self.tables.push(table.clone());
                self.tables.len() - 1
            }
        };
        let sa = self.slot(va, arg.span);
        Ok(self.emit(Op::Table(t as u32, sa), span, arg.span))
    }

    /// `a op b`, folding constants and using the immediate-constant forms.
    fn binary(&mut self, op: BinOp, a: Val, b: Val, span: Span, b_span: Span) -> Result<Val, ExprError> {
        use Val::{Const, Slot as S};
        let op = match (op, a, b) {
            (_, Const(x), Const(y)) => return self.constant(fold_binary(op, x, y), span),
            (BinOp::Add, S(s), Const(c)) | (BinOp::Add, Const(c), S(s)) if c == 0.0 => return Ok(S(s)),
            (BinOp::Sub, S(s), Const(0.0)) => return Ok(S(s)),
            (BinOp::Mul | BinOp::Div, S(s), Const(c)) | (BinOp::Mul, Const(c), S(s)) if c == 1.0 => return Ok(S(s)),
            (BinOp::Div, S(_), Const(0.0)) => return self.err(b_span, ErrorKind::DivisionByZero),
            (BinOp::Add, S(s), Const(c)) | (BinOp::Add, Const(c), S(s)) => Op::AddC(s, c),
            (BinOp::Sub, S(s), Const(c)) => Op::AddC(s, -c),
            (BinOp::Sub, Const(c), S(s)) => Op::CSub(c, s),
            (BinOp::Mul, S(s), Const(c)) | (BinOp::Mul, Const(c), S(s)) => Op::MulC(s, c),
            (BinOp::Div, S(s), Const(c)) => Op::DivC(s, c),
            (BinOp::Div, Const(c), S(s)) => Op::CDiv(c, s),
            (BinOp::Pow, S(s), Const(p)) => power_op(s, p),
            (BinOp::Pow, Const(_), S(s)) => {
                let base = self.slot(a, span);
                Op::Pow(base, s)
            }
            (BinOp::Add, S(x), S(y)) => Op::Add(x, y),
            (BinOp::Sub, S(x), S(y)) => Op::Sub(x, y),
            (BinOp::Mul, S(x), S(y)) => Op::Mul(x, y),
            (BinOp::Div, S(x), S(y)) => Op::Div(x, y),
            (BinOp::Pow, S(x), S(y)) => Op::Pow(x, y),
        };
        let operand = if matches!(op, Op::Pow(..) | Op::Powf(..)) { span } else { b_span };
        Ok(self.emit(op, span, operand))
    }

    fn call(&mut self, func: Func, args: &[Expr], span: Span) -> Result<Val, ExprError> {
        let vals = args.iter().map(|a| self.expr(a)).collect::<Result<Vec<Val>, ExprError>>()?;
        if let Some(consts) =
            vals.iter().map(|v| if let Val::Const(c) = v { Some(*c) } else { None }).collect::<Option<Vec<f64>>>()
        {
            let value = match consts.as_slice() {
                [a] => func1(func, *a),
                [a, b] => func2(func, *a, *b),
                [a, b, c] => func3(func, *a, *b, *c),
                _ => f64::NAN,
            };
            return self.constant(value, span);
        }
        let slots: Vec<Slot> = vals.iter().zip(args).map(|(v, a)| self.slot(*v, a.span)).collect();
        let op = match slots.as_slice() {
            [a] => Op::Func1(func, *a),
            [a, b] => Op::Func2(func, *a, *b),
            [a, b, c] => Op::Func3(func, *a, *b, *c),
            _ => {
                return self.err(
                    span,
                    ErrorKind::Arity { func: func.name().into(), expected: func.arity(), found: args.len() },
                );
            }
        };
        Ok(self.emit(op, span, args[0].span))
    }

    /// `if c then a else b`: a jump over the branch not taken; a constant condition keeps
    /// only its branch.
    fn if_else(&mut self, cond: &Expr, yes: &Expr, no: &Expr, span: Span) -> Result<Val, ExprError> {
        let c = match self.expr(cond)? {
            Val::Const(c) => return self.expr(if c != 0.0 { yes } else { no }),
            Val::Slot(s) => s,
        };
        let res = self.new_slot();
        let jump_if_false = self.push(res, Op::JumpIfFalse(c, 0), span, span);
        let a = self.expr(yes)?;
        let a = self.slot(a, yes.span);
        self.push(res, Op::Mov(a), span, span);
        let jump = self.push(res, Op::Jump(0), span, span);
        self.code[jump_if_false].op = Op::JumpIfFalse(c, self.code.len() as u32);
        let b = self.expr(no)?;
        let b = self.slot(b, no.span);
        self.push(res, Op::Mov(b), span, span);
        self.code[jump].op = Op::Jump(self.code.len() as u32);
        Ok(Val::Slot(res))
    }
}

/// `x^p` for constant `p`: an integer power by repeated multiplication when `p` is an integer
/// (exact for negative bases), otherwise `powf`.
fn power_op(s: Slot, p: f64) -> Op {
    if p.fract() == 0.0 && p.abs() <= f64::from(i32::MAX) { Op::Powi(s, p as i32) } else { Op::Powf(s, p) }
}

fn fold_binary(op: BinOp, x: f64, y: f64) -> f64 {
    match op {
        BinOp::Add => x + y,
        BinOp::Sub => x - y,
        BinOp::Mul => x * y,
        BinOp::Div => x / y,
        BinOp::Pow => x.powf(y),
    }
}
