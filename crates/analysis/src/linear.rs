//! Linearization of the plant DAE `M dx/dt = f(x, u)` at a converged steady state.
//!
//! With `J = ∂f/∂x` (all equations), `B = ∂f/∂u` (exact, by dual numbers) and `C` selecting the
//! output variables, deviations obey `M δẋ = J δx + B δu`, `δy = C δx`:
//! - steady-state gain `G(0) = −C J⁻¹ B` (one sparse LU of `J`, no inverse formed);
//! - frequency response `G(jω) = C (jωM − J)⁻¹ B` (one complex sparse LU per frequency, the
//!   symbolic analysis shared);
//! - state space: `M` pairs each differential variable `x_d` with the equation that is its time
//!   derivative; the other (algebraic) equations `0 = J_ad δx_d + J_aa δx_a + B_a δu` are solved
//!   for `δx_a` (index 1: `J_aa` nonsingular), giving
//!   `A = J_dd − J_da J_aa⁻¹ J_ad`, `B_ss = B_d − J_da J_aa⁻¹ B_a`, and for an algebraic output
//!   `C = −(J_aa⁻¹ J_ad)_y`, `D = −(J_aa⁻¹ B_a)_y` (a differential output has `C = e_y`, `D = 0`).
//!   `J_aa⁻¹ [J_ad | B_a]` is one sparse LU with many right-hand sides. Then
//!   `G(0) = D − C A⁻¹ B_ss` — the same number by a second route, and the eigenvalues of `A` give the
//!   time constants `τ = −1/Re λ`.
//!
//! Units are SI throughout (s, mol, K, Pa, J); time derivatives are per second.

use faer::linalg::solvers::Solve;
use faer::{Mat, c64};
use plantwide_flowsheet::Plant;
use plantwide_solve::sparse::SparseLu;
use plantwide_solve::{PlantSystem, System};
use rayon::prelude::*;

use crate::error::AnalysisError;
use crate::response::SparseResponse;

/// The Jacobians of a plant at one point.
#[derive(Debug, Clone)]
pub struct Linearization {
    n: usize,
    jx: Vec<(usize, usize, f64)>,
    ju: Vec<(usize, usize, f64)>,
    mass: Vec<(usize, usize)>,
}

/// A linear state-space model `dx/dt = A x + B u`, `y = C x + D u` in deviation variables.
#[derive(Debug, Clone)]
pub struct StateSpace {
    /// Variable index of each state (the differential variables, in variable order).
    pub states: Vec<usize>,
    /// State matrix [1/s].
    pub a: Mat<f64>,
    /// Input matrix.
    pub b: Mat<f64>,
    /// Output matrix.
    pub c: Mat<f64>,
    /// Feedthrough matrix.
    pub d: Mat<f64>,
}

fn singular(what: &str) -> AnalysisError {
    AnalysisError::Singular(format!(
        "{what} is singular at the steady state: an inventory is not tied down (an uncontrolled level or an integrating controller with nothing to integrate), or the DAE is of index > 1"
    ))
}

/// Solve `A X = B` in place for the square sparse `A` given by triplets (duplicates summed), with
/// the solvers' sparse LU, one column of `B` at a time.
fn solve_sparse(n: usize, a: &[(usize, usize, f64)], b: &mut Mat<f64>, what: &str) -> Result<(), AnalysisError> {
    let mut lu = SparseLu::default();
    lu.factor(n, a).map_err(|_| singular(what))?;
    for k in 0..b.ncols() {
        let col = b.col_mut(k).try_as_col_major_mut().ok_or_else(|| singular(what))?.as_slice_mut();
        lu.solve_in_place(col).map_err(|_| singular(what))?;
    }
    Ok(())
}

fn check_finite(m: &Mat<f64>, what: &str) -> Result<(), AnalysisError> {
    if m.col_iter().all(|c| c.iter().all(|v| v.is_finite())) { Ok(()) } else { Err(singular(what)) }
}

impl Linearization {
    /// Jacobians of `plant` at the point `(x, u)` (a converged steady state).
    pub fn new(plant: &Plant, x: &[f64], u: &[f64]) -> Linearization {
        let n = plant.n_vars();
        let mut r = vec![0.0; plant.n_eqs()];
        let (mut jx, mut ju) = (Vec::new(), Vec::new());
        plant.jacobian(x, u, 0.0, &mut r, &mut jx, &mut ju);
        let mass = PlantSystem::new(plant, u).mass();
        Linearization { n, jx, ju, mass }
    }

