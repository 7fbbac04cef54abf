//! Compilation of a checked syntax tree to a [`Tape`], folding constants.

use std::collections::BTreeSet;

use super::{Instr, InstrSpans, Load, Op, Slot, Source, Tape, Val, func1, func2, func3};
use crate::ast::{BinOp, Expr, ExprKind, Func};
use crate::check::bind;
use crate::error::{ErrorKind, ExprError};
use crate::external::{ExternalNode, FunctionRef};
use crate::span::Span;
use crate::symbols::{Symbol, SymbolTable};
use crate::table::Table;

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
    externals: Vec<ExternalNode>,
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
            externals: Vec::new(),
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
            externals: self.externals,
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
            ExprKind::Lookup { name, args, .. } => self.lookup(name, args, e.span),
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

    /// A call of external function `f`: its inputs loaded, one node computing it.
    fn external(&mut self, name: &str, f: &FunctionRef, args: &[Expr], span: Span) -> Result<Val, ExprError> {
        let call = bind(self.text, name, &f.0, span, args)?;
        let mut slots = Vec::with_capacity(call.reads.len());
        for &i in &call.reads {
            self.vars.insert(i);
            match self.load(Source::X(i as u32), span) {
                Val::Slot(s) => slots.push(s),
                Val::Const(_) => unreachable!("a load is a slot"),
            }
        }
        self.externals.push(ExternalNode { eval: call.eval, args: slots });
        Ok(self.emit(Op::External(self.externals.len() as u32 - 1), span, span))
    }

    fn lookup(&mut self, name: &str, args: &[Expr], span: Span) -> Result<Val, ExprError> {
        let symbols = self.symbols;
        if let Some(Symbol::Function(f)) = symbols.get(name) {
            return self.external(name, f, args, span);
        }
        let Some(Symbol::Table(table)) = symbols.get(name) else { return Ok(Val::Const(f64::NAN)) };
        let arg = &args[0];
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
