//! The built-in CSTR and surge tank against the same units written as `equations` units (issue 57):
//! the CSTR's two other steady states (ignition/extinction multiplicity) and the linearized plants.
//!
//! # Why the linearized plant is the quantity to compare
//! The two formulations order their variables and equations differently, write different algebraic
//! equations (`out.x[A]*M = NA` against the built-in's own closure) and place them at different rows,
//! so the raw Jacobians `∂f/∂x` are not comparable entry by entry. What both must share is the
//! linear dynamics they imply. Both carry the same physical states (`N[A]`, `N[B]`, `U`, `Tj` of the
//! reactor, `N` and `U` of the tank, the controllers' integrals) and the same inputs, so after the
//! algebraic variables are eliminated (index 1) the reduced ODE `ẋ_d = F(x_d, u)` is one and the same
//! function: its Jacobians `A = ∂F/∂x_d`, `B = ∂F/∂u` are unique, and so are `C`, `D` of any
//! physical variable (`effluent.T`, `reactor.level`, …) as a function of `(x_d, u)`. The transfer
//! matrix `G(s) = C (sM − J)⁻¹ B_u` from the inputs to every shared variable does not depend on the
//! state coordinates at all, so it is checked as well, at `s = 0` (the steady-state gains) and along
//! the imaginary axis. Each is computed here densely from the plant Jacobian, independently of
//! `plantwide-analysis`.

use std::path::Path;

use faer::linalg::solvers::Solve;
use faer::{Mat, c64};
use plantwide_flowsheet::{Plant, load_file};
use plantwide_solve::{NewtonSettings, PlantSystem, System, steady_state};

const TOL_STEADY: f64 = 1e-10;
const TOL_JACOBIAN: f64 = 1e-12;

