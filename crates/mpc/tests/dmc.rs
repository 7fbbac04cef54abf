//! Behavioural tests of the DMC / QDMC controller. Expected values are computed independently in
//! the tests (hand-written closed forms, brute-force minimisation, convolution, plant simulation).

// Index loops mirror the summation formulas being checked.
#![allow(clippy::needless_range_loop)]

use plantwide_mpc::{Dmc, MpcError, Settings, StepModel};

const INF: f64 = f64::INFINITY;

/// Wood–Berry column (minutes): gains, time constants, dead times.
fn wb_data() -> [[[f64; 2]; 2]; 3] {
    [[[12.8, -18.9], [6.6, -19.4]], [[16.7, 21.0], [10.9, 14.4]], [[1.0, 3.0], [7.0, 3.0]]]
}

fn to_vecs(m: [[f64; 2]; 2]) -> Vec<Vec<f64>> {
    m.iter().map(|r| r.to_vec()).collect()
}

fn wood_berry(n: usize) -> StepModel {
    let [k, t, d] = wb_data();
    StepModel::from_first_order(1.0, &to_vecs(k), &to_vecs(t), &to_vecs(d), n).unwrap()
}

/// Wide (inactive) but finite limits on everything.
fn wide_settings(p: usize, m: usize) -> Settings {
    Settings {
        prediction_horizon: p,
        control_horizon: m,
        output_weights: vec![1.0, 1.0],
        move_weights: vec![0.5, 0.5],
        u_min: vec![-100.0, -100.0],
        u_max: vec![100.0, 100.0],
        du_max: vec![50.0, 50.0],
        y_min: vec![-1e3, -1e3],
        y_max: vec![1e3, 1e3],
        soft_weight: 1e3,
    }
}

/// Exact discrete (ZOH) simulation of a FOPTD matrix plant with integer dead times (ts = 1).
struct Plant {
    a: Vec<f64>,
    b: Vec<f64>,
    delay: Vec<usize>,
    x: Vec<f64>,
    hist: Vec<Vec<f64>>, // deviation inputs u(0), u(1), ...
    nu: usize,
    ny: usize,
    y0: Vec<f64>,
    u0: Vec<f64>,
    dist: Vec<f64>,
}

impl Plant {
    fn new(k: [[f64; 2]; 2], tau: [[f64; 2]; 2], d: [[f64; 2]; 2], y0: &[f64], u0: &[f64]) -> Self {
        let mut p = Plant {
            a: vec![],
            b: vec![],
            delay: vec![],
            x: vec![0.0; 4],
            hist: vec![],
            nu: 2,
            ny: 2,
            y0: y0.to_vec(),
            u0: u0.to_vec(),
            dist: vec![0.0; 2],
        };
        for i in 0..2 {
            for j in 0..2 {
                let a = (-1.0 / tau[i][j]).exp();
                p.a.push(a);
                p.b.push(k[i][j] * (1.0 - a));
                p.delay.push(d[i][j] as usize);
            }
        }
        p
    }

    fn y(&self) -> Vec<f64> {
        (0..self.ny)
            .map(|i| self.y0[i] + self.dist[i] + (0..self.nu).map(|j| self.x[i * self.nu + j]).sum::<f64>())
            .collect()
    }

    /// Apply absolute input u(k) and advance to k+1.
    fn advance(&mut self, u: &[f64]) {
        self.hist.push(u.iter().zip(&self.u0).map(|(a, b)| a - b).collect());
        let k = self.hist.len() - 1;
        for e in 0..self.ny * self.nu {
            let j = e % self.nu;
            let ud = if k >= self.delay[e] { self.hist[k - self.delay[e]][j] } else { 0.0 };
            self.x[e] = self.a[e] * self.x[e] + self.b[e] * ud;
        }
    }
}

/// SISO first-order step coefficients by hand: a_i = K (1 − e^{−i/τ}), i = 1..n (ts = 1, θ = 0).
fn siso_coeffs(k: f64, tau: f64, n: usize) -> Vec<f64> {
    (1..=n).map(|i| k * (1.0 - (-(i as f64) / tau).exp())).collect()
}

fn siso_model(k: f64, tau: f64, n: usize) -> StepModel {
    StepModel::new(1.0, 1, 1, siso_coeffs(k, tau, n).into_iter().map(|a| vec![a]).collect()).unwrap()
}

fn siso_settings(p: usize, q: f64, r: f64) -> Settings {
    Settings::unconstrained(p, 1, vec![q], vec![r])
}

