//! Isothermal (TP) flash.

use num_dual::{Dual64, DualNum};

use super::input::{self, conditions};
use super::rachford_rice::{normalise, rachford_rice};
use super::saturation::{bubble_p, dew_p};
use crate::{FlashResult, PhaseState, ThermoError, ThermoPackage};

const SS_MAX: usize = 500;
const SS_TOL: f64 = 1e-10;
const NEWTON_MAX: usize = 50;

/// Single-phase result with enthalpy.
pub(crate) fn single_phase(
    pkg: &ThermoPackage,
    t: f64,
    p: f64,
    z: &[f64],
    phase: PhaseState,
    iterations: usize,
) -> FlashResult {
    let (beta, h) = match phase {
        PhaseState::Vapour => (1.0, pkg.h_vap(t, z)),
        _ => (0.0, pkg.h_liq(t, z)),
    };
    FlashResult { t, p, beta, x: z.to_vec(), y: z.to_vec(), h, phase, iterations }
}

/// TP flash. The phase is decided by the bubble and dew pressures of the feed at `t`:
/// liquid when `P ≥ P_bubble(T, z)` (i.e. `Σ z_i K_i(T, P, z) ≤ 1`), vapour when `P ≤ P_dew(T, z)`
/// (i.e. `Σ z_i / K_i ≤ 1` with the K-values of the incipient liquid), two phases otherwise.
/// Two phases: successive substitution (K from the liquid composition, β and compositions from
/// Rachford–Rice), then Newton's method on `(ln K_1 … ln K_n, β)` with residuals
/// `ln K_i − ln Φ_i(T, x̂) + ln P` and the Rachford–Rice function, to machine precision.
pub(crate) fn flash_tp(pkg: &ThermoPackage, t: f64, p: f64, z: &[f64]) -> Result<FlashResult, ThermoError> {
    const R: &str = "flash_tp";
    input::temperature(R, t)?;
    input::pressure(R, p)?;
    let z = input::composition(R, pkg.n(), z)?;
    let cond = || conditions(Some(t), Some(p), None, "z", &z);
    let bub = bubble_p(pkg, t, &z)?;
    if p >= bub.p {
        return Ok(single_phase(pkg, t, p, &z, PhaseState::Liquid, 1));
    }
    let dew = dew_p(pkg, t, &z)?;
    if p <= dew.p {
        return Ok(single_phase(pkg, t, p, &z, PhaseState::Vapour, 1 + dew.iterations));
    }
    let n = pkg.n();
    let ln_p = p.ln();
    // Start between the bubble (x = z) and dew (x = incipient liquid) states.
    let w = ((bub.p - p) / (bub.p - dew.p)).clamp(0.0, 1.0);
    let mut x: Vec<f64> = z.iter().zip(&dew.incipient).map(|(zi, xi)| (1.0 - w) * zi + w * xi).collect();
    normalise(&mut x);
    let mut lp = vec![0.0; n];
    let mut beta = w;
    let mut ss = 0;
    for it in 1..=SS_MAX {
        ss = it;
        pkg.ln_phi(t, &x, &mut lp);
        // ln K is clamped so that exp neither overflows nor underflows to zero.
        let k: Vec<f64> = lp.iter().map(|l| (l - ln_p).clamp(-700.0, 700.0).exp()).collect();
        let rr = rachford_rice(&z, &k).map_err(|_| ThermoError::NoConvergence {
            routine: R,
            iterations: it,
            residual: f64::NAN,
            conditions: cond(),
        })?;
        let d = rr.x.iter().zip(&x).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        x = rr.x;
        beta = rr.beta;
        if d < SS_TOL {
            break;
        }
    }
    // Newton polish on (ln K, β).
    pkg.ln_phi(t, &x, &mut lp);
    let mut u: Vec<f64> = lp.iter().map(|l| l - ln_p).collect();
    u.push(beta.clamp(1e-12, 1.0 - 1e-12));
    let mut lpd = vec![Dual64::from(0.0); n];
    let res = |v: &[Dual64]| {
        let b = v[n];
        let mut xs: Vec<Dual64> = Vec::with_capacity(n);
        let mut rr = Dual64::from(0.0);
        for (zi, lk) in z.iter().zip(v) {
            let km1 = lk.exp() - 1.0;
            let den = b * km1 + 1.0;
            xs.push(den.recip() * *zi);
            rr += km1 / den * *zi;
        }
        let sx: Dual64 = xs.iter().copied().sum();
        xs.iter_mut().for_each(|xi| *xi /= sx);
        pkg.ln_phi(Dual64::from(t), &xs, &mut lpd);
        let mut r: Vec<Dual64> = (0..n).map(|i| v[i] - lpd[i] + ln_p).collect();
        r.push(rr);
        r.iter().all(|ri| ri.re.is_finite()).then_some(r)
    };
    let it = crate::newton::newton(&mut u, res, NEWTON_MAX).map_err(|r| ThermoError::NoConvergence {
        routine: R,
        iterations: ss + NEWTON_MAX,
        residual: r,
        conditions: cond(),
    })?;
    let beta = u[n].clamp(0.0, 1.0);
    let mut x: Vec<f64> = z.iter().zip(&u).map(|(zi, lk)| zi / (1.0 + beta * (lk.exp() - 1.0))).collect();
    let mut y: Vec<f64> = x.iter().zip(&u).map(|(xi, lk)| xi * lk.exp()).collect();
    normalise(&mut x);
    normalise(&mut y);
    if !(x.iter().chain(&y).all(|v| v.is_finite())) {
        return Err(ThermoError::NoConvergence {
            routine: R,
            iterations: ss + it,
            residual: f64::NAN,
            conditions: cond(),
        });
    }
    let h = beta * pkg.h_vap(t, &y) + (1.0 - beta) * pkg.h_liq(t, &x);
    Ok(FlashResult { t, p, beta, x, y, h, phase: PhaseState::TwoPhase, iterations: ss + it })
}
