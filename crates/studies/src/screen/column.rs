//! The inventory configurations of a distillation column (Skogestad & Morari 1987; Skogestad,
//! Lundström & Jacobsen 1990; Luyben (ed.) 1992 ch. 5): which two of the column's four flows — reflux
//! L, boilup V (or the reboiler duty or steam that sets it), distillate D, bottoms B — hold the
//! condenser and reboiler levels, and so which two, or which ratios, are left to control the top
//! and bottom qualities.
//!
//! | name | condenser level by | reboiler level by | quality inputs |
//! |---|---|---|---|
//! | LV | D | B | L, V |
//! | DV | L | B | D, V |
//! | LB | D | V | L, B |
//! | DB | L | V | D, B |
//! | (L/D)V | D, with L = R·D | B | R = L/D, V |
//! | L(V/B) | D | B, with V = S·B | L, S = V/B |
//! | (L/D)(V/B) | D, with L = R·D | B, with V = S·B | R, S |
//!
//! Each is built from the flowsheet as written through [`Plant::restructure`]: the column's quality
//! loops (any other controller driving one of the four flows) opened, its level controllers moved
//! to their configuration's flows (gain rescaled by the ratio of the two flows' values when their
//! dimensions differ, bias and limits dropped so the loop is bumpless at the operating point), ratio
//! stations added for L/D and V/B; every free flow held at its value in the plant's steady state.
//! The configuration is then converged from that steady state, checked to reproduce the plant's
//! qualities (holdups do not set a steady state's compositions; a moved quality is an error), and
//! linearized: the gains of the two qualities to its two free inputs are exact (`−C J⁻¹ B`, SI units:
//! mole fraction per mol/s, per mol/mol of a ratio, per W of a duty).
//!
//! **Scaled gains** ([`scaling`]): SI gains mix watts, mol/s and mole fractions, so their condition
//! number γ says nothing. Each input is scaled by its nominal (steady-state) value and each quality
//! by its allowed deviation (given, or its distance to 0 or 1 for a mole fraction: a quality at
//! 0.995 may move by 0.005), `G̃ = diag(1/Δy) G diag(u₀)`; γ is `σ_max/σ_min` of `G̃`. The RGA and γ*
//! (the condition number minimized over scalings) do not depend on the scaling.
//!
//! **The recommended pairing**: the diagonal one (top quality with the first input) when
//! `λ11 ≥ 0.5`, the off-diagonal one (relative gain `1 − λ11`) otherwise; a configuration is ranked
//! by the pairing its verdict recommends.
//!
//! **The dynamic check** ([`mod@dynamic`], the default): each configuration that converged and is not
//! singular gets PI loops on its recommended pairing, tuned together by one rule (Luyben's BLT on
//! the exact linearization with a measurement dead time, as the pairing screen's dynamic test),
//! and every disturbance is stepped on the nonlinear plant; the configurations are ranked by their
//! scaled IAE, `Σ_runs Σ_qualities IAE/Δy` \[s\], with the steady-state measures beside it. Without
//! it they are ranked by the steady state alone (the relative gain of the recommended pairing
//! closest to 1, then γ*), and the verdict says so.
//!
//! DB is singular at steady state: with both products fixed, `D + B = F` leaves the total
//! inventory undetermined (the Jacobian is singular), so its gains do not exist; it is reported as
//! singular and not ranked (it can still be controlled dynamically — Skogestad et al. 1990).

mod dynamic;
pub mod scaling;
mod verdict;
mod write;

use faer::Mat;
use plantwide_analysis::linear::Linearization;
use plantwide_analysis::measures::{SINGULAR_RATIO, condition_number, niederlinski, rga, rows, svd};
use plantwide_analysis::min_cond::minimized_condition_number;
use plantwide_flowsheet::{Override, Plant, StructureEdit, VarPath};
use plantwide_model::ControllerSpec;
use plantwide_solve::{NewtonSettings, StrategySettings, steady_state};
use plantwide_units::QuantityValue;
use rayon::prelude::*;
use serde::Serialize;

pub use dynamic::ColumnDynamic;
pub use scaling::Scaling;

use super::ScreenError;
use super::pairings::DynamicResult;

