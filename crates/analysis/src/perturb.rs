//! Steady-state gains the book's way (*Practical Distillation Control* ch. 6): each input moved
//! `± h` from the base case, the plant re-converged from the base point, and central differences
//! `G_ij = (y_i(u + h_j e_j) − y_i(u − h_j e_j)) / (2 h_j)`, with the step chosen from the
//! variables' scales and every gain verified before it is returned. The re-convergences are
//! independent and run in parallel (rayon). A re-convergence whose Newton iteration from the base
//! point fails (a slow integral loop elsewhere in a recycle plant can stall pseudo-transient
//! continuation) is repeated from scratch the way `steady` converges (sequential-modular pass, then
//! Newton).
//!
//! **Step.** Central differences err by `h² y‴/6`; a high-purity column is so strongly curved
//! that a fixed relative step can be wrong by percents (column A with α = 2, `yD ≈ 0.99993`: 2.8 %
//! at `h/u = 1e-5`, and a negative RGA where the exact one is 3684). The curvature of an output is
//! set by its room: a mole fraction near 1 cannot move by more than its impurity `1 − y`. So the
//! default step of input `j` is the relative step 1e-5 of `|u_j|`, cut so that no output moves by
//! more than `linear_range` (1e-3) of its room `min(y − lower, upper − y)` at the exact gain
//! (when the Jacobian can be factored), and raised so that some output moves by at least 1e-9 of
//! its nominal size, far above what the polished re-convergence leaves (below). This is the
//! scale-based choice of Dennis & Schnabel (*Numerical Methods for Unconstrained Optimization*,
//! 1983, §5.4–5.6) and Gill, Murray & Wright (*Practical Optimization*, 1981, §8.6): the step
//! balances truncation (`∝ h²`) against the noise of the function values (`∝ 1/h`), here with
//! the noise made tiny by polishing and the truncation bounded through the output's room.
//!
//! **Verification.** Each input is moved by `h` and by `h/2` (four re-convergences). Richardson
//! extrapolation (Richardson 1911; Dahlquist & Björck, *Numerical Methods*, §7.2) gives the
//! returned gain `(4 D(h/2) − D(h)) / 3`, accurate to `O(h⁴)`, and the difference `D(h) − D(h/2)
//! ≈ ¾ c h²` measures the error that is left; it must stay below `tolerance` (1e-3) element by
//! element, and for a square gain the RGA of `D(h)` and `D(h/2)` must agree to `rga_tolerance`
//! (1e-2): a nearly singular gain (λ₁₁ in the thousands) amplifies element errors by λ₁₁. Where
//! the exact linearization `−C J⁻¹ B` exists, the gains and their RGA must agree with it to
//! `linear_tolerance` (1e-3) and `rga_tolerance`. A failed check (or a re-convergence that fails)
//! shrinks the step by the factor the `h²` error law asks for and tries again (up to
//! `max_attempts`, default 5); if it still fails, [`AnalysisError::PerturbationUnverified`] names
//! the input/output pair, the two estimates and what to try. Never a silently wrong gain.
//!
//! **Convergence accuracy.** After Newton converges at a perturbed point, Newton corrections
//! `δ = −J⁻¹ f` are applied (up to four, until `|δ_y|` is below `accuracy · step` times the
//! outputs' nominal size); the last `|δ_y|` bounds what the convergence left in the outputs (the
//! error after it is of order `|δ_y|²`). It must stay below `accuracy · max_i |Δy_i|` (default
//! 1e-6) for every input, or the gain is refused with the numbers that explain why (a larger step
//! would help).

use faer::Mat;
use plantwide_flowsheet::Plant;
use plantwide_solve::sequential::{SolveError, StrategySettings, steady_state_by};
use plantwide_solve::sparse::{SparseError, SparseLu};
use plantwide_solve::{NewtonSettings, NewtonStatus, PlantSystem, solve_steady};
use rayon::prelude::*;
use serde::Serialize;

