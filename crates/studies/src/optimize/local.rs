//! The local model of self-optimizing control at a plant's optimum (issue 58, item 2): for the
//! unconstrained degrees of freedom `u` (the free inputs of the reduced Hessian, the others moving
//! to hold the active limits), the candidate measurements `y` and the disturbances `d`,
//!
//! - `Gy = ∂y/∂u` along the free directions, `Gyd = ∂y/∂d` with `u` held and the active limits
//!   held (the dependent inputs moving by `−A_D⁻¹ ∂c/∂d`): exact, from one sparse LU of the
//!   plant Jacobian at the optimum;
//! - `Juu`: the reduced Hessian of the Lagrangian ([`super::certificate`]), exact;
//! - `Jud = ∂/∂d (Zᵀ∇L)`: the Lagrangian's mixed second derivatives along the free directions
//!   and each disturbance's move, the dependent inputs following it to hold the active limits:
//!   exact, by the adjoint and hyper-dual numbers ([`super::curvature`]);
//! - `Wd`, `Wn`: the disturbances' expected magnitudes and the measurements' errors.
//!
//! Everything is in display units: the objective's, the inputs' (of their bounds), each
//! disturbance's and candidate's (as written), so the losses are in the objective's unit.

use faer::Mat;
use faer::linalg::solvers::Solve;
use plantwide_analysis::linear::Linearization;
use plantwide_analysis::select::{Signal, select_input, select_output, split_unit};
use plantwide_flowsheet::Plant;
use plantwide_flowsheet::overrides::resolve_input;
use plantwide_units::parse_difference_as;

use super::certificate::Directions;
use super::curvature::Curvature;
use super::plant::{EvaluationFailure, PlantNlp};
use super::report::sign;
use super::request::{Problem, in_unit, unit_of};
use super::sqp::Solution;
use super::{OptimizeError, State};

/// What the local model is asked for: `PATH=±Δ` disturbances, candidate `PATH[@unit]`s and
/// `PATH=±e` implementation errors (one per candidate).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LocalRequest {
    /// Disturbances, each `PATH=±Δ` (a free input outside `vary`; Δ a quantity).
    pub disturbances: Vec<String>,
    /// Candidate measurements: variables, or degrees of freedom (a measured input).
    pub candidates: Vec<String>,
    /// Each candidate's implementation error, `PATH=±e`.
    pub errors: Vec<String>,
}

/// A disturbance resolved: the input and its magnitude (SI).
#[derive(Debug, Clone)]
pub(crate) struct Dist {
    pub signal: Signal,
    pub magnitude: f64,
}

/// What a candidate is: a plant variable, or a degree of freedom.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Source {
    Variable(usize),
    Dof(usize),
}

/// A candidate resolved, with its error (SI).
#[derive(Debug, Clone)]
pub(crate) struct Candidate {
    pub signal: Signal,
    pub source: Source,
    pub error: f64,
}

fn field(field: &str, message: impl Into<String>) -> OptimizeError {
    OptimizeError::Field { field: field.to_string(), message: message.into() }
}

/// `PATH=±X` → (`PATH`, `X`).
fn plus_minus<'t>(list: &str, text: &'t str) -> Result<(&'t str, &'t str), OptimizeError> {
    let hint = || field(list, format!("`{text}`: expected PATH=±MAGNITUDE, e.g. `feed.T=±5 K`"));
    let (path, rest) = text.split_once('=').ok_or_else(hint)?;
    let rest = rest.trim();
    let mag = ["±", "+-", "+/-"].iter().find_map(|p| rest.strip_prefix(p)).ok_or_else(hint)?;
    Ok((path.trim(), mag.trim()))
}

/// A positive magnitude of dimension `dim` (a difference: `5 degC` is 5 K), and its written unit.
fn magnitude(list: &str, text: &str, dim: plantwide_units::Dimension) -> Result<(f64, Option<String>), OptimizeError> {
    let v = parse_difference_as(text, dim).map_err(|e| field(list, format!("`{text}`: {e}")))?;
    if !(v.is_finite() && v > 0.0) {
        return Err(field(list, format!("`{text}`: a magnitude must be positive")));
    }
    Ok((v, unit_of(text)))
}

