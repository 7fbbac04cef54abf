//! The designs written into the plant ([`super::steady`]) and verified by nonlinear dynamic runs
//! ([`super::run`]): each design's run starts at its own steady state, steps the disturbance and
//! goes on until the level and the outflow have settled at the steady state the plant with the
//! design has after it. The integrator runs at `rtol` 10⁻⁷, ten times tighter than a scenario's
//! default: the verdicts are judged to [`VERIFY_TOLERANCE`](super::VERIFY_TOLERANCE) = 10⁻³ of the
//! limits, and the default's error near a band edge was seen to reach that (the two-column plant's
//! tank between the columns: 0.2996 m at 10⁻⁶, 0.3042 m at 10⁻⁷ for a 0.3 m band).
//!
//! A design whose steady state is not found, whose run stops or does not settle has no figures:
//! its `failure` says why, and the sizing lists it under `failed`.

use plantwide_flowsheet::{Plant, VarPath};

use super::run::{Ending, Run, peaks, swings};
use super::steady::{after, design_steady, slowest};
use super::vessel::{Kind, Vessel};
use super::{Current, Design, LevelDesign, Shape, SizeCriteria, SizeError, Trace, Verified, verdict};
use crate::tune::averaging::{AveragingForm, averaging};
use plantwide_model::ControllerSpec;
use plantwide_model::controllers::Setpoint;
use plantwide_model::controllers::averaging_level::{AveragingLaw, AveragingLevelConfig};
use plantwide_model::controllers::pid::PidConfig;
use plantwide_units::QuantityValue;

/// Most corrections of a closed-form design that the plant's run showed short.
pub const MAX_REFINEMENTS: usize = 8;

/// A run's longest: this many windows (its minimum length, see [`super::run`]) …
const WINDOWS: f64 = 8.0;
/// … or the window and this many of the plant's slowest time constants, if longer …
const SLOW_TIMES: f64 = 12.0;
/// … counting a time constant of at most this many windows (a slower mode is all but an
/// integrator: a run that waits for it is reported not settled rather than run without bound).
const MAX_SLOW: f64 = 1000.0;

/// One design of vessel `v` for the steady flow change `du` (signed), verified; refined when the
/// run exceeds a limit. The closed form takes the disturbance as a step of `du` at the vessel; in
/// a plant the vessel's inflow can overshoot its final change (interaction, recycle), which the
/// run shows as a level or rate past the limits. Then the design is redone for a larger flow
/// change `s·du` (gains and band scale with it: a level excess by `a` needs `s` larger by `a`) and
/// a larger area `f·A(s·du)` (the rate falls as `1/(s f)`: a rate excess `b` needs `f` larger by
/// `b/a`), each correction with 0.2 % to spare, until the run holds both or
/// [`MAX_REFINEMENTS`] corrections were made. The optimal law never exceeds its rate (its
/// `max_rate` is the limit); when an inflow that keeps rising after the law planned its ramp
/// carries the level past the band, the law is told a band smaller by the excess (it plans to stop
/// short of the edge); when that does not at least halve the excess (in log), the area grows by it
/// too. A design without figures (its steady state, its run) is returned as it is.
pub(super) fn design(v: &Vessel, d: LevelDesign, du: f64, r: &SizeCriteria) -> Result<Design, SizeError> {
    let closed = closed_form(v, d, du.abs(), r).0;
    let (mut s, mut f, mut plan, mut previous) = (1.0, 1.0, 1.0, f64::INFINITY);
    let mut k = 0;
    loop {
        let (area, time) = closed_form(v, d, s * du.abs(), r);
        let mut trial = attempt(v, d, du, Scales { flow: s, plan, time }, f * area, r)?;
        trial.closed_form_area = closed;
        trial.refinements = k;
        let t = &trial.verified;
        let (Some(dev), Some(rate)) = (t.max_level_deviation, t.max_outflow_rate) else { return Ok(trial) };
        if t.meets || k == MAX_REFINEMENTS {
            return Ok(trial);
        }
        k += 1;
        let level = (t.level_amplitude.unwrap_or(dev) / r.level_band).max(1.0) * 1.002;
        if d == LevelDesign::Optimal {
            // First the plan (the law overshooting its own target); when that did not at least
            // halve the excess in log, the capacity too (an inflow the capped rate cannot follow).
            if level > previous.sqrt() {
                f *= level;
            }
            (plan, previous) = (plan * level, level);
            continue;
        }
        let swing = match (r.attenuation, t.attenuation) {
            (Some(a), Some(got)) => got / a.ratio,
            _ => rate / r.max_outflow_rate,
        };
        let rate = (swing / level).max(1.0) * 1.002;
        (s, f) = (s * level, f * rate);
    }
}