use crate::error::{AnalysisError, Unverified};
use crate::linear::Linearization;
use crate::measures::rga;

/// Relative step of the first attempt when none is given: `h_j = 1e-5 · |u_j|`.
pub const DEFAULT_STEP: f64 = 1e-5;
/// Largest relative step the automatic step grows to when the re-converged states are too
/// inaccurate for a smaller one (the linearity checks still judge it).
const MAX_GROWN_STEP: f64 = 1e-2;
/// Smallest relative step tried: below it the output changes drown in round-off.
const MIN_STEP: f64 = 1e-11;
/// The automatic step moves some output by at least this fraction of its nominal size.
const MIN_EFFECT: f64 = 1e-9;
/// A gain smaller than this fraction of the largest in its row (inputs scaled by `|u_j|`) is
/// compared against that fraction instead of against itself.
const FLOOR: f64 = 1e-6;

/// Settings of the perturbation gains.
#[derive(Debug, Clone, PartialEq)]
pub struct PerturbSettings {
    /// Relative step `h_j / |u_j|` of the first attempt (`h_j = step` SI units when `u_j = 0`);
    /// `None` (default) chooses it from the scales (module docs). Verification may shrink it.
    pub step: Option<f64>,
    /// Largest change of an output, as a fraction of its room to its nearest bound, that the
    /// automatic step allows (default 1e-3).
    pub linear_range: f64,
    /// Largest relative difference of the gains at `h` and `h/2` (default 1e-3).
    pub tolerance: f64,
    /// Largest relative difference of the RGA at `h` and `h/2`, and of the RGA against the
    /// exact linearization's (default 1e-2).
    pub rga_tolerance: f64,
    /// Largest relative difference of the returned gains against the exact linearization
    /// (default 1e-3).
    pub linear_tolerance: f64,
    /// Attempts, each with a smaller step, before the gains are refused (default 5).
    pub max_attempts: usize,
    /// Largest allowed ratio of the convergence error in an output to the largest output change
    /// caused by the step (default 1e-6).
    pub accuracy: f64,
    /// Newton settings for the re-convergence (default: the steady-state defaults).
    pub newton: NewtonSettings,
}

impl Default for PerturbSettings {
    fn default() -> Self {
        PerturbSettings {
            step: None,
            linear_range: 1e-3,
            tolerance: 1e-3,
            rga_tolerance: 1e-2,
            linear_tolerance: 1e-3,
            max_attempts: 5,
            accuracy: 1e-6,
            newton: NewtonSettings::default(),
        }
    }
}

/// How the returned gains were verified (serialized as `"perturbation"` by `gains --json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PerturbCheck {
    /// Largest relative step `h_j / |u_j|` of the accepted attempt (the larger of `h`, `h/2`).
    pub step: f64,
    /// Relative step of each input in the accepted attempt.
    pub steps: Vec<f64>,
    /// The check: `richardson` (central differences at `h` and `h/2`).
    pub check: &'static str,
    /// Largest relative difference of the gains at `h` and `h/2`, element by element.
    pub max_relative_difference: f64,
    /// Largest relative difference of the RGA at `h` and `h/2` (square, regular gains only).
    pub rga_relative_difference: Option<f64>,
    /// Largest relative difference of the returned gains against the exact linearization (when
    /// the Jacobian could be factored).
    pub linear_relative_difference: Option<f64>,
    /// Attempts made (1 when the first step verified).
    pub attempts: usize,
}

/// Gains by perturbation, in SI units.
#[derive(Debug, Clone)]
pub struct PerturbGains {
    /// `dy_i/du_j` (outputs × inputs), SI: the Richardson extrapolation of the accepted attempt.
    pub gain: Mat<f64>,
    /// Absolute steps `h_j` of the accepted attempt (SI).
    pub steps: Vec<f64>,
    /// Largest ratio of estimated convergence error to output change, over all inputs.
    pub error_ratio: f64,
    /// Newton iterations over all re-convergences of all attempts.
    pub newton_iterations: usize,
    /// How the gains were verified.
    pub check: PerturbCheck,
}

