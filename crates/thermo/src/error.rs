//! Errors of the thermodynamics layer.

/// A thermodynamic calculation or data problem. Messages name the component or pair and the numbers.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ThermoError {
    /// A component name that is in neither the built-in library nor the inline definitions.
    #[error("unknown component `{name}` (not in the built-in library; define it inline or run `plantwide components`)")]
    UnknownComponent {
        /// The name as written.
        name: String,
    },
    /// Activity-model parameters are missing for a pair.
    #[error(
        "no {model} parameters for the pair `{i}`–`{j}`: give them under thermo.binary_parameters or choose another VLE model"
    )]
    MissingBinaryPair {
        /// The activity model, lower case (`nrtl`, `wilson`).
        model: String,
        /// First component of the pair.
        i: String,
        /// Second component of the pair.
        j: String,
    },
    /// A property is needed that the component's data do not provide.
    #[error("component `{component}` has no {property} data")]
    MissingProperty {
        /// The component.
        component: String,
        /// The property that is missing.
        property: String,
    },
    /// An iterative routine (bubble/dew point, flash) failed.
    #[error("{routine} did not converge after {iterations} iterations (last residual {residual:.3e}) at {conditions}")]
    NoConvergence {
        /// The routine (`tsat`, a bubble or dew point, a flash).
        routine: &'static str,
        /// Iterations made.
        iterations: usize,
        /// The last residual of the routine's equation (NaN where the routine keeps none).
        residual: f64,
        /// The conditions it was called at (component, pressure, composition).
        conditions: String,
    },
    /// Inputs outside the domain of the routine (negative pressure, compositions not summing to 1, …).
    #[error("{routine}: {reason}")]
    BadInput {
        /// The routine.
        routine: &'static str,
        /// What is wrong with its inputs.
        reason: String,
    },
    /// The embedded library data could not be read (a build defect, not a user error).
    #[error("component library data: {0}")]
    Data(String),
}