/// The closed-form cross-section of design `d` for the flow change `du` (a magnitude): by the
/// attenuation closed forms when the request has that criterion and the design has one (then with
/// the design's time, `τ_F` or `1/ω_n`), else by the rate closed form.
fn closed_form(v: &Vessel, d: LevelDesign, du: f64, r: &SizeCriteria) -> (f64, Option<f64>) {
    let by_attenuation = r
        .attenuation
        .and_then(|a| d.for_attenuation(v.v_l * du, a.ratio, std::f64::consts::TAU / a.period, r.level_band));
    match by_attenuation {
        Some((area, time)) => (area, Some(time)),
        None => (d.area(v.v_l * du, v.v_l * r.max_outflow_rate, r.level_band), None),
    }
}

/// The corrections of a design: its flow change and (optimal law) its planned band, each a factor
/// on the closed form's; and the design time of an attenuation closed form.
#[derive(Debug, Clone, Copy)]
struct Scales {
    flow: f64,
    plan: f64,
    time: Option<f64>,
}

/// Design `d` for the flow change `s.flow·|du|` in a vessel of cross-section `area`, verified (a
/// numerical failure of its steady state or run is the design's `failure`).
fn attempt(v: &Vessel, d: LevelDesign, du: f64, s: Scales, area: f64, r: &SizeCriteria) -> Result<Design, SizeError> {
    let (band_y, k_y) = v.measurement_scale(area, r.level_band);
    // A column's drum or base runs at a normal holdup of at least twice the band; a reactor at the
    // level that keeps its liquid volume, and so its conversion, at the file's (a reactor shrunk at
    // the same level lost its conversion and the recycle plant its steady state: generated plants
    // 0x474959d22bbe512d, 0x63ab0744bc51a652, 0xf2c8f3ffd416849e), but at least twice the band
    // (a design too wide for the reactor's volume to fill then holds more, and converts more).
    let normal = match &v.kind {
        Kind::Holdup { .. } => Some(v.sp.max(2.0 * band_y)),
        Kind::Area { area: a0, .. } if v.reacts() => Some((v.sp * a0 / area).max(2.0 * band_y)),
        Kind::Area { .. } => None,
    };
    let sp = QuantityValue::Number(normal.unwrap_or(v.sp));
    let du_design = s.flow * du.abs();
    // An attenuation design fixes the filter time instead of the band: the band the averaging rule
    // takes to give it (P: τ_F = Δ/(|k| Δu); PI: 1/ω_n = e Δ/(|k| Δu)).
    let law_band = match (s.time, d) {
        (Some(t), LevelDesign::P) => t * k_y * du_design,
        (Some(t), _) => t * k_y * du_design / std::f64::consts::E,
        (None, _) => band_y / s.plan,
    };
    let law = law(v, d, du_design, law_band, k_y, r.max_outflow_rate, sp)?;
    let what = format!("the {} design of `{}`", d.name(), v.measurement);
    let verified = match verify(v, &law, (area, normal, band_y), du, r, &what) {
        Ok(verified) => verified,
        Err(e) if !e.is_user_error() => Verified::failed(e.to_string(), 0.0),
        Err(e) => return Err(e),
    };
    Ok(Design {
        controller: d,
        area,
        closed_form_area: area,
        refinements: 0,
        design_flow_change: du_design,
        planned_band: (s.plan != 1.0).then(|| r.level_band / s.plan),
        band_volume: area * r.level_band,
        kc: law.kc,
        tau_i: law.tau_i,
        capacity: law.capacity,
        ramp_time: law.ramp,
        return_time: law.ramp.map(|t| 4.0 * t),
        normal_holdup: normal.filter(|_| matches!(v.kind, Kind::Holdup { .. })),
        normal_level: normal.filter(|_| matches!(v.kind, Kind::Area { .. })),
        design_time: law.time,
        verified,
    })
}