/// Why gains by perturbation could not be computed: a perturbed plant that did not re-converge,
/// or re-converged too inaccurately for the effect of its step. Joined into
/// [`AnalysisError::NotConverged`].
#[derive(Debug, Clone, thiserror::Error)]
pub enum PerturbError {
    /// A perturbed plant did not re-converge (at any step tried, the last reason is reported).
    #[error("{file}: the plant did not re-converge: `{input}` moved by {by:+.3e} (SI): {cause}; try a smaller `step`")]
    Reconverge {
        /// Flowsheet file.
        file: String,
        /// Path of the moved input.
        input: String,
        /// Its move from the base case (SI).
        by: f64,
        /// Why the point did not re-converge (boxed: it carries the solver's reason).
        cause: Box<PointError>,
    },
    /// The re-converged outputs are less accurate than the step moves them by.
    #[error(
        "{file}: moving `{input}` by ±{step:.3e} (SI) changes the outputs by at most {effect:.3e}, but the re-converged steady states are only accurate to {accuracy:.3e}; increase `step`"
    )]
    Inaccurate {
        /// Flowsheet file.
        file: String,
        /// Path of the moved input.
        input: String,
        /// The smaller move `h/2` (SI).
        step: f64,
        /// Largest output change `|y(u + h/2) − y(u − h/2)| / 2` (SI).
        effect: f64,
        /// Largest estimated convergence error left in an output (SI).
        accuracy: f64,
    },
}

/// Why one perturbed point gave no outputs.
#[derive(Debug, Clone, thiserror::Error)]
pub enum PointError {
    /// Newton from the base point failed, and so did the steady-state strategy from scratch.
    #[error(
        "from the base point: {status:?} after {iterations} iterations (worst: {equation}, scaled residual {residual:.2e}); from scratch: {scratch}"
    )]
    NotConverged {
        /// Newton's verdict from the base point.
        status: NewtonStatus,
        /// Its iterations.
        iterations: usize,
        /// The equation with the largest scaled residual.
        equation: String,
        /// That scaled residual.
        residual: f64,
        /// Why the cold start failed too.
        scratch: SolveError,
    },
    /// The Jacobian at the re-converged point could not be factored for the polishing
    /// corrections.
    #[error(transparent)]
    Polish(#[from] SparseError),
}

/// Outputs at one perturbed point and the estimated convergence error in each.
struct Point {
    y: Vec<f64>,
    errors: Vec<f64>,
    iterations: usize,
}

impl Point {
    /// The largest estimated convergence error over the outputs.
    fn error(&self) -> f64 {
        self.errors.iter().copied().fold(0.0, f64::max)
    }
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
) -> Result<Point, PointError> {
    let sys = PlantSystem::new(plant, u);
    let mut x = x0.to_vec();
    let report = solve_steady(&sys, &mut x, settings);
    let mut iterations = report.iterations;
    if report.status != NewtonStatus::Converged {
        let (eq, residual) = report.worst.unwrap_or((0, f64::NAN));
        let strategy = StrategySettings { newton: settings.clone(), ..StrategySettings::default() };
        let solution =
            steady_state_by(plant, u, &strategy, &mut |_| {}).map_err(|scratch| PointError::NotConverged {
                status: report.status,
                iterations: report.iterations,
                equation: plant.equation_name(eq),
                residual,
                scratch,
            })?;
        x = solution.x;
        iterations += solution.newton.map_or(0, |n| n.iterations);
    }
    let n = plant.n_vars();
    let (mut r, mut jx, mut ju) = (vec![0.0; n], Vec::new(), Vec::new());
    let mut lu = SparseLu::default();
    let mut errors = vec![f64::INFINITY; outputs.len()];
    for _ in 0..4 {
        plant.jacobian(&x, u, 0.0, &mut r, &mut jx, &mut ju);
        let mut dx: Vec<f64> = r.iter().map(|v| -v).collect();
        lu.solve(n, &jx, &mut dx)?;
        errors = outputs.iter().map(|&k| dx[k].abs()).collect();
        x.iter_mut().zip(&dx).for_each(|(a, b)| *a += b);
        if errors.iter().all(|e| *e <= error_goal) {
            break;
        }
    }
    Ok(Point { y: outputs.iter().map(|&k| x[k]).collect(), errors, iterations })
}

