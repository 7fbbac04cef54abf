//! Where a failed design-spec solve leaves its specs, measured on the plant itself.
//!
//! A spec's equation `x[var] − target = 0` is linear, so every full Newton step meets it exactly:
//! at the last iterate of a failed solve each spec reads "off by 0" while the plant's own
//! equations do not hold there, and that offset says nothing. Here the plant is converged with
//! the varied inputs held — at their last values (inside their ranges), or, where the plant has
//! no steady state there, at their starting values — and each spec is read at that steady state:
//! the offset the plant really gives, and the move of each varied input that the plant's exact
//! linearization asks for to meet them all, `G Δu = −offset`, with `G = −C J⁻¹ B` the steady-state
//! gains of the specs' variables to the varied inputs. A move out of a varied input's range at its
//! bound is what "the spec needs more (or less) than the input can give" means.

use plantwide_flowsheet::Plant;
use plantwide_model::limits::number;
use plantwide_units::Dimension;

use super::input_bounds;
use crate::sparse::SparseLu;
use crate::{NewtonSettings, steady_state};

/// The specs read at a steady state of the plant with the varied inputs held.
struct Standing {
    /// `last iterate` or `start`: where the held inputs come from.
    at: &'static str,
    /// The held values of the varied inputs, one per spec (SI).
    held: Vec<f64>,
    /// Each spec's variable there (SI).
    value: Vec<f64>,
    /// The linearized move of each varied input that meets the specs, when the gains are
    /// nonsingular.
    step: Option<Vec<f64>>,
}

/// The specs of a failed solve at unknowns `z` (started from inputs `u`), for its message
/// (`; design specs solved with the plant: …`), empty without specs.
pub(crate) fn note(plant: &Plant, u: &[f64], z: &[f64]) -> String {
    let specs = plant.specs();
    if specs.is_empty() {
        return String::new();
    }
    let n = plant.n_vars();
    let last: Vec<f64> = specs.iter().enumerate().map(|(k, s)| clamp_to_range(plant, s.input, z[n + k])).collect();
    let start: Vec<f64> = specs.iter().map(|s| u[s.input]).collect();
    let standing = held_standing(plant, u, &last, Some(&z[..n]), "last iterate")
        .or_else(|| held_standing(plant, u, &start, None, "start"));
    let items: Vec<String> = (0..specs.len()).map(|k| spec_item(plant, k, z[n + k], standing.as_ref())).collect();
    format!("; design specs solved with the plant (a spec no steady state can meet shows here): {}", items.join("; "))
}

/// Spec `k` whose varied input ended at `v`, read at `standing`.
fn spec_item(plant: &Plant, k: usize, v: f64, standing: Option<&Standing>) -> String {
    let s = &plant.specs()[k];
    let (u_dim, x_dim) = (plant.inputs()[s.input].dim, plant.vars()[s.var].spec.dim);
    let (lo, hi) = input_bounds(plant, s.input);
    let bound = if v <= lo {
        " (its lower bound)".to_string()
    } else if v >= hi {
        " (its upper bound)".to_string()
    } else {
        String::new()
    };
    let head =
        format!("{} ({}): `{}` = {}{bound} at the last iterate", s.label(), s.origin, s.vary, quantity(v, u_dim));
    let Some(st) = standing else {
        return format!(
            "{head}; the plant has no steady state with the varied inputs held there or at their starting values, so how far the spec is off is not known"
        );
    };
    let place = if st.at == "start" {
        format!(
            "; the plant has no steady state there; at the start, `{}` = {}, it gives",
            s.vary,
            quantity(st.held[k], u_dim)
        )
    } else {
        "; held there, the plant gives".to_string()
    };
    let how = st.step.as_ref().map_or(String::new(), |d| direction(d[k], st.held[k], v, (lo, hi), &s.vary, u_dim));
    format!(
        "{head}{place} `{}` = {} (off by {:+.3e}){how}",
        s.path,
        quantity(st.value[k], x_dim),
        st.value[k] - s.target
    )
}

/// `; to meet it `u` would have to go lower (to about …)`, from the linearized move `d` at the
/// held value `held`, the last iterate's value `v` and the input's range; beyond a bound, or
/// ended on one with the move pointing out, the spec asks for more (or less) than the input can
/// give.
fn direction(d: f64, held: f64, v: f64, (lo, hi): (f64, f64), vary: &str, dim: Dimension) -> String {
    if !(d.is_finite() && d != 0.0) {
        return String::new();
    }
    let (way, target) = (if d < 0.0 { "lower" } else { "higher" }, held + d);
    let (bound, side, what) = if d < 0.0 { (lo, "lower", "less") } else { (hi, "upper", "more") };
    let beyond = if (d < 0.0 && target < lo) || (d > 0.0 && target > hi) {
        format!(", beyond its {side} bound {}: the spec asks for {what} than the input can give", quantity(bound, dim))
    } else if (d < 0.0 && v <= lo) || (d > 0.0 && v >= hi) {
        format!("; the solve ended on that bound short of it: the spec asks for {what} than the input can give")
    } else {
        String::new()
    };
    format!(
        "; to meet it `{vary}` would have to go {way} (to about {} by the plant's gains there){beyond}",
        quantity(target, dim)
    )
}

