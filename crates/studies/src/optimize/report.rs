//! The [`Optimum`] of a converged SQP: limits and their shadow prices in display units, the
//! active set and the reduced Hessian; and the violated limits of an infeasible end.

use faer::Mat;
use indexmap::IndexMap;
use plantwide_analysis::select::Signal;
use plantwide_flowsheet::optimization::Sense;

use super::certificate::{Directions, active_rows, directions, eigenvalues, reduced_hessian};
use super::plant::{PlantNlp, State};
use super::request::Problem;
use super::sqp::{Bounds, Solution};
use super::{LimitResult, OptimizeError, Optimum, ReducedHessian};

/// A limit counts as active within this (scaled) distance, or with a nonzero multiplier.
const ACTIVE: f64 = 1e-7;

/// `PATH:min` / `PATH:max`.
fn name(path: &str, lower: bool) -> String {
    format!("{path}:{}", if lower { "min" } else { "max" })
}

/// Each violated limit at `state`, with its value and the limit in display units.
pub(super) fn violations(problem: &Problem, state: &State) -> Vec<String> {
    let mut out = Vec::new();
    let mut check = |s: &Signal, value: f64, lo: f64, hi: f64| {
        let unit = if s.unit == "-" { String::new() } else { format!(" {}", s.unit) };
        let shown = |v: f64| format!("{:.6}{unit}", s.display_value(v));
        let size = [lo, hi, value].into_iter().filter(|v| v.is_finite()).fold(0.0_f64, |m, v| m.max(v.abs()));
        let tol = 1e-9 * size;
        if value < lo - tol {
            out.push(format!("`{}` = {} is below its min {}", s.path, shown(value), shown(lo)));
        } else if value > hi + tol {
            out.push(format!("`{}` = {} is above its max {}", s.path, shown(value), shown(hi)));
        }
    };
    for c in &problem.constraints {
        check(&c.signal, state.x[c.signal.index], c.lo, c.hi);
    }
    for d in &problem.dofs {
        check(&d.signal, state.u[d.signal.index], d.lb, d.ub);
    }
    out
}

/// The sign that makes the objective a cost.
pub(super) fn sign(sense: Sense) -> f64 {
    if sense == Sense::Maximize { -1.0 } else { 1.0 }
}

/// The limits of the constraints and bounds with their activity and shadow prices; the indices
/// of the active constraints and bounds.
fn limits(
    nlp: &PlantNlp<'_>,
    problem: &Problem,
    bounds: &Bounds,
    sol: &Solution<State>,
) -> (Vec<LimitResult>, Vec<usize>, Vec<usize>) {
    let obj = &problem.objective;
    let to_objective = sign(problem.sense) * nlp.scale_f / obj.factor;
    let (mut out, mut act_c, mut act_b) = (Vec::new(), Vec::new(), Vec::new());
    let mut push = |s: &Signal, value: f64, si: (f64, f64), scaled: (f64, f64, f64), multiplier: f64, scale: f64| {
        let (at, lo, hi) = scaled;
        let mut any = false;
        for (lower, bound, limit) in [(true, lo, si.0), (false, hi, si.1)] {
            if !bound.is_finite() {
                continue;
            }
            let on_side = multiplier != 0.0 && (multiplier > 0.0) == lower;
            let active = on_side || ((at - bound).abs() <= ACTIVE && multiplier == 0.0);
            any |= active;
            let price = if on_side { multiplier * to_objective * s.factor / scale } else { 0.0 };
            out.push(LimitResult {
                name: name(&s.path, lower),
                path: s.path.clone(),
                unit: s.unit.clone(),
                value: s.display_value(value),
                limit: s.display_value(limit),
                active,
                shadow_price: price,
            });
        }
        any
    };
    for (i, c) in problem.constraints.iter().enumerate() {
        let x = sol.point.state.x[c.signal.index];
        let scaled = (sol.point.c[i], bounds.lo[i], bounds.hi[i]);
        if push(&c.signal, x, (c.lo, c.hi), scaled, sol.y[i], nlp.scale_c[i]) {
            act_c.push(i);
        }
    }
    for (j, d) in problem.dofs.iter().enumerate() {
        let u = sol.point.state.u[d.signal.index];
        let scaled = (sol.v[j], bounds.lb[j], bounds.ub[j]);
        if push(&d.signal, u, (d.lb, d.ub), scaled, sol.mu[j], nlp.scale_u[j]) {
            act_b.push(j);
        }
    }
    (out, act_c, act_b)
}

