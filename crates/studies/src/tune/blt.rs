//! Luyben's biggest-log-modulus tuning (BLT) of n diagonal PI loops.
//!
//! Luyben, W. L. (1986), "Simple method for tuning SISO controllers in multivariable systems",
//! Ind. Eng. Chem. Process Des. Dev. 25, 654–660:
//!
//! 1. Ziegler–Nichols settings of each diagonal element alone, `K_ZN,i = K_u,i/2.2`,
//!    `τ_ZN,i = P_u,i/1.2`.
//! 2. One detuning factor F ≥ 1 for all loops: `K_c,i = K_ZN,i/F`, `τ_I,i = F τ_ZN,i`, so that
//!    `K(s) = diag(K_c,i (1 + 1/(τ_I,i s)))`.
//! 3. The multivariable analogue of the closed-loop log modulus:
//!    `W(jω) = −1 + det(I + G(jω) K(jω))`, `L_cm(ω) = 20 log10 |W/(1 + W)|`.
//! 4. F is chosen so that the biggest log modulus `max_ω L_cm = 2n` dB (n the number of loops;
//!    +2 dB for a SISO loop is the classical closed-loop peak).
//!
//! The determinant is the complex LU with partial pivoting of faer (`Mat::determinant`).
//! The peak over ω is found on a log-spaced grid (default 50 points per decade over
//! `[1e-4 min ω_u, 10 max ω_u]`), each of its three highest local maxima refined by
//! golden-section search on ln ω; F is bracketed by doubling from 1 and solved by the Illinois
//! method to a relative width of 1e-12.

use faer::{Mat, c64};
use plantwide_analysis::tf::TfModel;

use super::ultimate::Ultimate;
use super::{LoopTuning, PiRule, TuneMethod, Tuning, diagonal_ultimates};
use crate::TuneError;
use crate::numeric::{golden_max, root_bracketed};

/// Settings of the BLT search.
#[derive(Debug, Clone, PartialEq)]
pub struct BltSettings {
    /// Target biggest log modulus \[dB\] (default: `None`, Luyben's 2n for n loops).
    pub target_db: Option<f64>,
    /// Grid points per decade of the peak search (default: 50).
    pub points_per_decade: usize,
    /// Largest detuning factor tried before giving up (default: 1e4).
    pub max_detuning: f64,
}

impl Default for BltSettings {
    fn default() -> Self {
        BltSettings { target_db: None, points_per_decade: 50, max_detuning: 1e4 }
    }
}

/// `L_cm(ω) = 20 log10 |W/(1+W)|` with `W = −1 + det(I + G(jω) K(jω))` for PI loops `(K_c,i, τ_I,i)`.
pub fn log_modulus(g: &Mat<c64>, kc: &[f64], tau_i: &[f64], omega: f64) -> f64 {
    let n = kc.len();
    let k: Vec<c64> = (0..n).map(|j| c64::new(kc[j], -kc[j] / (omega * tau_i[j]))).collect();
    let m = Mat::from_fn(n, n, |i, j| g[(i, j)] * k[j] + if i == j { 1.0 } else { 0.0 });
    let det = m.determinant();
    20.0 * ((det - 1.0).norm() / det.norm()).log10()
}

/// The biggest log modulus over `[omega_lo, omega_hi]` \[rad/s\]: `(ω_peak, L_cm,max in dB)`.
///
/// `g(ω)` returns `G(jω)` (n × n). A log-spaced grid of `points_per_decade` per decade, then
/// golden-section refinement on ln ω around each of the three highest local maxima of the grid.
pub fn max_log_modulus(
    g: &dyn Fn(f64) -> Mat<c64>,
    kc: &[f64],
    tau_i: &[f64],
    (omega_lo, omega_hi): (f64, f64),
    points_per_decade: usize,
) -> (f64, f64) {
    let lcm = |ln_w: f64| {
        let w = ln_w.exp();
        log_modulus(&g(w), kc, tau_i, w)
    };
    let (a, b) = (omega_lo.ln(), omega_hi.ln());
    let n_points = ((omega_hi / omega_lo).log10() * points_per_decade as f64).ceil().max(8.0) as usize;
    let grid: Vec<f64> = (0..=n_points).map(|k| a + (b - a) * k as f64 / n_points as f64).collect();
    let values: Vec<f64> = grid.iter().map(|&x| lcm(x)).collect();
    let mut peaks: Vec<usize> = (0..values.len())
        .filter(|&k| (k == 0 || values[k] >= values[k - 1]) && (k + 1 == values.len() || values[k] >= values[k + 1]))
        .collect();
    peaks.sort_by(|&p, &q| values[q].total_cmp(&values[p]));
    let mut best = (grid[peaks[0]].exp(), values[peaks[0]]);
    for &k in peaks.iter().take(3) {
        let (lo, hi) = (grid[k.saturating_sub(1)], grid[(k + 1).min(grid.len() - 1)]);
        let (x, v) = golden_max(lcm, lo, hi, 1e-10);
        if v > best.1 {
            best = (x.exp(), v);
        }
    }
    best
}