/// The flow left for the top quality: reflux, distillate, or the reflux ratio L/D.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Top {
    L,
    D,
    Ratio,
}

/// The flow left for the bottom quality: boilup (or duty), bottoms, or the boilup ratio V/B.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Bottom {
    V,
    B,
    Ratio,
}

/// The seven configurations, in the order they are reported.
const CONFIGURATIONS: [(&str, Top, Bottom); 7] = [
    ("LV", Top::L, Bottom::V),
    ("DV", Top::D, Bottom::V),
    ("LB", Top::L, Bottom::B),
    ("DB", Top::D, Bottom::B),
    ("(L/D)V", Top::Ratio, Bottom::V),
    ("L(V/B)", Top::L, Bottom::Ratio),
    ("(L/D)(V/B)", Top::Ratio, Bottom::Ratio),
];

/// A configuration's name as a file name: `LV`, `DV`, `LB`, `DB`, `LD-V`, `L-VB`, `LD-VB`.
pub fn file_stem(name: &str) -> String {
    name.replace(")(", "-").replace(['(', ')', '/'], "").replace("LDV", "LD-V").replace("LVB", "L-VB")
}

/// What to screen.
#[derive(Debug, Clone, PartialEq)]
pub struct ColumnRequest {
    /// The column.
    pub column: String,
    /// The top and bottom qualities (variable paths).
    pub outputs: Vec<String>,
    /// The largest deviation allowed of each quality (SI), top first: the scale of its gains and
    /// of its IAE; `None`: each quality's distance to 0 or 1 (a mole fraction), else its steady
    /// value.
    pub allowed: Option<[f64; 2]>,
    /// The dynamic check; `None`: the steady-state measures alone (the fast path).
    pub dynamic: Option<ColumnDynamic>,
}

impl ColumnRequest {
    /// The steady-state screening of `column` for `outputs`, without the dynamic check.
    pub fn steady(column: &str, outputs: &[String]) -> ColumnRequest {
        ColumnRequest { column: column.into(), outputs: outputs.to_vec(), allowed: None, dynamic: None }
    }
}

/// One configuration: its steady-state interaction measures and, when the check ran, its dynamic
/// test. `gain[i][j]` is quality i (top, bottom) to input j of `inputs`; `rga[0][0]` pairs the top
/// quality with the first input.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ColumnStructure {
    /// `LV`, `DV`, `LB`, `DB`, `(L/D)V`, `L(V/B)` or `(L/D)(V/B)`.
    pub name: String,
    /// Input paths left for the qualities (top first): a column flow or a ratio station's `ratio`.
    pub inputs: Vec<String>,
    /// Steady-state gains (SI), `None` when singular.
    pub gain: Option<Vec<Vec<f64>>>,
    /// The gains scaled ([`Scaling`]): `gain[i][j] · input_scales[j] / allowed_deviation[i]`.
    pub scaled_gain: Option<Vec<Vec<f64>>>,
    /// Each input's scale: its nominal (steady-state) value (SI).
    pub input_scales: Option<Vec<f64>>,
    /// Relative gain array.
    pub rga: Option<Vec<Vec<f64>>>,
    /// Niederlinski index of the diagonal pairing.
    pub niederlinski: Option<f64>,
    /// γ: `σ_max/σ_min` of the scaled gains.
    pub condition_number: Option<f64>,
    /// γ*: the condition number minimized over input and output scalings.
    pub minimized_condition_number: Option<f64>,
    /// Singular at steady state.
    pub singular: bool,
    /// The pairing its verdict recommends: the input paired with the top quality, then the one
    /// paired with the bottom quality.
    pub pairing: Option<Vec<String>>,
    /// The relative gain of that pairing (`λ11`, or `1 − λ11` off the diagonal).
    pub relative_gain: Option<f64>,
    /// Place by the steady-state measures alone (the relative gain of the recommended pairing
    /// closest to 1, then γ*), `None` when singular or failed.
    pub steady_rank: Option<usize>,
    /// The dynamic check of the recommended pairing (`null` when not run: `--steady-only`, a
    /// singular or failed configuration); its `score` is its scaled IAE over the best one's.
    pub dynamic: Option<DynamicResult>,
    /// `Σ_runs Σ_qualities IAE/allowed deviation` \[s\] of the dynamic check, `null` when it was
    /// not run or failed.
    pub iae_scaled: Option<f64>,
    /// Place in the ranking (1 best): by `iae_scaled` when the dynamic check ran, else by the
    /// steady state; `None` when singular or failed.
    pub rank: Option<usize>,
    /// What the numbers say, in words, and where the evidence disagrees with the recommendation.
    pub verdict: String,
    /// Why its steady state, gains or dynamic check failed (the solver's verdict, naming the
    /// unit, equation and variable), its measures then `null`; `null` when it was judged.
    pub failure: Option<String>,
    /// Where the plant under this configuration left its operating range in the dynamic check (a
    /// vessel ran dry or overflowed, a loop drove a flow below zero), run by run: the
    /// configuration cannot ride through those disturbances, so it is not ranked; an answer, not
    /// a failure. `null` when every run went through.
    pub lost: Option<String>,
    /// The configuration with its loops as tuned, the text of a flowsheet file (kept when asked
    /// for).
    #[serde(skip)]
    pub flowsheet: Option<String>,
}

