//! The economic optimum of a plant at steady state (issue 58; Skogestad's top-down procedure,
//! step 2: optimal operation and its active constraints).
//!
//! The problem is the file's `"optimization"` section ([`OptimizationSpec`]): an objective (a tag,
//! i.e. an expression of plant variables and prices, or any variable), the degrees of freedom
//! (free inputs and setpoints, with bounds) and limits on any variable. It is solved in the
//! reduced space of the degrees of freedom: every point is a converged, certified steady state of
//! the whole plant with its controllers, and the exact first derivatives come from the plant
//! Jacobian ([`plant`]). The SQP ([`sqp`]) is a trust-region Sℓ1QP whose quadratic subproblems
//! clarabel solves with the KKT structure built once ([`qp`]).
//!
//! The answer ([`Optimum`]): the optimum, its active set, the shadow prices `∂J*/∂limit` of the
//! active limits in display units, the KKT residual, and the exact reduced Hessian of the
//! Lagrangian at the optimum ([`certificate`], [`curvature`]). No feasible point, or a KKT point that is no
//! minimum, is an error naming what failed.

mod certificate;
mod curvature;
pub mod local;
mod plant;
mod polish;
mod qp;
pub mod request;
pub mod select;
mod sqp;
pub mod sweep;

use indexmap::IndexMap;
use plantwide_flowsheet::Plant;
use plantwide_flowsheet::optimization::{OptimizationSpec, Sense};
use serde::Serialize;

pub use plant::State;
use plant::{EvaluationFailure, PlantNlp};
pub use request::{Constraint, Dof, Problem, parse_limits};
use sqp::{Bounds, Outcome, Settings, SqpError};

/// A limit at the optimum.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LimitResult {
    /// `PATH:min` or `PATH:max`: the name in `active` and `multipliers`.
    pub name: String,
    /// The variable or input.
    pub path: String,
    /// Display unit of `value` and `limit`.
    pub unit: String,
    /// Its value at the optimum (display unit).
    pub value: f64,
    /// The limit (display unit).
    pub limit: f64,
    /// Whether the limit is active.
    pub active: bool,
    /// `∂J*/∂limit`: the change of the optimal objective per display unit the limit rises
    /// (objective unit per this unit); zero when inactive.
    pub shadow_price: f64,
}

/// The reduced Hessian of the Lagrangian at the optimum, in the free inputs' display units.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReducedHessian {
    /// The free inputs (`path@unit`): each moved with the others moving to hold the active
    /// limits.
    pub free: Vec<String>,
    /// `∂²J/∂u_i∂u_j` along those directions: objective unit per (unit_i · unit_j).
    pub matrix: Vec<Vec<f64>>,
    /// Eigenvalues of the scaled matrix (ascending): all positive at a strict minimum.
    pub scaled_eigenvalues: Vec<f64>,
}

/// The optimum of a plant.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Optimum {
    /// The objective at the optimum, in its display unit.
    pub objective: f64,
    /// Every degree of freedom, the objective's variable and every constrained variable: path →
    /// SI value.
    pub values: IndexMap<String, f64>,
    /// The active limits (`PATH:min`, `PATH:max`), constraints first, then bounds.
    pub active: Vec<String>,
    /// Shadow price of each active limit (see [`LimitResult::shadow_price`]).
    pub multipliers: IndexMap<String, f64>,
    /// The KKT residual (scaled: stationarity, feasibility, complementarity; see
    /// `docs/optimize.md`).
    pub kkt_residual: f64,
    /// The objective's variable path.
    pub objective_path: String,
    /// The objective's display unit.
    pub objective_unit: String,
    /// `minimize` or `maximize`.
    pub sense: Sense,
    /// Every finite limit, constraints first, then bounds.
    pub limits: Vec<LimitResult>,
    /// The reduced Hessian.
    pub reduced_hessian: ReducedHessian,
    /// SQP iterations.
    pub iterations: usize,
    /// Plant steady states solved (the certificate's included).
    pub plant_solves: usize,
}

