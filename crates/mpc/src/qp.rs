//! The QDMC quadratic program in clarabel's standard form.
//!
//! Decision `z = [ΔU (M·nu); ε (n_ε)]`, problem
//!
//! ```text
//! minimize ½ zᵀ Pq z + qᵀ z,   Pq = blockdiag(AᵀQA + R, ρI),   q = [−AᵀQ(r − f); ρ·1]
//! subject to  b − Ãz ∈ R₊^m      (clarabel NonnegativeCone)
//! ```
//!
//! with the rows (only for finite bounds, so the structure is fixed at build time):
//!
//! | rows                      | `Ã` row                  | `b`                      |
//! |---------------------------|--------------------------|--------------------------|
//! | `u_prev + LΔU ≤ u_max`    | `+L` row                 | `u_max − u_prev`         |
//! | `u_prev + LΔU ≥ u_min`    | `−L` row                 | `u_prev − u_min`         |
//! | `±ΔU ≤ du_max`            | `±e`                     | `du_max`                 |
//! | `f + AΔU − ε ≤ y_max`     | `+A` row, `−1` at slack  | `y_max − f`              |
//! | `f + AΔU + ε ≥ y_min`     | `−A` row, `−1` at slack  | `f − y_min`              |
//! | `ε ≥ 0`                   | `−1` at slack            | `0`                      |
//!
//! `L` is the block lower-triangular matrix of `nu × nu` identities (cumulative sum of moves).
//! `Ã`, `Pq` and the cones are built once; per sample only `q` and `b` are rewritten in the
//! solver with `update_q` / `update_b` (clarabel's data-updating API, presolve disabled).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus,
};
use faer::Mat;

use crate::error::MpcError;
use crate::settings::Settings;

/// What a constraint row bounds; determines its `b` entry each sample.
#[derive(Debug, Clone, Copy)]
enum Row {
    /// Cumulative input `j` upper limit.
    UMax(usize),
    /// Cumulative input `j` lower limit.
    UMin(usize),
    /// Rate limit of input `j` (either sign).
    DuMax(usize),
    /// Output upper limit at prediction row `p = (step-1)·ny + i`.
    YMax(usize),
    /// Output lower limit at prediction row `p`.
    YMin(usize),
    /// Slack non-negativity.
    Slack,
}

/// Solution of one QP.
#[derive(Debug, Clone)]
pub(crate) struct QpSolution {
    /// Moves `ΔU` (length `M·nu`).
    pub du: Vec<f64>,
    /// Slacks `ε`.
    pub eps: Vec<f64>,
    /// Clarabel's final status.
    pub status: SolverStatus,
    /// Interior-point iterations.
    pub iterations: u32,
    /// Wall time of `solver.solve()` (s), measured with `Instant` (clarabel's own
    /// `solve_time` also counts the one-off setup, so it is not a per-sample figure).
    pub solve_time: f64,
}

/// The clarabel solver with fixed structure plus the bookkeeping to refresh `q` and `b`.
pub(crate) struct Qp {
    solver: DefaultSolver<f64>,
    rows: Vec<Row>,
    ny: usize,
    n_du: usize,
    n_eps: usize,
    q: Vec<f64>,
    b: Vec<f64>,
}

impl std::fmt::Debug for Qp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Qp")
            .field("n_du", &self.n_du)
            .field("n_eps", &self.n_eps)
            .field("rows", &self.rows.len())
            .finish()
    }
}

/// The clarabel settings of a QP built once and re-solved with its data updated in place (this
/// controller's, and the steady-state optimizer's subproblems): tight tolerances, so that an
/// inactive-constraint QP reproduces its closed form to ~1e-10; presolve off, which in-place data
/// updates require; explicit zeros kept, so the pattern stays the one built. A caller adds its own.
pub fn in_place_settings() -> DefaultSettingsBuilder<f64> {
    let mut b = DefaultSettingsBuilder::default();
    b.verbose(false)
        .max_iter(200)
        .tol_gap_abs(1e-12)
        .tol_gap_rel(1e-12)
        .tol_feas(1e-12)
        .presolve_enable(false)
        .input_sparse_dropzeros(false);
    b
}

fn solver_settings() -> Result<DefaultSettings<f64>, MpcError> {
    in_place_settings().build().map_err(|e| MpcError::Setup(e.to_string()))
}