    /// From explicit parts: `jx` = `∂f/∂x` and `ju` = `∂f/∂u` as triplets (duplicates summed), and
    /// the mass-matrix entries `(equation, variable)` of the differential variables.
    pub fn from_parts(
        n: usize,
        jx: Vec<(usize, usize, f64)>,
        ju: Vec<(usize, usize, f64)>,
        mass: Vec<(usize, usize)>,
    ) -> Linearization {
        Linearization { n, jx, ju, mass }
    }

    /// Number of variables.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Number of differential variables (states).
    pub fn n_states(&self) -> usize {
        self.mass.len()
    }

    /// Dense `∂f/∂u` columns of the chosen inputs (`n × inputs`).
    fn input_columns(&self, inputs: &[usize]) -> Mat<f64> {
        let mut b = Mat::<f64>::zeros(self.n, inputs.len());
        for &(i, j, v) in &self.ju {
            for (k, _) in inputs.iter().enumerate().filter(|(_, inp)| **inp == j) {
                b[(i, k)] += v;
            }
        }
        b
    }

    /// Steady-state gain `dy/du = −C J⁻¹ B` in SI units (outputs × inputs); `inputs` are input
    /// indices, `outputs` variable indices.
    pub fn steady_gain(&self, inputs: &[usize], outputs: &[usize]) -> Result<Mat<f64>, AnalysisError> {
        let mut x = self.input_columns(inputs);
        solve_sparse(self.n, &self.jx, &mut x, "the plant Jacobian ∂f/∂x")?;
        check_finite(&x, "the plant Jacobian ∂f/∂x")?;
        Ok(Mat::from_fn(outputs.len(), inputs.len(), |i, k| -x[(outputs[i], k)]))
    }

    /// The steady state's response to moves of the inputs: `δx = −J⁻¹ B δu` for each column of
    /// `du` (rows: every input of the plant, SI), as the columns of the result (`n × du.ncols()`).
    pub fn state_moves(&self, du: &Mat<f64>) -> Result<Mat<f64>, AnalysisError> {
        let mut x = Mat::<f64>::zeros(self.n, du.ncols());
        for &(i, j, v) in &self.ju {
            for k in 0..du.ncols() {
                x[(i, k)] -= v * du[(j, k)];
            }
        }
        solve_sparse(self.n, &self.jx, &mut x, "the plant Jacobian ∂f/∂x")?;
        check_finite(&x, "the plant Jacobian ∂f/∂x")?;
        Ok(x)
    }

    /// The adjoint `λ` of `J` for weights `w` on the variables: `Jᵀ λ = w` (one sparse LU of
    /// `Jᵀ`). For a function `φ = wᵀx` of the steady state, `−λ` weighs the equations' residuals
    /// in `dφ` and `∂²φ/∂u∂u = −λᵀ f''[δw, δw']` along input moves and their state responses.
    pub fn adjoint(&self, w: &[f64]) -> Result<Vec<f64>, AnalysisError> {
        let jt: Vec<(usize, usize, f64)> = self.jx.iter().map(|&(i, j, v)| (j, i, v)).collect();
        let mut lambda = Mat::from_fn(self.n, 1, |i, _| w[i]);
        solve_sparse(self.n, &jt, &mut lambda, "the transposed plant Jacobian ∂f/∂xᵀ")?;
        check_finite(&lambda, "the transposed plant Jacobian ∂f/∂xᵀ")?;
        Ok(lambda.col(0).iter().copied().collect())
    }

    /// Frequency response `G(jω) = C (jωM − J)⁻¹ B` at each `ω` [rad/s], in parallel.
    pub fn frequency_response(
        &self,
        inputs: &[usize],
        outputs: &[usize],
        omegas: &[f64],
    ) -> Result<Vec<Mat<c64>>, AnalysisError> {
        let response = self.response(inputs, outputs)?;
        omegas.par_iter().map(|&w| response.at(w)).collect()
    }

    /// The frequency response from `inputs` (input indices) to `outputs` (variable indices), to be
    /// evaluated one frequency at a time ([`SparseResponse::at`]).
    pub fn response(&self, inputs: &[usize], outputs: &[usize]) -> Result<SparseResponse, AnalysisError> {
        SparseResponse::new(self.n, &self.jx, &self.mass, self.input_columns(inputs), outputs)
    }

