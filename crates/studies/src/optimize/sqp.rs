//! A trust-region SQP with the ℓ1 exact penalty (Sℓ1QP: Fletcher, *Practical Methods of
//! Optimization*, 2nd ed., 1987, §14.5; Nocedal & Wright, *Numerical Optimization*, 2nd ed.,
//! 2006, §18.5) for
//!
//! ```text
//! minimize f(v)  subject to  lo ≤ c(v) ≤ hi,  lb ≤ v ≤ ub
//! ```
//!
//! in variables scaled by the caller (so that a unit step is a large one). Each iteration solves
//! the elastic QP of [`super::qp`] in a trust region, judges the step by the merit
//! `φ = f + ρ Σ viol(c)` (actual over predicted decrease), tries one second-order correction
//! before rejecting a step (against the Maratos effect), and updates the Hessian of the
//! Lagrangian by damped BFGS (Powell 1978).
//!
//! Why BFGS and not the exact Hessian the plant can give ([`super::curvature`]): clarabel's
//! subproblems need a convex objective, and away from the optimum, or across active limits, the
//! exact Hessian of the Lagrangian is often indefinite; convexifying it discards the Newton
//! property it would bring. Damped BFGS is positive definite by construction and converges
//! superlinearly; the exact curvature certifies the answer at the optimum.
//!
//! The penalty `ρ` only grows: tenfold while the QP needs slacks (its linearization cannot be
//! met inside the region) or while a multiplier comes near it. With `ρ` at its cap and the
//! slacks still positive at a stationary point, the constraints cannot be met: the answer is
//! [`Outcome::Infeasible`] at a local minimizer of the violation.

use faer::Mat;

use super::qp::{Qp, QpData, QpFailure, QpStep};

/// The functions and first derivatives at one point (scaled).
#[derive(Debug, Clone)]
pub(crate) struct Point<S> {
    /// Objective `f`.
    pub f: f64,
    /// Its gradient (n).
    pub g: Vec<f64>,
    /// Constraints `c` (m).
    pub c: Vec<f64>,
    /// Their Jacobian (m × n).
    pub a: Mat<f64>,
    /// What the evaluation found besides (the plant's state), to start the next one from.
    pub state: S,
}

/// A problem the SQP can evaluate.
pub(crate) trait Nlp {
    /// The state kept with a point.
    type State;
    /// Why an evaluation failed.
    type Failure;
    /// `f`, `c` and their derivatives at `v`, started from the state of a point near it.
    fn evaluate(&mut self, v: &[f64], near: Option<&Self::State>) -> Result<Point<Self::State>, Self::Failure>;
}

/// Bounds and limits of the problem (scaled; ±∞ where absent).
#[derive(Debug, Clone)]
pub(crate) struct Bounds {
    /// Lower bounds on `v`.
    pub lb: Vec<f64>,
    /// Upper bounds on `v`.
    pub ub: Vec<f64>,
    /// Lower limits on `c`.
    pub lo: Vec<f64>,
    /// Upper limits on `c`.
    pub hi: Vec<f64>,
}

/// Settings of the SQP.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Settings {
    /// Most iterations.
    pub max_iterations: usize,
    /// KKT tolerance (scaled): stationarity, feasibility and complementarity.
    pub tolerance: f64,
    /// First trust-region radius (in the scaled variables).
    pub radius: f64,
}

impl Default for Settings {
    fn default() -> Settings {
        Settings { max_iterations: 200, tolerance: 1e-9, radius: 0.1 }
    }
}

/// How the SQP ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Outcome {
    /// A KKT point within the tolerance.
    Optimal,
    /// A stationary point of the constraint violation with the violation above the tolerance.
    Infeasible,
    /// The trust region shrank to nothing without a KKT point (no step decreases the merit).
    Stalled,
    /// The iteration limit.
    IterationLimit,
}

/// The SQP's answer.
#[derive(Debug, Clone)]
pub(crate) struct Solution<S> {
    /// How it ended.
    pub outcome: Outcome,
    /// The last accepted point's variables.
    pub v: Vec<f64>,
    /// The last accepted point.
    pub point: Point<S>,
    /// Signed constraint multipliers (≥ 0 on a lower limit): `∂f*/∂limit`.
    pub y: Vec<f64>,
    /// Signed bound multipliers (≥ 0 on a lower bound).
    pub mu: Vec<f64>,
    /// The KKT residual at `v` with `y`, `mu`.
    pub kkt: Kkt,
    /// Iterations.
    pub iterations: usize,
}