/// Test 1a: SISO, M = 1: QP and closed form `ΔU = Σ a_i q (r − f_i) / (Σ q a_i² + R)`, two samples.
#[test]
fn siso_m1_matches_hand_closed_form() {
    let (k, tau, p, q, rw) = (2.0, 5.0, 10, 1.5, 0.3);
    let (y0, u0, r) = (1.0, 0.5, 2.0);
    let a = siso_coeffs(k, tau, 50);
    let mut s = siso_settings(p, q, rw);
    s.u_min = vec![-50.0];
    s.u_max = vec![50.0];
    s.du_max = vec![40.0];
    s.y_min = vec![-100.0];
    s.y_max = vec![100.0];
    s.soft_weight = 10.0;
    let mut dmc = Dmc::new(siso_model(k, tau, 50), s, &[u0], &[y0]).unwrap();
    let den: f64 = (0..p).map(|i| q * a[i] * a[i]).sum::<f64>() + rw;
    // Sample 0: at steady state, f_i = y0.
    let num: f64 = (0..p).map(|i| a[i] * q * (r - y0)).sum();
    let du1 = num / den;
    let unc = dmc.unconstrained_move(&[y0], &[r]).unwrap();
    assert!((unc[0] - du1).abs() < 1e-10, "{} vs {du1}", unc[0]);
    let mv = dmc.step(&[y0], &[r]).unwrap();
    assert_eq!(mv.status, "Solved");
    assert!((mv.du[0] - du1).abs() < 1e-8, "{} vs {du1}", mv.du[0]);
    assert!((mv.u[0] - (u0 + mv.du[0])).abs() < 1e-15);
    // Sample 1: measured = model + 0.1 disturbance; f_i = y0 + a_{i+1} Δu1 + 0.1.
    let dist = 0.1;
    let du1 = mv.du[0];
    let y1 = y0 + a[0] * du1 + dist;
    let num: f64 = (0..p).map(|i| a[i] * q * (r - (y0 + a[i + 1] * du1 + dist))).sum();
    let du2 = num / den;
    let unc = dmc.unconstrained_move(&[y1], &[r]).unwrap();
    assert!((unc[0] - du2).abs() < 1e-10, "{} vs {du2}", unc[0]);
    let mv = dmc.step(&[y1], &[r]).unwrap();
    assert!((mv.du[0] - du2).abs() < 1e-8, "{} vs {du2}", mv.du[0]);
    assert!((dmc.disturbance()[0] - dist).abs() < 1e-12);
}

/// Test 1b: Wood–Berry 2x2, P = 30, M = 5, all limits present but inactive: QP = closed form.
#[test]
fn wood_berry_inactive_constraints_match_unconstrained() {
    let (y0, u0) = ([96.0, 0.5], [1.95, 1.71]);
    let mut dmc = Dmc::new(wood_berry(120), wide_settings(30, 5), &u0, &y0).unwrap();
    assert_eq!(dmc.n_constraints(), 5 * 2 * 4 + 30 * 2 * 2 + 4);
    let [k, t, d] = wb_data();
    let mut plant = Plant::new(k, t, d, &y0, &u0);
    let sp = [97.0, 0.0];
    for _ in 0..15 {
        let y = plant.y();
        let unc = dmc.unconstrained_move(&y, &sp).unwrap();
        let mv = dmc.step(&y, &sp).unwrap();
        assert_eq!(mv.status, "Solved");
        for j in 0..2 {
            let tol = 1e-8 * (1.0 + unc[j].abs());
            assert!((mv.du[j] - unc[j]).abs() < tol, "input {j}: {} vs {}", mv.du[j], unc[j]);
        }
        assert!(mv.slack < 1e-8);
        plant.advance(&mv.u);
    }
}

/// Brute-force golden-section minimisation of a convex 1-D function on [lo, hi].
fn golden(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..200 {
        let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if f(x1) < f(x2) { hi = x2 } else { lo = x1 }
    }
    0.5 * (lo + hi)
}

