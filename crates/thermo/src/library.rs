//! The built-in component library and binary interaction parameters, embedded from `data/*.json`.

use serde::{Deserialize, Serialize};

use crate::{ActivityModel, Component, ThermoError};

/// Binary interaction parameters for one pair, in the Aspen Plus form used by [`ActivityModel`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BinaryPair {
    /// `"nrtl"` or `"wilson"`.
    pub model: String,
    /// First component name.
    pub i: String,
    /// Second component name.
    pub j: String,
    /// `a_ij` [-].
    #[serde(default)]
    pub a_ij: f64,
    /// `a_ji` [-].
    #[serde(default)]
    pub a_ji: f64,
    /// `b_ij` [K].
    #[serde(default)]
    pub b_ij: f64,
    /// `b_ji` [K].
    #[serde(default)]
    pub b_ji: f64,
    /// NRTL non-randomness `α_ij = α_ji` [-] (ignored for Wilson).
    #[serde(default)]
    pub alpha: f64,
    /// Where the numbers come from.
    #[serde(default)]
    pub source: String,
}

/// The built-in library: pure components and binary pairs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Library {
    /// Free-text description of the data sources.
    #[serde(default)]
    pub sources: Vec<String>,
    /// Pure components.
    pub components: Vec<Component>,
    /// Binary interaction parameters.
    pub binary_pairs: Vec<BinaryPair>,
}

impl Library {
    /// The library shipped in `data/library.json`.
    pub fn builtin() -> Result<Library, ThermoError> {
        todo!()
    }
    /// A component by name.
    pub fn component(&self, name: &str) -> Result<&Component, ThermoError> {
        todo!("{name}")
    }
    /// Build the activity model for `names` (in that order) from the library's pairs plus `extra`
    /// pairs (which take precedence). `kind` is `"nrtl"` or `"wilson"`. Missing pairs are an error.
    pub fn activity_model(&self, kind: &str, names: &[&str], extra: &[BinaryPair]) -> Result<ActivityModel, ThermoError> {
        todo!("{kind}{}{}", names.len(), extra.len())
    }
}
