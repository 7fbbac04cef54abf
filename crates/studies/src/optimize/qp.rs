//! The SQP's quadratic subproblem in clarabel's standard form: ℓ1-elastic constraints and a box
//! that is the intersection of the variables' bounds with the trust region (Fletcher's Sℓ1QP;
//! Nocedal & Wright, *Numerical Optimization*, 2nd ed., §18.5).
//!
//! Decision `x = [d (n); e (k)]`, one elastic slack `e` per finite constraint limit:
//!
//! ```text
//! minimize   gᵀd + ½ dᵀBd + ρ Σ e
//! subject to c_i + a_i d + e ≥ lo_i     (row  −a_i d − e ≤ c_i − lo_i)
//!            c_i + a_i d − e ≤ hi_i     (row   a_i d − e ≤ hi_i − c_i)
//!            e ≥ 0,  low ≤ d ≤ up       (low = max(lb − v, −Δ), up = min(ub − v, Δ))
//! ```
//!
//! Always feasible (`d = 0` with large enough slacks). The sparsity pattern depends only on `n`
//! and which limits are finite, so the solver is built once and every iteration rewrites `P`,
//! `q`, `A` and `b` in place (clarabel's data updating: the KKT system's symbolic factorization
//! is kept); presolve, equilibration and the dropping of structural zeros are off to allow it.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus};
use faer::Mat;
use plantwide_mpc::qp::in_place_settings;

use super::polish::{Held, polish};

/// Why a quadratic subproblem has no answer (clarabel's setup or status).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub(crate) struct QpFailure(pub String);

/// Multipliers below this (scaled) are an interior point's zeros.
const MULTIPLIER_FLOOR: f64 = 1e-11;

/// A finite limit of constraint `i`: `true` for the lower limit.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Side {
    constraint: usize,
    lower: bool,
}

/// The data of one subproblem (scaled).
pub(crate) struct QpData<'a> {
    /// Objective gradient `g` (n).
    pub g: &'a [f64],
    /// Hessian approximation `B` (n × n, symmetric).
    pub b: &'a Mat<f64>,
    /// Constraint values `c` (m).
    pub c: &'a [f64],
    /// Constraint Jacobian `A` (m × n).
    pub a: &'a Mat<f64>,
    /// Box on the step: `low ≤ d ≤ up`.
    pub low: &'a [f64],
    /// Upper end of the box.
    pub up: &'a [f64],
    /// Whether each end of the box is a bound of the variable (`(low, up)`), not the trust
    /// region's.
    pub at_bound: (&'a [bool], &'a [bool]),
    /// Penalty `ρ` of the slacks.
    pub rho: f64,
}

/// The subproblem's answer.
#[derive(Debug, Clone)]
pub(crate) struct QpStep {
    /// The step `d`.
    pub d: Vec<f64>,
    /// Signed constraint multipliers `y` (≥ 0 on a lower limit, ≤ 0 on an upper one): at the
    /// solution `g + Bd − Aᵀy − μ = 0`.
    pub y: Vec<f64>,
    /// Signed multipliers of the box (≥ 0 on its lower end).
    pub mu: Vec<f64>,
    /// The largest slack: how far the linearized constraints are from being met.
    pub slack: f64,
    /// Model decrease `m(0) − m(d)` of `m(d) = gᵀd + ½dᵀBd + ρ Σ viol(c + Ad)`.
    pub predicted: f64,
}

/// The solver with its fixed structure.
pub(crate) struct Qp {
    solver: DefaultSolver<f64>,
    n: usize,
    m: usize,
    sides: Vec<Side>,
    lo: Vec<f64>,
    hi: Vec<f64>,
}

impl std::fmt::Debug for Qp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Qp").field("n", &self.n).field("sides", &self.sides.len()).finish()
    }
}

