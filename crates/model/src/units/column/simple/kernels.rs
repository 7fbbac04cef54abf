//! The stage loops of the simple column's hot paths — the completion of its explicit variables
//! and the residuals of its kept equations, run at every Newton iteration of the dynamic
//! integrator — with the number of components `NC` a compile-time constant for two to four
//! components (`0`: read at run time). The per-component loops then unroll and the offsets
//! within a stage fold into constants; the operations and their order are the same for every
//! `NC`, so the values are bit for bit those of the general loop (tested).

use crate::UnitIo;
use crate::stream::{F, H, P, T, Z0};

use super::{IN_BOILUP, IN_BOTTOMS, IN_DISTILLATE, IN_REFLUX, SimpleColumn, StageIdx};

/// A stage's `M = Σ n`, `x = n/M` and `y = K x` in its variables `v` (returned: `M`), with
/// constant `alpha` as `y_j = α_j n_j / Σ α n` (`= α_j x_j / Σ α x`: `M` cancels) or from
/// `k_values(T, x, k)` (scratch `k`). On slices of the stage's blocks: this is the inner loop of
/// every completion. With constant α the two divisions (`1/M`, `1/Σ α n`) are independent, where
/// `1/Σ α x` waited on `x` and so on the first: on column A the chain of two divisions per stage
/// was a quarter of the completion's time.
#[inline(always)]
fn stage_composition(
    v: &mut [f64],
    nc: usize,
    alpha: Option<&[f64]>,
    k_values: impl Fn(f64, &[f64], &mut [f64]),
    k: &mut [f64],
) -> f64 {
    let ix = StageIdx { nc };
    let (n, rest) = v.split_at_mut(nc);
    let (x, rest) = rest.split_at_mut(nc);
    let (y, tail) = rest.split_at_mut(nc);
    let m = n.iter().fold(0.0, |a, b| a + b);
    // One division: `x = n·(1/M)` is within an ulp of `n/M`.
    let inv_m = 1.0 / m;
    x.iter_mut().zip(n.iter()).for_each(|(xj, nj)| *xj = nj * inv_m);
    match alpha {
        Some(a) => {
            let inv = n.iter().zip(a).fold(0.0, |d, (nj, aj)| d + nj * aj).recip();
            y.iter_mut().zip(n.iter().zip(a)).for_each(|(yj, (nj, aj))| *yj = inv * aj * nj);
        }
        None => {
            k_values(tail[0], x, k);
            y.iter_mut().zip(x.iter().zip(k.iter())).for_each(|(yj, (xj, kj))| *yj = kj * xj);
        }
    }
    v[ix.m()] = m;
    m
}

impl SimpleColumn {
    /// The liquid leaving tray `s` of holdup `m` with `v_below` rising into it (Francis-weir
    /// linearization with the vapour effect λ, none below the weir; module documentation of
    /// `simple.rs`).
    #[inline(always)]
    fn tray_liquid(&self, s: usize, m: f64, v_below: f64) -> f64 {
        let l = self.l0[s] + (m - self.m0[s]) / self.tau_l;
        let l = if self.lambda != 0.0 { l + (v_below - self.v0) * self.lambda } else { l };
        // `<`, not `max`: a NaN stays one.
        if l < 0.0 { 0.0 } else { l }
    }

    /// [`UnitModel::eval_kept`](crate::UnitModel::eval_kept) with `NC` components (`0`: as many
    /// as the column has).
    pub(super) fn eval_kept_nc<const NC: usize>(
        &self,
        io: &UnitIo<'_, f64>,
        own: &[f64],
        r: &mut [f64],
        skip: &[bool],
    ) {
        let nc = if NC == 0 { self.nc() } else { NC };
        let (n, ix, ps) = (self.n_stages, StageIdx { nc }, 3 * nc + 4);
        let internal0 = self.n_outlets() * io.layout.stream.len();
        let stages = &own[internal0..internal0 + n * ps];
        let d_in = io.input(IN_DISTILLATE);
        for (s, v) in stages.chunks_exact(ps).enumerate() {
            let o = internal0 + s * ps;
            let rows = &mut r[o..o + ps];
            if self.plain[s] {
                // A tray with no feed and no draw: the general loop's operations in its order (the
                // empty feed sum is its 0.0), without the scans for feeds and draws and the tests
                // for the neighbours, which a tray always has.
                let (dn, up) = (&stages[(s - 1) * ps..s * ps], &stages[(s + 1) * ps..(s + 2) * ps]);
                for j in 0..nc {
                    let acc = 0.0 - v[ix.l()] * v[ix.x(j)] - v[ix.v()] * v[ix.y(j)];
                    rows[ix.n(j)] = acc + up[ix.l()] * up[ix.x(j)] + dn[ix.v()] * dn[ix.y(j)];
                }
            } else {
                self.balances_general::<NC>(io, stages, s, d_in, rows);
            }
            if !skip.get(o + ix.t()).copied().unwrap_or(false) {
                rows[ix.t()] = io.thermo.bubble_residual(v[ix.t()], self.pressure, &v[ix.x(0)..ix.x(0) + nc]);
            }
        }
    }