/// The parts of the KKT residual (scaled), each an ∞-norm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Kkt {
    /// `‖g − Aᵀy − μ‖`.
    pub stationarity: f64,
    /// The largest violation of a limit or bound.
    pub feasibility: f64,
    /// The largest `|y_i|·(distance of c_i from the limit its sign names)`, and the same of `μ`.
    pub complementarity: f64,
}

impl Kkt {
    /// The largest part.
    pub fn max(&self) -> f64 {
        self.stationarity.max(self.feasibility).max(self.complementarity)
    }
}

/// The cap of the penalty.
const RHO_MAX: f64 = 1e6;
/// The least ratio of actual to predicted decrease that accepts a step.
const ETA: f64 = 1e-4;
/// The relative noise of the merit function (the plant's steady solves).
const NOISE: f64 = 1e-10;
/// The interior-point QP solves to ~1e-12 of its scaled objective, which leaves the multipliers,
/// and so the stationarity, a few orders above that: a point where the QP finds no decrease is
/// accepted as a KKT point within this many tolerances.
const QP_FLOOR: f64 = 100.0;
/// The share of the attainable decrease of the linearized violation a step must achieve.
const STEERING: f64 = 0.1;
/// The smallest trust region before the SQP gives up.
const RADIUS_MIN: f64 = 1e-12;

/// Run the SQP from `v0` (moved into the bounds).
pub(crate) fn solve<N: Nlp>(
    nlp: &mut N,
    bounds: &Bounds,
    v0: &[f64],
    settings: &Settings,
) -> Result<Solution<N::State>, SqpError<N::Failure>>
where
    N::State: Clone,
{
    let n = v0.len();
    let mut v: Vec<f64> = (0..n).map(|j| v0[j].max(bounds.lb[j]).min(bounds.ub[j])).collect();
    let mut p = nlp.evaluate(&v, None).map_err(SqpError::Start)?;
    let mut qp = Qp::new(n, &bounds.lo, &bounds.hi).map_err(SqpError::Qp)?;
    let mut run = Run { b: Mat::identity(n, n), radius: settings.radius, rho: 1.0 };
    for iteration in 0..settings.max_iterations {
        let step = run.step(&mut qp, bounds, &v, &p, None).map_err(SqpError::Qp)?;
        let kkt = kkt(bounds, &v, &p, &step);
        let done = |outcome| Solution {
            outcome,
            v: v.clone(),
            point: p.clone(),
            y: step.y.clone(),
            mu: step.mu.clone(),
            kkt,
            iterations: iteration,
        };
        if kkt.max() <= settings.tolerance {
            return Ok(done(Outcome::Optimal));
        }
        let size = step.d.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
        if size <= 1e-12 {
            // The QP finds no step: a KKT point to the QP's own accuracy, or a stationary point
            // of the violation. (A step whose predicted decrease is below the QP's accuracy, even
            // negative by rounding, is still tried: the merit judges it.)
            return Ok(done(if kkt.max() <= QP_FLOOR * settings.tolerance {
                Outcome::Optimal
            } else if kkt.feasibility > settings.tolerance {
                Outcome::Infeasible
            } else {
                Outcome::Stalled
            }));
        }
        match run.trial(nlp, &mut qp, bounds, (&v, &p), &step).map_err(SqpError::Qp)? {
            Some((v_new, p_new)) => {
                run.bfgs(&v, &p, &v_new, &p_new, &step.y);
                if size >= 0.8 * run.radius {
                    run.radius = (2.0 * run.radius).min(1e3);
                }
                (v, p) = (v_new, p_new);
            }
            None => {
                run.radius = 0.25 * size;
                if run.radius < RADIUS_MIN {
                    let infeasible = kkt.feasibility > settings.tolerance;
                    return Ok(done(if infeasible { Outcome::Infeasible } else { Outcome::Stalled }));
                }
            }
        }
    }
    let step = run.step(&mut qp, bounds, &v, &p, None).map_err(SqpError::Qp)?;
    let kkt = kkt(bounds, &v, &p, &step);
    let outcome = if kkt.max() <= settings.tolerance { Outcome::Optimal } else { Outcome::IterationLimit };
    Ok(Solution { outcome, point: p, y: step.y, mu: step.mu, v, kkt, iterations: settings.max_iterations })
}

