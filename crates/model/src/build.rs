//! Building units from their flowsheet descriptions: quantity conversion and error collection.

use std::collections::BTreeMap;

use plantwide_thermo::ThermoPackage;
use plantwide_units::{Dimension, QuantityValue};

/// A problem with one field of the flowsheet file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{path}: {message}")]
pub struct FieldError {
    /// JSON path of the field (`units.feed.F`).
    pub path: String,
    /// What is wrong and what would fix it.
    pub message: String,
}

/// Context for building one unit: the flowsheet's components and thermodynamics, the JSON path of
/// the unit, and the errors found so far (all are reported, not only the first).
#[derive(Debug)]
pub struct BuildCx<'a> {
    /// Component names in flowsheet order.
    pub components: &'a [String],
    /// Thermodynamic package.
    pub thermo: &'a ThermoPackage,
    /// JSON path of the unit being built (`units.tank1`).
    pub path: String,
    /// Errors collected while building.
    pub errors: Vec<FieldError>,
    /// Where the notes of bare numbers go (see [`BuildCx::noting`]).
    notes: Notes,
}

/// A shared list of notes on a flowsheet's fields: numbers given without a unit for a quantity
/// that has one, read in SI (`"T": 80` is 80 K), which a user may not have meant.
pub type Notes = std::sync::Arc<std::sync::Mutex<Vec<FieldError>>>;

