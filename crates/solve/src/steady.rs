//! Whole-plant steady state: the degrees-of-freedom check, then Newton on `f(x, u) = 0`.

use plantwide_flowsheet::Plant;
use plantwide_model::VarKind;
use plantwide_units::Dimension;

use crate::certify::{CertificateFailure, Warning, certify};
use crate::rank::{self, Rank};
use crate::specs::SteadySystem;
use crate::{NewtonReport, NewtonSettings, NewtonStatus, System, maximum_matching, solve_steady_observed};

/// The plant at fixed inputs `u`, seen as a nonlinear system.
pub struct PlantSystem<'a> {
    /// The plant.
    pub plant: &'a Plant,
    /// Input values (SI).
    pub u: &'a [f64],
    mass: Vec<(usize, usize)>,
}

impl<'a> PlantSystem<'a> {
    /// Wrap a plant at inputs `u`.
    pub fn new(plant: &'a Plant, u: &'a [f64]) -> PlantSystem<'a> {
        let mut mass = Vec::new();
        for b in plant.blocks() {
            for k in 0..b.layout.n_own().min(b.n_eq) {
                if plant.vars()[b.own_offset + k].spec.kind == VarKind::Differential {
                    mass.push((b.eq_offset + k, b.own_offset + k));
                }
            }
        }
        PlantSystem { plant, u, mass }
    }
}

impl System for PlantSystem<'_> {
    fn n(&self) -> usize {
        self.plant.n_vars()
    }
    fn residual(&self, x: &[f64], r: &mut [f64]) {
        self.plant.residual(x, self.u, 0.0, r);
    }
    fn jacobian(&self, x: &[f64], r: &mut [f64], jac: &mut Vec<(usize, usize, f64)>) {
        let mut ju = Vec::new();
        self.plant.jacobian(x, self.u, 0.0, r, jac, &mut ju);
    }
    fn nominal(&self, i: usize) -> f64 {
        self.plant.vars()[i].spec.nominal
    }
    fn bounds(&self, i: usize) -> (f64, f64) {
        let s = &self.plant.vars()[i].spec;
        (s.lower, s.upper)
    }
    fn mass(&self) -> Vec<(usize, usize)> {
        self.mass.clone()
    }
}

/// A well-posedness problem found before Newton is attempted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DofError {
    /// Equations and variables do not match in number.
    #[error("{file}: the plant has {n_eqs} equations for {n_vars} variables: {hint}")]
    Count {
        /// Flowsheet file.
        file: String,
        /// Number of equations.
        n_eqs: usize,
        /// Number of variables.
        n_vars: usize,
        /// What would fix it.
        hint: String,
    },
    /// Some variables are not determined (structurally or numerically).
    #[error("{file}: the steady state is not determined: {explanation}{}", newton_note(.newton))]
    Underdetermined {
        /// Flowsheet file.
        file: String,
        /// Which variables are loose and what would fix it.
        explanation: String,
        /// How Newton ended, when the numerical probe explains a failed Newton: a singular
        /// Jacobian at one point is a diagnosis, confirmed by the failure, not a proof.
        newton: Option<String>,
    },
}

/// The holdups on their floor at a failed solve's last iterate, said as the certificate says them.
fn floor_note(at_floor: &[String]) -> String {
    crate::certify::hint(at_floor).replacen("; ", "; at the last iterate ", 1)
}

fn newton_note(newton: &Option<String>) -> String {
    newton.as_ref().map_or(String::new(), |n| {
        format!(
            " (a diagnosis from the Jacobian at the starting point and after 3 pseudo-transient steps, made because Newton failed: {n})"
        )
    })
}

/// `history (iteration: scaled residual) 1: r1, 2: r2, …` with the first three and the last five
/// iterations.
pub fn history_summary(report: &NewtonReport) -> String {
    let h = &report.history;
    let fmt = |r: &crate::IterationRecord| {
        let ptc = if r.pseudo_dt.is_some() { " (pseudo-transient)" } else { "" };
        format!("{}: {:.2e}{ptc}", r.iter + 1, r.residual)
    };
    let mut items: Vec<String> = h.iter().take(3).map(fmt).collect();
    if h.len() > 8 {
        items.push("…".into());
    }
    items.extend(h.iter().skip(h.len().saturating_sub(5).max(3)).map(fmt));
    format!("history (iteration: scaled residual) {}", items.join(", "))
}