impl LocalRequest {
    /// The disturbances resolved against `plant` (free inputs outside the degrees of freedom).
    pub(crate) fn disturbances(&self, plant: &Plant, problem: &Problem) -> Result<Vec<Dist>, OptimizeError> {
        let mut out: Vec<Dist> = Vec::new();
        for text in &self.disturbances {
            let (path, mag) = plus_minus("disturbances", text)?;
            let signal = select_input(plant, path).map_err(|e| field("disturbances", e.to_string()))?;
            if problem.dofs.iter().any(|d| d.signal.index == signal.index) {
                return Err(field(
                    "disturbances",
                    format!("`{path}` is a degree of freedom (in `vary`), not a disturbance"),
                ));
            }
            if out.iter().any(|d| d.signal.index == signal.index) {
                return Err(field("disturbances", format!("`{path}` is given twice")));
            }
            let (magnitude, unit) = magnitude("disturbances", mag, plant.inputs()[signal.index].dim)?;
            out.push(Dist { signal: in_unit(signal, unit), magnitude });
        }
        if out.is_empty() {
            return Err(field("disturbances", "is empty: name the disturbances and their expected magnitudes"));
        }
        Ok(out)
    }

    /// The candidates resolved against `plant`, each with its error.
    pub(crate) fn candidates(&self, plant: &Plant, problem: &Problem) -> Result<Vec<Candidate>, OptimizeError> {
        let mut out: Vec<Candidate> = Vec::new();
        for text in &self.candidates {
            let (path, _) = split_unit(text);
            let dof = resolve_input(plant, path).and_then(|i| problem.dofs.iter().position(|d| d.signal.index == i));
            let (signal, source) = match dof {
                Some(j) => {
                    let s = select_input(plant, text).map_err(|e| field("candidates", e.to_string()))?;
                    (s, Source::Dof(j))
                }
                None => {
                    let s = select_output(plant, text).map_err(|e| field("candidates", e.to_string()))?;
                    let i = s.index;
                    (s, Source::Variable(i))
                }
            };
            if out.iter().any(|c| c.source == source) {
                return Err(field("candidates", format!("`{path}` is given twice")));
            }
            out.push(Candidate { signal, source, error: f64::NAN });
        }
        for text in &self.errors {
            let (path, mag) = plus_minus("errors", text)?;
            let c = out.iter_mut().find(|c| c.signal.path == path).ok_or_else(|| {
                field("errors", format!("`{path}` is no candidate: give errors for the candidates, by the same path"))
            })?;
            let dim = match c.source {
                Source::Variable(i) => plant.vars()[i].spec.dim,
                Source::Dof(j) => plant.inputs()[problem.dofs[j].signal.index].dim,
            };
            c.error = magnitude("errors", mag, dim)?.0;
        }
        let missing: Vec<&str> = out.iter().filter(|c| c.error.is_nan()).map(|c| c.signal.path.as_str()).collect();
        if !missing.is_empty() {
            return Err(field(
                "errors",
                format!("no implementation error for {}: give each candidate one", missing.join(", ")),
            ));
        }
        if out.is_empty() {
            return Err(field("candidates", "is empty: name the candidate measurements"));
        }
        Ok(out)
    }
}

/// The exact first derivatives at the optimum: of the candidates and active constraints, with
/// respect to every degree of freedom and disturbance (SI).
pub(crate) struct Sensitivities {
    /// Candidates × (dofs, disturbances).
    pub y: Mat<f64>,
    /// Active rows (the pivots' rows, in pivot order) × (dofs, disturbances).
    pub act: Mat<f64>,
}

/// The first derivatives of the candidates and active rows at `state`.
pub(crate) fn sensitivities(
    plant: &Plant,
    problem: &Problem,
    state: &State,
    (dists, cands): (&[Dist], &[Candidate]),
    (act_c, act_b, dirs): (&[usize], &[usize], &Directions),
) -> Result<Sensitivities, OptimizeError> {
    let n = problem.dofs.len();
    let inputs: Vec<usize> =
        problem.dofs.iter().map(|d| d.signal.index).chain(dists.iter().map(|d| d.signal.index)).collect();
    let vars: Vec<usize> = cands
        .iter()
        .filter_map(|c| if let Source::Variable(i) = c.source { Some(i) } else { None })
        .chain(act_c.iter().map(|&i| problem.constraints[i].signal.index))
        .collect();
    let g = Linearization::new(plant, &state.x, &state.u).steady_gain(&inputs, &vars).map_err(|e| {
        OptimizeError::NotConverged { reason: format!("the gains at the optimum: {e}"), iterations: 0, kkt: f64::NAN }
    })?;
    let cols = inputs.len();
    let mut k = 0;
    let y = Mat::from_fn(cands.len(), cols, |_, _| 0.0);
    let mut y = y;
    for (r, c) in cands.iter().enumerate() {
        match c.source {
            Source::Variable(_) => {
                (0..cols).for_each(|j| y[(r, j)] = g[(k, j)]);
                k += 1;
            }
            Source::Dof(j) => y[(r, j)] = 1.0,
        }
    }
    let n_var = k;
    let act = Mat::from_fn(dirs.pivots.len(), cols, |p, j| {
        let row = dirs.pivots[p].0;
        if row < act_c.len() { g[(n_var + row, j)] } else { f64::from(j < n && j == act_b[row - act_c.len()]) }
    });
    Ok(Sensitivities { y, act })
}