/// The configurations of one column.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ColumnScreen {
    /// The column.
    pub column: String,
    /// The top and bottom qualities.
    pub outputs: Vec<String>,
    /// Values of L, V (or its duty or steam), D and B at the steady state (SI).
    pub flows: Flows,
    /// How the gains and IAEs are scaled.
    pub scaling: Scaling,
    /// `dynamic check` or `steady state`.
    pub ranked_by: String,
    /// The dynamic check's steps, one run each (empty when it was not run).
    pub disturbances: Vec<String>,
    /// Length of every run \[s\] (`null` when the dynamic check was not run).
    pub duration: Option<f64>,
    /// Measurement dead time of the tuning \[s\] (`null` when the dynamic check was not run).
    pub measurement_dead_time: Option<f64>,
    /// The configurations, in the table's order.
    pub structures: Vec<ColumnStructure>,
    /// The configurations that failed, each with its reason (also in its `failure`); empty when
    /// all were judged.
    pub failed: Vec<String>,
    /// The recommendation and what it rests on; when the steady-state measures alone would
    /// recommend another configuration, it says so.
    pub verdict: String,
    /// The plant's inventory control as the file has it: throughput manipulator candidates and
    /// each inventory's consistency ([`plantwide_flowsheet::inventory`]).
    pub inventory: plantwide_flowsheet::inventory::InventoryCheck,
    /// The dynamic check's scenarios, one per step (a file name and its text), kept with the
    /// flowsheets.
    #[serde(skip)]
    pub scenarios: Vec<(String, plantwide_flowsheet::scenario::ScenarioSpec)>,
}

/// The column's four flows at the steady state (SI: mol/s; W or kg/s for a duty or steam boilup).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Flows {
    /// Reflux.
    pub reflux: f64,
    /// Boilup, reboiler duty or steam flow.
    pub boilup: f64,
    /// Distillate.
    pub distillate: f64,
    /// Bottoms.
    pub bottoms: f64,
}

/// The column as the configurations see it: its four flow inputs, its level loops, its products'
/// flow variables and the quality loops to open.
struct Handles {
    column: String,
    /// Input paths: reflux, boilup (or duty or steam), distillate, bottoms.
    paths: [String; 4],
    condenser_level: String,
    reboiler_level: String,
    distillate_flow: String,
    bottoms_flow: String,
    quality_loops: Vec<String>,
}

/// A configuration that converged with regular gains: its plant, steady state and SI gains.
pub(crate) struct Variant {
    plant: Plant,
    x: Vec<f64>,
    gain: Mat<f64>,
}

/// Screen the inventory configurations of `column` for the qualities `outputs` (top, bottom) at
/// the steady state of `plant` as written, by the steady-state measures alone (the fast path;
/// [`screen_column_with`] runs the dynamic check).
///
/// # Errors
/// [`ScreenError`] naming the column, output or configuration that failed.
pub fn screen_column(plant: &Plant, column: &str, outputs: &[String]) -> Result<ColumnScreen, ScreenError> {
    screen_column_with(plant, &ColumnRequest::steady(column, outputs))
}