/// Column-major dense pattern with every entry stored (zeros included).
fn dense_csc(rows: usize, cols: usize, entries: impl Fn(usize) -> Vec<(usize, f64)>) -> CscMatrix<f64> {
    let (mut colptr, mut rowval, mut nzval) = (vec![0], Vec::new(), Vec::new());
    for j in 0..cols {
        for (i, v) in entries(j) {
            rowval.push(i);
            nzval.push(v);
        }
        colptr.push(rowval.len());
    }
    CscMatrix::new(rows, cols, colptr, rowval, nzval)
}

impl Qp {
    /// The structure for `n` variables and constraints with limits `lo`, `hi` (scaled, ±∞ where
    /// absent).
    pub fn new(n: usize, lo: &[f64], hi: &[f64]) -> Result<Qp, QpFailure> {
        let m = lo.len();
        let mut sides = Vec::new();
        for i in 0..m {
            if lo[i].is_finite() {
                sides.push(Side { constraint: i, lower: true });
            }
            if hi[i].is_finite() {
                sides.push(Side { constraint: i, lower: false });
            }
        }
        let p = p_matrix(n, sides.len(), &Mat::identity(n, n));
        let a = a_matrix(n, &sides, &Mat::zeros(m, n));
        let rows = a.m;
        let settings = in_place_settings().equilibrate_enable(false).build().map_err(|e| QpFailure(e.to_string()))?;
        let q = vec![0.0; n + sides.len()];
        let b = vec![1.0; rows];
        let solver = DefaultSolver::new(&p, &q, &a, &b, &[NonnegativeConeT(rows)], settings)
            .map_err(|e| QpFailure(e.to_string()))?;
        Ok(Qp { solver, n, m, sides, lo: lo.to_vec(), hi: hi.to_vec() })
    }

    /// Solve one subproblem.
    pub fn solve(&mut self, data: &QpData<'_>) -> Result<QpStep, QpFailure> {
        let (n, k) = (self.n, self.sides.len());
        // The objective divided by w = max(1, ρ), so that q stays of order one: a large ρ
        // otherwise reads to the interior point as an unbounded problem. Multipliers scale back.
        let w = data.rho.max(1.0);
        let mut q: Vec<f64> = data.g.iter().map(|g| g / w).collect();
        q.extend(std::iter::repeat_n(data.rho / w, k));
        let mut b = Vec::with_capacity(2 * k + 2 * n);
        for s in &self.sides {
            let ci = data.c[s.constraint];
            b.push(if s.lower { ci - self.lo[s.constraint] } else { self.hi[s.constraint] - ci });
        }
        b.extend(std::iter::repeat_n(0.0, k));
        b.extend_from_slice(data.up);
        b.extend(data.low.iter().map(|l| -l));
        let upd = |e: clarabel::solver::DataUpdateError| QpFailure(e.to_string());
        let p = p_matrix(n, k, &Mat::from_fn(n, n, |i, j| data.b[(i, j)] / w));
        let a = a_matrix(n, &self.sides, data.a);
        self.solver.update_data(&p.nzval, &q, &a.nzval, &b).map_err(upd)?;
        self.solver.solve();
        let sol = &self.solver.solution;
        // A solve short of its tolerance still gives a usable step when it is finite: the trust
        // region judges every step on the plant's own merit function.
        let usable = match sol.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => true,
            SolverStatus::InsufficientProgress | SolverStatus::MaxIterations => {
                sol.x.iter().chain(&sol.z).chain(&sol.s).all(|v| v.is_finite())
            }
            _ => false,
        };
        if !usable {
            return Err(QpFailure(format!(
                "the quadratic subproblem ended {:?} after {} iterations",
                sol.status, sol.iterations
            )));
        }
        // An interior point leaves ~1e-13 on inactive rows: those are zeros.
        let z: Vec<f64> = sol.z.iter().map(|&z| if (w * z).abs() < MULTIPLIER_FLOOR { 0.0 } else { w * z }).collect();
        let mut d = sol.x[..n].to_vec();
        let mut y = vec![0.0; self.m];
        for (r, s) in self.sides.iter().enumerate() {
            y[s.constraint] += if s.lower { z[r] } else { -z[r] };
        }
        let mut mu: Vec<f64> = (0..n).map(|j| z[2 * k + n + j] - z[2 * k + j]).collect();
        let slack = sol.x[n..].iter().fold(0.0_f64, |m, &e| m.max(e));
        if slack <= 1e-10 {
            // Rows whose dual exceeds their primal slack are the interior point's active set.
            let active = |r: usize| sol.z[r] > sol.s[r];
            let mut held: Vec<Held> = self
                .sides
                .iter()
                .enumerate()
                .filter(|(r, _)| active(*r))
                .map(|(_, s)| Held::Limit(s.constraint, s.lower))
                .collect();
            // Only a bound is held: a trust-region end is no active set of the problem.
            let (low_bound, up_bound) = data.at_bound;
            held.extend((0..n).filter(|&j| up_bound[j] && active(2 * k + j)).map(|j| Held::Box(j, false)));
            let lower = |j: usize| low_bound[j] && active(2 * k + n + j) && !(up_bound[j] && active(2 * k + j));
            held.extend((0..n).filter(|&j| lower(j)).map(|j| Held::Box(j, true)));
            if let Some(p) = polish(data, (&self.lo, &self.hi), &held) {
                (d, y, mu) = p;
            }
        }
        let predicted = self.violation(data.c, None, data.a) * data.rho - model(data, &d, self);
        Ok(QpStep { d, y, mu, slack, predicted })
    }

    /// `Σ viol(c + A d)` (of `c` alone when `d` is `None`), scaled.
    pub fn violation(&self, c: &[f64], d: Option<&[f64]>, a: &Mat<f64>) -> f64 {
        (0..self.m)
            .map(|i| {
                let ci = c[i] + d.map_or(0.0, |d| (0..self.n).map(|j| a[(i, j)] * d[j]).sum());
                (self.lo[i] - ci).max(0.0) + (ci - self.hi[i]).max(0.0)
            })
            .sum()
    }
}