/// Central differences of one input at `h` and `h/2` (four re-convergences, in parallel).
struct Column {
    /// `D(h)`, one entry per output.
    coarse: Vec<f64>,
    /// `D(h/2)`.
    fine: Vec<f64>,
    /// Convergence error left in each output, the largest over the four points.
    errors: Vec<f64>,
    /// The largest of `errors`.
    error: f64,
    /// Largest output change `|y(u + h/2) − y(u − h/2)| / 2`.
    effect: f64,
    iterations: usize,
}

/// What the caller of [`perturb_gains`] asked for, and the base point.
struct Problem<'a> {
    plant: &'a Plant,
    x0: &'a [f64],
    u0: &'a [f64],
    inputs: &'a [usize],
    outputs: &'a [usize],
    settings: &'a PerturbSettings,
    /// `|u_j|`, or 1 where `u_j = 0`: absolute step = relative step × scale.
    scales: Vec<f64>,
}

impl Problem<'_> {
    /// Re-converge with input `k` moved by `±h` and `±h/2`; `Err` names the failed move.
    fn column(&self, k: usize, h: f64) -> Result<Column, PerturbError> {
        let (plant, input) = (self.plant, self.inputs[k]);
        // Aim at the accuracy relative to the outputs' nominal sizes times the smaller relative
        // step; the error ratio is checked against the effect afterwards.
        let goal = self.outputs.iter().map(|&o| plant.vars()[o].spec.nominal).fold(f64::INFINITY, f64::min)
            * (h / 2.0 / self.scales[k])
            * self.settings.accuracy;
        let moves = [h, -h, h / 2.0, -h / 2.0];
        let points = moves
            .par_iter()
            .map(|&d| {
                let mut u = self.u0.to_vec();
                u[input] += d;
                reconverge(plant, &u, self.x0, self.outputs, &self.settings.newton, goal).map_err(|cause| {
                    PerturbError::Reconverge {
                        file: plant.file().to_string(),
                        input: plant.inputs()[input].path.clone(),
                        by: d,
                        cause: Box::new(cause),
                    }
                })
            })
            .collect::<Vec<Result<Point, PerturbError>>>()
            // In move order: rayon's own `collect` into a `Result` keeps whichever error a thread
            // stored first, so with two failed moves the reported one depended on the schedule.
            .into_iter()
            .collect::<Result<Vec<Point>, PerturbError>>()?;
        let diff = |a: &Point, b: &Point, i: usize| a.y[i] - b.y[i];
        let n = self.outputs.len();
        Ok(Column {
            coarse: (0..n).map(|i| diff(&points[0], &points[1], i) / (2.0 * h)).collect(),
            fine: (0..n).map(|i| diff(&points[2], &points[3], i) / h).collect(),
            errors: (0..n).map(|i| points.iter().map(|p| p.errors[i]).fold(0.0, f64::max)).collect(),
            error: points.iter().map(Point::error).fold(0.0, f64::max),
            effect: (0..n).map(|i| diff(&points[2], &points[3], i).abs() / 2.0).fold(0.0, f64::max),
            iterations: points.iter().map(|p| p.iterations).sum(),
        })
    }

    /// Room of each output to its nearest bound (the scale of its curvature): a mole fraction
    /// at 0.99993 has room 7e-5. Unbounded outputs get their magnitude or nominal size.
    fn rooms(&self) -> Vec<f64> {
        self.outputs
            .iter()
            .map(|&o| {
                let (spec, y) = (&self.plant.vars()[o].spec, self.x0[o]);
                let room = match (spec.lower.is_finite(), spec.upper.is_finite()) {
                    (true, true) => (y - spec.lower).min(spec.upper - y),
                    (true, false) => y - spec.lower,
                    (false, true) => spec.upper - y,
                    (false, false) => y.abs().max(spec.nominal),
                };
                room.max(1e-12 * spec.nominal)
            })
            .collect()
    }

    /// Relative steps that keep every output within `linear_range` of its room at gain `g`
    /// (SI), never above `steps`, and that move some output by at least `MIN_EFFECT` of its
    /// nominal size.
    fn fit_steps(&self, steps: &[f64], g: &Mat<f64>) -> Vec<f64> {
        let rooms = self.rooms();
        (0..self.inputs.len())
            .map(|k| {
                let (mut cap, mut floor) = (steps[k], 0.0_f64);
                for (i, &o) in self.outputs.iter().enumerate() {
                    let slope = g[(i, k)].abs() * self.scales[k];
                    if slope > 0.0 {
                        cap = cap.min(self.settings.linear_range * rooms[i] / slope);
                        floor = floor.max(MIN_EFFECT * self.plant.vars()[o].spec.nominal / slope);
                    }
                }
                cap.max(floor.min(steps[k])).max(MIN_STEP)
            })
            .collect()
    }
}

