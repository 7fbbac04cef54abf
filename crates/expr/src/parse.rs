//! The parser: text to [`ast`](crate::ast) with byte spans.
//!
//! Written with [winnow](https://docs.rs/winnow) (see the crate documentation for why). The
//! grammar, from loosest to tightest binding (Modelica's precedence, Modelica Language
//! Specification 3.6, §3.2):
//!
//! ```text
//! equation := expr '=' expr
//! expr     := 'if' expr 'then' expr ('elseif' expr 'then' expr)* 'else' expr | or
//! or       := and ('or' and)*
//! and      := not ('and' not)*
//! not      := 'not' not | cmp
//! cmp      := sum (('<' | '<=' | '>' | '>=') sum)?       -- not chained
//! sum      := term (('+' | '-') term)*                    -- left-associative
//! term     := unary (('*' | '/') unary)*                  -- left-associative
//! unary    := ('-' | '+') unary | power                   -- so -x^2 = -(x^2)
//! power    := primary ('^' unary)?                        -- right-associative: a^b^c = a^(b^c)
//! primary  := number | name | name '(' args ')' | 'der' '(' name ')' | '(' expr ')'
//! number   := digits ('.' digits?)? exponent? | '.' digits exponent?
//! exponent := ('e' | 'E') ('+' | '-')? digits
//! ```
//!
//! Names follow [`crate::name`]. A call `f(…)` is a built-in function when `f` is one
//! ([`Func`]), otherwise a table lookup. As in Modelica, an `if` expression that is an operand
//! must be parenthesised: `2*(if a > b then a else b)`.
//!
//! Work is bounded: the text is at most [`MAX_TEXT_LEN`] bytes and nesting at most
//! [`MAX_DEPTH`] levels, checked before recursing, so hostile text cannot exhaust the stack.

use winnow::ascii::{digit0, digit1, multispace0};
use winnow::combinator::opt;
use winnow::error::{ContextError, ErrMode, StrContext, StrContextValue};
use winnow::prelude::*;
use winnow::stream::{LocatingSlice, Location, Stream};
use winnow::token::{any, one_of, take};

use crate::ast::{BinOp, CmpOp, Equation, Expr, ExprKind, Func};
use crate::error::{ErrorKind, ExprError};
use crate::name::{Input, is_keyword, name};
use crate::span::Span;
use crate::{MAX_DEPTH, MAX_TEXT_LEN};

type PResult<T> = ModalResult<T>;

/// Marks the error raised when nesting exceeds [`MAX_DEPTH`].
const TOO_DEEP: &str = "nesting depth";

/// Parses an equation `lhs = rhs`.
///
/// # Errors
/// [`ErrorKind::TooLong`], [`ErrorKind::TooDeep`] or [`ErrorKind::Syntax`], located in `text`.
pub fn parse_equation(text: &str) -> Result<Equation, ExprError> {
    run(text, |i| {
        let lhs = expr(i, 0)?;
        ws(i)?;
        if !i.starts_with('=') {
            return Err(expected("`=` between the two sides of the equation"));
        }
        any.parse_next(i)?;
        let rhs = expr(i, 0)?;
        let span = lhs.span.join(rhs.span);
        Ok(Equation { lhs, rhs, span })
    })
}

/// Parses an expression (a tag, a spec, an objective).
///
/// # Errors
/// As [`parse_equation`].
pub fn parse_expression(text: &str) -> Result<Expr, ExprError> {
    run(text, |i| expr(i, 0))
}

