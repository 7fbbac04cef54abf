//! Thermodynamics for plantwide: pure-component property correlations, vapour–liquid equilibrium
//! (constant relative volatility, Raoult, Wilson, NRTL), bubble and dew points, isothermal (TP) and
//! adiabatic (PH) flashes, and liquid/vapour molar enthalpies consistent with the VLE.
//!
//! Units are SI throughout: K, Pa, mol, J, m³. Molar enthalpies are J/mol referred to the ideal gas at
//! 298.15 K (so `h_vap` of a pure component at 298.15 K is 0).
//!
//! Everything that enters a residual of the plant model (K-values, activity coefficients, vapour
//! pressures, enthalpies, liquid volumes) is generic over [`Scalar`], so the model layer gets exact
//! derivatives with dual numbers. Iterative routines (bubble/dew points, flashes) work in `f64`.
//!
//! **Architecture Invariant:** this crate depends on no other plantwide crate.

#![warn(missing_docs)]

pub mod component;
mod correlations;
pub mod equilibrium;
pub mod error;
pub mod flash;
pub mod library;
pub mod package;
pub mod scalar;
pub mod vle;

mod newton;
mod solve1d;

pub use component::{Component, CpIdealGas, CpLiquid, HeatOfVaporization, LiquidVolume, VapourPressure};
pub use error::ThermoError;
/// The crate-level error: every public fallible function of this crate returns a [`ThermoError`].
pub use error::ThermoError as Error;
pub use flash::{FlashResult, PhaseState, SaturationPoint};
pub use library::{BinaryPair, Library};
pub use package::ThermoPackage;
pub use scalar::Scalar;
pub use vle::{ActivityModel, VleModel};

/// Universal gas constant [J/(mol·K)].
pub const R_GAS: f64 = 8.314_462_618;
/// Reference temperature of the enthalpy datum [K].
pub const T_REF: f64 = 298.15;
