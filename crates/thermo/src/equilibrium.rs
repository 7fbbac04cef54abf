//! Equilibrium (phase-aware) molar enthalpy `h_eq(T, P, z)` of a stream that may be liquid, vapour
//! or two-phase, with exact derivatives for dual numbers.
//!
//! The TP flash is solved in `f64`. In the two-phase region the flash unknowns
//! `w = (β, x_1…x_n, y_1…y_n)` satisfy `G(w; T, P, z) = 0` with
//! `G_i = y_i − K_i(T, P, x) x_i`, `G_{n+i} = z_i − β y_i − (1 − β) x_i`, `G_{2n} = Σ_i (y_i − x_i)`.
//! One Newton correction `w ← w* − J_w⁻¹ G(w*; T, P, z)` evaluated in the caller's scalar type
//! carries the exact first derivatives `dw = −J_w⁻¹ ∂G/∂(T,P,z)` (implicit function theorem), so
//! `h = β h_V(T, y) + (1 − β) h_L(T, x)` is differentiated exactly without differentiating through
//! the iterations of the flash.

use num_dual::Dual64;

use crate::{PhaseState, Scalar, ThermoPackage};

impl ThermoPackage {
    /// Molar enthalpy [J/mol] of composition `z` at `t` [K], `p` [Pa] in phase equilibrium: the
    /// liquid enthalpy below the bubble point, the vapour enthalpy above the dew point, and the
    /// flash-weighted mixture between them. Falls back to the liquid enthalpy if the flash fails.
    ///
    /// Like `h_liq` and `h_vap` it is homogeneous of degree one in `z` (`h(c z) = c h(z)`), so its
    /// derivatives agree in every direction, also off `Σ z = 1`.
    pub fn h_equilibrium<S: Scalar>(&self, t: S, p: S, z: &[S]) -> S {
        let sum = z.iter().fold(S::from(0.0), |a, b| a + *b);
        if sum.re() <= 0.0 {
            return self.h_liq(t, z);
        }
        let zn: Vec<S> = z.iter().map(|v| *v / sum).collect();
        sum * self.h_equilibrium_normalized(t, p, &zn)
    }

    fn h_equilibrium_normalized<S: Scalar>(&self, t: S, p: S, z: &[S]) -> S {
        let zr: Vec<f64> = z.iter().map(|v| v.re()).collect();
        let Ok(fl) = self.flash_tp(t.re(), p.re(), &zr) else {
            return self.h_liq(t, z);
        };
        match fl.phase {
            PhaseState::Liquid => self.h_liq(t, z),
            PhaseState::Vapour => self.h_vap(t, z),
            PhaseState::TwoPhase => {
                let n = z.len();
                let mut w = Vec::with_capacity(2 * n + 1);
                w.push(fl.beta);
                w.extend_from_slice(&fl.x);
                w.extend_from_slice(&fl.y);
                let Some(dw) = self.flash_correction(&w, t, p, z) else {
                    return self.h_liq(t, z);
                };
                let ws: Vec<S> = w.iter().zip(&dw).map(|(wi, di)| S::from(*wi) - *di).collect();
                let beta = ws[0];
                let (x, y) = (&ws[1..=n], &ws[n + 1..]);
                beta * self.h_vap(t, y) + (S::from(1.0) - beta) * self.h_liq(t, x)
            }
        }
    }

    /// `J_w⁻¹ G(w; t, p, z)` in the caller's scalar type (see the module documentation).
    fn flash_correction<S: Scalar>(&self, w: &[f64], t: S, p: S, z: &[S]) -> Option<Vec<S>> {
        let m = w.len();
        // Jacobian ∂G/∂w at fixed (t, p, z), column by column with dual numbers.
        let (tr, pr) = (Dual64::from_re(t.re()), Dual64::from_re(p.re()));
        let zr: Vec<Dual64> = z.iter().map(|v| Dual64::from_re(v.re())).collect();
        let mut jac = vec![0.0; m * m];
        let mut wd: Vec<Dual64> = w.iter().map(|&v| Dual64::from_re(v)).collect();
        let mut g = vec![Dual64::from_re(0.0); m];
        for j in 0..m {
            wd[j].eps = 1.0;
            self.flash_residual(&wd, tr, pr, &zr, &mut g);
            for i in 0..m {
                jac[i * m + j] = g[i].eps;
            }
            wd[j].eps = 0.0;
        }
        let ws: Vec<S> = w.iter().map(|&v| S::from(v)).collect();
        let mut rhs = vec![S::from(0.0); m];
        self.flash_residual(&ws, t, p, z, &mut rhs);
        solve_dense(&mut jac, &mut rhs, m).then_some(rhs)
    }