/// The detuning factor F ≥ 1 of the ZN settings `(K_ZN,i, τ_ZN,i)` that makes the biggest log
/// modulus equal `target_db`: `(F, ω_peak, L_cm,max)`; F = 1 when the ZN settings already stay
/// below the target. The peak is sought over `[omega_range.0 / F, omega_range.1]` \[rad/s\].
///
/// # Errors
/// [`TuneError::DetuningLimit`] when even F = `max_detuning` leaves the peak above the target.
pub fn blt_detuning(
    g: &dyn Fn(f64) -> Mat<c64>,
    zn: &[(f64, f64)],
    omega_range: (f64, f64),
    target_db: f64,
    settings: &BltSettings,
) -> Result<(f64, f64, f64), TuneError> {
    let peak = |f: f64| {
        let kc: Vec<f64> = zn.iter().map(|(k, _)| k / f).collect();
        let ti: Vec<f64> = zn.iter().map(|(_, t)| t * f).collect();
        // Detuning slows the loops: the lower end of the range moves down with F.
        max_log_modulus(g, &kc, &ti, (omega_range.0 / f, omega_range.1), settings.points_per_decade)
    };
    let at_one = peak(1.0);
    if at_one.1 <= target_db {
        return Ok((1.0, at_one.0, at_one.1));
    }
    let (mut f_lo, mut f_hi) = (1.0, 2.0);
    while peak(f_hi).1 > target_db {
        if f_hi >= settings.max_detuning {
            return Err(TuneError::DetuningLimit { target_db, detuning: f_hi });
        }
        (f_lo, f_hi) = (f_hi, 2.0 * f_hi);
    }
    let f = root_bracketed(|f| peak(f).1 - target_db, f_lo, f_hi, 1e-12);
    let (w, db) = peak(f);
    Ok((f, w, db))
}

/// Whether PI loops `(K_c,i, τ_I,i)` on the stable `G` close stably, by the generalized Nyquist
/// criterion on `d(jω) = det(I + G(jω) K(jω))` (MacFarlane & Postlethwaite 1977; Skogestad &
/// Postlethwaite, *Multivariable Feedback Control*, Thm 4.9). With `n` integrators in `K`
/// (indented around `s = 0`) and `d → 1` at high frequency, the closed loop is stable iff the
/// phase of `d` rises by `nπ/2` from `ω → 0` to `ω → ∞` (each pair of closed-loop poles in the
/// right half plane takes `2π` from it); `d`'s low-frequency phase is `−nπ/2 + arg det(G(0) K_c
/// T_I⁻¹)`, so a plant `det(G(0) K_c T_I⁻¹) < 0` fails too (Niederlinski). The phase is unwrapped
/// on a log grid from `omega_lo` (steps turning it by at most π/16), and the march goes on past
/// `omega_hi` until `|d − 1| < 0.1`; `None` when it does not get there by `1e4 · omega_hi` (the
/// criterion cannot be read).
pub fn nyquist_stable(
    g: &dyn Fn(f64) -> Mat<c64>,
    kc: &[f64],
    tau_i: &[f64],
    (omega_lo, omega_hi): (f64, f64),
) -> Option<bool> {
    let n = kc.len();
    let d = |w: f64| {
        let k: Vec<c64> = (0..n).map(|j| c64::new(kc[j], -kc[j] / (w * tau_i[j]))).collect();
        let gw = g(w);
        Mat::from_fn(n, n, |i, j| gw[(i, j)] * k[j] + if i == j { 1.0 } else { 0.0 }).determinant()
    };
    let pi = std::f64::consts::PI;
    let (mut w, mut dw) = (omega_lo, d(omega_lo));
    let (mut phase, mut ratio) = (0.0, 1.1_f64);
    while w < omega_hi || (dw - 1.0).norm() >= 0.1 {
        if w > 1e4 * omega_hi || !dw.norm().is_finite() || dw.norm() == 0.0 {
            return None;
        }
        let w_next = w * ratio;
        let d_next = d(w_next);
        let step = (d_next / dw).arg();
        if step.abs() > pi / 16.0 && ratio > 1.0 + 1e-6 {
            ratio = 1.0 + 0.5 * (ratio - 1.0);
            continue;
        }
        (w, dw, phase, ratio) = (w_next, d_next, phase + step, 1.1);
    }
    // From ω_lo (near the −nπ/2 + arg det(G(0) K_c T_I⁻¹) limit) to where d ≈ 1: the rise.
    Some((phase - 0.5 * pi * n as f64).abs() < 0.5 * pi)
}

