//! The syntax tree of an expression or equation; every node carries its byte [`Span`].

use crate::span::Span;

/// An equation `lhs = rhs`; its residual is `lhs − rhs`.
#[derive(Debug, Clone, PartialEq)]
pub struct Equation {
    /// Left-hand side.
    pub lhs: Expr,
    /// Right-hand side.
    pub rhs: Expr,
    /// The span of the whole equation (both sides).
    pub span: Span,
}

/// An expression node with its span in the source text.
#[derive(Debug, Clone, PartialEq)]
pub struct Expr {
    /// What the node is.
    pub kind: ExprKind,
    /// Where it is in the source text.
    pub span: Span,
    /// Height of the subtree (a leaf is 1), bounded by [`crate::MAX_DEPTH`].
    pub(crate) depth: usize,
}

impl Expr {
    pub(crate) fn new(kind: ExprKind, span: Span) -> Self {
        let depth = 1 + kind.children().map(|c| c.depth).max().unwrap_or(0);
        Expr { kind, span, depth }
    }

    /// Height of the subtree: 1 for a number or a name.
    pub fn depth(&self) -> usize {
        self.depth
    }

    /// The names the expression reads, in order of first appearance, each once with the span of
    /// that first appearance (a table's callee and a `der()` argument are not among them).
    pub fn names(&self) -> Vec<(String, Span)> {
        let mut out: Vec<(String, Span)> = Vec::new();
        let mut stack = vec![self];
        while let Some(e) = stack.pop() {
            if let ExprKind::Name(n) = &e.kind
                && !out.iter().any(|(m, _)| m == n)
            {
                out.push((n.clone(), e.span));
            }
            // Children pushed in reverse so that they are visited in source order.
            let children: Vec<&Expr> = e.kind.children().collect();
            stack.extend(children.into_iter().rev());
        }
        out
    }
}

/// The kinds of expression node.
#[derive(Debug, Clone, PartialEq)]
pub enum ExprKind {
    /// A number literal, such as `1`, `1.5e-3` or `.5`.
    Number(f64),
    /// A name: a parameter, a variable, or (only as a callee) a table.
    Name(String),
    /// Unary minus.
    Neg(Box<Expr>),
    /// A binary arithmetic operation.
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// A built-in function applied to its arguments.
    Call(Func, Vec<Expr>),
    /// `der(name)`: the time derivative of a differential variable.
    Der {
        /// The variable's name.
        name: String,
        /// The span of the name inside the parentheses.
        name_span: Span,
    },
    /// `name(arg)` for a name that is not a built-in function: a table lookup.
    Lookup {
        /// The table's name.
        name: String,
        /// The span of the name before the parenthesis.
        name_span: Span,
        /// The arguments (a table takes exactly one; checked against the symbols).
        args: Vec<Expr>,
    },
    /// `if cond then a else b` (`elseif` nests another `If` in the else branch).
    If(Box<Expr>, Box<Expr>, Box<Expr>),
    /// A comparison, `a < b`; its value is a condition, not a number.
    Compare(CmpOp, Box<Expr>, Box<Expr>),
    /// `a and b`.
    And(Box<Expr>, Box<Expr>),
    /// `a or b`.
    Or(Box<Expr>, Box<Expr>),
    /// `not a`.
    Not(Box<Expr>),
}

impl ExprKind {
    /// The direct sub-expressions, in source order.
    pub fn children(&self) -> impl Iterator<Item = &Expr> {
        let (fixed, list): ([Option<&Expr>; 3], &[Expr]) = match self {
            ExprKind::Number(_) | ExprKind::Name(_) | ExprKind::Der { .. } => ([None, None, None], &[]),
            ExprKind::Neg(a) | ExprKind::Not(a) => ([Some(a), None, None], &[]),
            ExprKind::Binary(_, a, b) | ExprKind::Compare(_, a, b) | ExprKind::And(a, b) | ExprKind::Or(a, b) => {
                ([Some(a), Some(b), None], &[])
            }
            ExprKind::If(c, a, b) => ([Some(c), Some(a), Some(b)], &[]),
            ExprKind::Call(_, args) | ExprKind::Lookup { args, .. } => ([None, None, None], args.as_slice()),
        };
        fixed.into_iter().flatten().chain(list.iter())
    }
}