fn load(rel: &str) -> Plant {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(rel);
    load_file(&path).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// The equations unit's name for a built-in variable path, if it has one.
fn counterpart(eqs: &Plant, path: &str) -> Option<usize> {
    let renamed = match path {
        "reactor.N[A]" => "reactor.NA",
        "reactor.N[B]" => "reactor.NB",
        "reactor.rate[1]" => "reactor.rate",
        "tank.N[water]" => "tank.N",
        p => p,
    };
    eqs.var(renamed)
}

/// Pairs `(built-in index, equations index)` of every variable both plants have.
fn shared_variables(builtin: &Plant, eqs: &Plant) -> Vec<(usize, usize)> {
    builtin.vars().iter().enumerate().filter_map(|(i, v)| counterpart(eqs, &v.path).map(|j| (i, j))).collect()
}

/// Pairs of input indices with the same path that no controller drives in either plant.
fn shared_free_inputs(builtin: &Plant, eqs: &Plant) -> Vec<(usize, usize)> {
    builtin
        .inputs()
        .iter()
        .enumerate()
        .filter(|(_, inp)| inp.driven_by.is_none())
        .filter_map(|(i, inp)| {
            let j = eqs.input(&inp.path)?;
            eqs.inputs()[j].driven_by.is_none().then_some((i, j))
        })
        .collect()
}

/// Worst relative difference over the variables the reactor determines: its own and its
/// effluent's. (The feed, the product and the level controller are the same built-in units in
/// both plants; the controller's integral is roundoff around zero at steady state.)
fn worst_state_difference(builtin: &Plant, xb: &[f64], eqs: &Plant, xe: &[f64]) -> f64 {
    let mut worst: f64 = 0.0;
    let reactor = |i: usize| ["reactor.", "effluent."].iter().any(|p| builtin.vars()[i].path.starts_with(p));
    for (i, j) in shared_variables(builtin, eqs).into_iter().filter(|&(i, _)| reactor(i)) {
        let d = (xb[i] - xe[j]).abs() / xb[i].abs().max(1e-300);
        if d > TOL_STEADY {
            eprintln!("{:>18} {:>22.15e} {:>22.15e}  rel {d:.1e}", builtin.vars()[i].path, xb[i], xe[j]);
        }
        worst = worst.max(d);
    }
    worst
}

fn newton_only() -> NewtonSettings {
    NewtonSettings { pseudo_transient: false, ..NewtonSettings::default() }
}

/// Reaction rate constant of `cstr_multiplicity.json` at `t` [1/s].
fn rate_constant(t: f64) -> f64 {
    0.01 * (-(8.0e4 / 8.314_462_618) * (1.0 / t - 1.0 / 350.0)).exp()
}

/// The cold start moved to reactor temperature `t` (as `tests/it/core.rs` reaches the three
/// steady states): holdups, energy, jacket and effluent consistent with the closed-form mass
/// balance `x_A = F/(F + k M)` at that temperature. Paths absent from `plant` are skipped.
fn cstr_guess_at(plant: &Plant, t: f64) -> Vec<f64> {
    let mut x = plant.initial_guess();
    let (f, m, volume) = (10.0, 1000.0, 0.1);
    let k = rate_constant(t);
    let xa = f / (f + k * m);
    let h = plant.thermo().h_liq(t, &[xa, 1.0 - xa]);
    let tj = (5.0 * 4184.0 * 300.0 + 2000.0 * t) / (5.0 * 4184.0 + 2000.0);
    for (paths, v) in [
        (&["effluent.T"][..], t),
        (&["effluent.h"], h),
        (&["effluent.x[A]"], xa),
        (&["effluent.x[B]"], 1.0 - xa),
        (&["reactor.N[A]", "reactor.NA"], m * xa),
        (&["reactor.N[B]", "reactor.NB"], m * (1.0 - xa)),
        (&["reactor.U"], m * h),
        (&["reactor.Tj"], tj),
        (&["reactor.Q"], 2000.0 * (tj - t)),
        (&["reactor.rate[1]", "reactor.rate"], k * m * xa / volume),
    ] {
        let i = paths.iter().find_map(|p| plant.var(p)).unwrap_or_else(|| panic!("no variable among {paths:?}"));
        x[i] = v;
    }
    x
}

/// The steady state of `plant` reached by Newton from the guess at `t_guess` [K].
fn cstr_steady_from(plant: &Plant, t_guess: f64) -> Vec<f64> {
    let x0 = cstr_guess_at(plant, t_guess);
    steady_state(plant, &plant.input_values(), Some(&x0), &newton_only())
        .unwrap_or_else(|e| panic!("{}: from {t_guess} K: {e}", plant.name()))
        .x
}

/// Guesses [K] that reach the low, middle (open-loop unstable) and high steady states, and the
/// reactor temperatures there (bisection of the reduced energy balance, `tests/it/core.rs`).
const CSTR_STATES: [(f64, f64); 3] = [(300.0, 301.848), (336.5, 335.787), (460.0, 450.020)];

#[test]
fn cstr_as_equations_has_all_three_built_in_steady_states() {
    let (builtin, eqs) = (load("flowsheets/cstr_multiplicity.json"), load("tests/data/cstr_equations.json"));
    let t = builtin.var("effluent.T").unwrap();
    for (guess, root) in CSTR_STATES {
        let (xb, xe) = (cstr_steady_from(&builtin, guess), cstr_steady_from(&eqs, guess));
        assert!((xb[t] - root).abs() < 0.01, "from {guess} K the built-in reached {} K, not {root} K", xb[t]);
        let worst = worst_state_difference(&builtin, &xb, &eqs, &xe);
        eprintln!("cstr steady state at {:.6} K: worst relative difference {worst:.1e}", xb[t]);
        assert!(worst < TOL_STEADY, "at {root} K: worst relative difference {worst:.2e}");
    }
}

/// The linearized plant in the coordinates of the shared physical quantities.
struct Linear {
    /// Path of each state (differential variable), in the built-in's variable order.
    states: Vec<String>,
    a: Mat<f64>,
    b: Mat<f64>,
    c: Mat<f64>,
    d: Mat<f64>,
    /// `G(jω)` at each of [`OMEGAS`], then `G(0)`, as (real, imaginary) parts.
    g: Vec<(Mat<f64>, Mat<f64>)>,
}

/// Frequencies [rad/s] spanning the time constants of both plants (jacket ~seconds, residence
/// time 100 s, level loops 200–300 s).
const OMEGAS: [f64; 5] = [1e-4, 1e-3, 1e-2, 1e-1, 1.0];

/// Linearize `plant` at `(x, u)`: the states in the order `state_vars` (variable indices), inputs
/// `inputs` (input indices) and outputs `outputs` (variable indices).
fn linearize(plant: &Plant, x: &[f64], state_vars: &[usize], inputs: &[usize], outputs: &[usize]) -> Linear {
    let (n, u) = (plant.n_vars(), plant.input_values());
    let mut r = vec![0.0; n];
    let (mut jx, mut ju) = (Vec::new(), Vec::new());
    plant.jacobian(x, &u, 0.0, &mut r, &mut jx, &mut ju);
    let mut j = Mat::<f64>::zeros(n, n);
    jx.iter().for_each(|&(row, col, v)| j[(row, col)] += v);
    let mut bu = Mat::<f64>::zeros(n, inputs.len());
    for &(row, col, v) in &ju {
        if let Some(k) = inputs.iter().position(|&i| i == col) {
            bu[(row, k)] += v;
        }
    }
    // The equation that is each state's time derivative (M's 1), in `state_vars` order.
    let mass = PlantSystem::new(plant, &u).mass();
    assert_eq!(mass.len(), state_vars.len(), "{}: states {:?}", plant.name(), mass);
    let state_rows: Vec<usize> = state_vars
        .iter()
        .map(|v| mass.iter().find(|&&(_, c)| c == *v).unwrap_or_else(|| panic!("{v} is not a state")).0)
        .collect();
    let alg_cols: Vec<usize> = (0..n).filter(|c| !state_vars.contains(c)).collect();
    let alg_rows: Vec<usize> = (0..n).filter(|r| !state_rows.contains(r)).collect();
    let (nd, na, m) = (state_vars.len(), alg_cols.len(), inputs.len());
    // Z = J_aa⁻¹ [J_ad | B_a].
    let j_aa = Mat::from_fn(na, na, |p, q| j[(alg_rows[p], alg_cols[q])]);
    let rhs =
        Mat::from_fn(
            na,
            nd + m,
            |p, k| {
                if k < nd { j[(alg_rows[p], state_vars[k])] } else { bu[(alg_rows[p], k - nd)] }
            },
        );
    let z = j_aa.partial_piv_lu().solve(&rhs);
    let a = Mat::from_fn(nd, nd, |p, q| {
        j[(state_rows[p], state_vars[q])] - (0..na).map(|s| j[(state_rows[p], alg_cols[s])] * z[(s, q)]).sum::<f64>()
    });
    let b = Mat::from_fn(nd, m, |p, k| {
        bu[(state_rows[p], k)] - (0..na).map(|s| j[(state_rows[p], alg_cols[s])] * z[(s, nd + k)]).sum::<f64>()
    });
    let (mut c, mut d) = (Mat::<f64>::zeros(outputs.len(), nd), Mat::<f64>::zeros(outputs.len(), m));
    for (i, y) in outputs.iter().enumerate() {
        match state_vars.iter().position(|s| s == y) {
            Some(p) => c[(i, p)] = 1.0,
            None => {
                let s = alg_cols.iter().position(|col| col == y).unwrap();
                (0..nd).for_each(|k| c[(i, k)] = -z[(s, k)]);
                (0..m).for_each(|k| d[(i, k)] = -z[(s, nd + k)]);
            }
        }
    }
    // G(s) = C_y (sM − J)⁻¹ B_u on the full DAE, C_y selecting the outputs.
    let mut g = Vec::new();
    for omega in OMEGAS.into_iter().chain([0.0]) {
        let lhs = Mat::from_fn(n, n, |row, col| {
            let s =
                if state_rows.iter().zip(state_vars).any(|(&sr, &sv)| sr == row && sv == col) { omega } else { 0.0 };
            c64::new(-j[(row, col)], s)
        });
        let rhs = Mat::from_fn(n, m, |row, k| c64::new(bu[(row, k)], 0.0));
        let xs = lhs.partial_piv_lu().solve(&rhs);
        let re = Mat::from_fn(outputs.len(), m, |i, k| xs[(outputs[i], k)].re);
        let im = Mat::from_fn(outputs.len(), m, |i, k| xs[(outputs[i], k)].im);
        g.push((re, im));
    }
    let states = state_vars.iter().map(|&v| plant.vars()[v].path.clone()).collect();
    Linear { states, a, b, c, d, g }
}

/// Entries of a column below this fraction of the column's largest (rows in units of their
/// variables' nominal values) are not compared entry by entry: an entry that is zero in exact
/// arithmetic (the feed's enthalpy against the level setpoint) is computed as roundoff of the
/// column's large entries, in either formulation.
const SIGNIFICANT: f64 = 1e-3;

/// How far `reference + diff` is from `reference` (rows scaled by `row_scale`, the nominal values
/// of the states or outputs): the worst entrywise relative difference `|diff| / |reference|` over
/// the significant entries (see [`SIGNIFICANT`]) and the worst `|diff|` of any entry relative to
/// its column's largest scaled entry, each with its position.
fn worst_relative(reference: &Mat<f64>, diff: &Mat<f64>, row_scale: &[f64]) -> [(f64, (usize, usize)); 2] {
    let mut worst = [(0.0, (0, 0)); 2];
    for k in 0..reference.ncols() {
        let col_max = (0..reference.nrows()).map(|i| reference[(i, k)].abs() / row_scale[i]).fold(0.0, f64::max);
        for i in 0..reference.nrows() {
            let (entry, d) = (reference[(i, k)].abs(), diff[(i, k)].abs());
            if entry / row_scale[i] >= SIGNIFICANT * col_max && d / entry > worst[0].0 {
                worst[0] = (d / entry, (i, k));
            }
            let normwise = if col_max > 0.0 { d / row_scale[i] / col_max } else { d };
            if normwise > worst[1].0 {
                worst[1] = (normwise, (i, k));
            }
        }
    }
    worst
}

/// Linearize both plants at their steady states and compare A, B, C, D and G; returns the worst
/// relative difference.
fn compare_linearizations(label: &str, builtin: &Plant, xb: &[f64], eqs: &Plant, xe: &[f64]) -> f64 {
    let shared = shared_variables(builtin, eqs);
    let inputs = shared_free_inputs(builtin, eqs);
    assert!(!inputs.is_empty(), "{label}: no shared free inputs");
    let ub = PlantSystem::new(builtin, &[]).mass();
    let states_b: Vec<usize> = {
        let mut s: Vec<usize> = ub.iter().map(|&(_, c)| c).collect();
        s.sort_unstable();
        s
    };
    let states_e: Vec<usize> = states_b
        .iter()
        .map(|&i| {
            shared
                .iter()
                .find(|p| p.0 == i)
                .unwrap_or_else(|| panic!("{label}: no counterpart of state {}", builtin.vars()[i].path))
                .1
        })
        .collect();
    let (out_b, out_e): (Vec<usize>, Vec<usize>) = shared.iter().copied().unzip();
    let (in_b, in_e): (Vec<usize>, Vec<usize>) = inputs.iter().copied().unzip();
    let lb = linearize(builtin, xb, &states_b, &in_b, &out_b);
    let le = linearize(eqs, xe, &states_e, &in_e, &out_e);
    let mut worst: f64 = 0.0;
    let in_names: Vec<&str> = in_b.iter().map(|&i| builtin.inputs()[i].path.as_str()).collect();
    let nominal = |i: usize| builtin.vars()[i].spec.nominal.abs();
    let (state_scale, output_scale): (Vec<f64>, Vec<f64>) =
        (states_b.iter().map(|&i| nominal(i)).collect(), out_b.iter().map(|&i| nominal(i)).collect());
    let state = |p: usize| lb.states[p].clone();
    let output = |i: usize| builtin.vars()[out_b[i]].path.clone();
    let input = |k: usize| in_names[k].to_owned();
    let mut check = |what: String,
                     rb: &Mat<f64>,
                     diff: &Mat<f64>,
                     rows: (&[f64], &dyn Fn(usize) -> String),
                     cols: &dyn Fn(usize) -> String| {
        let [(entrywise, (i, k)), (normwise, (p, q))] = worst_relative(rb, diff, rows.0);
        eprintln!(
            "{label} {what:<9} {:>2}x{:<2} entrywise {entrywise:.1e} at ({}, {}) {:.6e}; normwise {normwise:.1e} at ({}, {})",
            rb.nrows(),
            rb.ncols(),
            rows.1(i),
            cols(k),
            rb[(i, k)],
            rows.1(p),
            cols(q)
        );
        worst = worst.max(entrywise).max(normwise);
    };
    check("A".into(), &lb.a, &(&lb.a - &le.a), (&state_scale, &state), &state);
    check("B".into(), &lb.b, &(&lb.b - &le.b), (&state_scale, &state), &input);
    check("C".into(), &lb.c, &(&lb.c - &le.c), (&output_scale, &output), &state);
    check("D".into(), &lb.d, &(&lb.d - &le.d), (&output_scale, &output), &input);
    for (k, ((gb_re, gb_im), (ge_re, ge_im))) in lb.g.iter().zip(&le.g).enumerate() {
        let omega = OMEGAS.get(k).copied().unwrap_or(0.0);
        // |G_b − G_e| relative to |G_b|, entry by entry.
        let modulus =
            |re: &Mat<f64>, im: &Mat<f64>| Mat::from_fn(re.nrows(), re.ncols(), |i, j| re[(i, j)].hypot(im[(i, j)]));
        check(
            format!("G({omega:.0e}j)"),
            &modulus(gb_re, gb_im),
            &modulus(&(gb_re - ge_re), &(gb_im - ge_im)),
            (&output_scale, &output),
            &input,
        );
    }
    worst
}

#[test]
fn cstr_as_equations_has_the_built_in_linearization_at_each_steady_state() {
    let (builtin, eqs) = (load("flowsheets/cstr_multiplicity.json"), load("tests/data/cstr_equations.json"));
    for (guess, root) in CSTR_STATES {
        let (xb, xe) = (cstr_steady_from(&builtin, guess), cstr_steady_from(&eqs, guess));
        let worst = compare_linearizations(&format!("cstr@{root}K"), &builtin, &xb, &eqs, &xe);
        assert!(worst < TOL_JACOBIAN, "cstr at {root} K: worst relative difference {worst:.2e}");
    }
}

#[test]
fn surge_tank_as_equations_has_the_built_in_linearization() {
    let (builtin, eqs) = (load("flowsheets/surge_tank_pi.json"), load("tests/data/surge_tank_equations.json"));
    let solve = |p: &Plant| steady_state(p, &p.input_values(), None, &NewtonSettings::default()).unwrap().x;
    let (xb, xe) = (solve(&builtin), solve(&eqs));
    let worst = compare_linearizations("surge tank", &builtin, &xb, &eqs, &xe);
    assert!(worst < TOL_JACOBIAN, "surge tank: worst relative difference {worst:.2e}");
}
