//! The designs written into the plant and verified by nonlinear dynamic runs.
//!
//! A run starts at the design's checked steady state, steps the disturbance at `t = 0` and samples
//! the level and the outflow through a [`Session`]: the first sample `10⁻⁵ T` after the step (`T`
//! the design's time: P filter time, PI `1/ω_n`, optimal ramp time), each interval 1.1 times the
//! last up to `T/200`. The largest outflow rate is the largest difference quotient between
//! samples; after a step it sits in the first interval, where the quotient is short of the slope
//! at `t = 0⁺` by about `10⁻⁵/2`. The run lasts at least its minimum (12 `T` for P, 14 `T` for PI,
//! 25 `T` for the optimal law: the level within 10⁻⁴ of its end) and goes on until the outflow is
//! within 10⁻³ of its new steady value and the level still, up to 8 times that minimum. The
//! integrator runs at `rtol` 10⁻⁷, ten times tighter than a scenario's default: the verdicts are
//! judged to [`VERIFY_TOLERANCE`] = 10⁻³ of the limits, and the default's error near a band edge
//! was seen to reach that (the two-column plant's tank between the columns: 0.2996 m at 10⁻⁶,
//! 0.3042 m at 10⁻⁷ for a 0.3 m band).

use plantwide_flowsheet::{Plant, StructureEdit};
use plantwide_solve::dynamic::Session;

use super::vessel::{Kind, Vessel};
use super::{
    Current, Design, LevelDesign, Shape, SizeError, SizeRequest, Trace, VERIFY_TOLERANCE, Verified, steady_at,
};
use crate::tune::averaging::{AveragingForm, averaging};

/// Most samples of one verification run (the sampling coarsens beyond it, so that no request makes a
/// run record without bound).
const MAX_SAMPLES: f64 = 2e5;

/// Most periods of a sinusoidal disturbance a verification run follows (each costs tens of
/// integrator steps).
const MAX_PERIODS: f64 = 2000.0;

/// Most corrections of a closed-form design that the plant's run showed short.
pub const MAX_REFINEMENTS: usize = 8;

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
/// too.
pub(super) fn design(v: &Vessel, d: LevelDesign, du: f64, r: &SizeRequest) -> Result<Design, SizeError> {
    let closed = closed_form(v, d, du.abs(), r).0;
    let (mut s, mut f, mut plan, mut previous) = (1.0, 1.0, 1.0, f64::INFINITY);
    for k in 0..=MAX_REFINEMENTS {
        let (area, time) = closed_form(v, d, s * du.abs(), r);
        let mut trial = attempt(v, d, du, Scales { flow: s, plan, time }, f * area, r)?;
        trial.closed_form_area = closed;
        trial.refinements = k;
        let t = &trial.verified;
        if t.meets || t.failure.is_some() || k == MAX_REFINEMENTS {
            return Ok(trial);
        }
        let level = (t.level_amplitude.unwrap_or(t.max_level_deviation) / r.level_band).max(1.0) * 1.002;
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
            _ => t.max_outflow_rate / r.max_outflow_rate,
        };
        let rate = (swing / level).max(1.0) * 1.002;
        (s, f) = (s * level, f * rate);
    }
    unreachable!("the loop returns at its last pass")
}

