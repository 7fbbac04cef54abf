//! The unit library: one file per unit type. Adding a unit touches its file, a `pub mod` line here
//! and one line of the registry in `crate::registry`.

pub mod column;
pub mod cstr;
pub mod equations;
pub mod feed;
pub mod flash;
pub mod gas_vessel;
pub mod heater;
pub mod hx;
pub mod mixer;
pub mod outflow;
pub mod product;
pub mod pump;
pub mod splitter;
pub mod tank;
pub mod valve;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::Scalar;
use plantwide_thermo::ThermoPackage;

/// The phase of an outlet stream whose state follows from an energy balance.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Liquid (subcooled or saturated): `h = h_L(T, z)`.
    #[default]
    Liquid,
    /// Vapour (superheated or saturated): `h = h_V(T, z)`.
    Vapour,
    /// Whatever phase equilibrium gives at `T`, `P`: liquid, vapour or a two-phase mixture
    /// (`h = h_eq(T, P, z)` by a TP flash with exact derivatives); use it for streams that may flash.
    Equilibrium,
}

impl Phase {
    /// Molar enthalpy [J/mol] of composition `z` at `t` [K] and `p` [Pa] in this phase.
    pub fn enthalpy<S: Scalar>(self, thermo: &ThermoPackage, t: S, p: S, z: &[S]) -> S {
        match self {
            Phase::Liquid => thermo.h_liq(t, z),
            Phase::Vapour => thermo.h_vap(t, z),
            Phase::Equilibrium => thermo.h_equilibrium(t, p, z),
        }
    }
    /// Temperature [K] at which `h_phase(T, P, z) = h` (f64, for initial guesses), from `t0`.
    pub fn temperature(self, thermo: &ThermoPackage, h: f64, p: f64, z: &[f64], t0: f64) -> f64 {
        if self == Phase::Equilibrium {
            return thermo.flash_ph(p, h, z).map(|f| f.t).unwrap_or(t0);
        }
        let mut t = t0;
        for _ in 0..50 {
            let zd: Vec<num_dual::Dual64> = z.iter().map(|&v| num_dual::Dual64::from_re(v)).collect();
            let hd = self.enthalpy(thermo, num_dual::Dual64::new(t, 1.0), num_dual::Dual64::from_re(p), &zd);
            if !(hd.eps.is_finite() && hd.eps > 0.0) {
                break;
            }
            let dt = (h - hd.re) / hd.eps;
            t = (t + dt.clamp(-100.0, 100.0)).max(10.0);
            if dt.abs() < 1e-10 * t {
                break;
            }
        }
        t
    }
}
