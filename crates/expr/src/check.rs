//! Name resolution and dimensional analysis of a parsed expression.
//!
//! Rules (each violation is an [`ErrorKind`] with the span of the offending node):
//! - `+`, `-`, `min`, `max`, the smooth functions, comparisons, the branches of `if` and the
//!   two sides of an equation need equal dimensions;
//! - `*` and `/` multiply and divide dimensions;
//! - `exp`, `ln`, `log10` need a dimensionless argument and give a dimensionless result;
//! - `sqrt` halves the exponents (an error if one is odd), `abs` keeps the dimension;
//! - `x^p`: `p` is dimensionless; if `x` has a dimension, `p` must be a constant (numbers and
//!   parameters) and every exponent of `x` times `p` an integer;
//! - `der(x)` has the dimension of `x` per second, for differential variables only;
//! - `table(x)`: `x` in the table's input dimension, the result in its output dimension;
//! - `f(args)` of an external function: the arguments are names the function interprets, the
//!   result in the dimension the function's binding gives;
//! - numbers are dimensionless, but a bare number (an expression of number literals only) that
//!   must match a dimensioned quantity is refused, asking for a parameter with units
//!   (`T + 273.15` hides a unit; `2*F` and `F/2` are fine). The literal `0` matches any
//!   dimension (`der(M) = 0`, `max(F, 0)`).

use plantwide_units::Dimension;

use crate::ast::{BinOp, Equation, Expr, ExprKind, Func};
use crate::error::{ErrorKind, ExprError};
use crate::external::{ExternalCall, ExternalFunction};
use crate::span::Span;
use crate::symbols::{Symbol, SymbolTable, VarKind};

/// How an expression may combine with dimensioned ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Lit {
    /// Contains a name: its dimension is what it is.
    Quantity,
    /// Number literals only: dimensionless, but refused where a dimension is needed.
    Bare,
    /// The literal zero: matches any dimension.
    Zero,
}

/// What the checker knows about a numeric sub-expression.
#[derive(Debug, Clone, Copy)]
struct Info {
    dim: Dimension,
    lit: Lit,
    /// The value, when it is a constant of numbers and parameters under + − * / ^.
    value: Option<f64>,
}

impl Info {
    fn quantity(dim: Dimension) -> Info {
        Info { dim, lit: Lit::Quantity, value: None }
    }
}

/// Checks an equation: names resolve, both sides agree in dimension. Returns that dimension.
pub(crate) fn check_equation(text: &str, symbols: &SymbolTable, eq: &Equation) -> Result<Dimension, ExprError> {
    let c = Checker { text, symbols };
    let lhs = c.number(&eq.lhs)?;
    let rhs = c.number(&eq.rhs)?;
    c.agree(eq.span, "the two sides of the equation", (lhs, &eq.lhs), (rhs, &eq.rhs)).map(|i| i.dim)
}

/// Checks an expression and returns its dimension.
pub(crate) fn check_expression(text: &str, symbols: &SymbolTable, e: &Expr) -> Result<Dimension, ExprError> {
    Checker { text, symbols }.number(e).map(|i| i.dim)
}

/// Binds a call of external function `name` (see [`crate::external`]), locating a refusal at
/// the argument at fault or at the call.
pub(crate) fn bind(
    text: &str,
    name: &str,
    f: &std::sync::Arc<dyn ExternalFunction>,
    span: Span,
    args: &[Expr],
) -> Result<ExternalCall, ExprError> {
    let texts: Vec<&str> = args.iter().map(|a| a.span.slice(text).trim()).collect();
    f.bind(&texts).map_err(|e| {
        let at = e.arg.and_then(|k| args.get(k)).map_or(span, |a| a.span);
        ExprError::new(text, at, ErrorKind::BadCall { func: name.to_owned(), message: e.message })
    })
}

struct Checker<'a> {
    text: &'a str,
    symbols: &'a SymbolTable,
}

type Checked<T> = Result<T, ExprError>;