/// Screen the inventory configurations of `r.column` as `r` asks: steady-state measures on scaled
/// gains, and with `r.dynamic` the dynamic check, which the ranking then follows.
///
/// # Errors
/// [`ScreenError`] naming the column, output, disturbance or configuration that failed; a
/// configuration whose steady state or dynamic check fails numerically is marked in its place
/// (and listed in `failed`) instead.
pub fn screen_column_with(plant: &Plant, r: &ColumnRequest) -> Result<ColumnScreen, ScreenError> {
    let outputs = &r.outputs;
    if outputs.len() != 2 {
        return Err(ScreenError::OutputCount(outputs.len()));
    }
    super::without_mpc(plant, "screen")?;
    let h = handles(plant, &r.column)?;
    let out: Vec<usize> = outputs.iter().map(|p| output_var(plant, p)).collect::<Result<_, _>>()?;
    let steps = r.dynamic.as_ref().map(|d| dynamic::disturbances(plant, &r.column, outputs, d)).transpose()?;
    let steady = |e| ScreenError::Steady { structure: "file".into(), source: Box::new(e) };
    let base = plantwide_solve::converge(plant, &StrategySettings::default()).map_err(|e| steady(e.into()))?;
    let scaling = scaling::outputs(plant, &base.x, &out, outputs, r.allowed)?;
    let flows = h.paths.each_ref().map(|p| input_value(plant, &base.x, p));
    let built: Vec<_> =
        CONFIGURATIONS.par_iter().map(|&c| configuration(plant, &h, &base.x, &flows, &out, c)).collect();
    let (mut structures, mut variants) = (Vec::new(), Vec::new());
    for (b, (name, top, bottom)) in built.into_iter().zip(CONFIGURATIONS) {
        // A configuration whose steady state is not determined (an inventory it leaves free, as DB
        // leaves D + B = F) is singular; one that fails numerically is marked and the others are
        // judged; a request at fault stops the screening.
        let (s, v) = match b {
            Ok(sv) => sv,
            Err(ScreenError::Steady { source, .. }) if source.is_user_error() => {
                (undetermined(name, edits(plant, &h, &flows, top, bottom).1, &source.to_string()), None)
            }
            Err(e) if e.is_user_error() => return Err(e),
            Err(e) => (failed(name, edits(plant, &h, &flows, top, bottom).1, e.to_string()), None),
        };
        structures.push(s);
        variants.push(v);
    }
    for (s, v) in structures.iter_mut().zip(&variants) {
        if let Some(v) = v {
            scaling::apply(s, v, &scaling)?;
        }
    }
    verdict::rank_steady(&mut structures);
    let check = match (&r.dynamic, steps) {
        (Some(d), Some(steps)) => {
            Some(dynamic::check(plant, outputs, &steps, d, &scaling, &mut structures, &variants)?)
        }
        _ => None,
    };
    verdict::rank(&mut structures, check.is_some());
    let verdict = verdict::judge(&mut structures, check.is_some());
    let failed = structures.iter().flat_map(failures).collect();
    let [reflux, boilup, distillate, bottoms] = flows;
    let check = check.unwrap_or_default();
    Ok(ColumnScreen {
        column: r.column.clone(),
        outputs: outputs.to_vec(),
        flows: Flows { reflux, boilup, distillate, bottoms },
        scaling,
        ranked_by: if r.dynamic.is_some() { "dynamic check" } else { "steady state" }.into(),
        disturbances: check.steps,
        duration: check.duration,
        measurement_dead_time: r.dynamic.as_ref().map(|d| d.measurement.dead_time),
        structures,
        failed,
        verdict,
        inventory: plantwide_flowsheet::inventory::check(plant),
        scenarios: check.scenarios,
    })
}

/// What failed of configuration `c`, each with its reason: its steady state, or its dynamic
/// check's tuning or runs.
fn failures(c: &ColumnStructure) -> Vec<String> {
    let label = format!("configuration {}", c.name);
    match (&c.dynamic, &c.failure) {
        (Some(d), Some(_)) if !d.completed() => d.failures(&label),
        (_, Some(why)) => vec![format!("{label}: {why}")],
        (_, None) => Vec::new(),
    }
}