    /// State-space model for the chosen inputs (input indices) and outputs (variable indices), the
    /// algebraic variables eliminated by sparse solves.
    pub fn state_space(&self, inputs: &[usize], outputs: &[usize]) -> Result<StateSpace, AnalysisError> {
        let n = self.n;
        // Position of each variable and equation among the differential (Some(d)) or algebraic ones.
        let mut col_d = vec![None; n];
        let mut row_d = vec![None; n];
        let mut states: Vec<(usize, usize)> = self.mass.iter().map(|&(r, c)| (c, r)).collect();
        states.sort_unstable();
        for (p, &(c, r)) in states.iter().enumerate() {
            col_d[c] = Some(p);
            row_d[r] = Some(p);
        }
        let (mut col_a, mut row_a) = (vec![usize::MAX; n], vec![usize::MAX; n]);
        for (k, j) in (0..n).filter(|&j| col_d[j].is_none()).enumerate() {
            col_a[j] = k;
        }
        for (k, i) in (0..n).filter(|&i| row_d[i].is_none()).enumerate() {
            row_a[i] = k;
        }
        let na = n - states.len();
        let (nd, m) = (states.len(), inputs.len());
        // Blocks: J_dd, J_da (dense rows, few), J_aa (sparse), J_ad and B_a as right-hand sides.
        let mut a = Mat::<f64>::zeros(nd, nd);
        let mut j_da: Vec<(usize, usize, f64)> = Vec::new();
        let mut j_aa: Vec<(usize, usize, f64)> = Vec::new();
        let mut rhs = Mat::<f64>::zeros(na, nd + m);
        for &(i, j, v) in &self.jx {
            match (row_d[i], col_d[j]) {
                (Some(p), Some(q)) => a[(p, q)] += v,
                (Some(p), None) => j_da.push((p, col_a[j], v)),
                (None, Some(q)) => rhs[(row_a[i], q)] += v,
                (None, None) => j_aa.push((row_a[i], col_a[j], v)),
            }
        }
        let bu = self.input_columns(inputs);
        let mut b = Mat::<f64>::zeros(nd, m);
        for i in 0..n {
            for k in 0..m {
                match row_d[i] {
                    Some(p) => b[(p, k)] += bu[(i, k)],
                    None => rhs[(row_a[i], nd + k)] += bu[(i, k)],
                }
            }
        }
        // Z = J_aa⁻¹ [J_ad | B_a].
        if na > 0 {
            solve_sparse(na, &j_aa, &mut rhs, "the algebraic block ∂g/∂x_a of the plant Jacobian")?;
            check_finite(&rhs, "the algebraic block ∂g/∂x_a of the plant Jacobian")?;
        }
        let z = rhs;
        for &(p, q, v) in &j_da {
            for k in 0..nd {
                a[(p, k)] -= v * z[(q, k)];
            }
            for k in 0..m {
                b[(p, k)] -= v * z[(q, nd + k)];
            }
        }
        let mut c = Mat::<f64>::zeros(outputs.len(), nd);
        let mut d = Mat::<f64>::zeros(outputs.len(), m);
        for (i, &y) in outputs.iter().enumerate() {
            match col_d[y] {
                Some(p) => c[(i, p)] = 1.0,
                None => {
                    for k in 0..nd {
                        c[(i, k)] = -z[(col_a[y], k)];
                    }
                    for k in 0..m {
                        d[(i, k)] = -z[(col_a[y], nd + k)];
                    }
                }
            }
        }
        Ok(StateSpace { states: states.iter().map(|&(c, _)| c).collect(), a, b, c, d })
    }
}

impl StateSpace {
    /// Steady-state gain `D − C A⁻¹ B` (dense solve with `A`).
    pub fn steady_gain(&self) -> Result<Mat<f64>, AnalysisError> {
        if self.a.nrows() == 0 {
            return Ok(self.d.clone());
        }
        let x = self.a.partial_piv_lu().solve(&self.b);
        check_finite(&x, "the state matrix A")?;
        Ok(&self.d - &self.c * &x)
    }

