//! Checked and compiled equations and expressions: the types a unit model holds.

use crate::Scalar;
use plantwide_units::Dimension;

use crate::check::{check_equation, check_expression};
use crate::error::ExprError;
use crate::parse::{parse_equation, parse_expression};
use crate::symbols::SymbolTable;
use crate::tape::{Tape, Workspace, compile, compile_residual};

/// An equation `lhs = rhs`, parsed, checked against a [`SymbolTable`] and compiled; its residual
/// is `lhs − rhs`, in [`Equation::dimension`].
#[derive(Debug, Clone, PartialEq)]
pub struct Equation {
    text: String,
    dim: Dimension,
    tape: Tape,
}

impl Equation {
    /// Parses, checks and compiles `text`.
    ///
    /// # Errors
    /// Syntax, unknown names (with a suggestion), misused symbols, dimension mismatches and
    /// constant parts that are not finite; each located in `text`.
    pub fn new(text: &str, symbols: &SymbolTable) -> Result<Equation, ExprError> {
        let eq = parse_equation(text)?;
        let dim = check_equation(text, symbols, &eq)?;
        let tape = compile_residual(text, symbols, &eq.lhs, &eq.rhs)?;
        Ok(Equation { text: text.to_owned(), dim, tape })
    }

    /// The source text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The dimension of both sides, hence of the residual.
    pub fn dimension(&self) -> Dimension {
        self.dim
    }

    /// The residual `lhs − rhs` at variables `x` and derivatives `dx` (`dx[i]` is `der` of the
    /// variable at index `i`). Over `Dual64` with one seeded variable it gives that column of
    /// the Jacobian exactly.
    ///
    /// # Panics
    /// If `x` or `dx` is shorter than [`Tape::required_lengths`].
    pub fn residual<S: Scalar>(&self, x: &[S], dx: &[S]) -> S {
        self.tape.eval(x, dx)
    }

    /// The residual and its exact partial derivatives with respect to the variables and the
    /// derivatives it reads (in the order of [`Equation::variables`] and
    /// [`Equation::derivatives`]), by reverse mode ([`Tape::gradient_in`]). Allocates; use
    /// [`Equation::gradient_in`] in loops.
    pub fn gradient(&self, x: &[f64], dx: &[f64]) -> Gradient {
        let (n_x, n_dx) = self.tape.required_lengths();
        let (mut d_x, mut d_dx) = (vec![0.0; n_x], vec![0.0; n_dx]);
        let value = self.tape.gradient_in(x, dx, &mut Workspace::new(), &mut d_x, &mut d_dx);
        Gradient {
            value,
            d_x: self.variables().iter().map(|&i| d_x[i]).collect(),
            d_dx: self.derivatives().iter().map(|&i| d_dx[i]).collect(),
        }
    }

    /// The residual, with `∂r/∂x[i]` added to `d_x[i]` and `∂r/∂ẋ[i]` to `d_dx[i]` (dense
    /// slices indexed like `x` and `dx`); see [`Tape::gradient_in`].
    ///
    /// # Panics
    /// If a slice is shorter than [`Tape::required_lengths`].
    pub fn gradient_in(&self, x: &[f64], dx: &[f64], ws: &mut Workspace, d_x: &mut [f64], d_dx: &mut [f64]) -> f64 {
        self.tape.gradient_in(x, dx, ws, d_x, d_dx)
    }

    /// Evaluates at the guess and refuses what would stop Newton at its first step: a
    /// denominator exactly zero, `ln`/`log10` of a non-positive number, `sqrt` of a negative,
    /// a negative base under a fractional power, or any non-finite value; each error names the
    /// span of the offending operand. Returns the residual at the guess.
    ///
    /// # Errors
    /// [`ErrorKind::ZeroDenominator`](crate::ErrorKind::ZeroDenominator),
    /// [`ErrorKind::OutOfDomain`](crate::ErrorKind::OutOfDomain),
    /// [`ErrorKind::NonFinite`](crate::ErrorKind::NonFinite).
    pub fn check_at(&self, x: &[f64], dx: &[f64]) -> Result<f64, ExprError> {
        self.tape.eval_checked(&self.text, x, dx)
    }

    /// Indices into `x` the residual reads: the row's sparsity in `∂F/∂x`.
    pub fn variables(&self) -> &[usize] {
        self.tape.variables()
    }

    /// Indices into `dx` the residual reads: the row's sparsity in `∂F/∂ẋ`.
    pub fn derivatives(&self) -> &[usize] {
        self.tape.derivatives()
    }

    /// The compiled tape.
    pub fn tape(&self) -> &Tape {
        &self.tape
    }
}

/// A residual and its exact partial derivatives (see [`Equation::gradient`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Gradient {
    /// The residual.
    pub value: f64,
    /// ∂r/∂x at the indices of [`Equation::variables`].
    pub d_x: Vec<f64>,
    /// ∂r/∂ẋ at the indices of [`Equation::derivatives`].
    pub d_dx: Vec<f64>,
}

/// An expression (a tag, a spec, an objective), parsed, checked and compiled.
#[derive(Debug, Clone, PartialEq)]
pub struct Expression {
    text: String,
    dim: Dimension,
    tape: Tape,
}

impl Expression {
    /// Parses, checks and compiles `text`.
    ///
    /// # Errors
    /// As [`Equation::new`].
    pub fn new(text: &str, symbols: &SymbolTable) -> Result<Expression, ExprError> {
        let e = parse_expression(text)?;
        let dim = check_expression(text, symbols, &e)?;
        let tape = compile(text, symbols, &e)?;
        Ok(Expression { text: text.to_owned(), dim, tape })
    }

    /// The source text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The dimension of the value.
    pub fn dimension(&self) -> Dimension {
        self.dim
    }

    /// The value at `x` and `dx`.
    ///
    /// # Panics
    /// If `x` or `dx` is shorter than [`Tape::required_lengths`].
    pub fn value<S: Scalar>(&self, x: &[S], dx: &[S]) -> S {
        self.tape.eval(x, dx)
    }

    /// As [`Equation::check_at`].
    ///
    /// # Errors
    /// As [`Equation::check_at`].
    pub fn check_at(&self, x: &[f64], dx: &[f64]) -> Result<f64, ExprError> {
        self.tape.eval_checked(&self.text, x, dx)
    }

    /// Indices into `x` the value reads.
    pub fn variables(&self) -> &[usize] {
        self.tape.variables()
    }

    /// Indices into `dx` the value reads.
    pub fn derivatives(&self) -> &[usize] {
        self.tape.derivatives()
    }

    /// The compiled tape.
    pub fn tape(&self) -> &Tape {
        &self.tape
    }
}