/// Why there is no optimum.
#[derive(Debug, Clone, thiserror::Error)]
pub enum OptimizeError {
    /// A field of the problem is wrong.
    #[error("{field}: {message}")]
    Field {
        /// The field (`optimization.vary.feed.F`).
        field: String,
        /// What is wrong and what would fix it.
        message: String,
    },
    /// The plant has no steady state at the start.
    #[error("optimize: no steady state at the start point (the file's inputs, moved into the bounds of `vary`): {0}")]
    Start(String),
    /// No point meets every limit.
    #[error("optimize: no feasible point: {} ({why})", .violated.join("; "))]
    Infeasible {
        /// Each violated limit with its value.
        violated: Vec<String>,
        /// How the search ended: at a local minimum of the violation, or short of one.
        why: String,
    },
    /// The quadratic subproblem failed.
    #[error("optimize: the QP solver (clarabel) failed: {0}")]
    Qp(String),
    /// A request the search refuses (its size or count), named by the search's own field.
    #[error("{0}")]
    Request(String),
    /// The SQP ended without a certified minimum.
    #[error("optimize: no optimum certified: {reason} after {iterations} iterations (KKT residual {kkt:.2e})")]
    NotConverged {
        /// Why.
        reason: String,
        /// Iterations.
        iterations: usize,
        /// The KKT residual at the last point.
        kkt: f64,
    },
}

impl OptimizeError {
    /// Whether the error is in the request (exit 1) rather than the plant or the numbers (exit 2).
    pub fn is_user_error(&self) -> bool {
        matches!(self, OptimizeError::Field { .. } | OptimizeError::Request(_))
    }
}

/// The scaled bounds and limits of `nlp`'s problem.
fn scaled_bounds(problem: &Problem, nlp: &PlantNlp<'_>) -> Bounds {
    Bounds {
        lb: problem.dofs.iter().zip(&nlp.scale_u).map(|(d, s)| d.lb / s).collect(),
        ub: problem.dofs.iter().zip(&nlp.scale_u).map(|(d, s)| d.ub / s).collect(),
        lo: problem.constraints.iter().zip(&nlp.scale_c).map(|(c, s)| c.lo / s).collect(),
        hi: problem.constraints.iter().zip(&nlp.scale_c).map(|(c, s)| c.hi / s).collect(),
    }
}

/// The optimum of `plant` for `spec`, from the steady state `start` at the plant's inputs.
///
/// # Errors
/// [`OptimizeError::Field`] for a problem that does not fit the plant; the others when the plant
/// or the numbers fail (each names what).
pub fn optimize(plant: &Plant, spec: &OptimizationSpec, start: &State) -> Result<Optimum, OptimizeError> {
    let problem = Problem::new(plant, spec)?;
    let mut solved = solve_problem(plant, &problem, start)?;
    report::optimum(&mut solved.nlp, &problem, &solved.bounds, &solved.sol)
}

/// A converged SQP with what it ran on.
pub(crate) struct Solved<'a> {
    nlp: PlantNlp<'a>,
    bounds: Bounds,
    sol: sqp::Solution<State>,
}

/// Solve `problem` from `start`: the SQP to a KKT point, or the error its end means.
fn solve_problem<'a>(plant: &'a Plant, problem: &'a Problem, start: &State) -> Result<Solved<'a>, OptimizeError> {
    if !plant.specs().is_empty() {
        return Err(OptimizeError::Field {
            field: "specs".into(),
            message: "design specs fix inputs at the optimum's expense: meet them first (the faces do), or make \
                      their targets constraints"
                .into(),
        });
    }
    let start_failure = |e: EvaluationFailure| OptimizeError::Start(e.message);
    let mut nlp = PlantNlp::new(plant, problem, start).map_err(start_failure)?;
    let bounds = scaled_bounds(problem, &nlp);
    let v0 = nlp.variables(&start.u);
    let sol = sqp::solve(&mut nlp, &bounds, &v0, &Settings::default()).map_err(|e| match e {
        SqpError::Start(f) => start_failure(f),
        SqpError::Qp(m) => OptimizeError::Qp(m.to_string()),
    })?;
    match sol.outcome {
        Outcome::Optimal => Ok(Solved { nlp, bounds, sol }),
        Outcome::Infeasible => {
            let violated = report::violations(problem, &sol.point.state);
            let dofs = problem.dofs.iter().map(|d| format!("`{}`", d.signal.path)).collect::<Vec<_>>().join(", ");
            let why = format!(
                "a local minimum of the violation after {} iterations: no move of {dofs} reduces it further",
                sol.iterations
            );
            Err(OptimizeError::Infeasible { violated, why })
        }
        Outcome::Stalled | Outcome::IterationLimit => {
            let reason = if sol.outcome == Outcome::Stalled {
                "no step decreases the merit function (the trust region shrank to nothing)"
            } else {
                "the iteration limit"
            };
            let violated = report::violations(problem, &sol.point.state);
            if !violated.is_empty() {
                let why = format!(
                    "none found: the search ended at {reason} after {} iterations, these limits still violated",
                    sol.iterations
                );
                return Err(OptimizeError::Infeasible { violated, why });
            }
            Err(OptimizeError::NotConverged { reason: reason.into(), iterations: sol.iterations, kkt: sol.kkt.max() })
        }
    }
}

mod report;
