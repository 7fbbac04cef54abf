//! Test support for unit models: a small thermodynamic package and a check of the dual-number
//! Jacobian against central finite differences.

use plantwide_thermo::{Component, ThermoPackage, VleModel};

use crate::{LocalLayout, Unit, UnitIo};

/// Two hypothetical components `light` (α = 2) and `heavy` (α = 1), Raoult's law, sharing
/// `hvap = 30 kJ/mol`, boiling near 350 K at 1 atm; cp 150 J/(mol K), v 1e-4 m³/mol, MW 50 and 80 g/mol.
pub fn binary_package() -> ThermoPackage {
    ThermoPackage {
        components: vec![
            Component::hypothetical("light", 2.0, 0.05, 3.0e4, 350.0, 150.0, 1.0e-4),
            Component::hypothetical("heavy", 1.0, 0.08, 3.0e4, 350.0, 150.0, 1.0e-4),
        ],
        vle: VleModel::Ideal,
    }
}

/// Largest mismatch between the dual-number Jacobian of `unit` at `local` and a central finite
/// difference, relative to `max(|J_ij|, row scale)`. Steps are `1e-6·max(|x_j|, 1e-3)`.
pub fn jacobian_error(
    unit: &dyn Unit,
    layout: &LocalLayout,
    thermo: &ThermoPackage,
    local: &[f64],
    n_eq: usize,
) -> f64 {
    let n = local.len();
    let mut r = vec![0.0; n_eq];
    let mut jac = vec![0.0; n_eq * n];
    let io = UnitIo { local, layout, thermo, time: 0.0 };
    unit.jacobian(&io, &mut r, &mut jac);
    let mut worst: f64 = 0.0;
    let mut rp = vec![0.0; n_eq];
    let mut rm = vec![0.0; n_eq];
    let mut xp = local.to_vec();
    for j in 0..n {
        let h = 1e-6 * local[j].abs().max(1e-3);
        xp[j] = local[j] + h;
        unit.residual(&UnitIo { local: &xp, layout, thermo, time: 0.0 }, &mut rp);
        xp[j] = local[j] - h;
        unit.residual(&UnitIo { local: &xp, layout, thermo, time: 0.0 }, &mut rm);
        xp[j] = local[j];
        for k in 0..n_eq {
            let fd = (rp[k] - rm[k]) / (2.0 * h);
            let row_scale = (0..n).map(|c| (jac[k * n + c] * local[c].abs().max(1e-3)).abs()).fold(0.0, f64::max)
                / local[j].abs().max(1e-3);
            let denom = jac[k * n + j].abs().max(row_scale).max(1e-12);
            worst = worst.max((jac[k * n + j] - fd).abs() / denom);
        }
    }
    worst
}

/// Local layout of a controller (no ports) with two components.
pub fn controller_layout(u: &dyn Unit) -> LocalLayout {
    LocalLayout {
        stream: crate::StreamLayout { n_comp: 2 },
        n_outlets: 0,
        n_internal: u.internal_vars().len(),
        n_inlets: 0,
        n_inputs: u.inputs().len(),
        n_signals: u.signals().len(),
    }
}

/// A controller's residuals and guess at `local = [internal | inputs | signals]`.
pub fn controller_eval(u: &dyn Unit, local: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let thermo = binary_package();
    let layout = controller_layout(u);
    assert_eq!(layout.len(), local.len());
    let io = UnitIo { local, layout: &layout, thermo: &thermo, time: 0.0 };
    let mut r = vec![0.0; layout.n_own()];
    u.residual(&io, &mut r);
    let mut own = local[..layout.n_own()].to_vec();
    u.guess(&io, &mut own);
    (r, own)
}
