//! An independent check of a steady state the solver calls converged: every unit (not the feeds,
//! products or controllers) closes its component balances over its ports (its mass balance if it
//! reacts), every stream's mole fractions sum to 1, and no holdup `M`/`M[k]` sits on its lower
//! bound (an emptied vessel the bounds hid). And of a finished run: every value finite.

use plantwide::flowsheet::{BlockKind, Plant};
use plantwide::model::stream::{F, Z0};
use plantwide::solve::dynamic::SimulationResult;
use plantwide::units::Dimension;

/// Relative tolerance of the balances and the mole-fraction sums.
const TOL: f64 = 1e-9;

/// Check the steady state `x` of `plant`.
pub fn steady(plant: &Plant, x: &[f64]) -> Result<(), String> {
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        return Err(format!("{} = {} is not finite", plant.vars()[i].path, x[i]));
    }
    let len = plant.stream_layout().len();
    for s in plant.streams() {
        let sum: f64 = x[s.offset + Z0..s.offset + len].iter().sum();
        if (sum - 1.0).abs() > TOL {
            return Err(format!("stream {}: mole fractions sum to {sum:.12}", s.name));
        }
    }
    for (bi, b) in plant.blocks().iter().enumerate() {
        if b.kind == BlockKind::Unit && !matches!(b.unit.type_name(), "feed" | "product") {
            balance(plant, bi, x)?;
        }
    }
    holdups(plant, x)
}

/// Component (or, for a reacting unit, mass) balance of block `bi` over its port streams.
fn balance(plant: &Plant, bi: usize, x: &[f64]) -> Result<(), String> {
    let b = &plant.blocks()[bi];
    let reacting = b.unit.type_name() == "cstr";
    let mw: Vec<f64> = plant.thermo().components.iter().map(|c| c.mw).collect();
    let nc = plant.stream_layout().n_comp;
    let mut net = vec![0.0; if reacting { 1 } else { nc }];
    let (mut inflow, mut outflow) = (0.0f64, 0.0f64);
    for s in plant.streams() {
        let sign = match (s.to.0 == bi, s.from.0 == bi) {
            (true, false) => 1.0,
            (false, true) => -1.0,
            _ => continue,
        };
        let f = x[s.offset + F];
        let z = &x[s.offset + Z0..s.offset + Z0 + nc];
        let amount = if reacting { f * z.iter().zip(&mw).map(|(zi, m)| zi * m).sum::<f64>() } else { f };
        if reacting {
            net[0] += sign * amount;
        } else {
            net.iter_mut().zip(z).for_each(|(n, zi)| *n += sign * f * zi);
        }
        if sign > 0.0 { inflow += amount } else { outflow += amount }
    }
    let scale = inflow.max(outflow);
    if scale == 0.0 {
        return Ok(());
    }
    let (k, worst) = net.iter().enumerate().fold((0, 0.0f64), |a, (k, n)| if n.abs() > a.1 { (k, n.abs()) } else { a });
    if worst / scale > TOL {
        let what = if reacting { "mass".to_string() } else { format!("component {}", plant.components()[k]) };
        return Err(format!(
            "unit {}: {what} balance off by {:.3e} of its throughput (in {inflow:.6e}, out {outflow:.6e})",
            b.name,
            worst / scale
        ));
    }
    Ok(())
}

/// No total holdup at its lower bound.
fn holdups(plant: &Plant, x: &[f64]) -> Result<(), String> {
    for (v, &xv) in plant.vars().iter().zip(x) {
        let s = &v.spec;
        let holdup = s.name == "M" || s.name.starts_with("M[");
        if holdup
            && s.dim == Dimension::AMOUNT
            && s.lower.is_finite()
            && xv - s.lower <= TOL * s.nominal.max(s.lower.abs())
        {
            return Err(format!("{} = {xv:.3e} sits on its lower bound {:.3e}", v.path, s.lower));
        }
    }
    Ok(())
}

/// Check a finished run: finite final state, times and recorded values.
pub fn run(res: &SimulationResult) -> Result<(), String> {
    if let Some(i) = res.x.iter().position(|v| !v.is_finite()) {
        return Err(format!("final state entry {i} = {}", res.x[i]));
    }
    if let Some(t) = res.times.iter().find(|t| !t.is_finite()) {
        return Err(format!("recorded time {t}"));
    }
    for (t, row) in res.times.iter().zip(&res.rows) {
        if let Some(k) = row.iter().position(|v| !v.is_finite()) {
            return Err(format!("{} = {} at t = {t}", res.columns[k].path, row[k]));
        }
    }
    Ok(())
}