/// The active constraints and bounds of a converged SQP, and the split of the degrees of freedom
/// into free and dependent ones.
pub(super) fn active_set(
    nlp: &PlantNlp<'_>,
    problem: &Problem,
    bounds: &Bounds,
    sol: &Solution<State>,
) -> (Vec<usize>, Vec<usize>, Directions) {
    let (_, act_c, act_b) = limits(nlp, problem, bounds, sol);
    let n = problem.dofs.len();
    let dirs = directions(n, &active_rows(n, &sol.point.a, &act_c, &act_b));
    (act_c, act_b, dirs)
}

/// The optimum of a converged SQP, with its certificate.
pub(super) fn optimum(
    nlp: &mut PlantNlp<'_>,
    problem: &Problem,
    bounds: &Bounds,
    sol: &Solution<State>,
) -> Result<Optimum, OptimizeError> {
    let (limits, act_c, act_b) = limits(nlp, problem, bounds, sol);
    let n = problem.dofs.len();
    let dirs = directions(n, &active_rows(n, &sol.point.a, &act_c, &act_b));
    let certificate_failure = |m: String| OptimizeError::NotConverged {
        reason: format!("the reduced Hessian could not be measured: {m}"),
        iterations: sol.iterations,
        kkt: sol.kkt.max(),
    };
    let h = reduced_hessian(nlp, &sol.point.state, &sol.y, &dirs).map_err(|e| certificate_failure(e.message))?;
    let scaled_eigenvalues = eigenvalues(&h);
    let largest = scaled_eigenvalues.iter().fold(1.0_f64, |m, e| m.max(e.abs()));
    if let Some(&least) = scaled_eigenvalues.first().filter(|&&e| e < -1e-6 * largest) {
        return Err(OptimizeError::NotConverged {
            reason: format!(
                "a KKT point that is no minimum: the reduced Hessian has the eigenvalue {least:.3e} (scaled) along the free inputs"
            ),
            iterations: sol.iterations,
            kkt: sol.kkt.max(),
        });
    }
    let reduced_hessian = in_display_units(nlp, problem, &dirs.free, &h, scaled_eigenvalues);
    let obj = &problem.objective;
    let state = &sol.point.state;
    let mut values = IndexMap::new();
    for d in &problem.dofs {
        values.insert(d.signal.path.clone(), state.u[d.signal.index]);
    }
    values.insert(obj.path.clone(), state.x[obj.index]);
    for c in &problem.constraints {
        values.insert(c.signal.path.clone(), state.x[c.signal.index]);
    }
    let active: Vec<String> = limits.iter().filter(|l| l.active).map(|l| l.name.clone()).collect();
    let multipliers = limits.iter().filter(|l| l.active).map(|l| (l.name.clone(), l.shadow_price)).collect();
    Ok(Optimum {
        objective: obj.display_value(state.x[obj.index]),
        values,
        active,
        multipliers,
        kkt_residual: sol.kkt.max(),
        objective_path: obj.path.clone(),
        objective_unit: obj.unit.clone(),
        sense: problem.sense,
        limits,
        reduced_hessian,
        iterations: sol.iterations,
        plant_solves: nlp.solves,
    })
}

/// The scaled reduced Hessian `h` over the free inputs, in the objective's unit per the inputs'.
fn in_display_units(
    nlp: &PlantNlp<'_>,
    problem: &Problem,
    free: &[usize],
    h: &Mat<f64>,
    scaled_eigenvalues: Vec<f64>,
) -> ReducedHessian {
    let obj = &problem.objective;
    let factor = sign(problem.sense) * nlp.scale_f / obj.factor;
    let per = |j: usize| problem.dofs[j].signal.factor / nlp.scale_u[j];
    let matrix = (0..free.len())
        .map(|a| (0..free.len()).map(|b| h[(a, b)] * factor * per(free[a]) * per(free[b])).collect())
        .collect();
    let free =
        free.iter().map(|&j| format!("{}@{}", problem.dofs[j].signal.path, problem.dofs[j].signal.unit)).collect();
    ReducedHessian { free, matrix, scaled_eigenvalues }
}