    /// The component balances of stage `s` into its `rows`, any stage: feeds, draws, the
    /// distillate at the top, the neighbours it has (see [`SimpleColumn::eval_kept_nc`]).
    #[inline(always)]
    fn balances_general<const NC: usize>(
        &self,
        io: &UnitIo<'_, f64>,
        stages: &[f64],
        s: usize,
        d_in: f64,
        rows: &mut [f64],
    ) {
        let nc = if NC == 0 { self.nc() } else { NC };
        let (n, ix, ps) = (self.n_stages, StageIdx { nc }, 3 * nc + 4);
        let v = &stages[s * ps..(s + 1) * ps];
        let up = (s + 1 < n).then(|| &stages[(s + 1) * ps..(s + 2) * ps]);
        let dn = (s > 0).then(|| &stages[(s - 1) * ps..s * ps]);
        for j in 0..nc {
            let feed = self.feeds.iter().enumerate().filter(|(_, f)| f.stage == s).fold(0.0, |acc, (k, _)| {
                let inlet = io.inlet(k);
                acc + inlet.f() * inlet.z()[j]
            });
            let xj = v[ix.x(j)];
            let mut acc = feed - v[ix.l()] * xj - v[ix.v()] * v[ix.y(j)];
            if let Some(up) = up {
                acc += up[ix.l()] * up[ix.x(j)];
            }
            if let Some(dn) = dn {
                acc += dn[ix.v()] * dn[ix.y(j)];
            }
            if s + 1 == n {
                acc -= d_in * xj;
            }
            for (k, d) in self.draws.iter().enumerate() {
                if d.stage == s {
                    acc -= io.input(4 + k) * xj;
                }
            }
            rows[ix.n(j)] = acc;
        }
    }

    /// [`UnitModel::complete`](crate::UnitModel::complete) with `NC` components (`0`: as many as the column has).
    pub(super) fn complete_nc<const NC: usize>(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let nc = if NC == 0 { self.nc() } else { NC };
        let (n, ix, ps) = (self.n_stages, StageIdx { nc }, 3 * nc + 4);
        let (outs, stages) = own.split_at_mut(self.n_outlets() * io.layout.stream.len());
        let mut k_stack = [0.0; 8];
        let mut k_heap = Vec::new();
        let k: &mut [f64] = if nc <= k_stack.len() {
            &mut k_stack[..nc]
        } else {
            k_heap.resize(nc, 0.0);
            &mut k_heap
        };
        let alpha = io.thermo.constant_alpha();
        // One pass up the column: each stage's M, x, y, then its V (from the V below) and L.
        let mut v_below = 0.0;
        for (s, v) in stages[..n * ps].chunks_exact_mut(ps).enumerate() {
            let m = stage_composition(v, nc, alpha, |t, x, k| io.thermo.k_values(t, self.pressure, x, k), k);
            if self.plain[s] {
                // A tray with no feed: its vapour is the one from below (`+ Σ` over no feeds adds
                // −0.0, which leaves every value as it is) and its liquid the tray's hydraulics.
                v[ix.l()] = self.tray_liquid(s, m, v_below);
                v[ix.v()] = v_below;
                continue;
            }
            // The feed quality may read this stage's x and y, just computed.
            let fed: f64 =
                (0..self.feeds.len()).filter(|&f| self.feeds[f].stage == s).map(|f| self.feed_vapour(io, f, v)).sum();
            // A subcooled feed condenses at most the vapour there is (CMO's `V + (1 − q) F`
            // would turn negative once the boilup is lost).
            let floor = |v: f64| if v < 0.0 { 0.0 } else { v };
            v[ix.v()] = match s {
                0 => floor(io.input(IN_BOILUP) + fed),
                _ if s + 1 == n => 0.0,
                _ => floor(v_below + fed),
            };
            v[ix.l()] = match s {
                _ if s + 1 == n => io.input(IN_REFLUX),
                0 => io.input(IN_BOTTOMS),
                _ => self.tray_liquid(s, m, v_below),
            };
            v_below = v[ix.v()];
        }
        let slen = io.layout.stream.len();
        let stages: &[f64] = stages;
        // `move`: the closure holds copies of `nc`, `ix` and `ps`. Captured by reference, their
        // stack slots escaped into it, and the stage loop above reloaded `nc` from memory at
        // every stage (a call may write an escaped slot): its loops over the components ran
        // with a run-time count, not unrolled for the fixed `NC`.
        let mut outlet = move |k: usize, s: usize, flow: f64| {
            let v = &stages[self.stage(s)..self.stage(s) + ps];
            let x = &v[ix.x(0)..ix.x(0) + nc];
            let out = &mut outs[k * slen..(k + 1) * slen];
            out[F] = flow;
            out[T] = v[ix.t()];
            out[P] = self.pressure;
            out[H] = io.thermo.h_liq(v[ix.t()], x);
            out[Z0..Z0 + nc].copy_from_slice(x);
        };
        let bottoms = stages[self.stage(0) + ix.l()];
        outlet(0, n - 1, io.input(IN_DISTILLATE));
        outlet(1, 0, bottoms);
        for (k, d) in self.draws.iter().enumerate() {
            outlet(2 + k, d.stage, io.input(4 + k));
        }
    }
}