impl Qp {
    /// Build the structure once from the dynamic matrix `a` (`P·ny × M·nu`), the Hessian
    /// `h = AᵀQA + R` and the limits. `q` and `b` start at zero and are set by [`Qp::solve`].
    pub fn new(a: &Mat<f64>, h: &Mat<f64>, s: &Settings, ny: usize, nu: usize) -> Result<Self, MpcError> {
        let m = s.control_horizon;
        let n_du = m * nu;
        // Slack index for each finite output-limit side.
        let mut n_eps = 0;
        let mut eps_max = vec![None; ny];
        let mut eps_min = vec![None; ny];
        for i in 0..ny {
            if s.y_max[i].is_finite() {
                eps_max[i] = Some(n_du + n_eps);
                n_eps += 1;
            }
            if s.y_min[i].is_finite() {
                eps_min[i] = Some(n_du + n_eps);
                n_eps += 1;
            }
        }
        let mut tri = Triplets::default();
        let mut rows = Vec::new();
        input_rows(s, m, nu, &mut tri, &mut rows);
        for p in 0..a.nrows() {
            let i = p % ny;
            for (slack, sign, kind) in [(eps_max[i], 1.0, Row::YMax(p)), (eps_min[i], -1.0, Row::YMin(p))] {
                if let Some(e) = slack {
                    let r = rows.len();
                    for c in 0..n_du {
                        if a[(p, c)] != 0.0 {
                            tri.push(r, c, sign * a[(p, c)]);
                        }
                    }
                    tri.push(r, e, -1.0);
                    rows.push(kind);
                }
            }
        }
        for e in n_du..n_du + n_eps {
            tri.push(rows.len(), e, -1.0);
            rows.push(Row::Slack);
        }
        let n = n_du + n_eps;
        let a_qp = tri.into_csc(rows.len(), n);
        let p_qp = hessian_csc(h, n_eps, s.soft_weight);
        let q = vec![0.0; n];
        let b = vec![0.0; rows.len()];
        let cones = [NonnegativeConeT(rows.len())];
        let solver = DefaultSolver::new(&p_qp, &q, &a_qp, &b, &cones, solver_settings()?)
            .map_err(|e| MpcError::Setup(e.to_string()))?;
        Ok(Qp { solver, rows, ny, n_du, n_eps, q, b })
    }

    /// Number of constraint rows (all finite bounds).
    pub fn n_rows(&self) -> usize {
        self.rows.len()
    }

    /// Solve for gradient `g = −AᵀQ(r − f)`, free response `f` and previous input `u_prev`.
    ///
    /// Only `q = [g; ρ·1]` and `b` are rewritten; the interior-point iterate is re-initialised
    /// by clarabel on every call (no warm start).
    pub fn solve(&mut self, g: &[f64], f: &[f64], u_prev: &[f64], s: &Settings) -> Result<QpSolution, MpcError> {
        let ny = self.ny;
        self.q[..self.n_du].copy_from_slice(g);
        self.q[self.n_du..].fill(s.soft_weight);
        for (bk, row) in self.b.iter_mut().zip(&self.rows) {
            *bk = match *row {
                Row::UMax(j) => s.u_max[j] - u_prev[j],
                Row::UMin(j) => u_prev[j] - s.u_min[j],
                Row::DuMax(j) => s.du_max[j],
                Row::YMax(p) => s.y_max[p % ny] - f[p],
                Row::YMin(p) => f[p] - s.y_min[p % ny],
                Row::Slack => 0.0,
            };
        }
        let upd = |e: clarabel::solver::DataUpdateError| MpcError::Setup(e.to_string());
        self.solver.update_q(&self.q).map_err(upd)?;
        self.solver.update_b(&self.b).map_err(upd)?;
        let t0 = std::time::Instant::now();
        self.solver.solve();
        let solve_time = t0.elapsed().as_secs_f64();
        let sol = &self.solver.solution;
        Ok(QpSolution {
            du: sol.x[..self.n_du].to_vec(),
            eps: sol.x[self.n_du..].to_vec(),
            status: sol.status,
            iterations: sol.iterations,
            solve_time,
        })
    }
}

/// Input-limit and rate-limit rows (finite bounds only).
fn input_rows(s: &Settings, m: usize, nu: usize, tri: &mut Triplets, rows: &mut Vec<Row>) {
    for l in 0..m {
        for j in 0..nu {
            for (finite, sign, kind) in
                [(s.u_max[j].is_finite(), 1.0, Row::UMax(j)), (s.u_min[j].is_finite(), -1.0, Row::UMin(j))]
            {
                if finite {
                    let r = rows.len();
                    for lp in 0..=l {
                        tri.push(r, lp * nu + j, sign);
                    }
                    rows.push(kind);
                }
            }
            if s.du_max[j].is_finite() {
                for sign in [1.0, -1.0] {
                    tri.push(rows.len(), l * nu + j, sign);
                    rows.push(Row::DuMax(j));
                }
            }
        }
    }
}

/// Upper triangle of `blockdiag(h, ρI)` in CSC form (diagonal always stored).
fn hessian_csc(h: &Mat<f64>, n_eps: usize, rho: f64) -> CscMatrix<f64> {
    let n_du = h.nrows();
    let mut tri = Triplets::default();
    for c in 0..n_du {
        for r in 0..=c {
            if r == c || h[(r, c)] != 0.0 {
                tri.push(r, c, h[(r, c)]);
            }
        }
    }
    for e in n_du..n_du + n_eps {
        tri.push(e, e, rho);
    }
    tri.into_csc(n_du + n_eps, n_du + n_eps)
}

/// Coordinate-format accumulator.
#[derive(Default)]
struct Triplets {
    i: Vec<usize>,
    j: Vec<usize>,
    v: Vec<f64>,
}

impl Triplets {
    fn push(&mut self, i: usize, j: usize, v: f64) {
        self.i.push(i);
        self.j.push(j);
        self.v.push(v);
    }

    fn into_csc(self, m: usize, n: usize) -> CscMatrix<f64> {
        CscMatrix::new_from_triplets(m, n, self.i, self.j, self.v)
    }
}