/// How thorough the degrees-of-freedom check is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DofProbe {
    /// Equation count and structural rank only (cheap: O(nnz · n) at worst).
    Structural,
    /// Also the numerical null-space probe (sparse estimates of the extreme singular values and
    /// the null direction, O(nnz) per iteration).
    Numerical,
}

/// Degrees-of-freedom check at the point `x` (the varied inputs of design specs at their values in
/// `u`): equation count, structural rank (maximum matching) and, with [`DofProbe::Numerical`], a
/// numerical null-space probe that names the inventory or variable left free (an uncontrolled
/// level, a flow fixed at both ends, a spec its input cannot move). Each design spec adds one
/// unknown (its input) and one equation ([`crate::specs`]).
pub fn dof_check(plant: &Plant, u: &[f64], x: &[f64], probe: DofProbe) -> Result<(), DofError> {
    let file = plant.file().to_string();
    let (n_eqs, n_vars) = (plant.n_eqs(), plant.n_vars());
    if n_eqs != n_vars {
        let hint = if n_eqs > n_vars {
            "a flow is set twice — e.g. a valve or pump in flow mode downstream of a vessel whose outflow is not `free`"
                .to_string()
        } else {
            "a flow is set nowhere — e.g. a vessel with a `free` outflow but no valve or pump after it".to_string()
        };
        return Err(DofError::Count { file, n_eqs, n_vars, hint });
    }
    let sys = SteadySystem::new(plant, u);
    let z = sys.unknowns(x);
    let n = sys.n();
    let mut r = vec![0.0; n];
    let mut jac = Vec::new();
    sys.jacobian(&z, &mut r, &mut jac);
    let entries: Vec<(usize, usize)> = jac.iter().map(|&(i, j, _)| (i, j)).collect();
    let m = maximum_matching(n, n, &entries);
    let loose = m.unmatched_cols();
    if !loose.is_empty() {
        return Err(DofError::Underdetermined {
            file,
            explanation: explain_loose(plant, &loose, "no equation is left to determine"),
            newton: None,
        });
    }
    if probe == DofProbe::Numerical && n > 0 {
        // A plant that is ill-posed is singular at every consistent point; a guess can be singular
        // by accident (a component absent from a loop's measurement at a linear profile). Only a
        // null direction found at the guess and again after a few pseudo-transient steps (which
        // satisfy the algebraic equations and move the inventories along the plant's dynamics) is
        // reported. The probe removes the controllers' output limits: a clamped output no longer
        // depends on its measurement, which makes a well-posed plant singular (a level loop
        // saturated at a cold start).
        let relaxed = SteadySystem::new(plant, u).relaxed();
        let Some(_) = null_direction(&relaxed, &z) else { return Ok(()) };
        let mut zp = z.clone();
        crate::pseudo_transient_steps(&sys, &mut zp, 3, 10.0);
        if let Some(idx) = null_direction(&relaxed, &zp) {
            return Err(DofError::Underdetermined {
                file,
                explanation: explain_loose(
                    plant,
                    &idx,
                    "these variables can move together without changing any equation",
                ),
                newton: None,
            });
        }
    }
    Ok(())
}

/// The unknowns spanning a numerical null direction of the scaled Jacobian at `z`, largest first,
/// or `None` if the smallest singular value is not negligible (≤ 10⁻¹² of the largest): the sparse
/// estimate of [`crate::rank`], whose inverse-iteration vector is the direction.
fn null_direction(sys: &SteadySystem<'_>, z: &[f64]) -> Option<Vec<usize>> {
    let n = sys.n();
    let mut r = vec![0.0; n];
    let mut jac = Vec::new();
    sys.jacobian(z, &mut r, &mut jac);
    let a = scaled(sys, z, jac);
    let direction = |v: &[f64]| {
        let null: Vec<f64> = v.iter().map(|a| a.abs()).collect();
        let top = null.iter().cloned().fold(0.0, f64::max);
        let mut idx: Vec<usize> = (0..n).filter(|&j| null[j] > 0.05 * top).collect();
        idx.sort_by(|&a, &b| null[b].total_cmp(&null[a]));
        idx
    };
    match rank::estimate(n, &a) {
        Rank::Estimated { sigma_max, sigma_min, .. } if sigma_min > 1e-12 * sigma_max => None,
        Rank::Estimated { v, .. } | Rank::Singular { v } => Some(direction(&v)),
        Rank::Pivotless(col) => Some(col.into_iter().collect()),
    }
}

