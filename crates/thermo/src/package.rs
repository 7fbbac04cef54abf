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
    /// The relative volatilities `α_i` of a `ConstantAlpha` package with one per component, for
    /// callers that evaluate `K_i = α_i / Σ_k α_k x_k` inline in a hot loop; `None` otherwise.
    pub fn constant_alpha(&self) -> Option<&[f64]> {
        match &self.vle {
            VleModel::ConstantAlpha { alpha } if alpha.len() >= self.n() => Some(&alpha[..self.n()]),
            _ => None,
        }
    }
    /// K-values `K_i = y_i / x_i` at `t` [K], `p` [Pa] and liquid composition `x`, into `out`.
    ///
    /// * `ConstantAlpha`: `K_i = α_i / Σ_k α_k x_k` (independent of `t` and `p`);
    /// * `Ideal`: `K_i = P_sat,i(T) / P`;
    /// * `Activity`: `K_i = γ_i(T, x) P_sat,i(T) / P`.
    ///
    /// Entries beyond the number of components, or all entries when the data do not match the
    /// component count (α vector or parameter matrices too short), are set to NaN.
    pub fn k_values<S: Scalar>(&self, t: S, p: S, x: &[S], out: &mut [S]) {
        let n = self.n();
        if x.len() < n || out.len() < n {
            out.iter_mut().for_each(|o| *o = S::from(f64::NAN));
            return;
        }
        match &self.vle {
            VleModel::ConstantAlpha { alpha } => {
                if alpha.len() < n {
                    out.iter_mut().for_each(|o| *o = S::from(f64::NAN));
                    return;
                }
                let mut den = S::from(0.0);
                for (xi, ai) in x.iter().zip(alpha).take(n) {
                    den += *xi * *ai;
                }
                let inv = den.recip();
                for (o, ai) in out.iter_mut().zip(alpha).take(n) {
                    *o = inv * *ai;
                }
            }
            VleModel::Ideal => {
                let inv_p = p.recip();
                for (o, c) in out.iter_mut().zip(&self.components) {
                    *o = c.psat(t) * inv_p;
                }
            }
            VleModel::Activity(model) => {
                model.ln_gamma(t, &x[..n], &mut out[..n]);
                let ln_p = p.ln();
                for (o, c) in out.iter_mut().zip(&self.components) {
                    *o = (*o + c.psat.ln_psat(t) - ln_p).exp();
                }
            }
        }
        out.iter_mut().skip(n).for_each(|o| *o = S::from(f64::NAN));
    }

    /// `ln Φ_i(T, x)` with `K_i = Φ_i / P`: the pressure-free part of the K-values used by the
    /// bubble/dew points and flashes.
    ///
    /// For `ConstantAlpha`, `Φ_i = α_i · Σ_k x_k P_sat,k(T) / Σ_k α_k x_k`: the relative volatilities
    /// fix the phase compositions and the temperature of a two-phase state is the Raoult bubble
    /// temperature of its liquid (`Σ x_k P_sat,k(T) = P`). At such a state `K_i = α_i / Σ α_k x_k`,
    /// the same as [`ThermoPackage::k_values`].
    pub(crate) fn ln_phi<S: Scalar>(&self, t: S, x: &[S], out: &mut [S]) {
        let n = self.n();
        if x.len() < n || out.len() < n {
            out.iter_mut().for_each(|o| *o = S::from(f64::NAN));
            return;
        }
        match &self.vle {
            VleModel::ConstantAlpha { alpha } => {
                if alpha.len() < n {
                    out.iter_mut().for_each(|o| *o = S::from(f64::NAN));
                    return;
                }
                let mut num = S::from(0.0);
                let mut den = S::from(0.0);
                for ((xi, ai), c) in x.iter().zip(alpha).zip(&self.components) {
                    num += *xi * c.psat(t);
                    den += *xi * *ai;
                }
                let lr = num.ln() - den.ln();
                for (o, ai) in out.iter_mut().zip(alpha) {
                    *o = lr + ai.ln();
                }
            }
            VleModel::Ideal => {
                for (o, c) in out.iter_mut().zip(&self.components) {
                    *o = c.psat.ln_psat(t);
                }
            }
            VleModel::Activity(model) => {
                model.ln_gamma(t, &x[..n], &mut out[..n]);
                for (o, c) in out.iter_mut().zip(&self.components) {
                    *o += c.psat.ln_psat(t);
                }
            }
        }
    }

    /// Liquid molar enthalpy [J/mol] (ideal mixing of the pure-liquid enthalpies; heat of mixing
    /// neglected): `h_L = Σ x_i (h_ig,i(T) − ΔH_vap,i(T))`.
    pub fn h_liq<S: Scalar>(&self, t: S, x: &[S]) -> S {
        let mut h = S::from(0.0);
        for (xi, c) in x.iter().zip(&self.components) {
            h += *xi * c.h_liq(t);
        }
        h
    }
    /// Vapour molar enthalpy [J/mol] (ideal gas): `h_V = Σ y_i h_ig,i(T)`.
    pub fn h_vap<S: Scalar>(&self, t: S, y: &[S]) -> S {
        let mut h = S::from(0.0);
        for (yi, c) in y.iter().zip(&self.components) {
            h += *yi * c.h_ig(t);
        }
        h
    }
    /// Liquid molar volume [m³/mol] (ideal mixing of pure-liquid volumes): `v_L = Σ x_i v_i(T)`.
    pub fn v_liq<S: Scalar>(&self, t: S, x: &[S]) -> S {
        let mut v = S::from(0.0);
        for (xi, c) in x.iter().zip(&self.components) {
            v += *xi * c.v_liq(t);
        }
        v
    }
    /// Mean molar mass [kg/mol] of a mixture of composition `z`: `Σ z_i M_i`.
    pub fn mw<S: Scalar>(&self, z: &[S]) -> S {
        let mut m = S::from(0.0);
        for (zi, c) in z.iter().zip(&self.components) {
            m += *zi * c.mw;
        }
        m
    }

    /// Bubble-point residual of liquid `x` at `t` [K], `p` [Pa]: `Σ_i K_i x_i − 1`. For constant
    /// relative volatility, where `Σ K x ≡ 1`, it is the vapour-pressure scale `Σ_i x_i P_sat,i(T)/P − 1`
    /// (the temperature scale of the components), so that the bubble temperature stays defined.
    pub fn bubble_residual<S: Scalar>(&self, t: S, p: S, x: &[S]) -> S {
        match &self.vle {
            VleModel::ConstantAlpha { .. } => {
                let inv_p = p.recip();
                self.components.iter().zip(x).fold(S::from(-1.0), |acc, (c, xi)| acc + c.psat(t) * *xi * inv_p)
            }
            _ => {
                let mut k = vec![S::from(0.0); x.len()];
                self.k_values(t, p, x, &mut k);
                k.iter().zip(x).fold(S::from(-1.0), |acc, (ki, xi)| acc + *ki * *xi)
            }
        }
    }
}
