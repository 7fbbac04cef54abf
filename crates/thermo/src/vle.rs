//! Vapour–liquid equilibrium models: `y_i = K_i x_i` with `K_i = γ_i P_sat,i / P` (modified Raoult,
//! low pressure) or constant relative volatility.

use serde::{Deserialize, Serialize};

use crate::Scalar;

/// How K-values are computed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case")]
pub enum VleModel {
    /// Constant relative volatility: `y_i = α_i x_i / Σ_k α_k x_k`, i.e. `K_i = α_i / Σ_k α_k x_k`,
    /// independent of T and P. Temperatures, where needed, come from the components' vapour
    /// pressures through the bubble point of the reference (α = 1) scale.
    ConstantAlpha {
        /// Relative volatility of each component against a common reference [-].
        alpha: Vec<f64>,
    },
    /// Raoult's law with the components' vapour pressures (γ = 1).
    Ideal,
    /// Modified Raoult with an activity-coefficient model.
    Activity(ActivityModel),
}

/// Liquid activity-coefficient models, multicomponent, with temperature-dependent binary parameters
/// in the Aspen Plus form. Matrices are `n × n`, indexed `[i][j]`, diagonal ignored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ActivityModel {
    /// NRTL (Renon & Prausnitz 1968): `τ_ij = a_ij + b_ij/T`, `G_ij = exp(−α_ij τ_ij)`,
    /// `ln γ_i = Σ_j τ_ji G_ji x_j / Σ_k G_ki x_k + Σ_j x_j G_ij/Σ_k G_kj x_k · (τ_ij − Σ_m x_m τ_mj G_mj / Σ_k G_kj x_k)`.
    Nrtl { a: Vec<Vec<f64>>, b: Vec<Vec<f64>>, alpha: Vec<Vec<f64>> },
    /// Wilson (1964): `ln Λ_ij = a_ij + b_ij/T`,
    /// `ln γ_i = 1 − ln(Σ_j x_j Λ_ij) − Σ_k x_k Λ_ki / Σ_j x_j Λ_kj`.
    Wilson { a: Vec<Vec<f64>>, b: Vec<Vec<f64>> },
}

impl ActivityModel {
    /// `ln γ_i` at temperature `t` [K] and liquid mole fractions `x`, written into `out`.
    pub fn ln_gamma<S: Scalar>(&self, t: S, x: &[S], out: &mut [S]) {
        todo!("{t:?}{}{}", x.len(), out.len())
    }
}
