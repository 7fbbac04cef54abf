//! QP solve time per sample over a 500-sample closed loop (std::time::Instant).
//!
//! (a) Wood–Berry 2x2, N = 120, P = 30, M = 5; (b) a column-A-sized 2x2 (LV gains of
//! Skogestad's column A, τ = 75 min, ts = 2 min), N = 200, P = 60, M = 10; both with input and
//! rate bounds and soft output limits; (c) the dense unconstrained solve for contrast.

use std::time::Instant;

use plantwide_mpc::{Dmc, Settings, StepModel};

type M2 = [[f64; 2]; 2];

/// Exact ZOH simulation of a 2x2 FOPTD plant with dead times that are multiples of `ts`.
struct Plant {
    a: [f64; 4],
    b: [f64; 4],
    delay: [usize; 4],
    x: [f64; 4],
    hist: Vec<[f64; 2]>,
    y0: [f64; 2],
    u0: [f64; 2],
    dist: [f64; 2],
}

impl Plant {
    fn new(ts: f64, k: M2, tau: M2, d: M2, y0: [f64; 2], u0: [f64; 2]) -> Self {
        let mut p =
            Plant { a: [0.0; 4], b: [0.0; 4], delay: [0; 4], x: [0.0; 4], hist: vec![], y0, u0, dist: [0.0; 2] };
        for e in 0..4 {
            let (i, j) = (e / 2, e % 2);
            p.a[e] = (-ts / tau[i][j]).exp();
            p.b[e] = k[i][j] * (1.0 - p.a[e]);
            p.delay[e] = (d[i][j] / ts).round() as usize;
        }
        p
    }
    fn y(&self) -> [f64; 2] {
        [0, 1].map(|i| self.y0[i] + self.dist[i] + self.x[2 * i] + self.x[2 * i + 1])
    }
    fn advance(&mut self, u: &[f64]) {
        self.hist.push([u[0] - self.u0[0], u[1] - self.u0[1]]);
        let k = self.hist.len() - 1;
        for e in 0..4 {
            let ud = if k >= self.delay[e] { self.hist[k - self.delay[e]][e % 2] } else { 0.0 };
            self.x[e] = self.a[e] * self.x[e] + self.b[e] * ud;
        }
    }
}

struct Case {
    name: &'static str,
    ts: f64,
    k: M2,
    tau: M2,
    d: M2,
    n: usize,
    settings: Settings,
    y0: [f64; 2],
    u0: [f64; 2],
    sp: [[f64; 2]; 2],
    dist: [f64; 2],
}

fn quantiles(mut v: Vec<f64>) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
    (at(0.5), at(0.9))
}

fn run(c: &Case, samples: usize) {
    let vecs = |m: M2| m.iter().map(|r| r.to_vec()).collect::<Vec<_>>();
    let model = StepModel::from_first_order(c.ts, &vecs(c.k), &vecs(c.tau), &vecs(c.d), c.n).unwrap();
    let mut dmc = Dmc::new(model, c.settings.clone(), &c.u0, &c.y0).unwrap();
    // Plant gains 20 % above the model's.
    let mut plant = Plant::new(c.ts, c.k.map(|r| r.map(|g| 1.2 * g)), c.tau, c.d, c.y0, c.u0);
    let (mut wall, mut clar, mut unc, mut iters, mut active) = (vec![], vec![], vec![], 0u64, 0);
    for k in 0..samples {
        let sp = if k < samples / 2 { c.sp[0] } else { c.sp[1] };
        if k == samples / 4 {
            plant.dist = c.dist;
        }
        let y = plant.y();
        let t0 = Instant::now();
        let du_unc = dmc.unconstrained_move(&y, &sp).unwrap();
        unc.push(t0.elapsed().as_secs_f64());
        let t0 = Instant::now();
        let mv = dmc.step(&y, &sp).unwrap();
        wall.push(t0.elapsed().as_secs_f64());
        clar.push(mv.solve_time);
        iters += u64::from(mv.iterations);
        if (0..2).any(|j| (mv.du[j] - du_unc[j]).abs() > 1e-6 * (1.0 + du_unc[j].abs())) || mv.slack > 1e-8 {
            active += 1;
        }
        plant.advance(&mv.u);
    }
    let us = |(a, b): (f64, f64)| (a * 1e6, b * 1e6);
    let (wm, w9) = us(quantiles(wall));
    let (cm, c9) = us(quantiles(clar));
    let (um, u9) = us(quantiles(unc));
    println!(
        "{}: {} QP rows, {samples} samples, {} with an active constraint, {:.1} IPM iterations/sample",
        c.name,
        dmc.n_constraints(),
        active,
        iters as f64 / samples as f64
    );
    println!("  QP step (wall, Instant):   median {wm:8.1} µs   p90 {w9:8.1} µs");
    println!("  QP clarabel solve() only: median {cm:8.1} µs   p90 {c9:8.1} µs");
    println!("  unconstrained dense solve: median {um:8.1} µs   p90 {u9:8.1} µs");
}

fn settings(
    p: usize,
    m: usize,
    q: [f64; 2],
    r: [f64; 2],
    u: ([f64; 2], [f64; 2]),
    du: f64,
    y: ([f64; 2], [f64; 2]),
) -> Settings {
    Settings {
        prediction_horizon: p,
        control_horizon: m,
        output_weights: q.to_vec(),
        move_weights: r.to_vec(),
        u_min: u.0.to_vec(),
        u_max: u.1.to_vec(),
        du_max: vec![du; 2],
        y_min: y.0.to_vec(),
        y_max: y.1.to_vec(),
        soft_weight: 1e3,
    }
}

fn main() {
    let wood_berry = Case {
        name: "(a) Wood-Berry 2x2, N=120, P=30, M=5",
        ts: 1.0,
        k: [[12.8, -18.9], [6.6, -19.4]],
        tau: [[16.7, 21.0], [10.9, 14.4]],
        d: [[1.0, 3.0], [7.0, 3.0]],
        n: 120,
        settings: settings(30, 5, [1.0, 1.0], [0.5, 0.5], ([1.5, 1.2], [2.2, 2.0]), 0.05, ([90.0, 0.0], [97.5, 2.0])),
        y0: [96.0, 0.5],
        u0: [1.95, 1.71],
        sp: [[97.0, 1.0], [95.0, 0.2]],
        dist: [0.5, -0.3],
    };
    let column_a = Case {
        name: "(b) column-A-sized 2x2, N=200, P=60, M=10",
        ts: 2.0,
        k: [[0.878, -0.864], [1.082, -1.096]],
        tau: [[75.0, 75.0], [75.0, 75.0]],
        d: [[2.0, 2.0], [2.0, 2.0]],
        n: 200,
        settings: settings(60, 10, [1.0, 1.0], [0.1, 0.1], ([-1.0, -1.0], [1.0, 1.0]), 0.2, ([-0.5, -0.5], [0.5, 0.5])),
        y0: [0.0, 0.0],
        u0: [0.0, 0.0],
        sp: [[0.05, 0.06], [-0.05, -0.04]],
        dist: [0.02, 0.015],
    };
    run(&wood_berry, 500);
    run(&column_a, 500);
}
