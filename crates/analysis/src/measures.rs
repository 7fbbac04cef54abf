//! Interaction measures of a gain matrix `G` (outputs × inputs).
//!
//! - Relative gain array (Bristol 1966): `Λ = G ∘ (G⁻¹)ᵀ` (element-wise product; `G⁺` for a
//!   non-square `G`). Rows and columns of a square RGA sum to 1; `λ_ij` is the ratio of the
//!   open-loop gain `y_i/u_j` to the gain with all other outputs held by the other inputs.
//! - RGA number of a pairing `P` (permutation matrix): `‖Λ − P‖_sum = Σ_ij |λ_ij − p_ij|`.
//! - Singular values and directions `G = U Σ Vᵀ`; condition number `γ = σ_max/σ_min`.
//! - Niederlinski index of a pairing (Niederlinski 1971; Grosdidier, Morari & Holt 1985):
//!   `NI = det G / Π_i g_{i,p(i)}` with the paired elements brought onto the diagonal; `NI < 0`
//!   means the decentralized loops are unstable under integral action for any tuning.
//! - Block relative gain (Manousiouthakis, Savage & Arkun 1986) of a block of outputs `y₁` paired
//!   with inputs `u₁`: `BRG = G₁₁ · [G⁻¹]₁₁`, the block's open-loop gain times the inverse of its
//!   gain with every other output held (`Ĝ₁₁ = G₁₁ − G₁₂ G₂₂⁻¹ G₂₁ = ([G⁻¹]₁₁)⁻¹`). For a 1 × 1
//!   block it is `λ₁₁`.
//! - Scaling `G_s = D_e⁻¹ G D_u` by expected input ranges `D_u` and allowed output deviations `D_e`;
//!   Morari resiliency index `MRI = σ_min(G_s)` (larger: more resilient).
//!
//! # References
//! - E. H. Bristol, *On a new measure of interaction for multivariable process control*, IEEE TAC
//!   11 (1966) 133–134.
//! - P. Grosdidier, M. Morari, B. R. Holt, *Closed-loop properties from steady-state gain
//!   information*, Ind. Eng. Chem. Fundam. 24 (1985) 221–235.
//! - V. Manousiouthakis, R. Savage, Y. Arkun, *Synthesis of decentralized process control
//!   structures using the concept of block relative gain*, AIChE J. 32 (1986) 991–1003.
//! - S. Skogestad, I. Postlethwaite, *Multivariable Feedback Control*, 2nd ed., Wiley 2005, §3.3, §A.4.

use faer::linalg::solvers::DenseSolveCore;
use faer::{Mat, MatRef, c64};

use crate::error::AnalysisError;

/// Ratio `σ_min/σ_max` below which a gain matrix is treated as singular.
pub const SINGULAR_RATIO: f64 = 1e-13;

/// Singular value decomposition `G = U Σ Vᵀ` (thin).
#[derive(Debug, Clone)]
pub struct Svd {
    /// Singular values, non-increasing.
    pub singular_values: Vec<f64>,
    /// Output directions (columns), outputs × k.
    pub u: Mat<f64>,
    /// Input directions (columns), inputs × k.
    pub v: Mat<f64>,
}

/// Thin SVD of `g`.
pub fn svd(g: MatRef<'_, f64>) -> Result<Svd, AnalysisError> {
    if g.nrows() == 0 || g.ncols() == 0 {
        return Err(AnalysisError::Request("the gain matrix is empty".into()));
    }
    if g.has_nan() || !g.is_all_finite() {
        return Err(AnalysisError::Singular("the gain matrix has non-finite entries".into()));
    }
    let s = g.thin_svd().map_err(|e| AnalysisError::Singular(format!("SVD failed: {e:?}")))?;
    Ok(Svd {
        singular_values: s.S().column_vector().iter().copied().collect(),
        u: s.U().to_owned(),
        v: s.V().to_owned(),
    })
}

/// Condition number `σ_max/σ_min` (infinite for a singular matrix).
pub fn condition_number(singular_values: &[f64]) -> f64 {
    match (singular_values.first(), singular_values.last()) {
        (Some(&a), Some(&b)) if b > 0.0 => a / b,
        _ => f64::INFINITY,
    }
}

