//! The caller's names: parameters, variables and tables, each with its dimension.

use std::collections::BTreeMap;
use std::sync::Arc;

use plantwide_units::Dimension;

use crate::ast::Func;
use crate::error::SymbolError;
use crate::external::{ExternalFunction, FunctionRef};
use crate::name::is_valid_name;
use crate::table::Table;

/// Whether a variable has a time derivative in the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VarKind {
    /// An algebraic variable: `der(x)` is refused.
    Algebraic,
    /// A differential variable (holdup, controller integral): `der(x)` is allowed.
    Differential,
}

/// What a name stands for.
#[derive(Debug, Clone, PartialEq)]
pub enum Symbol {
    /// A constant known at load, folded into the compiled tape.
    Parameter {
        /// Its value in SI units.
        value: f64,
        /// Its dimension.
        dim: Dimension,
    },
    /// An unknown of the model: slot `index` of the variable vector `x` (and of `dx` for its
    /// derivative).
    Variable {
        /// Index into `x` and `dx`.
        index: usize,
        /// Its dimension.
        dim: Dimension,
        /// Algebraic or differential.
        kind: VarKind,
    },
    /// A one-argument table.
    Table(Table),
    /// A function the caller implements (see [`crate::external`]).
    Function(FunctionRef),
}

impl Symbol {
    /// `"a parameter"`, `"a variable"` or `"a table"`, for messages.
    pub fn describe(&self) -> &'static str {
        match self {
            Symbol::Parameter { .. } => "a parameter",
            Symbol::Variable { .. } => "a variable",
            Symbol::Table(_) => "a table",
            Symbol::Function(_) => "a function",
        }
    }
}

/// The names an equation may use. Names follow [`crate::name`]; the built-in functions' names
/// and the keywords are reserved.
#[derive(Debug, Clone, Default)]
pub struct SymbolTable {
    symbols: BTreeMap<String, Symbol>,
    /// The first name and kind declared for each variable index.
    var_names: BTreeMap<usize, (String, VarKind)>,
}

impl SymbolTable {
    /// An empty table.
    pub fn new() -> Self {
        Self::default()
    }

    /// Declares a parameter (a constant in SI units).
    ///
    /// # Errors
    /// An invalid, reserved or duplicate name, or a value that is not finite.
    pub fn add_parameter(&mut self, name: &str, value: f64, dim: Dimension) -> Result<(), SymbolError> {
        if !value.is_finite() {
            return Err(SymbolError::NonFiniteParameter { name: name.to_owned(), value });
        }
        self.insert(name, Symbol::Parameter { value, dim })
    }

    /// Declares a variable at slot `index` of `x` (and of `dx`).
    ///
    /// # Errors
    /// An invalid, reserved or duplicate name.
    pub fn add_variable(&mut self, name: &str, index: usize, dim: Dimension, kind: VarKind) -> Result<(), SymbolError> {
        self.insert(name, Symbol::Variable { index, dim, kind })?;
        self.var_names.entry(index).or_insert_with(|| (name.to_owned(), kind));
        Ok(())
    }

    /// Declares a table, called as `name(x)`.
    ///
    /// # Errors
    /// An invalid, reserved or duplicate name.
    pub fn add_table(&mut self, name: &str, table: Table) -> Result<(), SymbolError> {
        self.insert(name, Symbol::Table(table))
    }

    /// Declares an external function, called as `name(args)` (see [`crate::external`]).
    ///
    /// # Errors
    /// An invalid, reserved or duplicate name.
    pub fn add_function(&mut self, name: &str, f: Arc<dyn ExternalFunction>) -> Result<(), SymbolError> {
        self.insert(name, Symbol::Function(FunctionRef(f)))
    }

    fn insert(&mut self, name: &str, symbol: Symbol) -> Result<(), SymbolError> {
        if !is_valid_name(name) {
            return Err(SymbolError::InvalidName { name: name.to_owned() });
        }
        if Func::from_name(name).is_some() {
            return Err(SymbolError::Reserved { name: name.to_owned() });
        }
        if self.symbols.contains_key(name) {
            return Err(SymbolError::Duplicate { name: name.to_owned() });
        }
        self.symbols.insert(name.to_owned(), symbol);
        Ok(())
    }

    /// The symbol of this name.
    pub fn get(&self, name: &str) -> Option<&Symbol> {
        self.symbols.get(name)
    }

    /// The (first) name declared for variable slot `index`.
    pub fn variable_name(&self, index: usize) -> Option<&str> {
        self.var_names.get(&index).map(|(n, _)| n.as_str())
    }

    /// The kind of the (first) variable declared at slot `index`.
    pub fn variable_kind(&self, index: usize) -> Option<VarKind> {
        self.var_names.get(&index).map(|&(_, k)| k)
    }

    /// The known name closest to `unknown`, if close enough to be a likely typo: the smallest
    /// optimal-string-alignment distance (Damerau–Levenshtein without repeated edits, via
    /// `strsim`) among names within `max(1, len/3)` edits, a case-only difference counting as
    /// closest. Ties go to the alphabetically first name.
    pub fn suggest(&self, unknown: &str) -> Option<String> {
        let limit = (unknown.chars().count() / 3).max(1);
        self.symbols
            .keys()
            .map(|k| {
                let d = if k.eq_ignore_ascii_case(unknown) { 0 } else { strsim::osa_distance(k, unknown) };
                (d, k)
            })
            .filter(|&(d, _)| d <= limit)
            .min_by_key(|&(d, _)| d)
            .map(|(_, k)| k.clone())
    }

    /// Every declared name, sorted.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.symbols.keys().map(String::as_str)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn declarations_are_validated() {
        let mut s = SymbolTable::new();
        s.add_parameter("UA", 5.0e3, Dimension::UA).unwrap();
        assert_eq!(s.add_parameter("UA", 1.0, Dimension::UA), Err(SymbolError::Duplicate { name: "UA".into() }));
        assert_eq!(s.add_parameter("exp", 1.0, Dimension::UA), Err(SymbolError::Reserved { name: "exp".into() }));
        assert_eq!(s.add_parameter("a b", 1.0, Dimension::UA), Err(SymbolError::InvalidName { name: "a b".into() }));
        assert_eq!(s.add_parameter("then", 1.0, Dimension::UA), Err(SymbolError::InvalidName { name: "then".into() }));
        assert!(matches!(s.add_parameter("k", f64::NAN, Dimension::UA), Err(SymbolError::NonFiniteParameter { .. })));
    }

    #[test]
    fn suggestions() {
        let mut s = SymbolTable::new();
        for (i, n) in ["CA", "CAf", "T", "Tj", "in.F"].iter().enumerate() {
            s.add_variable(n, i, Dimension::DIMENSIONLESS, VarKind::Algebraic).unwrap();
        }
        assert_eq!(s.suggest("Caf").as_deref(), Some("CAf"));
        assert_eq!(s.suggest("in.f").as_deref(), Some("in.F"));
        assert_eq!(s.suggest("Tjj").as_deref(), Some("Tj"));
        assert_eq!(s.suggest("pressure"), None);
        assert_eq!(s.variable_name(3), Some("Tj"));
    }
}