impl<'a> BuildCx<'a> {
    /// A context for the unit at JSON path `path`.
    pub fn new(components: &'a [String], thermo: &'a ThermoPackage, path: impl Into<String>) -> BuildCx<'a> {
        BuildCx { components, thermo, path: path.into(), errors: Vec::new(), notes: Notes::default() }
    }
    /// Send the notes of bare numbers to `notes` (the assembler's list for the whole flowsheet).
    pub fn noting(mut self, notes: Notes) -> BuildCx<'a> {
        self.notes = notes;
        self
    }
    /// Record an error on `field` of the current unit.
    pub fn error(&mut self, field: &str, message: impl Into<String>) {
        let path = if field.is_empty() { self.path.clone() } else { format!("{}.{field}", self.path) };
        self.errors.push(FieldError { path, message: message.into() });
    }
    /// Convert a quantity to SI, recording a dimension or parse error (returns NaN on error).
    pub fn quantity(&mut self, field: &str, value: &QuantityValue, dim: Dimension) -> f64 {
        self.within(field, value, dim, crate::limits::max_magnitude(dim), "in which the models hold")
    }
    /// `value` in SI, finite and at most `max` in magnitude (else NaN and an error saying `what`).
    fn within(&mut self, field: &str, value: &QuantityValue, dim: Dimension, max: f64, what: &str) -> f64 {
        if let Some(note) = bare_note(value, dim) {
            let path = if field.is_empty() { self.path.clone() } else { format!("{}.{field}", self.path) };
            self.notes
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
                .push(FieldError { path, message: note });
        }
        match value.to_si(dim) {
            Ok(v) if v.is_finite() && v.abs() <= max => v,
            Ok(v) if v.is_finite() => {
                let (v, max) = (crate::limits::number(v), crate::limits::number(max));
                self.error(field, format!("{v} {dim} is beyond the ±{max} {dim} {what}"));
                f64::NAN
            }
            Ok(v) => {
                self.error(field, format!("value {v} is not finite"));
                f64::NAN
            }
            Err(e) => {
                self.error(field, e.to_string());
                f64::NAN
            }
        }
    }
    /// A quantity that must be ≥ 0.
    pub fn non_negative(&mut self, field: &str, value: &QuantityValue, dim: Dimension) -> f64 {
        let v = self.quantity(field, value, dim);
        if v < 0.0 {
            self.error(field, format!("must not be negative (got `{value}`)"));
        }
        v
    }
    /// A quantity that must be > 0.
    pub fn positive(&mut self, field: &str, value: &QuantityValue, dim: Dimension) -> f64 {
        let v = self.quantity(field, value, dim);
        if v <= 0.0 {
            self.error(field, format!("must be positive (got `{value}`)"));
        }
        v
    }
    /// A controller gain (output per unit of measurement): positive and finite, at most
    /// [`GAIN_SPAN`] times the largest magnitude of its dimension. A gain is not a quantity of
    /// the output's kind: a flow per mole fraction of a high-purity column, tuned by BLT, is
    /// 5e7 mol/s per unit and was refused as "beyond ±1e6 mol/s", taking the engine's own
    /// tunings down with it.
    pub fn gain(&mut self, field: &str, value: &QuantityValue, dim: Dimension) -> f64 {
        let max = GAIN_SPAN * crate::limits::max_magnitude(dim);
        let v = self.within(field, value, dim, max, "a controller gain may have");
        if v <= 0.0 {
            self.error(field, format!("must be positive (got `{value}`)"));
        }
        v
    }
    /// A count (`stages`, `inlets`) within `limit`; records an error naming the field and the
    /// environment variable that raises the limit.
    pub fn count(&mut self, field: &str, n: usize, limit: crate::limits::Limit) -> bool {
        match limit.check(n, &format!("`{field}`")) {
            Some(msg) => {
                self.error(field, msg);
                false
            }
            None => true,
        }
    }
    /// A plain fraction in `[lo, hi]`.
    pub fn in_range(&mut self, field: &str, v: f64, lo: f64, hi: f64) -> f64 {
        if !(v.is_finite() && v >= lo && v <= hi) {
            self.error(field, format!("must lie in [{lo}, {hi}] (got {v})"));
        }
        v
    }
    /// A composition given as `{component: fraction}`; missing components are 0; the fractions must
    /// be non-negative and sum to 1 within 1e-6 (they are then normalised exactly).
    pub fn composition(&mut self, field: &str, map: &BTreeMap<String, f64>) -> Vec<f64> {
        let mut z = vec![0.0; self.components.len()];
        for (name, &v) in map {
            match self.components.iter().position(|c| c == name) {
                Some(i) => {
                    if !(v.is_finite() && v >= 0.0) {
                        self.error(
                            &format!("{field}.{name}"),
                            format!("mole fraction must be finite and ≥ 0 (got {v})"),
                        );
                    }
                    z[i] = v;
                }
                None => self.error(
                    &format!("{field}.{name}"),
                    format!(
                        "`{name}` is not a component of this flowsheet (components: {})",
                        self.components.join(", ")
                    ),
                ),
            }
        }
        let sum: f64 = z.iter().sum();
        if (sum - 1.0).abs() > 1e-6 {
            self.error(field, format!("mole fractions sum to {sum}, not 1"));
        } else {
            z.iter_mut().for_each(|v| *v /= sum);
        }
        z
    }
    /// Finish: the built value or every error found.
    pub fn finish<T>(self, value: T) -> Result<T, Vec<FieldError>> {
        if self.errors.is_empty() { Ok(value) } else { Err(self.errors) }
    }
}

/// The note on `value` if it is a bare number for a quantity of dimension `dim` (zero needs no
/// unit, except a temperature's): what it is read as, and what to write instead.
pub fn bare_note(value: &QuantityValue, dim: Dimension) -> Option<String> {
    let x = value.bare()?;
    if dim == Dimension::DIMENSIONLESS || (x == 0.0 && dim != Dimension::TEMPERATURE) {
        return None;
    }
    let example =
        if dim == Dimension::TEMPERATURE { format!("\"{x} degC\" or \"{x} K\"") } else { format!("\"{x} {dim}\"") };
    Some(format!("{x} has no unit and is read in SI, as {x} {dim}; write the unit meant (e.g. {example})"))
}

/// How far a controller gain may exceed the largest magnitude of its dimension: the output's
/// whole range for a billionth of the measurement's unit.
pub const GAIN_SPAN: f64 = 1e9;