fn check_regular(sv: &[f64], what: &str) -> Result<(), AnalysisError> {
    let (max, min) = (sv[0], sv[sv.len() - 1]);
    if min.is_nan() || min <= SINGULAR_RATIO * max {
        return Err(AnalysisError::Singular(format!(
            "the {what} is singular (σ_min/σ_max = {:.1e}): the inputs cannot move the outputs independently",
            min / max
        )));
    }
    Ok(())
}

/// `D₁ G D₂` with positive diagonal `D₁`, `D₂` that bring every row's and column's largest
/// magnitude to 1 (alternate row and column sweeps, powers of two so that the scaling is exact).
/// The relative gains, the Niederlinski index and the minimized condition number of a square `G`
/// do not depend on the units of its signals, and neither does whether it is singular: a gain
/// from a reboiler duty in W to a bottoms impurity of 1e-9 is 1e-13, beside 1 mol/s per mol/s,
/// without the plant being any less controllable. They are computed on this matrix.
pub fn equilibrated(g: MatRef<'_, f64>) -> Mat<f64> {
    let mut e = g.to_owned();
    let pow2 = |m: f64| if m > 0.0 && m.is_finite() { 2f64.powi(-(m.log2().round() as i32)) } else { 1.0 };
    for _ in 0..4 {
        for i in 0..e.nrows() {
            let f = pow2((0..e.ncols()).map(|j| e[(i, j)].abs()).fold(0.0, f64::max));
            (0..e.ncols()).for_each(|j| e[(i, j)] *= f);
        }
        for j in 0..e.ncols() {
            let f = pow2((0..e.nrows()).map(|i| e[(i, j)].abs()).fold(0.0, f64::max));
            (0..e.nrows()).for_each(|i| e[(i, j)] *= f);
        }
    }
    e
}

/// Whether `g` is numerically regular: `σ_min/σ_max` above [`SINGULAR_RATIO`], of the
/// [`equilibrated`] matrix when `g` is square (whatever the units of its signals).
pub fn is_regular(g: MatRef<'_, f64>) -> Result<bool, AnalysisError> {
    let judged = if g.nrows() == g.ncols() { equilibrated(g) } else { g.to_owned() };
    Ok(check_regular(&svd(judged.as_ref())?.singular_values, "gain matrix").is_ok())
}

/// Relative gain array `Λ = G ∘ (G⁻¹)ᵀ` (`G⁺` when `G` is not square; a square `G` is
/// [`equilibrated`] first, which leaves `Λ` as it is).
pub fn rga(g: MatRef<'_, f64>) -> Result<Mat<f64>, AnalysisError> {
    let e = if g.nrows() == g.ncols() { Some(equilibrated(g)) } else { None };
    let g = e.as_ref().map_or(g, |e| e.as_ref());
    let s = svd(g)?;
    check_regular(&s.singular_values, "gain matrix")?;
    let inv = if g.nrows() == g.ncols() {
        g.partial_piv_lu().inverse()
    } else {
        // G⁺ = V Σ⁻¹ Uᵀ.
        Mat::from_fn(g.ncols(), g.nrows(), |i, j| {
            (0..s.singular_values.len()).map(|k| s.v[(i, k)] * s.u[(j, k)] / s.singular_values[k]).sum()
        })
    };
    Ok(Mat::from_fn(g.nrows(), g.ncols(), |i, j| g[(i, j)] * inv[(j, i)]))
}

/// Relative gain array of a complex (frequency-response) matrix `G(jω)`: `Λ = G ∘ (G⁻¹)ᵀ`.
pub fn rga_complex(g: MatRef<'_, c64>) -> Result<Mat<c64>, AnalysisError> {
    if g.nrows() != g.ncols() || g.nrows() == 0 {
        return Err(AnalysisError::Request(format!(
            "the frequency-dependent RGA needs a square G(jω) (got {}×{})",
            g.nrows(),
            g.ncols()
        )));
    }
    let sv = g.singular_values().map_err(|e| AnalysisError::Singular(format!("SVD failed: {e:?}")))?;
    check_regular(&sv, "frequency response G(jω)")?;
    let inv = g.partial_piv_lu().inverse();
    Ok(Mat::from_fn(g.nrows(), g.ncols(), |i, j| g[(i, j)] * inv[(j, i)]))
}

