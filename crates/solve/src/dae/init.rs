//! Consistent initialization of an index-1 DAE: with the differential variables fixed, solve the
//! algebraic equations `0 = f_a(t, x_d, x_a)` for the algebraic variables `x_a` by the
//! steady-state Newton solver (line search, bounds) on that subsystem.

use super::{DaeError, DaeSystem, Equation, Inconsistent};
use crate::{NewtonSettings, NewtonStatus, System, solve_steady};

/// The algebraic subsystem of a DAE at fixed time and differential variables.
struct Algebraic<'a> {
    sys: &'a dyn DaeSystem,
    t: f64,
    base: Vec<f64>,
    /// Algebraic equations (global rows) and variables (global columns).
    rows: Vec<usize>,
    cols: Vec<usize>,
    /// Global index → local index, `usize::MAX` if not in the subsystem.
    row_map: Vec<usize>,
    col_map: Vec<usize>,
}

impl Algebraic<'_> {
    fn full(&self, xa: &[f64]) -> Vec<f64> {
        let mut x = self.base.clone();
        for (k, &j) in self.cols.iter().enumerate() {
            x[j] = xa[k];
        }
        x
    }
}

impl System for Algebraic<'_> {
    fn n(&self) -> usize {
        self.cols.len()
    }
    fn residual(&self, xa: &[f64], r: &mut [f64]) {
        let mut full = vec![0.0; self.sys.n()];
        self.sys.residual(self.t, &self.full(xa), &mut full);
        for (k, &i) in self.rows.iter().enumerate() {
            r[k] = full[i];
        }
    }
    fn jacobian(&self, xa: &[f64], r: &mut [f64], jac: &mut Vec<(usize, usize, f64)>) {
        let mut full = vec![0.0; self.sys.n()];
        let mut all = Vec::new();
        self.sys.jacobian(self.t, &self.full(xa), &mut full, &mut all);
        for (k, &i) in self.rows.iter().enumerate() {
            r[k] = full[i];
        }
        jac.clear();
        jac.extend(all.into_iter().filter_map(|(i, j, v)| {
            let (a, b) = (self.row_map[i], self.col_map[j]);
            (a != usize::MAX && b != usize::MAX).then_some((a, b, v))
        }));
    }
    fn nominal(&self, k: usize) -> f64 {
        self.sys.nominal(self.cols[k])
    }
    fn bounds(&self, k: usize) -> (f64, f64) {
        self.sys.bounds(self.cols[k])
    }
    fn mass(&self) -> Vec<(usize, usize)> {
        Vec::new()
    }
}

/// Largest scaled algebraic residual accepted when Newton stalls short of its own tolerance.
const STALL_TOLERANCE: f64 = 1e-7;

/// Solve the algebraic variables of `x` (in place) for consistency with its differential variables
/// at time `t`. Returns the numbers of residual and Jacobian evaluations it took.
pub fn consistent_algebraic(sys: &dyn DaeSystem, t: f64, x: &mut [f64]) -> Result<(usize, usize), DaeError> {
    let n = sys.n();
    let (mut diff_row, mut diff_col) = (vec![false; n], vec![false; n]);
    for &(i, j) in sys.mass() {
        diff_row[i] = true;
        diff_col[j] = true;
    }
    let rows: Vec<usize> = (0..n).filter(|&i| !diff_row[i]).collect();
    let cols: Vec<usize> = (0..n).filter(|&j| !diff_col[j]).collect();
    let mut row_map = vec![usize::MAX; n];
    let mut col_map = vec![usize::MAX; n];
    rows.iter().enumerate().for_each(|(k, &i)| row_map[i] = k);
    cols.iter().enumerate().for_each(|(k, &j)| col_map[j] = k);
    let alg = Algebraic { sys, t, base: x.to_vec(), rows, cols, row_map, col_map };
    if alg.cols.is_empty() {
        return Ok((0, 0));
    }
    let mut xa: Vec<f64> = alg.cols.iter().map(|&j| x[j]).collect();
    let settings = NewtonSettings { pseudo_transient: false, ..NewtonSettings::default() };
    let report = solve_steady(&alg, &mut xa, &settings);
    // Newton aims at 1e-10 (scaled); a stall at round-off above that (large, ill-conditioned
    // plants) is still consistent below the integrator's tolerances (rtol 1e-6 by default), and
    // the first corrector step solves every equation again.
    let stalled_at_roundoff = report.worst.is_some_and(|(_, r)| r <= STALL_TOLERANCE);
    if report.status != NewtonStatus::Converged && !stalled_at_roundoff {
        let (k, residual) = report.worst.unwrap_or((0, f64::NAN));
        let equation = Equation::of(sys, alg.rows.get(k).copied().unwrap_or(0));
        let pinned = pinned_on_bounds(&alg, x, &xa);
        return Err(DaeError::Initialization(Box::new(Inconsistent { time: t, residual, equation, pinned })));
    }
    for (k, &j) in alg.cols.iter().enumerate() {
        x[j] = xa[k];
    }
    Ok((report.n_residual_evals, report.n_jacobian_evals))
}

/// The algebraic variables a failed solve left on a bound they did not start on (a flow that
/// would reverse, a holdup that would go negative): where the solution the equations ask for lies
/// outside the bounds, as `` `path` at its lower bound 0 ``.
fn pinned_on_bounds(alg: &Algebraic<'_>, x0: &[f64], xa: &[f64]) -> Vec<String> {
    let mut pinned = Vec::new();
    for (k, &j) in alg.cols.iter().enumerate() {
        let (lo, hi) = alg.sys.bounds(j);
        let near = |v: f64, b: f64| (v - b).abs() <= 1e-9 * alg.sys.nominal(j).abs().max(b.abs());
        let side = if near(xa[k], lo) && !near(x0[j], lo) {
            ("lower", lo)
        } else if near(xa[k], hi) && !near(x0[j], hi) {
            ("upper", hi)
        } else {
            continue;
        };
        let name = alg.sys.variable_name(j).unwrap_or_else(|| format!("variable {j}"));
        pinned.push(format!("`{name}` at its {} bound {}", side.0, side.1));
    }
    pinned
}
