//! The steady-state strategy: sequential-modular, equation-oriented (whole-plant Newton), or
//! `auto` — a sequential-modular pass to a loose tolerance as the start of the whole-plant Newton.

use plantwide_flowsheet::Plant;
use serde::{Deserialize, Serialize};

use crate::certify::certify_to;
use crate::{DofError, DofProbe, dof_check};

use super::{PassRecord, SmError, SmReport, SmSettings, plan, solve_sequential_observed};
use crate::steady::steady_state_within;
use crate::{IterationRecord, NewtonReport, NewtonSettings, SteadyError, Warning, steady_state_observed};

/// How to find the steady state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Whole-plant Newton from the cold-start guess (equation oriented).
    Eo,
    /// Sequential modular alone, to [`SmSettings::tol`].
    Sm,
    /// Plants with recycles: sequential modular to [`StrategySettings::auto_tol`], then whole-plant
    /// Newton from there (from the cold start if the pass fails). Plants without: Newton from the
    /// cold start, from a pass after 20 iterations without convergence.
    Auto,
}

/// Settings of [`steady_state_by`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StrategySettings {
    /// Method (default: `auto`).
    pub method: Method,
    /// Sequential-modular settings.
    pub sm: SmSettings,
    /// Whole-plant Newton settings.
    pub newton: NewtonSettings,
    /// Tear tolerance of the sequential-modular pass in `auto` (default: 1e-4).
    pub auto_tol: f64,
}

impl Default for StrategySettings {
    fn default() -> Self {
        StrategySettings {
            method: Method::Auto,
            sm: SmSettings::default(),
            newton: NewtonSettings::default(),
            auto_tol: 1e-4,
        }
    }
}