    /// Eigenvalues of `A` [1/s], slowest (smallest |Re λ|) first.
    pub fn eigenvalues(&self) -> Result<Vec<c64>, AnalysisError> {
        if self.a.nrows() == 0 {
            return Ok(Vec::new());
        }
        // Balanced first, as LAPACK's `dgeev` does: on an unbalanced plant matrix the QR
        // algorithm's `ε‖A‖` moved a CSTR's unstable pair by 1.5e-3 of its real part.
        let (a, _) = crate::balance::balanced(&self.a);
        let mut ev = a.eigenvalues().map_err(|e| AnalysisError::Singular(format!("eigenvalues of A: {e:?}")))?;
        ev.sort_by(|x, y| x.re.abs().total_cmp(&y.re.abs()).then(x.im.total_cmp(&y.im)));
        Ok(ev)
    }

    /// Time constants `τ = −1/Re λ` \[s\] of the stable eigenvalues, slowest first (a complex pair
    /// counted once); eigenvalues with `Re λ ≥ 0` are skipped (see [`StateSpace::unstable`]).
    pub fn time_constants(&self) -> Result<Vec<f64>, AnalysisError> {
        Ok(self.eigenvalues()?.iter().filter(|l| l.re < 0.0 && l.im >= 0.0).map(|l| -1.0 / l.re).collect())
    }

    /// Eigenvalues with `Re λ ≥ −tol·max|λ|`: integrating or unstable modes.
    pub fn unstable(&self, tol: f64) -> Result<Vec<c64>, AnalysisError> {
        let ev = self.eigenvalues()?;
        let scale = ev.iter().map(|l| l.norm()).fold(0.0, f64::max);
        Ok(ev.into_iter().filter(|l| l.re >= -tol * scale).collect())
    }