fn run<T: HasDepth>(text: &str, body: impl FnOnce(&mut Input<'_>) -> PResult<T>) -> Result<T, ExprError> {
    if text.len() > MAX_TEXT_LEN {
        let kind = ErrorKind::TooLong { len: text.len(), max: MAX_TEXT_LEN };
        return Err(ExprError::new(text, Span::new(0, text.len()), kind));
    }
    let mut i = LocatingSlice::new(text);
    let res = body(&mut i).and_then(|res| {
        ws(&mut i)?;
        if i.is_empty() { Ok(res) } else { Err(expected("an operator or the end of the text")) }
    });
    match res {
        Ok(res) if res.depth() > MAX_DEPTH => {
            Err(ExprError::new(text, Span::new(0, text.len()), ErrorKind::TooDeep { max: MAX_DEPTH }))
        }
        Ok(res) => Ok(res),
        Err(e) => Err(syntax_error(text, i.current_token_start(), e)),
    }
}

trait HasDepth {
    fn depth(&self) -> usize;
}

impl HasDepth for Expr {
    fn depth(&self) -> usize {
        self.depth
    }
}

impl HasDepth for Equation {
    fn depth(&self) -> usize {
        self.lhs.depth.max(self.rhs.depth) + 1
    }
}

/// Turns a parser failure at byte `offset` into an [`ExprError`] naming what was expected and
/// what was found.
fn syntax_error(text: &str, offset: usize, e: ErrMode<ContextError>) -> ExprError {
    let ctx = match e {
        ErrMode::Backtrack(c) | ErrMode::Cut(c) => c,
        ErrMode::Incomplete(_) => ContextError::new(),
    };
    let rest = text.get(offset..).unwrap_or("");
    let found_len = found_token_len(rest);
    let span = Span::new(offset, offset + found_len);
    if ctx.context().any(|c| *c == StrContext::Label(TOO_DEEP)) {
        return ExprError::new(text, span, ErrorKind::TooDeep { max: MAX_DEPTH });
    }
    let found = if rest.is_empty() { "the end of the text".to_owned() } else { format!("`{}`", &rest[..found_len]) };
    let wanted = ctx.to_string().replace('\n', "; ");
    let message = if wanted.is_empty() { format!("unexpected {found}") } else { format!("{wanted}, found {found}") };
    ExprError::new(text, span, ErrorKind::Syntax { message })
}

/// Byte length of the token at the start of `rest`: a name, a number, or one character.
fn found_token_len(rest: &str) -> usize {
    let word = rest.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '.')).unwrap_or(rest.len());
    if word > 0 { word } else { rest.chars().next().map_or(0, char::len_utf8) }
}

/// A hard (non-backtracking) error expecting `what`.
fn expected(what: &'static str) -> ErrMode<ContextError> {
    let mut e = ContextError::new();
    e.push(StrContext::Expected(StrContextValue::Description(what)));
    ErrMode::Cut(e)
}

fn too_deep() -> ErrMode<ContextError> {
    let mut e = ContextError::new();
    e.push(StrContext::Label(TOO_DEEP));
    ErrMode::Cut(e)
}

fn ws(i: &mut Input<'_>) -> PResult<()> {
    multispace0.void().parse_next(i)
}

/// Whether the input starts with keyword `kw` as a whole word.
fn at_keyword(i: &Input<'_>, kw: &str) -> bool {
    i.starts_with(kw) && !i[kw.len()..].starts_with(|c: char| c.is_ascii_alphanumeric() || c == '_' || c == '[')
}

/// Consumes keyword `kw` (after white space), or fails expecting `what`.
fn keyword(i: &mut Input<'_>, kw: &'static str, what: &'static str) -> PResult<()> {
    ws(i)?;
    if !at_keyword(i, kw) {
        return Err(expected(what));
    }
    take(kw.len()).void().parse_next(i)
}

fn expr(i: &mut Input<'_>, depth: usize) -> PResult<Expr> {
    if depth >= MAX_DEPTH {
        return Err(too_deep());
    }
    ws(i)?;
    if at_keyword(i, "if") { if_expr(i, depth + 1) } else { or_expr(i, depth + 1) }
}

/// After white space, at `if` or `elseif`.
fn if_expr(i: &mut Input<'_>, depth: usize) -> PResult<Expr> {
    let start = i.current_token_start();
    let kw = if at_keyword(i, "if") { "if" } else { "elseif" };
    take(kw.len()).void().parse_next(i)?;
    let cond = expr(i, depth)?;
    keyword(i, "then", "`then` after the condition")?;
    let yes = expr(i, depth)?;
    ws(i)?;
    let no = if at_keyword(i, "elseif") {
        if depth >= MAX_DEPTH {
            return Err(too_deep());
        }
        if_expr(i, depth + 1)?
    } else {
        keyword(i, "else", "`else` or `elseif` (an `if` expression needs an else branch)")?;
        expr(i, depth)?
    };
    let span = Span::new(start, no.span.end);
    Ok(Expr::new(ExprKind::If(Box::new(cond), Box::new(yes), Box::new(no)), span))
}

fn or_expr(i: &mut Input<'_>, depth: usize) -> PResult<Expr> {
    let mut lhs = and_expr(i, depth)?;
    loop {
        ws(i)?;
        if !at_keyword(i, "or") {
            return Ok(lhs);
        }
        take(2usize).void().parse_next(i)?;
        let rhs = and_expr(i, depth)?;
        let span = lhs.span.join(rhs.span);
        lhs = Expr::new(ExprKind::Or(Box::new(lhs), Box::new(rhs)), span);
        if lhs.depth > MAX_DEPTH {
            return Err(too_deep());
        }
    }
}

