//! Convergence of the tear variables `t` of one SCC, whose pass computes `φ(t)` (the values the
//! torn connections take after one sweep through the SCC); the fixed point `φ(t) = t` is the
//! SCC's steady state. Each method proposes the next `t` from the history of `(t, φ(t))`:
//!
//! - **direct substitution**: `t ← φ(t)`. Converges linearly with the ratio of the spectral
//!   radius of `∂φ/∂t` (the loop gain), and not at all when that exceeds 1.
//! - **bounded Wegstein** (Wegstein 1958), per variable: with the secant slope
//!   `s_i = Δφ_i/Δt_i` of the last two passes, `q_i = s_i/(s_i − 1)` clipped to `[q_min, q_max]`
//!   (default `[−5, 0]`), `t_i ← q_i t_i + (1 − q_i) φ_i`. The first `wait` passes are direct.
//!   Exact in one step for an uncoupled linear map; ignores coupling between variables.
//! - **Broyden** (good Broyden, Broyden 1965) on the tear residual `g(t) = φ(t) − t` in scaled
//!   variables `τ_i = t_i / scale_i`, one matrix `B ≈ ∂g/∂τ` for all tears of the SCC: start
//!   `B = −I` (the first step is direct substitution), step `B Δτ = −g`, update
//!   `B ← B + (Δg − B Δτ) Δτᵀ / (Δτᵀ Δτ)`; `B` is reset to `−I` when a step raises the residual
//!   tenfold or `B` is singular.
//!
//! Steps are clipped to the variables' bounds. Whatever the method, the loop gain is estimated as
//! the spectral radius of a least-squares secant model `A ≈ ∂φ/∂τ` fitted to the recent steps
//! larger than 1e-7 (scaled).
//!
//! # References
//! - J. H. Wegstein, *Accelerating convergence of iterative processes*, Comm. ACM 1 (1958) 9–13.
//! - C. G. Broyden, *A class of methods for solving nonlinear simultaneous equations*, Math. Comp.
//!   19 (1965) 577–593.

use faer::Mat;
use faer::linalg::solvers::Solve;
use serde::{Deserialize, Serialize};

/// How the tears of an SCC are converged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Accelerator {
    /// Wegstein for an SCC with one torn connection (one stream: its variables are nearly
    /// uncoupled), Broyden for several (coupled tears that per-variable Wegstein cannot see).
    Auto,
    /// Direct substitution.
    Direct,
    /// Bounded Wegstein, per variable.
    Wegstein,
    /// Good Broyden on the tear residual, one matrix per SCC.
    Broyden,
}

impl Accelerator {
    /// The method used for an SCC with `n_tears` torn connections.
    pub fn resolve(self, n_tears: usize) -> Accelerator {
        match self {
            Accelerator::Auto if n_tears <= 1 => Accelerator::Wegstein,
            Accelerator::Auto => Accelerator::Broyden,
            m => m,
        }
    }
    /// Lower-case name, as in settings.
    pub fn name(self) -> &'static str {
        match self {
            Accelerator::Auto => "auto",
            Accelerator::Direct => "direct substitution",
            Accelerator::Wegstein => "Wegstein",
            Accelerator::Broyden => "Broyden",
        }
    }
}

/// Smallest scaled step that updates the loop-gain model: below it the change of `φ` is
/// dominated by the local solves' rounding (about 1e-12 relative), not by the loop.
const SECANT_MIN_STEP: f64 = 1e-7;

/// Wegstein's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct WegsteinBounds {
    pub wait: usize,
    pub q_min: f64,
    pub q_max: f64,
}

/// The iteration state of one SCC's tears.
pub(crate) struct TearIteration {
    method: Accelerator,
    wegstein: WegsteinBounds,
    /// Scale of each variable (fixed for the SCC's iteration).
    scale: Vec<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    /// Last `(t, φ)` pair, unscaled.
    last: Option<(Vec<f64>, Vec<f64>)>,
    passes: usize,
    broyden: Mat<f64>,
    /// Scaled steps `Δτ` and the changes `Δφ` they caused, for the loop-gain model.
    steps: Vec<(Vec<f64>, Vec<f64>)>,
}

fn identity_neg(n: usize) -> Mat<f64> {
    Mat::from_fn(n, n, |i, j| if i == j { -1.0 } else { 0.0 })
}

/// Rank-one secant update `M ← M + (y − M s) sᵀ / (sᵀ s)`.
fn secant_update(m: &mut Mat<f64>, s: &[f64], y: &[f64]) {
    let ss: f64 = s.iter().map(|v| v * v).sum();
    if !(ss > 0.0 && ss.is_finite()) {
        return;
    }
    let n = s.len();
    let ms: Vec<f64> = (0..n).map(|i| (0..n).map(|j| m[(i, j)] * s[j]).sum()).collect();
    for i in 0..n {
        let c = (y[i] - ms[i]) / ss;
        if c.is_finite() {
            for j in 0..n {
                m[(i, j)] += c * s[j];
            }
        }
    }
}