/// Relative difference of `a` against `b`, element by element: the largest `|a_ij − b_ij| /
/// size_ij` with `size_ij = max(|b_ij|, FLOOR · max_k |b_ik| s_k / s_j)` (`s`: column scales),
/// and where it is; then the same with `allowance(i, j)`, the noise the convergence error can put
/// in element `(i, j)`, subtracted first (what the checks judge).
struct Difference {
    raw: f64,
    excess: f64,
    at: (usize, usize),
}

fn relative_difference(a: &Mat<f64>, b: &Mat<f64>, s: &[f64], allowance: &dyn Fn(usize, usize) -> f64) -> Difference {
    let mut d = Difference { raw: 0.0, excess: 0.0, at: (0, 0) };
    let nan_max = |v: f64| if v.is_nan() { f64::INFINITY } else { v };
    for i in 0..a.nrows() {
        let row = (0..a.ncols()).map(|k| b[(i, k)].abs() * s[k]).fold(0.0, f64::max);
        for j in 0..a.ncols() {
            let size = b[(i, j)].abs().max(FLOOR * row / s[j]);
            let diff = (a[(i, j)] - b[(i, j)]).abs();
            let raw = if diff == 0.0 { 0.0 } else { nan_max(diff / size) };
            let beyond = (diff - allowance(i, j)).max(0.0);
            let excess = if beyond == 0.0 { 0.0 } else { nan_max(beyond / size) };
            d.raw = d.raw.max(raw);
            if excess > d.excess {
                (d.excess, d.at) = (excess, (i, j));
            }
        }
    }
    d
}

/// A failed check of one attempt: which, where, the two estimates and how far apart.
struct Failure {
    quantity: &'static str,
    check: &'static str,
    output: usize,
    input: usize,
    first: f64,
    second: f64,
    difference: f64,
    tolerance: f64,
}

/// The figures of one attempt that passed or the first check that failed.
struct Assessment {
    gain: Mat<f64>,
    check: PerturbCheck,
    failure: Option<Failure>,
}

/// Richardson extrapolation of central differences at `h` and `h/2`: their errors are `c h²`
/// and `c h²/4`, so `(4 D(h/2) − D(h)) / 3` cancels the `h²` term and leaves `O(h⁴)`.
fn richardson(coarse: f64, fine: f64) -> f64 {
    (4.0 * fine - coarse) / 3.0
}