/// The Jacobian triplets with duplicates summed, columns scaled by their unknowns' sizes
/// ([`own_size`]) and rows by their largest entry.
fn scaled(sys: &SteadySystem<'_>, z: &[f64], mut jx: Vec<(usize, usize, f64)>) -> Vec<(usize, usize, f64)> {
    jx.sort_unstable_by_key(|t| (t.0, t.1));
    let scale: Vec<f64> = (0..sys.n()).map(|j| own_size(sys, z, j, TRACE_FLOOR)).collect();
    let mut a: Vec<(usize, usize, f64)> = Vec::with_capacity(jx.len());
    for (i, j, v) in jx {
        let v = v * scale[j];
        match a.last_mut() {
            Some(last) if (last.0, last.1) == (i, j) => last.2 += v,
            _ => a.push((i, j, v)),
        }
    }
    let mut row_max = vec![0.0f64; sys.n()];
    a.iter().for_each(|&(i, _, v)| row_max[i] = row_max[i].max(v.abs()));
    a.iter_mut().filter(|t| row_max[t.0] > 0.0).for_each(|t| t.2 /= row_max[t.0]);
    a
}

/// Smallest size, relative to its nominal value, that Newton's stopping test gives a trace
/// amount: a trace is judged relative to itself down to 1e-4 of its nominal value, below that to
/// 1e-4 of the nominal value (so to 1e-14 of a mole fraction at the default tolerance). Lower, a
/// component that is absent (a pure feed's other fraction, 0 by `1 − Σz`) would be held to the
/// round-off that the LU leaves on it, 2.5e-19 in a CSTR loop, which no iteration removes.
pub const STOP_FLOOR: f64 = 1e-4;

/// Smallest size, relative to its nominal value, that the probe gives a trace amount.
const TRACE_FLOOR: f64 = 1e-12;

/// The size of unknown `j` at `z` that the probe and Newton's stopping test
/// ([`crate::System::size`]) scale its column by: its nominal value, except
/// for an amount of one component (a mole fraction, bounded by [0, 1], or a component holdup,
/// bounded below by 0 and no total inventory), whose size is its own value (between `floor` times
/// the nominal value and the nominal value).
///
/// A trace component's balances are homogeneous in its own amounts, so what determines them is
/// relative: a bottoms mole fraction held at 1e-9 by a PI loop moves by a factor when boilup
/// and reflux move together, which is a change of about 1e-9 on the nominal scale of a mole
/// fraction. Scaled by nominal values, that loop's row would see every such move as nothing and
/// the smallest singular value would be about the trace's size (1.5e-12 on a methanol/water
/// column with xB = 3e-12), below the probe's 1e-12 threshold on a plant whose steady state is
/// isolated. A positive diagonal column scaling does not change the rank, only what the threshold
/// measures: on the relative scale of the trace the same direction is a change of order one.
///
/// The stopping test has the same blind spot: the row `e = sp − pv` of a PI loop holding a bottoms
/// fraction at 7.24e-9 weighs on the nominal scale its error of 1.4e-13, a miss of 2e-5 relative,
/// as 1.4e-13, far below the tolerance; at the stopping test's floor of sizes ([`STOP_FLOOR`],
/// higher than the probe's) it weighs 1.4e-9, above it.
pub(crate) fn own_size(sys: &SteadySystem<'_>, z: &[f64], j: usize, floor: f64) -> f64 {
    let nominal = sys.nominal(j);
    let Some(v) = sys.plant_var(j) else { return nominal };
    let fraction = v.dim == Dimension::DIMENSIONLESS && v.lower == 0.0 && v.upper == 1.0;
    let component = v.dim == Dimension::AMOUNT && v.lower == 0.0 && !v.inventory;
    if fraction || component { z[j].abs().clamp(floor * nominal, nominal) } else { nominal }
}