/// Why the SQP could not run.
#[derive(Debug, Clone)]
pub(crate) enum SqpError<F> {
    /// The first point could not be evaluated.
    Start(F),
    /// A QP failed.
    Qp(QpFailure),
}

/// An accepted trial point, if any.
type Accepted<S> = Option<(Vec<f64>, Point<S>)>;

/// The state of a run besides the iterate.
struct Run {
    b: Mat<f64>,
    radius: f64,
    rho: f64,
}

impl Run {
    /// The QP step at `(v, p)` (constraints `c` replaced by `shifted` for a second-order
    /// correction), raising `ρ` while the linearization needs slacks or a multiplier nears it.
    fn step<S>(
        &mut self,
        qp: &mut Qp,
        bounds: &Bounds,
        v: &[f64],
        p: &Point<S>,
        shifted: Option<&[f64]>,
    ) -> Result<QpStep, QpFailure> {
        let n = v.len();
        let low: Vec<f64> = (0..n).map(|j| (bounds.lb[j] - v[j]).max(-self.radius).min(0.0)).collect();
        let up: Vec<f64> = (0..n).map(|j| (bounds.ub[j] - v[j]).min(self.radius).max(0.0)).collect();
        let low_bound: Vec<bool> = (0..n).map(|j| bounds.lb[j] - v[j] >= -self.radius).collect();
        let up_bound: Vec<bool> = (0..n).map(|j| bounds.ub[j] - v[j] <= self.radius).collect();
        let mut feasibility_step: Option<QpStep> = None;
        loop {
            let c = shifted.unwrap_or(&p.c);
            let at_bound = (low_bound.as_slice(), up_bound.as_slice());
            let data = QpData { g: &p.g, b: &self.b, c, a: &p.a, low: &low, up: &up, at_bound, rho: self.rho };
            let step = qp.solve(&data)?;
            if self.rho >= RHO_MAX {
                return Ok(step);
            }
            let y_max = step.y.iter().fold(0.0_f64, |m, y| m.max(y.abs()));
            // With slacks the elastic multipliers sit at ρ by construction: only a feasible
            // linearization's multipliers say ρ is too small for the merit to be exact.
            if step.slack <= 1e-10 && y_max > 0.5 * self.rho {
                self.rho *= 10.0;
                continue;
            }
            if step.slack > 1e-10 {
                // Steering (Byrd, Nocedal & Waltz 2008): the step must achieve a tenth of the
                // largest decrease of the linearized violation the region allows, else ρ rises.
                let best = match &feasibility_step {
                    Some(b) => b,
                    None => feasibility_step.insert(qp.solve(&QpData { rho: RHO_MAX, ..data })?),
                };
                let zero = qp.violation(c, None, &p.a);
                let (now, least) = (qp.violation(c, Some(&step.d), &p.a), qp.violation(c, Some(&best.d), &p.a));
                if zero - now < STEERING * (zero - least) {
                    self.rho *= 10.0;
                    continue;
                }
            }
            return Ok(step);
        }
    }

    /// The merit `φ = f + ρ Σ viol(c)`.
    fn merit<S>(&self, qp: &Qp, p: &Point<S>) -> f64 {
        p.f + self.rho * qp.violation(&p.c, None, &p.a)
    }