/// Extrapolate and verify one attempt's columns (module docs: Richardson, RGA, exact gains).
fn assess(p: &Problem, columns: &[Column], rel: &[f64], exact: Option<&Mat<f64>>) -> Assessment {
    let (n, m) = (p.outputs.len(), p.inputs.len());
    let coarse = Mat::from_fn(n, m, |i, k| columns[k].coarse[i]);
    let fine = Mat::from_fn(n, m, |i, k| columns[k].fine[i]);
    let gain = Mat::from_fn(n, m, |i, k| richardson(coarse[(i, k)], fine[(i, k)]));
    // Convergence noise: at most 3 e_i / h in D(h) − D(h/2) and in the extrapolated gain.
    let allowance = |i: usize, k: usize| 3.0 * columns[k].errors[i] / (rel[k] * p.scales[k]);
    let s = &p.settings;
    let mut failures = Vec::new();
    let mut judge = |quantity, check, a: &Mat<f64>, b: &Mat<f64>, d: Difference, tolerance: f64| {
        if d.excess > tolerance {
            let ((i, j), difference) = (d.at, d.excess);
            let (first, second) = (a[(i, j)], b[(i, j)]);
            failures.push(Failure { quantity, check, output: i, input: j, first, second, difference, tolerance });
        }
        d.raw
    };
    let d = relative_difference(&coarse, &fine, &p.scales, &allowance);
    let richardson = judge("gain", "central differences at h and h/2", &coarse, &fine, d, s.tolerance);
    let ones = vec![1.0; m];
    let rga_pair = |a: &Mat<f64>, b: &Mat<f64>| match (n == m, rga(a.as_ref()), rga(b.as_ref())) {
        (true, Ok(la), Ok(lb)) => Some((relative_difference(&la, &lb, &ones, &|_, _| 0.0), la, lb)),
        _ => None,
    };
    let rga_h = rga_pair(&coarse, &fine)
        .map(|(d, la, lb)| judge("relative gain", "RGA at h and h/2", &la, &lb, d, s.rga_tolerance));
    let mut linear = None;
    if let Some(g) = exact {
        let d = relative_difference(&gain, g, &p.scales, &allowance);
        linear = Some(judge("gain", "against the exact linearization", &gain, g, d, s.linear_tolerance));
        if let Some((d, la, lb)) = rga_pair(&gain, g) {
            judge("relative gain", "RGA against the exact linearization", &la, &lb, d, s.rga_tolerance);
        }
    }
    let check = PerturbCheck {
        step: rel.iter().copied().fold(0.0, f64::max),
        steps: rel.to_vec(),
        check: "richardson",
        max_relative_difference: richardson,
        rga_relative_difference: rga_h,
        linear_relative_difference: linear,
        attempts: 0,
    };
    let failure =
        failures.into_iter().max_by(|a, b| (a.difference / a.tolerance).total_cmp(&(b.difference / b.tolerance)));
    Assessment { gain, check, failure }
}