/// Test 2: active input bound; SISO M = 1 against brute force, plus KKT sign; 2x2 lands on u_max.
#[test]
fn active_input_bound() {
    let (k, tau, p, q, rw) = (2.0, 5.0, 10, 1.0, 0.1);
    let (y0, u0, r) = (0.0, 1.0, 10.0);
    let mut s = siso_settings(p, q, rw);
    s.u_min = vec![0.0];
    s.u_max = vec![1.3];
    let a = siso_coeffs(k, tau, 40);
    let mut dmc = Dmc::new(siso_model(k, tau, 40), s, &[u0], &[y0]).unwrap();
    let cost = |du: f64| 0.5 * (0..p).map(|i| q * (r - y0 - a[i] * du).powi(2)).sum::<f64>() + 0.5 * rw * du * du;
    let brute = golden(cost, 0.0 - u0, 1.3 - u0);
    let mv = dmc.step(&[y0], &[r]).unwrap();
    assert_eq!(mv.status, "Solved");
    assert!((mv.u[0] - 1.3).abs() < 1e-7, "u = {}", mv.u[0]);
    assert!((mv.du[0] - brute).abs() < 1e-6);
    // KKT at the upper bound: the gradient must point outward (dJ/dΔu < 0 ⇒ multiplier ≥ 0).
    let grad = (0..p).map(|i| -q * a[i] * (r - y0 - a[i] * mv.du[0])).sum::<f64>() + rw * mv.du[0];
    assert!(grad < 0.0, "gradient {grad}");

    // 2x2: a tight u_max on input 0 under a large setpoint change.
    let (y0, u0) = ([96.0, 0.5], [1.95, 1.71]);
    let mut s = wide_settings(30, 5);
    s.u_max[0] = u0[0] + 0.05;
    let mut dmc = Dmc::new(wood_berry(120), s, &u0, &y0).unwrap();
    let sp = [98.0, 0.5];
    let unc = dmc.unconstrained_move(&y0, &sp).unwrap();
    assert!(unc[0] > 0.05, "precondition: unconstrained move {} must exceed the bound", unc[0]);
    let mv = dmc.step(&y0, &sp).unwrap();
    assert_eq!(mv.status, "Solved");
    assert!((mv.u[0] - (u0[0] + 0.05)).abs() < 1e-7, "u0 = {}", mv.u[0]);
}

/// Test 3: rate limit active → |Δu| = du_max (both signs; SISO and 2x2).
#[test]
fn active_rate_limit() {
    for (r, sign) in [(10.0, 1.0), (-10.0, -1.0)] {
        let mut s = siso_settings(10, 1.0, 0.1);
        s.du_max = vec![0.2];
        let mut dmc = Dmc::new(siso_model(2.0, 5.0, 40), s, &[0.0], &[0.0]).unwrap();
        let mv = dmc.step(&[0.0], &[r]).unwrap();
        assert_eq!(mv.status, "Solved");
        assert!((mv.du[0] - sign * 0.2).abs() < 1e-7, "du = {}", mv.du[0]);
    }
    let (y0, u0) = ([96.0, 0.5], [1.95, 1.71]);
    let mut s = wide_settings(30, 5);
    s.du_max = vec![0.01, 0.01];
    let mut dmc = Dmc::new(wood_berry(120), s, &u0, &y0).unwrap();
    let sp = [98.0, -1.0];
    let unc = dmc.unconstrained_move(&y0, &sp).unwrap();
    assert!(unc.iter().all(|d| d.abs() > 0.01), "precondition {unc:?}");
    let mv = dmc.step(&y0, &sp).unwrap();
    for j in 0..2 {
        // (The sign need not follow the unconstrained move: the inputs interact.)
        assert!((mv.du[j].abs() - 0.01).abs() < 1e-7, "du[{j}] = {}", mv.du[j]);
    }
}

/// Test 4: a soft output limit that cannot be met as a hard one (dead time, output already above
/// the limit) → the QP is still solved and the slack equals the unavoidable violation.
#[test]
fn soft_output_limit_uses_slack() {
    // y = 2 e^{-2s}/(5s+1): the output cannot move for two samples.
    let model = StepModel::from_first_order(1.0, &[vec![2.0]], &[vec![5.0]], &[vec![2.0]], 40).unwrap();
    let mut s = siso_settings(15, 1.0, 0.1);
    s.control_horizon = 3;
    s.u_min = vec![-1.0];
    s.u_max = vec![1.0];
    s.y_max = vec![3.0];
    s.soft_weight = 100.0;
    let mut dmc = Dmc::new(model, s, &[0.0], &[0.0]).unwrap();
    // Model says 0, plant shows 5: d = 5 and f ≡ 5 > y_max for the first samples whatever we do.
    let mv = dmc.step(&[5.0], &[0.0]).unwrap();
    assert_eq!(mv.status, "Solved");
    assert!(mv.slack > 0.0);
    assert!((mv.slack - 2.0).abs() < 1e-6, "slack = {}", mv.slack);
    assert!(mv.u[0] >= -1.0 - 1e-9 && mv.u[0] <= 1.0 + 1e-9);
    // The planned trajectory respects y_max + ε everywhere.
    assert!(mv.predicted.iter().all(|y| *y <= 3.0 + mv.slack + 1e-6));
    // And the first predicted sample is exactly the unavoidable 5.
    assert!((mv.predicted[0] - 5.0).abs() < 1e-12);
}