/// Progress of [`steady_state_by`].
#[derive(Debug, Clone, Copy)]
pub enum Progress<'a> {
    /// A sequential-modular pass.
    Pass(&'a PassRecord),
    /// A whole-plant Newton iteration.
    Newton(&'a IterationRecord),
}

/// A steady state and how it was found.
#[derive(Debug, Clone)]
pub struct Solution {
    /// Variable values (SI).
    pub x: Vec<f64>,
    /// Input values (SI).
    pub u: Vec<f64>,
    /// The sequential-modular report, if a pass ran.
    pub sm: Option<SmReport>,
    /// Why the sequential-modular pass of `auto` was abandoned, if it was.
    pub sm_failure: Option<String>,
    /// The whole-plant Newton report, if Newton ran.
    pub newton: Option<NewtonReport>,
    /// Controllers that hold their output at a limit with the measurement off setpoint.
    pub warnings: Vec<Warning>,
    /// How the loops were closed from the open plant, where the cold start failed
    /// ([`super::closing`]).
    pub closed_loops: Option<String>,
}

impl Solution {
    /// Every variable and every free input (one no controller drives) under its path, in SI: the
    /// `values` of `plantwide steady --json` and the mapping the Python face returns.
    pub fn values(&self, plant: &Plant) -> Vec<(String, f64)> {
        let vars = plant.vars().iter().zip(&self.x).map(|(v, x)| (v.path.clone(), *x));
        let free = plant.inputs().iter().zip(&self.u).filter(|(i, _)| i.driven_by.is_none());
        vars.chain(free.map(|(i, u)| (i.path.clone(), *u))).collect()
    }
}

/// Meet `plant`'s design specs (converged the default way, [`converge`]) and fix their varied
/// inputs at the values found ([`Plant::fix_specs`]), so that dynamics and analyses start from the
/// plant the specs define. `None` (and `plant` unchanged) when it has no specs.
pub fn fix_design_point(plant: &mut Plant) -> Result<Option<Solution>, SolveError> {
    if plant.specs().is_empty() {
        return Ok(None);
    }
    let sol = converge(plant, &StrategySettings::default())?;
    plant.fix_specs(&sol.u);
    Ok(Some(sol))
}

/// Why no steady state was found.
#[derive(Debug, Clone, thiserror::Error)]
pub enum SolveError {
    /// From the sequential-modular pass.
    #[error(transparent)]
    Sm(#[from] SmError),
    /// From the whole-plant Newton.
    #[error(transparent)]
    Eo(#[from] SteadyError),
    /// Design specs asked of the sequential-modular method alone.
    #[error(
        "{file}: design specs ({specs}) are met by the whole-plant Newton, which `method` sm leaves out: use `method` auto (a sequential-modular start, then Newton) or eo"
    )]
    SpecsNeedNewton {
        /// Flowsheet file.
        file: String,
        /// The specs.
        specs: String,
    },
}

impl SolveError {
    /// True for an ill-posed plant or bad settings (a user error), false for a numerical failure.
    pub fn is_user_error(&self) -> bool {
        matches!(
            self,
            SolveError::Sm(SmError::Dof(_) | SmError::Settings(_) | SmError::NotInRecycle(_))
                | SolveError::Eo(SteadyError::Dof(_))
                | SolveError::SpecsNeedNewton { .. }
        )
    }
}

/// Find the steady state of `plant` at inputs `u` by `settings.method`, from the cold start. Design
/// specs are met by the whole-plant Newton; `auto` starts it from the plant converged with the
/// varied inputs held at their values in `u` (a flowsheet converged first, its design-spec loop
/// closed from there, as sequential simulators do), or from the cold start when that fails; `sm`
/// alone refuses them.
pub fn steady_state_by(
    plant: &Plant,
    u: &[f64],
    settings: &StrategySettings,
    observer: &mut dyn FnMut(Progress<'_>),
) -> Result<Solution, SolveError> {
    if settings.method == Method::Auto && !plant.specs().is_empty() {
        let mut held = plant.clone();
        held.fix_specs(u);
        if let Ok(start) = steady_state_by(&held, u, settings, observer)
            && let Ok(ss) = steady_state_observed(plant, u, Some(&start.x), &settings.newton, &mut |r| {
                observer(Progress::Newton(r))
            })
        {
            let newton = Some(ss.report);
            return Ok(Solution {
                x: ss.x,
                u: ss.u,
                sm: start.sm,
                sm_failure: None,
                newton,
                warnings: ss.warnings,
                closed_loops: None,
            });
        }
    }
    steady_state_from_cold(plant, u, settings, observer)
}

/// [`steady_state_by`] in one stage: specs, if any, solved with the plant from the cold start.
fn steady_state_from_cold(
    plant: &Plant,
    u: &[f64],
    settings: &StrategySettings,
    observer: &mut dyn FnMut(Progress<'_>),
) -> Result<Solution, SolveError> {
    let eo = |x0: Option<&[f64]>, observer: &mut dyn FnMut(Progress<'_>)| {
        steady_state_observed(plant, u, x0, &settings.newton, &mut |r| observer(Progress::Newton(r)))
    };
    match settings.method {
        Method::Eo => {
            let ss = eo(None, observer)?;
            Ok(Solution {
                x: ss.x,
                u: ss.u,
                sm: None,
                sm_failure: None,
                newton: Some(ss.report),
                warnings: ss.warnings,
                closed_loops: None,
            })
        }
        Method::Sm if !plant.specs().is_empty() => Err(SolveError::SpecsNeedNewton {
            file: plant.file().to_string(),
            specs: plant.specs().iter().map(|s| s.label()).collect::<Vec<_>>().join(", "),
        }),
        Method::Sm => {
            let sol = solve_sequential_observed(plant, u, None, &settings.sm, &mut |p| observer(Progress::Pass(p)))?;
            let tol = (10.0 * settings.sm.tol).max(crate::certify::TOL);
            let warnings = certify_to(plant, &sol.x, &sol.u, tol).map_err(|e| SteadyError::Certificate(Box::new(e)))?;
            Ok(Solution {
                x: sol.x,
                u: sol.u,
                sm: Some(sol.report),
                sm_failure: None,
                newton: None,
                warnings,
                closed_loops: None,
            })
        }
        Method::Auto => {
            let x0 = plant.initial_guess_at(u);
            let loose = SmSettings { tol: settings.auto_tol, ..settings.sm.clone() };
            if plan(plant, u, &x0).recycles().next().is_none() {
                return without_recycles(plant, u, &x0, settings, &loose, observer);
            }
            let (start, sm, sm_failure) = match solve_sequential_observed(plant, u, Some(&x0), &loose, &mut |p| {
                observer(Progress::Pass(p))
            }) {
                Ok(sol) => (sol.x, Some(sol.report), None),
                Err(e @ (SmError::Dof(_) | SmError::Settings(_) | SmError::NotInRecycle(_))) => return Err(e.into()),
                Err(SmError::NotConverged(f)) => (f.x.clone(), Some(f.report.clone()), Some(f.to_string())),
                Err(SmError::Local(f)) => (x0.clone(), None, Some(f.to_string())),
            };
            let ss = match eo(Some(&start), observer) {
                Ok(ss) => ss,
                Err(first) if sm_failure.is_none() => eo(Some(&x0), observer).map_err(|_| first)?,
                Err(e) => return Err(e.into()),
            };
            Ok(Solution {
                x: ss.x,
                u: ss.u,
                sm,
                sm_failure,
                newton: Some(ss.report),
                warnings: ss.warnings,
                closed_loops: None,
            })
        }
    }
}

/// Whole-plant Newton iterations that `auto` gives a plant without recycles from the cold start
/// before it starts it from a sequential-modular pass instead. From a start in its basin Newton
/// converges in a few iterations (every shipped flowsheet without recycles but one in at most 13);
/// a long run of damped steps means the cold guess is far from the solution somewhere in the plant,
/// and the step length the line search and the bounds allow is that of the worst unit, so that on a
/// train of N columns the iterations grow with N (7 for one column A, 42 for 64, 148 for 256). The
/// pass solves each unit from its own inlet in flow order, in time linear in N.
const AUTO_NEWTON_BUDGET: usize = 20;

/// `auto` on a plant without recycles: whole-plant Newton from the cold start `x0`; if it has not
/// converged within [`AUTO_NEWTON_BUDGET`] iterations, Newton from a sequential-modular pass to
/// `loose`; if that fails too, whole-plant Newton from the cold start with every iteration and the
/// continuation `settings` allow (the solve of `method` eo, whose first iterations the budgeted run
/// repeats exactly). A plant that converges within the budget gets the same solve as before the
/// budget existed.
fn without_recycles(
    plant: &Plant,
    u: &[f64],
    x0: &[f64],
    settings: &StrategySettings,
    loose: &SmSettings,
    observer: &mut dyn FnMut(Progress<'_>),
) -> Result<Solution, SolveError> {
    let budget = NewtonSettings {
        max_iter: AUTO_NEWTON_BUDGET.min(settings.newton.max_iter),
        pseudo_transient: false,
        ..settings.newton.clone()
    };
    let eo = |x0: &[f64], observer: &mut dyn FnMut(Progress<'_>)| {
        steady_state_observed(plant, u, Some(x0), &settings.newton, &mut |r| observer(Progress::Newton(r)))
    };
    let mut sm = None;
    let ss = match steady_state_within(plant, u, x0, &budget, &mut |r| observer(Progress::Newton(r))) {
        Some(done) => done?,
        None => {
            let pass = solve_sequential_observed(plant, u, Some(x0), loose, &mut |p| observer(Progress::Pass(p)));
            match pass.map(|sol| (eo(&sol.x, observer), sol.report)) {
                Ok((Ok(ss), report)) => {
                    sm = Some(report);
                    ss
                }
                _ => eo(x0, observer)?,
            }
        }
    };
    Ok(Solution {
        x: ss.x,
        u: ss.u,
        sm,
        sm_failure: None,
        newton: Some(ss.report),
        warnings: ss.warnings,
        closed_loops: None,
    })
}

/// The one steady-state entry point of the library, the CLI and the tests: [`steady_state_by`] at
/// the plant's input values with the numerical degrees-of-freedom probe, so that a steady state is
/// reported only where the plant's Jacobian is nonsingular, i.e. where it is an isolated solution.
/// Every Newton solve probes its solution ([`crate::steady_state`]); a solve that fails is
/// explained by the probe at the cold-start guess (an uncontrolled level, a flow set twice), and a
/// state found by the sequential-modular pass alone is probed where the guess was singular. A null
/// direction of the guess alone (only a dry tray of the guess) neither stops a plant that converges
/// nor lets a plant with a free inventory report one of its infinitely many steady states. Every
/// reported state passed the certificate ([`crate::certify`]).
pub fn converge(plant: &Plant, settings: &StrategySettings) -> Result<Solution, SolveError> {
    converge_observed(plant, settings, &mut |_| {})
}

/// [`converge`] reporting every sequential-modular pass and Newton iteration to `observer`.
pub fn converge_observed(
    plant: &Plant,
    settings: &StrategySettings,
    observer: &mut dyn FnMut(Progress<'_>),
) -> Result<Solution, SolveError> {
    let u = plant.input_values();
    let x0 = plant.initial_guess_at(&u);
    if let Err(e @ DofError::Count { .. }) = dof_check(plant, &u, &x0, DofProbe::Structural) {
        return Err(SteadyError::Dof(e).into());
    }
    let at_guess = || dof_check(plant, &u, &x0, DofProbe::Numerical);
    let sol = match steady_state_by(plant, &u, settings, observer) {
        Ok(sol) => sol,
        Err(e @ SolveError::Eo(SteadyError::Dof(_))) => return Err(e),
        Err(e) => match super::closing::close_from_open(plant, settings, observer) {
            Some(sol) if !e.is_user_error() => sol,
            _ => return Err(at_guess().map_or_else(|dof| SteadyError::Dof(dof).into(), |()| e)),
        },
    };
    // A Newton solution was probed where it was found; the pass's alone only if the guess is
    // singular (a pass solves unit by unit and cannot see a free inventory).
    if sol.newton.is_none() && at_guess().is_err() {
        dof_check(plant, &u, &sol.x, DofProbe::Numerical).map_err(SteadyError::Dof)?;
    }
    Ok(sol)
}
