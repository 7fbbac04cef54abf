//! A tag: a named quantity computed from plant variables by an expression (issue 57), such as an
//! operating cost `"cost": "steam_price*reboiler.duty + feed_price*fresh.F"`.
//!
//! A tag is one algebraic variable `value` of the plant with the equation
//!
//! ```text
//! value = expr(v_1, …, v_n)
//! ```
//!
//! where `v_k` are the plant variables and inputs the expression names by path (`column.T[5]`,
//! `reboiler.duty`, `lc.op`, another tag's `cost.value`), read as the block's signals, and the
//! constants are the flowsheet's `parameters` with their units. So the tag has the dimension of
//! its expression, an exact Jacobian (the expression's tape over dual numbers) and a sparsity
//! pattern read from the expression, and every analysis sees it as a variable: `gains` and
//! `linearize` take it as an output, `run` records it, a design spec or a controller may hold it.
//! It is explicit ([`UnitModel::explicit`]): the dynamic integrator computes it after every step
//! rather than iterating on it.
//!
//! The residual is scaled by the value's nominal size, `(expr − value)/s` with `s` the larger of
//! `|expr|` at the guess and 1 SI unit, so that a cost of 10⁶ $/s and a fraction of 10⁻³ weigh
//! alike in Newton's stopping test.

use plantwide_expr::{ExprError, Expression, SymbolError, SymbolTable, VarKind as ExprVarKind};
use plantwide_units::Dimension;

use crate::{Scalar, SignalSpec, UnitIo, UnitModel, VarSpec};

/// Why a tag's expression cannot be compiled.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TagError {
    /// The expression's own error (syntax, a dimension mismatch, an unknown name), located in
    /// its text; `Display` renders the text with a caret under the position.
    #[error("{}", .0.render())]
    Expression(#[from] ExprError),
    /// A parameter or a read path the symbol table refuses.
    #[error("`{name}`: {source}")]
    Symbol {
        /// The parameter's name or the path.
        name: String,
        /// Why.
        source: SymbolError,
    },
    /// A `der()` in a tag.
    #[error("a tag is a function of the plant's variables; `der()` has no place in it: {text}")]
    Derivative {
        /// The expression.
        text: String,
    },
}

/// A tag's expression compiled against the plant paths it reads.
#[derive(Debug, Clone)]
pub struct Tag {
    expr: Expression,
    /// The paths read, in signal order (signal `k` is local slot `1 + k`).
    paths: Vec<String>,
    dim: Dimension,
    scale: f64,
}

/// Local slot of signal `k`: after the tag's one own variable (a tag has no inlets or inputs).
const fn slot(k: usize) -> usize {
    1 + k
}

impl Tag {
    /// Compile `text` against `reads`, the paths it names with their dimensions (in the order of
    /// [`names`]), and the flowsheet's `parameters` (name, SI value, dimension). `guess` holds the
    /// values of the read paths at the plant's initial guess, for the residual's scale.
    ///
    /// # Errors
    /// The expression's error (a dimension mismatch, a name that is neither a read path nor a
    /// parameter, a `der()`), located in the text.
    pub fn build(
        text: &str,
        reads: &[(String, Dimension)],
        parameters: &[(String, f64, Dimension)],
        guess: &[f64],
    ) -> Result<Tag, TagError> {
        let mut symbols = SymbolTable::new();
        fn symbol(name: &str) -> impl FnOnce(SymbolError) -> TagError + '_ {
            move |source| TagError::Symbol { name: name.to_string(), source }
        }
        for (name, value, dim) in parameters {
            symbols.add_parameter(name, *value, *dim).map_err(symbol(name))?;
        }
        for (k, (path, dim)) in reads.iter().enumerate() {
            if symbols.get(path).is_none() {
                symbols.add_variable(path, slot(k), *dim, ExprVarKind::Algebraic).map_err(symbol(path))?;
            }
        }
        let expr = Expression::new(text, &symbols)?;
        if !expr.derivatives().is_empty() {
            return Err(TagError::Derivative { text: text.to_string() });
        }
        let mut local = vec![0.0; slot(reads.len())];
        local[1..].copy_from_slice(guess);
        let at_guess = expr.value(&local, &[]);
        let scale = if at_guess.is_finite() { at_guess.abs().max(1.0) } else { 1.0 };
        let dim = expr.dimension();
        Ok(Tag { expr, paths: reads.iter().map(|(p, _)| p.clone()).collect(), dim, scale })
    }

    /// The tag's dimension: its expression's.
    pub fn dimension(&self) -> Dimension {
        self.dim
    }

    /// The expression's text.
    pub fn text(&self) -> &str {
        self.expr.text()
    }
}