    /// Try `v + d`, then its second-order correction; the accepted point, if any.
    fn trial<N: Nlp>(
        &mut self,
        nlp: &mut N,
        qp: &mut Qp,
        bounds: &Bounds,
        (v, p): (&[f64], &Point<N::State>),
        step: &QpStep,
    ) -> Result<Accepted<N::State>, QpFailure> {
        let n = v.len();
        let at =
            |d: &[f64]| -> Vec<f64> { (0..n).map(|j| (v[j] + d[j]).max(bounds.lb[j]).min(bounds.ub[j])).collect() };
        let phi0 = self.merit(qp, p);
        let v1 = at(&step.d);
        let Ok(p1) = nlp.evaluate(&v1, Some(&p.state)) else { return Ok(None) };
        // A decrease below the noise of φ is judged by not rising above it: the steady states are
        // solved to a scaled residual of 1e-12, which leaves φ uncertain to about 1e-10.
        let noise = NOISE * (1.0 + phi0.abs());
        let good = |phi: f64| {
            let actual = phi0 - phi;
            actual >= ETA * step.predicted || (step.predicted < noise && actual > -noise)
        };
        if good(self.merit(qp, &p1)) {
            return Ok(Some((v1, p1)));
        }
        if p.c.is_empty() {
            return Ok(None);
        }
        // Second-order correction: the linearization re-anchored on the constraint values found
        // at the trial point, c(v + d) − A d.
        let shifted: Vec<f64> =
            (0..p.c.len()).map(|i| p1.c[i] - (0..n).map(|j| p.a[(i, j)] * step.d[j]).sum::<f64>()).collect();
        let rho = self.rho;
        let soc = self.step(qp, bounds, v, p, Some(&shifted))?;
        if self.rho != rho {
            return Ok(None);
        }
        let v2 = at(&soc.d);
        let Ok(p2) = nlp.evaluate(&v2, Some(&p.state)) else { return Ok(None) };
        Ok(good(self.merit(qp, &p2)).then_some((v2, p2)))
    }

    /// Damped BFGS update of `B` with `s = v₁ − v₀` and the change of `∇L = g − Aᵀy`
    /// (Powell 1978: `y` mixed with `Bs` so that `sᵀy ≥ 0.2 sᵀBs`).
    fn bfgs<S>(&mut self, v0: &[f64], p0: &Point<S>, v1: &[f64], p1: &Point<S>, y: &[f64]) {
        let n = v0.len();
        let grad_l = |p: &Point<S>, j: usize| p.g[j] - (0..y.len()).map(|i| p.a[(i, j)] * y[i]).sum::<f64>();
        let s: Vec<f64> = (0..n).map(|j| v1[j] - v0[j]).collect();
        let mut r: Vec<f64> = (0..n).map(|j| grad_l(p1, j) - grad_l(p0, j)).collect();
        let bs: Vec<f64> = (0..n).map(|i| (0..n).map(|j| self.b[(i, j)] * s[j]).sum()).collect();
        let sbs: f64 = (0..n).map(|j| s[j] * bs[j]).sum();
        let sr: f64 = (0..n).map(|j| s[j] * r[j]).sum();
        if sbs <= 0.0 || !sbs.is_finite() {
            return;
        }
        if sr < 0.2 * sbs {
            let theta = 0.8 * sbs / (sbs - sr);
            r = (0..n).map(|j| theta * r[j] + (1.0 - theta) * bs[j]).collect();
        }
        let sr: f64 = (0..n).map(|j| s[j] * r[j]).sum();
        if sr <= 0.0 || !sr.is_finite() {
            return;
        }
        let updated = Mat::from_fn(n, n, |i, j| self.b[(i, j)] + r[i] * r[j] / sr - bs[i] * bs[j] / sbs);
        // Damping keeps B positive definite in exact arithmetic; where the plant's derivatives
        // span many orders, rounding can still break it, and the QP needs it convex: start over.
        let finite = (0..n).all(|i| (0..n).all(|j| updated[(i, j)].is_finite()));
        self.b = if finite && updated.llt(faer::Side::Lower).is_ok() { updated } else { Mat::identity(n, n) };
    }
}