/// The design (`law` at `area`, a column's drum or base at its `normal` holdup, `band_y` its band
/// in the measurement's units) written into the plant, its steady state, and its run through the
/// disturbance until settled at the steady state after it.
fn verify(
    v: &Vessel,
    law: &Law,
    (area, normal, band_y): (f64, Option<f64>, f64),
    du: f64,
    r: &SizeCriteria,
    what: &str,
) -> Result<Verified, SizeError> {
    let (plant, xs) = design_steady(v, &law.spec, area, normal, &format!("the steady state of {what}"))?;
    let index = |p: &str| {
        plant
            .var(p)
            .ok_or_else(|| SizeError::LevelLoop { vessel: v.measurement.clone(), why: format!("{what} has no `{p}`") })
    };
    let (pv, op) = (index(&v.measurement)?, index(VarPath::controller_output(&v.controller, 0).as_str())?);
    let t_min = r.duration.unwrap_or(law.minimum * law.time);
    let after_what = format!("the steady state of {what} after the disturbance");
    let Target { end, scale, t_max } = target(&plant, &xs, (pv, op), r, &after_what, (band_y, du, t_min))?;
    let run = Run { plant: &plant, x: &xs, pv, op, end, scale, t_char: law.time, t_min, t_max, what };
    let (trace, ending) = run.step(r)?;
    let to_m = match v.kind {
        Kind::Area { .. } => 1.0,
        Kind::Holdup { .. } => v.v_l / area,
    };
    let trace = Trace { deviation: trace.deviation.iter().map(|y| y * to_m).collect(), ..trace };
    let duration = trace.times.last().copied().unwrap_or(0.0);
    let failure = match ending {
        Ending::Settled => None,
        Ending::Unsettled(why) | Ending::Failed(why) => Some(why),
    };
    if let Some(why) = failure {
        return Ok(Verified { trace, ..Verified::failed(why, duration) });
    }
    let mut f = Figures::of(&trace, r, du);
    if law.ramp.is_some() {
        // The optimal law's output moves at most at its `max_rate`, the limit (a clamp in its
        // equation): a difference quotient above it is the integrator's error at the law's
        // switches (1.7e-3 above on generated plant 0xf38343b7fe0bb0c2, which refined the design
        // eight times on that noise where the same limits in other units stopped at two).
        f.rate = f.rate.min(r.max_outflow_rate);
    }
    let meets = verdict(false, &f.judged(r, Level::Shown)) == Some(true);
    Ok(Verified {
        max_level_deviation: Some(f.dev),
        max_outflow_rate: Some(f.rate),
        meets,
        duration,
        failure: None,
        level_amplitude: f.level_amplitude,
        attenuation: f.attenuation,
        trace,
    })
}

/// What a run settles to and how long it may take.
struct Target {
    /// The level's and the outflow's values at the steady state after the disturbance; none for a
    /// sinusoid's run of fixed length.
    end: Option<(f64, f64)>,
    /// The band (in the measurement's units) and the outflow's steady change (the request's
    /// `|du|` when it does not move) that settling is measured against.
    scale: (f64, f64),
    /// The longest run \[s\].
    t_max: f64,
}

/// The [`Target`] of a run on `plant` from its steady state `x`, watching the level `pv` and
/// the outflow `op`, with the band `band_y`, the request's flow change `du` and the window `t_min`.
fn target(
    plant: &Plant,
    x: &[f64],
    (pv, op): (usize, usize),
    r: &SizeCriteria,
    what: &str,
    (band_y, du, t_min): (f64, f64, f64),
) -> Result<Target, SizeError> {
    if matches!(r.disturbance.shape, Shape::Sine { .. }) {
        return Ok(Target { end: None, scale: (band_y, du.abs()), t_max: t_min });
    }
    let xe = after(plant, x, r, what)?;
    let change = (xe[op] - x[op]).abs();
    let moves = change > 1e-9 * x[op].abs().max(1e-12);
    Ok(Target {
        end: Some((xe[pv], xe[op])),
        scale: (band_y, if moves { change } else { du.abs() }),
        // A length asked is the run's: a run not settled by then has not shown its peaks.
        t_max: r.duration.unwrap_or_else(|| longest(plant, x, t_min)),
    })
}

/// The longest a run with window `t_min` may take to settle on `plant` (at `x`): see
/// [`WINDOWS`], [`SLOW_TIMES`], [`MAX_SLOW`].
fn longest(plant: &Plant, x: &[f64], t_min: f64) -> f64 {
    let slow = slowest(plant, x).map_or(0.0, |t| t.min(MAX_SLOW * t_min));
    (WINDOWS * t_min).max(t_min + SLOW_TIMES * slow)
}

