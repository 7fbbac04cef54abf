//! Self-optimizing control on a plant (issue 58, item 2): the optimum, the local model there
//! ([`super::local`]), the best measurement subsets by branch and bound (`plantwide_soc`), and each
//! listed subset verified on the nonlinear plant.
//!
//! Verification, for each disturbance moved by ± its magnitude (the others nominal): the
//! combination `c = H y` is held at its value at the nominal optimum and the active limits at
//! theirs (Newton on the degrees of freedom with exact gains, every point a certified steady
//! state): the objective there is `J_held`. The plant is re-optimized at that disturbance with
//! every limit (`J_opt`, which may rest on other limits than the nominal optimum). The loss is
//! `J_held − J_opt` (reversed for a maximum), reported beside the local estimate
//! `½‖Juu^½ (H Gy)⁻¹ H F Wd e_k‖²` of the exact local method.

use faer::Mat;
use faer::linalg::solvers::Solve;
use plantwide_analysis::continuation::{Steps, reach};
use plantwide_flowsheet::Plant;
use plantwide_flowsheet::optimization::{OptimizationSpec, Sense};
use plantwide_soc::{LocalModel, Parts, Ranking, Search, branch_and_bound};
use plantwide_solve::{NewtonSettings, steady_state};
use serde::Serialize;

use super::local::{
    Candidate, Dist, LocalRequest, Source, dependent_move, gains, jud, physical_directions, sensitivities,
};
use super::report::{active_set, optimum, violations};
use super::request::Problem;
use super::{OptimizeError, Optimum, State, solve_problem};

/// One verification point: a disturbance moved by `sign` × its magnitude.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LossPoint {
    /// The disturbance's path.
    pub disturbance: String,
    /// +1 or −1 (times its magnitude).
    pub sign: f64,
    /// The exact local method's loss (objective unit).
    pub local_loss: f64,
    /// The nonlinear loss `J_held − J_opt` (objective unit); None when a part failed.
    pub loss: Option<f64>,
    /// The objective with `H y` and the active limits held.
    pub held_objective: Option<f64>,
    /// The objective re-optimized at the disturbance.
    pub optimal_objective: Option<f64>,
    /// Limits the held point violates.
    pub violated: Vec<String>,
    /// Why a part failed, if one did.
    pub failure: Option<String>,
}

/// A listed subset and its verification.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SubsetCheck {
    /// The measurements.
    pub measurements: Vec<String>,
    /// One point per disturbance and sign.
    pub points: Vec<LossPoint>,
}

/// The answer of `select` on a plant.
#[derive(Debug, Clone)]
pub struct PlantSelection {
    /// The nominal optimum.
    pub optimum: Optimum,
    /// The local model there (display units).
    pub model: LocalModel,
    /// The best subsets.
    pub ranking: Ranking,
    /// Each listed subset on the nonlinear plant.
    pub verification: Vec<SubsetCheck>,
}

impl PlantSelection {
    /// The verification points without an answer, each with its subset, disturbance and reason.
    pub fn failed(&self) -> Vec<String> {
        self.verification
            .iter()
            .flat_map(|c| {
                c.points.iter().filter_map(move |p| {
                    let sign = if p.sign > 0.0 { "+" } else { "-" };
                    p.failure.as_ref().map(|f| format!("{} ({sign}{}): {f}", c.measurements.join(", "), p.disturbance))
                })
            })
            .collect()
    }
}

fn numerical(reason: String) -> OptimizeError {
    OptimizeError::NotConverged { reason, iterations: 0, kkt: f64::NAN }
}

