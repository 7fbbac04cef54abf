//! Sensitivity sweeps (Luyben 1975; *Practical Distillation Control* fig. 6-6): one disturbance at
//! a time moved over a range with the flowsheet's control structure active, the plant
//! re-converged at each point, chosen outputs recorded.
//!
//! Each sweep walks outward from the base case in both directions, every point started from its
//! converged neighbour (natural-parameter continuation); a point that does not converge is
//! approached in halved steps (down to 1/64 of the spacing) before the walk on that side stops and
//! the failure is recorded. The `2 × disturbances` walks are independent and run in parallel (task
//! `2k` walks disturbance `k` up from the base, task `2k + 1` down; [`walks`] computes a
//! [`Share`] of them for a sharded job and [`curves`] puts them together). The
//! plant's design specifications are solved with it at each point (their varied inputs are
//! unknowns, [`SteadySystem`]): a model predictive controller holding its CVs is one.
//!
//! Ranges are written `PATH[@unit]=LOW:HIGH`, each end a percentage of the base value (`-10%`,
//! `+10%`) or a quantity (`0.9 kmol/min`).

use plantwide_flowsheet::Plant;
use plantwide_solve::specs::equation_name;
use plantwide_solve::{NewtonSettings, NewtonStatus, SteadySystem, solve_steady};
use plantwide_units::parse_quantity_as;
use rayon::prelude::*;

use crate::continuation::{Steps, reach};
use crate::error::{AnalysisError, request};
use crate::select::{Signal, select_input};
use crate::shard::Share;

/// A disturbance and its range (SI).
#[derive(Debug, Clone, PartialEq)]
pub struct Disturbance {
    /// The input moved (display unit for absolute values).
    pub signal: Signal,
    /// Base value (SI).
    pub base: f64,
    /// Low end of the range (SI).
    pub low: f64,
    /// High end of the range (SI).
    pub high: f64,
}

impl Disturbance {
    /// Parse `PATH[@unit]=LOW:HIGH` for `plant` at inputs `u`.
    pub fn parse(plant: &Plant, u: &[f64], text: &str) -> Result<Disturbance, AnalysisError> {
        let (path, range) = text.split_once('=').ok_or_else(|| {
            request(format!("disturb `{text}`: expected PATH=LOW:HIGH, e.g. `feed_source.F=-10%:+10%`"))
        })?;
        let signal = select_input(plant, path)?;
        let base = u[signal.index];
        let (lo, hi) = range
            .split_once(':')
            .ok_or_else(|| request(format!("disturb `{text}`: the range needs LOW:HIGH, e.g. `-10%:+10%`")))?;
        let dim = plant.inputs()[signal.index].dim;
        let end = |s: &str| -> Result<f64, AnalysisError> {
            let s = s.trim();
            if let Some(p) = s.strip_suffix('%') {
                let pct: f64 =
                    p.trim().parse().map_err(|_| request(format!("disturb `{text}`: `{s}` is not a percentage")))?;
                if base == 0.0 {
                    return Err(request(format!(
                        "disturb `{text}`: `{}` is zero at the base case, so give the range as quantities, not percentages",
                        signal.path
                    )));
                }
                Ok(base + pct / 100.0 * base.abs())
            } else {
                parse_quantity_as(s, dim).map_err(|e| request(format!("disturb `{text}`: {e}")))
            }
        };
        let (low, high) = (end(lo)?, end(hi)?);
        if !(low.is_finite() && high.is_finite() && low < high) {
            return Err(request(format!("disturb `{text}`: the range must go from low to high")));
        }
        Ok(Disturbance { signal, base, low, high })
    }

    /// Change from the base in percent (the value itself when the base is zero).
    pub fn percent(&self, value: f64) -> f64 {
        if self.base == 0.0 { value } else { (value - self.base) / self.base.abs() * 100.0 }
    }
}

/// Settings of a sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepSettings {
    /// Points over the range, ends included (default 21); the base case is added.
    pub points: usize,
    /// Newton settings at each point.
    pub newton: NewtonSettings,
}

impl Default for SweepSettings {
    fn default() -> Self {
        SweepSettings { points: 21, newton: NewtonSettings::default() }
    }
}

/// One swept disturbance: its values and the outputs at each (`None` where not converged).
#[derive(Debug, Clone)]
pub struct Curve {
    /// The disturbance.
    pub disturbance: Disturbance,
    /// Disturbance values (SI), increasing, base included.
    pub values: Vec<f64>,
    /// Outputs (SI) at each value.
    pub outputs: Vec<Option<Vec<f64>>>,
    /// Why the walk stopped early on a side, if it did.
    pub failures: Vec<SweepFailure>,
}

/// Why a sweep stopped early on one side: the point it could not reach, from where, and Newton's
/// verdict at the last halving of the step.
#[derive(Debug, Clone, PartialEq, thiserror::Error, serde::Serialize, serde::Deserialize)]
#[error("`{path}` = {value:.6e} (SI): not converged from {from:.6e}: {newton}")]
pub struct SweepFailure {
    /// Path of the disturbance.
    pub path: String,
    /// The value it could not reach (SI).
    pub value: f64,
    /// The last value reached (SI).
    pub from: f64,
    /// Why Newton failed there.
    pub newton: NewtonFailure,
}

/// A Newton iteration that did not converge: its verdict and where the residual is worst.
#[derive(Debug, Clone, PartialEq, thiserror::Error, serde::Serialize, serde::Deserialize)]
#[error("{status:?} (worst: {equation}, scaled residual {residual:.2e})")]
pub struct NewtonFailure {
    /// Newton's verdict.
    pub status: NewtonStatus,
    /// The equation with the largest scaled residual.
    pub equation: String,
    /// That scaled residual.
    pub residual: f64,
}