/// The closed-form cross-section of design `d` for the flow change `du` (a magnitude): by the
/// attenuation closed forms when the request has that criterion and the design has one (then with
/// the design's time, `τ_F` or `1/ω_n`), else by the rate closed form.
fn closed_form(v: &Vessel, d: LevelDesign, du: f64, r: &SizeRequest) -> (f64, Option<f64>) {
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

/// Design `d` for the flow change `s.flow·|du|` in a vessel of cross-section `area`, verified.
fn attempt(v: &Vessel, d: LevelDesign, du: f64, s: Scales, area: f64, r: &SizeRequest) -> Result<Design, SizeError> {
    let (band_y, k_y) = v.measurement_scale(area, r.level_band);
    let normal = matches!(v.kind, Kind::Holdup { .. }).then(|| v.sp.max(2.0 * band_y));
    let sp = serde_json::json!(normal.unwrap_or(v.sp));
    let du_design = s.flow * du.abs();
    // An attenuation design fixes the filter time instead of the band: the band the averaging rule
    // takes to give it (P: τ_F = Δ/(|k| Δu); PI: 1/ω_n = e Δ/(|k| Δu)).
    let law_band = match (s.time, d) {
        (Some(t), LevelDesign::P) => t * k_y * du_design,
        (Some(t), _) => t * k_y * du_design / std::f64::consts::E,
        (None, _) => band_y / s.plan,
    };
    let law = law(v, d, du_design, law_band, k_y, r.max_outflow_rate, sp)?;
    let mut edits: Vec<StructureEdit> = v.size_edit(area).into_iter().collect();
    edits.push(StructureEdit::RemoveController(v.controller.clone()));
    edits.push(StructureEdit::AddController { name: v.controller.clone(), spec: law.spec });
    let what = format!("the {} design of `{}`", d.name(), v.measurement);
    let plant = v.plant.restructure(&edits).map_err(|source| SizeError::Structure { what: what.clone(), source })?;
    let mut guess = crate::screen::column::mapped_guess(&v.plant, &v.x, &plant);
    if let Some(n) = normal {
        scale_holdup(&plant, &mut guess, &v.measurement, n / v.x[v.pv]);
    }
    let xs = steady_at(&plant, &guess, &format!("the steady state of {what}"))?;
    let index = |p: &str| {
        plant
            .var(p)
            .ok_or_else(|| SizeError::LevelLoop { vessel: v.measurement.clone(), why: format!("{what} has no `{p}`") })
    };
    let (pv, op) = (index(&v.measurement)?, index(&format!("{}.op", v.controller))?);
    let run = Run { plant: &plant, x: &xs, pv, op, t_char: law.time, t_min: law.minimum * law.time, what: &what };
    let duration = r.duration.unwrap_or(run.t_min);
    let (trace, ending) = run.step(r, du, band_y, duration, r.duration.is_some())?;
    let to_m = match v.kind {
        Kind::Area { .. } => 1.0,
        Kind::Holdup { .. } => v.v_l / area,
    };
    let trace = Trace { deviation: trace.deviation.iter().map(|y| y * to_m).collect(), ..trace };
    let verified = judge(trace, ending, r, du);
    Ok(Design {
        controller: d,
        area,
        closed_form_area: area,
        refinements: 0,
        design_flow_change: s.flow * du.abs(),
        planned_band: (s.plan != 1.0).then(|| r.level_band / s.plan),
        band_volume: area * r.level_band,
        kc: law.kc,
        tau_i: law.tau_i,
        capacity: law.capacity,
        ramp_time: law.ramp,
        return_time: law.ramp.map(|t| 4.0 * t),
        normal_holdup: normal,
        verified,
    })
}

/// The verdict on a run's record (level in m): the peaks, a sinusoid's periodic swings, and whether
/// it holds the request's limits — the band and the rate, or under an attenuation criterion the
/// band and the ratio in the periodic steady state.
fn judge(trace: Trace, ending: Ending, r: &SizeRequest, du: f64) -> Verified {
    let (dev, rate) = peaks(&trace);
    let failure = match ending {
        Ending::Settled => None,
        Ending::Unsettled => Some(format!("not settled after {:.0} s", trace.times.last().copied().unwrap_or(0.0))),
        Ending::Failed(why) => Some(why),
    };
    let (level_amplitude, attenuation) = match r.disturbance.shape {
        Shape::Sine { period } => {
            let (level, flow) = swings(&trace, 2.0 * period);
            (Some(level), Some(flow / du.abs()))
        }
        _ => (None, None),
    };
    let within = |v: f64, limit: f64| v <= limit * (1.0 + VERIFY_TOLERANCE);
    let holds = match (r.attenuation, level_amplitude, attenuation) {
        (Some(a), Some(level), Some(att)) => within(level, r.level_band) && within(att, a.ratio),
        _ => within(dev, r.level_band) && within(rate, r.max_outflow_rate),
    };
    let duration = trace.times.last().copied().unwrap_or(0.0);
    let meets = failure.is_none() && holds;
    Verified {
        max_level_deviation: dev,
        max_outflow_rate: rate,
        meets,
        duration,
        failure,
        level_amplitude,
        attenuation,
        trace,
    }
}

/// Half the peak-to-peak swing of the level and of the outflow over the record's last `window` s.
fn swings(tr: &Trace, window: f64) -> (f64, f64) {
    let end = tr.times.last().copied().unwrap_or(0.0);
    let from = tr.times.partition_point(|&t| t < end - window);
    let half = |v: &[f64]| {
        let (lo, hi) = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        0.5 * (hi - lo)
    };
    (half(&tr.deviation[from..]), half(&tr.outflow[from..]))
}

/// The guess of a column stage's holdup (`COL.M[k]` and its `COL.n[k][c]`) scaled by `factor`:
/// a drum or base run at a larger normal holdup starts from its compositions at the new holdup.
fn scale_holdup(plant: &Plant, guess: &mut [f64], measurement: &str, factor: f64) {
    let Some(stage) = measurement.strip_suffix(']').and_then(|m| m.split_once(".M[")) else { return };
    let parts = format!("{}.n[{}][", stage.0, stage.1);
    for (k, info) in plant.vars().iter().enumerate() {
        if info.path == measurement || info.path.starts_with(&parts) {
            guess[k] *= factor;
        }
    }
}

/// A design's controller description and settings.
struct Law {
    spec: serde_json::Value,
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
    sp: serde_json::Value,
) -> Result<Law, SizeError> {
    let c = &v.config;
    let form = match d {
        LevelDesign::P => AveragingForm::P,
        LevelDesign::Pi => AveragingForm::Pi,
        LevelDesign::Optimal => {
            let ramp = du / rate;
            let mut spec = serde_json::json!({
                "type": "averaging_level", "law": "optimal", "pv": c["pv"], "output": c["output"], "sp": sp,
                "level_band": band_y, "capacity": 1.0 / k_y, "return_time": 4.0 * ramp, "max_rate": rate,
                "filter": 1e-4 * ramp, "action": c["action"]});
            for limit in ["op_min", "op_max"] {
                if let Some(l) = c.get(limit) {
                    spec[limit] = l.clone();
                }
            }
            let capacity = Some(1.0 / k_y);
            return Ok(Law { spec, kc: None, tau_i: None, capacity, ramp: Some(ramp), time: ramp, minimum: 25.0 });
        }
    };
    let a = averaging(k_y, du, band_y, form)
        .map_err(|e| SizeError::LevelLoop { vessel: v.measurement.clone(), why: e.to_string() })?;
    let mut spec = c.clone();
    spec["type"] = "pid".into();
    spec["kc"] = a.kc.abs().into();
    spec["sp"] = sp;
    spec["bias"] = v.x[v.op].into();
    if let Some(o) = spec.as_object_mut() {
        o.remove("tau_d");
        o.remove("tau_i");
        o.remove("filter_ratio");
    }
    if let Some(ti) = a.tau_i {
        spec["tau_i"] = ti.into();
    }
    let minimum = if d == LevelDesign::P { 12.0 } else { 14.0 };
    Ok(Law { spec, kc: Some(a.kc.abs()), tau_i: a.tau_i, capacity: None, ramp: None, time: a.time, minimum })
}

/// How a run ended.
enum Ending {
    /// At its end, settled (or at the exact duration asked).
    Settled,
    /// At 8 times its minimum, not settled.
    Unsettled,
    /// The integrator stopped: the plant with this design cannot be run on (a limit, a vessel run
    /// dry, an unstable loop).
    Failed(String),
}

/// A verification run's plant and sampling.
struct Run<'a> {
    plant: &'a Plant,
    x: &'a [f64],
    /// The level measurement and the recorded outflow (variable indices).
    pv: usize,
    op: usize,
    t_char: f64,
    t_min: f64,
    /// What is run (for errors).
    what: &'a str,
}