impl TearIteration {
    pub fn new(
        method: Accelerator,
        wegstein: WegsteinBounds,
        scale: Vec<f64>,
        bounds: Vec<(f64, f64)>,
    ) -> TearIteration {
        let n = scale.len();
        let (lower, upper) = bounds.into_iter().unzip();
        TearIteration {
            method,
            wegstein,
            scale,
            lower,
            upper,
            last: None,
            passes: 0,
            broyden: identity_neg(n),
            steps: Vec::new(),
        }
    }

    fn scaled(&self, v: &[f64]) -> Vec<f64> {
        v.iter().zip(&self.scale).map(|(a, s)| a / s).collect()
    }

    /// Record the pass `φ(t)` and propose the next `t`.
    pub fn next(&mut self, t: &[f64], phi: &[f64]) -> Vec<f64> {
        self.passes += 1;
        let n = t.len();
        let g: Vec<f64> = phi.iter().zip(t).map(|(p, x)| p - x).collect();
        if let Some((t0, phi0)) = &self.last {
            let s = self.scaled(&t.iter().zip(t0).map(|(a, b)| a - b).collect::<Vec<_>>());
            let dphi = self.scaled(&phi.iter().zip(phi0).map(|(a, b)| a - b).collect::<Vec<_>>());
            if s.iter().fold(0.0f64, |m, v| m.max(v.abs())) >= SECANT_MIN_STEP {
                self.steps.push((s.clone(), dphi));
            }
            if self.method == Accelerator::Broyden {
                let g0: Vec<f64> = phi0.iter().zip(t0).map(|(p, x)| p - x).collect();
                let dg: Vec<f64> = self.scaled(&g.iter().zip(&g0).map(|(a, b)| a - b).collect::<Vec<_>>());
                let norm = |v: &[f64]| self.scaled(v).iter().fold(0.0f64, |m, x| m.max(x.abs()));
                if norm(&g) > 10.0 * norm(&g0) {
                    self.broyden = identity_neg(n);
                } else {
                    let mut b = std::mem::replace(&mut self.broyden, Mat::zeros(0, 0));
                    secant_update(&mut b, &s, &dg);
                    self.broyden = b;
                }
            }
        }
        let proposal = match self.method {
            Accelerator::Wegstein if self.passes > self.wegstein.wait => self.wegstein_step(t, phi),
            Accelerator::Broyden => self.broyden_step(t, &g),
            _ => phi.to_vec(),
        };
        self.last = Some((t.to_vec(), phi.to_vec()));
        proposal.iter().enumerate().map(|(i, v)| v.clamp(self.lower[i], self.upper[i])).collect()
    }

    fn wegstein_step(&self, t: &[f64], phi: &[f64]) -> Vec<f64> {
        let Some((t0, phi0)) = &self.last else { return phi.to_vec() };
        let WegsteinBounds { q_min, q_max, .. } = self.wegstein;
        (0..t.len())
            .map(|i| {
                let dt = t[i] - t0[i];
                let q = if dt.abs() > 1e-14 * self.scale[i] {
                    let s = (phi[i] - phi0[i]) / dt;
                    if s == 1.0 { q_min } else { (s / (s - 1.0)).clamp(q_min, q_max) }
                } else {
                    0.0
                };
                q * t[i] + (1.0 - q) * phi[i]
            })
            .collect()
    }

    fn broyden_step(&mut self, t: &[f64], g: &[f64]) -> Vec<f64> {
        let n = t.len();
        let rhs = Mat::from_fn(n, 1, |i, _| -g[i] / self.scale[i]);
        let mut step = self.broyden.partial_piv_lu().solve(&rhs);
        if (0..n).any(|i| !step[(i, 0)].is_finite()) {
            self.broyden = identity_neg(n);
            step = Mat::from_fn(n, 1, |i, _| g[i] / self.scale[i]);
        }
        (0..n).map(|i| t[i] + step[(i, 0)] * self.scale[i]).collect()
    }

