//! The loss of holding a combination `c = H y_s` of a subset `s` of the measurements at its
//! nominal value, and the combination that makes it smallest (the exact local method).
//!
//! With `c` held constant the inputs move by `Δu = −(H Gy_s)⁻¹ H (Gyd_s Δd + n_s)`, and the loss
//! against re-optimized operation is `L = ½ ‖z‖²` with `z = M [d'; n']` (Halvorsen et al. 2003,
//! eq. 15; Alstad, Skogestad & Hori 2009, eq. 24):
//!
//! ```text
//! M = −Juu^{1/2} (H Gy_s)⁻¹ H Y_s,        Y_s = [F_s Wd, Wn_s]
//! worst-case loss  = ½ σ̄(M)²             over ‖[d'; n']‖₂ ≤ 1
//! average loss     = ½ ‖M‖²_F            [d'; n'] normally distributed with unit covariance
//! ```
//!
//! (Kariwala, Cao & Janardhanan, "Local self-optimizing control with average loss minimization",
//! Ind. Eng. Chem. Res. 47 (2008) 1150–1158: the same `H` minimizes both; their eq. 11 normalizes the
//! average over a uniform ball instead, `‖M‖²_F / (6 (n + nd))`, as pySOC's fixtures do.)
//!
//! **Exact local method.** With `G̃ = Gy Juu^{-1/2}`, `L L ᵀ = Y_s Y_sᵀ` and the thin SVD
//! `L⁻¹ G̃_s = U Σ Vᵀ`, the best `H` gives `σ(M) = 1/σ(L⁻¹ G̃_s)` (Alstad et al. 2009, eq. 31; Kariwala
//! & Cao 2009, eq. 9, where `Λ = G̃_sᵀ (Y_s Y_sᵀ)⁻¹ G̃_s` and the worst-case loss is `1 / (2 λ_min(Λ))`):
//!
//! ```text
//! worst-case loss = 1 / (2 σ_min²),   average loss = ½ Σ 1/σ_i²
//! H = Juu^{1/2} (Gy_sᵀ (Y_s Y_sᵀ)⁻¹ Gy_s)⁻¹ Gy_sᵀ (Y_s Y_sᵀ)⁻¹ = V Σ⁻¹ Uᵀ L⁻¹
//! ```
//!
//! `H` is unique up to a nonsingular factor on the left; this one is scaled so that `H Gy_s =
//! Juu^{1/2}` (then `M = −H Y_s`). When the subset has as many measurements as inputs, `H` is
//! square and cancels: `M = −Juu^{1/2} Gy_s⁻¹ Y_s`, computed so, by LU, which keeps the digits of
//! a nearly singular `Gy_s` that the normal-equation form would square away.
//!
//! **Null space.** Alstad et al. 2009, eq. 41 (the extended null-space method): with `J̃ = [Juu^{1/2},
//! Juu^{-1/2} Jud]`, `G̃ʸ = [Gy_s, Gyd_s]` and the noise factor `L_n L_nᵀ = (Wn Wnᵀ)_ss`,
//! `H = J̃ (L_n⁻¹ G̃ʸ)⁺ L_n⁻¹`. With `n ≥ nu + nd` measurements and no noise it gives zero loss
//! for every disturbance (`H F = 0`, Alstad & Skogestad 2007); with fewer it is the
//! least-squares extension.

use faer::linalg::solvers::{DenseSolveCore, Solve};
use faer::{Mat, MatRef};
use serde::Serialize;

use crate::dense::{cholesky, lower_solve, lower_transpose_solve, pinv, principal, rank_deficient, rows, thin_svd};
use crate::error::SocError;
use crate::model::LocalModel;
use crate::model::RANK_TOLERANCE;

/// The two losses of a combination.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Losses {
    /// `½ σ̄(M)²`.
    pub worst_case: f64,
    /// `½ ‖M‖²_F`.
    pub average: f64,
}