impl Run<'_> {
    /// Step the disturbance and sample to `duration` (then, unless `exact`, on until settled: the
    /// outflow within 10⁻³ of its new steady value `x[op] + du` and the level still, to 8 times it).
    /// Returns the record (level as deviation from its start, in the measurement's units) and how
    /// the run ended.
    fn step(
        &self,
        r: &SizeRequest,
        du: f64,
        band_y: f64,
        duration: f64,
        exact: bool,
    ) -> Result<(Trace, Ending), SizeError> {
        let fail =
            |source| SizeError::Simulation { what: format!("the run of {}", self.what), source: Box::new(source) };
        let settings = plantwide_solve::dae::BdfSettings { rtol: 1e-7, ..Default::default() };
        let mut s = Session::with_settings(self.plant, self.x, settings).map_err(fail)?;
        let i = plantwide_flowsheet::overrides::resolve_input(self.plant, &r.disturbance.path)
            .ok_or_else(|| SizeError::Disturbance { path: r.disturbance.path.clone(), why: "no such input".into() })?;
        let d = &r.disturbance;
        s.set_waveform(i, d.shape.wave(self.plant.inputs()[i].value, d.change));
        // A sinusoid does not settle: it runs its fixed length (at least 10 periods), and the
        // integrator follows every period of it, so the work is bounded by refusing more than
        // MAX_PERIODS of them.
        let (duration, exact) = match d.shape {
            Shape::Sine { period } if duration / period > MAX_PERIODS => {
                return Err(SizeError::Disturbance {
                    path: d.path.clone(),
                    why: format!(
                        "a sinusoid of period {period:e} s would need {:.3e} periods to show the periodic steady \
                         state of {} ({duration:.4e} s, its settling time); at most {MAX_PERIODS} are simulated: a \
                         disturbance this fast is filtered by the vessel itself — give a period of at least {:.4e} s",
                        duration / period,
                        self.what,
                        duration / MAX_PERIODS
                    ),
                });
            }
            Shape::Sine { period } => (duration.max(10.0 * period), true),
            _ => (duration, exact),
        };
        let (y0, op_end) = (self.x[self.pv], self.x[self.op] + du);
        let mut tr = Trace { times: vec![0.0], deviation: vec![0.0], outflow: vec![self.x[self.op]] };
        let dt_max = match d.shape {
            Shape::Sine { period } => (self.t_char / 200.0).min(period / 200.0),
            Shape::Ramp { duration: ramp } => (self.t_char / 200.0).min(ramp / 200.0),
            Shape::Step => self.t_char / 200.0,
        };
        let t_max = if exact { duration } else { 8.0 * duration };
        // At most MAX_SAMPLES samples, whatever the duration, ramp or period asked.
        let dt_max = dt_max.max(t_max / MAX_SAMPLES);
        let (mut t, mut dt) = (0.0, 1e-5 * self.t_char.min(dt_max * 200.0));
        loop {
            dt = (1.1 * dt).min(dt_max);
            t = (t + dt).min(t_max);
            if let Err(e) = s.advance_to(t) {
                let limits = at_limits(self.plant, s.state());
                let why = if limits.is_empty() { e.to_string() } else { format!("{e} (at a limit then: {limits})") };
                return Ok((tr, Ending::Failed(why)));
            }
            let (y, op) = (s.state()[self.pv] - y0, s.state()[self.op]);
            let still = (y - tr.deviation[tr.deviation.len() - 1]).abs() <= 1e-4 * band_y;
            tr.times.push(t);
            tr.deviation.push(y);
            tr.outflow.push(op);
            let settled = (op - op_end).abs() <= 1e-3 * du.abs() && still;
            if (t >= duration && (exact || settled)) || t >= t_max {
                return Ok((tr, if exact || settled { Ending::Settled } else { Ending::Unsettled }));
            }
        }
    }
}

