//! Steady state `f(x) = 0` by Newton's method with a sparse LU (faer), row-scaled residuals,
//! bound-respecting backtracking line search and, when Newton stalls from a poor start,
//! pseudo-transient continuation (Kelley & Keyes 1998): `(M/δ − J) Δx = f`, with the pseudo time
//! step δ grown by switched evolution relaxation with an increment, `δ_{k+1} = 1.1 δ_k ‖f_{k−1}‖/‖f_k‖`
//! (PETSc's `TSPSEUDO` default) — the "converge dynamically" advice of Luyben's ch. 3, done
//! implicitly. The increment matters on a plateau, where the residual stays put while the plant
//! moves (a vessel draining at a controller's output limit): plain relaxation keeps δ constant there
//! and marches through the transient at the first step's pace.
//!
//! Pseudo-transient continuation hands over to Newton once its scaled residual is below 1e-6.
//! When that Newton stalls ([`NEWTON_STALL_WINDOW`]), the continuation resumes from where Newton
//! left the state, at the pseudo time step it had reached, and runs to the tolerance itself: with δ
//! large it is Newton's method regularized by `M/δ`, as Kelley & Keyes analyse it, down to the root.
//! This is the case on a high-purity column, whose slowest mode (the composition profile sliding
//! along the column) leaves the Jacobian nearly singular: a scaled residual of 1e-7 there can be a
//! Newton step of order one on a tray's mole fractions, along which the line search's merit is so
//! curved that only steps of 1e-4 to 1e-9 of it are accepted, while the `M/δ` term damps exactly that
//! mode.
//!
//! # References
//! - C. T. Kelley, D. E. Keyes, *Convergence analysis of pseudo-transient continuation*, SIAM J.
//!   Numer. Anal. 35 (1998) 508–523.
//! - J. E. Dennis, R. B. Schnabel, *Numerical Methods for Unconstrained Optimization and Nonlinear
//!   Equations*, SIAM 1996, §6.3 (backtracking line search).

use serde::{Deserialize, Serialize};

use crate::System;
use crate::sparse::SparseLu;

/// Settings of the steady-state solver.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NewtonSettings {
    /// Maximum Newton iterations (default: 60).
    pub max_iter: usize,
    /// Tolerance on the scaled residual ‖W·f‖∞ (default: 1e-10), `W` the row scaling by each
    /// equation's largest term at the unknowns' own sizes ([`stopping_weights`]).
    pub tol: f64,
    /// Use pseudo-transient continuation when Newton fails (default: true).
    pub pseudo_transient: bool,
    /// Maximum pseudo-transient steps (default: 400).
    pub max_ptc_iter: usize,
    /// Initial pseudo time step [s] (default: 1).
    pub ptc_dt0: f64,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        NewtonSettings { max_iter: 60, tol: 1e-10, pseudo_transient: true, max_ptc_iter: 400, ptc_dt0: 1.0 }
    }
}

/// Outcome of a steady-state solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NewtonStatus {
    /// ‖W·f‖∞ ≤ tol ([`stopping_weights`]).
    Converged,
    /// Iteration limit reached.
    MaxIterations,
    /// The line search could not reduce the residual.
    LineSearchFailed,
    /// The Jacobian is singular.
    Singular,
    /// Pseudo-transient continuation made no progress: its best residual did not fall by 1 % over
    /// [`PTC_STALL_WINDOW`] iterations, while its pseudo time step grew ×1.1 per step (ten-thousand-
    /// fold over the window), so neither the transient nor the Newton limit of it is approaching a
    /// steady state. (Newton's own stall, [`NEWTON_STALL_WINDOW`], hands over to the continuation
    /// and is not an outcome.)
    Stalled,
}

/// Iterations without a 1 % improvement after which pseudo-transient continuation gives up.
pub const PTC_STALL_WINDOW: usize = 100;

/// Newton iterations without a 1 % fall of the scaled residual after which Newton hands over to
/// pseudo-transient continuation, when that continuation has already been under way: a converging
/// Newton halves the residual at least every iteration or two, so ten iterations that gain less than
/// 1 % are line searches accepting a sliver of each step.
pub const NEWTON_STALL_WINDOW: usize = 10;

