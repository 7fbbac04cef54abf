//! The steady states a sizing needs beyond the file's: a design's (its area and level controller
//! written into the plant), and the plant's after the disturbance; and the plant's slowest time
//! constant, which bounds how long a verification run may take to settle.
//!
//! A design can move a plant's steady state far: a reactor's cross-section is also its volume at
//! the setpoint, so inside a recycle a smaller reactor moves every recycle flow and composition
//! (the two-column plant's reactor sized from 4 m² to 0.6 m²); a column's drum run at a larger
//! normal holdup changes its stage. Newton from the file's steady state mapped onto the design
//! then stalls where the design's steady state exists. So when that first attempt fails, the
//! design is reached by continuation from the file's vessel: the design's controller at the
//! file's size first (the file's steady state, the bias at its outflow), then the size in steps —
//! the area geometrically, the normal holdup by the setpoint — each Newton started from the last
//! steady state, a step halved where Newton fails, down to 1/512 of the way. Where no step goes
//! on, the design has no steady state near the file's and the error says how far it got.

use plantwide_analysis::continuation::{Steps, reach};
use plantwide_analysis::linear::Linearization;
use plantwide_flowsheet::{Plant, StructureEdit, VarPath};
use plantwide_solve::SteadyError;

use super::run::near_limits;
use super::vessel::{Kind, Vessel};
use super::{SizeCriteria, SizeError, Stall, newton};
use crate::screen::column::mapped_guess;

/// The smallest continuation step, as a fraction of the way from the file's size to the design's.
const MIN_STEP: f64 = 1.0 / 512.0;

/// Where continuation stops, the loops whose output is within this fraction of its range of a
/// limit are named (a loop about to saturate is the usual end of a steady state).
const LIMIT_NOTE: f64 = 0.05;

/// The plant with the design — the vessel's `area`, its level controller replaced by `law` under
/// its own name — and its steady state; a column's drum or base at its `normal` holdup.
///
/// # Errors
/// [`SizeError::Structure`] when the design cannot be written into the flowsheet;
/// [`SizeError::Continuation`] when no steady state is found on the way to the design's.
pub(super) fn design_steady(
    v: &Vessel,
    law: &plantwide_model::ControllerSpec,
    area: f64,
    normal: Option<f64>,
    what: &str,
) -> Result<(Plant, Vec<f64>), SizeError> {
    let build = |area: f64| -> Result<Plant, SizeError> {
        let mut edits: Vec<StructureEdit> = v.size_edit(area).into_iter().collect();
        edits.push(StructureEdit::RemoveController(v.controller.clone()));
        edits.push(StructureEdit::AddController { name: v.controller.clone(), spec: Box::new(law.clone()) });
        v.plant.restructure(&edits).map_err(|source| SizeError::Structure { what: what.to_string(), source })
    };
    let plant = build(area)?;
    let mut guess = mapped_guess(&v.plant, &v.x, &plant);
    if let Some(n) = normal {
        scale_holdup(&plant, &mut guess, &v.measurement, n / v.x[v.pv]);
    }
    let first = match newton(&plant, &guess) {
        Ok(x) => return Ok((plant, x)),
        Err(e) => e,
    };
    match (&v.kind, normal) {
        (Kind::Area { area: a0, unit, .. }, _) => {
            let reacts = v.plant.block_index(unit).is_some_and(|b| v.plant.blocks()[b].unit.reacts());
            let why = match (reacts, area < *a0) {
                (false, _) => String::new(),
                (true, smaller) => reactor_why(v, *a0, area, normal, smaller),
            };
            let path = Path {
                at: &|s: f64| build(a0 * (area / a0).powf(s)),
                size: &|s: f64| format!("area {} m²", sig(a0 * (area / a0).powf(s))),
                why: &why,
            };
            continuation(v, &path, what, first)
        }
        (Kind::Holdup { .. }, Some(n)) => {
            let Some(sp) = plant.input(VarPath::setpoint(&v.controller)) else {
                return Err(SizeError::Steady { what: what.to_string(), source: Box::new(first) });
            };
            let at = |s: f64| -> Result<Plant, SizeError> {
                let mut p = plant.clone();
                p.set_input_value(sp, v.sp + s * (n - v.sp));
                Ok(p)
            };
            let path =
                Path { at: &at, size: &|s: f64| format!("normal holdup {} mol", sig(v.sp + s * (n - v.sp))), why: "" };
            continuation(v, &path, what, first)
        }
        _ => Err(SizeError::Steady { what: what.to_string(), source: Box::new(first) }),
    }
}

/// A way from the file's vessel (`s = 0`) to the design's (`s = 1`).
struct Path<'a> {
    /// The plant at `s`.
    at: &'a dyn Fn(f64) -> Result<Plant, SizeError>,
    /// The size `s` stands for, for messages (`area 1.2 m²`).
    size: &'a dyn Fn(f64) -> String,
    /// What a failure means for this vessel (a clause beginning with `; `, or empty).
    why: &'a str,
}