/// The column's flows, level loops and quality loops.
fn handles(plant: &Plant, column: &str) -> Result<Handles, ScreenError> {
    let boil = ["boilup", "reboiler_duty", "steam_flow"];
    let find = |c: &str| boil.iter().map(|b| VarPath::new(c, b)).find(|p| plant.input(p).is_some());
    let is_column =
        |c: &str| ["reflux", "distillate", "bottoms"].iter().all(|f| plant.input(VarPath::new(c, f)).is_some());
    let boilup = find(column).filter(|_| is_column(column));
    let Some(boilup) = boilup else {
        let columns: Vec<&str> =
            plant.spec().units.keys().map(String::as_str).filter(|c| is_column(c) && find(c).is_some()).collect();
        let hint = plantwide_flowsheet::error::did_you_mean(column, columns.iter().copied());
        return Err(ScreenError::NotAColumn { name: column.into(), hint, columns: columns.join(", ") });
    };
    let paths: [String; 4] =
        [VarPath::new(column, "reflux"), boilup, VarPath::new(column, "distillate"), VarPath::new(column, "bottoms")]
            .map(String::from);
    let pids: Vec<(&String, &plantwide_model::controllers::pid::PidConfig)> = plant
        .spec()
        .controllers
        .iter()
        .filter_map(|(n, c)| if let ControllerSpec::Pid(p) = c { Some((n, p)) } else { None })
        .collect();
    let drives =
        |p: &plantwide_model::controllers::pid::PidConfig| p.output.as_ref().is_some_and(|o| paths.contains(o));
    let level = |end: &'static str, is_pv: &dyn Fn(&str) -> bool, pv: String| {
        pids.iter()
            .find(|(_, p)| drives(p) && is_pv(&p.pv))
            .map(|(n, _)| (*n).clone())
            .ok_or_else(|| ScreenError::NoLevelLoop { column: column.into(), end, pv, handles: paths.join(", ") })
    };
    let holdups = VarPath::new(column, "M");
    let bottom_pv = holdups.clone().index(1);
    let reboiler_level = level("reboiler", &|pv| pv == bottom_pv.as_str(), bottom_pv.to_string())?;
    let top = |pv: &str| holdups.has_element(pv) && pv != bottom_pv.as_str();
    let condenser_level = level("condenser", &top, holdups.clone().index("N").into())?;
    let quality_loops = plant
        .spec()
        .controllers
        .iter()
        .filter(|(n, c)| **n != condenser_level && **n != reboiler_level && drives_any(c, &paths))
        .map(|(n, _)| n.clone())
        .collect();
    let product = |port: &str| stream_from(plant, VarPath::new(column, port).as_str());
    Ok(Handles {
        column: column.to_string(),
        distillate_flow: product("distillate"),
        bottoms_flow: product("bottoms"),
        paths,
        condenser_level,
        reboiler_level,
        quality_loops,
    })
}

/// True when controller `c` drives one of `paths`.
pub(super) fn drives_any(c: &ControllerSpec, paths: &[String]) -> bool {
    c.config().paths().driven.iter().any(|(_, p)| paths.contains(p))
}

/// Path of the molar flow of the stream leaving `port` (`unit.port`), or of the port's own input
/// when no stream leaves it.
fn stream_from(plant: &Plant, port: &str) -> String {
    plant
        .spec()
        .streams
        .iter()
        .find(|(_, s)| s.from == port)
        .map_or_else(|| port.to_string(), |(name, _)| VarPath::new(name, "F").into())
}

fn output_var(plant: &Plant, path: &str) -> Result<usize, ScreenError> {
    plant.var(path).ok_or_else(|| ScreenError::NoOutput {
        path: path.into(),
        hint: plantwide_flowsheet::error::did_you_mean(path, plant.vars().iter().map(|v| v.path.as_str())),
    })
}

/// The value input `path` takes at state `x`: its controller's output when one drives it.
pub(super) fn input_value(plant: &Plant, x: &[f64], path: &str) -> f64 {
    let Some(i) = plant.input(path) else { return f64::NAN };
    let info = &plant.inputs()[i];
    info.driven_by.map_or(info.value, |op| x[op])
}