/// The PID controllers whose output sits on one of its limits at state `x`, as `name at op_min
/// (value SI)`: what a run that stopped had run out of.
fn at_limits(plant: &Plant, x: &[f64]) -> String {
    use plantwide_model::ControllerSpec;
    let mut out = Vec::new();
    for (name, c) in &plant.spec().controllers {
        let (ControllerSpec::Pid(cfg), Some(op)) = (c, plant.var(&format!("{name}.op"))) else { continue };
        let dim = plant.vars()[op].spec.dim;
        for (which, limit) in [("op_min", &cfg.op_min), ("op_max", &cfg.op_max)] {
            let Some(l) = limit.as_ref().and_then(|l| l.to_si(dim).ok()) else { continue };
            if (x[op] - l).abs() <= 1e-9 * l.abs().max(1e-12) {
                out.push(format!("`{name}` at {which} ({l:.6e})"));
            }
        }
    }
    out.join(", ")
}

/// The largest `|deviation|` and the largest `|Δoutflow/Δt|` of a record.
fn peaks(tr: &Trace) -> (f64, f64) {
    let dev = tr.deviation.iter().map(|d| d.abs()).fold(0.0, f64::max);
    let rate = tr
        .times
        .windows(2)
        .zip(tr.outflow.windows(2))
        .map(|(t, q)| (q[1] - q[0]).abs() / (t[1] - t[0]))
        .fold(0.0, f64::max);
    (dev, rate)
}