impl Checker<'_> {
    fn err<T>(&self, span: Span, kind: ErrorKind) -> Checked<T> {
        Err(ExprError::new(self.text, span, kind))
    }

    /// A numeric expression's dimension.
    fn number(&self, e: &Expr) -> Checked<Info> {
        match &e.kind {
            ExprKind::Number(v) => self.literal(e.span, *v),
            ExprKind::Name(name) => self.name(e.span, name),
            ExprKind::Neg(a) => {
                let a = self.number(a)?;
                Ok(Info { value: a.value.map(|v| -v), ..a })
            }
            ExprKind::Binary(op, a, b) => self.binary(e.span, *op, a, b),
            ExprKind::Call(func, args) => self.call(e.span, *func, args),
            ExprKind::Der { name, name_span } => self.der(*name_span, name),
            ExprKind::Lookup { name, name_span, args } => self.lookup(e.span, *name_span, name, args),
            ExprKind::If(cond, yes, no) => {
                self.condition(cond)?;
                let (a, b) = (self.number(yes)?, self.number(no)?);
                self.agree(e.span, "the two branches of `if`", (a, yes), (b, no))
            }
            ExprKind::Compare(..) | ExprKind::And(..) | ExprKind::Or(..) | ExprKind::Not(_) => {
                self.err(e.span, ErrorKind::ConditionAsNumber)
            }
        }
    }

    /// A condition: comparisons of agreeing dimensions joined by `and`, `or`, `not`.
    fn condition(&self, e: &Expr) -> Checked<()> {
        match &e.kind {
            ExprKind::Compare(op, a, b) => {
                let (ia, ib) = (self.number(a)?, self.number(b)?);
                let what = format!("the two sides of `{}`", op.symbol());
                self.agree(e.span, &what, (ia, a), (ib, b)).map(drop)
            }
            ExprKind::And(a, b) | ExprKind::Or(a, b) => {
                self.condition(a)?;
                self.condition(b)
            }
            ExprKind::Not(a) => self.condition(a),
            _ => self.err(e.span, ErrorKind::NumberAsCondition),
        }
    }

    fn literal(&self, span: Span, v: f64) -> Checked<Info> {
        if !v.is_finite() {
            return self.err(span, ErrorKind::NumberOutOfRange { literal: span.slice(self.text).to_owned() });
        }
        let lit = if v == 0.0 { Lit::Zero } else { Lit::Bare };
        Ok(Info { dim: Dimension::DIMENSIONLESS, lit, value: Some(v) })
    }

    fn unknown<T>(&self, span: Span, name: &str) -> Checked<T> {
        let kind = ErrorKind::UnknownName { name: name.to_owned(), suggestion: self.symbols.suggest(name) };
        self.err(span, kind)
    }

    fn name(&self, span: Span, name: &str) -> Checked<Info> {
        match self.symbols.get(name) {
            None => self.unknown(span, name),
            Some(Symbol::Parameter { value, dim }) => Ok(Info { value: Some(*value), ..Info::quantity(*dim) }),
            Some(Symbol::Variable { dim, .. }) => Ok(Info::quantity(*dim)),
            Some(s @ (Symbol::Table(_) | Symbol::Function(_))) => self.err(
                span,
                ErrorKind::WrongKind {
                    name: name.to_owned(),
                    found: s.describe(),
                    expected: "a value (call a table or a function as `name(…)`)",
                },
            ),
        }
    }

    fn der(&self, span: Span, name: &str) -> Checked<Info> {
        match self.symbols.get(name) {
            None => self.unknown(span, name),
            Some(Symbol::Variable { dim, kind: VarKind::Differential, .. }) => {
                let dim = dim.checked_div(Dimension::TIME);
                dim.map(Info::quantity).map_or_else(|| self.err(span, ErrorKind::DimensionOverflow), Ok)
            }
            Some(Symbol::Variable { kind: VarKind::Algebraic, .. }) => {
                self.err(span, ErrorKind::NotDifferential { name: name.to_owned() })
            }
            Some(s) => self.err(
                span,
                ErrorKind::WrongKind {
                    name: name.to_owned(),
                    found: s.describe(),
                    expected: "a differential variable",
                },
            ),
        }
    }

    fn lookup(&self, span: Span, name_span: Span, name: &str, args: &[Expr]) -> Checked<Info> {
        let table = match self.symbols.get(name) {
            None => return self.unknown(name_span, name),
            Some(Symbol::Table(t)) => t,
            Some(Symbol::Function(f)) => {
                return bind(self.text, name, &f.0, span, args).map(|call| Info::quantity(call.dim));
            }
            Some(s) => {
                let kind = ErrorKind::WrongKind {
                    name: name.to_owned(),
                    found: s.describe(),
                    expected: "a table or a function",
                };
                return self.err(name_span, kind);
            }
        };
        if args.len() != 1 {
            return self.err(span, ErrorKind::Arity { func: name.to_owned(), expected: 1, found: args.len() });
        }
        let arg = self.number(&args[0])?;
        let input = Info::quantity(table.input());
        let what = format!("the argument of table `{name}` and its input");
        self.agree(args[0].span, &what, (arg, &args[0]), (input, &args[0]))?;
        Ok(Info::quantity(table.output()))
    }

    fn binary(&self, span: Span, op: BinOp, a: &Expr, b: &Expr) -> Checked<Info> {
        let (ia, ib) = (self.number(a)?, self.number(b)?);
        let both_bare = ia.lit != Lit::Quantity && ib.lit != Lit::Quantity;
        let lit = if both_bare { Lit::Bare } else { Lit::Quantity };
        let value = match (ia.value, ib.value) {
            (Some(x), Some(y)) => Some(match op {
                BinOp::Add => x + y,
                BinOp::Sub => x - y,
                BinOp::Mul => x * y,
                BinOp::Div => x / y,
                BinOp::Pow => x.powf(y),
            }),
            _ => None,
        };
        let dim = match op {
            BinOp::Add | BinOp::Sub => {
                let what = format!("the operands of `{}`", op.symbol());
                return Ok(Info { value, ..self.agree(span, &what, (ia, a), (ib, b))? });
            }
            BinOp::Mul => ia.dim.checked_mul(ib.dim),
            BinOp::Div => ia.dim.checked_div(ib.dim),
            BinOp::Pow => return self.power(span, (ia, a), (ib, b)).map(|dim| Info { dim, lit, value }),
        };
        match dim {
            Some(dim) => Ok(Info { dim, lit, value }),
            None => self.err(span, ErrorKind::DimensionOverflow),
        }
    }

    /// The dimension of `base^exponent`.
    fn power(&self, span: Span, (base, _): (Info, &Expr), (exp, exp_e): (Info, &Expr)) -> Checked<Dimension> {
        if !exp.dim.is_dimensionless() {
            return self.err(exp_e.span, ErrorKind::NotDimensionless { what: "an exponent".into(), dim: exp.dim });
        }
        if base.dim.is_dimensionless() {
            return Ok(Dimension::DIMENSIONLESS);
        }
        let Some(p) = exp.value else {
            return self.err(exp_e.span, ErrorKind::NonConstantExponent { dim: base.dim });
        };
        let mut out = [0i8; Dimension::BASES];
        for (o, e) in out.iter_mut().zip(base.dim.exponents()) {
            let scaled = f64::from(e) * p;
            let rounded = scaled.round();
            if (scaled - rounded).abs() > 1e-9 {
                return self.err(span, ErrorKind::FractionalPower { dim: base.dim, exponent: p });
            }
            if rounded.abs() > f64::from(i8::MAX) {
                return self.err(span, ErrorKind::DimensionOverflow);
            }
            *o = rounded as i8;
        }
        Ok(Dimension::from_exponents(out))
    }

    fn call(&self, span: Span, func: Func, args: &[Expr]) -> Checked<Info> {
        if args.len() != func.arity() {
            let kind = ErrorKind::Arity { func: func.name().into(), expected: func.arity(), found: args.len() };
            return self.err(span, kind);
        }
        let infos = args.iter().map(|a| self.number(a)).collect::<Checked<Vec<Info>>>()?;
        let bare = if infos.iter().all(|i| i.lit != Lit::Quantity) { Lit::Bare } else { Lit::Quantity };
        let what = || format!("the arguments of `{}`", func.name());
        match func {
            Func::Exp | Func::Ln | Func::Log10 => {
                if !infos[0].dim.is_dimensionless() {
                    let what = format!("the argument of `{}`", func.name());
                    return self.err(args[0].span, ErrorKind::NotDimensionless { what, dim: infos[0].dim });
                }
                Ok(Info { dim: Dimension::DIMENSIONLESS, lit: bare, value: None })
            }
            Func::Sqrt => self.sqrt(args[0].span, infos[0].dim).map(|dim| Info { dim, lit: bare, value: None }),
            Func::Abs => Ok(Info { value: None, lit: bare, ..infos[0] }),
            Func::Min | Func::Max | Func::SmoothAbs => {
                let res = self.agree(span, &what(), (infos[0], &args[0]), (infos[1], &args[1]))?;
                Ok(Info { value: None, ..res })
            }
            Func::SmoothMax | Func::SmoothMin => {
                let ab = self.agree(span, &what(), (infos[0], &args[0]), (infos[1], &args[1]))?;
                let res = self.agree(span, &what(), (ab, &args[0]), (infos[2], &args[2]))?;
                Ok(Info { value: None, ..res })
            }
        }
    }

    fn sqrt(&self, span: Span, dim: Dimension) -> Checked<Dimension> {
        let e = dim.exponents();
        if e.iter().any(|x| x % 2 != 0) {
            return self.err(span, ErrorKind::OddRoot { dim });
        }
        Ok(Dimension::from_exponents(e.map(|x| x / 2)))
    }

    /// Two operands that must share a dimension; the literal 0 takes the other's, and a bare
    /// number against a dimensioned quantity is refused at the number.
    fn agree(&self, span: Span, what: &str, (a, ae): (Info, &Expr), (b, be): (Info, &Expr)) -> Checked<Info> {
        let lit = if a.lit != Lit::Quantity && b.lit != Lit::Quantity { Lit::Bare } else { Lit::Quantity };
        if a.lit == Lit::Zero {
            return Ok(Info { value: None, ..b });
        }
        if b.lit == Lit::Zero || a.dim == b.dim {
            return Ok(Info { lit, value: None, ..a });
        }
        let bare = |e: &Expr, dim| ErrorKind::BareNumber { literal: e.span.slice(self.text).to_owned(), dim };
        match (a.lit, b.lit) {
            (Lit::Bare, _) => self.err(ae.span, bare(ae, b.dim)),
            (_, Lit::Bare) => self.err(be.span, bare(be, a.dim)),
            _ => self.err(span, ErrorKind::DimensionMismatch { what: what.to_owned(), left: a.dim, right: b.dim }),
        }
    }
}