    /// Spectral radius of the secant model of `∂φ/∂τ` (`None` before two passes).
    ///
    /// The model is the least-squares `A = ΔΦ ΔT⁺` over the last `3n` recorded steps (`ΔT`, `ΔΦ`
    /// their columns): it honours every recent secant condition, where a rank-one update keeps
    /// only the last. Singular values of `ΔT` below 1e-3 of the largest are dropped: directions
    /// the history barely explored (direct substitution soon steps along the dominant eigenvector
    /// only) would otherwise bring noise in as spurious eigenvalues.
    pub fn loop_gain(&self) -> Option<f64> {
        let n = self.scale.len();
        let recent = &self.steps[self.steps.len().saturating_sub(3 * n)..];
        if recent.is_empty() {
            return None;
        }
        let m = recent.len();
        let dt = Mat::from_fn(n, m, |i, k| recent[k].0[i]);
        let dphi = Mat::from_fn(n, m, |i, k| recent[k].1[i]);
        let svd = dt.thin_svd().ok()?;
        let sv = svd.S().column_vector();
        let smax = (0..sv.nrows()).map(|k| sv[k]).fold(0.0f64, f64::max);
        // A = ΔΦ V Σ⁺ Uᵀ.
        let (u, v) = (svd.U(), svd.V());
        let mut a = Mat::<f64>::zeros(n, n);
        for k in 0..sv.nrows() {
            if sv[k].is_nan() || sv[k] <= 1e-3 * smax {
                continue;
            }
            let col: Vec<f64> = (0..n).map(|i| (0..m).map(|j| dphi[(i, j)] * v[(j, k)]).sum::<f64>() / sv[k]).collect();
            for i in 0..n {
                for j in 0..n {
                    a[(i, j)] += col[i] * u[(j, k)];
                }
            }
        }
        let ev = a.eigenvalues().ok()?;
        let rho = ev.iter().map(|z| z.norm()).fold(0.0f64, f64::max);
        rho.is_finite().then_some(rho)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const BOUNDS: WegsteinBounds = WegsteinBounds { wait: 2, q_min: -5.0, q_max: 0.0 };

    /// Iterate the map `phi` from `t0` until `|φ − t| ≤ 1e-12`; passes used and the fixed point.
    fn iterate(method: Accelerator, phi: impl Fn(&[f64]) -> Vec<f64>, t0: &[f64]) -> (usize, Vec<f64>, Option<f64>) {
        let n = t0.len();
        let mut it = TearIteration::new(method, BOUNDS, vec![1.0; n], vec![(f64::NEG_INFINITY, f64::INFINITY); n]);
        let mut t = t0.to_vec();
        for pass in 1..=500 {
            let p = phi(&t);
            if p.iter().zip(&t).all(|(a, b)| (a - b).abs() <= 1e-12) {
                return (pass, p, it.loop_gain());
            }
            t = it.next(&t, &p);
        }
        panic!("{method:?} did not converge");
    }

    /// A linear map `φ(t) = A t + b` with eigenvalues 0.9 and 0.5 (closed-form fixed point
    /// `t* = (I − A)⁻¹ b`).
    fn linear(t: &[f64]) -> Vec<f64> {
        // A = [[0.7, 0.2], [0.2, 0.7]] has eigenvalues 0.9 and 0.5; b = (1, 2).
        vec![0.7 * t[0] + 0.2 * t[1] + 1.0, 0.2 * t[0] + 0.7 * t[1] + 2.0]
    }

    #[test]
    fn all_methods_reach_the_closed_form_fixed_point() {
        // (I − A) t = b: [[0.3, −0.2], [−0.2, 0.3]] t = (1, 2), det 0.05 → t = (14, 16).
        let exact = [14.0, 16.0];
        let mut passes = Vec::new();
        for m in [Accelerator::Direct, Accelerator::Wegstein, Accelerator::Broyden] {
            let (n, t, gain) = iterate(m, linear, &[0.0, 0.0]);
            assert!(t.iter().zip(&exact).all(|(a, b)| (a - b).abs() < 1e-10), "{m:?}: {t:?}");
            passes.push(n);
            if m == Accelerator::Direct {
                // Direct substitution converges at the dominant eigenvalue, 0.9: ln(1e-12/10)/ln(0.9) ≈ 285.
                assert!((250..320).contains(&n), "direct substitution took {n} passes");
            }
            // The map is linear: the secant model is exact on the directions explored.
            let g = gain.unwrap();
            assert!((g - 0.9).abs() < 1e-6, "{m:?}: loop gain {g}");
        }
        // Broyden is exact on a linear map in at most 2n + 1 steps (Gay 1979) plus the first pass.
        assert!(passes[2] <= 6, "Broyden took {} passes", passes[2]);
        // Per-variable Wegstein sees the diagonal slopes 0.7 only, not the coupling: it helps, but
        // far less than on an uncoupled map.
        assert!(passes[2] < passes[1] && passes[1] < passes[0], "passes {passes:?}");
    }

    #[test]
    fn wegstein_is_exact_for_an_uncoupled_linear_map_after_its_wait() {
        // Slope 0.5: q = −1, and one Wegstein step lands on the fixed point 2 (passes: two direct,
        // one accelerated, one to confirm).
        let (n, t, _) = iterate(Accelerator::Wegstein, |t| vec![0.5 * t[0] + 1.0], &[0.0]);
        assert!((t[0] - 2.0).abs() < 1e-12 && n == 4, "{n} passes, t = {t:?}");
        // Slope 0.95: q = −19 is clipped to −5, so each step multiplies the error by
        // q + (1 − q)·0.95 = 0.7 instead of 0 (direct substitution: 0.95).
        let (n, t, _) = iterate(Accelerator::Wegstein, |t| vec![0.95 * t[0] + 1.0], &[0.0]);
        assert!((t[0] - 20.0).abs() < 1e-10);
        assert!((70..100).contains(&n), "{n}");
    }

    #[test]
    fn bounds_are_respected() {
        let mut it = TearIteration::new(Accelerator::Direct, BOUNDS, vec![1.0], vec![(0.0, 1.0)]);
        assert_eq!(it.next(&[0.5], &[1.7]), vec![1.0]);
        assert_eq!(it.next(&[1.0], &[-0.2]), vec![0.0]);
    }
}