/// One iteration of the history.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IterationRecord {
    /// Iteration number (continuing across the pseudo-transient phase).
    pub iter: usize,
    /// Scaled residual ‖W·f‖∞ of the stopping test before the step (for a pseudo-transient step,
    /// the continuation's own measure of progress, weighted by nominal sizes).
    pub residual: f64,
    /// Step length accepted by the line search (1 = full Newton step).
    pub step: f64,
    /// Pseudo time step [s] (`None` for a Newton step).
    pub pseudo_dt: Option<f64>,
}

/// Result of [`solve_steady`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NewtonReport {
    /// Outcome.
    pub status: NewtonStatus,
    /// Iterations used (Newton plus pseudo-transient).
    pub iterations: usize,
    /// Final scaled residual ‖W·f‖∞ of the stopping test ([`stopping_weights`]).
    pub residual: f64,
    /// Equation with the largest scaled residual, and that residual.
    pub worst: Option<(usize, f64)>,
    /// Iteration history.
    pub history: Vec<IterationRecord>,
    /// Residual function evaluations.
    pub n_residual_evals: usize,
    /// Jacobian evaluations (each one sparse LU factorization).
    pub n_jacobian_evals: usize,
}

/// Growth factor of the pseudo time step per accepted step, on top of switched evolution
/// relaxation (PETSc `-ts_pseudo_increment`, default 1.1).
const PTC_INCREMENT: f64 = 1.1;

/// Overshoot of a bound, relative to the variable's nominal size, that is clipped rather than
/// allowed to shorten the Newton step.
const BOUND_SLACK: f64 = 1e-10;

struct Work<'a, S: System> {
    sys: &'a S,
    n: usize,
    lu: SparseLu,
    jac: Vec<(usize, usize, f64)>,
    r: Vec<f64>,
    w: Vec<f64>,
    /// The stopping test's row weights ([`stopping_weights`]).
    ws: Vec<f64>,
    n_res: usize,
    n_jac: usize,
}

impl<'a, S: System> Work<'a, S> {
    /// Work space for `sys`, reusing `lu`'s symbolic factorization.
    fn new(sys: &'a S, lu: SparseLu) -> Self {
        let n = sys.n();
        Work { sys, n, lu, jac: Vec::new(), r: vec![0.0; n], w: vec![1.0; n], ws: vec![1.0; n], n_res: 0, n_jac: 0 }
    }
    /// Residual and Jacobian at `x`; refreshes the merit's row scaling ([`row_weights`]) and the
    /// stopping test's ([`stopping_weights`]).
    fn linearize(&mut self, x: &[f64]) {
        self.sys.jacobian(x, &mut self.r, &mut self.jac);
        self.n_jac += 1;
        row_weights(&self.jac, |j| self.sys.nominal(j), &mut self.w);
        stopping_weights(&self.jac, |j| self.sys.size(x, j), &mut self.ws);
    }
    /// The largest residual weighted by nominal sizes (the merit's weights) and its row: the
    /// measure of progress.
    fn scaled_norm(&self, r: &[f64]) -> (f64, usize) {
        weighted_max(r, &self.w)
    }
    /// The largest residual weighted by the stopping test's weights and its row.
    fn stop_norm(&self, r: &[f64]) -> (f64, usize) {
        weighted_max(r, &self.ws)
    }
    fn merit(&mut self, x: &[f64], r: &mut [f64]) -> f64 {
        self.sys.residual(x, r);
        self.n_res += 1;
        r.iter().zip(&self.w).map(|(a, b)| (a * b) * (a * b)).sum::<f64>() * 0.5
    }
    /// Largest fraction τ ≤ 1 of `dx` keeping `x` inside the bounds (fraction to the boundary 0.995).
    /// A step that would cross a bound by less than [`BOUND_SLACK`] of the variable's nominal size
    /// does not limit τ: the variable is clipped (a trace mole fraction of 1e-40 pushed to −1e-31
    /// must not shrink a whole-plant step to 1e-12).
    fn max_step(&self, x: &[f64], dx: &[f64]) -> f64 {
        let mut tau: f64 = 1.0;
        for i in 0..self.n {
            let (lo, hi) = self.sys.bounds(i);
            let target = x[i] + dx[i];
            let slack = BOUND_SLACK * self.sys.nominal(i);
            if target < lo - slack && dx[i] < 0.0 {
                tau = tau.min(0.995 * (x[i] - lo).max(0.0) / -dx[i]);
            } else if target > hi + slack && dx[i] > 0.0 {
                tau = tau.min(0.995 * (hi - x[i]).max(0.0) / dx[i]);
            }
        }
        tau
    }
}

