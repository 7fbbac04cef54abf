//! Newton finish of the cold-start profile, with a pseudo-transient fallback.
//!
//! The column alone is not a square steady-state problem: its drum and sump holdups integrate
//! `V − L − D` and `L − V − B`. Here the inputs `distillate` and `bottoms` become unknowns tied to
//! the holdups by proportional level laws, `D = D₀ + k_D (M_N − M_drum)` and
//! `B = B₀ + k_B (M_1 − M_sump)` (`k = (reflux + D₀)/M_drum` and `(reflux + B₀)/M_sump` [1/s],
//! `D₀, B₀` the profile's flows) — an index-1 system whose steady state is the column's at the
//! input reflux and reboiler duty. The drum and sump holdups, which no steady equation reads, are
//! reset to their nominal values at the end.
//!
//! 1. Newton on the steady equations from the bubble-point profile.
//! 2. If that fails (the profile is far from a solution, typically a composition front that the
//!    bubble-point method had not finished moving next to a product-purity cliff): implicit-Euler
//!    pseudo-transient continuation on the column's own dynamics — `(M/Δt − J) Δx = f` — from the
//!    profile. Each step iterates on its first Jacobian (chord method); Δt grows fourfold after a
//!    step that converges in at most three iterations, twofold after one that needs up to six,
//!    by 20 % after one that needs up to ten, and shrinks to 30 % after one that does not
//!    converge; once Δt exceeds 10⁶ s, Newton again ("converge dynamically", Luyben (ed.) 1992
//!    ch. 3).
//!
//! Linear algebra: dual-number Jacobian of the unit; the outlet streams, defined explicitly by the
//! stages, are eliminated; the rest is ordered stage by stage (`[B, stage 1, …, stage N, Qc, D]`
//! against `[B law, stage rows, Qc row, D law]`), a banded matrix solved by Gaussian elimination
//! with partial pivoting inside the band. Rows are scaled by `max_j |J_ij| nominal_j`; steps are
//! clipped to the variable bounds and halved until the scaled residual falls.

use super::{IN_BOTTOMS, IN_DISTILLATE, IN_REFLUX, RigorousColumn, UnitModel};
use crate::stream::F;
use crate::units::column::StageIdx;
use crate::{Coloring, Unit, UnitIo, VarKind};

/// Most Newton iterations on the steady equations.
const MAX_NEWTON: usize = 30;
/// Most Newton iterations from a previous guess.
const MAX_WARM_NEWTON: usize = 8;
/// Most chord iterations in one pseudo-time step (a step needing more is retried shorter).
const MAX_STEP_NEWTON: usize = 10;
/// Scaled residual at which a pseudo-time step is accepted.
const STEP_TOL: f64 = 1e-8;
/// Most pseudo-time steps.
const MAX_STEPS: usize = 200;
/// Most Newton iterations of the whole transient march (the hardest cold start of the tests, the
/// ethanol–water column next to its purity cliff, needs 786); a march that needs more is not
/// converging (a bottoms flow of 10⁹ kmol/h took 6000 per call).
const MAX_MARCH_NEWTON: usize = 2000;
/// Shortest implicit-Euler step [s] of the transient march before it gives up.
const MIN_STEP: f64 = 1e-4;
/// Scaled residual at which Newton stops.
const TOL: f64 = 1e-12;

/// The column's own system with D and B on level laws.
struct System<'a> {
    col: &'a RigorousColumn,
    io: &'a UnitIo<'a, f64>,
    n_own: usize,
    len: usize,
    d_at: usize,
    b_at: usize,
    m_drum: usize,
    m_sump: usize,
    d0: f64,
    b0: f64,
    k_d: f64,
    k_b: f64,
    /// Core unknowns (local indices) and rows (own residual index or an extra row), banded order.
    core_cols: Vec<usize>,
    core_rows: Vec<usize>,
    nominal: Vec<f64>,
    bounds: Vec<(f64, f64)>,
    differential: Vec<bool>,
    /// Column colouring of the column's Jacobian pattern, computed once.
    coloring: Option<Coloring>,
    /// Per core row: the core positions and local columns its Jacobian row can hold (a regular
    /// row; the level-law rows hold their two), from the unit's pattern.
    row_cols: Vec<Vec<(usize, usize)>>,
    /// The dense core matrix, allocated once for every Newton call of one polish: a fresh m²
    /// matrix per call (m ≈ 330 for 32 stages, 0.9 MB) comes from mmap and page faults, which
    /// made a failing cold start with a thousand pseudo-time steps several times slower.
    core: std::cell::RefCell<Vec<f64>>,
}

