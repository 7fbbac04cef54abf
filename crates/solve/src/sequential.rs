//! Sequential-modular (SM) steady state: the plant solved one block at a time in flow order, its
//! recycles converged by iterating on tear variables — the method of Aspen Plus, DWSIM and
//! BioSTEAM, here as a robust start for the whole-plant Newton and a diagnosis of recycle gain.
//!
//! # Design
//! - **Blocks** are *solve groups* ([`solve_groups`]): a unit or controller alone when its own
//!   equations determine its own variables, else the few blocks that must be solved together (a
//!   `free`-outflow vessel and its valve; an integrating controller and the loop it closes; a
//!   controller that measures and drives the same unit).
//! - **Local Newton.** A group is solved for its own variables with everything it reads fixed, by
//!   the same Newton (sparse LU, line search, pseudo-transient fallback) on the same
//!   `Unit::residual`/`Unit::jacobian` as the whole plant: there is no second model of any unit.
//! - **Tearing** ([`plantwide_flowsheet::tears`]): the graph of groups, with streams and signals as
//!   edges, is split into SCCs in precedence order; each recycle SCC gets a minimum tear set and a
//!   calculation order. Upstream SCCs converge before downstream ones, each with its own
//!   accelerator state, so one loop's accelerator never touches another loop's variables.
//! - **Tear convergence** ([`Accelerator`]): direct substitution, bounded Wegstein or good
//!   Broyden, chosen per SCC ([`SmSettings::per_scc`]) or automatically. A pass writes the tear
//!   guesses `t` into the torn variables, solves every group of the SCC in order (the producer of
//!   a torn variable returns its new value `φ(t)` without overwriting `t`) and measures
//!   `max_i |φ_i − t_i| / max(|t_i|, 1e-3·nominal_i)`. The SCC is converged only when that is
//!   at most [`SmSettings::tol`] (default 1e-8); the torn variables then take `φ`.
//! - **Nested loops.** Loops inside loops are either absorbed into a solve group (a controller
//!   loop inside the material recycle) or lie in the same SCC (an inner recycle inside an outer
//!   one) and are torn by one minimum set, converged together with one accelerator state;
//!   recycles nested in the precedence order (one feeding another) converge one after the other.
//! - **Log.** Passes, the residual history and the loop gain — the spectral radius of a secant
//!   model of `∂φ/∂t` — per SCC. Direct substitution removes a fraction `1 − gain` of the error per
//!   pass, and a disturbance entering the loop is amplified `1/(1 − gain)` times: a gain near 1 is a
//!   recycle near the snowball limit.
//!
//! [`steady_state_by`] chooses between SM, whole-plant Newton (EO) and `auto` (SM to a loose
//! tolerance, then Newton).
//!
//! Like `steady.rs`, this module is a bridge from a [`Plant`]: it sees blocks and streams, while
//! the Newton it calls sees only a [`crate::System`] (one per solve group).

mod accel;
mod closing;
mod groups;
mod plan;
mod report;
mod strategy;

use petgraph::graph::NodeIndex;
use plantwide_flowsheet::Plant;
use plantwide_flowsheet::tears::Scc;
use serde::{Deserialize, Serialize};

pub use accel::Accelerator;
pub use groups::{SolveGroup, solve_groups};
pub use plan::{SequentialPlan, plan};
pub use report::{PassRecord, SccReport, SmReport};
pub use strategy::{
    Method, Progress, Solution, SolveError, StrategySettings, converge, converge_observed, fix_design_point,
    steady_state_by,
};

use crate::newton::solve_steady_reusing;
use crate::sparse::SparseLu;
use crate::{DofError, DofProbe, NewtonSettings, NewtonStatus, dof_check};
use accel::{TearIteration, WegsteinBounds};
use groups::{GroupLayout, GroupSystem};