/// RGA number `Σ_ij |λ_ij − p_ij|` of a pairing (`pairing[i]` = input paired with output `i`).
pub fn rga_number(rga: MatRef<'_, f64>, pairing: &[usize]) -> f64 {
    let mut s = 0.0;
    for i in 0..rga.nrows() {
        for j in 0..rga.ncols() {
            let p = if pairing.get(i) == Some(&j) { 1.0 } else { 0.0 };
            s += (rga[(i, j)] - p).abs();
        }
    }
    s
}

/// Relative gains of the paired elements `λ_{i,p(i)}`.
pub fn paired_relative_gains(rga: MatRef<'_, f64>, pairing: &[usize]) -> Vec<f64> {
    pairing.iter().enumerate().map(|(i, &j)| rga[(i, j)]).collect()
}

/// The diagonal pairing `0 ↔ 0, 1 ↔ 1, …`.
pub fn diagonal_pairing(n: usize) -> Vec<usize> {
    (0..n).collect()
}

/// Niederlinski index `det G_p / Π_i g_{i,p(i)}`, `G_p` the columns of `G` reordered so the paired
/// inputs sit on the diagonal (`G_p[i][k] = G[i][p(k)]`).
pub fn niederlinski(g: MatRef<'_, f64>, pairing: &[usize]) -> Result<f64, AnalysisError> {
    let n = g.nrows();
    if g.ncols() != n || pairing.len() != n {
        return Err(AnalysisError::Request(format!(
            "the Niederlinski index needs a square gain matrix and a full pairing (got {}×{})",
            n,
            g.ncols()
        )));
    }
    let gp = Mat::from_fn(n, n, |i, k| g[(i, pairing[k])]);
    let diag: f64 = (0..n).map(|i| gp[(i, i)]).product();
    if diag == 0.0 {
        return Err(AnalysisError::Singular("the Niederlinski index is undefined: a paired gain is zero".into()));
    }
    Ok(gp.determinant() / diag)
}

/// Block relative gain `G₁₁ · [G⁻¹]₁₁` of the block pairing outputs `rows` with inputs `cols`.
pub fn block_relative_gain(g: MatRef<'_, f64>, rows: &[usize], cols: &[usize]) -> Result<Mat<f64>, AnalysisError> {
    let n = g.nrows();
    if g.ncols() != n {
        return Err(AnalysisError::Request(format!(
            "the block relative gain needs a square gain matrix (got {}×{})",
            n,
            g.ncols()
        )));
    }
    if rows.len() != cols.len() || rows.is_empty() || rows.iter().chain(cols).any(|&k| k >= n) {
        return Err(AnalysisError::Request(
            "a block needs as many outputs as inputs, all within the gain matrix".into(),
        ));
    }
    check_regular(&svd(g)?.singular_values, "gain matrix")?;
    let inv = g.partial_piv_lu().inverse();
    let m = rows.len();
    let g11 = Mat::from_fn(m, m, |a, b| g[(rows[a], cols[b])]);
    // [G⁻¹]₁₁ maps the block's outputs to its inputs: rows of G⁻¹ are inputs, columns outputs.
    let inv11 = Mat::from_fn(m, m, |a, b| inv[(cols[a], rows[b])]);
    Ok(&g11 * &inv11)
}