/// The ZN settings detuned by `f`: `(K_c,i / f, τ_I,i f)`.
fn detuned(zn: &[(f64, f64)], f: f64) -> (Vec<f64>, Vec<f64>) {
    (zn.iter().map(|(k, _)| k / f).collect(), zn.iter().map(|(_, t)| t * f).collect())
}

/// The smallest detuning factor from `blt_f` up (steps of 10 %) at which the loops close stably
/// ([`nyquist_stable`]): BLT's log-modulus target presumes a stable closed loop, which a strongly
/// interacting pairing at F = 1 may not have (a DV column at 1-min analyzer dead time: ZN settings
/// below the target and two right-half-plane poles). `blt_f` itself when stable or when the
/// criterion cannot be read.
///
/// # Errors
/// [`TuneError::NeverStable`] past `max_detuning`.
fn stable_detuning(
    g: &dyn Fn(f64) -> Mat<c64>,
    zn: &[(f64, f64)],
    range: (f64, f64),
    blt_f: f64,
    settings: &BltSettings,
) -> Result<f64, TuneError> {
    let mut f = blt_f;
    loop {
        let (kc, ti) = detuned(zn, f);
        if nyquist_stable(g, &kc, &ti, (range.0 / f, range.1)) != Some(false) {
            return Ok(f);
        }
        if f > settings.max_detuning {
            return Err(TuneError::NeverStable { detuning: f });
        }
        f *= 1.1;
    }
}

/// A square system of loops to tune together: output i paired with input i, its frequency
/// response, steady-state gain and the ultimate gain and period of each diagonal element.
pub struct LoopSystem<'a> {
    /// Name (for messages).
    pub name: String,
    /// Controlled outputs.
    pub outputs: Vec<String>,
    /// Manipulated inputs.
    pub inputs: Vec<String>,
    /// `G(jω)` at `ω` \[rad/s\] (n × n).
    pub response: &'a dyn Fn(f64) -> Mat<c64>,
    /// `G(0)`.
    pub gain: Mat<f64>,
    /// Ultimate gain and frequency of each diagonal element.
    pub ultimates: Vec<Ultimate>,
}

/// Luyben's BLT tuning of the diagonal pairing (output i ↔ input i) of a square model.
///
/// # Errors
/// [`TuneError::NotSquare`], [`TuneError::SingularGain`] (σ_min/σ_max of `G(0)`, equilibrated, below 1e-10),
/// [`TuneError::NoPhaseCrossover`] naming a diagonal element without an ultimate gain,
/// [`TuneError::Svd`] when the SVD of `G(0)` fails, [`TuneError::DetuningLimit`] from [`blt_detuning`].
pub fn blt(model: &TfModel, settings: &BltSettings) -> Result<Tuning, TuneError> {
    let ultimates: Vec<Ultimate> = diagonal_ultimates(model)?;
    let g = |w: f64| model.response(w);
    let system = LoopSystem {
        name: model.name.clone(),
        outputs: model.outputs.iter().map(|s| s.name.clone()).collect(),
        inputs: model.inputs.iter().map(|s| s.name.clone()).collect(),
        response: &g,
        gain: model.gain(),
        ultimates,
    };
    Ok(super::with_margins(model, blt_system(&system, settings)?))
}