/// Settings of the sequential-modular pass.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SmSettings {
    /// Accelerator of every SCC not listed in `per_scc` (default: `auto` — Wegstein for one torn
    /// connection, Broyden for several).
    pub accelerator: Accelerator,
    /// Per-SCC choices: the name of any block in the SCC, and its accelerator (default: none).
    pub per_scc: Vec<(String, Accelerator)>,
    /// Tolerance on the scaled tear residual `max_i |φ_i − t_i| / max(|t_i|, 1e-3·nominal_i)`
    /// (default: 1e-8).
    pub tol: f64,
    /// Maximum passes per SCC (default: 300).
    pub max_passes: usize,
    /// Direct-substitution passes before Wegstein accelerates (default: 2).
    pub wegstein_wait: usize,
    /// Lower bound of Wegstein's q (default: −5).
    pub q_min: f64,
    /// Upper bound of Wegstein's q (default: 0).
    pub q_max: f64,
    /// Local Newton on each group (default: tolerance 1e-12, otherwise as the whole-plant Newton).
    pub local: NewtonSettings,
}

impl Default for SmSettings {
    fn default() -> Self {
        SmSettings {
            accelerator: Accelerator::Auto,
            per_scc: Vec::new(),
            tol: 1e-8,
            max_passes: 300,
            wegstein_wait: 2,
            q_min: -5.0,
            q_max: 0.0,
            local: NewtonSettings { tol: 1e-12, ..NewtonSettings::default() },
        }
    }
}

impl SmSettings {
    /// Check every field; the error names the field and what would fix it.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let bad = |field: &'static str, got: String, fix: &'static str| Err(SettingsError { field, got, fix });
        if !(self.tol.is_finite() && self.tol > 0.0) {
            return bad("sm.tol", self.tol.to_string(), "a positive number, e.g. 1e-8");
        }
        if self.max_passes == 0 {
            return bad("sm.max_passes", "0".into(), "at least 1");
        }
        if !(self.q_min.is_finite() && self.q_max.is_finite() && self.q_min <= self.q_max && self.q_max < 1.0) {
            let got = format!("[{}, {}]", self.q_min, self.q_max);
            return bad("sm.q_min, sm.q_max", got, "q_min ≤ q_max < 1 for Wegstein's q; the usual bounds are [−5, 0]");
        }
        if !(self.local.tol.is_finite() && self.local.tol > 0.0) {
            return bad("sm.local.tol", self.local.tol.to_string(), "a positive number, e.g. 1e-10");
        }
        Ok(())
    }
}

/// A sequential-modular setting out of its range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field} = {got} is out of range; it must be {fix}")]
pub struct SettingsError {
    /// The setting (`sm.tol`).
    pub field: &'static str,
    /// Its value.
    pub got: String,
    /// What it must be.
    pub fix: &'static str,
}

/// A local Newton that failed: which group, and its worst equation.
#[derive(Debug, Clone, thiserror::Error)]
#[error(
    "{file}: sequential-modular pass: the local Newton on `{group}` failed ({status:?} after {iterations} iterations, scaled residual {residual:.3e}); worst equation: {equation}"
)]
pub struct LocalFailure {
    /// Flowsheet file.
    pub file: String,
    /// Name of the group.
    pub group: String,
    /// Newton's status.
    pub status: NewtonStatus,
    /// Iterations used.
    pub iterations: usize,
    /// Final scaled residual.
    pub residual: f64,
    /// Name of the worst equation.
    pub equation: String,
    /// The plant vector when it failed.
    pub x: Vec<f64>,
}

/// Tears that did not converge.
#[derive(Debug, Clone, thiserror::Error)]
#[error(
    "{file}: sequential-modular pass: recycle {index} ({members}) not converged after {passes} passes by {method}: tear residual {residual:.3e} > tolerance {tol:.1e}{gain}"
)]
pub struct TearFailure {
    /// Flowsheet file.
    pub file: String,
    /// Recycle number (1-based, precedence order).
    pub index: usize,
    /// Its groups.
    pub members: String,
    /// Passes used.
    pub passes: usize,
    /// Accelerator used.
    pub method: &'static str,
    /// Final tear residual.
    pub residual: f64,
    /// Tolerance.
    pub tol: f64,
    /// Loop-gain remark (empty if unknown).
    pub gain: String,
    /// The report so far.
    pub report: SmReport,
    /// The plant vector after the last pass.
    pub x: Vec<f64>,
}

