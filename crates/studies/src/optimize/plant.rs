//! The plant as the SQP sees it: at each point the degrees of freedom are written into the
//! inputs, the steady state is solved (warm-started from a nearby point) and certified, and the
//! exact first derivatives of the objective and the constrained variables with respect to the
//! degrees of freedom come from one sparse LU of the plant Jacobian (implicit-function theorem,
//! `dx/du = −F_x⁻¹ F_u`, [`Linearization::steady_gain`]).
//!
//! Scaling, fixed at the start point: each degree of freedom by the width of its bounds (by its
//! magnitude when a bound is missing), the objective by its largest change over one such width
//! to second order (so the scaled gradient starts at unit size unless the curvature dominates;
//! at a stationary start, the curvature alone), each constraint by its largest first-order
//! change.

use plantwide_analysis::linear::Linearization;
use plantwide_flowsheet::Plant;
use plantwide_flowsheet::optimization::Sense;
use plantwide_solve::{NewtonSettings, SteadyError, steady_state};

use super::curvature::Curvature;
use super::request::Problem;
use super::sqp::{Nlp, Point};

/// The scaled residual the optimizer's steady states are solved to.
const TIGHT: f64 = 1e-12;

/// A checked steady state of the plant.
#[derive(Debug, Clone)]
pub struct State {
    /// Variables (SI).
    pub x: Vec<f64>,
    /// Inputs (SI).
    pub u: Vec<f64>,
}

/// Why the plant could not be evaluated at a point.
#[derive(Debug, Clone)]
pub struct EvaluationFailure {
    /// The message of the steady solve or of the linearization.
    pub message: String,
}

/// The plant, its problem and the scales.
pub(crate) struct PlantNlp<'a> {
    plant: &'a Plant,
    problem: &'a Problem,
    u0: Vec<f64>,
    /// Width of each degree of freedom (SI).
    pub scale_u: Vec<f64>,
    /// Scale of the objective (SI).
    pub scale_f: f64,
    /// Scale of each constraint (SI).
    pub scale_c: Vec<f64>,
    settings: NewtonSettings,
    /// The start point's steady state.
    home: State,
    /// Plant solves done.
    pub solves: usize,
}

/// Raw values and SI derivatives at one state: `[objective, constraints…]` and their gradients.
struct Raw {
    values: Vec<f64>,
    gradients: Vec<Vec<f64>>,
}

