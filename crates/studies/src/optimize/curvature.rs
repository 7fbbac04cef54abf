//! Exact second derivatives of the Lagrangian along moves of the inputs, by the implicit-function
//! theorem and hyper-dual numbers.
//!
//! At a steady state `f(x, u) = 0`, a function of the state `φ = wᵀx` (the Lagrangian of the
//! SQP: the objective and the constraints are plant variables) has, along input moves `δu_a`,
//! `δu_b` with state responses `δx = −J⁻¹ B δu` ([`Linearization::state_moves`]),
//!
//! `∂²φ/∂u_a∂u_b = −λᵀ f''[(δx_a, δu_a), (δx_b, δu_b)]`, with `Jᵀλ = w` ([`Linearization::adjoint`]),
//!
//! (differentiate `f(x(u), u) = 0` twice: `J x'' + f''[δw_a, δw_b] = 0`). `f''` is exact by one
//! hyper-dual pass of the plant's residuals per pair of moves ([`Plant::curvature`]); `J` and `B`
//! are exact by dual numbers. So `Juu` and `Jud` carry no truncation error: one sparse LU of
//! `J`, one of `Jᵀ`, and `k(k+1)/2` residual passes for `k` moves.

use faer::Mat;
use plantwide_analysis::linear::Linearization;
use plantwide_flowsheet::Plant;

use super::plant::{EvaluationFailure, State};

/// A move of the inputs and the state's response to it (SI).
#[derive(Debug, Clone)]
pub(crate) struct Move {
    dx: Vec<f64>,
    du: Vec<f64>,
}

/// The adjoint of a function of the steady state, ready to give its second derivatives.
pub(crate) struct Curvature<'p> {
    plant: &'p Plant,
    state: &'p State,
    lin: Linearization,
    lambda: Vec<f64>,
}

fn failure(e: impl std::fmt::Display) -> EvaluationFailure {
    EvaluationFailure { message: e.to_string() }
}

impl<'p> Curvature<'p> {
    /// The function `wᵀx` of the steady state `state` of `plant` (weights `w` per variable).
    ///
    /// # Errors
    /// The plant Jacobian is singular there.
    pub fn new(plant: &'p Plant, state: &'p State, w: &[f64]) -> Result<Curvature<'p>, EvaluationFailure> {
        let lin = Linearization::new(plant, &state.x, &state.u);
        let lambda = lin.adjoint(w).map_err(failure)?;
        Ok(Curvature { plant, state, lin, lambda })
    }

    /// The moves `du` (each a full input vector, SI) with their state responses.
    ///
    /// # Errors
    /// The plant Jacobian is singular.
    pub fn moves(&self, du: &[Vec<f64>]) -> Result<Vec<Move>, EvaluationFailure> {
        let n_u = self.state.u.len();
        let cols = Mat::from_fn(n_u, du.len(), |i, k| du[k][i]);
        let dx = self.lin.state_moves(&cols).map_err(failure)?;
        Ok(du
            .iter()
            .enumerate()
            .map(|(k, d)| Move { dx: dx.col(k).iter().copied().collect(), du: d.clone() })
            .collect())
    }

    /// `∂²(wᵀx)` along the moves `a` and `b`.
    pub fn second(&self, a: &Move, b: &Move) -> f64 {
        let mut f2 = vec![0.0; self.plant.n_eqs()];
        self.plant.curvature((&self.state.x, &self.state.u), (&a.dx, &a.du), (&b.dx, &b.du), &mut f2);
        -self.lambda.iter().zip(&f2).map(|(l, f)| l * f).sum::<f64>()
    }

    /// The symmetric matrix of [`Curvature::second`] over `moves`.
    pub fn matrix(&self, moves: &[Move]) -> Mat<f64> {
        let k = moves.len();
        let mut h = Mat::zeros(k, k);
        for a in 0..k {
            for b in a..k {
                h[(a, b)] = self.second(&moves[a], &moves[b]);
                h[(b, a)] = h[(a, b)];
            }
        }
        h
    }
}