/// Optimize `plant`, form the local model for `request`, search by `search` and verify the
/// subsets found.
///
/// # Errors
/// As [`super::optimize`]; [`OptimizeError::Field`] for the request's lists (`disturbances`,
/// `candidates`, `errors`) and the search (`size`, `best`).
pub fn select_on_plant(
    plant: &Plant,
    spec: &OptimizationSpec,
    start: &State,
    request: &LocalRequest,
    search: &Search,
) -> Result<PlantSelection, OptimizeError> {
    let problem = Problem::new(plant, spec)?;
    let dists = request.disturbances(plant, &problem)?;
    let cands = request.candidates(plant, &problem)?;
    let mut solved = solve_problem(plant, &problem, start)?;
    let opt = optimum(&mut solved.nlp, &problem, &solved.bounds, &solved.sol)?;
    let (act_c, act_b, dirs) = active_set(&solved.nlp, &problem, &solved.bounds, &solved.sol);
    if dirs.free.is_empty() {
        return Err(field(
            "vary",
            "the active limits fix every degree of freedom at the optimum: nothing is left for self-optimizing control",
        ));
    }
    let state = solved.sol.point.state.clone();
    let sens = sensitivities(plant, &problem, &state, (&dists, &cands), (&act_c, &act_b, &dirs))?;
    let n = problem.dofs.len();
    let dep = dependent_move(&sens, &dirs, n)?;
    let z = physical_directions(&solved.nlp, &dirs);
    let (gy, gyd) = gains(&problem, &sens, (&z, &dep, &dirs), (&dists, &cands));
    let jud = jud(&solved.nlp, &problem, &solved.sol, (&dep, &dirs), &dists)?;
    let juu = Mat::from_fn(dirs.free.len(), dirs.free.len(), |a, b| opt.reduced_hessian.matrix[a][b]);
    let parts =
        Parts {
            inputs: opt.reduced_hessian.free.clone(),
            disturbances: dists.iter().map(|d| format!("{}@{}", d.signal.path, d.signal.unit)).collect(),
            measurements: cands.iter().map(|c| format!("{}@{}", c.signal.path, c.signal.unit)).collect(),
            gy,
            gyd,
            juu,
            jud,
            wd: Mat::from_fn(dists.len(), dists.len(), |i, j| {
                if i == j { dists[i].magnitude / dists[i].signal.factor } else { 0.0 }
            }),
            wn: Mat::from_fn(cands.len(), cands.len(), |i, j| {
                if i == j { cands[i].error / cands[i].signal.factor } else { 0.0 }
            }),
        };
    let model = LocalModel::new(parts).map_err(|e| numerical(format!("the local model at the optimum: {e}")))?;
    let ranking = branch_and_bound(&model, search).map_err(|e| match e.is_user_error() {
        true => OptimizeError::Request(e.to_string()),
        false => numerical(e.to_string()),
    })?;
    let ctx = Context {
        plant,
        spec,
        problem: &problem,
        state: &state,
        dists: &dists,
        cands: &cands,
        act: (&act_c, &act_b),
        dirs: &dirs,
    };
    let verification = ranking.subsets.iter().map(|s| ctx.verify(&model, &s.measurements, &s.h, &opt)).collect();
    Ok(PlantSelection { optimum: opt, model, ranking, verification })
}

fn field(field: &str, message: &str) -> OptimizeError {
    OptimizeError::Field { field: field.to_string(), message: message.to_string() }
}

/// Why a verification point has no answer.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
struct PointFailure(String);

/// What the verification needs of the nominal optimum.
struct Context<'a> {
    plant: &'a Plant,
    spec: &'a OptimizationSpec,
    problem: &'a Problem,
    state: &'a State,
    dists: &'a [Dist],
    cands: &'a [Candidate],
    act: (&'a [usize], &'a [usize]),
    dirs: &'a super::certificate::Directions,
}

