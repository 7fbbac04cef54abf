//! The local model of a plant's economics at its nominal optimum, the data of every
//! self-optimizing-control calculation (Halvorsen, Skogestad, Morud & Alstad, "Optimal selection of
//! controlled variables", Ind. Eng. Chem. Res. 42 (2003) 3273–3284, §3; Alstad, Skogestad & Hori,
//! "Optimal measurement combinations as controlled variables", J. Process Control 19 (2009)
//! 138–148, §2).
//!
//! For the unconstrained degrees of freedom `u` (`nu`), the disturbances `d` (`nd`) and the
//! candidate measurements `y` (`ny`), all deviations from the nominal optimum:
//!
//! ```text
//! J(u, d) ≈ J* + ½ Δuᵀ Juu Δu + Δuᵀ Jud Δd + (terms without Δu)
//! Δy      = Gy Δu + Gyd Δd + n,        d = Wd d',  n = Wn n',  ‖[d'; n']‖₂ ≤ 1
//! ```
//!
//! `Wd` scales the expected disturbances and `Wn` the measurement errors (implementation error
//! included), each a diagonal of magnitudes or a full matrix. The optimal sensitivity of the
//! measurements to the disturbances is `F = Gyd − Gy Juu⁻¹ Jud`, and the scaled data of the loss are
//! `Y = [F Wd, Wn]` (ny × (nd + ny)). Every loss of a subset `s` of the measurements depends on the
//! data only through `Ys = Y[s, :]` and `G̃ = Gy Juu^{-1/2}`, which [`LocalModel::new`] forms once.

use faer::linalg::solvers::Solve;
use faer::{Mat, MatRef, Side};

use crate::error::{SocError, field};

/// Most candidate measurements a model may have: the search factors a matrix as large as the
/// candidate set at each of its nodes, so thousands of candidates would be work without end.
pub const MAX_MEASUREMENTS: usize = 500;

/// Relative asymmetry of `Juu` accepted as round-off (a Hessian from finite differences); the
/// symmetric part is used.
const SYMMETRY_TOLERANCE: f64 = 1e-8;

/// The model's data as given (names and matrices, SI or any consistent units), checked by
/// [`LocalModel::new`].
#[derive(Debug, Clone)]
pub struct Parts {
    /// Names of the unconstrained degrees of freedom (nu).
    pub inputs: Vec<String>,
    /// Names of the disturbances (nd; may be empty).
    pub disturbances: Vec<String>,
    /// Names of the candidate measurements (ny).
    pub measurements: Vec<String>,
    /// ∂y/∂u at the optimum, ny × nu.
    pub gy: Mat<f64>,
    /// ∂y/∂d at the optimum, ny × nd.
    pub gyd: Mat<f64>,
    /// ∂²J/∂u², nu × nu: symmetric positive definite at an unconstrained optimum.
    pub juu: Mat<f64>,
    /// ∂²J/∂u∂d, nu × nd.
    pub jud: Mat<f64>,
    /// Disturbance magnitudes, nd × nd (a diagonal is given as a diagonal matrix).
    pub wd: Mat<f64>,
    /// Measurement-error magnitudes, ny × ny.
    pub wn: Mat<f64>,
}

/// A checked local model with the quantities every loss uses, formed on scaled data.
///
/// The losses do not change when a measurement's unit changes (its row of `Gy`, `Gyd` and `Wn`
/// scaled together: `H` absorbs it), and they scale with the cost's unit (`Juu` and `Jud`
/// together). So the quantities below are formed on data with each row of `Y` scaled to a largest
/// entry of 1 (`D = diag(1/max|Y_i|)`) and `Juu`, `Jud` divided by `Juu`'s largest eigenvalue
/// (`c`): magnitudes anywhere in the double range then neither overflow nor underflow in `Y Yᵀ`
/// or in the losses. Every loss and `H` the crate returns is brought back to the data's units
/// (losses ÷ c, `H` → `H D_s / √c`).
#[derive(Debug, Clone)]
pub struct LocalModel {
    parts: Parts,
    /// `c`: the scaled cost is `c J`.
    cost_scale: f64,
    /// `D`'s diagonal: the scaled measurement `i` is `y_i · row_scale[i]`.
    row_scale: Vec<f64>,
    /// `D Gy`, `D Gyd`.
    gy: Mat<f64>,
    gyd: Mat<f64>,
    /// `(c Juu)^{1/2}`, the principal square root.
    juu_half: Mat<f64>,
    /// `G̃ = D Gy (c Juu)^{-1/2}`, ny × nu.
    g_tilde: Mat<f64>,
    /// `Juu⁻¹ Jud`, nu × nd (the same scaled or not).
    juu_inv_jud: Mat<f64>,
    /// `Y = D [F Wd, Wn]`, ny × (nd + ny).
    y: Mat<f64>,
    /// `Y Yᵀ`, ny × ny, positive definite.
    y2: Mat<f64>,
}

