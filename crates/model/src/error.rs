//! Errors of the unit library: a unit or controller description that cannot be read or built, an
//! input value outside its physical range or refused by its unit, a resource limit that is not a
//! number. [`Error`] joins them for callers that propagate any of them.

use plantwide_thermo::ThermoError;

use crate::build::FieldError;
use crate::limits::{LimitsError, RangeError};

/// Any error of this crate.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A field of a unit or controller description.
    #[error(transparent)]
    Field(#[from] FieldError),
    /// A description that does not deserialize.
    #[error(transparent)]
    Spec(#[from] SpecError),
    /// An input value outside its physical range.
    #[error(transparent)]
    Range(#[from] RangeError),
    /// An input value a unit refuses ([`crate::UnitModel::check_inputs`]).
    #[error(transparent)]
    Input(#[from] InputError),
    /// A resource limit in the environment that is not a positive whole number.
    #[error(transparent)]
    Limits(#[from] LimitsError),
    /// A thermodynamic calculation a unit needed.
    #[error(transparent)]
    Thermo(#[from] ThermoError),
}

/// A unit or controller description that does not deserialize into its type
/// ([`crate::UnitSpec::from_tagged`], [`crate::ControllerSpec::from_tagged`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct SpecError {
    /// JSON path below the description of the first problem (`outflow.cv`; empty for the
    /// description itself).
    pub path: String,
    /// What serde reported.
    pub message: String,
}

/// An input value that only its unit knows to be wrong ([`crate::UnitModel::check_inputs`]).
/// The message is the reason alone; [`InputError::input`] names the input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InputError {
    /// A saturated-liquid feed whose bubble point cannot be found at its pressure.
    #[error("no bubble point at {pressure} Pa: {source}")]
    NoBubblePoint {
        /// The input (`P`).
        input: String,
        /// The feed pressure [Pa].
        pressure: f64,
        /// Why the bubble point failed.
        source: ThermoError,
    },
    /// A saturated-liquid feed that would boil below the temperatures of a component's
    /// vapour-pressure data (where no liquid exists).
    #[error(
        "at {pressure} Pa this saturated liquid would boil at {bubble_t:.1} K, below {t_min:.1} K where the vapour-pressure data of {component} begin (no liquid exists there): raise the pressure"
    )]
    BelowVapourPressureData {
        /// The input (`P`).
        input: String,
        /// The feed pressure [Pa].
        pressure: f64,
        /// Its bubble-point temperature [K].
        bubble_t: f64,
        /// Lowest temperature of the component's vapour-pressure data [K].
        t_min: f64,
        /// The component.
        component: String,
    },
}

impl InputError {
    /// The name of the input, as in [`crate::UnitModel::inputs`].
    pub fn input(&self) -> &str {
        match self {
            InputError::NoBubblePoint { input, .. } | InputError::BelowVapourPressureData { input, .. } => input,
        }
    }
}