const SUMP_LAW: usize = usize::MAX - 1;
const DRUM_LAW: usize = usize::MAX;

impl<'a> System<'a> {
    fn new(col: &'a RigorousColumn, io: &'a UnitIo<'a, f64>, own: &[f64]) -> System<'a> {
        let lay = io.layout;
        let (n_own, len) = (lay.n_own(), lay.len());
        let slen = lay.stream.len();
        let internal0 = col.n_outlets() * slen;
        let (d_at, b_at) = (lay.inputs_offset() + IN_DISTILLATE, lay.inputs_offset() + IN_BOTTOMS);
        let ix = StageIdx { nc: col.nc() };
        let (m_sump, m_drum) = (internal0 + ix.m(), internal0 + col.stage(col.n_stages - 1) + ix.m());
        let reflux = io.input(IN_REFLUX);
        let (d0, b0) = (own[F], own[slen + F]);
        let mut specs: Vec<_> = (0..col.n_outlets()).flat_map(|_| lay.stream.var_specs(&col.comp_names, 1.0)).collect();
        specs.extend(UnitModel::internal_vars(col));
        let flow_nom = (reflux + d0 + b0).max(1e-3);
        let mut nominal = vec![1.0; len];
        let mut bounds = vec![(f64::NEG_INFINITY, f64::INFINITY); len];
        let mut differential = vec![false; len];
        for (c, s) in specs.iter().enumerate() {
            nominal[c] = s.nominal;
            bounds[c] = (s.lower, s.upper);
            differential[c] = s.kind == VarKind::Differential;
        }
        for at in [d_at, b_at] {
            nominal[at] = flow_nom;
            bounds[at] = (0.0, f64::INFINITY);
        }
        let core_cols: Vec<usize> = [b_at].into_iter().chain(internal0..n_own).chain([d_at]).collect();
        let core_rows: Vec<usize> = [SUMP_LAW].into_iter().chain(internal0..n_own).chain([DRUM_LAW]).collect();
        let pattern = UnitModel::pattern(col, lay);
        let row_cols = core_structure(
            &core_rows,
            &core_cols,
            pattern.as_deref(),
            len,
            internal0,
            [(b_at, m_sump), (d_at, m_drum)],
        );
        System {
            col,
            io,
            n_own,
            len,
            d_at,
            b_at,
            m_drum,
            m_sump,
            d0,
            b0,
            k_d: (reflux + d0).max(1e-3) / col.m_condenser,
            k_b: (reflux + b0).max(1e-3) / col.m_reboiler,
            core_cols,
            core_rows,
            nominal,
            bounds,
            differential,
            coloring: pattern.map(|p| Coloring::new(&p, n_own, len)),
            core: std::cell::RefCell::new(vec![0.0; row_cols.len() * row_cols.len()]),
            row_cols,
        }
    }
    /// The core matrix and right-hand side at the Jacobian `jac` and residuals `r` (implicit
    /// Euler of step `dt` on the differential rows), after clearing the region `dirty` (the band
    /// of the last solve) of `a`.
    fn fill_core(
        &self,
        a: &mut [f64],
        rhs: &mut [f64],
        dirty: (usize, usize),
        jac: &[f64],
        r: &[f64],
        dt: Option<f64>,
    ) {
        let (m, len, n_own) = (self.core_rows.len(), self.len, self.n_own);
        let internal0 = self.col.n_outlets() * self.io.layout.stream.len();
        let (below, above) = dirty;
        for i in 0..m {
            a[i * m + i.saturating_sub(below)..=i * m + (i + above + below).min(m - 1)].fill(0.0);
        }
        for (i, &row) in self.core_rows.iter().enumerate() {
            let extra = match row {
                SUMP_LAW => n_own,
                DRUM_LAW => n_own + 1,
                _ => {
                    for &(k, c) in &self.row_cols[i] {
                        a[i * m + k] = jac[row * len + c];
                    }
                    if let (Some(dt), true) = (dt, self.differential[row]) {
                        a[i * m + (row - internal0 + 1)] -= 1.0 / dt;
                    }
                    rhs[i] = -r[row];
                    continue;
                }
            };
            let gain = if row == SUMP_LAW { self.k_b } else { self.k_d };
            let (k_at, k_held) = (self.row_cols[i][0].0, self.row_cols[i][1].0);
            a[i * m + k_at] = 1.0;
            a[i * m + k_held] = -gain;
            rhs[i] = -r[extra];
        }
    }
    /// The band `(below, above)` of the core matrix at the Jacobian `jac`: its nonzero values,
    /// the implicit-Euler diagonal and the level laws. The declared pattern would give a full
    /// band (the distillate and bottoms, first and last core unknowns, are declared in every row).
    fn value_band(&self, jac: &[f64]) -> (usize, usize) {
        let (mut below, mut above) = (0, 0);
        for (i, (&row, entries)) in self.core_rows.iter().zip(&self.row_cols).enumerate() {
            let law = row == SUMP_LAW || row == DRUM_LAW;
            for &(k, c) in entries {
                if law || jac[row * self.len + c] != 0.0 {
                    below = below.max(i.saturating_sub(k));
                    above = above.max(k.saturating_sub(i));
                }
            }
        }
        (below, above)
    }
    fn io<'b>(&'b self, local: &'b [f64]) -> UnitIo<'b, f64> {
        UnitIo { local, layout: self.io.layout, thermo: self.io.thermo, time: 0.0 }
    }
    /// Own residuals, then the sump and drum level laws.
    fn residual(&self, local: &[f64], r: &mut [f64]) {
        self.col.residual(&self.io(local), &mut r[..self.n_own]);
        r[self.n_own] = local[self.b_at] - self.b0 - self.k_b * (local[self.m_sump] - self.col.m_reboiler);
        r[self.n_own + 1] = local[self.d_at] - self.d0 - self.k_d * (local[self.m_drum] - self.col.m_condenser);
    }
    /// Solve for the steady state (`dt = None`, full Newton to [`TOL`]) or one implicit-Euler step of
    /// length `dt` from `old` (chord iterations on the step's first Jacobian, to [`STEP_TOL`]),
    /// starting at `local`; the number of iterations on success.
    fn newton(&self, local: &mut [f64], dt: Option<f64>, old: &[f64], max_iter: usize) -> Option<usize> {
        let tol = if dt.is_some() { STEP_TOL } else { TOL };
        let (n_own, len, m) = (self.n_own, self.len, self.core_cols.len());
        let internal0 = self.col.n_outlets() * self.io.layout.stream.len();
        let (mut r, mut trial) = (vec![0.0; n_own + 2], vec![0.0; n_own + 2]);
        let mut jac = vec![0.0; n_own * len];
        let mut w = vec![1.0; n_own + 2];
        // Implicit Euler: differential rows become f − (x − old)/Δt.
        let stepped = |local: &[f64], r: &mut [f64]| {
            self.residual(local, r);
            if let Some(dt) = dt {
                for c in (0..n_own).filter(|&c| self.differential[c]) {
                    r[c] -= (local[c] - old[c]) / dt;
                }
            }
        };
        let merit = |r: &[f64], w: &[f64]| r.iter().zip(w).map(|(a, b)| (a * b).powi(2)).sum::<f64>();
        let mut a = self.core.borrow_mut();
        let mut rhs = vec![0.0; m];
        // The band of the held Jacobian's nonzero values, and the region the last solve may have
        // written (elimination with row exchanges reaches `above + below` right of the diagonal).
        let (mut band, mut dirty) = ((0, 0), (m, m));
        for it in 0..max_iter {
            if it == 0 || dt.is_none() {
                jac.iter_mut().for_each(|v| *v = 0.0);
                self.col.jacobian_colored(&self.io(local), &mut r[..n_own], &mut jac, self.coloring.as_ref());
                for (i, wi) in w.iter_mut().enumerate().take(n_own) {
                    let s = (0..len).map(|c| (jac[i * len + c] * self.nominal[c]).abs()).fold(0.0, f64::max);
                    *wi = if s > 0.0 && s.is_finite() { 1.0 / s } else { 1.0 };
                }
                w[n_own] = 1.0 / self.nominal[self.b_at];
                w[n_own + 1] = 1.0 / self.nominal[self.d_at];
                band = self.value_band(&jac);
            }
            stepped(local, &mut r);
            let norm = r.iter().zip(&w).map(|(a, b)| (a * b).abs()).fold(0.0, f64::max);
            if !norm.is_finite() {
                return None;
            }
            if norm <= tol {
                return Some(it);
            }
            self.fill_core(&mut a, &mut rhs, dirty, &jac, &r, dt);
            dirty = band;
            if !banded_solve(&mut a, &mut rhs, m, band) {
                return None;
            }
            // Outlet streams: unit coefficient on their own variable, none on another outlet's.
            let mut dx = vec![0.0; len];
            for (k, &c) in self.core_cols.iter().enumerate() {
                dx[c] = rhs[k];
            }
            for row in 0..internal0 {
                let coupled: f64 = self.core_cols.iter().enumerate().map(|(k, &c)| jac[row * len + c] * rhs[k]).sum();
                dx[row] = -r[row] - coupled;
            }
            let f0 = merit(&r, &w);
            let base = local.to_vec();
            let mut lam = 1.0;
            loop {
                for c in (0..n_own).chain([self.d_at, self.b_at]) {
                    let (lo, hi) = self.bounds[c];
                    local[c] = (base[c] + lam * dx[c]).clamp(lo, hi);
                }
                stepped(local, &mut trial);
                let f = merit(&trial, &w);
                if f.is_finite() && f < (1.0 - 1e-4 * lam) * f0 {
                    break;
                }
                lam *= 0.5;
                if lam < 1e-10 {
                    return None;
                }
            }
        }
        None
    }
}

/// Move `own` (a profile of the column at the inputs and inlets of `io`, its D and B in the
/// product streams) to the column's steady state at the input reflux and reboiler duty: Newton,
/// then (if `transient`) the pseudo-transient continuation. False, and `own` as it was, if neither
/// gets there.
pub(super) fn polish(col: &RigorousColumn, io: &UnitIo<'_, f64>, own: &mut [f64], transient: bool) -> bool {
    let sys = System::new(col, io, own);
    let n_own = sys.n_own;
    let mut local = io.local.to_vec();
    local[..n_own].copy_from_slice(own);
    local[sys.d_at] = sys.d0;
    local[sys.b_at] = sys.b0;
    let start = local.clone();
    let max_newton = if transient { MAX_NEWTON } else { MAX_WARM_NEWTON };
    let mut solved = sys.newton(&mut local, None, &[], max_newton).is_some();
    if !solved && transient {
        local.copy_from_slice(&start);
        let mut dt = 10.0;
        let mut spent = 0;
        for _ in 0..MAX_STEPS {
            if spent > MAX_MARCH_NEWTON {
                break;
            }
            let old = local.clone();
            let step = sys.newton(&mut local, Some(dt), &old, MAX_STEP_NEWTON);
            spent += step.map_or(MAX_STEP_NEWTON, |it| it + 1);
            match step {
                Some(iters) => {
                    dt *= match iters {
                        0..=3 => 4.0,
                        4..=6 => 2.0,
                        _ => 1.2,
                    };
                    if dt > 1e6 {
                        let before = local.clone();
                        spent += MAX_NEWTON;
                        if sys.newton(&mut local, None, &[], MAX_NEWTON).is_some() {
                            solved = true;
                            break;
                        }
                        local.copy_from_slice(&before);
                    }
                }
                None => {
                    local.copy_from_slice(&old);
                    dt *= 0.3;
                    // Eleven failed steps in a row from 10 s: the march cannot advance (an
                    // infeasible column: no boilup, a dry sump); stop rather than shrink forever.
                    if dt < MIN_STEP {
                        break;
                    }
                }
            }
        }
    }
    if !solved {
        return false;
    }
    // Back to the nominal drum and sump holdups (no steady equation reads them).
    let ix = StageIdx { nc: col.nc() };
    for (m_at, m_nom) in [(sys.m_drum, col.m_condenser), (sys.m_sump, col.m_reboiler)] {
        let scale = m_nom / local[m_at];
        for j in 0..col.nc() {
            local[m_at - ix.m() + ix.n(j)] *= scale;
        }
        local[m_at] = m_nom;
    }
    own.copy_from_slice(&local[..n_own]);
    true
}

/// The core matrix's structure (see [`System`]): for each core row, the `(core position, local
/// column)` pairs of its structural Jacobian entries (the pattern, or every core column for a
/// dense unit), and the level-law rows' `(position of the flow, position of the holdup)`.
fn core_structure(
    core_rows: &[usize],
    core_cols: &[usize],
    pattern: Option<&[(usize, usize)]>,
    len: usize,
    internal0: usize,
    laws: [(usize, usize); 2],
) -> Vec<Vec<(usize, usize)>> {
    let mut pos = vec![usize::MAX; len];
    core_cols.iter().enumerate().for_each(|(k, &c)| pos[c] = k);
    let mut by_row: Vec<Vec<usize>> = vec![Vec::new(); core_rows.len() + internal0];
    let n_rows = by_row.len();
    match pattern {
        Some(p) => p.iter().filter(|&&(r, _)| r < n_rows).for_each(|&(r, c)| by_row[r].push(c)),
        None => by_row.iter_mut().for_each(|v| v.extend(0..len)),
    }
    core_rows
        .iter()
        .map(|&row| match row {
            SUMP_LAW | DRUM_LAW => {
                let (at, held) = laws[usize::from(row == DRUM_LAW)];
                vec![(pos[at], at), (pos[held], held)]
            }
            _ => {
                let mut v: Vec<(usize, usize)> =
                    by_row[row].iter().filter(|&&c| pos[c] != usize::MAX).map(|&c| (pos[c], c)).collect();
                v.sort_unstable();
                v.dedup();
                v
            }
        })
        .collect()
}

/// Solve `A x = b` in place (`A` row-major `n × n`, nonzeros near the diagonal) by Gaussian
/// elimination with partial pivoting, each step confined to the band of the remaining matrix;
/// false if `A` is singular.
fn banded_solve(a: &mut [f64], b: &mut [f64], n: usize, (kl, ku): (usize, usize)) -> bool {
    for c in 0..n {
        let last_row = (c + kl).min(n - 1);
        let last_col = (c + ku + kl).min(n - 1);
        let p = (c..=last_row).max_by(|&i, &j| a[i * n + c].abs().total_cmp(&a[j * n + c].abs())).unwrap_or(c);
        if a[p * n + c] == 0.0 || !a[p * n + c].is_finite() {
            return false;
        }
        if p != c {
            for k in c..=last_col {
                a.swap(p * n + k, c * n + k);
            }
            b.swap(p, c);
        }
        let piv = a[c * n + c];
        for i in c + 1..=last_row {
            let f = a[i * n + c] / piv;
            if f != 0.0 {
                for k in c..=last_col {
                    a[i * n + k] -= f * a[c * n + k];
                }
                b[i] -= f * b[c];
            }
        }
    }
    for c in (0..n).rev() {
        let last_col = (c + ku + kl).min(n - 1);
        let s: f64 = (c + 1..=last_col).map(|k| a[c * n + k] * b[k]).sum();
        b[c] = (b[c] - s) / a[c * n + c];
    }
    true
}
