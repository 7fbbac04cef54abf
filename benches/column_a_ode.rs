//! Column A as the peers integrate it: the 82 component holdups `n[i][c]` [mol] as an ODE
//! `dn/dt = f(n)` with every other quantity eliminated in closed form (the model of
//! `tools/bench_bdf_scipy.py`, SI units), on plantwide's BDF with an exact hand-derived Jacobian.
//! Against the plant run of the same scenario it separates the integrator's cost from what the
//! plant DAE adds (348 algebraic variables iterated by Newton, the unit models' residuals).
//!
//! Equations (stage 0 = reboiler, 40 = condenser, feed on stage 20): `M_i = Σ_c n_ic`,
//! `x_i = n_i0 / M_i`, `y_i = α x_i / (1 + (α − 1) x_i)`; liquid `L_i = L0_i + (M_i − M0)/τ_L` on
//! the trays, the reflux from the condenser and `B = B0 + K_c (M_0 − M0)` from the reboiler;
//! vapour `V` below the condenser; `D = D0 + K_c (M_40 − M0)`;
//! `dn_ic/dt = L_{i+1} x_{i+1,c} + V_{i−1} y_{i−1,c} − L_i x_ic − V_i y_ic + F z_c [i = 20] − D x_40,c [i = 40]`.

use plantwide::solve::dae::DaeSystem;

const KMOL_MIN: f64 = 1000.0 / 60.0;
const N: usize = 41;
const FEED_STAGE: usize = 20;
const ALPHA: f64 = 1.5;
const M0: f64 = 500.0;
const TAU_L: f64 = 0.063 * 60.0;
const L_NOM: f64 = 2.70629 * KMOL_MIN;
const V_NOM: f64 = 3.20629 * KMOL_MIN;
const F_NOM: f64 = KMOL_MIN;
const KC: f64 = 10.0 / 60.0;

/// Column A's holdup ODE at feed flow `feed` [mol/s] (composition 0.5/0.5).
pub struct ColumnOde {
    pub feed: f64,
    mass: Vec<(usize, usize)>,
}

/// Per stage: `x`, `∂x/∂n_c`, `y`, `∂y/∂n_c`, `L`, `∂L/∂n_c` (the same for both components), `V`.
struct Stage {
    x: f64,
    dx: [f64; 2],
    y: f64,
    dy: [f64; 2],
    l: f64,
    dl: f64,
    v: f64,
}

impl ColumnOde {
    pub fn new(feed: f64) -> ColumnOde {
        ColumnOde { feed, mass: (0..2 * N).map(|i| (i, i)).collect() }
    }

    fn stage(&self, n: &[f64], i: usize) -> Stage {
        let (a, b) = (n[2 * i], n[2 * i + 1]);
        let m = a + b;
        let x = a / m;
        let dx = [b / (m * m), -a / (m * m)];
        let den = 1.0 + (ALPHA - 1.0) * x;
        let y = ALPHA * x / den;
        let dydx = ALPHA / (den * den);
        let (l, dl) = match i {
            0 => (0.5 * KMOL_MIN + KC * (m - M0), KC),
            _ if i == N - 1 => (L_NOM, 0.0),
            _ => (L_NOM + if i <= FEED_STAGE { F_NOM } else { 0.0 } + (m - M0) / TAU_L, 1.0 / TAU_L),
        };
        let v = if i == N - 1 { 0.0 } else { V_NOM };
        Stage { x, dx, y, dy: [dydx * dx[0], dydx * dx[1]], l, dl, v }
    }

    /// `D` and `∂D/∂n_{40,c}`.
    fn distillate(n: &[f64]) -> (f64, f64) {
        (0.5 * KMOL_MIN + KC * (n[2 * N - 2] + n[2 * N - 1] - M0), KC)
    }
}