fn explain_loose(plant: &Plant, vars: &[usize], why: &str) -> String {
    let paths: Vec<String> = vars.iter().take(8).map(|&j| crate::specs::unknown_path(plant, j)).collect();
    let inventories: Vec<&str> = vars
        .iter()
        .filter(|&&j| j < plant.n_vars() && plant.vars()[j].spec.kind == VarKind::Differential)
        .map(|&j| plant.vars()[j].path.as_str())
        .collect();
    let mut s = if paths.is_empty() {
        format!("{why}: the sparse LU finds no pivot, even with a diagonal shift, and cannot name them")
    } else {
        format!("{why}: {}", paths.join(", "))
    };
    if vars.len() > 8 {
        s.push_str(&format!(" and {} more", vars.len() - 8));
    }
    if !inventories.is_empty() {
        let units: Vec<&str> = {
            let mut u: Vec<&str> = inventories.iter().map(|p| p.split('.').next().unwrap_or(p)).collect();
            u.dedup();
            u
        };
        s.push_str(&format!(
            ". The inventory of {} is uncontrolled at steady state: nothing ties its holdup to a steady value — add a level (or pressure) controller on it, or give it an outflow that depends on its level (a valve)",
            units.iter().map(|u| format!("`{u}`")).collect::<Vec<_>>().join(", ")
        ));
    }
    if vars.iter().any(|&j| j >= plant.n_vars()) {
        s.push_str(
            ". A varied input is among them: its spec's variable does not respond to it here (or two specs ask the same of their inputs) — vary an input that moves the held variable",
        );
    }
    s
}

/// A converged (or failed) steady state.
#[derive(Debug, Clone)]
pub struct SteadyState {
    /// Variable values (SI).
    pub x: Vec<f64>,
    /// Input values used (SI).
    pub u: Vec<f64>,
    /// Newton report.
    pub report: NewtonReport,
    /// Controllers that hold their output at a limit with the measurement off setpoint.
    pub warnings: Vec<Warning>,
}

/// Why a steady state could not be found.
#[derive(Debug, Clone, thiserror::Error)]
pub enum SteadyError {
    /// The problem is ill-posed.
    #[error(transparent)]
    Dof(#[from] DofError),
    /// Newton did not converge.
    #[error(transparent)]
    NotConverged(Box<ConvergenceFailure>),
    /// Newton converged to a point that fails the steady-state certificate.
    #[error(transparent)]
    Certificate(Box<CertificateFailure>),
}

/// A steady-state solve that did not converge: where and how it failed.
#[derive(Debug, Clone, thiserror::Error)]
#[error(
    "{file}: steady state not found ({status:?} after {iterations} iterations, scaled residual {residual:.3e}); worst equation: {equation} (variable {variable}, scaled residual {worst:.3e}){}{specs}; {}", floor_note(.at_floor), history_summary(.report)
)]
pub struct ConvergenceFailure {
    /// Flowsheet file.
    pub file: String,
    /// Solver status.
    pub status: NewtonStatus,
    /// Iterations.
    pub iterations: usize,
    /// Final scaled residual.
    pub residual: f64,
    /// Name of the worst equation.
    pub equation: String,
    /// Path of the variable that equation belongs to.
    pub variable: String,
    /// Its scaled residual.
    pub worst: f64,
    /// Total holdups resting on their lower bound at the last iterate.
    pub at_floor: Vec<String>,
    /// The design specs at the last iterate (empty without specs): each varied input's value, the
    /// offset the plant gives with it held there (or at its start, where the plant has no steady
    /// state there) and which way it would have to move ([`crate::specs::standing`]).
    pub specs: String,
    /// The full report with the iteration history.
    pub report: NewtonReport,
    /// The last iterate.
    pub x: Vec<f64>,
}

/// Solve the plant's steady state at inputs `u` from `x0` (or the cold-start guess). The structural
/// DOF check runs first; a converged point is certified and checked to be isolated (the numerical
/// probe at the solution); if Newton fails, the numerical probe runs to explain an ill-posed plant.
pub fn steady_state(
    plant: &Plant,
    u: &[f64],
    x0: Option<&[f64]>,
    settings: &NewtonSettings,
) -> Result<SteadyState, SteadyError> {
    steady_state_observed(plant, u, x0, settings, &mut |_| {})
}