impl Context<'_> {
    /// The candidates' values (display units) at a state.
    fn measured(&self, s: &State) -> Vec<f64> {
        self.cands
            .iter()
            .map(|c| match c.source {
                Source::Variable(i) => s.x[i] / c.signal.factor,
                Source::Dof(j) => s.u[self.problem.dofs[j].signal.index] / c.signal.factor,
            })
            .collect()
    }

    /// The active rows' values (SI) at a state, in pivot order.
    fn held(&self, s: &State) -> Vec<f64> {
        let (act_c, act_b) = self.act;
        self.dirs
            .pivots
            .iter()
            .map(|&(row, _)| {
                if row < act_c.len() {
                    s.x[self.problem.constraints[act_c[row]].signal.index]
                } else {
                    s.u[self.problem.dofs[act_b[row - act_c.len()]].signal.index]
                }
            })
            .collect()
    }

    /// Every point of one subset.
    fn verify(&self, model: &LocalModel, subset: &[usize], h: &Mat<f64>, opt: &Optimum) -> SubsetCheck {
        let names = subset.iter().map(|&i| model.parts().measurements[i].clone()).collect();
        let mut points = Vec::new();
        for (k, d) in self.dists.iter().enumerate() {
            for sign in [1.0, -1.0] {
                let local_loss = local_loss(model, subset, h, k, sign);
                let mut p = LossPoint {
                    disturbance: d.signal.path.clone(),
                    sign,
                    local_loss,
                    loss: None,
                    held_objective: None,
                    optimal_objective: None,
                    violated: Vec::new(),
                    failure: None,
                };
                match self.point(subset, h, d, sign) {
                    Ok((held, best, violated)) => {
                        let cost = if opt.sense == Sense::Maximize { best - held } else { held - best };
                        (p.loss, p.held_objective, p.optimal_objective, p.violated) =
                            (Some(cost), Some(held), Some(best), violated);
                    }
                    Err(e) => p.failure = Some(e.to_string()),
                }
                points.push(p);
            }
        }
        SubsetCheck { measurements: names, points }
    }

    /// `(J_held, J_opt, violated)` at disturbance `d` moved by `sign` × its magnitude.
    fn point(
        &self,
        subset: &[usize],
        h: &Mat<f64>,
        d: &Dist,
        sign: f64,
    ) -> Result<(f64, f64, Vec<String>), PointFailure> {
        // Continuation along the disturbance ([`reach`]): steps of a quarter of it, halved (down
        // to 1/64) where one fails and doubled back after a success, each predicted by the
        // linearization (the held combination's and active rows' gains) and corrected by Newton.
        let advance = |s: &State, from: f64, to: f64| self.advance(subset, h, (d, sign), s, (from, to));
        let held = reach(self.state.clone(), (0.0, 1.0), Steps::halving(0.25, 4), advance).map_err(|stalled| {
            let at = self.state.u[d.signal.index] + sign * d.magnitude * stalled.reached;
            PointFailure(format!(
                "the combination is held only to {:.0} % of the disturbance ({} = {:.6} {}), not beyond: {}",
                100.0 * stalled.reached,
                d.signal.path,
                d.signal.display_value(at),
                d.signal.unit,
                stalled.error,
            ))
        })?;
        let obj = &self.problem.objective;
        let j_held = obj.display_value(held.x[obj.index]);
        let best =
            super::optimize(self.plant, self.spec, &held).map_err(|e| PointFailure(format!("re-optimized: {e}")))?;
        Ok((j_held, best.objective, violations(self.problem, &held)))
    }

    /// The held point with the disturbance moved from the fraction `from` of its move to `to`,
    /// starting at the held point `s` of `from`.
    fn advance(
        &self,
        subset: &[usize],
        h: &Mat<f64>,
        (d, sign): (&Dist, f64),
        s: &State,
        (from, to): (f64, f64),
    ) -> Result<State, PointFailure> {
        let delta = sign * d.magnitude * (to - from);
        let (jac, dcol) = self.newton_matrix(subset, h, s, Some(d))?;
        let predictor = jac.partial_piv_lu().solve(Mat::from_fn(jac.nrows(), 1, |i, _| -dcol[i] * delta));
        let mut start = s.clone();
        start.u[d.signal.index] = self.state.u[d.signal.index] + sign * d.magnitude * to;
        let predicted = self.damped(&start, &predictor)?;
        self.hold(subset, h, &predicted)
    }

    /// The plant after the Newton step `step` on the degrees of freedom, halved (up to 1/64)
    /// while the plant has no steady state there.
    fn damped(&self, s: &State, step: &Mat<f64>) -> Result<State, PointFailure> {
        let tight = NewtonSettings { tol: 1e-12, ..NewtonSettings::default() };
        let mut last = String::new();
        for halving in 0..7 {
            let alpha = 0.5_f64.powi(halving);
            let mut u = s.u.clone();
            for (j, dof) in self.problem.dofs.iter().enumerate() {
                u[dof.signal.index] += alpha * step[(j, 0)];
            }
            match steady_state(self.plant, &u, Some(&s.x), &tight)
                .or_else(|_| steady_state(self.plant, &u, Some(&s.x), &NewtonSettings::default()))
            {
                Ok(next) => return Ok(State { x: next.x, u: next.u }),
                Err(e) => last = brief(&e.to_string()),
            }
        }
        Err(PointFailure(format!("held: no steady state even at 1/64 of the Newton step: {last}")))
    }

    /// The Jacobian of `[H y; active rows]` with respect to the degrees of freedom (display units
    /// of the candidates, SI of the rest) at `s`, and its column for disturbance `d`.
    fn newton_matrix(
        &self,
        subset: &[usize],
        h: &Mat<f64>,
        s: &State,
        d: Option<&Dist>,
    ) -> Result<(Mat<f64>, Vec<f64>), PointFailure> {
        let dists: Vec<Dist> = d.into_iter().cloned().collect();
        let sens =
            sensitivities(self.plant, self.problem, s, (&dists, self.cands), (self.act.0, self.act.1, self.dirs))
                .map_err(|e| PointFailure(e.to_string()))?;
        let (n, nu) = (self.problem.dofs.len(), h.nrows());
        let entry = |row: usize, j: usize| {
            if row < nu {
                subset
                    .iter()
                    .enumerate()
                    .map(|(c, &m)| h[(row, c)] * sens.y[(m, j)] / self.cands[m].signal.factor)
                    .sum()
            } else {
                sens.act[(row - nu, j)]
            }
        };
        let jac = Mat::from_fn(n, n, entry);
        let dcol = if d.is_some() { (0..n).map(|row| entry(row, n)).collect() } else { Vec::new() };
        Ok((jac, dcol))
    }

    /// The residuals of holding: `H (y − y*)` and the active rows minus their values, each
    /// relative to its own size (`|H_i|·|y*|` for a combination, the limit for an active row:
    /// the steady states carry ~1e-12 of each).
    fn hold_residual(&self, subset: &[usize], h: &Mat<f64>, s: &State) -> (Vec<f64>, Vec<f64>) {
        let (target_y, target_a) = (self.measured(self.state), self.held(self.state));
        let (y, a) = (self.measured(s), self.held(s));
        let nu = h.nrows();
        let mut r: Vec<f64> =
            (0..nu).map(|i| subset.iter().enumerate().map(|(c, &m)| h[(i, c)] * (y[m] - target_y[m])).sum()).collect();
        r.extend(a.iter().zip(&target_a).map(|(x, t)| x - t));
        let combination = |i: usize| {
            subset.iter().enumerate().map(|(c, &m)| (h[(i, c)] * target_y[m]).abs()).sum::<f64>().max(1e-300)
        };
        let scale = (0..nu).map(combination).chain(target_a.iter().map(|t| t.abs().max(1e-12))).collect();
        (r, scale)
    }

    /// Newton on the degrees of freedom: `H (y − y*) = 0` and the active rows at their values,
    /// each step backtracked (down to 1/64) until the scaled residual falls.
    fn hold(&self, subset: &[usize], h: &Mat<f64>, from: &State) -> Result<State, PointFailure> {
        let n = self.problem.dofs.len();
        let size = |r: &[f64], scale: &[f64]| r.iter().zip(scale).fold(0.0_f64, |m, (v, sc)| m.max((v / sc).abs()));
        let mut s = from.clone();
        let (mut r, scale) = self.hold_residual(subset, h, &s);
        for _ in 0..30 {
            let now = size(&r, &scale);
            if now < 1e-10 {
                return Ok(s);
            }
            let (jac, _) = self.newton_matrix(subset, h, &s, None)?;
            let step = jac.partial_piv_lu().solve(Mat::from_fn(n, 1, |i, _| -r[i]));
            if (0..n).any(|i| !step[(i, 0)].is_finite()) {
                return Err(PointFailure(
                    "the held combination does not fix the degrees of freedom here (singular)".into(),
                ));
            }
            let (mut accepted, mut unsolved) = (None, None);
            for halving in 0..7 {
                let alpha = 0.5_f64.powi(halving);
                let next = match self.damped(&s, &Mat::from_fn(n, 1, |i, _| alpha * step[(i, 0)])) {
                    Ok(next) => next,
                    Err(e) => {
                        unsolved = Some(e);
                        continue;
                    }
                };
                let (r_next, _) = self.hold_residual(subset, h, &next);
                if size(&r_next, &scale) < (1.0 - 1e-4 * alpha) * now {
                    accepted = Some((next, r_next));
                    break;
                }
            }
            let Some((next, r_next)) = accepted else {
                let why = unsolved.map_or(String::new(), |e| format!("; a step's plant: {e}"));
                return Err(PointFailure(format!(
                    "no Newton step reduces the held combination's residual ({now:.2e}, scaled; its Jacobian's condition number {:.1e} there){why}",
                    condition(&jac)
                )));
            };
            (s, r) = (next, r_next);
        }
        Err(PointFailure("holding the combination did not converge in 30 Newton steps".into()))
    }
}

