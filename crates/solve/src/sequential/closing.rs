//! Closing the loops from the open plant: the fallback of [`super::converge`] when a plant with
//! PI loops in auto finds no steady state from its cold start.
//!
//! A cold start guesses each controller's output as `bias + Kc·e` at the guessed measurement, so a
//! tight composition loop (Kc of 10⁴ mol/s per mole fraction) starts its reflux or boilup far from
//! anything the column can take, and the whole-plant Newton stalls. Commercial simulators converge
//! such a plant open and close the loops afterwards; this does the same as a homotopy on the
//! setpoints (Allgower & Georg, *Introduction to Numerical Continuation Methods*, 2003, ch. 1):
//! 1. every PI loop in auto with a local setpoint whose opening leaves the plant structurally
//!    well posed (a level loop's does not: its inventory would be free) is put in manual at its
//!    manual output (by default its bias, the driven input's value in the file);
//! 2. that open plant is converged;
//! 3. the loops are closed there with setpoints at the measurements they have: a steady state
//!    once each integral (and derivative filter) takes the value that keeps the output where it is,
//!    equations linear in those states, which the first Newton step of the path meets;
//! 4. the setpoints are moved to the file's along `sp(λ) = sp₀ + λ (sp₁ − sp₀)` (geometrically,
//!    `sp₀ (sp₁/sp₀)^λ`, for two positive values a decade or more apart, such as a bottoms impurity
//!    going from 1e-4 to 1e-8), each step a Newton solve from the last state; a failed step is
//!    halved, a good one lets the next double.
//!
//! The state reached at λ = 1 is the plant's own steady state, certified like any other.

use plantwide_flowsheet::{Plant, VarPath};
use plantwide_model::ControllerSpec;
use plantwide_model::controllers::Setpoint;

use super::strategy::{Progress, Solution, StrategySettings, steady_state_by};
use crate::{DofProbe, dof_check, steady_state_observed};

/// Smallest step in λ before the homotopy gives up.
const MIN_STEP: f64 = 1.0 / 64.0;
/// Most Newton solves along the path.
const MAX_SOLVES: usize = 40;

/// A loop the homotopy opens and closes again.
struct Opened {
    name: String,
    auto: usize,
    sp: usize,
    pv: usize,
}

/// The plant's steady state reached by closing its PI loops from the open plant, with a note saying
/// so; `None` when there is no loop to open or the path fails (the caller keeps its own error).
pub(super) fn close_from_open(
    plant: &Plant,
    settings: &StrategySettings,
    observer: &mut dyn FnMut(Progress<'_>),
) -> Option<Solution> {
    if !plant.specs().is_empty() {
        return None;
    }
    let target = plant.input_values();
    let loops = openable(plant, &target);
    if loops.is_empty() {
        return None;
    }
    let mut u = target.clone();
    loops.iter().for_each(|l| u[l.auto] = 0.0);
    let open = steady_state_by(plant, &u, settings, observer).ok()?;
    let mut x = open.x;
    loops.iter().for_each(|l| u[l.auto] = 1.0);
    let start: Vec<f64> = loops.iter().map(|l| x[l.pv]).collect();
    let (mut lambda, mut step, mut solves) = (0.0_f64, 1.0_f64, 0);
    while lambda < 1.0 && solves < MAX_SOLVES {
        let next = (lambda + step).min(1.0);
        for (l, &s0) in loops.iter().zip(&start) {
            u[l.sp] = along(s0, target[l.sp], next);
        }
        solves += 1;
        match steady_state_observed(plant, &u, Some(&x), &settings.newton, &mut |r| observer(Progress::Newton(r))) {
            Ok(ss) if next >= 1.0 => {
                let names: Vec<&str> = loops.iter().map(|l| l.name.as_str()).collect();
                let note = format!(
                    "converged open (loops {} in manual), then closed by moving their setpoints from the open plant's measurements in {solves} step{}",
                    names.join(", "),
                    if solves == 1 { "" } else { "s" }
                );
                return Some(Solution {
                    x: ss.x,
                    u: ss.u,
                    sm: open.sm,
                    sm_failure: None,
                    newton: Some(ss.report),
                    warnings: ss.warnings,
                    closed_loops: Some(note),
                });
            }
            Ok(ss) => {
                (x, lambda, step) = (ss.x, next, 2.0 * step);
            }
            Err(_) if step > MIN_STEP => step /= 2.0,
            Err(_) => return None,
        }
    }
    None
}

/// The setpoint at `lambda` on the path from `s0` to `s1`: geometric between two positive values a
/// decade or more apart, linear otherwise.
fn along(s0: f64, s1: f64, lambda: f64) -> f64 {
    if lambda >= 1.0 {
        return s1;
    }
    if s0 > 0.0 && s1 > 0.0 && (s1 / s0).log10().abs() >= 1.0 {
        s0 * (s1 / s0).powf(lambda)
    } else {
        s0 + lambda * (s1 - s0)
    }
}

/// The PI loops in auto with a local setpoint whose opening, one after another in file order,
/// keeps the plant structurally well posed at the cold-start guess.
fn openable(plant: &Plant, u: &[f64]) -> Vec<Opened> {
    let x0 = plant.initial_guess_at(u);
    let mut trial = u.to_vec();
    let mut loops = Vec::new();
    for (name, spec) in &plant.spec().controllers {
        let ControllerSpec::Pid(cfg) = spec else { continue };
        if cfg.tau_i.is_none() || !matches!(cfg.sp, Setpoint::Value(_)) {
            continue;
        }
        let Some(l) = opened(plant, name) else { continue };
        if trial[l.auto] < 0.5 {
            continue;
        }
        trial[l.auto] = 0.0;
        if dof_check(plant, &trial, &x0, DofProbe::Numerical).is_ok() {
            loops.push(l);
        } else {
            trial[l.auto] = 1.0;
        }
    }
    loops
}

/// Loop `name`'s inputs and measurement in the built plant.
fn opened(plant: &Plant, name: &str) -> Option<Opened> {
    let b = plant.controller(name).ok()?;
    let (auto, sp) = (plant.input(VarPath::auto(name))?, plant.input(VarPath::setpoint(name))?);
    Some(Opened { name: name.to_string(), auto, sp, pv: plant.measured_var(b)? })
}

#[cfg(test)]
mod tests {
    use super::along;

    #[test]
    fn the_path_ends_on_the_target_and_goes_geometrically_across_decades() {
        assert_eq!(along(1e-4, 1e-8, 1.0), 1e-8);
        assert!((along(1e-4, 1e-8, 0.5) - 1e-6).abs() < 1e-18);
        assert!((along(0.9, 0.95, 0.5) - 0.925).abs() < 1e-15);
        assert_eq!(along(-1.0, 1.0, 0.25), -0.5);
    }
}