/// `∂u_D/∂d` (dependent × disturbances): the dependent inputs' move that holds the active rows.
pub(crate) fn dependent_move(s: &Sensitivities, dirs: &Directions, n: usize) -> Result<Mat<f64>, OptimizeError> {
    let np = dirs.pivots.len();
    let nd = s.act.ncols() - n;
    if np == 0 {
        return Ok(Mat::zeros(0, nd));
    }
    let a_d = Mat::from_fn(np, np, |r, c| s.act[(r, dirs.pivots[c].1)]);
    let rhs = Mat::from_fn(np, nd, |r, k| -s.act[(r, n + k)]);
    let m = a_d.partial_piv_lu().solve(&rhs);
    if (0..np).any(|r| (0..nd).any(|k| !m[(r, k)].is_finite())) {
        return Err(OptimizeError::NotConverged {
            reason: "the active limits cannot be held as the disturbances move (their gradients are singular)".into(),
            iterations: 0,
            kkt: f64::NAN,
        });
    }
    Ok(m)
}

/// The physical directions (SI per SI of each free input): column `f` over the dofs.
pub(crate) fn physical_directions(nlp: &PlantNlp<'_>, dirs: &Directions) -> Mat<f64> {
    let n = nlp.scale_u.len();
    Mat::from_fn(n, dirs.free.len(), |j, f| dirs.z[f][j] * nlp.scale_u[j] / nlp.scale_u[dirs.free[f]])
}

/// `Gy` and `Gyd` in display units.
pub(crate) fn gains(
    problem: &Problem,
    s: &Sensitivities,
    (z, dep, dirs): (&Mat<f64>, &Mat<f64>, &Directions),
    (dists, cands): (&[Dist], &[Candidate]),
) -> (Mat<f64>, Mat<f64>) {
    let n = problem.dofs.len();
    let gy = Mat::from_fn(cands.len(), dirs.free.len(), |r, f| {
        let si: f64 = (0..n).map(|j| s.y[(r, j)] * z[(j, f)]).sum();
        si * problem.dofs[dirs.free[f]].signal.factor / cands[r].signal.factor
    });
    let gyd = Mat::from_fn(cands.len(), dists.len(), |r, k| {
        let follow: f64 = dirs.pivots.iter().enumerate().map(|(p, &(_, j))| s.y[(r, j)] * dep[(p, k)]).sum();
        (s.y[(r, n + k)] + follow) * dists[k].signal.factor / cands[r].signal.factor
    });
    (gy, gyd)
}

/// `Jud` in display units, exact: `∂(Zᵀ∇L)/∂d = Zᵀ ∇²L δ_d` along each disturbance's move with
/// the dependent inputs following it ([`super::curvature`]).
pub(crate) fn jud(
    nlp: &PlantNlp<'_>,
    problem: &Problem,
    sol: &Solution<State>,
    (dep, dirs): (&Mat<f64>, &Directions),
    dists: &[Dist],
) -> Result<Mat<f64>, OptimizeError> {
    let fail = |e: EvaluationFailure| OptimizeError::NotConverged {
        reason: format!("Jud at the optimum: {}", e.message),
        iterations: sol.iterations,
        kkt: sol.kkt.max(),
    };
    let state = &sol.point.state;
    let curvature = Curvature::new(nlp.plant(), state, &nlp.lagrangian_weights(&sol.y)).map_err(fail)?;
    let mut du: Vec<Vec<f64>> = dirs.z.iter().map(|z| nlp.input_move(z)).collect();
    for (k, d) in dists.iter().enumerate() {
        let mut m = vec![0.0; state.u.len()];
        m[d.signal.index] = 1.0;
        for (p, &(_, j)) in dirs.pivots.iter().enumerate() {
            m[problem.dofs[j].signal.index] += dep[(p, k)];
        }
        du.push(m);
    }
    let moves = curvature.moves(&du).map_err(fail)?;
    let nf = dirs.free.len();
    let to_objective = sign(problem.sense) * nlp.scale_f / problem.objective.factor;
    Ok(Mat::from_fn(nf, dists.len(), |f, k| {
        let per_input = problem.dofs[dirs.free[f]].signal.factor / nlp.scale_u[dirs.free[f]];
        curvature.second(&moves[f], &moves[nf + k]) * to_objective * per_input * dists[k].signal.factor
    }))
}
