//! A thermodynamic package: the components of a flowsheet plus the VLE model that relates them.

use crate::{Component, Scalar, VleModel};

/// Components and VLE model of one flowsheet. Component order is the flowsheet's component order.
#[derive(Debug, Clone, PartialEq)]
pub struct ThermoPackage {
    /// Pure-component data, in flowsheet order.
    pub components: Vec<Component>,
    /// VLE model.
    pub vle: VleModel,
}

impl ThermoPackage {
    /// Number of components.
    pub fn n(&self) -> usize {
        self.components.len()
    }
    /// K-values `K_i = y_i / x_i` at `t` [K], `p` [Pa] and liquid composition `x`, into `out`.
    pub fn k_values<S: Scalar>(&self, t: S, p: S, x: &[S], out: &mut [S]) {
        todo!("{t:?}{p:?}{}{}", x.len(), out.len())
    }
    /// Liquid molar enthalpy [J/mol] (ideal mixing of the pure-liquid enthalpies; heat of mixing neglected).
    pub fn h_liq<S: Scalar>(&self, t: S, x: &[S]) -> S {
        todo!("{t:?}{}", x.len())
    }
    /// Vapour molar enthalpy [J/mol] (ideal gas).
    pub fn h_vap<S: Scalar>(&self, t: S, y: &[S]) -> S {
        todo!("{t:?}{}", y.len())
    }
    /// Liquid molar volume [m³/mol] (ideal mixing of pure-liquid volumes).
    pub fn v_liq<S: Scalar>(&self, t: S, x: &[S]) -> S {
        todo!("{t:?}{}", x.len())
    }
    /// Mean molar mass [kg/mol] of a mixture of composition `z`.
    pub fn mw<S: Scalar>(&self, z: &[S]) -> S {
        todo!("{}", z.len())
    }
}