/// A subset of the measurements, the combination `H` held, and its losses.
#[derive(Debug, Clone)]
pub struct Combination {
    /// Measurement indices, ascending.
    pub measurements: Vec<usize>,
    /// `H`, nu × n.
    pub h: Mat<f64>,
    /// Its losses.
    pub losses: Losses,
}

/// The losses of holding `c = H y_s` constant, from `M = −Juu^{1/2} (H Gy_s)⁻¹ H Y_s`.
///
/// # Errors
/// [`SocError::Request`] when `H` is not nu × n or `H Gy_s` is singular (the combination cannot
/// hold the inputs).
pub fn losses_of(model: &LocalModel, subset: &[usize], h: MatRef<'_, f64>) -> Result<Losses, SocError> {
    if (h.nrows(), h.ncols()) != (model.nu(), subset.len()) {
        return Err(SocError::Request(format!(
            "H is {} × {}; it must be {} × {} (inputs × measurements of the subset)",
            h.nrows(),
            h.ncols(),
            model.nu(),
            subset.len()
        )));
    }
    let h = model.scale_h(h, subset);
    Ok(unscaled(model, scaled_losses_of(model, subset, &h)?))
}

/// The losses of the scaled combination `h` of the scaled measurements, in scaled units.
fn scaled_losses_of(model: &LocalModel, subset: &[usize], h: &Mat<f64>) -> Result<Losses, SocError> {
    let hg = h * rows(model.gy(), subset);
    let hy = h * rows(model.y(), subset);
    let m = -(model.juu_half() * singular_checked_solve(hg.as_ref(), hy.as_ref())?);
    from_m(m.as_ref())
}

/// The exact local method's best combination of the measurements `subset` (ascending indices)
/// and its losses; `None` when `L⁻¹ G̃_s` is rank-deficient to working precision
/// (`σ_min/σ_max` ≤ 1e-12: fewer independent measurements than inputs, no combination holds the
/// inputs).
///
/// # Errors
/// [`SocError::Numerical`] when a factorization fails.
pub fn exact_local(model: &LocalModel, subset: &[usize]) -> Result<Option<Combination>, SocError> {
    let nu = model.nu();
    let l = cholesky(principal(model.y2(), subset).as_ref(), "Y Yᵀ of the subset")?;
    let w = lower_solve(l.as_ref(), rows(model.g_tilde(), subset).as_ref());
    let svd = thin_svd(w.as_ref())?;
    if svd.sigma.last().is_none_or(|&lo| lo.is_nan() || lo <= RANK_TOLERANCE * svd.sigma[0]) {
        return Ok(None);
    }
    let (h, losses) = match subset.len() == nu {
        true => {
            let lu = rows(model.gy(), subset).partial_piv_lu();
            let m = -(model.juu_half() * lu.solve(rows(model.y(), subset)));
            (model.juu_half() * lu.inverse(), from_m(m.as_ref())?)
        }
        false => {
            let b = Mat::from_fn(subset.len(), nu, |i, j| {
                (0..nu).map(|r| svd.u[(i, r)] * svd.v[(j, r)] / svd.sigma[r]).sum()
            });
            (lower_transpose_solve(l.as_ref(), b.as_ref()).transpose().to_owned(), from_sigma(&svd.sigma))
        }
    };
    let losses = unscaled(model, losses);
    if !(losses.worst_case.is_finite() && losses.average.is_finite()) {
        return Ok(None);
    }
    Ok(Some(Combination { measurements: subset.to_vec(), h: model.unscale_h(&h, subset), losses }))
}