/// Component `c` of a stage's liquid and vapour compositions and their derivatives.
fn comp(s: &Stage, c: usize) -> (f64, [f64; 2], f64, [f64; 2]) {
    if c == 0 { (s.x, s.dx, s.y, s.dy) } else { (1.0 - s.x, [-s.dx[0], -s.dx[1]], 1.0 - s.y, [-s.dy[0], -s.dy[1]]) }
}

impl DaeSystem for ColumnOde {
    fn n(&self) -> usize {
        2 * N
    }
    fn residual(&self, _t: f64, n: &[f64], r: &mut [f64]) {
        let st: Vec<Stage> = (0..N).map(|i| self.stage(n, i)).collect();
        let (d, _) = Self::distillate(n);
        for i in 0..N {
            for c in 0..2 {
                let (x, _, y, _) = comp(&st[i], c);
                let mut acc = -st[i].l * x - st[i].v * y;
                if i + 1 < N {
                    acc += st[i + 1].l * comp(&st[i + 1], c).0;
                }
                if i > 0 {
                    acc += st[i - 1].v * comp(&st[i - 1], c).2;
                }
                if i == FEED_STAGE {
                    acc += 0.5 * self.feed;
                }
                if i == N - 1 {
                    acc -= d * x;
                }
                r[2 * i + c] = acc;
            }
        }
    }
    fn jacobian(&self, t: f64, n: &[f64], r: &mut [f64], jac: &mut Vec<(usize, usize, f64)>) {
        self.residual(t, n, r);
        jac.clear();
        let st: Vec<Stage> = (0..N).map(|i| self.stage(n, i)).collect();
        let (d, dd) = Self::distillate(n);
        for i in 0..N {
            for c in 0..2 {
                let row = 2 * i + c;
                let (x, dx, _, dy) = comp(&st[i], c);
                for k in 0..2 {
                    let mut own = -st[i].dl * x - st[i].l * dx[k] - st[i].v * dy[k];
                    if i == N - 1 {
                        own -= dd * x + d * dx[k];
                    }
                    jac.push((row, 2 * i + k, own));
                    if i + 1 < N {
                        let (xu, dxu, _, _) = comp(&st[i + 1], c);
                        jac.push((row, 2 * (i + 1) + k, st[i + 1].l * dxu[k] + st[i + 1].dl * xu));
                    }
                    if i > 0 {
                        jac.push((row, 2 * (i - 1) + k, st[i - 1].v * comp(&st[i - 1], c).3[k]));
                    }
                }
            }
        }
    }
    fn mass(&self) -> &[(usize, usize)] {
        &self.mass
    }
    fn nominal(&self, _i: usize) -> f64 {
        M0
    }
    fn bounds(&self, _i: usize) -> (f64, f64) {
        (0.0, f64::INFINITY)
    }
    fn error_controlled(&self, _i: usize) -> bool {
        true
    }
}

/// The Jacobian against central differences of the residual (relative step 1e-6) at `n`.
pub fn check_jacobian(sys: &ColumnOde, n: &[f64]) -> f64 {
    let m = sys.n();
    let (mut r, mut jac) = (vec![0.0; m], Vec::new());
    sys.jacobian(0.0, n, &mut r, &mut jac);
    let mut dense = vec![0.0; m * m];
    jac.iter().for_each(|&(i, j, v)| dense[i * m + j] += v);
    let mut worst: f64 = 0.0;
    for j in 0..m {
        let h = 1e-6 * n[j].abs().max(1.0);
        let (mut p, mut q) = (n.to_vec(), n.to_vec());
        p[j] += h;
        q[j] -= h;
        let (mut rp, mut rq) = (vec![0.0; m], vec![0.0; m]);
        sys.residual(0.0, &p, &mut rp);
        sys.residual(0.0, &q, &mut rq);
        for i in 0..m {
            let fd = (rp[i] - rq[i]) / (2.0 * h);
            worst = worst.max((fd - dense[i * m + j]).abs() / (1.0 + fd.abs()));
        }
    }
    worst
}
