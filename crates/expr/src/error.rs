//! Errors: [`ExprError`] locates a problem in an equation's text; [`SymbolError`] rejects a
//! declaration.

use plantwide_units::Dimension;

use crate::span::{Span, render_caret};
use crate::table::TableError;

/// A problem in an expression or equation: what ([`ErrorKind`]), the text, and the byte span.
///
/// `Display` gives the message with the span and the text on one line; [`ExprError::render`]
/// gives the message over the text with a caret line under the span.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{kind} (at bytes {span} of `{text}`)")]
pub struct ExprError {
    /// The full text of the equation or expression.
    pub text: String,
    /// The offending part of `text`.
    pub span: Span,
    /// What is wrong.
    pub kind: ErrorKind,
}

impl ExprError {
    pub(crate) fn new(text: &str, span: Span, kind: ErrorKind) -> Self {
        ExprError { text: text.to_owned(), span, kind }
    }

    /// The message, then the text, then carets under the offending span:
    ///
    /// ```text
    /// `+` needs operands of the same dimension, found K and mol/s
    /// T + F
    /// ^^^^^
    /// ```
    pub fn render(&self) -> String {
        format!("{}\n{}", self.kind, render_caret(&self.text, self.span))
    }
}

/// A dimension for messages: its SI symbol (`mol/s`, `J/(mol*K)`, `kg*m/s3`), or
/// `dimensionless`.
pub(crate) fn show(dim: &Dimension) -> String {
    if dim.is_dimensionless() { "dimensionless".to_owned() } else { dim.to_string() }
}

fn did_you_mean(suggestion: &Option<String>) -> String {
    suggestion.as_ref().map(|s| format!("; did you mean `{s}`?")).unwrap_or_default()
}