/// `m(d) = gᵀd + ½dᵀBd + ρ Σ viol(c + Ad)`.
fn model(data: &QpData<'_>, d: &[f64], qp: &Qp) -> f64 {
    let n = d.len();
    let mut quad = 0.0;
    for i in 0..n {
        for j in 0..n {
            quad += d[i] * data.b[(i, j)] * d[j];
        }
    }
    let lin: f64 = (0..n).map(|j| data.g[j] * d[j]).sum();
    lin + 0.5 * quad + data.rho * qp.violation(data.c, Some(d), data.a)
}

/// `P = blockdiag(B, 0)` over `n` steps and `k` slacks, upper triangle, every entry of `B`'s
/// stored.
fn p_matrix(n: usize, k: usize, b: &Mat<f64>) -> CscMatrix<f64> {
    dense_csc(n + k, n + k, |j| if j < n { (0..=j).map(|i| (i, b[(i, j)])).collect() } else { vec![] })
}

/// The constraint rows: one per side, the slacks' signs, then the box (upper ends, lower ends).
fn a_matrix(n: usize, sides: &[Side], a: &Mat<f64>) -> CscMatrix<f64> {
    let k = sides.len();
    dense_csc(2 * k + 2 * n, n + k, |j| {
        if j < n {
            let mut col: Vec<(usize, f64)> = sides
                .iter()
                .enumerate()
                .map(|(r, s)| (r, if s.lower { -a[(s.constraint, j)] } else { a[(s.constraint, j)] }))
                .collect();
            col.push((2 * k + j, 1.0));
            col.push((2 * k + n + j, -1.0));
            col
        } else {
            let s = j - n;
            vec![(s, -1.0), (k + s, -1.0)]
        }
    })
}