/// Test 5: closed loop on a simulated Wood–Berry plant whose gains are 20 % above the model's:
/// setpoint change reached with zero offset, then a step output disturbance rejected.
#[test]
fn closed_loop_offset_free_with_gain_mismatch() {
    let (y0, u0) = ([96.0, 0.5], [1.95, 1.71]);
    let mut s = wide_settings(30, 5);
    s.u_min = vec![0.0, 0.0];
    s.u_max = vec![5.0, 5.0];
    s.du_max = vec![0.5, 0.5];
    s.y_min = vec![90.0, -5.0];
    s.y_max = vec![100.0, 5.0];
    let mut dmc = Dmc::new(wood_berry(120), s, &u0, &y0).unwrap();
    let [k, t, d] = wb_data();
    let kp = k.map(|r| r.map(|g| 1.2 * g));
    let mut plant = Plant::new(kp, t, d, &y0, &u0);
    let sp = [97.0, 0.0];
    let mut run = |plant: &mut Plant, n: usize| {
        let mut e = [0.0; 2];
        for _ in 0..n {
            let y = plant.y();
            e = [sp[0] - y[0], sp[1] - y[1]];
            let mv = dmc.step(&y, &sp).unwrap();
            assert!(mv.status == "Solved" || mv.status == "AlmostSolved", "{}", mv.status);
            plant.advance(&mv.u);
        }
        e
    };
    let e = run(&mut plant, 300);
    assert!(e.iter().all(|x| x.abs() < 1e-6), "offset after setpoint change {e:?}");
    plant.dist = vec![0.5, -0.3];
    let e_first = sp[0] - plant.y()[0];
    assert!(e_first.abs() > 0.4, "the disturbance must be visible first");
    let e = run(&mut plant, 300);
    assert!(e.iter().all(|x| x.abs() < 1e-6), "offset after output disturbance {e:?}");
}

/// Test 6: bad input is rejected with an error naming the field.
#[test]
fn bad_input_names_field() {
    let m = wood_berry(60);
    let (y0, u0) = ([0.0, 0.0], [0.0, 0.0]);
    let field = |s: Settings| Dmc::new(m.clone(), s, &u0, &y0).unwrap_err().field();
    let mut s = wide_settings(30, 5);
    s.prediction_horizon = 0;
    assert_eq!(field(s), Some("prediction_horizon"));
    let mut s = wide_settings(30, 5);
    s.control_horizon = 0;
    assert_eq!(field(s), Some("control_horizon"));
    assert_eq!(field(wide_settings(4, 5)), Some("control_horizon"));
    let mut s = wide_settings(30, 5);
    s.output_weights = vec![1.0];
    assert_eq!(field(s), Some("output_weights"));
    let mut s = wide_settings(30, 5);
    s.move_weights[1] = -0.1;
    assert_eq!(field(s), Some("move_weights"));
    let mut s = wide_settings(30, 5);
    s.output_weights[0] = f64::NAN;
    assert_eq!(field(s), Some("output_weights"));
    let mut s = wide_settings(30, 5);
    s.u_min[1] = 200.0;
    assert_eq!(field(s), Some("u_min"));
    let mut s = wide_settings(30, 5);
    s.u_max[0] = f64::NAN;
    assert_eq!(field(s), Some("u_max"));
    let mut s = wide_settings(30, 5);
    s.du_max = vec![0.1, 0.0];
    assert_eq!(field(s), Some("du_max"));
    let mut s = wide_settings(30, 5);
    s.y_min = vec![0.0, 0.0, 0.0];
    assert_eq!(field(s), Some("y_min"));
    let mut s = wide_settings(30, 5);
    s.soft_weight = -1.0;
    assert_eq!(field(s), Some("soft_weight"));
    let mut s = wide_settings(30, 5);
    s.soft_weight = 0.0;
    assert_eq!(field(s), Some("soft_weight"));
    let err = Dmc::new(m.clone(), wide_settings(30, 5), &[0.0], &y0).unwrap_err();
    assert!(matches!(err, MpcError::Dimension { field: "u0", expected: 2, got: 1 }));
    let err = Dmc::new(m.clone(), wide_settings(30, 5), &[500.0, 0.0], &y0).unwrap_err();
    assert_eq!(err.field(), Some("u0"));
    let mut dmc = Dmc::new(m, wide_settings(30, 5), &u0, &y0).unwrap();
    assert_eq!(dmc.step(&[0.0], &[0.0, 0.0]).unwrap_err().field(), Some("y_meas"));
    assert_eq!(dmc.step(&[0.0, 0.0], &[f64::NAN, 0.0]).unwrap_err().field(), Some("setpoint"));
    assert_eq!(dmc.unconstrained_move(&[0.0, INF], &[0.0, 0.0]).unwrap_err().field(), Some("y_meas"));
    assert_eq!(dmc.set_applied(&[0.0]).unwrap_err().field(), Some("u"));
    // Model validation.
    let e = StepModel::new(0.0, 1, 1, vec![vec![1.0]]).unwrap_err();
    assert_eq!(e.field(), Some("ts"));
    let e = StepModel::new(1.0, 1, 2, vec![vec![1.0]]).unwrap_err();
    assert_eq!(e.field(), Some("steps"));
    let e = StepModel::new(1.0, 1, 1, vec![vec![f64::NAN]]).unwrap_err();
    assert_eq!(e.field(), Some("steps"));
    let e = StepModel::from_first_order(1.0, &[vec![1.0]], &[vec![-1.0]], &[vec![0.0]], 10).unwrap_err();
    assert_eq!(e.field(), Some("taus"));
    let e = StepModel::from_first_order(1.0, &[vec![1.0]], &[vec![1.0]], &[vec![0.0, 1.0]], 10).unwrap_err();
    assert_eq!(e.field(), Some("delays"));
    let e = StepModel::from_first_order(1.0, &[vec![1.0]], &[vec![1.0]], &[vec![0.0]], 0).unwrap_err();
    assert_eq!(e.field(), Some("n"));
}