/// The file's own vessel and level controller (for a new tank: the stream without it) through the
/// disturbance, over `duration` (`du` the steady flow change, the inflow amplitude of a sinusoid).
pub(super) fn current(v: &Vessel, r: &SizeRequest, duration: f64, du: f64) -> Result<Current, SizeError> {
    let (plant, x) = (&v.original.0, &v.original.1);
    let (pv, op, area) = match &v.kind {
        Kind::Area { new_on: Some(stream), .. } => {
            let f = plant.var(&format!("{stream}.F")).unwrap_or(v.op);
            (f, f, None)
        }
        Kind::Area { area, .. } => (v.pv, v.op, Some(*area)),
        Kind::Holdup { .. } => (v.pv, v.op, None),
    };
    let what = format!("`{}` as the file has it", v.measurement);
    let run = Run { plant, x, pv, op, t_char: duration / 25.0, t_min: duration, what: &what };
    let (trace, ending) = run.step(r, 0.0, 1.0, run.t_min, true)?;
    let failure = match ending {
        Ending::Failed(why) => Some(why),
        _ => None,
    };
    let (dev, rate) = peaks(&trace);
    let new_tank = matches!(v.kind, Kind::Area { new_on: Some(_), .. });
    let max_deviation = (!new_tank).then_some(dev);
    let level_ok = !matches!(v.kind, Kind::Area { new_on: None, .. }) || dev <= r.level_band * (1.0 + VERIFY_TOLERANCE);
    let attenuation = match (r.attenuation, r.disturbance.shape) {
        (Some(_), Shape::Sine { period }) => Some(swings(&trace, 2.0 * period).1 / du.abs()),
        _ => None,
    };
    let swing_ok = match (r.attenuation, attenuation) {
        (Some(a), Some(att)) => att <= a.ratio * (1.0 + VERIFY_TOLERANCE),
        _ => rate <= r.max_outflow_rate * (1.0 + VERIFY_TOLERANCE),
    };
    let meets = failure.is_none() && level_ok && swing_ok;
    Ok(Current { area, max_deviation, max_outflow_rate: rate, meets, failure, attenuation, trace })
}