/// The KKT residual at `(v, p)` with the multipliers of `step`.
fn kkt<S>(bounds: &Bounds, v: &[f64], p: &Point<S>, step: &QpStep) -> Kkt {
    let (n, m) = (v.len(), p.c.len());
    let stationarity = (0..n)
        .map(|j| (p.g[j] - (0..m).map(|i| p.a[(i, j)] * step.y[i]).sum::<f64>() - step.mu[j]).abs())
        .fold(0.0, f64::max);
    let mut feasibility: f64 = 0.0;
    let mut complementarity: f64 = 0.0;
    for i in 0..m {
        feasibility = feasibility.max(bounds.lo[i] - p.c[i]).max(p.c[i] - bounds.hi[i]);
        let gap = if step.y[i] > 0.0 { p.c[i] - bounds.lo[i] } else { bounds.hi[i] - p.c[i] };
        if step.y[i] != 0.0 {
            complementarity = complementarity.max(step.y[i].abs() * gap.abs().min(1.0));
        }
    }
    for (j, &vj) in v.iter().enumerate() {
        let gap = if step.mu[j] > 0.0 { vj - bounds.lb[j] } else { bounds.ub[j] - vj };
        if step.mu[j] != 0.0 {
            complementarity = complementarity.max(step.mu[j].abs() * gap.abs().min(1.0));
        }
    }
    Kkt { stationarity, feasibility, complementarity }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A value and its gradient.
    type Valued = (f64, Vec<f64>);

    /// An analytic problem: `f`, `c` and their gradients by closures.
    struct Analytic {
        f: fn(&[f64]) -> (f64, Vec<f64>),
        c: fn(&[f64]) -> Vec<Valued>,
    }

    impl Nlp for Analytic {
        type State = ();
        type Failure = ();
        fn evaluate(&mut self, v: &[f64], _: Option<&()>) -> Result<Point<()>, ()> {
            let (f, g) = (self.f)(v);
            let cs = (self.c)(v);
            let a = Mat::from_fn(cs.len(), v.len(), |i, j| cs[i].1[j]);
            Ok(Point { f, g, c: cs.iter().map(|c| c.0).collect(), a, state: () })
        }
    }

    fn run(p: &mut Analytic, b: &Bounds, v0: &[f64]) -> Solution<()> {
        match solve(p, b, v0, &Settings::default()) {
            Ok(s) => s,
            Err(SqpError::Qp(m)) => panic!("{m}"),
            Err(SqpError::Start(())) => panic!("start"),
        }
    }

    /// Hock & Schittkowski (1981) problem 71, the Ipopt tutorial's: f* = 17.0140173 at
    /// (1, 4.7429994, 3.8211503, 1.3794082).
    fn hs071() -> (Analytic, Bounds) {
        let f = |x: &[f64]| {
            let s = x[0] + x[1] + x[2];
            (x[0] * x[3] * s + x[2], vec![x[3] * (s + x[0]), x[0] * x[3], x[0] * x[3] + 1.0, x[0] * s])
        };
        let c = |x: &[f64]| {
            let prod = vec![x[1] * x[2] * x[3], x[0] * x[2] * x[3], x[0] * x[1] * x[3], x[0] * x[1] * x[2]];
            vec![(x[0] * prod[0], prod), (x.iter().map(|v| v * v).sum(), x.iter().map(|v| 2.0 * v).collect())]
        };
        let b = Bounds { lb: vec![1.0; 4], ub: vec![5.0; 4], lo: vec![25.0, 40.0], hi: vec![f64::INFINITY, 40.0] };
        (Analytic { f, c }, b)
    }

    #[test]
    fn hock_schittkowski_71_is_solved_to_its_published_optimum() {
        let (mut p, b) = hs071();
        let s = run(&mut p, &b, &[1.0, 5.0, 5.0, 1.0]);
        assert_eq!(s.outcome, Outcome::Optimal, "{:?}", s.kkt);
        assert!((s.point.f - 17.014_017_3).abs() < 1e-6, "{}", s.point.f);
        for (x, r) in s.v.iter().zip([1.0, 4.742_999_4, 3.821_150_3, 1.379_408_2]) {
            assert!((x - r).abs() < 1e-6, "{:?}", s.v);
        }
    }

    #[test]
    fn multipliers_are_the_change_of_the_optimum_with_each_limit() {
        // ∂f*/∂limit by re-solving with the limit moved ± h (central differences): a second
        // route to the multipliers the QP returns.
        let (mut p, b) = hs071();
        let s = run(&mut p, &b, &[1.0, 5.0, 5.0, 1.0]);
        let h = 1e-4;
        for (i, both) in [(0, false), (1, true)] {
            let moved = |d: f64| {
                let mut bb = b.clone();
                bb.lo[i] += d;
                if both {
                    bb.hi[i] += d;
                }
                run(&mut hs071().0, &bb, &s.v).point.f
            };
            let fd = (moved(h) - moved(-h)) / (2.0 * h);
            assert!((s.y[i] - fd).abs() < 1e-6 * (1.0 + fd.abs()), "constraint {i}: {} vs {fd}", s.y[i]);
        }
        // f rises with the product's limit, and falls as the sphere's radius grows.
        assert!(s.y[0] > 0.0 && s.y[1] < 0.0, "{:?}", s.y);
    }

    #[test]
    fn hock_schittkowski_35_bounds_and_a_linear_limit() {
        // HS35: f* = 1/9 at (4/3, 7/9, 4/9).
        let f = |x: &[f64]| {
            let f = 9.0 - 8.0 * x[0] - 6.0 * x[1] - 4.0 * x[2]
                + 2.0 * x[0] * x[0]
                + 2.0 * x[1] * x[1]
                + x[2] * x[2]
                + 2.0 * x[0] * x[1]
                + 2.0 * x[0] * x[2];
            let g = vec![
                -8.0 + 4.0 * x[0] + 2.0 * x[1] + 2.0 * x[2],
                -6.0 + 4.0 * x[1] + 2.0 * x[0],
                -4.0 + 2.0 * x[2] + 2.0 * x[0],
            ];
            (f, g)
        };
        let c = |x: &[f64]| vec![(x[0] + x[1] + 2.0 * x[2], vec![1.0, 1.0, 2.0])];
        let b = Bounds { lb: vec![0.0; 3], ub: vec![f64::INFINITY; 3], lo: vec![f64::NEG_INFINITY], hi: vec![3.0] };
        let s = run(&mut Analytic { f, c }, &b, &[0.5, 0.5, 0.5]);
        assert_eq!(s.outcome, Outcome::Optimal);
        assert!((s.point.f - 1.0 / 9.0).abs() < 1e-9, "{}", s.point.f);
        for (x, r) in s.v.iter().zip([4.0 / 3.0, 7.0 / 9.0, 4.0 / 9.0]) {
            assert!((x - r).abs() < 1e-7, "{:?}", s.v);
        }
    }

    #[test]
    fn limits_no_point_can_meet_end_infeasible_at_the_least_violation() {
        // x1 + x2 ≥ 3 with both in [0, 1]: the least violation is at (1, 1).
        let f = |x: &[f64]| (x[0] * x[0] + x[1] * x[1], vec![2.0 * x[0], 2.0 * x[1]]);
        let c = |x: &[f64]| vec![(x[0] + x[1] * x[1], vec![1.0, 2.0 * x[1]])];
        let b = Bounds { lb: vec![0.0; 2], ub: vec![1.0; 2], lo: vec![3.0], hi: vec![f64::INFINITY] };
        let s = run(&mut Analytic { f, c }, &b, &[0.2, 0.3]);
        assert_eq!(s.outcome, Outcome::Infeasible);
        assert!((s.v[0] - 1.0).abs() < 1e-9 && (s.v[1] - 1.0).abs() < 1e-9, "{:?}", s.v);
    }

    #[test]
    fn an_unconstrained_valley_is_followed_to_its_minimum() {
        // Rosenbrock from (−1.2, 1): minimum 0 at (1, 1).
        let f = |x: &[f64]| {
            let (a, b) = (1.0 - x[0], x[1] - x[0] * x[0]);
            (a * a + 100.0 * b * b, vec![-2.0 * a - 400.0 * x[0] * b, 200.0 * b])
        };
        let c = |_: &[f64]| Vec::new();
        let inf = f64::INFINITY;
        let b = Bounds { lb: vec![-inf; 2], ub: vec![inf; 2], lo: vec![], hi: vec![] };
        let s = run(&mut Analytic { f, c }, &b, &[-1.2, 1.0]);
        assert_eq!(s.outcome, Outcome::Optimal);
        assert!((s.v[0] - 1.0).abs() < 1e-7 && (s.v[1] - 1.0).abs() < 1e-7, "{:?} after {}", s.v, s.iterations);
    }
}