/// The steady state at the end of `path`, each step's Newton started from the last steady state,
/// a step halved where Newton fails (`first`: the direct attempt's failure, reported when the
/// design's controller has no steady state even at the file's size).
fn continuation(v: &Vessel, path: &Path<'_>, what: &str, first: SteadyError) -> Result<(Plant, Vec<f64>), SizeError> {
    let here = (path.at)(0.0)?;
    let x = newton(&here, &mapped_guess(&v.plant, &v.x, &here))
        .map_err(|_| SizeError::Steady { what: what.to_string(), source: Box::new(first) })?;
    let advance = |(here, x): &(Plant, Vec<f64>), _: f64, next: f64| -> Result<(Plant, Vec<f64>), Step> {
        let p = (path.at)(next).map_err(Step::Unbuilt)?;
        let xn = newton(&p, &mapped_guess(here, x, &p)).map_err(Step::Newton)?;
        Ok((p, xn))
    };
    let steps = Steps { first: 0.25, largest: 0.5, smallest: MIN_STEP };
    reach((here, x), (0.0, 1.0), steps, advance).map_err(|stalled| {
        let source = match stalled.error {
            Step::Unbuilt(e) => return e,
            Step::Newton(e) => e,
        };
        let (here, x) = &stalled.state;
        let near = near_limits(here, x, LIMIT_NOTE);
        let stall = Stall {
            from: (path.size)(0.0),
            to: (path.size)(1.0),
            reached: (path.size)(stalled.reached),
            next: (path.size)(stalled.tried),
            reason: short(&source),
            limits: if near.is_empty() {
                String::new()
            } else {
                format!("; at {}: {near}", (path.size)(stalled.reached))
            },
            why: path.why.to_string(),
        };
        SizeError::Continuation { what: what.to_string(), stall: Box::new(stall), source: Box::new(source) }
    })
}

/// Why a step of the size continuation failed: the plant could not be built at the size, or
/// Newton found no steady state there.
enum Step {
    Unbuilt(SizeError),
    Newton(SteadyError),
}

/// The steady state of `plant` (at `x`) after the disturbance's full change, by Newton from `x`;
/// where Newton does not reach it, the input is moved in steps, halved down to 1/64 of the change.
///
/// # Errors
/// [`SizeError::Steady`] when no steady state is found.
pub(super) fn after(plant: &Plant, x: &[f64], r: &SizeCriteria, what: &str) -> Result<Vec<f64>, SizeError> {
    let d = &r.disturbance;
    let i = plantwide_flowsheet::overrides::resolve_input(plant, &d.path)
        .ok_or_else(|| SizeError::Disturbance { path: d.path.clone(), why: "no such input".into() })?;
    let u0 = plant.inputs()[i].value;
    let mut p = plant.clone();
    let advance = |x: &Vec<f64>, _: f64, next: f64| {
        p.set_input_value(i, u0 + next * d.change);
        newton(&p, x)
    };
    reach(x.to_vec(), (0.0, 1.0), Steps::halving(1.0, 6), advance)
        .map_err(|stalled| SizeError::Steady { what: what.to_string(), source: Box::new(stalled.error) })
}

/// The slowest time constant \[s\] of `plant` at its steady state `x`, from its exact
/// linearization (none when it has no stable mode or cannot be linearized).
pub(super) fn slowest(plant: &Plant, x: &[f64]) -> Option<f64> {
    let ss = Linearization::new(plant, x, &plant.input_values()).state_space(&[], &[]).ok()?;
    ss.time_constants().ok()?.into_iter().filter(|t| t.is_finite() && *t > 0.0).reduce(f64::max)
}

/// The guess of a column stage's holdup (`COL.M[k]` and its `COL.n[k][c]`) scaled by `factor`:
/// a drum or base run at a larger normal holdup starts from its compositions at the new holdup.
fn scale_holdup(plant: &Plant, guess: &mut [f64], measurement: &str, factor: f64) {
    let Some(stage) = measurement.strip_suffix(']').and_then(|m| m.split_once(".M[")) else { return };
    let parts = VarPath::new(stage.0, "n").index(stage.1);
    for (k, info) in plant.vars().iter().enumerate() {
        if info.path == measurement || parts.has_element(&info.path) {
            guess[k] *= factor;
        }
    }
}

/// Why a reactor's design (cross-section `area`, level setpoint `normal`; the file's `a0`) may
/// have no steady state: its volume is its conversion.
fn reactor_why(v: &Vessel, a0: f64, area: f64, normal: Option<f64>, smaller: bool) -> String {
    let (file, held) = (a0 * v.sp, area * normal.unwrap_or(v.sp));
    let how = if smaller { "small" } else { "large" };
    if held > file * (1.0 + 1e-9) {
        format!(
            "; a reactor's volume is also its conversion: this design's band needs a level setpoint of twice the \
             band, so it holds {held:.4} m³ against the file's {file:.4} m³, and no steady state was found with a \
             reactor this {how} — size surge elsewhere (`candidates`) or allow a narrower band"
        )
    } else {
        format!(
            "; the reactor's liquid volume was kept at the file's ({file:.4} m³, its level setpoint moved with its \
             area), yet no steady state was found with a reactor this {how} — size surge elsewhere (`candidates`)"
        )
    }
}

/// A failed steady state in short: how Newton ended and where (the full report, with its history,
/// stays the error's source).
fn short(e: &SteadyError) -> String {
    match e {
        SteadyError::NotConverged(f) => format!(
            "newton {} after {} iterations at a scaled residual of {:.3e}, worst in {} (variable {})",
            format!("{:?}", f.status).to_lowercase(),
            f.iterations,
            f.residual,
            f.equation,
            f.variable
        ),
        other => other.to_string(),
    }
}

/// Four significant digits (`0.6123`, `1234`, `1.235e-5`).
fn sig(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    if v.abs() < 1e-3 || v.abs() >= 1e6 {
        return format!("{v:.3e}");
    }
    let digits = (3 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}