/// Why the sequential-modular pass failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum SmError {
    /// Bad settings.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// A per-recycle setting names a block that is in no recycle.
    #[error("sm.per_scc: `{0}` is not a block of any recycle; `plantwide check` lists the recycles and their blocks")]
    NotInRecycle(String),
    /// The plant is ill-posed.
    #[error(transparent)]
    Dof(#[from] DofError),
    /// A group's local Newton failed.
    #[error(transparent)]
    Local(Box<LocalFailure>),
    /// A recycle did not converge.
    #[error(transparent)]
    NotConverged(Box<TearFailure>),
}

/// A sequential-modular steady state.
#[derive(Debug, Clone)]
pub struct SmSolution {
    /// Variable values (SI).
    pub x: Vec<f64>,
    /// Input values (SI).
    pub u: Vec<f64>,
    /// Passes, residuals and loop gains per recycle.
    pub report: SmReport,
}

/// Solve `plant` at inputs `u` sequentially from `x0` (or the cold-start guess).
pub fn solve_sequential(
    plant: &Plant,
    u: &[f64],
    x0: Option<&[f64]>,
    settings: &SmSettings,
) -> Result<SmSolution, SmError> {
    solve_sequential_observed(plant, u, x0, settings, &mut |_| {})
}

/// [`solve_sequential`] reporting every pass to `observer`.
pub fn solve_sequential_observed(
    plant: &Plant,
    u: &[f64],
    x0: Option<&[f64]>,
    settings: &SmSettings,
    observer: &mut dyn FnMut(&PassRecord),
) -> Result<SmSolution, SmError> {
    settings.validate()?;
    let mut x = x0.map_or_else(|| plant.initial_guess_at(u), <[f64]>::to_vec);
    dof_check(plant, u, &x, DofProbe::Structural)?;
    let plan = plan(plant, u, &x);
    for (name, _) in &settings.per_scc {
        let in_recycle = plan.recycles().any(|s| {
            s.order.iter().any(|&v| plan.groups[plan.graph[v]].blocks.iter().any(|&b| plant.blocks()[b].name == *name))
        });
        if !in_recycle {
            return Err(SmError::NotInRecycle(name.clone()));
        }
    }
    let layouts: Vec<GroupLayout> = plan.groups.iter().map(|g| GroupLayout::new(plant, &g.blocks)).collect();
    let mut run = Run {
        plant,
        u,
        settings,
        plan: &plan,
        layouts: &layouts,
        torn: vec![false; plant.n_vars()],
        phi: vec![0.0; plant.n_vars()],
        lus: (0..layouts.len()).map(|_| SparseLu::default()).collect(),
        report: SmReport::default(),
    };
    run.report.n_groups = plan.groups.len();
    for scc in &plan.sccs {
        if scc.is_recycle() {
            run.converge(scc, &mut x, observer)?;
        } else {
            for &v in &scc.order {
                run.solve_group(plan.graph[v], &mut x)?;
            }
        }
    }
    Ok(SmSolution { x, u: u.to_vec(), report: run.report })
}

/// State of one sequential-modular solve.
struct Run<'a> {
    plant: &'a Plant,
    u: &'a [f64],
    settings: &'a SmSettings,
    plan: &'a SequentialPlan,
    layouts: &'a [GroupLayout],
    /// Variables torn in the SCC being converged.
    torn: Vec<bool>,
    /// New values `φ` of the torn variables.
    phi: Vec<f64>,
    /// One LU per group, kept from pass to pass.
    lus: Vec<SparseLu>,
    report: SmReport,
}