impl LocalModel {
    /// Check the data and form the scaled `Juu^{1/2}`, `G̃`, `Y` and `Y Yᵀ`.
    ///
    /// # Errors
    /// [`SocError::Field`] naming the field: a name empty, given twice or with a comma or control
    /// character, a matrix of the wrong shape or with a value that is not finite, `Juu` not
    /// symmetric or not positive definite, measurement errors that leave
    /// `Y Yᵀ` singular, a `Gy` whose rank is less than the number of inputs, a product that
    /// overflows.
    pub fn new(parts: Parts) -> Result<LocalModel, SocError> {
        check_names(&parts)?;
        check_shapes(&parts)?;
        let (largest, juu_half, juu_inv_half) = normalized_roots(parts.juu.as_ref())?;
        let cost_scale = 1.0 / largest;
        let juu = &parts.juu * cost_scale;
        let juu_inv_jud = juu.llt(Side::Lower).map_err(|_| not_definite(f64::NAN))?.solve(&parts.jud * cost_scale);
        let f = &parts.gyd - &parts.gy * &juu_inv_jud;
        finite("Gyd", "F = Gyd − Gy Juu⁻¹ Jud", f.as_ref())?;
        let (ny, nd) = (parts.gy.nrows(), parts.gyd.ncols());
        let mut y = Mat::zeros(ny, nd + ny);
        y.as_mut().get_mut(.., ..nd).copy_from(&f * &parts.wd);
        y.as_mut().get_mut(.., nd..).copy_from(&parts.wn);
        finite("Wd", "F Wd", y.as_ref())?;
        let row_scale = row_scales(&y, &parts.measurements)?;
        let scale_rows = |m: &Mat<f64>| Mat::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)] * row_scale[i]);
        let (gy, gyd, y) = (scale_rows(&parts.gy), scale_rows(&parts.gyd), scale_rows(&y));
        let g_tilde = &gy * &juu_inv_half;
        finite("Gy", "Gy Juu^{-1/2}", g_tilde.as_ref())?;
        let y2 = &y * y.transpose();
        y2.llt(Side::Lower).map_err(|_| {
            field("Wn", "the measurement errors, with the disturbances, leave some combination of the measurements without an error that counts (Y Yᵀ is singular to working precision: errors zero, or negligible beside the disturbances' effect F Wd): give the measurements errors of a size that counts")
        })?;
        check_rank(&y2, &g_tilde)?;
        Ok(LocalModel { parts, cost_scale, row_scale, gy, gyd, juu_half, g_tilde, juu_inv_jud, y, y2 })
    }

    /// A loss of the scaled data in the data's own units.
    pub(crate) fn loss(&self, scaled: f64) -> f64 {
        scaled / self.cost_scale
    }

    /// A loss in the data's own units as one of the scaled data.
    pub(crate) fn scaled_loss(&self, loss: f64) -> f64 {
        loss * self.cost_scale
    }

    /// A combination `H'` of the scaled measurements `subset` as one of the data's measurements:
    /// `H = H' D_s / √c`.
    pub(crate) fn unscale_h(&self, h: &Mat<f64>, subset: &[usize]) -> Mat<f64> {
        let root = self.cost_scale.sqrt();
        Mat::from_fn(h.nrows(), h.ncols(), |i, j| h[(i, j)] * self.row_scale[subset[j]] / root)
    }

    /// A combination `H` of the data's measurements `subset` as one of the scaled ones:
    /// `H' = H D_s⁻¹ √c`.
    pub(crate) fn scale_h(&self, h: MatRef<'_, f64>, subset: &[usize]) -> Mat<f64> {
        let root = self.cost_scale.sqrt();
        Mat::from_fn(h.nrows(), h.ncols(), |i, j| h[(i, j)] / self.row_scale[subset[j]] * root)
    }

    /// `D Gy`.
    pub(crate) fn gy(&self) -> MatRef<'_, f64> {
        self.gy.as_ref()
    }

    /// `D Gyd`.
    pub(crate) fn gyd(&self) -> MatRef<'_, f64> {
        self.gyd.as_ref()
    }

    /// Number of unconstrained degrees of freedom.
    pub fn nu(&self) -> usize {
        self.parts.gy.ncols()
    }

    /// Number of disturbances.
    pub fn nd(&self) -> usize {
        self.parts.gyd.ncols()
    }

    /// Number of candidate measurements.
    pub fn ny(&self) -> usize {
        self.parts.gy.nrows()
    }

    /// The data as given.
    pub fn parts(&self) -> &Parts {
        &self.parts
    }

    /// `(c Juu)^{1/2}`.
    pub(crate) fn juu_half(&self) -> MatRef<'_, f64> {
        self.juu_half.as_ref()
    }

    /// `G̃ = D Gy (c Juu)^{-1/2}`.
    pub(crate) fn g_tilde(&self) -> MatRef<'_, f64> {
        self.g_tilde.as_ref()
    }

    /// `Juu⁻¹ Jud`.
    pub fn juu_inv_jud(&self) -> MatRef<'_, f64> {
        self.juu_inv_jud.as_ref()
    }

    /// `Y = D [F Wd, Wn]`.
    pub(crate) fn y(&self) -> MatRef<'_, f64> {
        self.y.as_ref()
    }

    /// `Y Yᵀ` of the scaled data.
    pub(crate) fn y2(&self) -> MatRef<'_, f64> {
        self.y2.as_ref()
    }
}