/// `max_i |r_i·w_i|` and its row `i` (infinite at the first non-finite term).
fn weighted_max(r: &[f64], w: &[f64]) -> (f64, usize) {
    let mut worst = (0.0, 0);
    for (i, (ri, wi)) in r.iter().zip(w).enumerate() {
        let v = (ri * wi).abs();
        if !v.is_finite() {
            return (f64::INFINITY, i);
        }
        if v > worst.0 {
            worst = (v, i);
        }
    }
    worst
}

/// The row scaling of the stopping test, `w_i = 1/max_j |J_ij·s_j|` with `s_j` the size of unknown
/// `j` at the iterate ([`System::size`]; 1 for a row without a finite nonzero entry), into `w`:
/// a residual is judged against the largest term of its own equation at the unknowns' own sizes.
/// With nominal sizes ([`row_weights`]) a trace component's equations, whose terms are all of
/// the trace's size, would pass with any relative error: the row `e = sp − pv` of a loop holding a
/// mole fraction at 1e-9 weighs a miss of 10 % as 1e-10. Where sizes are at most the nominal values
/// (as [`crate::SteadySystem`]'s are), `w_i` is at least the merit's weight and the test at least
/// as strict as the nominal one.
pub fn stopping_weights(jac: &[(usize, usize, f64)], size: impl Fn(usize) -> f64, w: &mut [f64]) {
    row_weights(jac, size, w);
}

/// The row scaling of the line search's merit, `w_i = 1/max_j |J_ij·nominal_j|` (1 for a row
/// without a finite nonzero entry), into `w` (its length is the number of rows): a residual is
/// judged against the largest term of its own equation, whatever that equation's units.
pub(crate) fn row_weights(jac: &[(usize, usize, f64)], nominal: impl Fn(usize) -> f64, w: &mut [f64]) {
    w.iter_mut().for_each(|v| *v = 0.0);
    for &(i, j, v) in jac {
        w[i] = w[i].max((v * nominal(j)).abs());
    }
    w.iter_mut().for_each(|m| *m = if *m > 0.0 && m.is_finite() { 1.0 / *m } else { 1.0 });
}

/// Backtracking line search along `dx`. Returns the accepted step (the residual at the new `x`
/// left in `wk.r`) or `None`.
fn line_search<S: System>(wk: &mut Work<'_, S>, x: &mut [f64], dx: &[f64], f0: f64) -> Option<f64> {
    let mut lam = wk.max_step(x, dx);
    if lam < 1e-12 {
        // Steps pinned at bounds: clip instead of stopping.
        lam = 1.0;
    }
    let mut trial = vec![0.0; wk.n];
    let mut r = vec![0.0; wk.n];
    for _ in 0..30 {
        for i in 0..wk.n {
            let (lo, hi) = wk.sys.bounds(i);
            trial[i] = (x[i] + lam * dx[i]).clamp(lo, hi);
        }
        let f = wk.merit(&trial, &mut r);
        if f.is_finite() && f <= (1.0 - 1e-4 * lam) * f0 {
            x.copy_from_slice(&trial);
            wk.r = r;
            return Some(lam);
        }
        lam *= 0.5;
    }
    None
}

/// Solve `f(x) = 0` from the start `x` (overwritten with the result).
pub fn solve_steady<S: System>(sys: &S, x: &mut [f64], settings: &NewtonSettings) -> NewtonReport {
    solve_steady_observed(sys, x, settings, &mut |_| {})
}

/// [`solve_steady`] reporting every iteration to `observer` (progress display).
pub fn solve_steady_observed<S: System>(
    sys: &S,
    x: &mut [f64],
    settings: &NewtonSettings,
    observer: &mut dyn FnMut(&IterationRecord),
) -> NewtonReport {
    solve_steady_reusing(sys, x, settings, observer, &mut SparseLu::default())
}