fn and_expr(i: &mut Input<'_>, depth: usize) -> PResult<Expr> {
    let mut lhs = not_expr(i, depth)?;
    loop {
        ws(i)?;
        if !at_keyword(i, "and") {
            return Ok(lhs);
        }
        take(3usize).void().parse_next(i)?;
        let rhs = not_expr(i, depth)?;
        let span = lhs.span.join(rhs.span);
        lhs = Expr::new(ExprKind::And(Box::new(lhs), Box::new(rhs)), span);
        if lhs.depth > MAX_DEPTH {
            return Err(too_deep());
        }
    }
}

fn not_expr(i: &mut Input<'_>, depth: usize) -> PResult<Expr> {
    ws(i)?;
    if !at_keyword(i, "not") {
        return cmp_expr(i, depth);
    }
    if depth >= MAX_DEPTH {
        return Err(too_deep());
    }
    let start = i.current_token_start();
    take(3usize).void().parse_next(i)?;
    let inner = not_expr(i, depth + 1)?;
    let span = Span::new(start, inner.span.end);
    Ok(Expr::new(ExprKind::Not(Box::new(inner)), span))
}

fn cmp_op(i: &mut Input<'_>) -> PResult<Option<CmpOp>> {
    ws(i)?;
    let op = [("<=", CmpOp::Le), (">=", CmpOp::Ge), ("<", CmpOp::Lt), (">", CmpOp::Gt)]
        .into_iter()
        .find(|(s, _)| i.starts_with(s));
    match op {
        Some((s, op)) => {
            take(s.len()).void().parse_next(i)?;
            Ok(Some(op))
        }
        None => Ok(None),
    }
}

fn cmp_expr(i: &mut Input<'_>, depth: usize) -> PResult<Expr> {
    let lhs = sum(i, depth)?;
    let Some(op) = cmp_op(i)? else { return Ok(lhs) };
    let rhs = sum(i, depth)?;
    ws(i)?;
    if ["<", ">"].iter().any(|s| i.starts_with(s)) {
        return Err(expected("`and` between comparisons (comparisons do not chain)"));
    }
    let span = lhs.span.join(rhs.span);
    Ok(Expr::new(ExprKind::Compare(op, Box::new(lhs), Box::new(rhs)), span))
}

/// A left-associative chain of `operand (op operand)*`, the operators given as characters.
fn chain(
    i: &mut Input<'_>,
    depth: usize,
    ops: [(char, BinOp); 2],
    operand: fn(&mut Input<'_>, usize) -> PResult<Expr>,
) -> PResult<Expr> {
    let mut lhs = operand(i, depth)?;
    loop {
        ws(i)?;
        let Some(&(_, op)) = ops.iter().find(|(c, _)| i.starts_with(*c)) else { return Ok(lhs) };
        any.parse_next(i)?;
        let rhs = operand(i, depth)?;
        let span = lhs.span.join(rhs.span);
        lhs = Expr::new(ExprKind::Binary(op, Box::new(lhs), Box::new(rhs)), span);
        // A long flat chain is a deep tree: stop growing it as soon as it is too deep.
        if lhs.depth > MAX_DEPTH {
            return Err(too_deep());
        }
    }
}

fn sum(i: &mut Input<'_>, depth: usize) -> PResult<Expr> {
    chain(i, depth, [('+', BinOp::Add), ('-', BinOp::Sub)], term)
}

fn term(i: &mut Input<'_>, depth: usize) -> PResult<Expr> {
    chain(i, depth, [('*', BinOp::Mul), ('/', BinOp::Div)], unary)
}

fn unary(i: &mut Input<'_>, depth: usize) -> PResult<Expr> {
    ws(i)?;
    let sign = if i.starts_with('-') {
        Some(true)
    } else if i.starts_with('+') {
        Some(false)
    } else {
        None
    };
    let Some(negate) = sign else { return power(i, depth) };
    if depth >= MAX_DEPTH {
        return Err(too_deep());
    }
    let start = i.current_token_start();
    any.parse_next(i)?;
    let inner = unary(i, depth + 1)?;
    if !negate {
        return Ok(inner);
    }
    let span = Span::new(start, inner.span.end);
    Ok(Expr::new(ExprKind::Neg(Box::new(inner)), span))
}

fn power(i: &mut Input<'_>, depth: usize) -> PResult<Expr> {
    let base = primary(i, depth)?;
    ws(i)?;
    if !i.starts_with('^') {
        return Ok(base);
    }
    if depth >= MAX_DEPTH {
        return Err(too_deep());
    }
    any.parse_next(i)?;
    let exponent = unary(i, depth + 1)?;
    let span = base.span.join(exponent.span);
    Ok(Expr::new(ExprKind::Binary(BinOp::Pow, Box::new(base), Box::new(exponent)), span))
}

fn primary(i: &mut Input<'_>, depth: usize) -> PResult<Expr> {
    ws(i)?;
    match i.chars().next() {
        Some(c) if c.is_ascii_digit() || c == '.' => number(i),
        Some('(') => parenthesised(i, depth),
        Some(c) if c.is_ascii_alphabetic() || c == '_' => named(i, depth),
        _ => Err(expected("a number, a name or `(`")),
    }
}

fn number(i: &mut Input<'_>) -> PResult<Expr> {
    let start = i.current_token_start();
    let mantissa = |i: &mut Input<'_>| -> PResult<()> {
        if i.starts_with('.') {
            ('.', digit1).void().parse_next(i)
        } else {
            (digit1, opt(('.', digit0))).void().parse_next(i)
        }
    };
    let exponent = (one_of(['e', 'E']), opt(one_of(['+', '-'])), digit1).void();
    let literal =
        (mantissa, opt(exponent)).take().parse_next(i).map_err(|_: ErrMode<ContextError>| expected("a number"))?;
    let value: f64 = literal.parse().map_err(|_| expected("a number"))?;
    Ok(Expr::new(ExprKind::Number(value), Span::new(start, i.previous_token_end())))
}

