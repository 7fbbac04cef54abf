//! Stiff integration of the plant's semi-explicit index-1 DAE `M dx/dt = f(t, x)`, where `M` is a
//! 0/1 selection: each pair `(equation i, variable j)` of [`DaeSystem::mass`] says that equation `i`
//! *is* `dx_j/dt`; every other equation is algebraic (`0 = f_i`) and every other variable algebraic.
//!
//! [`Bdf`] is a variable-step, variable-order (1–5) backward differentiation formula in the
//! quasi-constant step-size form of Shampine & Reichelt (ode15s) as SciPy implements it: a modified
//! divided-difference array that is re-interpolated when the step changes. Error control is on the
//! differential variables only; the algebraic variables are solved exactly (to the Newton
//! tolerance) at every step, and solved for consistency ([`consistent_algebraic`]) at the start and
//! after every event. [`DaeIntegrator`] is the interface the simulation driver uses, so another
//! integrator can be put behind it.

pub mod bdf;
mod init;
pub(crate) mod reduce;

pub use bdf::{Bdf, BdfSettings, BdfState, BdfStats, DenseOutput};
pub use init::consistent_algebraic;
pub use reduce::ReduceError;

/// A time-aware semi-explicit DAE `M dx/dt = f(t, x)` with a 0/1 mass matrix.
pub trait DaeSystem: Sync {
    /// Number of variables (= number of equations).
    fn n(&self) -> usize;
    /// `f(t, x)` into `r`.
    fn residual(&self, t: f64, x: &[f64], r: &mut [f64]);
    /// `f(t, x)` into `r` and `∂f/∂x` as triplets `(row, column, value)` into `jac` (cleared first);
    /// the pattern must not depend on the point.
    fn jacobian(&self, t: f64, x: &[f64], r: &mut [f64], jac: &mut Vec<(usize, usize, f64)>);
    /// The `(equation, variable)` pairs that carry a time derivative.
    fn mass(&self) -> &[(usize, usize)];
    /// Typical magnitude of variable `i` (in its own units): absolute tolerances are relative to it.
    fn nominal(&self, i: usize) -> f64;
    /// Bounds of variable `i`, respected by the consistent initialization.
    fn bounds(&self, i: usize) -> (f64, f64);
    /// Whether variable `i` takes part in the local error test (default: the differential ones).
    /// Quadratures (running integrals recorded for output) are differential but need not.
    fn error_controlled(&self, i: usize) -> bool;
    /// Whether variable `i` is a quadrature (a running integral that nothing else reads): such
    /// variables are left out of the Newton convergence test as well (default: none).
    fn quadrature(&self, _i: usize) -> bool {
        false
    }
    /// Algebraic variables the system computes in closed form from the others, as
    /// `(equation, variable)` pairs in the order [`DaeSystem::complete`] computes them: each
    /// equation is solved exactly for its variable, reading only kept variables and explicit ones
    /// earlier in the list. The integrator's Newton iteration then runs on the other variables
    /// alone (default: none).
    fn explicit(&self) -> &[(usize, usize)] {
        &[]
    }
    /// Output-only algebraic variables, as `(equation, variable)` pairs: no equation of the other
    /// (non-explicit) variables reads them, directly or through an explicit variable. The
    /// integrator leaves them and their equations out of its iteration, where their values
    /// stay as they were, and solves them when asked ([`Bdf::complete_outputs`]);
    /// [`DaeSystem::residual_completed`] may skip their equations (default: none).
    fn outputs(&self) -> &[(usize, usize)] {
        &[]
    }
    /// Overwrite the [`DaeSystem::explicit`] variables of `x` with their values from the others
    /// at time `t` (default: nothing).
    fn complete(&self, _t: f64, _x: &mut [f64]) {}
    /// [`DaeSystem::residual`] at an `x` that [`DaeSystem::complete`] has just completed: the
    /// explicit equations hold there, and their rows and those of [`DaeSystem::outputs`] may be
    /// left anything, unevaluated (the integrator reads the other rows alone; default: the
    /// residual).
    fn residual_completed(&self, t: f64, x: &[f64], r: &mut [f64]) {
        self.residual(t, x, r);
    }
    /// What equation `i` is, for messages (a plant: its unit, equation and variable; default:
    /// nothing beyond its index).
    fn equation_name(&self, _i: usize) -> Option<String> {
        None
    }
    /// What variable `i` is, for messages (a plant: its path; default: nothing beyond its index).
    fn variable_name(&self, _i: usize) -> Option<String> {
        None
    }
    /// What a failure on equation `i` most often means, as a clause beginning with `"; "` (a
    /// plant: a vessel running dry for a unit's equation, an output the plant cannot take for a
    /// controller's; default: nothing).
    fn equation_hint(&self, _i: usize) -> Option<&'static str> {
        None
    }
}

