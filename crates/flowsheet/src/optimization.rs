//! The `"optimization"` section of a flowsheet file: the economic problem `plantwide optimize`
//! solves at steady state (Skogestad's top-down procedure, step 1: optimal operation with its
//! active constraints).
//!
//! ```json
//! "optimization": {
//!   "objective": "cost@$/h",
//!   "vary": {"evaporator.F1": {"max": "20 kg/min"}, "evaporator.P100": {"max": "400 kPa"}},
//!   "constraints": {"evaporator.X2": {"min": "35.5 %"}, "evaporator.P2": {"min": "40 kPa", "max": "80 kPa"}}
//! }
//! ```
//!
//! The objective is a tag (an expression of plant variables and the file's priced `parameters`,
//! in the file's units) or any variable; the degrees of freedom are free inputs and controller
//! setpoints, each with optional bounds; the constraints are bounds on any variable (product
//! specifications, operating limits). Limits are quantities with units; a bare number is SI.

use indexmap::IndexMap;
use plantwide_units::QuantityValue;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Whether the objective is minimized (a cost) or maximized (a profit).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Sense {
    /// Minimize the objective (default).
    #[default]
    Minimize,
    /// Maximize the objective.
    Maximize,
}

/// A lower and an upper limit, either optional (a quantity with units; a bare number is SI).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Limits {
    /// Lower limit (`"35.5 %"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<QuantityValue>,
    /// Upper limit (`"400 kPa"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<QuantityValue>,
}

/// The economic optimization problem of a plant at steady state.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OptimizationSpec {
    /// What to optimize: a tag's name (`"cost"`, read as `cost.value`) or a variable path, with an
    /// optional display unit after `@` (`"cost@$/h"`; default the tag's declared unit, else SI).
    pub objective: String,
    /// `"minimize"` (default) or `"maximize"`.
    #[serde(default)]
    pub sense: Sense,
    /// The degrees of freedom: free inputs or controller setpoints (`"x2_control.sp"`), each with
    /// optional bounds (`{}` for none).
    pub vary: IndexMap<String, Limits>,
    /// Bounds on variables (`"distillate.x[light]": {"min": 0.99}`): product specifications and
    /// operating limits.
    #[serde(default, skip_serializing_if = "IndexMap::is_empty")]
    pub constraints: IndexMap<String, Limits>,
}