/// `v` with its SI unit (`33.04 mol/s`; a bare number when dimensionless).
fn quantity(v: f64, dim: Dimension) -> String {
    if dim == Dimension::DIMENSIONLESS { number(v) } else { format!("{} {dim}", number(v)) }
}

/// Value `v` of input `i` inside its physical range.
fn clamp_to_range(plant: &Plant, i: usize, v: f64) -> f64 {
    let (lo, hi) = input_bounds(plant, i);
    if v.is_finite() { v.clamp(lo, hi) } else { plant.inputs()[i].value }
}

/// The specs at the plant's steady state with the varied inputs held at `held` (from `x0` or the
/// cold start), or `None` when there is none.
fn held_standing(plant: &Plant, u: &[f64], held: &[f64], x0: Option<&[f64]>, at: &'static str) -> Option<Standing> {
    let specs = plant.specs();
    let mut uh = u.to_vec();
    specs.iter().zip(held).for_each(|(s, &v)| uh[s.input] = v);
    let mut fixed = plant.clone();
    fixed.fix_specs(&uh);
    let settings = NewtonSettings::default();
    let ss = match steady_state(&fixed, &uh, x0, &settings) {
        Ok(ss) => ss,
        Err(_) if x0.is_some() => steady_state(&fixed, &uh, None, &settings).ok()?,
        Err(_) => return None,
    };
    let value = specs.iter().map(|s| ss.x[s.var]).collect();
    let offset: Vec<f64> = specs.iter().map(|s| s.target - ss.x[s.var]).collect();
    let step = spec_gains(plant, &ss.x, &uh).and_then(|g| solve_dense(g, offset));
    Some(Standing { at, held: held.to_vec(), value, step })
}

/// The steady-state gains `G[j][k] = ∂x[var_j]/∂u_k` of the specs' variables to their varied
/// inputs at steady state `x`, inputs `u`: `J dx = −∂f/∂u_k` by the sparse LU.
fn spec_gains(plant: &Plant, x: &[f64], u: &[f64]) -> Option<Vec<Vec<f64>>> {
    let (n, specs) = (plant.n_vars(), plant.specs());
    let (mut r, mut jx, mut ju) = (vec![0.0; n], Vec::new(), Vec::new());
    plant.jacobian(x, u, 0.0, &mut r, &mut jx, &mut ju);
    let mut lu = SparseLu::default();
    lu.factor(n, &jx).ok()?;
    let mut g = vec![vec![0.0; specs.len()]; specs.len()];
    for (k, s) in specs.iter().enumerate() {
        let mut b = vec![0.0; n];
        ju.iter().filter(|t| t.1 == s.input).for_each(|&(i, _, v)| b[i] -= v);
        lu.solve_in_place(&mut b).ok()?;
        specs.iter().enumerate().for_each(|(j, sj)| g[j][k] = b[sj.var]);
    }
    Some(g)
}

/// `G d = rhs` by Gaussian elimination with partial pivoting (`None` if `G` is singular).
fn solve_dense(mut g: Vec<Vec<f64>>, mut rhs: Vec<f64>) -> Option<Vec<f64>> {
    let m = rhs.len();
    let scale = g.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    for c in 0..m {
        let p = (c..m).max_by(|&a, &b| g[a][c].abs().total_cmp(&g[b][c].abs()))?;
        if g[p][c].abs() <= 1e-14 * scale || !g[p][c].is_finite() {
            return None;
        }
        g.swap(c, p);
        rhs.swap(c, p);
        let pivot = g[c].clone();
        for r in c + 1..m {
            let f = g[r][c] / pivot[c];
            g[r].iter_mut().zip(&pivot).skip(c).for_each(|(a, b)| *a -= f * b);
            rhs[r] -= f * rhs[c];
        }
    }
    let mut d = vec![0.0; m];
    for c in (0..m).rev() {
        let s: f64 = (c + 1..m).map(|k| g[c][k] * d[k]).sum();
        d[c] = (rhs[c] - s) / g[c][c];
    }
    Some(d)
}

#[cfg(test)]
mod tests {
    use super::solve_dense;

    /// `[[2, 1], [1, 3]] d = [3, 5]` has `d = (4/5, 7/5)`; a singular matrix gives `None`.
    #[test]
    fn dense_solve_matches_its_closed_form() {
        let d = solve_dense(vec![vec![2.0, 1.0], vec![1.0, 3.0]], vec![3.0, 5.0]).unwrap();
        assert!((d[0] - 0.8).abs() < 1e-15 && (d[1] - 1.4).abs() < 1e-15, "{d:?}");
        assert!(solve_dense(vec![vec![1.0, 2.0], vec![2.0, 4.0]], vec![1.0, 1.0]).is_none());
    }
}