/// An equation of a [`DaeSystem`] as a failure names it: its index and, when the system knows
/// it, its name ([`DaeSystem::equation_name`]); shown as `equation 6 (flash: …)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Equation {
    /// Global index.
    pub index: usize,
    /// The system's name for it.
    pub name: Option<String>,
    /// What a failure on it most often means ([`DaeSystem::equation_hint`]).
    pub hint: Option<&'static str>,
}

impl Equation {
    /// Equation `index` of `sys`, with its name and hint.
    pub fn of(sys: &dyn DaeSystem, index: usize) -> Equation {
        Equation { index, name: sys.equation_name(index), hint: sys.equation_hint(index) }
    }
}

impl std::fmt::Display for Equation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.name {
            Some(name) => write!(f, "equation {} ({name})", self.index),
            None => write!(f, "equation {}", self.index),
        }
    }
}

/// Why an integration stopped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DaeError {
    /// The step size fell below the resolution of the time axis.
    #[error(
        "step size too small ({h:.3e} s) at t = {time} s: the model may be discontinuous or ill-posed there{}",
        culprit.as_ref().map(|c| format!("; the last attempt failed on {c}")).unwrap_or_default()
    )]
    StepSizeTooSmall {
        /// Time [s].
        time: f64,
        /// Step size [s].
        h: f64,
        /// The variable that stopped the last attempt and how (`column1.x[3][A] (the largest
        /// local error)`), when known.
        culprit: Option<String>,
    },
    /// More steps than [`BdfSettings::max_steps`].
    #[error("more than {max_steps} steps before t = {time} s (raise max_steps or loosen the tolerances)")]
    TooManySteps {
        /// Time reached [s].
        time: f64,
        /// The limit.
        max_steps: usize,
    },
    /// The algebraic variables could not be made consistent.
    #[error(transparent)]
    Initialization(Box<Inconsistent>),
    /// The iteration matrix could not be factorized.
    #[error("iteration matrix singular at t = {time} s: {source}")]
    Singular {
        /// Time [s].
        time: f64,
        /// What the factorization said.
        source: crate::sparse::SparseError,
    },
    /// The output-only variables did not converge when asked for.
    #[error("output-only variables at t = {time} s did not converge: {equation} keeps a residual of {residual:.3e}")]
    Outputs {
        /// Time [s].
        time: f64,
        /// The equation with the largest residual.
        equation: Box<Equation>,
        /// Its residual.
        residual: f64,
    },
    /// The explicit variables could not be eliminated from the iteration matrix.
    #[error("explicit variables at t = {time} s: {source}")]
    Explicit {
        /// Time [s].
        time: f64,
        /// What the elimination found.
        source: ReduceError,
    },
    /// A restored state does not fit the system.
    #[error("integrator state does not fit the system: {0}")]
    BadState(bdf::StateMismatch),
}

/// A consistent initialization that failed: where, and what the algebraic equations asked for.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "consistent initialization failed at t = {time} s: scaled residual {residual:.3e} in {equation}{}",
    pinned_note(.pinned)
)]
pub struct Inconsistent {
    /// Time [s].
    pub time: f64,
    /// Final scaled residual.
    pub residual: f64,
    /// The worst equation.
    pub equation: Equation,
    /// The variables the solve left on a bound they did not start on (`` `path` at its lower
    /// bound 0 ``): the equations ask for values beyond them.
    pub pinned: Vec<String>,
}