/// Rank below which the candidates' scaled gains `L⁻¹ G̃_s` count as rank-deficient
/// (`σ_min/σ_max`): exactly collinear measurements come out near 1e-15 (round-off), the most nearly
/// collinear real subsets of the evaporator (P2, T2, T3) near 5e-11, whose losses still carry four
/// digits.
pub(crate) const RANK_TOLERANCE: f64 = 1e-12;

/// `D`: one over each row's largest entry of `Y`.
fn row_scales(y: &Mat<f64>, names: &[String]) -> Result<Vec<f64>, SocError> {
    (0..y.nrows())
        .map(|i| {
            let m = y.row(i).iter().fold(0.0_f64, |a, v| a.max(v.abs()));
            match m > 0.0 {
                true => Ok(1.0 / m),
                false => Err(field(
                    "Wn",
                    format!("measurement `{}` has no error and no disturbance moves it: give it an error", names[i]),
                )),
            }
        })
        .collect()
}

/// A product of the data that overflowed.
fn finite(name: &'static str, what: &str, m: MatRef<'_, f64>) -> Result<(), SocError> {
    match (0..m.ncols()).all(|j| m.col(j).iter().all(|v| v.is_finite())) {
        true => Ok(()),
        false => Err(field(
            name,
            format!("{what} overflows double precision: give the data in units that keep them nearer 1"),
        )),
    }
}

/// All the candidates together must hold the inputs: `G̃` of full column rank.
fn check_rank(y2: &Mat<f64>, g_tilde: &Mat<f64>) -> Result<(), SocError> {
    let l = y2.llt(Side::Lower).map_err(|_| field("Wn", "Y Yᵀ is singular"))?;
    let mut w = g_tilde.clone();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l.L(), w.as_mut(), faer::Par::Seq);
    let sigma = w.singular_values().map_err(|e| SocError::Numerical(format!("{e:?}")))?;
    let rank = sigma.iter().filter(|&&s| s > RANK_TOLERANCE * sigma[0]).count();
    match rank == g_tilde.ncols() {
        true => Ok(()),
        false => Err(field(
            "Gy",
            format!(
                "has rank {rank} but there are {} inputs: no combination of the measurements can hold them all; leave out the inputs the measurements cannot tell apart",
                g_tilde.ncols()
            ),
        )),
    }
}

