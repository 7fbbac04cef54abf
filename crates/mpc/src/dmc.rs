//! The DMC / QDMC controller: prediction bookkeeping, disturbance feedback and the per-sample QP.

use clarabel::solver::SolverStatus;
use faer::linalg::solvers::{Llt, Solve};
use faer::{Mat, Side};
use serde::Serialize;

use crate::error::{MpcError, check_vec};
use crate::model::StepModel;
use crate::qp::Qp;
use crate::settings::Settings;

/// Result of one controller execution.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Move {
    /// Input to apply now (absolute units), `u(k) = u(k−1) + Δu(k)`.
    pub u: Vec<f64>,
    /// The move taken now, `Δu(k)` (first block of `ΔU`).
    pub du: Vec<f64>,
    /// Clarabel's `SolverStatus` as text (`"Solved"`, `"AlmostSolved"`, `"MaxIterations"`, ...).
    pub status: String,
    /// Interior-point iterations.
    pub iterations: u32,
    /// Wall time of clarabel's `solve()` for this sample (s, `Instant`-measured; clarabel's own
    /// `solve_time` includes the one-off setup and is therefore not used).
    pub solve_time: f64,
    /// Largest output-limit slack `max ε` (output units; 0 if no soft limits).
    pub slack: f64,
    /// Planned output trajectory `f + AΔU` over the horizon (`P·ny`, sample-major:
    /// entry `(l−1)·ny + i` is output `i` at `k + l`), including the disturbance estimate.
    pub predicted: Vec<f64>,
}

/// Dynamic matrix controller (QDMC when limits are present).
///
/// State: the open-loop prediction `ŷ(k+l | k−1)`, `l = 0..N_h−1` of the step-response model
/// driven by all past moves (absolute units, starting from the steady state `y0`, `u0`), and the
/// last applied input. Per sample the output-disturbance estimate `d = y_meas − ŷ(k|k−1)` is held
/// constant over the horizon (offset-free feedback).
pub struct Dmc {
    model: StepModel,
    settings: Settings,
    /// Dynamic matrix `A` (`P·ny × M·nu`), block `(l, m) = S_{l−m}` for `l ≥ m`.
    a: Mat<f64>,
    /// `AᵀQ` (`M·nu × P·ny`).
    atq: Mat<f64>,
    /// `H = AᵀQA + R`.
    h: Mat<f64>,
    /// Cholesky factor of `H` (None if `H` is not positive definite).
    llt: Option<Llt<f64>>,
    qp: Qp,
    /// Open-loop prediction, `n_h` samples of `ny`, entry `l·ny + i` = `ŷ_i(k+l | k−1)`.
    pred: Vec<f64>,
    n_h: usize,
    u_prev: Vec<f64>,
    d: Vec<f64>,
}

impl std::fmt::Debug for Dmc {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Dmc")
            .field("ny", &self.model.ny)
            .field("nu", &self.model.nu)
            .field("settings", &self.settings)
            .field("qp", &self.qp)
            .field("u_prev", &self.u_prev)
            .field("d", &self.d)
            .finish_non_exhaustive()
    }
}

impl Dmc {
    /// Build once: dynamic matrix `A` (`P·ny × M·nu`), Hessian `H = AᵀQA + R`, its Cholesky
    /// factor, and the clarabel problem (matrices and cones). `u0`, `y0`: the steady state the
    /// plant is at (absolute units); `u0` must satisfy the input limits.
    pub fn new(model: StepModel, settings: Settings, u0: &[f64], y0: &[f64]) -> Result<Dmc, MpcError> {
        model.validate()?;
        let (ny, nu) = (model.ny, model.nu);
        settings.validate(ny, nu)?;
        check_vec("u0", u0, nu)?;
        check_vec("y0", y0, ny)?;
        for (j, &u) in u0.iter().enumerate() {
            if u < settings.u_min[j] || u > settings.u_max[j] {
                return Err(MpcError::invalid("u0", format!("entry {j} outside [u_min, u_max]")));
            }
        }
        let a = dynamic_matrix(&model, settings.prediction_horizon, settings.control_horizon);
        let (atq, h) = hessian(&a, &settings, ny, nu);
        let llt = h.llt(Side::Lower).ok();
        let qp = Qp::new(&a, &h, &settings, ny, nu)?;
        let n_h = model.len().max(settings.prediction_horizon) + 1;
        let pred = (0..n_h).flat_map(|_| y0.iter().copied()).collect();
        Ok(Dmc { model, settings, a, atq, h, llt, qp, pred, n_h, u_prev: u0.to_vec(), d: vec![0.0; ny] })
    }

