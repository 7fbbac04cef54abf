//! Certified steady states: a converged Newton residual is not yet an answer.
//!
//! Newton can meet `f(x) = 0` at a degenerate point: a drum whose holdup rests on its floor, where
//! `x·M = n` holds for any composition `x`, passes every equation with a distillate larger than the
//! feed. Before a steady state is reported, [`certify`] checks it against conservation, written
//! from the stream values alone and so independent of each unit's equations:
//! - every value is finite and every stream's mole fractions sum to 1 (to [`TOL`]);
//! - for every unit other than feeds and products, `Σ_in F·z_c − Σ_out F·z_c = 0` for each
//!   component `c` (for a unit that reacts, the mass `Σ F Σ_c z_c·M_c` instead), relative to the
//!   unit's throughput (to [`TOL`]); and the same over the plant, feeds against products;
//! - no total holdup (a stage's, a drum's, a vessel's `M`) rests on its lower bound.
//!
//! A controller in auto whose output rests on a limit while its measurement is off setpoint is a
//! true steady state but not the one asked for: it is returned as a [`Warning`].

use plantwide_flowsheet::{BlockKind, Plant, VarPath};
use plantwide_model::{Boundary, UnitIo, limits::number};
use serde::Serialize;

/// Relative tolerance of the balances and of the mole-fraction sums of a Newton-converged steady
/// state. A sequential-modular answer is certified to ten times its tear tolerance instead
/// ([`certify_to`]): it is only as balanced as its tears are converged.
pub const TOL: f64 = 1e-9;

/// A steady state that fails its certificate: which unit, which equation, by how much.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}: the converged point is not a valid steady state: {unit}: {equation} = {} (tolerance ±{tol:e}){}", number(*.relative), hint(.at_bound))]
pub struct CertificateFailure {
    /// Flowsheet file.
    pub file: String,
    /// The unit (or stream, or `plant`) that fails.
    pub unit: String,
    /// The failed balance or condition, e.g. `component balance of light`.
    pub equation: String,
    /// Its relative imbalance.
    pub relative: f64,
    /// The tolerance it exceeds.
    pub tol: f64,
    /// Total holdups of that unit resting on their lower bound (the likely cause).
    pub at_bound: Vec<String>,
}

/// `; X rests on its lower bound: …` with what would fix it (empty if nothing is on its floor).
pub(crate) fn hint(at_bound: &[String]) -> String {
    if at_bound.is_empty() {
        return String::new();
    }
    format!(
        "; {} rest{} on {} lower bound: the specification asks for more than the plant can deliver (a product flow above its feed, a holdup setpoint below zero) — check the flows and setpoints of that unit",
        at_bound.join(", "),
        if at_bound.len() == 1 { "s" } else { "" },
        if at_bound.len() == 1 { "its" } else { "their" }
    )
}

/// A controller output resting on a limit with its measurement off setpoint.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Warning {
    /// The controller's output path (`xd.op`).
    pub path: String,
    /// The limit reached: `op_min` or `op_max`.
    pub limit: String,
    /// Its value (SI).
    pub value: f64,
    /// Measurement minus setpoint (SI).
    pub offset: f64,
    /// The same in words.
    pub message: String,
}

/// Check the steady state `x` of `plant` at inputs `u` (see the module documentation): `Ok` with
/// the controllers that saturate, or the first failed condition.
pub fn certify(plant: &Plant, x: &[f64], u: &[f64]) -> Result<Vec<Warning>, CertificateFailure> {
    certify_to(plant, x, u, TOL)
}

/// [`certify`] to the relative tolerance `tol`.
pub fn certify_to(plant: &Plant, x: &[f64], u: &[f64], tol: f64) -> Result<Vec<Warning>, CertificateFailure> {
    let fail = |unit: &str, equation: String, relative: f64, at_bound: Vec<String>| CertificateFailure {
        file: plant.file().to_string(),
        unit: unit.to_string(),
        equation,
        relative,
        tol,
        at_bound,
    };
    if let Some(j) = x.iter().position(|v| !v.is_finite()) {
        return Err(fail(&plant.vars()[j].path, "its value, not finite,".into(), f64::INFINITY, Vec::new()));
    }
    for (si, s) in plant.streams().iter().enumerate() {
        let sum: f64 = x[plant.stream_composition_vars(si)].iter().sum();
        if (sum - 1.0).abs() > tol {
            let at_bound = floors(plant, x, s.from.0);
            return Err(fail(&s.name, "the sum of its mole fractions − 1".into(), sum - 1.0, at_bound));
        }
    }
    let reacting = plant.blocks().iter().any(|b| b.unit.reacts());
    let scale = (0..plant.streams().len()).map(|s| x[plant.stream_flow_var(s)]).fold(0.0, f64::max).max(1e-12);
    for (bi, b) in plant.blocks().iter().enumerate() {
        if b.kind != BlockKind::Unit || b.unit.boundary() != Boundary::Interior {
            continue;
        }
        let streams = (plant.streams_into(bi).iter().copied(), plant.streams_out_of(bi).iter().copied());
        if let Some((equation, rel)) = imbalance(plant, x, streams, b.unit.reacts(), 1e-6 * scale, tol) {
            return Err(fail(&b.name, equation, rel, floors(plant, x, bi)));
        }
        if let Some(path) = floors(plant, x, bi).into_iter().next() {
            return Err(fail(&b.name, format!("the holdup {path} − its lower bound"), 0.0, vec![path]));
        }
    }
    let boundary = |bi: usize| plant.blocks()[bi].unit.boundary();
    let feeds = (0..plant.streams().len()).filter(|&s| boundary(plant.streams()[s].from.0) == Boundary::Source);
    let products = (0..plant.streams().len()).filter(|&s| boundary(plant.streams()[s].to.0) == Boundary::Sink);
    if let Some((equation, rel)) = imbalance(plant, x, (feeds, products), reacting, 1e-6 * scale, tol) {
        return Err(fail("plant", format!("{equation} (feeds against products)"), rel, Vec::new()));
    }
    Ok(saturated(plant, x, u))
}

