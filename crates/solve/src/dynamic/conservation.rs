//! The plant's material balance over a run, checked at its end.
//!
//! For every component `c` (moles), or for the mass `Σ_c MW_c n_c` [kg] when a unit reacts,
//! `Δ(Σ_units n_c) = ∫ (Σ_feeds F z_c − Σ_products F z_c) dt`: what the units hold
//! ([`plantwide_model::Unit::holdup`]) changes by what the boundary streams (outlets of `feed`
//! units, inlets of `product` units) brought in and took out. The integrals are quadratures
//! integrated by the same BDF formula as the holdups; BDF preserves linear invariants, so the two
//! sides agree to the accuracy of the corrector's Newton iteration, not of the time
//! discretization.

use serde::Serialize;

use plantwide_flowsheet::{BlockKind, Plant};
use plantwide_model::{Boundary, UnitIo};

/// Largest relative conservation error [`Conservation::check`] accepts.
///
/// BDF preserves linear invariants. The invariant here, `L·x = Σ_units n − Σ_boundary ±q`, has
/// `L·f(x) ≡ 0` (every internal stream leaves one unit and enters another; a boundary stream's
/// flow is its quadrature's derivative; reactions conserve mass), and every Newton update of the
/// corrector `cj·M·x − f(x) = 0` — with a fresh or a stale Jacobian — is the same linear
/// combination for the holdups and the quadratures, so `L·Δx` is round-off, not Newton or
/// truncation error: it does not grow with `rtol`. Measured (`plantwide run … --json`,
/// `conservation.max_relative_error`): column A feed step 8e-16, surge tank step 7e-16, surge
/// tank upsets (6562 steps, 1116 restarts) 3e-14, two-column reactor plant 5e-16, and 1e-14 …
/// 4e-14 at rtol 1e-3 and 1e-2. 1e-9 leaves four decades for round-off that accumulates over
/// long runs and still catches a unit whose balance or holdup is wrong by a millionth.
pub const CONSERVATION_TOL: f64 = 1e-9;

/// One balance: a component's moles, or the plant's mass.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Balance {
    /// Component name, or `mass`.
    pub name: String,
    /// `mol` or `kg`.
    pub unit: &'static str,
    /// Held at the start and at the end of the run (sum over the units).
    pub held: [f64; 2],
    /// `∫ Σ_feeds F z dt` over the run.
    pub fed: f64,
    /// `∫ Σ_products F z dt` over the run.
    pub removed: f64,
    /// `|Δ held − (fed − removed)| / scale`, `scale = max(fed, removed, held at start, held at
    /// end)` (the absolute gap if all are 0).
    pub relative_error: f64,
}

impl Balance {
    fn new(name: String, unit: &'static str, held: [f64; 2], fed: f64, removed: f64) -> Balance {
        let gap = (held[1] - held[0]) - (fed - removed);
        let scale = fed.abs().max(removed.abs()).max(held[0].abs()).max(held[1].abs());
        let relative_error = if scale > 0.0 { gap.abs() / scale } else { gap.abs() };
        Balance { name, unit, held, fed, removed, relative_error }
    }
}

/// The plant's material balances over a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Conservation {
    /// `moles` (one balance per component) or `mass` (one balance: the plant has reactions).
    pub basis: &'static str,
    /// The balances.
    pub balances: Vec<Balance>,
}

/// A run that does not conserve material.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "{name} is not conserved: the units' holdup changed by {change:.9e} {unit} but the feeds brought {fed:.9e} and the products took {removed:.9e} (net {net:.9e}); relative error {relative_error:.2e} > tolerance {tol:.0e}"
)]
pub struct ConservationError {
    /// Component or `mass`.
    pub name: String,
    /// `mol` or `kg`.
    pub unit: &'static str,
    /// `Δ held`.
    pub change: f64,
    /// Fed.
    pub fed: f64,
    /// Removed.
    pub removed: f64,
    /// `fed − removed`.
    pub net: f64,
    /// Relative error.
    pub relative_error: f64,
    /// Tolerance.
    pub tol: f64,
}

impl Conservation {
    /// From the component amounts held at the start and end, `held[0/1][c]` [mol], and the
    /// amounts fed and removed, `[c]` [mol]; on a mass basis the component amounts are weighted
    /// by `mw` [kg/mol].
    pub fn new(
        components: &[String],
        mw: Option<&[f64]>,
        held: [&[f64]; 2],
        fed: &[f64],
        removed: &[f64],
    ) -> Conservation {
        match mw {
            Some(mw) => {
                let mass = |v: &[f64]| v.iter().zip(mw).map(|(n, m)| n * m).sum::<f64>();
                let b = Balance::new("mass".into(), "kg", [mass(held[0]), mass(held[1])], mass(fed), mass(removed));
                Conservation { basis: "mass", balances: vec![b] }
            }
            None => {
                let balances = (0..components.len())
                    .map(|c| Balance::new(components[c].clone(), "mol", [held[0][c], held[1][c]], fed[c], removed[c]))
                    .collect();
                Conservation { basis: "moles", balances }
            }
        }
    }