/// Luyben's BLT tuning of a [`LoopSystem`].
///
/// # Errors
/// [`TuneError::NotSquare`], [`TuneError::SingularGain`], [`TuneError::Svd`], [`TuneError::DetuningLimit`] as [`blt`].
pub fn blt_system(system: &LoopSystem<'_>, settings: &BltSettings) -> Result<Tuning, TuneError> {
    let n = system.outputs.len();
    if n != system.inputs.len() || system.ultimates.len() != n {
        return Err(TuneError::NotSquare { model: system.name.clone(), n_outputs: n, n_inputs: system.inputs.len() });
    }
    // Integral action needs det G(0) ≠ 0, which the units of the signals do not change: judged on
    // G(0) equilibrated (a reboiler duty in W against a ppm impurity is not a singular plant).
    let equilibrated = plantwide_analysis::measures::equilibrated(system.gain.as_ref());
    let sv = equilibrated.singular_values().map_err(|e| TuneError::Svd { detail: format!("{e:?}") })?;
    let (s_max, s_min) = (sv.iter().cloned().fold(0.0, f64::max), sv.iter().cloned().fold(f64::INFINITY, f64::min));
    let ratio = if s_max > 0.0 { s_min / s_max } else { 0.0 };
    if ratio.is_nan() || ratio < 1e-10 {
        return Err(TuneError::SingularGain { model: system.name.clone(), ratio });
    }
    let ultimates = &system.ultimates;
    let zn: Vec<(f64, f64)> = ultimates.iter().map(|u| PiRule::ZieglerNichols.settings(u)).collect();
    let w_min = ultimates.iter().map(|u| u.omega_u).fold(f64::INFINITY, f64::min);
    let w_max = ultimates.iter().map(|u| u.omega_u).fold(0.0, f64::max);
    let target = settings.target_db.unwrap_or(2.0 * n as f64);
    let range = (1e-4 * w_min, 10.0 * w_max);
    let (blt_f, w_peak, db) = blt_detuning(system.response, &zn, range, target, settings)?;
    let f = stable_detuning(system.response, &zn, range, blt_f, settings)?;
    let (w_peak, db) = if f == blt_f {
        (w_peak, db)
    } else {
        let (kc, ti) = detuned(&zn, f);
        max_log_modulus(system.response, &kc, &ti, (range.0 / f, range.1), settings.points_per_decade)
    };
    let loops = (0..n)
        .map(|i| LoopTuning {
            output: system.outputs[i].clone(),
            input: system.inputs[i].clone(),
            ku: ultimates[i].ku,
            pu: ultimates[i].pu,
            kc: zn[i].0 / f,
            tau_i: zn[i].1 * f,
            margins: None,
        })
        .collect();
    Ok(Tuning {
        method: TuneMethod::Blt,
        detuning_factor: Some(f),
        unstable_at: (f != blt_f).then_some(blt_f),
        loops,
        max_lcm_db: Some(db),
        peak_omega: Some(w_peak),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `g = 1/((s+1)(0.5s+1))` under PI `K_c(1 + 1/(0.1 s))`: the characteristic polynomial
    /// `0.05 s³ + 0.15 s² + 0.1(1+K_c) s + K_c` is stable by Routh–Hurwitz iff
    /// `0.15 · 0.1(1+K_c) > 0.05 K_c`, i.e. `K_c < 3/7`.
    #[test]
    fn the_nyquist_check_agrees_with_routh_hurwitz() {
        let g = |w: f64| {
            let s = c64::new(0.0, w);
            Mat::from_fn(1, 1, |_, _| ((s + 1.0) * (s * 0.5 + 1.0)).inv())
        };
        for (kc, stable) in [(0.1, true), (0.4, true), (0.42, true), (0.44, false), (0.6, false), (3.0, false)] {
            assert_eq!(nyquist_stable(&g, &[kc], &[0.1], (1e-4, 1e2)), Some(stable), "Kc = {kc}");
        }
    }

    #[test]
    fn one_loop_blt_is_the_classical_2_db_closed_loop_peak() {
        // g = 2 e^(−s)/(10 s + 1): for n = 1, W/(1 + W) = g c/(1 + g c), the closed-loop response.
        let gs = |w: f64| c64::new(0.0, -w).exp() * 2.0 / c64::new(1.0, 10.0 * w);
        let g = |w: f64| Mat::from_fn(1, 1, |_, _| gs(w));
        let u = crate::tune::ultimate(gs, 1e-4, 1e3).unwrap();
        let zn = [PiRule::ZieglerNichols.settings(&u)];
        let range = (1e-4 * u.omega_u, 10.0 * u.omega_u);
        let (f, _, db) = blt_detuning(&g, &zn, range, 2.0, &BltSettings::default()).unwrap();
        assert!(f > 1.0 && (db - 2.0).abs() < 1e-9, "F = {f}, peak = {db}");
        let (kc, ti) = (zn[0].0 / f, zn[0].1 * f);
        let closed = |w: f64| {
            let l = gs(w) * c64::new(kc, -kc / (w * ti));
            20.0 * (l / (l + 1.0)).norm().log10()
        };
        let peak = (0..20_000).map(|k| closed(1e-3 * 1e4f64.powf(k as f64 / 20_000.0))).fold(f64::MIN, f64::max);
        assert!(peak <= 2.0 + 1e-9 && peak > 2.0 - 1e-4, "grid peak {peak}");
    }
}