/// Whether a variant's steady state has moved a controlled variable off the plant's value `base`:
/// by more than the two steady states' solving accounts for. Each is solved to the default
/// scaled residual, which leaves a high-purity composition of 1.5e-4 on a rigorous column ~1e-11
/// apart between two starts (8.5e-8 of itself, generated plant 0xe7c52428ce785f7b); a rewiring
/// that moves the operating point moves it by orders more.
pub(super) fn moved(value: f64, base: f64) -> bool {
    (value - base).abs() > 1e-6 * base.abs() + 1e-12
}

/// Build configuration `(name, top, bottom)`, find its steady state from the plant's and measure
/// its gains.
fn configuration(
    plant: &Plant,
    h: &Handles,
    x: &[f64],
    flows: &[f64; 4],
    out: &[usize],
    (name, top, bottom): (&str, Top, Bottom),
) -> Result<(ColumnStructure, Option<Variant>), ScreenError> {
    let (edits, inputs) = edits(plant, h, flows, top, bottom);
    let wiring = |e| ScreenError::Wiring { structure: name.into(), source: Box::new(e) };
    let v = plant.restructure(&edits).map_err(wiring)?;
    let u = v.input_values();
    let guess = guess(plant, x, &v, h, flows);
    let ids: Vec<usize> = inputs.iter().filter_map(|p| v.input(p)).collect();
    let outs: Vec<usize> = out.iter().filter_map(|&o| v.var(&plant.vars()[o].path)).collect();
    let steady = match steady_state(&v, &u, Some(&guess), &NewtonSettings::default()) {
        Ok(s) => s,
        // No isolated steady state: singular when the Jacobian at the plant's point is; a failure else.
        Err(e) => return singular_or_failure((&v, &guess, &u), name, inputs, (&ids, &outs), e).map(|s| (s, None)),
    };
    for (&o, &ob) in outs.iter().zip(out) {
        let (value, base) = (steady.x[o], x[ob]);
        if moved(value, base) {
            return Err(ScreenError::Moved { structure: name.into(), output: v.vars()[o].path.clone(), value, base });
        }
    }
    let g = Linearization::new(&v, &steady.x, &u).steady_gain(&ids, &outs).ok();
    let structure = measures(name, inputs, g.clone())?;
    let variant = g.filter(|_| !structure.singular).map(|gain| Variant { plant: v, x: steady.x, gain });
    Ok((structure, variant))
}

/// A configuration Newton could not converge: singular if its Jacobian at the plant's own steady
/// state (which the configuration shares) is, a numerical failure otherwise.
fn singular_or_failure(
    (v, x, u): (&Plant, &[f64], &[f64]),
    name: &str,
    inputs: Vec<String>,
    (ids, outs): (&[usize], &[usize]),
    e: plantwide_solve::SteadyError,
) -> Result<ColumnStructure, ScreenError> {
    match Linearization::new(v, x, u).steady_gain(ids, outs) {
        Err(_) => measures(name, inputs, None),
        Ok(g) if is_singular(&g) => measures(name, inputs, None),
        Ok(_) => Err(ScreenError::Steady {
            structure: name.into(),
            source: Box::new(plantwide_solve::Error::from(plantwide_solve::SolveError::from(e))),
        }),
    }
}

/// The edits that build a configuration, and its two quality inputs.
fn edits(plant: &Plant, h: &Handles, flows: &[f64; 4], top: Top, bottom: Bottom) -> (Vec<StructureEdit>, Vec<String>) {
    let mut e: Vec<StructureEdit> =
        h.quality_loops.iter().map(|q| StructureEdit::RemoveController(q.clone())).collect();
    let [l, v, d, b] = [0, 1, 2, 3].map(|k| h.paths[k].clone());
    let (top_level, top_input) = match top {
        Top::L => (d.clone(), l.clone()),
        Top::D => (l.clone(), d.clone()),
        Top::Ratio => (d.clone(), VarPath::new(&format!("{}_reflux_ratio", h.column), "ratio").into()),
    };
    let (bottom_level, bottom_input) = match bottom {
        Bottom::V => (b.clone(), v.clone()),
        Bottom::B => (v.clone(), b.clone()),
        Bottom::Ratio => (b.clone(), VarPath::new(&format!("{}_boilup_ratio", h.column), "ratio").into()),
    };
    e.extend(move_level(plant, &h.condenser_level, &top_level, flows, &h.paths));
    e.extend(move_level(plant, &h.reboiler_level, &bottom_level, flows, &h.paths));
    if top == Top::Ratio {
        e.push(ratio_station(&format!("{}_reflux_ratio", h.column), &h.distillate_flow, &l, flows[0] / flows[2]));
    }
    if bottom == Bottom::Ratio {
        e.push(ratio_station(&format!("{}_boilup_ratio", h.column), &h.bottoms_flow, &v, flows[1] / flows[3]));
    }
    // The flows no controller drives now hold their steady-state values.
    let mut driven = vec![top_level, bottom_level];
    driven.extend((top == Top::Ratio).then_some(l));
    driven.extend((bottom == Bottom::Ratio).then_some(v));
    for (k, p) in h.paths.iter().enumerate().filter(|(_, p)| !driven.contains(p)) {
        e.push(StructureEdit::Set(Override::new(p.clone(), format!("{:e}", flows[k]))));
    }
    (e, vec![top_input, bottom_input])
}