/// [`solve_steady_observed`] with the caller's LU, whose pattern analysis carries over from an
/// earlier solve of the same system (the sequential pass solves each group once per pass).
pub fn solve_steady_reusing<S: System>(
    sys: &S,
    x: &mut [f64],
    settings: &NewtonSettings,
    observer: &mut dyn FnMut(&IterationRecord),
    lu: &mut SparseLu,
) -> NewtonReport {
    let n = sys.n();
    let mut wk = Work::new(sys, std::mem::take(lu));
    let mut history = Observed { records: Vec::new(), observer };
    let mut status = newton_phase(&mut wk, x, settings, &mut history, None);
    if status != NewtonStatus::Converged && settings.pseudo_transient {
        let (reached, dt) = ptc_phase(&mut wk, x, settings, &mut history, settings.tol.max(1e-6), settings.ptc_dt0);
        status = reached;
        if status == NewtonStatus::Converged {
            // PTC reaches the basin; finish with plain Newton to full accuracy.
            status = newton_phase(&mut wk, x, settings, &mut history, Some(NEWTON_STALL_WINDOW));
            if matches!(status, NewtonStatus::Stalled | NewtonStatus::MaxIterations) {
                // Newton stalls near a nearly singular root: the continuation, at the pseudo time
                // step it had reached, takes the state to the tolerance itself. (Not on a singular
                // Jacobian: the `M/δ` term would make a plant without an isolated steady state
                // look solved.)
                status = ptc_phase(&mut wk, x, settings, &mut history, settings.tol, dt).0;
            }
        }
    }
    let history = history.records;
    // `newton_phase` reports convergence only with the residual at the final `x` in `wk.r`
    // (scaled by the last Jacobian's row weights); any other outcome may have moved `x` since.
    if status != NewtonStatus::Converged {
        wk.linearize(x);
    }
    let (residual, worst) = wk.stop_norm(&wk.r);
    *lu = std::mem::take(&mut wk.lu);
    NewtonReport {
        status,
        iterations: history.len(),
        residual,
        worst: (n > 0).then_some((worst, residual)),
        history,
        n_residual_evals: wk.n_res,
        n_jacobian_evals: wk.n_jac,
    }
}

/// Take `steps` pseudo-transient steps `(M/δ − J) Δx = f` of fixed pseudo time step `dt` [s] from
/// `x`, projected onto the bounds: the algebraic equations are (nearly) satisfied afterwards and the
/// differential variables have moved a little along the plant's own dynamics.
pub fn pseudo_transient_steps<S: System>(sys: &S, x: &mut [f64], steps: usize, dt: f64) {
    let n = sys.n();
    let mut wk = Work::new(sys, SparseLu::default());
    let mass = sys.mass();
    for _ in 0..steps {
        wk.linearize(x);
        let mut a = wk.jac.clone();
        a.extend(mass.iter().map(|&(i, j)| (i, j, -1.0 / dt)));
        let mut dx: Vec<f64> = wk.r.iter().map(|v| -v).collect();
        if wk.lu.solve(n, &a, &mut dx).is_err() {
            return;
        }
        for i in 0..n {
            let (lo, hi) = sys.bounds(i);
            x[i] = (x[i] + dx[i]).clamp(lo, hi);
        }
    }
}

/// The iteration history, shown to an observer as it grows.
struct Observed<'a> {
    records: Vec<IterationRecord>,
    observer: &'a mut dyn FnMut(&IterationRecord),
}

impl Observed<'_> {
    fn len(&self) -> usize {
        self.records.len()
    }
    fn push(&mut self, r: IterationRecord) {
        (self.observer)(&r);
        self.records.push(r);
    }
}