/// The worst relative imbalance of the component (or, with `mass`, the mass) balance between the
/// streams `ins` and `outs` (stream indices), if it exceeds `tol`; relative to the larger of the
/// throughput and `floor` [mol/s].
fn imbalance(
    plant: &Plant,
    x: &[f64],
    (ins, outs): (impl Iterator<Item = usize>, impl Iterator<Item = usize>),
    mass: bool,
    floor: f64,
    tol: f64,
) -> Option<(String, f64)> {
    let nc = plant.components().len();
    let mw: Vec<f64> = plant.thermo().components.iter().map(|c| c.mw).collect();
    let mut net = vec![0.0; nc];
    let mut through = 0.0;
    let mut add = |s: usize, sign: f64| {
        let (f, z) = (x[plant.stream_flow_var(s)], plant.stream_composition_vars(s).start);
        through += 0.5 * f;
        for (c, n) in net.iter_mut().enumerate() {
            *n += sign * f * x[z + c] * if mass { mw[c] } else { 1.0 };
        }
    };
    ins.for_each(|o| add(o, 1.0));
    outs.for_each(|o| add(o, -1.0));
    let denom = through.max(floor);
    if mass {
        let mw_max = mw.iter().copied().fold(0.0, f64::max).max(1e-12);
        let rel = net.iter().sum::<f64>() / (denom * mw_max);
        return (rel.abs() > tol).then(|| ("the mass balance (in − out)/throughput".to_string(), rel));
    }
    let (c, rel) = net.iter().map(|n| n / denom).enumerate().max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))?;
    (rel.abs() > tol).then(|| (format!("the balance of {} (in − out)/throughput", plant.components()[c]), rel))
}

/// Total holdups of the whole plant resting on their lower bound at `x` (a failed solve's last
/// iterate: a drum run dry says what the specification asks for).
pub fn floors_anywhere(plant: &Plant, x: &[f64]) -> Vec<String> {
    (0..plant.blocks().len()).flat_map(|bi| floors(plant, x, bi)).collect()
}

/// Total holdups of block `bi` resting on their lower bound.
fn floors(plant: &Plant, x: &[f64], bi: usize) -> Vec<String> {
    let b = &plant.blocks()[bi];
    let own = b.own_offset..b.own_offset + b.layout.n_own();
    plant.vars()[own.clone()]
        .iter()
        .zip(&x[own])
        .filter(|&(v, &xv)| {
            v.block == bi && v.spec.inventory && xv <= v.spec.lower + 1e-9 * v.spec.nominal.abs().max(1e-300)
        })
        .map(|(v, _)| v.path.clone())
        .collect()
}

/// Controllers in auto whose output rests on a limit with the measurement off setpoint.
fn saturated(plant: &Plant, x: &[f64], u: &[f64]) -> Vec<Warning> {
    let mut local = Vec::new();
    let mut out = Vec::new();
    for b in plant.blocks().iter().filter(|b| b.kind == BlockKind::Controller) {
        plant.gather(b, x, u, &mut local);
        let io = UnitIo { local: &local, layout: &b.layout, thermo: plant.thermo(), time: 0.0 };
        if let Some(s) = b.unit.saturation(&io) {
            let message = format!(
                "controller `{}` is saturated: its output rests on {} = {} with the measurement {} off setpoint; the steady state holds the output at its limit, not the measurement at its setpoint",
                b.name,
                s.limit,
                number(s.value),
                number(s.offset)
            );
            out.push(Warning {
                path: VarPath::controller_output(&b.name, 0).into(),
                limit: s.limit.into(),
                value: s.value,
                offset: s.offset,
                message,
            });
        }
    }
    out
}