/// Scaled gain `D_e⁻¹ G D_u`: `input_ranges[j]` is the expected range of input `j`,
/// `output_ranges[i]` the allowed deviation of output `i` (both in the units of `G`).
pub fn scale(g: MatRef<'_, f64>, input_ranges: &[f64], output_ranges: &[f64]) -> Result<Mat<f64>, AnalysisError> {
    if input_ranges.len() != g.ncols() || output_ranges.len() != g.nrows() {
        return Err(AnalysisError::Request(format!(
            "scaling needs one range per input ({}) and one per output ({}); got {} and {}",
            g.ncols(),
            g.nrows(),
            input_ranges.len(),
            output_ranges.len()
        )));
    }
    if let Some(bad) = input_ranges.iter().chain(output_ranges).find(|r| !(r.is_finite() && **r > 0.0)) {
        return Err(AnalysisError::Request(format!("scaling ranges must be positive and finite (got {bad})")));
    }
    Ok(Mat::from_fn(g.nrows(), g.ncols(), |i, j| g[(i, j)] * input_ranges[j] / output_ranges[i]))
}

/// Morari resiliency index: the smallest singular value of the scaled gain.
pub fn resiliency_index(scaled: MatRef<'_, f64>) -> Result<f64, AnalysisError> {
    let s = svd(scaled)?;
    Ok(s.singular_values[s.singular_values.len() - 1])
}

/// Matrix as nested rows (for JSON and printing).
pub fn rows(m: MatRef<'_, f64>) -> Vec<Vec<f64>> {
    (0..m.nrows()).map(|i| (0..m.ncols()).map(|j| m[(i, j)]).collect()).collect()
}