/// Whether the vessel shows a level to judge against the band.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Level {
    /// A vessel's level, or a design's equivalent drum.
    Shown,
    /// The file's column drum or base: a holdup without geometry.
    NoGeometry,
    /// A stream (the plant without the new tank): no vessel, nothing to hold.
    NoVessel,
}

/// A settled run's figures: its peaks, a sinusoid's periodic swings.
struct Figures {
    dev: f64,
    rate: f64,
    level_amplitude: Option<f64>,
    attenuation: Option<f64>,
}

impl Figures {
    /// The figures of `trace` for the request (`du` the inflow amplitude of a sinusoid).
    fn of(trace: &Trace, r: &SizeCriteria, du: f64) -> Figures {
        let (dev, rate) = peaks(trace);
        let (level_amplitude, attenuation) = match r.disturbance.shape {
            Shape::Sine { period } => {
                let (level, flow) = swings(trace, 2.0 * period);
                (Some(level), Some(flow / du.abs()))
            }
            _ => (None, None),
        };
        Figures { dev, rate, level_amplitude, attenuation }
    }

    /// The figures [`verdict`] judges, each with its limit: the level's peak (under an attenuation
    /// criterion its periodic swing) against the band, where the vessel shows a level; the
    /// outflow's largest rate against the limit (under an attenuation criterion its swing against
    /// the ratio).
    fn judged(&self, r: &SizeCriteria, level: Level) -> Vec<(Option<f64>, f64)> {
        let (y, q) = match (r.attenuation, self.level_amplitude, self.attenuation) {
            (Some(a), Some(amplitude), Some(att)) => ((amplitude, r.level_band), (att, a.ratio)),
            _ => ((self.dev, r.level_band), (self.rate, r.max_outflow_rate)),
        };
        match level {
            Level::Shown => vec![(Some(y.0), y.1), (Some(q.0), q.1)],
            Level::NoGeometry => vec![(None, y.1), (Some(q.0), q.1)],
            Level::NoVessel => vec![(Some(q.0), q.1)],
        }
    }
}

/// A design's controller description and settings.
struct Law {
    spec: ControllerSpec,
    kc: Option<f64>,
    tau_i: Option<f64>,
    capacity: Option<f64>,
    ramp: Option<f64>,
    /// Its time `T` \[s\] and the minimum run in units of it.
    time: f64,
    minimum: f64,
}

/// The level controller of design `d`: a PID (P, critically damped PI) with its bias at the steady
/// outflow, or the optimal averaging law, with the file's measurement, output, action and limits.
fn law(
    v: &Vessel,
    d: LevelDesign,
    du: f64,
    band_y: f64,
    k_y: f64,
    rate: f64,
    sp: QuantityValue,
) -> Result<Law, SizeError> {
    let c = &v.config;
    let form = match d {
        LevelDesign::P => AveragingForm::P,
        LevelDesign::Pi => AveragingForm::Pi,
        LevelDesign::Optimal => {
            let ramp = du / rate;
            let n = QuantityValue::Number;
            let spec = ControllerSpec::AveragingLevel(AveragingLevelConfig {
                pv: c.pv.clone(),
                output: c.output.clone().unwrap_or_default(),
                sp,
                law: AveragingLaw::Optimal,
                level_band: n(band_y),
                capacity: Some(n(1.0 / k_y)),
                return_time: Some(n(4.0 * ramp)),
                max_rate: Some(n(rate)),
                filter: Some(n(1e-4 * ramp)),
                kc: None,
                tau_i: None,
                action: c.action,
                bias: None,
                op_min: c.op_min.clone(),
                op_max: c.op_max.clone(),
            });
            let capacity = Some(1.0 / k_y);
            return Ok(Law { spec, kc: None, tau_i: None, capacity, ramp: Some(ramp), time: ramp, minimum: 25.0 });
        }
    };
    let a = averaging(k_y, du, band_y, form)
        .map_err(|e| SizeError::LevelLoop { vessel: v.measurement.clone(), why: e.to_string() })?;
    let spec = ControllerSpec::Pid(PidConfig {
        kc: QuantityValue::Number(a.kc.abs()),
        sp: Setpoint::Value(sp),
        bias: Some(QuantityValue::Number(v.x[v.op])),
        tau_i: a.tau_i.map(QuantityValue::Number),
        tau_d: None,
        filter_ratio: None,
        ..c.clone()
    });
    let minimum = if d == LevelDesign::P { 12.0 } else { 14.0 };
    Ok(Law { spec, kc: Some(a.kc.abs()), tau_i: a.tau_i, capacity: None, ramp: None, time: a.time, minimum })
}