/// Binary arithmetic operators.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
    /// `^` (right-associative, binds tighter than unary minus: `-x^2 = -(x^2)`)
    Pow,
}

impl BinOp {
    /// The operator as written.
    pub fn symbol(self) -> &'static str {
        match self {
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Pow => "^",
        }
    }
}

/// Comparison operators (non-associative: `a < b < c` is a syntax error).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CmpOp {
    /// `<`
    Lt,
    /// `<=`
    Le,
    /// `>`
    Gt,
    /// `>=`
    Ge,
}

impl CmpOp {
    /// The operator as written.
    pub fn symbol(self) -> &'static str {
        match self {
            CmpOp::Lt => "<",
            CmpOp::Le => "<=",
            CmpOp::Gt => ">",
            CmpOp::Ge => ">=",
        }
    }

    /// The comparison of two reals (`false` when either is NaN).
    pub fn holds(self, a: f64, b: f64) -> bool {
        match self {
            CmpOp::Lt => a < b,
            CmpOp::Le => a <= b,
            CmpOp::Gt => a > b,
            CmpOp::Ge => a >= b,
        }
    }
}

/// The built-in functions.
///
/// The smooth variants replace a kink by a hyperbola of width `eps` (same dimension as `x`),
/// so that Newton sees a continuous derivative:
/// - `smooth_abs(x, eps) = sqrt(x² + eps²)`, which is within `eps` of `|x|` everywhere;
/// - `smooth_max(a, b, eps) = (a + b + sqrt((a − b)² + eps²)) / 2`;
/// - `smooth_min(a, b, eps) = (a + b − sqrt((a − b)² + eps²)) / 2`;
///
/// both within `eps/2` of `max`/`min` (they are `(a + b ± smooth_abs(a − b, eps)) / 2`, the
/// identities `max(a, b) = (a + b + |a − b|)/2` and `min(a, b) = (a + b − |a − b|)/2` with the
/// smoothed absolute value; see e.g. Biegler, *Nonlinear Programming* (SIAM 2010), §11.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Func {
    /// `exp(x)`, x dimensionless.
    Exp,
    /// `ln(x)`, natural logarithm, x dimensionless.
    Ln,
    /// `log10(x)`, x dimensionless.
    Log10,
    /// `sqrt(x)`; halves the dimension's exponents.
    Sqrt,
    /// `abs(x)`.
    Abs,
    /// `min(a, b)`.
    Min,
    /// `max(a, b)`.
    Max,
    /// `smooth_abs(x, eps)`.
    SmoothAbs,
    /// `smooth_max(a, b, eps)`.
    SmoothMax,
    /// `smooth_min(a, b, eps)`.
    SmoothMin,
}

impl Func {
    /// Every built-in function, for lookups and for reserving their names.
    pub const ALL: [Func; 10] = [
        Func::Exp,
        Func::Ln,
        Func::Log10,
        Func::Sqrt,
        Func::Abs,
        Func::Min,
        Func::Max,
        Func::SmoothAbs,
        Func::SmoothMax,
        Func::SmoothMin,
    ];

    /// The function's name as written.
    pub fn name(self) -> &'static str {
        match self {
            Func::Exp => "exp",
            Func::Ln => "ln",
            Func::Log10 => "log10",
            Func::Sqrt => "sqrt",
            Func::Abs => "abs",
            Func::Min => "min",
            Func::Max => "max",
            Func::SmoothAbs => "smooth_abs",
            Func::SmoothMax => "smooth_max",
            Func::SmoothMin => "smooth_min",
        }
    }

    /// The number of arguments.
    pub fn arity(self) -> usize {
        match self {
            Func::Exp | Func::Ln | Func::Log10 | Func::Sqrt | Func::Abs => 1,
            Func::Min | Func::Max | Func::SmoothAbs => 2,
            Func::SmoothMax | Func::SmoothMin => 3,
        }
    }

    /// The built-in function of this name, if any.
    pub fn from_name(name: &str) -> Option<Func> {
        Func::ALL.into_iter().find(|f| f.name() == name)
    }
}