/// Matrix from nested rows (all of the same length).
pub fn from_rows(r: &[Vec<f64>]) -> Mat<f64> {
    let ncols = r.first().map_or(0, Vec::len);
    Mat::from_fn(r.len(), ncols, |i, j| r[i][j])
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// SplitMix64: a seeded generator for the identity tests (no dependency needed).
    pub(crate) struct Rng(u64);
    impl Rng {
        pub(crate) fn new(seed: u64) -> Rng {
            Rng(seed)
        }
        /// Uniform in [-1, 1).
        pub(crate) fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
        pub(crate) fn matrix(&mut self, n: usize, m: usize) -> Mat<f64> {
            Mat::from_fn(n, m, |_, _| self.next())
        }
    }

    /// Skogestad & Postlethwaite (2005) eq. 3.81, the LV distillation model of §12.4 scaled ×100:
    /// λ11 = 35.1, γ = 141.7 (their text).
    fn sp_lv() -> Mat<f64> {
        from_rows(&[vec![87.8, -86.4], vec![108.2, -109.6]])
    }

    #[test]
    fn rga_of_the_published_lv_model() {
        let l = rga(sp_lv().as_ref()).unwrap();
        // λ11 = g11 g22 / det = 87.8·(−109.6)/(87.8·(−109.6) − (−86.4)·108.2) = 35.0688.
        let hand = 87.8 * -109.6 / (87.8 * -109.6 - -86.4 * 108.2);
        assert!((l[(0, 0)] - hand).abs() < 1e-12 * hand);
        assert!((l[(0, 0)] - 35.1).abs() < 0.05);
        let s = svd(sp_lv().as_ref()).unwrap();
        assert!((condition_number(&s.singular_values) - 141.7).abs() < 0.05);
    }

    #[test]
    fn rga_rows_and_columns_sum_to_one() {
        let mut rng = Rng::new(7);
        for n in [1, 2, 3, 5, 8] {
            for _ in 0..20 {
                let l = rga(rng.matrix(n, n).as_ref()).unwrap();
                for k in 0..n {
                    let row: f64 = (0..n).map(|j| l[(k, j)]).sum();
                    let col: f64 = (0..n).map(|i| l[(i, k)]).sum();
                    let scale: f64 = (0..n).map(|j| l[(k, j)].abs() + l[(j, k)].abs()).sum::<f64>().max(1.0);
                    assert!(
                        (row - 1.0).abs() < 1e-10 * scale && (col - 1.0).abs() < 1e-10 * scale,
                        "n = {n}: {row} {col}"
                    );
                }
            }
        }
    }

    #[test]
    fn rga_is_invariant_to_scaling_and_permutes_with_the_matrix() {
        let mut rng = Rng::new(11);
        let n = 4;
        let g = rng.matrix(n, n);
        let l = rga(g.as_ref()).unwrap();
        let d1: Vec<f64> = (0..n).map(|_| 10f64.powf(2.0 * rng.next())).collect();
        let d2: Vec<f64> = (0..n).map(|_| 10f64.powf(2.0 * rng.next())).collect();
        let p = [2usize, 0, 3, 1];
        let q = [1usize, 3, 0, 2];
        // G' = P D1 G D2 Q: rows permuted by p, columns by q.
        let gs = Mat::from_fn(n, n, |i, j| d1[p[i]] * g[(p[i], q[j])] * d2[q[j]]);
        let ls = rga(gs.as_ref()).unwrap();
        for i in 0..n {
            for j in 0..n {
                assert!((ls[(i, j)] - l[(p[i], q[j])]).abs() < 1e-9 * (1.0 + l[(p[i], q[j])].abs()));
            }
        }
    }

    #[test]
    fn rga_of_a_triangular_matrix_is_the_identity() {
        let mut rng = Rng::new(3);
        for n in [2, 3, 6] {
            let g = Mat::from_fn(n, n, |i, j| if j <= i { rng.next() + if i == j { 2.0 } else { 0.0 } } else { 0.0 });
            let l = rga(g.as_ref()).unwrap();
            for i in 0..n {
                for j in 0..n {
                    let e = if i == j { 1.0 } else { 0.0 };
                    assert!((l[(i, j)] - e).abs() < 1e-12, "n = {n} ({i},{j}) = {}", l[(i, j)]);
                }
            }
        }
    }

    #[test]
    fn block_relative_gain_of_a_one_by_one_block_is_the_relative_gain() {
        let mut rng = Rng::new(5);
        for n in [2, 3, 4] {
            let g = rng.matrix(n, n);
            let l = rga(g.as_ref()).unwrap();
            for i in 0..n {
                for j in 0..n {
                    let b = block_relative_gain(g.as_ref(), &[i], &[j]).unwrap();
                    assert!((b[(0, 0)] - l[(i, j)]).abs() < 1e-10 * (1.0 + l[(i, j)].abs()));
                }
            }
            // The whole plant as one block is perfectly decoupled from nothing: BRG = I.
            let all: Vec<usize> = (0..n).collect();
            let b = block_relative_gain(g.as_ref(), &all, &all).unwrap();
            for i in 0..n {
                for j in 0..n {
                    assert!((b[(i, j)] - if i == j { 1.0 } else { 0.0 }).abs() < 1e-10);
                }
            }
        }
    }

    #[test]
    fn block_relative_gain_is_the_open_over_closed_loop_block_gain() {
        // BRG = G11 Ĝ11⁻¹ with Ĝ11 = G11 − G12 G22⁻¹ G21 (the other loop closed perfectly).
        let mut rng = Rng::new(17);
        let g = rng.matrix(4, 4);
        let (r, c) = ([0usize, 2], [1usize, 3]);
        let (r2, c2) = ([1usize, 3], [0usize, 2]);
        let pick = |rs: &[usize], cs: &[usize]| Mat::from_fn(rs.len(), cs.len(), |a, b| g[(rs[a], cs[b])]);
        let (g11, g12, g21, g22) = (pick(&r, &c), pick(&r, &c2), pick(&r2, &c), pick(&r2, &c2));
        let closed = &g11 - &g12 * g22.partial_piv_lu().inverse() * &g21;
        let expected = &g11 * closed.partial_piv_lu().inverse();
        let brg = block_relative_gain(g.as_ref(), &r, &c).unwrap();
        assert!((&brg - &expected).norm_l2() < 1e-9 * expected.norm_l2());
    }

    #[test]
    fn svd_reconstructs_the_matrix() {
        let mut rng = Rng::new(23);
        for (n, m) in [(2, 2), (3, 5), (6, 4)] {
            let g = rng.matrix(n, m);
            let s = svd(g.as_ref()).unwrap();
            let k = s.singular_values.len();
            let sig = Mat::from_fn(k, k, |i, j| if i == j { s.singular_values[i] } else { 0.0 });
            let back = &s.u * &sig * s.v.transpose();
            assert!((&back - &g).norm_l2() < 1e-12 * g.norm_l2());
            assert!(s.singular_values.windows(2).all(|w| w[0] >= w[1]));
        }
    }

    #[test]
    fn niederlinski_index_by_hand_and_for_a_swapped_pairing() {
        let g = sp_lv();
        let ni = niederlinski(g.as_ref(), &[0, 1]).unwrap();
        assert!((ni - (87.8 * -109.6 - -86.4 * 108.2) / (87.8 * -109.6)).abs() < 1e-14);
        // Off-diagonal pairing: columns swapped, det changes sign, diagonal is g12 g21.
        let ni_off = niederlinski(g.as_ref(), &[1, 0]).unwrap();
        assert!((ni_off - (-86.4 * 108.2 - 87.8 * -109.6) / (-86.4 * 108.2)).abs() < 1e-14);
        // For 2×2, NI = 1/λ11 of the pairing.
        let l = rga(g.as_ref()).unwrap();
        assert!((ni - 1.0 / l[(0, 0)]).abs() < 1e-12);
    }

    #[test]
    fn rga_number_is_zero_for_a_decoupled_plant() {
        let g = from_rows(&[vec![2.0, 0.0], vec![0.0, -3.0]]);
        let l = rga(g.as_ref()).unwrap();
        assert!(rga_number(l.as_ref(), &[0, 1]).abs() < 1e-15);
        assert!((rga_number(l.as_ref(), &[1, 0]) - 4.0).abs() < 1e-15);
    }

    #[test]
    fn scaling_and_resiliency() {
        let g = from_rows(&[vec![1.0, 0.0], vec![0.0, 4.0]]);
        let gs = scale(g.as_ref(), &[2.0, 1.0], &[1.0, 8.0]).unwrap();
        assert_eq!(rows(gs.as_ref()), vec![vec![2.0, 0.0], vec![0.0, 0.5]]);
        assert!((resiliency_index(gs.as_ref()).unwrap() - 0.5).abs() < 1e-15);
        assert!(scale(g.as_ref(), &[0.0, 1.0], &[1.0, 1.0]).is_err());
    }

    #[test]
    fn singular_gains_are_reported() {
        let g = from_rows(&[vec![1.0, 2.0], vec![2.0, 4.0]]);
        assert!(matches!(rga(g.as_ref()), Err(AnalysisError::Singular(_))));
        assert!(!is_regular(g.as_ref()).unwrap());
    }

    #[test]
    fn gains_in_badly_matched_units_are_not_singular() {
        // Skogestad's LV column with its boilup in W (×1e-5 per unit) and its bottoms impurity
        // in ppb-sized units (×1e-9): σ_min/σ_max ≈ 1e-16, yet the same plant, the same RGA.
        let g = sp_lv();
        let odd = Mat::from_fn(2, 2, |i, j| g[(i, j)] * [1.0, 1e-9][i] * [1.0, 1e-5][j]);
        let s = svd(odd.as_ref()).unwrap();
        assert!(s.singular_values[1] < SINGULAR_RATIO * s.singular_values[0]);
        assert!(is_regular(odd.as_ref()).unwrap());
        let (l, m) = (rga(g.as_ref()).unwrap(), rga(odd.as_ref()).unwrap());
        assert!((0..2).all(|i| (0..2).all(|j| (l[(i, j)] - m[(i, j)]).abs() < 1e-9 * l[(i, j)].abs())), "{m:?}");
        let e = equilibrated(odd.as_ref());
        assert!((0..2).all(|i| (0..2).map(|j| e[(i, j)].abs()).fold(0.0, f64::max) > 0.5));
    }

    #[test]
    fn complex_rga_at_zero_frequency_equals_the_real_rga() {
        let g = sp_lv();
        let gc = Mat::from_fn(2, 2, |i, j| c64::new(g[(i, j)], 0.0));
        let lc = rga_complex(gc.as_ref()).unwrap();
        let l = rga(g.as_ref()).unwrap();
        assert!((lc[(0, 0)].re - l[(0, 0)]).abs() < 1e-10 && lc[(0, 0)].im.abs() < 1e-12);
    }
}
