//! Errors of the thermodynamics layer.

/// A thermodynamic calculation or data problem. Messages name the component or pair and the numbers.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ThermoError {
    /// A component name that is in neither the built-in library nor the inline definitions.
    #[error("unknown component `{name}` (not in the built-in library; define it inline or run `plantwide components`)")]
    UnknownComponent { name: String },
    /// Activity-model parameters are missing for a pair.
    #[error(
        "no {model} parameters for the pair `{i}`–`{j}`: give them under thermo.binary_parameters or choose another VLE model"
    )]
    MissingBinaryPair { model: String, i: String, j: String },
    /// A property is needed that the component's data do not provide.
    #[error("component `{component}` has no {property} data")]
    MissingProperty { component: String, property: String },
    /// An iterative routine (bubble/dew point, flash) failed.
    #[error("{routine} did not converge after {iterations} iterations (last residual {residual:.3e}) at {conditions}")]
    NoConvergence { routine: &'static str, iterations: usize, residual: f64, conditions: String },
    /// Inputs outside the domain of the routine (negative pressure, compositions not summing to 1, …).
    #[error("{routine}: {reason}")]
    BadInput { routine: &'static str, reason: String },
    /// The embedded library data could not be read (a build defect, not a user error).
    #[error("component library data: {0}")]
    Data(String),
}