/// Every list of names non-empty where it must be, each name once.
fn check_names(p: &Parts) -> Result<(), SocError> {
    let lists: [(&'static str, &Vec<String>, bool); 3] = [
        ("inputs", &p.inputs, false),
        ("disturbances", &p.disturbances, true),
        ("measurements", &p.measurements, false),
    ];
    for (name, list, may_be_empty) in lists {
        if list.is_empty() && !may_be_empty {
            return Err(field(name, "is empty: give at least one name"));
        }
        for (k, n) in list.iter().enumerate() {
            if n.trim().is_empty() || n.trim() != n || n.contains(',') || n.chars().any(char::is_control) {
                return Err(field(
                    name,
                    format!(
                        "entry {k} (counted from 0), {n:?}: give a name without commas, control characters or surrounding spaces"
                    ),
                ));
            }
            if let Some(j) = list[..k].iter().position(|m| m == n) {
                return Err(field(
                    name,
                    format!("`{n}` is given twice (entries {} and {}, counted from 1)", j + 1, k + 1),
                ));
            }
        }
    }
    if p.measurements.len() > MAX_MEASUREMENTS {
        return Err(field(
            "measurements",
            format!("{} candidates; at most {MAX_MEASUREMENTS} are searched: preselect them", p.measurements.len()),
        ));
    }
    Ok(())
}

/// Each matrix of the size its names give, every value finite (a weight's signs do not matter:
/// only `W Wᵀ` enters the losses).
fn check_shapes(p: &Parts) -> Result<(), SocError> {
    let (nu, nd, ny) = (p.inputs.len(), p.disturbances.len(), p.measurements.len());
    let shapes: [(&'static str, &Mat<f64>, usize, usize, &str); 6] = [
        ("Gy", &p.gy, ny, nu, "measurements × inputs"),
        ("Gyd", &p.gyd, ny, nd, "measurements × disturbances"),
        ("Juu", &p.juu, nu, nu, "inputs × inputs"),
        ("Jud", &p.jud, nu, nd, "inputs × disturbances"),
        ("Wd", &p.wd, nd, nd, "disturbances × disturbances"),
        ("Wn", &p.wn, ny, ny, "measurements × measurements"),
    ];
    for (name, m, rows, cols, what) in shapes {
        if (m.nrows(), m.ncols()) != (rows, cols) {
            return Err(field(
                name,
                format!(
                    "is {} × {}; it must be {rows} × {cols} ({what}, from the lists of names)",
                    m.nrows(),
                    m.ncols()
                ),
            ));
        }
        if let Some((i, j)) =
            (0..rows).flat_map(|i| (0..cols).map(move |j| (i, j))).find(|&(i, j)| !m[(i, j)].is_finite())
        {
            return Err(field(name, format!("entry [{i}][{j}] (counted from 0) is not a finite number")));
        }
    }
    Ok(())
}

/// The largest eigenvalue `λ_max` of `Juu` (checked symmetric; its symmetric part is used), and
/// `(Juu/λ_max)^{1/2}`, `(Juu/λ_max)^{-1/2}` from one eigen-decomposition. `Juu` is divided by its
/// largest entry first, so that entries near 1e300 do not overflow.
fn normalized_roots(juu: MatRef<'_, f64>) -> Result<(f64, Mat<f64>, Mat<f64>), SocError> {
    let n = juu.nrows();
    let scale = (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).map(|(i, j)| juu[(i, j)].abs()).fold(0.0, f64::max);
    if !(scale > 0.0 && scale.is_finite()) {
        return Err(not_definite(0.0));
    }
    for i in 0..n {
        for j in 0..i {
            if (juu[(i, j)] - juu[(j, i)]).abs() > SYMMETRY_TOLERANCE * scale {
                return Err(field(
                    "Juu",
                    format!(
                        "is not symmetric: [{i}][{j}] = {:e} but [{j}][{i}] = {:e}; a Hessian is symmetric",
                        juu[(i, j)],
                        juu[(j, i)]
                    ),
                ));
            }
        }
    }
    let sym = Mat::from_fn(n, n, |i, j| 0.5 * (juu[(i, j)] / scale + juu[(j, i)] / scale));
    let eig = sym.self_adjoint_eigen(Side::Lower).map_err(|e| SocError::Numerical(format!("Juu: {e:?}")))?;
    let lambda: Vec<f64> = eig.S().column_vector().iter().copied().collect();
    let largest = lambda.iter().copied().fold(0.0, f64::max);
    if largest <= 0.0 || lambda[0] <= largest * f64::EPSILON * n as f64 {
        return Err(not_definite(lambda[0] / largest.max(f64::MIN_POSITIVE)));
    }
    let v = eig.U();
    let root =
        |p: f64| Mat::from_fn(n, n, |i, j| (0..n).map(|k| v[(i, k)] * (lambda[k] / largest).powf(p) * v[(j, k)]).sum());
    Ok((largest * scale, root(0.5), root(-0.5)))
}

fn not_definite(smallest: f64) -> SocError {
    field(
        "Juu",
        format!(
            "is not positive definite (smallest eigenvalue {smallest:e} of the largest: negative, zero or lost in round-off): the inputs are not at an unconstrained minimum of the cost; leave out the inputs that a constraint holds, or check the cost's sign"
        ),
    )
}