impl Run<'_> {
    /// Solve group `g` for its own variables; torn ones go to `phi`, the rest into `x`.
    fn solve_group(&mut self, g: usize, x: &mut [f64]) -> Result<(), SmError> {
        let layout = &self.layouts[g];
        let mut y: Vec<f64> = layout.unknowns.iter().map(|&v| x[v]).collect();
        let sys = GroupSystem { plant: self.plant, u: self.u, base: x, layout };
        let rep = solve_steady_reusing(&sys, &mut y, &self.settings.local, &mut |_| {}, &mut self.lus[g]);
        self.report.local_iterations += rep.iterations;
        self.report.local_solves += 1;
        if rep.status != NewtonStatus::Converged {
            let equation = rep.worst.map_or_else(
                || "-".to_string(),
                |(row, _)| self.plant.equation_name(layout.global_row(self.plant, row)),
            );
            return Err(SmError::Local(Box::new(LocalFailure {
                file: self.plant.file().to_string(),
                group: self.plan.groups[g].name(self.plant),
                status: rep.status,
                iterations: rep.iterations,
                residual: rep.residual,
                equation,
                x: x.to_vec(),
            })));
        }
        for (&v, &yv) in layout.unknowns.iter().zip(&y) {
            if self.torn[v] {
                self.phi[v] = yv;
            } else {
                x[v] = yv;
            }
        }
        Ok(())
    }

    /// Converge one recycle SCC.
    fn converge(&mut self, scc: &Scc, x: &mut [f64], observer: &mut dyn FnMut(&PassRecord)) -> Result<(), SmError> {
        let (plant, plan, st) = (self.plant, self.plan, self.settings);
        let index = self.report.sccs.len() + 1;
        let tears = plan.tear_vars(scc);
        let blocks_of = |v: NodeIndex| {
            plan.groups[plan.graph[v]].blocks.iter().map(|&b| plant.blocks()[b].name.clone()).collect::<Vec<_>>()
        };
        let chosen = st
            .per_scc
            .iter()
            .find(|(name, _)| scc.order.iter().any(|&v| blocks_of(v).contains(name)))
            .map_or(st.accelerator, |(_, a)| *a);
        let method = chosen.resolve(scc.tears.len());
        let spec = |v: usize| &plant.vars()[v].spec;
        let floor: Vec<f64> = tears.iter().map(|&v| 1e-3 * spec(v).nominal).collect();
        let scale: Vec<f64> = tears.iter().zip(&floor).map(|(&v, f)| x[v].abs().max(*f)).collect();
        let bounds = tears.iter().map(|&v| (spec(v).lower, spec(v).upper)).collect();
        let wegstein = WegsteinBounds { wait: st.wegstein_wait, q_min: st.q_min, q_max: st.q_max };
        let mut iteration = TearIteration::new(method, wegstein, scale, bounds);
        let mut t: Vec<f64> = tears.iter().map(|&v| x[v]).collect();
        tears.iter().for_each(|&v| self.torn[v] = true);
        let mut rec = SccReport {
            groups: scc.order.iter().map(|&v| plan.node_name(plant, v)).collect(),
            tears: plan.tear_names(plant, scc),
            n_tear_vars: tears.len(),
            accelerator: method,
            passes: 0,
            residual: f64::INFINITY,
            history: Vec::new(),
            loop_gain: None,
            converged: false,
        };
        let mut result = Ok(());
        for pass in 1..=st.max_passes {
            tears.iter().zip(&t).for_each(|(&v, &tv)| x[v] = tv);
            for &v in &scc.order {
                if let Err(e) = self.solve_group(plan.graph[v], x) {
                    result = Err(e);
                    break;
                }
            }
            if result.is_err() {
                break;
            }
            let phi: Vec<f64> = tears.iter().map(|&v| self.phi[v]).collect();
            let err = (0..tears.len()).map(|i| (phi[i] - t[i]).abs() / t[i].abs().max(floor[i])).fold(0.0, f64::max);
            let err = if phi.iter().all(|v| v.is_finite()) { err } else { f64::INFINITY };
            rec.passes = pass;
            rec.residual = err;
            rec.history.push(err);
            observer(&PassRecord { recycle: index, pass, residual: err });
            if err <= st.tol {
                tears.iter().zip(&phi).for_each(|(&v, &p)| x[v] = p);
                rec.converged = true;
                iteration.next(&t, &phi);
                break;
            }
            if !err.is_finite() || err > 1e6 * rec.history[0].max(st.tol) {
                break;
            }
            t = iteration.next(&t, &phi);
        }
        rec.loop_gain = iteration.loop_gain();
        tears.iter().for_each(|&v| self.torn[v] = false);
        let converged = rec.converged;
        self.report.sccs.push(rec);
        result?;
        if converged {
            return Ok(());
        }
        let rec = self.report.sccs.last().expect("just pushed");
        Err(SmError::NotConverged(Box::new(TearFailure {
            file: plant.file().to_string(),
            index,
            members: rec.groups.join(", "),
            passes: rec.passes,
            method: method.name(),
            residual: rec.residual,
            tol: st.tol,
            gain: rec.loop_gain.map_or_else(String::new, report::gain_remark),
            report: self.report.clone(),
            x: x.to_vec(),
        })))
    }
}
