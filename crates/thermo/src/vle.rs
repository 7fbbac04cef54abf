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
    Nrtl {
        /// `a_ij` [-].
        a: Vec<Vec<f64>>,
        /// `b_ij` [K].
        b: Vec<Vec<f64>>,
        /// Non-randomness `α_ij` [-].
        alpha: Vec<Vec<f64>>,
    },
    /// Wilson (1964): `ln Λ_ij = a_ij + b_ij/T`,
    /// `ln γ_i = 1 − ln(Σ_j x_j Λ_ij) − Σ_k x_k Λ_ki / Σ_j x_j Λ_kj`.
    Wilson {
        /// `a_ij` [-].
        a: Vec<Vec<f64>>,
        /// `b_ij` [K].
        b: Vec<Vec<f64>>,
    },
}

impl ActivityModel {
    /// Number of components the parameter matrices describe (the row count of `a`).
    pub fn n(&self) -> usize {
        match self {
            ActivityModel::Nrtl { a, .. } | ActivityModel::Wilson { a, .. } => a.len(),
        }
    }

    /// True when every parameter matrix is at least `n × n`.
    fn covers(&self, n: usize) -> bool {
        let ok = |m: &Vec<Vec<f64>>| m.len() >= n && m.iter().take(n).all(|row| row.len() >= n);
        match self {
            ActivityModel::Nrtl { a, b, alpha } => ok(a) && ok(b) && ok(alpha),
            ActivityModel::Wilson { a, b } => ok(a) && ok(b),
        }
    }

    /// `ln γ_i` at temperature `t` [K] and liquid mole fractions `x`, written into `out`.
    ///
    /// Only the first `min(x.len(), out.len())` entries are used. If the parameter matrices are
    /// smaller than that, `out` is filled with NaN (a data defect, reported by the callers'
    /// convergence checks rather than by a panic). Mole fractions need not be normalised exactly;
    /// the formulas are evaluated as written.
    pub fn ln_gamma<S: Scalar>(&self, t: S, x: &[S], out: &mut [S]) {
        let n = x.len().min(out.len());
        if !self.covers(n) {
            out.iter_mut().for_each(|o| *o = S::from(f64::NAN));
            return;
        }
        let x = &x[..n];
        let out = &mut out[..n];
        match self {
            ActivityModel::Nrtl { a, b, alpha } => nrtl(a, b, alpha, t, x, out),
            ActivityModel::Wilson { a, b } => wilson(a, b, t, x, out),
        }
    }
}

/// NRTL: `τ_ij = a_ij + b_ij/T` (τ_ii = 0), `G_ij = exp(−α_ij τ_ij)` (G_ii = 1);
/// with `D_i = Σ_k G_ki x_k` and `C_i = Σ_j τ_ji G_ji x_j`:
/// `ln γ_i = C_i/D_i + Σ_j x_j G_ij/D_j · (τ_ij − C_j/D_j)`.
fn nrtl<S: Scalar>(a: &[Vec<f64>], b: &[Vec<f64>], alpha: &[Vec<f64>], t: S, x: &[S], out: &mut [S]) {
    let n = x.len();
    let inv_t = t.recip();
    let mut tau = vec![S::from(0.0); n * n];
    let mut g = vec![S::from(1.0); n * n];
    for i in 0..n {
        for j in 0..n {
            if i != j {
                let tij = inv_t * b[i][j] + a[i][j];
                tau[i * n + j] = tij;
                g[i * n + j] = (tij * (-alpha[i][j])).exp();
            }
        }
    }
    // D_i = Σ_k G_ki x_k, C_i = Σ_k τ_ki G_ki x_k, E_i = C_i / D_i
    let mut d = vec![S::from(0.0); n];
    let mut e = vec![S::from(0.0); n];
    for i in 0..n {
        let mut di = S::from(0.0);
        let mut ci = S::from(0.0);
        for k in 0..n {
            let gx = g[k * n + i] * x[k];
            di += gx;
            ci += tau[k * n + i] * gx;
        }
        d[i] = di;
        e[i] = ci / di;
    }
    for i in 0..n {
        let mut s = e[i];
        for j in 0..n {
            s += x[j] * g[i * n + j] / d[j] * (tau[i * n + j] - e[j]);
        }
        out[i] = s;
    }
}

/// Wilson: `Λ_ij = exp(a_ij + b_ij/T)` (Λ_ii = 1), with `S_i = Σ_j x_j Λ_ij`:
/// `ln γ_i = 1 − ln S_i − Σ_k x_k Λ_ki / S_k`.
fn wilson<S: Scalar>(a: &[Vec<f64>], b: &[Vec<f64>], t: S, x: &[S], out: &mut [S]) {
    let n = x.len();
    let inv_t = t.recip();
    let mut lam = vec![S::from(1.0); n * n];
    for i in 0..n {
        for j in 0..n {
            if i != j {
                lam[i * n + j] = (inv_t * b[i][j] + a[i][j]).exp();
            }
        }
    }
    let mut s = vec![S::from(0.0); n];
    for i in 0..n {
        let mut si = S::from(0.0);
        for j in 0..n {
            si += x[j] * lam[i * n + j];
        }
        s[i] = si;
    }
    for i in 0..n {
        let mut v = S::from(1.0) - s[i].ln();
        for k in 0..n {
            v -= x[k] * lam[k * n + i] / s[k];
        }
        out[i] = v;
    }
}