/// Gains `dy/du` of `outputs` (variable indices) to `inputs` (free input indices) at the converged
/// steady state `(x0, u0)`, by central differences of re-converged steady states at a step chosen
/// from the scales and verified (module docs).
///
/// # Errors
/// [`AnalysisError::Request`] for a step outside `(0, 0.5)`; [`AnalysisError::NotConverged`] when
/// a perturbed plant does not re-converge at any step tried, or when the re-converged outputs are
/// too inaccurate for the effect of the step; [`AnalysisError::PerturbationUnverified`] when the
/// gains fail their check at every step tried.
pub fn perturb_gains(
    plant: &Plant,
    x0: &[f64],
    u0: &[f64],
    inputs: &[usize],
    outputs: &[usize],
    settings: &PerturbSettings,
) -> Result<PerturbGains, AnalysisError> {
    if let Some(step) = settings.step.filter(|s| !(*s > 0.0 && *s < 0.5)) {
        return Err(AnalysisError::Request(format!("the relative perturbation step must be in (0, 0.5) (got {step})")));
    }
    let scales = inputs.iter().map(|&j| if u0[j] == 0.0 { 1.0 } else { u0[j].abs() }).collect();
    let p = Problem { plant, x0, u0, inputs, outputs, settings, scales };
    // The exact gains (one sparse LU) scale the automatic step and check the result.
    let exact = Linearization::new(plant, x0, u0).steady_gain(inputs, outputs).ok();
    let mut rel = vec![settings.step.unwrap_or(DEFAULT_STEP); inputs.len()];
    if let (None, Some(g)) = (settings.step, &exact) {
        rel = p.fit_steps(&rel, g);
    }
    let mut iterations = 0;
    let mut last: Option<AnalysisError> = None;
    for attempt in 1..=settings.max_attempts.max(1) {
        let columns: Vec<Result<Column, PerturbError>> =
            (0..inputs.len()).into_par_iter().map(|k| p.column(k, rel[k] * p.scales[k])).collect();
        iterations += columns.iter().flatten().map(|c| c.iterations).sum::<usize>();
        // A move too large to re-converge: a tenth of the step for that input, and try again.
        let failed: Vec<(usize, &PerturbError)> =
            columns.iter().enumerate().filter_map(|(k, c)| c.as_ref().err().map(|e| (k, e))).collect();
        if let Some((_, e)) = failed.first() {
            last = Some((*e).clone().into());
            failed.iter().for_each(|&(k, _)| rel[k] = (rel[k] / 10.0).max(MIN_STEP));
            continue;
        }
        let columns: Vec<Column> = columns.into_iter().flatten().collect();
        // A step shrunk into the convergence noise cannot help: report why it was shrunk.
        let error_ratio = match (noise_check(&p, &columns, &rel), last.take()) {
            (Ok(r), _) => r,
            // An automatic step too small for the re-converged states' accuracy (and not shrunk
            // there by a failed check): larger, and try again.
            (Err(e), None) if settings.step.is_none() && grow_noisy(&p, &columns, &mut rel) => {
                last = Some(e);
                continue;
            }
            // The smaller step a failed check asked for is too noisy: no step is left to suggest.
            (Err(_), Some(AnalysisError::PerturbationUnverified(mut u))) => {
                u.suggestion = None;
                return Err(AnalysisError::PerturbationUnverified(u));
            }
            (Err(earlier), _) => return Err(earlier),
        };
        let mut a = assess(&p, &columns, &rel, exact.as_ref());
        a.check.attempts = attempt;
        let Some(f) = a.failure else {
            let steps = rel.iter().zip(&p.scales).map(|(r, s)| r * s).collect();
            return Ok(PerturbGains {
                gain: a.gain,
                steps,
                error_ratio,
                newton_iterations: iterations,
                check: a.check,
            });
        };
        // The h² law: the step that would bring the difference to a quarter of the tolerance,
        // shrinking by a factor between 4 and 1000, never below the round-off floor, and
        // within the linear range of the current estimate.
        let shrink = (0.5 * (f.tolerance / f.difference).sqrt()).clamp(1e-3, 0.25);
        let smaller: Vec<f64> = rel.iter().map(|r| (r * shrink).max(MIN_STEP)).collect();
        let stuck = smaller == rel;
        rel = p.fit_steps(&smaller, &a.gain).iter().zip(&smaller).map(|(f, s)| f.min(*s)).collect();
        last = Some(unverified(&p, &f, a.check.step, rel[f.input]));
        if stuck {
            break;
        }
    }
    // Every attempt that does not return leaves its reason in `last`.
    Err(last.expect("at least one attempt is made"))
}

/// The largest ratio of convergence error to output change; `Err` when it exceeds `accuracy`.
fn noise_check(p: &Problem, columns: &[Column], rel: &[f64]) -> Result<f64, AnalysisError> {
    let mut error_ratio: f64 = 0.0;
    for (k, c) in columns.iter().enumerate() {
        // No output moves at all (not even by round-off): the gains are exactly zero.
        let ratio = if c.effect == 0.0 { 0.0 } else { c.error / c.effect };
        if ratio.is_nan() || ratio > p.settings.accuracy {
            return Err(PerturbError::Inaccurate {
                file: p.plant.file().to_string(),
                input: p.plant.inputs()[p.inputs[k]].path.clone(),
                step: rel[k] * p.scales[k] / 2.0,
                effect: c.effect,
                accuracy: c.error,
            }
            .into());
        }
        error_ratio = error_ratio.max(ratio);
    }
    Ok(error_ratio)
}