/// Newton's method with the line search from `x`, at most `st.max_iter` iterations. With
/// `stall_window`, it stops as [`NewtonStatus::Stalled`] once the scaled residual has not fallen by
/// 1 % over that many iterations.
fn newton_phase<S: System>(
    wk: &mut Work<'_, S>,
    x: &mut [f64],
    st: &NewtonSettings,
    history: &mut Observed<'_>,
    stall_window: Option<usize>,
) -> NewtonStatus {
    let mut progress = Vec::new();
    for _ in 0..st.max_iter {
        wk.linearize(x);
        let (norm, _) = wk.stop_norm(&wk.r);
        if norm <= st.tol {
            return NewtonStatus::Converged;
        }
        progress.push(wk.scaled_norm(&wk.r).0);
        if stall_window.is_some_and(|w| stalled(&progress, w)) {
            return NewtonStatus::Stalled;
        }
        let mut dx: Vec<f64> = wk.r.iter().map(|v| -v).collect();
        let jac = std::mem::take(&mut wk.jac);
        let solved = wk.lu.solve(wk.n, &jac, &mut dx);
        wk.jac = jac;
        if solved.is_err() {
            return NewtonStatus::Singular;
        }
        let f0 = 0.5 * wk.r.iter().zip(&wk.w).map(|(a, b)| (a * b) * (a * b)).sum::<f64>();
        match line_search(wk, x, &dx, f0) {
            Some(step) => history.push(IterationRecord { iter: history.len(), residual: norm, step, pseudo_dt: None }),
            None => return NewtonStatus::LineSearchFailed,
        }
        // Converged at the new point by the row weights of the last Jacobian: no Jacobian is
        // evaluated only to rescale a residual that is already below the tolerance (the weights
        // are row maxima of `|J|`, which the last, quadratically small step hardly moves).
        if wk.stop_norm(&wk.r).0 <= st.tol {
            return NewtonStatus::Converged;
        }
    }
    wk.linearize(x);
    if wk.stop_norm(&wk.r).0 <= st.tol { NewtonStatus::Converged } else { NewtonStatus::MaxIterations }
}

/// Whether the last of the scaled residuals `norms` (one per iteration) is above 99 % of the one
/// `window` iterations earlier.
fn stalled(norms: &[f64], window: usize) -> bool {
    let k = norms.len();
    k > window && norms[k - 1] > 0.99 * norms[k - 1 - window]
}

