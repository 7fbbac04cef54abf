//! Steady-state gains the book's way (*Practical Distillation Control* ch. 6): each input moved
//! `± h` from the base case, the plant re-converged from the base point, and central differences
//! `G_ij = (y_i(u + h_j e_j) − y_i(u − h_j e_j)) / (2 h_j)`. The `2m` re-convergences are
//! independent and run in parallel (rayon). A re-convergence whose Newton iteration from the base
//! point fails (a slow integral loop elsewhere in a recycle plant can stall pseudo-transient
//! continuation) is repeated from scratch the way `steady` converges (sequential-modular pass, then
//! Newton); only if that fails too is the gain refused.
//!
//! **Step.** `h_j = step · |u_j|` with `step` relative (default 1e-5), or `step` SI units when
//! `u_j = 0`. Central differences err by `O(h²)`; high-purity columns are strongly curved (column
//! A: the error is about `1e4 · step²` relative, 1.5e-6 at the default step, 1.5e-4 at 1e-4).
//!
//! **Accuracy check.** After Newton converges at a perturbed point, Newton corrections
//! `δ = −J⁻¹ f` are applied (up to four, until `|δ_y|` is below `accuracy · step` times the
//! outputs' nominal size); the last `|δ_y|` bounds what the convergence left in the outputs (the
//! error after it is of order `|δ_y|²`). It must stay below `accuracy · max_i |Δy_i|` (default
//! 1e-6) for every input, or the gain is refused with the numbers that explain why (a larger step
//! would help).

use faer::Mat;
use plantwide_flowsheet::Plant;
use plantwide_solve::sequential::{StrategySettings, steady_state_by};
use plantwide_solve::sparse::SparseLu;
use plantwide_solve::{NewtonSettings, NewtonStatus, PlantSystem, solve_steady};
use rayon::prelude::*;

use crate::error::AnalysisError;

/// Settings of the perturbation gains.
#[derive(Debug, Clone, PartialEq)]
pub struct PerturbSettings {
    /// Relative step `h_j / |u_j|` (default 1e-5; `h_j = step` SI units when `u_j = 0`).
    pub step: f64,
    /// Largest allowed ratio of the convergence error in an output to the largest output change
    /// caused by the step (default 1e-6).
    pub accuracy: f64,
    /// Newton settings for the re-convergence (default: the steady-state defaults).
    pub newton: NewtonSettings,
}

impl Default for PerturbSettings {
    fn default() -> Self {
        PerturbSettings { step: 1e-5, accuracy: 1e-6, newton: NewtonSettings::default() }
    }
}

/// Gains by perturbation, in SI units.
#[derive(Debug, Clone)]
pub struct PerturbGains {
    /// `dy_i/du_j` (outputs × inputs), SI.
    pub gain: Mat<f64>,
    /// Absolute steps `h_j` (SI).
    pub steps: Vec<f64>,
    /// Largest ratio of estimated convergence error to output change, over all inputs.
    pub error_ratio: f64,
    /// Newton iterations over all re-convergences.
    pub newton_iterations: usize,
}

/// Outputs at one perturbed point and the largest estimated convergence error in them.
struct Point {
    y: Vec<f64>,
    error: f64,
    iterations: usize,
}

/// Re-converge at inputs `u` from `x0`, then polish with Newton corrections until `error_goal`
/// is met (at most 4); returns the outputs and the last correction's size in them.
fn reconverge(
    plant: &Plant,
    u: &[f64],
    x0: &[f64],
    outputs: &[usize],
    settings: &NewtonSettings,
    error_goal: f64,
) -> Result<Point, String> {
    let sys = PlantSystem::new(plant, u);
    let mut x = x0.to_vec();
    let report = solve_steady(&sys, &mut x, settings);
    let mut iterations = report.iterations;
    if report.status != NewtonStatus::Converged {
        let (eq, res) = report.worst.unwrap_or((0, f64::NAN));
        let from_base = format!(
            "from the base point: {:?} after {} iterations (worst: {}, scaled residual {res:.2e})",
            report.status,
            report.iterations,
            plant.equation_name(eq)
        );
        let strategy = StrategySettings { newton: settings.clone(), ..StrategySettings::default() };
        let solution =
            steady_state_by(plant, u, &strategy, &mut |_| {}).map_err(|e| format!("{from_base}; from scratch: {e}"))?;
        x = solution.x;
        iterations += solution.newton.map_or(0, |n| n.iterations);
    }
    let n = plant.n_vars();
    let (mut r, mut jx, mut ju) = (vec![0.0; n], Vec::new(), Vec::new());
    let mut lu = SparseLu::default();
    let mut error = f64::INFINITY;
    for _ in 0..4 {
        plant.jacobian(&x, u, 0.0, &mut r, &mut jx, &mut ju);
        let mut dx: Vec<f64> = r.iter().map(|v| -v).collect();
        lu.solve(n, &jx, &mut dx).map_err(|e| e.to_string())?;
        error = outputs.iter().map(|&k| dx[k].abs()).fold(0.0, f64::max);
        x.iter_mut().zip(&dx).for_each(|(a, b)| *a += b);
        if error <= error_goal {
            break;
        }
    }
    Ok(Point { y: outputs.iter().map(|&k| x[k]).collect(), error, iterations })
}

