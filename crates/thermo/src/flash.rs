//! Bubble and dew points and flashes (f64, iterative, converged to machine precision).

use crate::{ThermoError, ThermoPackage};

/// A saturation point: the temperature or pressure and the incipient phase's composition.
#[derive(Debug, Clone, PartialEq)]
pub struct SaturationPoint {
    /// Temperature [K].
    pub t: f64,
    /// Pressure [Pa].
    pub p: f64,
    /// Composition of the incipient phase (vapour for a bubble point, liquid for a dew point).
    pub incipient: Vec<f64>,
    /// Iterations used.
    pub iterations: usize,
}

/// Phase state of a flash result.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PhaseState {
    /// All liquid (subcooled or at its bubble point).
    Liquid,
    /// All vapour (superheated or at its dew point).
    Vapour,
    /// Two phases in equilibrium.
    TwoPhase,
}

/// Result of a TP or PH flash.
#[derive(Debug, Clone, PartialEq)]
pub struct FlashResult {
    /// Temperature [K].
    pub t: f64,
    /// Pressure [Pa].
    pub p: f64,
    /// Vapour mole fraction β [-] (0 liquid, 1 vapour).
    pub beta: f64,
    /// Liquid composition (equals the feed for a single liquid phase).
    pub x: Vec<f64>,
    /// Vapour composition (equals the feed for a single vapour phase).
    pub y: Vec<f64>,
    /// Molar enthalpy of the whole stream [J/mol].
    pub h: f64,
    /// Phase state.
    pub phase: PhaseState,
    /// Iterations used (outer loop).
    pub iterations: usize,
}

impl ThermoPackage {
    /// Bubble temperature at pressure `p` [Pa] of liquid `x`.
    pub fn bubble_t(&self, p: f64, x: &[f64]) -> Result<SaturationPoint, ThermoError> {
        todo!("{p}{}", x.len())
    }
    /// Bubble pressure at temperature `t` [K] of liquid `x`.
    pub fn bubble_p(&self, t: f64, x: &[f64]) -> Result<SaturationPoint, ThermoError> {
        todo!("{t}{}", x.len())
    }
    /// Dew temperature at pressure `p` [Pa] of vapour `y`.
    pub fn dew_t(&self, p: f64, y: &[f64]) -> Result<SaturationPoint, ThermoError> {
        todo!("{p}{}", y.len())
    }
    /// Dew pressure at temperature `t` [K] of vapour `y`.
    pub fn dew_p(&self, t: f64, y: &[f64]) -> Result<SaturationPoint, ThermoError> {
        todo!("{t}{}", y.len())
    }
    /// Isothermal flash of feed `z` at `t` [K], `p` [Pa] (Rachford–Rice with successive substitution
    /// on the activity coefficients).
    pub fn flash_tp(&self, t: f64, p: f64, z: &[f64]) -> Result<FlashResult, ThermoError> {
        todo!("{t}{p}{}", z.len())
    }
    /// Adiabatic flash: feed `z` at pressure `p` [Pa] with molar enthalpy `h` [J/mol].
    pub fn flash_ph(&self, p: f64, h: f64, z: &[f64]) -> Result<FlashResult, ThermoError> {
        todo!("{p}{h}{}", z.len())
    }
}