    /// One execution at sample `k`: measured outputs `y_meas` and setpoints (absolute units,
    /// length `ny`) → the input to apply now.
    ///
    /// `d = y_meas − ŷ(k|k−1)`; free response `f_l = ŷ(k+l|k−1) + d`, `l = 1..P`; `r_l = setpoint`;
    /// QP as in [`crate::qp`]; `Δu(k) = ΔU[0..nu]`; then the DMC shift
    /// `ŷ(k+1+l | k) = ŷ(k+1+l | k−1) + S_l Δu(k)`.
    /// If clarabel stops short of `Solved` (`AlmostSolved`, `MaxIterations`, `MaxTime`,
    /// `InsufficientProgress`) its iterate is used with the first move clipped to the hard limits,
    /// and the status is reported in [`Move::status`]; infeasible
    /// or numerical-error outcomes return [`MpcError::Solver`] and leave the state unchanged.
    pub fn step(&mut self, y_meas: &[f64], setpoint: &[f64]) -> Result<Move, MpcError> {
        let (d, f) = self.free_response(y_meas, setpoint)?;
        let g = self.gradient(&f, setpoint);
        let sol = self.qp.solve(&g, &f, &self.u_prev, &self.settings)?;
        let solved = match sol.status {
            SolverStatus::Solved => true,
            SolverStatus::AlmostSolved
            | SolverStatus::MaxIterations
            | SolverStatus::MaxTime
            | SolverStatus::InsufficientProgress => false,
            other => {
                return Err(MpcError::Solver { status: format!("{other:?}") });
            }
        };
        if sol.du.iter().chain(&sol.eps).any(|x| !x.is_finite()) {
            return Err(MpcError::Solver { status: format!("{:?}", sol.status) });
        }
        let nu = self.model.nu;
        let mut du = sol.du[..nu].to_vec();
        if !solved {
            self.clip_first_move(&mut du);
        }
        let u: Vec<f64> = self.u_prev.iter().zip(&du).map(|(a, b)| a + b).collect();
        let predicted = self.planned(&f, &sol.du);
        self.d = d;
        self.shift(&du);
        self.u_prev.clone_from(&u);
        Ok(Move {
            u,
            du,
            status: format!("{:?}", sol.status),
            iterations: sol.iterations,
            solve_time: sol.solve_time,
            slack: sol.eps.iter().fold(0.0, |m, &e| f64::max(m, e)),
            predicted,
        })
    }

    /// Minimizer of the same QP with every constraint dropped:
    /// `ΔU = H⁻¹ AᵀQ (r − f)` by the Cholesky factor of `H` (faer). Does not change the state.
    pub fn unconstrained_move(&self, y_meas: &[f64], setpoint: &[f64]) -> Result<Vec<f64>, MpcError> {
        let (_, f) = self.free_response(y_meas, setpoint)?;
        let llt = self.llt.as_ref().ok_or(MpcError::SingularHessian)?;
        let g = self.gradient(&f, setpoint);
        let rhs = Mat::from_fn(g.len(), 1, |i, _| -g[i]);
        let x = llt.solve(&rhs);
        Ok((0..g.len()).map(|i| x[(i, 0)]).collect())
    }

    /// Declare that the input actually applied since the last [`Dmc::step`] is `u` (e.g. clipped
    /// or overridden downstream). The prediction is corrected by `S_l (u − u_recorded)` and the
    /// next move is computed from `u`.
    pub fn set_applied(&mut self, u: &[f64]) -> Result<(), MpcError> {
        check_vec("u", u, self.model.nu)?;
        let delta: Vec<f64> = u.iter().zip(&self.u_prev).map(|(a, b)| a - b).collect();
        self.add_response(&delta);
        self.u_prev = u.to_vec();
        Ok(())
    }

    /// Output-disturbance estimate `d` of the last [`Dmc::step`].
    pub fn disturbance(&self) -> &[f64] {
        &self.d
    }

    /// Stored open-loop prediction `ŷ(k+l | k−1)`, `l = 0..N_h−1` (`N_h = max(N, P) + 1`),
    /// sample-major (`l·ny + i`), absolute units, without the disturbance estimate.
    pub fn prediction(&self) -> &[f64] {
        &self.pred
    }

    /// Last applied input.
    pub fn u_prev(&self) -> &[f64] {
        &self.u_prev
    }

    /// Dynamic matrix `A` (`P·ny × M·nu`).
    pub fn dynamic_matrix(&self) -> &Mat<f64> {
        &self.a
    }