/// Pseudo-transient continuation from `x` with the first pseudo time step `dt0` until the scaled
/// residual is at most `floor` (then [`NewtonStatus::Converged`]), at most `st.max_ptc_iter`
/// iterations. Returns the outcome and the pseudo time step reached.
fn ptc_phase<S: System>(
    wk: &mut Work<'_, S>,
    x: &mut [f64],
    st: &NewtonSettings,
    history: &mut Observed<'_>,
    floor: f64,
    dt0: f64,
) -> (NewtonStatus, f64) {
    let mass = wk.sys.mass();
    let mut dt = dt0;
    let mut prev_norm = f64::NAN;
    let mut failures = 0;
    let (mut best, mut best_at) = (f64::INFINITY, 0);
    for k in 0..st.max_ptc_iter {
        wk.linearize(x);
        let (norm, _) = wk.scaled_norm(&wk.r);
        if !norm.is_finite() {
            return (NewtonStatus::LineSearchFailed, dt);
        }
        // The hand-over to Newton is judged by the continuation's own measure; the tolerance
        // itself only by the stopping test.
        let reached = if floor <= st.tol { wk.stop_norm(&wk.r).0 } else { norm };
        if reached <= floor {
            return (NewtonStatus::Converged, dt);
        }
        if norm < 0.99 * best {
            (best, best_at) = (norm, k);
        } else if k - best_at >= PTC_STALL_WINDOW {
            return (NewtonStatus::Stalled, dt);
        }
        if prev_norm.is_finite() {
            dt = (PTC_INCREMENT * dt * (prev_norm / norm).clamp(0.2, 10.0)).min(1e12);
        }
        prev_norm = norm;
        // (M/δ − J) Δx = f  ⇔  (J − M/δ) Δx = −f.
        let mut a = wk.jac.clone();
        a.extend(mass.iter().map(|&(i, j)| (i, j, -1.0 / dt)));
        let mut dx: Vec<f64> = wk.r.iter().map(|v| -v).collect();
        if wk.lu.solve(wk.n, &a, &mut dx).is_err() {
            // A smaller pseudo time step makes M/δ dominate the differential rows; if even that
            // stays singular, the algebraic part itself is singular.
            failures += 1;
            if failures > 8 {
                return (NewtonStatus::Singular, dt);
            }
            dt *= 0.1;
            continue;
        }
        failures = 0;
        // The pseudo time step already damps the step: take it whole, projected onto the bounds,
        // unless the residual blows up, in which case retreat to a shorter pseudo time step.
        let trial: Vec<f64> = (0..wk.n)
            .map(|i| {
                let (lo, hi) = wk.sys.bounds(i);
                (x[i] + dx[i]).clamp(lo, hi)
            })
            .collect();
        let mut r = vec![0.0; wk.n];
        wk.sys.residual(&trial, &mut r);
        wk.n_res += 1;
        let trial_norm = wk.scaled_norm(&r).0;
        if !(trial_norm.is_finite() && trial_norm <= 10.0 * norm) {
            dt *= 0.25;
            prev_norm = f64::NAN;
            history.push(IterationRecord { iter: history.len(), residual: norm, step: 0.0, pseudo_dt: Some(dt) });
            continue;
        }
        x.copy_from_slice(&trial);
        history.push(IterationRecord { iter: history.len(), residual: norm, step: 1.0, pseudo_dt: Some(dt) });
    }
    (NewtonStatus::MaxIterations, dt)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rosenbrock-like 2×2 system with a known root (1, 1): f = (10(x1 − x0²), 1 − x0).
    struct Rosen;
    impl System for Rosen {
        fn n(&self) -> usize {
            2
        }
        fn residual(&self, x: &[f64], r: &mut [f64]) {
            r[0] = 10.0 * (x[1] - x[0] * x[0]);
            r[1] = 1.0 - x[0];
        }
        fn jacobian(&self, x: &[f64], r: &mut [f64], jac: &mut Vec<(usize, usize, f64)>) {
            self.residual(x, r);
            jac.clear();
            jac.extend([(0, 0, -20.0 * x[0]), (0, 1, 10.0), (1, 0, -1.0), (1, 1, 0.0)]);
        }
        fn nominal(&self, _i: usize) -> f64 {
            1.0
        }
        fn bounds(&self, _i: usize) -> (f64, f64) {
            (f64::NEG_INFINITY, f64::INFINITY)
        }
        fn mass(&self) -> Vec<(usize, usize)> {
            vec![(0, 1), (1, 0)]
        }
    }

    #[test]
    fn newton_finds_the_root_of_a_nonlinear_system() {
        let mut x = [-1.2, 1.0];
        let rep = solve_steady(&Rosen, &mut x, &NewtonSettings::default());
        assert_eq!(rep.status, NewtonStatus::Converged);
        assert!((x[0] - 1.0).abs() < 1e-12 && (x[1] - 1.0).abs() < 1e-12, "{x:?}");
    }

    /// `dx/dt = −x³ + 1` with a bound x ≥ 0: Newton from 0 has a singular Jacobian; PTC gets there.
    struct Cubic;
    impl System for Cubic {
        fn n(&self) -> usize {
            1
        }
        fn residual(&self, x: &[f64], r: &mut [f64]) {
            r[0] = 1.0 - x[0].powi(3);
        }
        fn jacobian(&self, x: &[f64], r: &mut [f64], jac: &mut Vec<(usize, usize, f64)>) {
            self.residual(x, r);
            jac.clear();
            jac.push((0, 0, -3.0 * x[0] * x[0]));
        }
        fn nominal(&self, _i: usize) -> f64 {
            1.0
        }
        fn bounds(&self, _i: usize) -> (f64, f64) {
            (0.0, f64::INFINITY)
        }
        fn mass(&self) -> Vec<(usize, usize)> {
            vec![(0, 0)]
        }
    }

    /// `f = (x0² − 4, x1 + 1e-31)` with `x1 ≥ 0`: the root has `x1` a round-off below its bound.
    /// From `x1 = 1e-42` the step to −1e-31 is clipped, not allowed to shrink the step of `x0` to
    /// 1e-11, below the round-off of `x0` (which stalled column 2 of the two-column plant at a scaled
    /// residual of 5e-7: the line search sees no decrease and fails).
    struct Trace;
    impl System for Trace {
        fn n(&self) -> usize {
            2
        }
        fn residual(&self, x: &[f64], r: &mut [f64]) {
            r[0] = x[0] * x[0] - 4.0;
            r[1] = x[1] + 1e-31;
        }
        fn jacobian(&self, x: &[f64], r: &mut [f64], jac: &mut Vec<(usize, usize, f64)>) {
            self.residual(x, r);
            jac.clear();
            jac.extend([(0, 0, 2.0 * x[0]), (1, 1, 1.0)]);
        }
        fn nominal(&self, _i: usize) -> f64 {
            1.0
        }
        fn bounds(&self, i: usize) -> (f64, f64) {
            if i == 1 { (0.0, f64::INFINITY) } else { (f64::NEG_INFINITY, f64::INFINITY) }
        }
        fn mass(&self) -> Vec<(usize, usize)> {
            vec![(0, 0), (1, 1)]
        }
    }

    #[test]
    fn a_trace_variable_at_its_bound_does_not_stall_newton() {
        let mut x = [2.000001, 1e-42];
        let settings = NewtonSettings { pseudo_transient: false, ..NewtonSettings::default() };
        let rep = solve_steady(&Trace, &mut x, &settings);
        assert_eq!(rep.status, NewtonStatus::Converged, "{rep:?}");
        assert!(rep.iterations <= 3, "{} iterations", rep.iterations);
        assert!((x[0] - 2.0).abs() < 1e-10 && x[1] == 0.0, "{x:?}");
    }

    /// `f = x − 1e-9` with `x ∈ [0, 1]`, nominal 1: a loop holding a mole fraction at 1e-9. With
    /// `relative`, the unknown's size is its own value (as [`crate::SteadySystem`] sizes a trace).
    struct TraceSetpoint {
        relative: bool,
    }
    impl System for TraceSetpoint {
        fn n(&self) -> usize {
            1
        }
        fn residual(&self, x: &[f64], r: &mut [f64]) {
            r[0] = x[0] - 1e-9;
        }
        fn jacobian(&self, x: &[f64], r: &mut [f64], jac: &mut Vec<(usize, usize, f64)>) {
            self.residual(x, r);
            jac.clear();
            jac.push((0, 0, 1.0));
        }
        fn nominal(&self, _i: usize) -> f64 {
            1.0
        }
        fn size(&self, x: &[f64], i: usize) -> f64 {
            if self.relative { x[i].abs().max(1e-12) } else { self.nominal(i) }
        }
        fn bounds(&self, _i: usize) -> (f64, f64) {
            (0.0, 1.0)
        }
        fn mass(&self) -> Vec<(usize, usize)> {
            vec![(0, 0)]
        }
    }

    #[test]
    fn a_trace_setpoint_is_met_on_its_own_scale() {
        // 5 % off the setpoint is a residual of 5e-11 on the nominal scale of a fraction: below
        // the tolerance, so the nominal test stops at once, 5 % off.
        let mut x = [1.05e-9];
        let rep = solve_steady(&TraceSetpoint { relative: false }, &mut x, &NewtonSettings::default());
        assert_eq!((rep.status, rep.iterations), (NewtonStatus::Converged, 0));
        assert!((x[0] / 1e-9 - 1.0 - 0.05).abs() < 1e-12, "{x:?}");
        // Weighed at its own size the same miss is 0.05 of the row's largest term: Newton steps.
        let mut x = [1.05e-9];
        let rep = solve_steady(&TraceSetpoint { relative: true }, &mut x, &NewtonSettings::default());
        assert_eq!(rep.status, NewtonStatus::Converged);
        assert!(rep.iterations >= 1 && rep.residual <= 1e-10, "{rep:?}");
        assert!((x[0] / 1e-9 - 1.0).abs() < 1e-10, "{x:?}");
    }

    #[test]
    fn a_stall_is_no_fall_of_one_percent_over_the_window() {
        assert!(!stalled(&[1.0, 0.5, 0.4], 2));
        assert!(stalled(&[1.0, 0.995, 0.991], 2));
        assert!(!stalled(&[1.0, 0.995], 2), "fewer iterations than the window");
    }

    #[test]
    fn pseudo_transient_continuation_rescues_a_singular_start() {
        let mut x = [0.0];
        let rep = solve_steady(&Cubic, &mut x, &NewtonSettings::default());
        assert_eq!(rep.status, NewtonStatus::Converged);
        assert!((x[0] - 1.0).abs() < 1e-12);
        assert!(rep.history.iter().any(|h| h.pseudo_dt.is_some()));
    }
}