/// Level controller `name` moved to drive `to`: the same description with its output changed, its
/// gain rescaled by the flows' ratio when the new flow has another dimension, bias and limits
/// dropped (the bias defaults to the new flow's value: bumpless at the operating point).
fn move_level(plant: &Plant, name: &str, to: &str, flows: &[f64; 4], paths: &[String; 4]) -> Vec<StructureEdit> {
    let Some(ControllerSpec::Pid(cfg)) = plant.spec().controllers.get(name) else { return Vec::new() };
    if cfg.output.as_deref() == Some(to) {
        return Vec::new();
    }
    let mut c = cfg.clone();
    let from = cfg.output.clone().unwrap_or_default();
    let dim = |p: &str| plant.input(p).map(|i| plant.inputs()[i].dim);
    if dim(&from) != dim(to) {
        let value = |p: &str| paths.iter().position(|q| q == p).map_or(1.0, |k| flows[k]);
        let kc = match &c.kc {
            QuantityValue::Number(n) => *n,
            QuantityValue::Text(t) => plantwide_units::parse_quantity(t).map_or(f64::NAN, |q| q.value_si),
        };
        let gain_dim =
            dim(to).zip(plant.var(&cfg.pv).map(|v| plant.vars()[v].spec.dim)).and_then(|(o, m)| o.checked_div(m));
        let kc = kc * value(to) / value(&from);
        c.kc = gain_dim.map_or(QuantityValue::Number(kc), |d| format!("{kc} {d}").into());
    }
    c.output = Some(to.to_string());
    (c.bias, c.op_min, c.op_max) = (None, None, None);
    // Removed and added again (not set in place): the moved loop comes last among the controllers,
    // as it always has in a configuration's layout.
    let spec = Box::new(ControllerSpec::Pid(c));
    vec![StructureEdit::RemoveController(name.into()), StructureEdit::AddController { name: name.into(), spec }]
}

/// A ratio station `name` driving `output` at `ratio` times the flow `wild`.
fn ratio_station(name: &str, wild: &str, output: &str, ratio: f64) -> StructureEdit {
    use plantwide_model::controllers::ratio::{RatioConfig, RatioValue};
    let spec = RatioConfig {
        wild: wild.into(),
        output: output.into(),
        ratio: RatioValue::Value(QuantityValue::Number(ratio)),
        bias: None,
        op_min: None,
        op_max: None,
    };
    StructureEdit::AddController { name: name.into(), spec: Box::new(ControllerSpec::Ratio(spec)) }
}

/// The configuration's starting point: the plant's steady state by variable path; a ratio
/// station's output at the flow it drives.
fn guess(plant: &Plant, x: &[f64], v: &Plant, h: &Handles, flows: &[f64; 4]) -> Vec<f64> {
    let mut g = mapped_guess(plant, x, v);
    for (station, flow) in [("reflux_ratio", flows[0]), ("boilup_ratio", flows[1])] {
        if let Some(k) = v.var(VarPath::controller_output(&format!("{}_{station}", h.column), 0)) {
            g[k] = flow;
        }
    }
    g
}

/// A starting point for variant `v` of `plant`: `x` by variable path, `v`'s own guess elsewhere.
pub(crate) fn mapped_guess(plant: &Plant, x: &[f64], v: &Plant) -> Vec<f64> {
    let mut g = v.initial_guess_at(&v.input_values());
    for (k, info) in v.vars().iter().enumerate() {
        if let Some(j) = plant.var(&info.path) {
            g[k] = x[j];
        }
    }
    g
}

