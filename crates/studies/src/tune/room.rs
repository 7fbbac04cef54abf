//! The room a plant test has: how far the loop's output may move, either way, before a flow of the
//! plant would cross its bound at the new steady state (a distillate flow driven
//! negative by a reflux step larger than itself, on a column refluxed at L/D = 58).
//!
//! With the loop in manual and the other loops as the file has them, the exact linearization's
//! steady gains `g_j = ∂x_j/∂u` give each flow `j` (molar, mass or volumetric) with a finite bound
//! the move `(x_j − lo_j)/|g_j|` (and `(hi_j − x_j)/|g_j|`) that takes it there: a flow set by a
//! balance answers a move about linearly. Mole fractions and component holdups are left out: near
//! 0 their response saturates long before the linear extrapolation says (a drum's heavy key at
//! x = 3e-4 would allow a thousandth of a reflux move that runs well). The least of them is the room. A variable already on its bound is left out:
//! the model holds it there (a total condenser's vapour flow, a clipped output).

use plantwide_analysis::linear::Linearization;
use plantwide_flowsheet::Plant;
use plantwide_units::Dimension;

use super::loops::{PlantLoop, in_manual};

/// Fraction of the room a default relay amplitude or step takes at most: a relay's cycle and a
/// step's response pass through the plant's nonlinear range on their way, so half the room keeps a
/// flow that the full move would reverse at steady state positive through the test.
pub const DEFAULT_ROOM_FRACTION: f64 = 0.5;

/// The room of a loop's output and the variable that bounds it.
#[derive(Debug, Clone, PartialEq)]
pub struct Room {
    /// The largest move either way (output units, SI) that keeps `path` within its bounds at the
    /// new steady state.
    pub limit: f64,
    /// The bounding variable's path.
    pub path: String,
}

/// The [`Room`] of loop `l`'s output at the steady state `x`; `None` when the plant with the loop
/// in manual has no steady state of its own (an inventory left free: no steady gain) or no bounded
/// flow moves.
pub fn room(plant: &Plant, x: &[f64], l: &PlantLoop) -> Option<Room> {
    let flow = [Dimension::MOLAR_FLOW, Dimension::MASS_FLOW, Dimension::VOLUMETRIC_FLOW];
    let bounded: Vec<usize> = (0..plant.n_vars())
        .filter(|&j| flow.contains(&plant.vars()[j].spec.dim))
        .filter(|&j| {
            let (lo, hi) = plant.var_range(j);
            lo.is_finite() || hi.is_finite()
        })
        .collect();
    if bounded.is_empty() {
        return None;
    }
    let manual = in_manual(plant, x, std::slice::from_ref(l));
    let gains = Linearization::new(&manual, x, &manual.input_values()).steady_gain(&[l.op_manual], &bounded).ok()?;
    let mut best: Option<Room> = None;
    for (k, &j) in bounded.iter().enumerate() {
        let g = gains[(k, 0)].abs();
        let (lo, hi) = plant.var_range(j);
        let margin = (x[j] - lo).min(hi - x[j]);
        // A variable on its bound at the steady state (a total condenser's vapour, 0) is held
        // there by the model (a complementarity, a clip), not moved through it by the test.
        let on_bound = margin <= 1e-9 * plant.vars()[j].spec.nominal.abs();
        if !(g > 0.0 && g.is_finite() && margin.is_finite()) || on_bound {
            continue;
        }
        let limit = margin / g;
        if best.as_ref().is_none_or(|b| limit < b.limit) {
            best = Some(Room { limit, path: plant.vars()[j].path.clone() });
        }
    }
    best
}