/// The extended null-space combination of `subset` (Alstad et al. 2009, eq. 41) and its losses.
///
/// With at least nu + nd measurements `G̃ʸ` has full column rank, its pseudo-inverse is a left
/// inverse, and `H` does not change when the disturbance columns of `G̃ʸ` and `J̃` are scaled
/// alike: they are scaled by `Wd` there, which keeps disturbances of any unit in range. With fewer,
/// the pseudo-inverse is the minimum-norm one of the unscaled columns, as Alstad et al. and pySOC
/// compute it.
///
/// # Errors
/// [`SocError::Request`] when the combination cannot hold the inputs; [`SocError::Numerical`]
/// when a factorization fails.
pub fn null_space(model: &LocalModel, subset: &[usize]) -> Result<Combination, SocError> {
    let (nu, nd) = (model.nu(), model.nd());
    let wd = match subset.len() >= nu + nd {
        true => model.parts().wd.clone(),
        false => Mat::identity(nd, nd),
    };
    let mut j_tilde = Mat::zeros(nu, nu + nd);
    j_tilde.as_mut().get_mut(.., ..nu).copy_from(model.juu_half());
    j_tilde.as_mut().get_mut(.., nu..).copy_from(model.juu_half() * model.juu_inv_jud() * &wd);
    let mut g = Mat::zeros(subset.len(), nu + nd);
    g.as_mut().get_mut(.., ..nu).copy_from(rows(model.gy(), subset));
    g.as_mut().get_mut(.., nu..).copy_from(rows(model.gyd(), subset) * &wd);
    let wn = rows(model.y(), subset);
    let wn = wn.as_ref().get(.., nd..);
    let ln = cholesky((wn * wn.transpose()).as_ref(), "the noise covariance of the subset")?;
    let scaled = pinv(lower_solve(ln.as_ref(), g.as_ref()).as_ref())?;
    // H = J̃ (L⁻¹ G)⁺ L⁻¹, i.e. Hᵀ = L⁻ᵀ ((L⁻¹ G)⁺)ᵀ J̃ᵀ.
    let ht = lower_transpose_solve(ln.as_ref(), (scaled.transpose() * j_tilde.transpose()).as_ref());
    let h = ht.transpose().to_owned();
    let losses = unscaled(model, scaled_losses_of(model, subset, &h)?);
    Ok(Combination { measurements: subset.to_vec(), h: model.unscale_h(&h, subset), losses })
}

/// Losses of the scaled data in the data's units.
fn unscaled(model: &LocalModel, l: Losses) -> Losses {
    Losses { worst_case: model.loss(l.worst_case), average: model.loss(l.average) }
}

/// Losses from the singular values of `L⁻¹ G̃_s` (the exact local method's closed form).
pub(crate) fn from_sigma(sigma: &[f64]) -> Losses {
    let smallest = sigma.last().copied().unwrap_or(0.0);
    Losses { worst_case: 0.5 / (smallest * smallest), average: 0.5 * sigma.iter().map(|s| 1.0 / (s * s)).sum::<f64>() }
}

/// Losses from the loss matrix `M`.
fn from_m(m: MatRef<'_, f64>) -> Result<Losses, SocError> {
    let sigma =
        m.singular_values().map_err(|e| SocError::Numerical(format!("the SVD of M did not converge: {e:?}")))?;
    let largest = sigma.first().copied().unwrap_or(0.0);
    let fro2: f64 = (0..m.ncols()).map(|j| m.col(j).iter().map(|v| v * v).sum::<f64>()).sum();
    Ok(Losses { worst_case: 0.5 * largest * largest, average: 0.5 * fro2 })
}

/// `a⁻¹ b` for a square `a`, refused when `a` is singular to working precision.
fn singular_checked_solve(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Result<Mat<f64>, SocError> {
    let sigma = a.singular_values().map_err(|e| SocError::Numerical(format!("{e:?}")))?;
    if rank_deficient(&sigma, a.nrows(), a.ncols()) {
        return Err(SocError::Request(
            "H Gy of the subset is singular: this combination cannot hold the inputs".to_string(),
        ));
    }
    Ok(a.partial_piv_lu().solve(b))
}