fn parenthesised(i: &mut Input<'_>, depth: usize) -> PResult<Expr> {
    let start = i.current_token_start();
    any.parse_next(i)?;
    let inner = expr(i, depth)?;
    close_paren(i)?;
    // The node keeps its own kind; the span widens to the parentheses so that errors point at
    // what the user wrote.
    Ok(Expr { span: Span::new(start, i.previous_token_end()), ..inner })
}

fn close_paren(i: &mut Input<'_>) -> PResult<()> {
    ws(i)?;
    if !i.starts_with(')') {
        return Err(expected("`)`"));
    }
    any.void().parse_next(i)
}

/// A name, a call `name(args)`, or `der(name)`; at a letter or `_`.
fn named(i: &mut Input<'_>, depth: usize) -> PResult<Expr> {
    let start = i.current_token_start();
    let before = i.checkpoint();
    let word = name.parse_next(i).map_err(|_: ErrMode<ContextError>| expected("a name"))?;
    let name_span = Span::new(start, i.previous_token_end());
    if word == "der" {
        return der(i, start);
    }
    if word == "if" {
        i.reset(&before);
        return Err(expected("an operand; an `if` expression inside an operation must be in parentheses"));
    }
    if is_keyword(word) {
        i.reset(&before);
        return Err(expected("a number, a name or `(`"));
    }
    ws(i)?;
    if !i.starts_with('(') {
        return Ok(Expr::new(ExprKind::Name(word.to_owned()), name_span));
    }
    any.parse_next(i)?;
    let args = arguments(i, depth)?;
    let span = Span::new(start, i.previous_token_end());
    let kind = match Func::from_name(word) {
        Some(func) => ExprKind::Call(func, args),
        None => ExprKind::Lookup { name: word.to_owned(), name_span, args },
    };
    Ok(Expr::new(kind, span))
}

/// Comma-separated arguments after `(`, through the closing `)`.
fn arguments(i: &mut Input<'_>, depth: usize) -> PResult<Vec<Expr>> {
    let mut args = Vec::new();
    ws(i)?;
    if i.starts_with(')') {
        any.parse_next(i)?;
        return Ok(args);
    }
    loop {
        args.push(expr(i, depth)?);
        ws(i)?;
        match i.chars().next() {
            Some(',') => any.void().parse_next(i)?,
            Some(')') => {
                any.parse_next(i)?;
                return Ok(args);
            }
            _ => return Err(expected("`,` or `)`")),
        }
    }
}

/// `der(name)`, after the keyword.
fn der(i: &mut Input<'_>, start: usize) -> PResult<Expr> {
    ws(i)?;
    if !i.starts_with('(') {
        return Err(expected("`(` after `der`"));
    }
    any.parse_next(i)?;
    ws(i)?;
    let name_start = i.current_token_start();
    let word = name.parse_next(i).map_err(|_: ErrMode<ContextError>| expected("a variable's name inside der()"))?;
    let name_span = Span::new(name_start, i.previous_token_end());
    close_paren(i)?;
    let kind = ExprKind::Der { name: word.to_owned(), name_span };
    Ok(Expr::new(kind, Span::new(start, i.previous_token_end())))
}