/// What is wrong with an expression or equation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The text exceeds [`crate::MAX_TEXT_LEN`] bytes.
    #[error("the text is {len} bytes long; at most {max} are allowed")]
    TooLong {
        /// Length of the text in bytes.
        len: usize,
        /// The limit.
        max: usize,
    },
    /// Parentheses, calls and operators nest deeper than [`crate::MAX_DEPTH`].
    #[error("the expression nests deeper than {max} levels")]
    TooDeep {
        /// The limit.
        max: usize,
    },
    /// The text does not follow the grammar.
    #[error("syntax error: {message}")]
    Syntax {
        /// What the parser expected.
        message: String,
    },
    /// A number literal overflows to infinity (`1e999`).
    #[error("number `{literal}` is out of range")]
    NumberOutOfRange {
        /// The literal as written.
        literal: String,
    },
    /// A name the symbol table does not know.
    #[error("unknown name `{name}`{}", did_you_mean(.suggestion))]
    UnknownName {
        /// The name as written.
        name: String,
        /// The closest known name, if one is close.
        suggestion: Option<String>,
    },
    /// A known name used as the wrong kind of symbol (a table as a value, a parameter in `der`).
    #[error("`{name}` is {found}, but {expected} is expected here")]
    WrongKind {
        /// The name.
        name: String,
        /// What it is (`"a table"`, `"a parameter"`, `"a variable"`).
        found: &'static str,
        /// What the place needs.
        expected: &'static str,
    },
    /// `der(x)` of an algebraic variable.
    #[error("der({name}): `{name}` is an algebraic variable; only differential variables have a derivative")]
    NotDifferential {
        /// The variable.
        name: String,
    },
    /// A function or table called with the wrong number of arguments.
    #[error("`{func}` takes {expected} argument(s), found {found}")]
    Arity {
        /// The function or table name.
        func: String,
        /// Arguments it takes.
        expected: usize,
        /// Arguments given.
        found: usize,
    },
    /// Two quantities that must agree in dimension do not.
    #[error("{what} must have the same dimension, found {} and {}", show(.left), show(.right))]
    DimensionMismatch {
        /// What must agree (`"the operands of `+`"`, `"the two sides of the equation"`).
        what: String,
        /// Dimension of the first (left) one.
        left: Dimension,
        /// Dimension of the second (right) one, or the one expected.
        right: Dimension,
    },
    /// A bare number where a dimensioned quantity is needed (`T + 273.15`).
    #[error(
        "bare number {literal} used with a quantity in {}: declare it as a parameter with units",
        show(.dim)
    )]
    BareNumber {
        /// The number as written.
        literal: String,
        /// The dimension of the other operand.
        dim: Dimension,
    },
    /// `exp`, `ln`, `log10` or a variable exponent applied to a dimensioned quantity.
    #[error("{what} must be dimensionless, found {}", show(.dim))]
    NotDimensionless {
        /// What must be dimensionless (`"the argument of `exp`"`).
        what: String,
        /// Its dimension.
        dim: Dimension,
    },
    /// The square root of a dimension with an odd exponent (`sqrt(T)`).
    #[error("sqrt of a quantity in {}: its dimension's exponents are not all even", show(.dim))]
    OddRoot {
        /// The argument's dimension.
        dim: Dimension,
    },
    /// `x^p` where x has a dimension and p is not a constant.
    #[error("the exponent of a quantity in {} must be a constant number", show(.dim))]
    NonConstantExponent {
        /// The base's dimension.
        dim: Dimension,
    },
    /// `x^p` whose dimension would have non-integer exponents (`T^0.5`).
    #[error("a quantity in {} raised to {exponent} has a fractional dimension", show(.dim))]
    FractionalPower {
        /// The base's dimension.
        dim: Dimension,
        /// The exponent.
        exponent: f64,
    },
    /// A dimension exponent leaves the range of the units crate (beyond ±127).
    #[error("the dimension's exponents overflow")]
    DimensionOverflow,
    /// A condition where a number is expected (`x + (a > b)`).
    #[error("a condition (comparison, `and`, `or`, `not`) is used where a number is expected")]
    ConditionAsNumber,
    /// A number where a condition is expected (`if x then …`).
    #[error("a number is used where a condition is expected; write a comparison such as `x > 0`")]
    NumberAsCondition,
    /// A constant sub-expression that is not a finite number (`ln(0)`, `1/0`).
    #[error("this constant part evaluates to {value}, not a finite number")]
    NonFiniteConstant {
        /// The value it folds to.
        value: f64,
    },
    /// A denominator that is a constant zero (`F/(a - a)` with `a` a parameter).
    #[error("division by a denominator that is always zero")]
    DivisionByZero,
    /// A denominator that is exactly zero at the guess values.
    #[error("the denominator is zero at the guess values")]
    ZeroDenominator,
    /// A logarithm or square root outside its domain at the guess values.
    #[error("{func} of {value} at the guess values, outside its domain")]
    OutOfDomain {
        /// `"ln"`, `"log10"`, `"sqrt"` or `"^"`.
        func: &'static str,
        /// The argument's value.
        value: f64,
    },
    /// A call of an external function refused by the function (an unknown port or component).
    #[error("`{func}`: {message}")]
    BadCall {
        /// The function's name.
        func: String,
        /// What the function says is wrong.
        message: String,
    },
    /// A value that is not finite at the guess values.
    #[error("this part evaluates to {value} at the guess values")]
    NonFinite {
        /// The value.
        value: f64,
    },
}

/// A declaration refused by [`crate::SymbolTable`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SymbolError {
    /// Not a name token (see [`crate::name`]) or a keyword.
    #[error("`{name}` is not a valid name (letters, digits, `_`, `.` segments and `[index]`; not a keyword)")]
    InvalidName {
        /// The name.
        name: String,
    },
    /// A built-in function's name.
    #[error("`{name}` is the name of a built-in function")]
    Reserved {
        /// The name.
        name: String,
    },
    /// Declared twice.
    #[error("`{name}` is declared twice")]
    Duplicate {
        /// The name.
        name: String,
    },
    /// A parameter whose value is NaN or infinite.
    #[error("parameter `{name}` has the value {value}, not a finite number")]
    NonFiniteParameter {
        /// The name.
        name: String,
        /// The value.
        value: f64,
    },
    /// A table with bad data.
    #[error("table `{name}`: {source}")]
    Table {
        /// The table's name.
        name: String,
        /// What is wrong with its points.
        source: TableError,
    },
}