    /// Two-phase flash residuals `G(w; t, p, z)`.
    fn flash_residual<S: Scalar>(&self, w: &[S], t: S, p: S, z: &[S], g: &mut [S]) {
        let n = z.len();
        let beta = w[0];
        let (x, y) = (&w[1..=n], &w[n + 1..]);
        let mut k = vec![S::from(0.0); n];
        self.k_values(t, p, x, &mut k);
        let mut sum = S::from(0.0);
        for i in 0..n {
            g[i] = y[i] - k[i] * x[i];
            g[n + i] = z[i] - beta * y[i] - (S::from(1.0) - beta) * x[i];
            sum += y[i] - x[i];
        }
        g[2 * n] = sum;
    }
}

/// Solve `A v = b` in place (`A` is `m × m` row-major `f64`, `b` in any scalar type) by Gaussian
/// elimination with partial pivoting. Returns false if `A` is singular.
fn solve_dense<S: Scalar>(a: &mut [f64], b: &mut [S], m: usize) -> bool {
    for col in 0..m {
        let piv = (col..m).max_by(|&i, &j| a[i * m + col].abs().total_cmp(&a[j * m + col].abs())).unwrap_or(col);
        if a[piv * m + col].abs() < 1e-300 {
            return false;
        }
        if piv != col {
            for j in 0..m {
                a.swap(col * m + j, piv * m + j);
            }
            b.swap(col, piv);
        }
        for i in col + 1..m {
            let f = a[i * m + col] / a[col * m + col];
            if f != 0.0 {
                for j in col..m {
                    a[i * m + j] -= f * a[col * m + j];
                }
                let bc = b[col];
                b[i] -= bc * f;
            }
        }
    }
    for col in (0..m).rev() {
        let mut s = b[col];
        for j in col + 1..m {
            s -= b[j] * a[col * m + j];
        }
        b[col] = s / a[col * m + col];
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Component, VleModel};

    fn package() -> ThermoPackage {
        ThermoPackage {
            components: vec![
                Component::hypothetical("light", 2.5, 0.05, 3.0e4, 350.0, 150.0, 1.0e-4),
                Component::hypothetical("mid", 1.6, 0.07, 3.3e4, 350.0, 160.0, 1.1e-4),
                Component::hypothetical("heavy", 1.0, 0.08, 3.6e4, 350.0, 170.0, 1.2e-4),
            ],
            vle: VleModel::Ideal,
        }
    }

    #[test]
    fn equals_the_flash_enthalpy_in_every_region() {
        let pk = package();
        let z = [0.3, 0.3, 0.4];
        let (tb, td) = (pk.bubble_t(101_325.0, &z).unwrap().t, pk.dew_t(101_325.0, &z).unwrap().t);
        for t in [tb - 20.0, tb - 1e-3, 0.7 * tb + 0.3 * td, 0.3 * tb + 0.7 * td, td + 1e-3, td + 30.0] {
            let fl = pk.flash_tp(t, 101_325.0, &z).unwrap();
            let h = pk.h_equilibrium(t, 101_325.0, &z);
            assert!((h - fl.h).abs() <= 1e-9 * fl.h.abs().max(1.0), "T = {t}: {h} vs {}", fl.h);
        }
    }

    #[test]
    fn dual_derivatives_match_central_differences_in_the_two_phase_region() {
        let pk = package();
        let z = [0.3, 0.3, 0.4];
        let p = 101_325.0;
        let t = 0.5 * (pk.bubble_t(p, &z).unwrap().t + pk.dew_t(p, &z).unwrap().t);
        assert_eq!(pk.flash_tp(t, p, &z).unwrap().phase, PhaseState::TwoPhase);
        // d/dT
        let d = pk.h_equilibrium(Dual64::new(t, 1.0), Dual64::from_re(p), &z.map(Dual64::from_re));
        let h = 1e-4;
        let fd = (pk.h_equilibrium(t + h, p, &z) - pk.h_equilibrium(t - h, p, &z)) / (2.0 * h);
        assert!((d.eps - fd).abs() < 1e-6 * fd.abs(), "dh/dT {} vs {fd}", d.eps);
        // d/dP
        let d = pk.h_equilibrium(Dual64::from_re(t), Dual64::new(p, 1.0), &z.map(Dual64::from_re));
        let hp = 1.0;
        let fd = (pk.h_equilibrium(t, p + hp, &z) - pk.h_equilibrium(t, p - hp, &z)) / (2.0 * hp);
        assert!((d.eps - fd).abs() < 1e-6 * fd.abs().max(1e-3), "dh/dP {} vs {fd}", d.eps);
        // d/dz_0 (z_0 up, z_2 down so that Σz = 1 stays)
        let zd = [Dual64::new(z[0], 1.0), Dual64::from_re(z[1]), Dual64::new(z[2], -1.0)];
        let d = pk.h_equilibrium(Dual64::from_re(t), Dual64::from_re(p), &zd);
        let e = 1e-6;
        let fd = (pk.h_equilibrium(t, p, &[z[0] + e, z[1], z[2] - e])
            - pk.h_equilibrium(t, p, &[z[0] - e, z[1], z[2] + e]))
            / (2.0 * e);
        assert!((d.eps - fd).abs() < 1e-5 * fd.abs().max(1.0), "dh/dz {} vs {fd}", d.eps);
    }
}