/// [`steady_state`] reporting every iteration to `observer`. With design specs
/// ([`Plant::specs`]), the varied inputs are unknowns too, starting from their values in `u`; the
/// returned `u` carries the values that meet the specs.
pub fn steady_state_observed(
    plant: &Plant,
    u: &[f64],
    x0: Option<&[f64]>,
    settings: &NewtonSettings,
    observer: &mut dyn FnMut(&crate::IterationRecord),
) -> Result<SteadyState, SteadyError> {
    let x_start = match x0 {
        Some(x0) => x0.to_vec(),
        None => plant.initial_guess_at(u),
    };
    dof_check(plant, u, &x_start, DofProbe::Structural)?;
    let sys = SteadySystem::new(plant, u);
    let mut z = sys.unknowns(&x_start);
    let report = solve_steady_observed(&sys, &mut z, settings, observer);
    if report.status == NewtonStatus::Converged {
        return checked(plant, &sys, &z, report);
    }
    let (x, _) = sys.split(&z);
    if let Err(mut e) = dof_check(plant, u, &x_start, DofProbe::Numerical) {
        if let DofError::Underdetermined { newton, .. } = &mut e {
            *newton = Some(format!(
                "{:?} after {} iterations, scaled residual {:.3e}; {}",
                report.status,
                report.iterations,
                report.residual,
                history_summary(&report)
            ));
        }
        return Err(e.into());
    }
    let (eq, worst) = report.worst.unwrap_or((0, f64::NAN));
    let equation = crate::specs::equation_name(plant, eq);
    let variable = match plant.equation_variable(eq) {
        Some(j) if eq < plant.n_eqs() => plant.vars()[j].path.clone(),
        _ => plant.specs().get(eq.wrapping_sub(plant.n_eqs())).map_or_else(|| "-".into(), |s| s.vary.clone()),
    };
    Err(SteadyError::NotConverged(Box::new(ConvergenceFailure {
        file: plant.file().to_string(),
        status: report.status,
        iterations: report.iterations,
        residual: report.residual,
        equation,
        variable,
        worst,
        at_floor: crate::certify::floors_anywhere(plant, &x),
        specs: crate::specs::standing::note(plant, u, &z),
        report,
        x,
    })))
}

/// [`steady_state_observed`] within `settings.max_iter` Newton iterations (and the continuation if
/// `settings` asks for it), for a caller with another way to go on: `None` when Newton did not
/// converge, without the numerical probe that explains a failure; a converged point is checked as
/// [`steady_state_observed`] checks it. The iterates are those of [`steady_state_observed`] from
/// the same start, so a solve that converges within the budget is the same solve.
pub(crate) fn steady_state_within(
    plant: &Plant,
    u: &[f64],
    x0: &[f64],
    settings: &NewtonSettings,
    observer: &mut dyn FnMut(&crate::IterationRecord),
) -> Option<Result<SteadyState, SteadyError>> {
    if let Err(e) = dof_check(plant, u, x0, DofProbe::Structural) {
        return Some(Err(e.into()));
    }
    let sys = SteadySystem::new(plant, u);
    let mut z = sys.unknowns(x0);
    let report = solve_steady_observed(&sys, &mut z, settings, observer);
    (report.status == NewtonStatus::Converged).then(|| checked(plant, &sys, &z, report))
}

/// A converged Newton solve `z` certified ([`certify`]) and probed for a singular Jacobian at the
/// solution: an isolated steady state only, since a Newton step on a singular Jacobian can still
/// land on one of infinitely many solutions (a free inventory) when round-off leaves a tiny pivot
/// rather than a zero one; the sparse probe at the solution refuses it.
fn checked(plant: &Plant, sys: &SteadySystem<'_>, z: &[f64], report: NewtonReport) -> Result<SteadyState, SteadyError> {
    let (x, u) = sys.split(z);
    let warnings = certify(plant, &x, &u).map_err(|e| SteadyError::Certificate(Box::new(e)))?;
    dof_check(plant, &u, &x, DofProbe::Numerical)?;
    Ok(SteadyState { x, u, report, warnings })
}
