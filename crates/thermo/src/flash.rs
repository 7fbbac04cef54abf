//! Bubble and dew points and flashes (f64, iterative, converged to machine precision).

mod input;
mod ph;
pub mod rachford_rice;
mod saturation;
mod tp;

pub use rachford_rice::{RachfordRice, rachford_rice};

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
    /// Bubble temperature at pressure `p` [Pa] of liquid `x`: the root of `Σ x_i K_i(T, P, x) = 1`
    /// (bracketed Newton on `ln Σ x_i Φ_i(T, x) − ln P`, to machine precision); `incipient` is the
    /// vapour `y_i = K_i x_i`.
    ///
    /// For `ConstantAlpha` the K-values do not depend on T, so the temperature is the Raoult bubble
    /// temperature of the liquid (`Σ x_i P_sat,i(T) = P`, as the `Ideal` model would give) and the
    /// incipient vapour is `y_i = α_i x_i / Σ α_k x_k`.
    pub fn bubble_t(&self, p: f64, x: &[f64]) -> Result<SaturationPoint, ThermoError> {
        saturation::bubble_t(self, p, x)
    }
    /// Bubble pressure at temperature `t` [K] of liquid `x`: `P = Σ x_i γ_i P_sat,i(T)` (direct);
    /// `ConstantAlpha`: the Raoult bubble pressure `Σ x_i P_sat,i(T)`, `y_i = α_i x_i / Σ α_k x_k`.
    pub fn bubble_p(&self, t: f64, x: &[f64]) -> Result<SaturationPoint, ThermoError> {
        saturation::bubble_p(self, t, x)
    }
    /// Dew temperature at pressure `p` [Pa] of vapour `y`: `Σ y_i / K_i(T, P, x) = 1` with the
    /// incipient liquid `x_i = y_i / K_i` (successive substitution, then Newton on `(ln K, ln T)`).
    ///
    /// For `ConstantAlpha` the incipient liquid is `x_i ∝ y_i / α_i` and the temperature is the
    /// Raoult bubble temperature of that liquid, so `bubble_t` and `dew_t` are exact inverses. It
    /// equals the Raoult dew temperature of `y` when the vapour pressures are proportional to the α
    /// (hypothetical components with a common `hvap` and `t_ref`, see [`crate::Component::hypothetical`]).
    pub fn dew_t(&self, p: f64, y: &[f64]) -> Result<SaturationPoint, ThermoError> {
        saturation::dew_t(self, p, y)
    }
    /// Dew pressure at temperature `t` [K] of vapour `y`: `1/P = Σ y_i / (γ_i(x) P_sat,i(T))` with the
    /// incipient liquid `x` (successive substitution, then Newton on `(ln K, ln P)`).
    pub fn dew_p(&self, t: f64, y: &[f64]) -> Result<SaturationPoint, ThermoError> {
        saturation::dew_p(self, t, y)
    }
    /// Isothermal flash of feed `z` at `t` [K], `p` [Pa] (Rachford–Rice with successive substitution
    /// on the activity coefficients, polished by Newton's method to machine precision).
    ///
    /// Liquid when `P ≥ P_bubble(T, z)`, vapour when `P ≤ P_dew(T, z)`, else two phases. For
    /// `ConstantAlpha` the two-phase state satisfies `y_i = α_i x_i / Σ α_k x_k` with `T` the
    /// Raoult bubble temperature of the liquid `x`.
    pub fn flash_tp(&self, t: f64, p: f64, z: &[f64]) -> Result<FlashResult, ThermoError> {
        tp::flash_tp(self, t, p, z)
    }
    /// Adiabatic flash: feed `z` at pressure `p` [Pa] with molar enthalpy `h` [J/mol] (bracketed
    /// between the bubble and dew temperatures; Newton in the single-phase regions, Brent on the
    /// TP-flash enthalpy in the two-phase region).
    pub fn flash_ph(&self, p: f64, h: f64, z: &[f64]) -> Result<FlashResult, ThermoError> {
        ph::flash_ph(self, p, h, z)
    }
}