/// Independent convolution: y_i(t) = y0_i + Σ_{τ < t} Σ_j S_{t−τ−1}(i, j) Δu_j(τ), S held past N.
fn convolve(m: &StepModel, y0: &[f64], moves: &[Vec<f64>], t: usize) -> Vec<f64> {
    let n = m.steps.len();
    (0..m.ny)
        .map(|i| {
            let mut y = y0[i];
            for (tau, du) in moves.iter().enumerate().take(t) {
                let s = &m.steps[(t - tau - 1).min(n - 1)];
                for j in 0..m.nu {
                    y += s[i * m.nu + j] * du[j];
                }
            }
            y
        })
        .collect()
}

/// Test 7: with measurements generated by convolving the model with the moves taken, the stored
/// prediction equals that convolution over its whole length and the disturbance estimate is 0.
/// Also `set_applied` keeps the prediction consistent with the input actually applied.
#[test]
fn prediction_matches_convolution() {
    let model = wood_berry(40);
    let (y0, u0) = ([96.0, 0.5], [1.95, 1.71]);
    let mut dmc = Dmc::new(model.clone(), wide_settings(30, 5), &u0, &y0).unwrap();
    let mut moves: Vec<Vec<f64>> = Vec::new();
    let mut u = u0.to_vec();
    for k in 0..25 {
        let sp = [96.0 + (k as f64 * 0.7).sin(), 0.5 + 0.3 * (k as f64 * 0.3).cos()];
        let y = convolve(&model, &y0, &moves, k);
        let mv = dmc.step(&y, &sp).unwrap();
        assert!(dmc.disturbance().iter().all(|d| d.abs() < 1e-9), "k={k}: d = {:?}", dmc.disturbance());
        let mut applied = mv.u.clone();
        if k == 10 {
            applied[0] -= 0.02; // external override
            dmc.set_applied(&applied).unwrap();
        }
        moves.push(applied.iter().zip(&u).map(|(a, b)| a - b).collect());
        u = applied;
    }
    let k = moves.len();
    let pred = dmc.prediction();
    assert_eq!(pred.len() % 2, 0);
    for l in 0..pred.len() / 2 {
        let y = convolve(&model, &y0, &moves, k + l);
        for i in 0..2 {
            assert!((pred[l * 2 + i] - y[i]).abs() < 1e-9, "l={l} i={i}: {} vs {}", pred[l * 2 + i], y[i]);
        }
    }
}

/// `StepModel::gain` is the last coefficient and the FOPTD samples follow the formula.
#[test]
fn model_gain_and_samples() {
    let m = wood_berry(200);
    let g = m.gain();
    assert!((g[0][0] - 12.8).abs() < 1e-3 && (g[1][1] + 19.4).abs() < 1e-3);
    // G21 has 7 min dead time: zero through t = 7, then 6.6 (1 − e^{−1/10.9}) at t = 8.
    assert_eq!(m.steps[6][2], 0.0);
    assert!((m.steps[7][2] - 6.6 * (1.0 - (-1.0f64 / 10.9).exp())).abs() < 1e-12);
}