    /// Frequency response `D + C (jωI − A)⁻¹ B` (dense; for checks and small models).
    pub fn frequency_response(&self, omega: f64) -> Mat<c64> {
        let nd = self.a.nrows();
        let lhs = Mat::from_fn(nd, nd, |i, j| c64::new(-self.a[(i, j)], if i == j { omega } else { 0.0 }));
        let rhs = Mat::from_fn(nd, self.b.ncols(), |i, k| c64::new(self.b[(i, k)], 0.0));
        let x = if nd > 0 { lhs.partial_piv_lu().solve(&rhs) } else { rhs };
        Mat::from_fn(self.c.nrows(), self.b.ncols(), |i, k| {
            let cx: c64 = (0..nd).map(|p| x[(p, k)] * self.c[(i, p)]).sum();
            cx + c64::new(self.d[(i, k)], 0.0)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The state matrix of `flowsheets/cstr_multiplicity.json` with two PI loops added (T by the
    /// coolant, x_A by the feed; `plantwide linearize`, states N_A, N_B, U, T_j, three integrals):
    /// entries from 9e-8 to 2e4. Its eigenvalues against LAPACK's `dgeev` (NumPy 1.26
    /// `linalg.eigvals`, which balances) to 1e-9 of each; unbalanced, the QR algorithm moved the
    /// unstable pair's real part from 9.39125e-4 to 9.37688e-4.
    #[test]
    fn the_eigenvalues_of_a_badly_scaled_plant_matrix_agree_with_lapack() {
        let rows: [[f64; 7]; 7] = [
            [
                -0.014694749110733386,
                0.739080913025507,
                -8.664420151992543e-08,
                0.0,
                -0.009145303882155403,
                0.0,
                0.2065697379967852,
            ],
            [
                0.002764723379074954,
                -0.007359881968738706,
                8.664420151992543e-08,
                0.0,
                -0.00011395537710385524,
                0.0,
                0.0,
            ],
            [
                -199.4373875488924,
                -22308.836190333266,
                -0.019001123257343436,
                2000.0,
                272.63828225433133,
                0.0,
                -6139.769037609448,
            ],
            [
                -0.01349070779966024,
                -0.013490707799660244,
                -4.581673566716462e-07,
                -0.0547801147231118,
                0.0,
                -2.0418116173194525e-05,
                0.0,
            ],
            [0.001, 0.001, 0.0, 0.0, 0.0, 0.0, 0.0],
            [0.1962995632231186, 0.19629956322311862, 6.666666666666667e-06, 0.0, 0.0, 0.0, 0.0],
            [-1.2307180727216425e-05, 0.0009876928192727836, 0.0, 0.0, 0.0, 0.0, 0.0],
        ];
        let ss = StateSpace {
            states: (0..7).collect(),
            a: Mat::from_fn(7, 7, |i, j| rows[i][j]),
            b: Mat::zeros(7, 0),
            c: Mat::zeros(0, 7),
            d: Mat::zeros(0, 0),
        };
        let lapack = [
            c64::new(-0.000116211212927003, 0.0),
            c64::new(-0.00016740762908809984, 0.0),
            c64::new(0.0009391251960509652, -0.002455785034788335),
            c64::new(0.0009391251960509652, 0.002455785034788335),
            c64::new(-0.024700011264606435, 0.0),
            c64::new(-0.036365244672703814, -0.02463285905518843),
            c64::new(-0.036365244672703814, 0.02463285905518843),
        ];
        let ev = ss.eigenvalues().unwrap();
        for (l, e) in ev.iter().zip(lapack) {
            assert!((l - e).norm() < 1e-9 * e.norm(), "{l} against LAPACK's {e}: {ev:?}");
        }
    }

    /// `dx/dt = −x + z`, `0 = −z − x + u` (so `z = u − x`, `dx/dt = −2x + u`), output `z`:
    /// `A = −2`, `B = 1`, `C = −1`, `D = 1`, `G(s) = (s + 1)/(s + 2)`, `G(0) = 1/2`.
    /// Variables `[x, z]`, equations `[x-equation, z-equation]`; listed with a row swap to check
    /// that equations and variables are paired through `M`, not by position.
    fn toy() -> Linearization {
        // Rows: 0 = algebraic equation, 1 = dx/dt. Mass pairs (row 1, var 0).
        let jx = vec![(1, 0, -1.0), (1, 1, 1.0), (0, 1, -1.0), (0, 0, -1.0)];
        let ju = vec![(0, 0, 1.0)];
        Linearization::from_parts(2, jx, ju, vec![(1, 0)])
    }

    #[test]
    fn state_space_of_a_small_dae_matches_the_hand_elimination() {
        let ss = toy().state_space(&[0], &[1, 0]).unwrap();
        assert_eq!(ss.states, vec![0]);
        assert!((ss.a[(0, 0)] + 2.0).abs() < 1e-15 && (ss.b[(0, 0)] - 1.0).abs() < 1e-15);
        // Output z: C = −1, D = 1; output x (a state): C = 1, D = 0.
        assert!((ss.c[(0, 0)] + 1.0).abs() < 1e-15 && (ss.d[(0, 0)] - 1.0).abs() < 1e-15);
        assert!((ss.c[(1, 0)] - 1.0).abs() < 1e-15 && ss.d[(1, 0)] == 0.0);
        let g = ss.steady_gain().unwrap();
        assert!((g[(0, 0)] - 0.5).abs() < 1e-15 && (g[(1, 0)] - 0.5).abs() < 1e-15);
        let direct = toy().steady_gain(&[0], &[1, 0]).unwrap();
        assert!((direct[(0, 0)] - 0.5).abs() < 1e-15 && (direct[(1, 0)] - 0.5).abs() < 1e-15);
        assert!((ss.time_constants().unwrap()[0] - 0.5).abs() < 1e-15);
    }

    #[test]
    fn sparse_frequency_response_matches_the_transfer_function() {
        let lin = toy();
        let ss = lin.state_space(&[0], &[1]).unwrap();
        let omegas = [0.0, 0.3, 1.0, 7.0];
        let g = lin.frequency_response(&[0], &[1], &omegas).unwrap();
        for (w, gw) in omegas.iter().zip(&g) {
            let exact = c64::new(1.0, *w) / c64::new(2.0, *w);
            assert!((gw[(0, 0)] - exact).norm() < 1e-14, "ω = {w}: {:?} vs {exact:?}", gw[(0, 0)]);
            assert!((ss.frequency_response(*w)[(0, 0)] - exact).norm() < 1e-14);
        }
    }

    #[test]
    fn a_singular_jacobian_is_an_error_not_a_panic() {
        // dx/dt = 0·x: an integrator with nothing tying it down.
        let lin = Linearization::from_parts(1, vec![(0, 0, 0.0)], vec![(0, 0, 1.0)], vec![(0, 0)]);
        assert!(matches!(lin.steady_gain(&[0], &[0]), Err(AnalysisError::Singular(_))));
    }
}