/// One walk of a sweep, away from the base case on one side of one disturbance.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Walk {
    /// Outputs (SI) at each target, ordered away from the base (`None` past a failure).
    pub outputs: Vec<Option<Vec<f64>>>,
    /// Why it stopped early, if it did.
    pub failure: Option<SweepFailure>,
}

/// Walk from `(x0, base)` through `targets` (ordered away from the base), each from its neighbour.
fn walk(
    plant: &Plant,
    u0: &[f64],
    x0: &[f64],
    d: &Disturbance,
    targets: &[f64],
    outputs: &[usize],
    settings: &NewtonSettings,
) -> Walk {
    // The inputs a design spec varies are unknowns: each point starts from the last one's values.
    let mut state = (x0.to_vec(), u0.to_vec());
    let mut at = d.base;
    let mut res = Vec::with_capacity(targets.len());
    let solve = |(x, u): &(Vec<f64>, Vec<f64>), _: f64, value: f64| -> Result<(Vec<f64>, Vec<f64>), NewtonFailure> {
        let mut trial_u = u.clone();
        trial_u[d.signal.index] = value;
        let sys = SteadySystem::new(plant, &trial_u);
        let mut z = sys.unknowns(x);
        let report = solve_steady(&sys, &mut z, settings);
        if report.status == NewtonStatus::Converged {
            Ok(sys.split(&z))
        } else {
            let (eq, residual) = report.worst.unwrap_or((0, f64::NAN));
            Err(NewtonFailure { status: report.status, equation: equation_name(plant, eq), residual })
        }
    };
    for (k, &target) in targets.iter().enumerate() {
        // The full step, halved (down to 1/64) where a sub-step does not converge.
        match reach(state, (at, target), Steps::halving(target - at, 6), &solve) {
            Ok(s) => (state, at) = (s, target),
            Err(stalled) => {
                res.extend(std::iter::repeat_n(None, targets.len() - k));
                let why = SweepFailure {
                    path: d.signal.path.clone(),
                    value: stalled.tried,
                    from: stalled.reached,
                    newton: stalled.error,
                };
                return Walk { outputs: res, failure: Some(why) };
            }
        }
        res.push(Some(outputs.iter().map(|&i| state.0[i]).collect()));
    }
    Walk { outputs: res, failure: None }
}

/// Sweep each disturbance over its range at `points` values (plus the base case) with the other
/// inputs at `u0`, from the converged base state `x0`; outputs are variable indices.
pub fn sweep(
    plant: &Plant,
    x0: &[f64],
    u0: &[f64],
    disturbances: &[Disturbance],
    outputs: &[usize],
    settings: &SweepSettings,
) -> Result<Vec<Curve>, AnalysisError> {
    let walks = walks(plant, x0, u0, disturbances, outputs, settings, &Share::All)?;
    let walks: Vec<Walk> = walks.into_iter().flatten().collect();
    let base: Vec<f64> = outputs.iter().map(|&i| x0[i]).collect();
    Ok(curves(disturbances, settings.points, &base, &walks))
}

/// The values disturbance `d` is swept through: `n` over its range, ends included, and the base.
fn grid(d: &Disturbance, n: usize) -> Vec<f64> {
    let mut g: Vec<f64> = (0..n).map(|k| d.low + (d.high - d.low) * k as f64 / (n - 1) as f64).collect();
    if !g.iter().any(|v| (v - d.base).abs() <= 1e-12 * d.base.abs()) {
        g.push(d.base);
    }
    g.sort_by(f64::total_cmp);
    g
}

/// The walks of a sweep that `share` asks for, in parallel: task `2k` walks disturbance `k` up
/// from the base, task `2k + 1` down (`None` for another shard's task).
///
/// # Errors
/// [`AnalysisError::Request`] for fewer than 2 points.
pub fn walks(
    plant: &Plant,
    x0: &[f64],
    u0: &[f64],
    disturbances: &[Disturbance],
    outputs: &[usize],
    settings: &SweepSettings,
    share: &Share<Walk>,
) -> Result<Vec<Option<Walk>>, AnalysisError> {
    if settings.points < 2 {
        return Err(request(format!("points must be at least 2 (got {})", settings.points)));
    }
    let tasks: Vec<usize> = (0..2 * disturbances.len()).collect();
    Ok(tasks
        .par_iter()
        .map(|&t| {
            share.run(t, || {
                let d = &disturbances[t / 2];
                let g = grid(d, settings.points);
                let targets: Vec<f64> = if t % 2 == 0 {
                    g.iter().copied().filter(|v| *v > d.base).collect()
                } else {
                    g.iter().rev().copied().filter(|v| *v < d.base).collect()
                };
                walk(plant, u0, x0, d, &targets, outputs, &settings.newton)
            })
        })
        .collect())
}

/// The curves of a sweep from all its walks (task order, as [`walks`] numbers them) and the
/// outputs at the base case.
pub fn curves(disturbances: &[Disturbance], points: usize, base: &[f64], walks: &[Walk]) -> Vec<Curve> {
    let mut curves = Vec::new();
    for (k, d) in disturbances.iter().enumerate() {
        let (up, down) = (&walks[2 * k], &walks[2 * k + 1]);
        let g = grid(d, points);
        let mut out: Vec<Option<Vec<f64>>> = down.outputs.iter().rev().cloned().collect();
        out.extend(g.iter().filter(|v| **v == d.base).map(|_| Some(base.to_vec())));
        out.extend(up.outputs.iter().cloned());
        curves.push(Curve {
            disturbance: d.clone(),
            values: g,
            outputs: out,
            failures: [&down.failure, &up.failure].into_iter().flatten().cloned().collect(),
        });
    }
    curves
}
