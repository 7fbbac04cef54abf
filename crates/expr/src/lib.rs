//! Equations written as text (issue 57): parsed once, checked for names and dimensions against
//! the caller's symbols, and compiled to a flat tape that evaluates over `f64` and over the dual
//! numbers the engine differentiates with, so that a unit written as equations gets exact
//! Jacobians and a sparsity pattern read from the expression.
//!
//! ```
//! use plantwide_expr::{Equation, SymbolTable, VarKind};
//! use plantwide_units::Dimension;
//!
//! let mut s = SymbolTable::new();
//! s.add_variable("M", 0, Dimension::AMOUNT, VarKind::Differential)?;
//! s.add_variable("Fin", 1, Dimension::MOLAR_FLOW, VarKind::Algebraic)?;
//! s.add_variable("Fout", 2, Dimension::MOLAR_FLOW, VarKind::Algebraic)?;
//! let eq = Equation::new("der(M) = Fin - Fout", &s)?;
//! assert_eq!(eq.dimension(), Dimension::MOLAR_FLOW);
//! assert_eq!((eq.variables(), eq.derivatives()), (&[1, 2][..], &[0][..]));
//! let r = eq.residual(&[10.0, 3.0, 1.0], &[0.5, 0.0, 0.0]);
//! assert_eq!(r, 0.5 - (3.0 - 1.0));
//!
//! let bad = Equation::new("der(M) = Fin - M", &s).unwrap_err();
//! assert_eq!(bad.render(), "the operands of `-` must have the same dimension, found mol/s and mol\n\
//!                           der(M) = Fin - M\n         ^^^^^^^");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Pipeline
//! [`parse_equation`] / [`parse_expression`] (syntax in [`parse`], names in [`name`]) →
//! dimension check against a [`SymbolTable`] (rules in the `check` module docs) → [`Tape`]
//! (constants folded). [`Equation::new`] and [`Expression::new`] do all three. Then
//! [`Equation::check_at`] refuses a guess at which the residual cannot be evaluated, and
//! [`check_structure`] refuses an equation set that is structurally singular.
//!
//! # External functions
//! A caller declares functions this crate does not know ([`SymbolTable::add_function`]): a call
//! `f(a, b)` is bound at load to the variables it reads and the dimension of its value, and
//! compiled into one tape node whose value and exact partial derivatives come from the caller's
//! [`ExternalEval`], so `f64`, dual-number and reverse-mode evaluation all stay exact. The model
//! crate binds the thermodynamic package's functions of a port's state this way; this crate
//! depends on no thermodynamics (see [`external`]).
//!
//! # Parser crate
//! The parser uses [winnow](https://docs.rs/winnow) 1.x: actively maintained (it parses every
//! `Cargo.toml` through `toml_edit`), no dependencies of its own so it builds in seconds,
//! byte offsets through `LocatingSlice`, and plain functions rather than a grammar file or a
//! proc macro (pest, lalrpop) or a large type-level combinator graph (chumsky), so the
//! precedence levels read as the grammar in [`parse`] and the nesting limit is an ordinary
//! counter.
//!
//! # Limits
//! Work is bounded by [`MAX_TEXT_LEN`] bytes of text and [`MAX_DEPTH`] levels of nesting; the
//! tape is then linear in the text.

#![warn(missing_docs)]

pub mod ast;
mod check;
mod compiled;
mod error;
pub mod external;
pub mod name;
pub mod parse;
mod span;
mod structure;
mod symbols;
mod table;
mod tape;
#[doc(hidden)]
pub mod testing;

pub use compiled::{Equation, Expression, Gradient};
pub use error::{ErrorKind, ExprError, SymbolError};
pub use external::{BindError, ExternalCall, ExternalEval, ExternalFunction};
pub use parse::{parse_equation, parse_expression};
pub use span::{Span, render_caret};
pub use structure::{Matching, StructuralError, StructureMode, check_structure, maximum_matching, name_list};
pub use symbols::{Symbol, SymbolTable, VarKind};
pub use table::{Interpolation, Table, TableError};
pub use tape::{INLINE_SLOTS, Tape, Workspace};

/// A real scalar the tapes evaluate over: `f64`, or a dual number of `num-dual` for exact
/// derivatives. The same bounds as the thermodynamics crate's `Scalar`, declared here so that
/// this crate depends on no thermodynamics: any scalar of the model layer is one of these.
pub trait Scalar: num_dual::DualNum<Primitive = f64> + Copy + Send + Sync + 'static {}

impl<T: num_dual::DualNum<Primitive = f64> + Copy + Send + Sync + 'static> Scalar for T {}

/// The longest equation or expression text accepted, in bytes (a long energy balance is a few
/// hundred).
pub const MAX_TEXT_LEN: usize = 4096;

/// The deepest nesting accepted: parentheses, calls, `if`, unary signs and powers while parsing,
/// and the height of the syntax tree (a sum of n terms is n − 1 deep). Keeps every recursive
/// pass (parse, check, compile) far from the stack's end.
pub const MAX_DEPTH: usize = 128;