/// Gains `dy/du` of `outputs` (variable indices) to `inputs` (free input indices) at the converged
/// steady state `(x0, u0)`, by central differences of re-converged steady states.
pub fn perturb_gains(
    plant: &Plant,
    x0: &[f64],
    u0: &[f64],
    inputs: &[usize],
    outputs: &[usize],
    settings: &PerturbSettings,
) -> Result<PerturbGains, AnalysisError> {
    if !(settings.step > 0.0 && settings.step < 0.5) {
        return Err(AnalysisError::Request(format!(
            "the relative perturbation step must be in (0, 0.5) (got {})",
            settings.step
        )));
    }
    let steps: Vec<f64> =
        inputs.iter().map(|&j| settings.step * if u0[j] == 0.0 { 1.0 } else { u0[j].abs() }).collect();
    let cases: Vec<(usize, f64)> = (0..inputs.len()).flat_map(|k| [(k, 1.0), (k, -1.0)]).collect();
    // The convergence goal needs the size of the effect, unknown before solving: aim at the
    // accuracy relative to the outputs' nominal sizes times the relative step, then check below.
    let goal = outputs.iter().map(|&k| plant.vars[k].spec.nominal).fold(f64::INFINITY, f64::min)
        * settings.step
        * settings.accuracy;
    let points: Vec<Result<Point, AnalysisError>> = cases
        .par_iter()
        .map(|&(k, sign)| {
            let mut u = u0.to_vec();
            u[inputs[k]] += sign * steps[k];
            reconverge(plant, &u, x0, outputs, &settings.newton, goal).map_err(|e| {
                AnalysisError::NotConverged(format!(
                    "{}: the plant did not re-converge with `{}` moved by {:+.3e} (SI): {e}; try a smaller --step",
                    plant.file,
                    plant.inputs[inputs[k]].path,
                    sign * steps[k]
                ))
            })
        })
        .collect();
    let points = points.into_iter().collect::<Result<Vec<Point>, AnalysisError>>()?;
    let (m, p) = (inputs.len(), outputs.len());
    let mut gain = Mat::<f64>::zeros(p, m);
    let mut error_ratio: f64 = 0.0;
    for k in 0..m {
        let (plus, minus) = (&points[2 * k], &points[2 * k + 1]);
        let effect = (0..p).map(|i| (plus.y[i] - minus.y[i]).abs() / 2.0).fold(0.0, f64::max);
        // No output moves at all (not even by round-off): the gains are exactly zero.
        let ratio = if effect == 0.0 { 0.0 } else { plus.error.max(minus.error) / effect };
        if ratio.is_nan() || ratio > settings.accuracy {
            return Err(AnalysisError::NotConverged(format!(
                "{}: moving `{}` by ±{:.3e} (SI) changes the outputs by at most {effect:.3e}, but the re-converged steady states are only accurate to {:.3e}; increase --step",
                plant.file,
                plant.inputs[inputs[k]].path,
                steps[k],
                plus.error.max(minus.error)
            )));
        }
        error_ratio = error_ratio.max(ratio);
        for i in 0..p {
            gain[(i, k)] = (plus.y[i] - minus.y[i]) / (2.0 * steps[k]);
        }
    }
    Ok(PerturbGains { gain, steps, error_ratio, newton_iterations: points.iter().map(|p| p.iterations).sum() })
}