/// Singular when the gains, rows and then columns scaled to a largest entry of 1 (so the units of
/// the qualities and flows do not count), have `σ_min/σ_max` below `√SINGULAR_RATIO` (≈ 3e-7: the
/// relative error of gains computed through a nearly singular Jacobian).
pub(super) fn is_singular(g: &Mat<f64>) -> bool {
    if !g.is_all_finite() {
        return true;
    }
    let mut e = g.clone();
    for i in 0..e.nrows() {
        let m = (0..e.ncols()).map(|j| e[(i, j)].abs()).fold(0.0, f64::max);
        (0..e.ncols()).for_each(|j| e[(i, j)] /= m);
    }
    for j in 0..e.ncols() {
        let m = (0..e.nrows()).map(|i| e[(i, j)].abs()).fold(0.0, f64::max);
        (0..e.nrows()).for_each(|i| e[(i, j)] /= m);
    }
    !e.is_all_finite()
        || svd(e.as_ref()).is_ok_and(|s| condition_number(&s.singular_values) > 1.0 / SINGULAR_RATIO.sqrt())
}

/// A configuration whose steady state is not determined (`why`: which variables move together):
/// singular, not ranked.
fn undetermined(name: &str, inputs: Vec<String>, why: &str) -> ColumnStructure {
    ColumnStructure {
        inputs,
        singular: true,
        verdict: format!("singular at steady state: the configuration leaves an inventory free; not ranked ({why})"),
        ..unjudged(name)
    }
}

/// A configuration whose steady state or gains failed for `why`: no measures, not ranked.
fn failed(name: &str, inputs: Vec<String>, why: String) -> ColumnStructure {
    ColumnStructure {
        inputs,
        verdict: "not judged: the configuration failed; not ranked".into(),
        failure: Some(why),
        ..unjudged(name)
    }
}

/// The measures of gains `g` (`None`: singular).
fn measures(name: &str, inputs: Vec<String>, g: Option<Mat<f64>>) -> Result<ColumnStructure, ScreenError> {
    let analysis = |e| ScreenError::Analysis { structure: name.into(), source: Box::new(e) };
    let Some(g) = g.filter(|g| !is_singular(g)) else {
        return Ok(ColumnStructure {
            inputs,
            singular: true,
            verdict: "singular at steady state: the two inputs cannot set both qualities (for DB, D + B = F ties \
                      the products); not ranked"
                .into(),
            ..unjudged(name)
        });
    };
    let l = rga(g.as_ref()).map_err(analysis)?;
    let ni = niederlinski(g.as_ref(), &[0, 1]).map_err(analysis)?;
    let min_cond = minimized_condition_number(g.as_ref()).map_err(analysis)?;
    // The pairing the verdict recommends: the diagonal one unless its relative gain is below 0.5.
    let l11 = l[(0, 0)];
    let (pairing, relative_gain) = match l11 >= 0.5 {
        true => (vec![inputs[0].clone(), inputs[1].clone()], l11),
        false => (vec![inputs[1].clone(), inputs[0].clone()], 1.0 - l11),
    };
    Ok(ColumnStructure {
        inputs,
        gain: Some(rows(g.as_ref())),
        rga: Some(rows(l.as_ref())),
        niederlinski: Some(ni),
        minimized_condition_number: Some(min_cond),
        pairing: Some(pairing),
        relative_gain: Some(relative_gain),
        ..unjudged(name)
    })
}

/// A configuration with nothing measured yet.
fn unjudged(name: &str) -> ColumnStructure {
    ColumnStructure {
        name: name.into(),
        inputs: Vec::new(),
        gain: None,
        scaled_gain: None,
        input_scales: None,
        rga: None,
        niederlinski: None,
        condition_number: None,
        minimized_condition_number: None,
        singular: false,
        pairing: None,
        relative_gain: None,
        steady_rank: None,
        dynamic: None,
        iae_scaled: None,
        rank: None,
        verdict: String::new(),
        failure: None,
        lost: None,
        flowsheet: None,
    }
}