/// Grow the automatic relative step of each input whose columns' convergence error is more than
/// `accuracy` of its effect, to bring it to a quarter of that (the effect grows with the step,
/// the error does not), at most to [`MAX_GROWN_STEP`]: whether any grew. A high-purity output
/// moved by 1.3e-6 at the default step against an accuracy of 4.9e-12 (generated plant
/// 0x4f68f799dcee2e64) was refused with "increase --step" though no step had been given.
fn grow_noisy(p: &Problem, columns: &[Column], rel: &mut [f64]) -> bool {
    let mut grew = false;
    for (k, c) in columns.iter().enumerate() {
        let ratio = if c.effect == 0.0 { 0.0 } else { c.error / c.effect };
        if ratio.is_nan() || ratio <= p.settings.accuracy || rel[k] >= MAX_GROWN_STEP {
            continue;
        }
        rel[k] = (rel[k] * 4.0 * ratio / p.settings.accuracy).min(MAX_GROWN_STEP);
        grew = true;
    }
    grew
}

/// The typed error for a check that failed at the last step tried.
fn unverified(p: &Problem, f: &Failure, step: f64, next: f64) -> AnalysisError {
    Unverified {
        file: p.plant.file().to_string(),
        quantity: f.quantity,
        output: p.plant.vars()[p.outputs[f.output]].path.clone(),
        input: p.plant.inputs()[p.inputs[f.input]].path.clone(),
        check: f.check,
        first: f.first,
        second: f.second,
        difference: f.difference,
        tolerance: f.tolerance,
        step,
        suggestion: Some(next),
    }
    .into()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measures::from_rows;

    #[test]
    fn relative_difference_measures_small_elements_against_their_row() {
        let b = from_rows(&[vec![1.0, 1e-9], vec![2.0, -2.0]]);
        // 1e-9 off a 1e-9 element is 100 % of it, but only 1e-9 of its row: judged as 1e-9 / FLOOR.
        let a = from_rows(&[vec![1.0, 2e-9], vec![2.0, -2.0]]);
        let d = relative_difference(&a, &b, &[1.0, 1.0], &|_, _| 0.0);
        assert!((d.raw - 1e-9 / FLOOR).abs() < 1e-12, "{}", d.raw);
        assert_eq!(d.at, (0, 1));
        // Column scales enter the row size: input 2 in units a million times larger.
        let d = relative_difference(&a, &b, &[1.0, 1e6], &|_, _| 0.0);
        assert!((d.raw - 1.0).abs() < 1e-12, "{}", d.raw);
        // What the convergence error can explain is not held against the gains.
        let a = from_rows(&[vec![1.0 + 1e-4, 1e-9], vec![2.0, -2.0]]);
        let d = relative_difference(&a, &b, &[1.0, 1.0], &|i, j| if (i, j) == (0, 0) { 2e-4 } else { 0.0 });
        assert!((d.raw - 1e-4).abs() < 1e-12 && d.excess == 0.0, "{} {}", d.raw, d.excess);
    }

    #[test]
    fn richardson_extrapolation_removes_the_h_squared_error() {
        // D(h) = g + c h² exactly: the extrapolation (4 D(h/2) − D(h)) / 3 returns g.
        let (g, c, e, h) = (0.8, 3e4, 5e6, 1e-3);
        let d = |h: f64| g + c * h * h + e * h.powi(4);
        let err = richardson(d(h), d(h / 2.0)) - g;
        assert!((err - e * h.powi(4) * (4.0 / 16.0 - 1.0) / 3.0).abs() < 1e-12, "{err}");
        assert!(err.abs() < 1e-3 * (d(h / 2.0) - g).abs());
    }
}