impl<'a> PlantNlp<'a> {
    /// The plant at inputs `u0` with `problem`, scaled at the steady state `start` (the inputs'
    /// values there are the start of the optimization).
    pub fn new(plant: &'a Plant, problem: &'a Problem, start: &State) -> Result<PlantNlp<'a>, EvaluationFailure> {
        let scale_u = problem
            .dofs
            .iter()
            .map(|d| {
                let width = d.ub - d.lb;
                let bound = [d.lb, d.ub].into_iter().filter(|b| b.is_finite()).fold(0.0_f64, |m, b| m.max(b.abs()));
                let magnitude = start.u[d.signal.index].abs().max(bound);
                if width.is_finite() && width > 0.0 {
                    width
                } else if magnitude > 0.0 && magnitude.is_finite() {
                    magnitude
                } else {
                    1.0
                }
            })
            .collect::<Vec<_>>();
        let mut nlp = PlantNlp {
            plant,
            problem,
            u0: start.u.clone(),
            scale_u,
            scale_f: 1.0,
            scale_c: vec![1.0; problem.constraints.len()],
            settings: NewtonSettings { tol: TIGHT, ..NewtonSettings::default() },
            solves: 0,
            home: start.clone(),
        };
        let raw = nlp.raw(start)?;
        let size = |k: usize| -> f64 {
            raw.gradients[k].iter().zip(&nlp.scale_u).fold(0.0_f64, |m, (g, s)| m.max((g * s).abs()))
        };
        let fallback = |v: f64| if v.abs() > 0.0 { v.abs() } else { 1.0 };
        let change = nlp.objective_change(start, &raw.gradients[0])?;
        nlp.scale_f = if change > 0.0 { change } else { fallback(raw.values[0]) };
        for (i, c) in problem.constraints.iter().enumerate() {
            let limit = if c.lo.is_finite() { c.lo } else { c.hi };
            nlp.scale_c[i] = if size(i + 1) > 0.0 { size(i + 1) } else { fallback(limit.abs().max(raw.values[i + 1])) };
        }
        Ok(nlp)
    }

    /// The inputs at scaled variables `v`.
    pub fn inputs(&self, v: &[f64]) -> Vec<f64> {
        let mut u = self.u0.clone();
        for (j, d) in self.problem.dofs.iter().enumerate() {
            u[d.signal.index] = v[j] * self.scale_u[j];
        }
        u
    }

    /// The scaled variables of the inputs `u`.
    pub fn variables(&self, u: &[f64]) -> Vec<f64> {
        self.problem.dofs.iter().enumerate().map(|(j, d)| u[d.signal.index] / self.scale_u[j]).collect()
    }

    /// The objective's largest change over one width of a degree of freedom, to second order:
    /// `max_j |g_j| w_j + ½ |H_jj| w_j²` (`H_jj` exact, [`Curvature`]). The curvature matters
    /// where the start is stationary: at an optimum whose disturbance the caller moves (a
    /// re-optimization from the held point), the gradient is rounding, and a scale taken from it
    /// alone would magnify that rounding into the SQP's steps.
    fn objective_change(&self, start: &State, gradient: &[f64]) -> Result<f64, EvaluationFailure> {
        let mut w = vec![0.0; self.plant.n_vars()];
        w[self.problem.objective.index] = 1.0;
        let curvature = Curvature::new(self.plant, start, &w)?;
        let unit = |j: usize| (0..self.scale_u.len()).map(|k| f64::from(u8::from(k == j))).collect::<Vec<_>>();
        let moves = curvature.moves(&(0..self.scale_u.len()).map(|j| self.input_move(&unit(j))).collect::<Vec<_>>())?;
        Ok(moves
            .iter()
            .enumerate()
            .map(|(j, m)| (gradient[j] * self.scale_u[j]).abs() + 0.5 * curvature.second(m, m).abs())
            .fold(0.0_f64, f64::max))
    }

    /// The plant.
    pub fn plant(&self) -> &Plant {
        self.plant
    }

    /// The SQP's Lagrangian `f − Σ yᵢ cᵢ` (scaled objective and constraints) as weights on the
    /// plant's variables: `L = wᵀx` up to the bounds' terms, which are linear in the inputs.
    pub fn lagrangian_weights(&self, y: &[f64]) -> Vec<f64> {
        let mut w = vec![0.0; self.plant.n_vars()];
        w[self.problem.objective.index] += self.sign() / self.scale_f;
        for (i, c) in self.problem.constraints.iter().enumerate() {
            w[c.signal.index] -= y[i] / self.scale_c[i];
        }
        w
    }

    /// The move of every input (SI) along the scaled direction `z` of the degrees of freedom.
    pub fn input_move(&self, z: &[f64]) -> Vec<f64> {
        let mut du = vec![0.0; self.u0.len()];
        for (j, d) in self.problem.dofs.iter().enumerate() {
            du[d.signal.index] += z[j] * self.scale_u[j];
        }
        du
    }

    /// The sign that makes the objective a cost.
    fn sign(&self) -> f64 {
        match self.problem.sense {
            Sense::Minimize => 1.0,
            Sense::Maximize => -1.0,
        }
    }

    /// Values and SI gradients of the objective and the constraints at a steady state.
    fn raw(&self, s: &State) -> Result<Raw, EvaluationFailure> {
        let outputs: Vec<usize> = std::iter::once(self.problem.objective.index)
            .chain(self.problem.constraints.iter().map(|c| c.signal.index))
            .collect();
        let inputs: Vec<usize> = self.problem.dofs.iter().map(|d| d.signal.index).collect();
        let gain = Linearization::new(self.plant, &s.x, &s.u)
            .steady_gain(&inputs, &outputs)
            .map_err(|e| EvaluationFailure { message: e.to_string() })?;
        let values = outputs.iter().map(|&i| s.x[i]).collect();
        let gradients = (0..outputs.len()).map(|k| (0..inputs.len()).map(|j| gain[(k, j)]).collect()).collect();
        Ok(Raw { values, gradients })
    }

    /// The checked steady state at inputs `u`, started from `near` (or the plant's own guess).
    pub fn steady(&mut self, u: &[f64], near: Option<&State>) -> Result<State, EvaluationFailure> {
        self.solves += 1;
        let fail = |e: SteadyError| EvaluationFailure { message: e.to_string() };
        let start = near.unwrap_or(&self.home);
        // Tight first (the optimizer compares objectives to ~1e-10); the default tolerance where
        // rounding keeps a large plant's residual above it; then from the start point.
        let ss = steady_state(self.plant, u, Some(&start.x), &self.settings)
            .or_else(|_| steady_state(self.plant, u, Some(&start.x), &NewtonSettings::default()))
            .or_else(|_| steady_state(self.plant, u, Some(&self.home.x), &NewtonSettings::default()))
            .map_err(fail)?;
        Ok(State { x: ss.x, u: ss.u })
    }

    /// The scaled point of a steady state.
    pub fn point(&self, s: State) -> Result<Point<State>, EvaluationFailure> {
        let raw = self.raw(&s)?;
        let (n, m) = (self.scale_u.len(), self.scale_c.len());
        let sign = self.sign();
        let f = sign * raw.values[0] / self.scale_f;
        let g = (0..n).map(|j| sign * raw.gradients[0][j] * self.scale_u[j] / self.scale_f).collect();
        let c = (0..m).map(|i| raw.values[i + 1] / self.scale_c[i]).collect();
        let a = faer::Mat::from_fn(m, n, |i, j| raw.gradients[i + 1][j] * self.scale_u[j] / self.scale_c[i]);
        let finite = raw.values.iter().chain(raw.gradients.iter().flatten()).all(|v| v.is_finite());
        if !finite {
            return Err(EvaluationFailure {
                message: "a derivative of the objective or a constraint is not finite".into(),
            });
        }
        Ok(Point { f, g, c, a, state: s })
    }
}

impl Nlp for PlantNlp<'_> {
    type State = State;
    type Failure = EvaluationFailure;

    fn evaluate(&mut self, v: &[f64], near: Option<&State>) -> Result<Point<State>, EvaluationFailure> {
        let u = self.inputs(v);
        let s = self.steady(&u, near)?;
        self.point(s)
    }
}
