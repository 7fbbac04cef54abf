//! Controllers are units: a PI controller's integral is a differential variable, so at steady state
//! its residual forces the error to zero and a "design spec" is just a controller in the flowsheet.

pub mod averaging_level;
pub mod condenser_reboiler;
pub mod delay;
pub mod lag;
pub mod mpc;
pub mod pid;
pub mod ratio;
pub mod selector;
pub mod split_range;
pub mod summer;

use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// What the flowsheet resolved for a controller before building it: the dimensions of the measured
/// variable and of the driven input, the driven input's value in the flowsheet, and the scale of the
/// measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct ControllerLinks {
    /// Dimension of the measurement (`pv`).
    pub pv_dim: Dimension,
    /// Dimension of the driven input.
    pub op_dim: Dimension,
    /// The driven input's value in the flowsheet (SI): the default bias, for a bumpless start.
    pub op_value: f64,
    /// Scale of the measurement (SI): the nominal magnitude of the states that carry it (a PID's
    /// integral `I` ~ `pv_nominal τ_I` and filter `x_f`, a lag's or delay's states with the bias),
    /// hence of Newton's scaling and the integrator's absolute tolerance on them; and the least
    /// scale against which a saturated PID's offset is judged. The flowsheet passes 1 (one SI
    /// unit of the measurement) for every controller: a plant's numbers are pinned to that scale,
    /// and the measurement's value is not known before the plant is assembled and guessed.
    pub pv_nominal: f64,
    /// Dimension of every measured path, in the order of [`ControllerPaths::measured`] (for
    /// controllers that read several: a model predictive controller's controlled variables).
    pub measured_dims: Vec<Dimension>,
    /// Dimension and file value (SI) of every driven input, in the order of
    /// [`ControllerPaths::driven`].
    pub driven: Vec<(Dimension, f64)>,
    /// Physical range `[lo, hi]` (SI) of every measured path, in the order of
    /// [`ControllerPaths::measured`]: its variable's bounds, or the range of the input a master
    /// controller drives; a setpoint outside it can never be met.
    pub measured_ranges: Vec<(f64, f64)>,
    /// Physical range `[lo, hi]` (SI) of every driven input, in the order of
    /// [`ControllerPaths::driven`]: the values it can take.
    pub driven_ranges: Vec<(f64, f64)>,
}

impl ControllerLinks {
    /// The first measurement's physical range (unbounded if unknown).
    pub fn pv_range(&self) -> (f64, f64) {
        self.measured_ranges.first().copied().unwrap_or((f64::NEG_INFINITY, f64::INFINITY))
    }
    /// The first driven input's physical range (unbounded if unknown).
    pub fn op_range(&self) -> (f64, f64) {
        self.driven_ranges.first().copied().unwrap_or((f64::NEG_INFINITY, f64::INFINITY))
    }
}

/// A setpoint: a value (an input `sp` that analyses and scenarios may move) or another controller's
/// output (cascade).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum Setpoint {
    /// A local setpoint, e.g. `"1.2 m"`.
    Value(QuantityValue),
    /// A remote setpoint: `{"from": "tc1.op"}`.
    Remote {
        /// Variable path of the master controller's output.
        from: String,
    },
}

/// Controller action.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Action {
    /// Output falls when the measurement rises (`e = sp − pv`): most flow-to-level-out loops are *not*
    /// this; a heater duty on a temperature is.
    #[default]
    Reverse,
    /// Output rises when the measurement rises (`e = pv − sp`), e.g. a level held by the outflow.
    Direct,
}

/// Operating mode.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Closed loop.
    #[default]
    Auto,
    /// Output held at `op_manual`; the integral tracks it for a bumpless return to auto.
    Manual,
}

/// The variable paths a controller description names, resolved by the flowsheet before building.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ControllerPaths {
    /// Measured variables (`pv`, remote setpoints, selector inputs), with their JSON field names.
    pub measured: Vec<(String, String)>,
    /// Driven inputs (`unit.input`), with their JSON field names.
    pub driven: Vec<(String, String)>,
}

/// What every controller description offers.
pub trait ControllerConfig: std::fmt::Debug {
    /// The paths it reads and drives.
    fn paths(&self) -> ControllerPaths;
    /// Ports: none (a controller exchanges signals, not streams).
    fn ports() -> &'static str
    where
        Self: Sized,
    {
        ""
    }
    /// Dimension of the output when the controller drives no input directly (its `op` is read by
    /// a selector, split range or another controller), from its own description; `None` if unknown.
    fn op_dimension(&self, _pv_dim: Dimension) -> Option<Dimension> {
        None
    }
}

/// `u` limited to `[lo, hi]`; the derivative follows the active branch.
pub(crate) fn clamp<S: crate::Scalar>(u: S, lo: f64, hi: f64) -> S {
    if u.re() < lo {
        S::from(lo)
    } else if u.re() > hi {
        S::from(hi)
    } else {
        u
    }
}

/// The dimension a controller gain must have: output per unit of measurement.
pub fn gain_dimension(links: &ControllerLinks) -> Dimension {
    links.op_dim / links.pv_dim
}