/// The file's own vessel and level controller (for a new tank: the stream without it) through the
/// disturbance (`du` the steady flow change, the inflow amplitude of a sinusoid), sampled at the
/// designs' fastest time, over at least the designs' longest run and until settled.
pub(super) fn current(v: &Vessel, r: &SizeCriteria, designs: &[Design], du: f64) -> Result<Current, SizeError> {
    let (plant, x) = (&v.original.0, &v.original.1);
    let fail = |why: String| SizeError::LevelLoop { vessel: v.measurement.clone(), why };
    let (pv, op, area, level, what) = match &v.kind {
        Kind::Area { new_on: Some(stream), .. } => {
            let f = plant
                .var(VarPath::new(stream, "F"))
                .ok_or_else(|| fail(format!("the stream `{stream}` has no flow")))?;
            (f, f, None, Level::NoVessel, format!("`{stream}` without a tank"))
        }
        Kind::Area { area, .. } => {
            (v.pv, v.op, Some(*area), Level::Shown, format!("`{}` as the file has it", v.measurement))
        }
        Kind::Holdup { .. } => (v.pv, v.op, None, Level::NoGeometry, format!("`{}` as the file has it", v.measurement)),
    };
    // Settling is judged on the level against the band where the vessel has one, on a column's
    // holdup against the smallest design's band in mol, on a bare stream against its change.
    let band_y = match level {
        Level::Shown => r.level_band,
        Level::NoGeometry => designs.iter().map(|d| d.area * r.level_band / v.v_l).fold(f64::INFINITY, f64::min),
        Level::NoVessel => du.abs(),
    };
    let t_char = designs.iter().map(|d| d.design_time).fold(f64::INFINITY, f64::min);
    let ran = designs.iter().filter(|d| d.verified.failure.is_none()).map(|d| d.verified.duration).fold(0.0, f64::max);
    let t_min = r.duration.unwrap_or(if ran > 0.0 { ran } else { 25.0 * t_char });
    let after_what = format!("the steady state of {what} after the disturbance");
    let Target { end, scale, t_max } = match target(plant, x, (pv, op), r, &after_what, (band_y, du, t_min)) {
        Ok(target) => target,
        Err(e) if !e.is_user_error() => return Ok(Current::failed(area, e.to_string(), 0.0)),
        Err(e) => return Err(e),
    };
    let run = Run { plant, x, pv, op, end, scale, t_char, t_min, t_max, what: &what };
    let (trace, ending) = run.step(r)?;
    let duration = trace.times.last().copied().unwrap_or(0.0);
    if let Ending::Failed(why) | Ending::Unsettled(why) = ending {
        return Ok(Current { trace, ..Current::failed(area, why, duration) });
    }
    let f = Figures::of(&trace, r, du);
    let meets = verdict(false, &f.judged(r, level));
    Ok(Current {
        area,
        max_deviation: (level == Level::Shown).then_some(f.dev),
        max_holdup_deviation: (level == Level::NoGeometry).then_some(f.dev),
        max_outflow_rate: Some(f.rate),
        meets,
        duration,
        failure: None,
        attenuation: if r.attenuation.is_some() { f.attenuation } else { None },
        outside: (level == Level::Shown).then(|| outside(v, &trace)).flatten(),
        trace,
    })
}

/// Where the file's vessel's level (setpoint `v.sp`, the record's deviations from it) went past
/// its top or below its bottom, if it did.
fn outside(v: &Vessel, trace: &Trace) -> Option<String> {
    let Kind::Area { height, .. } = &v.kind else { return None };
    let (lo, hi) = trace.deviation.iter().fold((0.0f64, 0.0f64), |(lo, hi), &d| (lo.min(d), hi.max(d)));
    match height {
        Some(h) if v.sp + hi > *h => Some(format!("its level reaches {:.4} m, above its top at {h} m", v.sp + hi)),
        _ if v.sp + lo < 0.0 => Some(format!("its level falls {:.4} m below its bottom", -(v.sp + lo))),
        _ => None,
    }
}

impl Current {
    /// The file's vessel without an answer: `why` it has none.
    fn failed(area: Option<f64>, why: String, duration: f64) -> Current {
        Current {
            area,
            max_deviation: None,
            max_holdup_deviation: None,
            max_outflow_rate: None,
            meets: verdict(true, &[]),
            duration,
            failure: Some(why),
            attenuation: None,
            outside: None,
            trace: Trace::default(),
        }
    }
}