    /// The largest relative error, 0 without balances.
    pub fn worst(&self) -> f64 {
        self.balances.iter().map(|b| b.relative_error).fold(0.0, f64::max)
    }

    /// The first balance whose relative error exceeds `tol` (or is NaN), as an error.
    ///
    /// # Errors
    /// [`ConservationError`] naming the component (or `mass`) and the figures.
    pub fn check(&self, tol: f64) -> Result<(), ConservationError> {
        match self.balances.iter().find(|b| b.relative_error.is_nan() || b.relative_error > tol) {
            None => Ok(()),
            Some(b) => Err(ConservationError {
                name: b.name.clone(),
                unit: b.unit,
                change: b.held[1] - b.held[0],
                fed: b.fed,
                removed: b.removed,
                net: b.fed - b.removed,
                relative_error: b.relative_error,
                tol,
            }),
        }
    }
}

/// The boundary streams: `(stream, +1)` for the outlets of source units (feeds), `(stream, −1)`
/// for the inlets of sink units (products), as each unit declares its [`Boundary`].
pub fn boundary_streams(plant: &Plant) -> Vec<(usize, f64)> {
    let boundary = |b: usize| (plant.blocks()[b].kind == BlockKind::Unit).then(|| plant.blocks()[b].unit.boundary());
    let mut v = Vec::new();
    for (k, s) in plant.streams().iter().enumerate() {
        if boundary(s.from.0) == Some(Boundary::Source) {
            v.push((k, 1.0));
        }
        if boundary(s.to.0) == Some(Boundary::Sink) {
            v.push((k, -1.0));
        }
    }
    v
}

/// Component amounts [mol] held by all units at the plant state `x` (inputs `u`, time `t`).
pub fn plant_holdup(plant: &Plant, x: &[f64], u: &[f64], t: f64) -> Vec<f64> {
    let mut held = vec![0.0; plant.components().len()];
    let mut local = Vec::new();
    for b in plant.blocks().iter().filter(|b| b.kind == BlockKind::Unit) {
        plant.gather(b, x, u, &mut local);
        let io = UnitIo { local: &local, layout: &b.layout, thermo: plant.thermo(), time: t };
        if let Some(n) = b.unit.holdup(&io) {
            held.iter_mut().zip(&n).for_each(|(h, v)| *h += v);
        }
    }
    held
}

/// Whether the plant conserves mass rather than moles per component (a unit reacts).
pub fn reacts(plant: &Plant) -> bool {
    plant.blocks().iter().any(|b| b.kind == BlockKind::Unit && b.unit.reacts())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names() -> Vec<String> {
        vec!["light".into(), "heavy".into()]
    }

    #[test]
    fn a_consistent_balance_passes_and_an_inconsistent_holdup_fails_naming_the_component() {
        // 100 mol of each fed, 90 removed, the holdup up by 10: conserved.
        let ok = Conservation::new(&names(), None, [&[50.0, 50.0], &[60.0, 60.0]], &[100.0, 100.0], &[90.0, 90.0]);
        assert_eq!(ok.basis, "moles");
        assert!(ok.worst() < 1e-15 && ok.check(CONSERVATION_TOL).is_ok());
        // A holdup that misreports the heavy component by 0.1 mol (0.1 % of the 100 mol fed).
        let bad = Conservation::new(&names(), None, [&[50.0, 50.0], &[60.0, 60.1]], &[100.0, 100.0], &[90.0, 90.0]);
        let e = bad.check(CONSERVATION_TOL).unwrap_err();
        assert_eq!(e.name, "heavy");
        assert!((e.relative_error - 1e-3).abs() < 1e-12, "{e}");
        let msg = e.to_string();
        assert!(msg.contains("heavy is not conserved") && msg.contains("changed by 1.010000000e1 mol"), "{msg}");
        // NaN (a run gone bad) never passes.
        let nan = Conservation::new(&names(), None, [&[50.0, 50.0], &[f64::NAN, 60.0]], &[100.0, 100.0], &[90.0, 90.0]);
        assert_eq!(nan.check(CONSERVATION_TOL).unwrap_err().name, "light");
    }

    #[test]
    fn a_reacting_plant_is_checked_on_mass() {
        // A (40 kg/kmol) + B (60) -> R (100): 1 mol of A and of B fed, 1 mol of R held.
        let mw = [0.04, 0.06, 0.1];
        let n: Vec<String> = ["A", "B", "R"].iter().map(|s| s.to_string()).collect();
        let c = Conservation::new(&n, Some(&mw), [&[0.0; 3], &[0.0, 0.0, 1.0]], &[1.0, 1.0, 0.0], &[0.0; 3]);
        assert_eq!((c.basis, c.balances.len(), c.balances[0].unit), ("mass", 1, "kg"));
        assert!(c.check(CONSERVATION_TOL).is_ok(), "{:?}", c);
        let lost = Conservation::new(&n, Some(&mw), [&[0.0; 3], &[0.0, 0.0, 0.99]], &[1.0, 1.0, 0.0], &[0.0; 3]);
        assert_eq!(lost.check(CONSERVATION_TOL).unwrap_err().name, "mass");
    }
}