/// The names an expression's text uses, in order of first appearance, with their byte spans: the
/// candidates for plant paths (the caller tells paths from parameters).
///
/// # Errors
/// The text's syntax error.
pub fn names(text: &str) -> Result<Vec<(String, plantwide_expr::Span)>, ExprError> {
    Ok(plantwide_expr::parse_expression(text)?.names())
}

impl UnitModel for Tag {
    fn type_name(&self) -> &'static str {
        "tag"
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        vec![VarSpec::algebraic("value", self.dim, self.scale)]
    }
    fn signals(&self) -> Vec<SignalSpec> {
        self.paths.iter().enumerate().map(|(k, p)| SignalSpec { role: format!("read[{k}]"), path: p.clone() }).collect()
    }
    fn equation_name(&self, _k: usize, _own_names: &[String]) -> String {
        format!("value = {}", self.expr.text())
    }
    fn pattern(&self, _layout: &crate::LocalLayout) -> Option<Vec<(usize, usize)>> {
        let mut p = vec![(0, 0)];
        p.extend(self.expr.variables().iter().map(|&j| (0, j)));
        Some(p)
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        r[0] = (self.expr.value(io.local, &[]) - io.var(0)) / self.scale;
    }
    fn explicit(&self, _layout: &crate::LocalLayout) -> Vec<usize> {
        vec![0]
    }
    fn complete(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        own[0] = self.expr.value(io.local, &[]);
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let v = self.expr.value(io.local, &[]);
        own[0] = if v.is_finite() { v } else { 0.0 };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{binary_package, jacobian_error};
    use crate::{LocalLayout, StreamLayout, Unit};

    fn layout(n: usize) -> LocalLayout {
        LocalLayout {
            stream: StreamLayout { n_comp: 2 },
            n_outlets: 0,
            n_internal: 1,
            n_inlets: 0,
            n_inputs: 0,
            n_signals: n,
        }
    }

    #[test]
    fn cost_tag_value_dimension_and_exact_jacobian() {
        let price = Dimension::CURRENCY / Dimension::ENERGY;
        let feed_price = Dimension::CURRENCY / Dimension::AMOUNT;
        let params = vec![("steam".to_string(), 2e-8, price), ("feed".to_string(), 0.03, feed_price)];
        let reads =
            vec![("reboiler.duty".to_string(), Dimension::POWER), ("fresh.F".to_string(), Dimension::MOLAR_FLOW)];
        let tag = Tag::build("steam*reboiler.duty + feed*fresh.F", &reads, &params, &[1e6, 10.0]).unwrap();
        assert_eq!(tag.dimension(), Dimension::COST_RATE);
        // value = 2e-8·1e6 + 0.03·10 = 0.32 $/s; the residual is zero there and scaled by 1.
        let thermo = binary_package();
        let l = layout(2);
        let mut r = [f64::NAN];
        let local = [0.32, 1e6, 10.0];
        Unit::residual(&tag, &UnitIo { local: &local, layout: &l, thermo: &thermo, time: 0.0 }, &mut r);
        assert!(r[0].abs() < 1e-16, "{}", r[0]);
        let local = [0.0, 2e6, 5.0];
        Unit::residual(&tag, &UnitIo { local: &local, layout: &l, thermo: &thermo, time: 0.0 }, &mut r);
        assert!((r[0] - (0.04 + 0.15)).abs() < 1e-15, "{}", r[0]);
        assert!(jacobian_error(&tag, &l, &thermo, &local, 1) < 1e-9);
    }

    #[test]
    fn a_dimension_mismatch_is_located_in_the_text() {
        let reads =
            vec![("reboiler.duty".to_string(), Dimension::POWER), ("fresh.F".to_string(), Dimension::MOLAR_FLOW)];
        let err = Tag::build("reboiler.duty + fresh.F", &reads, &[], &[1.0, 1.0]).unwrap_err().to_string();
        assert!(err.contains("W and mol/s") && err.contains("^^^"), "{err}");
    }

    #[test]
    fn names_in_source_order_once_each() {
        let n = names("a*column.x[3][light] + max(b, a) - c.value").unwrap();
        let n: Vec<&str> = n.iter().map(|(s, _)| s.as_str()).collect();
        assert_eq!(n, ["a", "column.x[3][light]", "b", "c.value"]);
    }
}