/// The 2-norm condition number of a small square matrix (∞ when singular).
fn condition(m: &Mat<f64>) -> f64 {
    match m.singular_values() {
        Ok(s) if s.last().is_some_and(|&least| least > 0.0) => s[0] / s[s.len() - 1],
        _ => f64::INFINITY,
    }
}

/// A solver's message without its iteration history.
fn brief(message: &str) -> String {
    message.split("; history").next().unwrap_or(message).to_string()
}

/// `½‖Juu^½ (H Gy)⁻¹ H F Wd e_k‖²` for the disturbance `k` moved by `sign`: `δu = −(H Gy)⁻¹ H F
/// Wd e_k`, loss `½ δuᵀ Juu δu`.
fn local_loss(model: &LocalModel, subset: &[usize], h: &Mat<f64>, k: usize, sign: f64) -> f64 {
    let p = model.parts();
    let nu = p.juu.nrows();
    // F = Gyd − Gy Juu⁻¹ Jud, column k.
    let juu_inv_jud = p.juu.partial_piv_lu().solve(&p.jud);
    let f = |m: usize| p.gyd[(m, k)] - (0..nu).map(|i| p.gy[(m, i)] * juu_inv_jud[(i, k)]).sum::<f64>();
    let hgy =
        Mat::from_fn(nu, nu, |i, j| subset.iter().enumerate().map(|(c, &m)| h[(i, c)] * p.gy[(m, j)]).sum::<f64>());
    let hf = Mat::from_fn(nu, 1, |i, _| {
        subset.iter().enumerate().map(|(c, &m)| h[(i, c)] * f(m)).sum::<f64>() * p.wd[(k, k)] * sign
    });
    let du = hgy.partial_piv_lu().solve(&hf);
    let mut loss = 0.0;
    for i in 0..nu {
        for j in 0..nu {
            loss += 0.5 * du[(i, 0)] * p.juu[(i, j)] * du[(j, 0)];
        }
    }
    loss
}