    /// Hessian block `H = AᵀQA + R`.
    pub fn hessian(&self) -> &Mat<f64> {
        &self.h
    }

    /// Number of QP constraint rows (finite bounds only).
    pub fn n_constraints(&self) -> usize {
        self.qp.n_rows()
    }

    /// The model.
    pub fn model(&self) -> &StepModel {
        &self.model
    }

    /// The settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Validate the measurement and setpoint; return `d` and the free response `f` (`P·ny`).
    fn free_response(&self, y_meas: &[f64], setpoint: &[f64]) -> Result<(Vec<f64>, Vec<f64>), MpcError> {
        let ny = self.model.ny;
        check_vec("y_meas", y_meas, ny)?;
        check_vec("setpoint", setpoint, ny)?;
        let d: Vec<f64> = (0..ny).map(|i| y_meas[i] - self.pred[i]).collect();
        let p = self.settings.prediction_horizon;
        let f = (0..p * ny).map(|r| self.pred[ny + r] + d[r % ny]).collect();
        Ok((d, f))
    }

    /// `g = −AᵀQ(r − f)` with `r` the setpoint held over the horizon.
    fn gradient(&self, f: &[f64], setpoint: &[f64]) -> Vec<f64> {
        let ny = self.model.ny;
        (0..self.atq.nrows())
            .map(|c| -(0..f.len()).map(|r| self.atq[(c, r)] * (setpoint[r % ny] - f[r])).sum::<f64>())
            .collect()
    }

    /// `f + AΔU`.
    fn planned(&self, f: &[f64], du: &[f64]) -> Vec<f64> {
        (0..f.len()).map(|r| f[r] + (0..du.len()).map(|c| self.a[(r, c)] * du[c]).sum::<f64>()).collect()
    }

    /// Clip `Δu(k)` to the rate limits and `u_prev + Δu` to the absolute limits.
    fn clip_first_move(&self, du: &mut [f64]) {
        let s = &self.settings;
        for (j, dj) in du.iter_mut().enumerate() {
            let lo = (s.u_min[j] - self.u_prev[j]).max(-s.du_max[j]);
            let hi = (s.u_max[j] - self.u_prev[j]).min(s.du_max[j]);
            *dj = dj.clamp(lo.min(hi), hi);
        }
    }

    /// DMC shift: drop `ŷ(k|k−1)`, hold the settled tail, add `S_l Δu(k)`.
    fn shift(&mut self, du: &[f64]) {
        let ny = self.model.ny;
        // The last block keeps its old value: it is settled w.r.t. all moves up to k−1.
        self.pred.copy_within(ny.., 0);
        self.add_response(du);
    }

    /// `ŷ(k+1+l) += S_l δ` for `l = 0..N_h−1`.
    fn add_response(&mut self, delta: &[f64]) {
        let (ny, nu) = (self.model.ny, self.model.nu);
        for l in 0..self.n_h {
            let s = self.model.coefficient(l);
            for i in 0..ny {
                self.pred[l * ny + i] += (0..nu).map(|j| s[i * nu + j] * delta[j]).sum::<f64>();
            }
        }
    }
}

/// Dynamic matrix: block `(l, m)` (`ny × nu`, `l < P`, `m < M`) is `S_{l−m}` for `l ≥ m`, else 0.
fn dynamic_matrix(model: &StepModel, p: usize, m: usize) -> Mat<f64> {
    let (ny, nu) = (model.ny, model.nu);
    Mat::from_fn(p * ny, m * nu, |r, c| {
        let (l, i) = (r / ny, r % ny);
        let (mm, j) = (c / nu, c % nu);
        if l >= mm { model.coefficient(l - mm)[i * nu + j] } else { 0.0 }
    })
}

/// `AᵀQ` and `H = AᵀQA + R` with `Q = diag(output_weights)` per sample and
/// `R = diag(move_weights)` per move.
fn hessian(a: &Mat<f64>, s: &Settings, ny: usize, nu: usize) -> (Mat<f64>, Mat<f64>) {
    let atq = Mat::from_fn(a.ncols(), a.nrows(), |c, r| a[(r, c)] * s.output_weights[r % ny]);
    let mut h = &atq * a;
    for c in 0..a.ncols() {
        h[(c, c)] += s.move_weights[c % nu];
    }
    // Symmetrise exactly (the product is symmetric up to rounding).
    for c in 0..h.ncols() {
        for r in 0..c {
            let v = 0.5 * (h[(r, c)] + h[(c, r)]);
            h[(r, c)] = v;
            h[(c, r)] = v;
        }
    }
    (atq, h)
}