/// `; the equations ask for values beyond the bounds of …` (empty when nothing was pinned).
fn pinned_note(pinned: &[String]) -> String {
    if pinned.is_empty() {
        return String::new();
    }
    format!("; the equations ask for values beyond the bounds of {}", pinned.join(", "))
}

/// A DAE integrator that can be stopped exactly at given times and restarted after events.
pub trait DaeIntegrator {
    /// (Re)start at `t` from `x`: the algebraic variables are solved for consistency with the
    /// differential ones, and the history is discarded (restart at order 1).
    fn restart(&mut self, sys: &dyn DaeSystem, t: f64, x: &[f64]) -> Result<(), DaeError>;
    /// Take one step, never past `t_stop` (a step that would cross it ends exactly on it).
    fn step(&mut self, sys: &dyn DaeSystem, t_stop: f64) -> Result<(), DaeError>;
    /// Current time [s].
    fn t(&self) -> f64;
    /// Current state.
    fn x(&self) -> &[f64];
    /// Time at the start of the last step [s]: [`DaeIntegrator::interpolate`] is valid on
    /// `[t_prev, t]`.
    fn t_prev(&self) -> f64;
    /// The state at `t` within the last step, from the integrator's interpolating polynomial.
    fn interpolate(&self, t: f64, out: &mut [f64]);
    /// [`DaeIntegrator::interpolate`] of the entries `indices` of the state only (the other
    /// entries of `out` are left as they are).
    fn interpolate_at(&self, t: f64, indices: &[usize], out: &mut [f64]);
    /// Counters.
    fn stats(&self) -> BdfStats;
}

/// Weighted root-mean-square norm `√(Σ_{i ∈ over} (v_i·w_i)² / |over|)` (0 over no index), `over`
/// ascending without repeats (summed in that order); `w` are reciprocal error scales.
fn rms(v: &[f64], weight: &[f64], over: &[usize]) -> f64 {
    if over.is_empty() {
        return 0.0;
    }
    let sq = |a: f64, w: f64| (a * w) * (a * w);
    // `over` ascends without repeats, so it is `0..m` when its last index is `m − 1` (every
    // variable but the quadratures, which come last).
    let sum: f64 = if over.last() == Some(&(over.len() - 1)) {
        // Four partial sums: one running sum is a chain of dependent additions, latency-bound.
        let m = over.len();
        let (v, w) = (v[..m].chunks_exact(4), weight[..m].chunks_exact(4));
        let tail: f64 = v.remainder().iter().zip(w.remainder()).map(|(&a, &w)| sq(a, w)).sum();
        let lanes = v.zip(w).fold([0.0; 4], |mut acc, (a, w)| {
            acc.iter_mut().enumerate().for_each(|(k, s)| *s += sq(a[k], w[k]));
            acc
        });
        (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + tail
    } else {
        over.iter().map(|&i| sq(v[i], weight[i])).sum()
    };
    (sum / over.len() as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::rms;

    /// The contiguous path (four partial sums and a tail) and the gathered path give the closed
    /// form `w·√(Σ_{i=1}^{m} i² / m)`: for m = 7, `√(140/7) = √20`.
    #[test]
    fn weighted_rms_matches_its_closed_form_on_both_paths() {
        let v: Vec<f64> = (1..=9).map(f64::from).collect();
        let w = vec![0.5; 9];
        let contiguous: Vec<usize> = (0..7).collect();
        assert!((rms(&v, &w, &contiguous) - 0.5 * 20f64.sqrt()).abs() < 1e-15);
        // Indices 2, 4, 8 hold 3, 5, 9: √((9 + 25 + 81)/3).
        assert!((rms(&v, &w, &[2, 4, 8]) - 0.5 * (115.0f64 / 3.0).sqrt()).abs() < 1e-15);
        assert_eq!(rms(&v, &w, &[]), 0.0);
    }
}
