//! External functions: calls whose implementation the caller provides, so that equations can
//! use functions this crate does not know (the thermodynamic package's K-values, enthalpies,
//! densities and bubble temperatures of a port's state) without this crate depending on them.
//!
//! A call `f(a, b, …)` to a name declared with [`SymbolTable::add_function`](crate::SymbolTable::add_function)
//! is resolved at load: the function's [`ExternalFunction::bind`] receives the *source text* of
//! each argument (port and component names, `h_L(out)`, `K(out, o-xylene)`; the arguments are
//! names for the function to interpret, not expressions to evaluate) and returns an
//! [`ExternalCall`]: the variables the call reads (its sparsity), the dimension of its value, and
//! the evaluator. The tape loads those variables and computes the node with
//! [`ExternalEval::value`] over `f64`; over dual numbers and in reverse mode it asks
//! [`ExternalEval::value_and_partials`] for the value and the exact partial derivatives with
//! respect to each variable read, and applies the chain rule itself, so derivatives stay exact
//! (first order: over a dual type of higher order the node is its first-order expansion).
//!
//! ```
//! use std::sync::Arc;
//! use plantwide_expr::{BindError, Equation, ExternalCall, ExternalEval, ExternalFunction, SymbolTable, VarKind};
//! use plantwide_units::Dimension;
//!
//! /// `sq(v)`: the square of variable `v`, by name.
//! #[derive(Debug)]
//! struct Square;
//! #[derive(Debug)]
//! struct SquareEval;
//! impl ExternalEval for SquareEval {
//!     fn value(&self, x: &[f64]) -> f64 { x[0] * x[0] }
//!     fn value_and_partials(&self, x: &[f64], d: &mut [f64]) -> f64 {
//!         d[0] = 2.0 * x[0];
//!         x[0] * x[0]
//!     }
//! }
//! impl ExternalFunction for Square {
//!     fn bind(&self, args: &[&str]) -> Result<ExternalCall, BindError> {
//!         match args {
//!             ["v"] => Ok(ExternalCall { reads: vec![0], dim: Dimension::DIMENSIONLESS, eval: Arc::new(SquareEval) }),
//!             [_] => Err(BindError::at(0, "only `v` can be squared")),
//!             _ => Err(BindError::call(format!("`sq` takes 1 argument, found {}", args.len()))),
//!         }
//!     }
//! }
//! let mut s = SymbolTable::new();
//! s.add_variable("v", 0, Dimension::DIMENSIONLESS, VarKind::Algebraic)?;
//! s.add_function("sq", Arc::new(Square))?;
//! let eq = Equation::new("sq(v) = 4", &s)?;
//! assert_eq!(eq.residual(&[3.0], &[]), 5.0);
//! assert_eq!(eq.gradient(&[3.0], &[]).d_x, [6.0]);
//! let bad = Equation::new("sq(w) = 4", &s).unwrap_err();
//! assert_eq!(bad.render(), "`sq`: only `v` can be squared\nsq(w) = 4\n   ^");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::fmt::Debug;
use std::sync::Arc;

use plantwide_units::Dimension;

/// A function the caller implements, declared by name in a [`crate::SymbolTable`].
pub trait ExternalFunction: Send + Sync + Debug {
    /// Resolves one call: `args` are the arguments' source texts, trimmed.
    ///
    /// # Errors
    /// A [`BindError`] naming the argument at fault (unknown port, unknown component) or the
    /// whole call (wrong number of arguments); the checker locates it in the equation's text.
    fn bind(&self, args: &[&str]) -> Result<ExternalCall, BindError>;
}

/// The evaluator of one bound call, over the values of the variables it reads.
pub trait ExternalEval: Send + Sync + Debug {
    /// The value at `inputs` (`inputs[k]` is the variable `reads[k]` of its [`ExternalCall`]).
    fn value(&self, inputs: &[f64]) -> f64;
    /// The value, and `∂value/∂inputs[k]` into `d[k]` (`d` as long as `inputs`), exact.
    fn value_and_partials(&self, inputs: &[f64], d: &mut [f64]) -> f64;
}

/// A resolved call of an [`ExternalFunction`].
#[derive(Debug, Clone)]
pub struct ExternalCall {
    /// Indices into `x` that the value depends on, in the order the evaluator takes them: the
    /// call's sparsity.
    pub reads: Vec<usize>,
    /// Dimension of the value.
    pub dim: Dimension,
    /// The evaluator.
    pub eval: Arc<dyn ExternalEval>,
}

/// Why a call of an external function is refused.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BindError {
    /// The argument at fault (an index into the arguments), or `None` for the whole call.
    pub arg: Option<usize>,
    /// What is wrong, lowercase, no trailing period.
    pub message: String,
}

impl BindError {
    /// An error located at argument `arg`.
    pub fn at(arg: usize, message: impl Into<String>) -> BindError {
        BindError { arg: Some(arg), message: message.into() }
    }

    /// An error located at the whole call.
    pub fn call(message: impl Into<String>) -> BindError {
        BindError { arg: None, message: message.into() }
    }
}

/// A declared external function (compared by identity).
#[derive(Debug, Clone)]
pub struct FunctionRef(pub Arc<dyn ExternalFunction>);

impl PartialEq for FunctionRef {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

/// A bound call compiled into a tape: the evaluator and the slots of its inputs.
#[derive(Debug, Clone)]
pub(crate) struct ExternalNode {
    pub(crate) eval: Arc<dyn ExternalEval>,
    pub(crate) args: Vec<u32>,
}

impl PartialEq for ExternalNode {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.eval, &other.eval) && self.args == other.args
    }
}
