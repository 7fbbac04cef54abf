//! A verification run: the plant from a steady state through the disturbance, its level and
//! outflow sampled through a [`Session`], until settled.
//!
//! Sampling: the first sample `10⁻⁵ T` after the step (`T` the run's time: a design's P filter
//! time, PI `1/ω_n` or optimal ramp time), each interval 1.1 times the last up to `T/200` (and
//! 1/200 of a ramp's duration or a sinusoid's period) over the run's minimum length, the *window*
//! (12 `T` for P, 14 `T` for PI, 25 `T` for the optimal law). The largest outflow rate is the
//! largest difference quotient between samples; after a step it sits in the first interval, where
//! the quotient is short of the slope at `t = 0⁺` by about `10⁻⁵/2`. Beyond the window the
//! controller's own response has died out (`e^−12`) and what still moves is the rest of the
//! plant, slower than the time already run: an interval may then grow to 1/200 of the time since
//! the window, so a run of hundreds of the plant's time constants costs a few thousand samples.
//!
//! Settled: the level and the outflow both within 10⁻³ of their way to the steady state the plant
//! (with the design) has after the disturbance — the level of the band, the outflow of its steady
//! change. Those end values come from a steady state, not from the run, so a run cannot stop on a
//! slow drift; it may go on to the longer of 8 windows and the window plus 12 of the plant's
//! slowest time constants (a mode `C e^{−t/τ}` is within 10⁻³ after `τ ln(10³ C)`, 12 τ for `C`
//! up to 160), then it is reported not settled with how far it still was.

use plantwide_flowsheet::{Plant, VarPath};
use plantwide_solve::dynamic::Session;

use super::{Shape, SizeCriteria, SizeError, Trace};

/// Most samples of a verification run's window (the window's sampling coarsens beyond it, so that
/// no request makes a run record without bound).
const MAX_SAMPLES: f64 = 2e5;

/// Most periods of a sinusoidal disturbance a verification run follows (each costs tens of
/// integrator steps).
const MAX_PERIODS: f64 = 2000.0;

/// Settled: within this fraction of the band (level) and of the steady change (outflow).
const SETTLED: f64 = 1e-3;

/// How a run ended.
pub(super) enum Ending {
    /// Settled (or at the exact length asked).
    Settled,
    /// At its longest, not settled: how far it still was.
    Unsettled(String),
    /// The integrator stopped: the plant with this design cannot be run on (a limit, a vessel run
    /// dry, an unstable loop).
    Failed(String),
}

/// A verification run's plant, what it watches and how long it may last.
pub(super) struct Run<'a> {
    pub plant: &'a Plant,
    /// The steady state it starts from.
    pub x: &'a [f64],
    /// The level measurement and the recorded outflow (variable indices).
    pub pv: usize,
    pub op: usize,
    /// The level's and the outflow's steady values after the disturbance; none for a run of
    /// exactly `t_min` (a sinusoid).
    pub end: Option<(f64, f64)>,
    /// What settling is measured against: the band (in the measurement's units) and the outflow's
    /// steady change.
    pub scale: (f64, f64),
    /// The run's time `T` \[s\].
    pub t_char: f64,
    /// The window and the longest run \[s\].
    pub t_min: f64,
    pub t_max: f64,
    /// What is run (for errors).
    pub what: &'a str,
}

impl Run<'_> {
    /// Step the disturbance and sample until settled (or to exactly `t_min`). Returns the record
    /// (level as deviation from its start, in the measurement's units) and how the run ended.
    ///
    /// # Errors
    /// [`SizeError::Disturbance`] for a sinusoid too fast to follow over the run.
    pub fn step(&self, r: &SizeCriteria) -> Result<(Trace, Ending), SizeError> {
        let d = &r.disturbance;
        let i = plantwide_flowsheet::overrides::resolve_input(self.plant, &d.path)
            .ok_or_else(|| SizeError::Disturbance { path: d.path.clone(), why: "no such input".into() })?;
        let (t_min, end) = match d.shape {
            Shape::Sine { period } => (self.sine_length(r, period)?, None),
            _ => (self.t_min, self.end),
        };
        let t_max = if end.is_some() { self.t_max.max(t_min) } else { t_min };
        let (y0, op0) = (self.x[self.pv], self.x[self.op]);
        let mut tr = Trace { times: vec![0.0], deviation: vec![0.0], outflow: vec![op0] };
        let settings = plantwide_solve::dae::BdfSettings { rtol: 1e-7, ..Default::default() };
        let mut s = match Session::with_settings(self.plant, self.x, settings) {
            Ok(s) => s,
            Err(e) => return Ok((tr, Ending::Failed(e.to_string()))),
        };
        s.set_waveform(i, d.shape.wave(self.plant.inputs()[i].value, d.change));
        let (base, window) = self.sampling(d.shape, t_min);
        let (mut t, mut dt) = (0.0, 1e-5 * self.t_char.min(base * 200.0));
        loop {
            let grown = if end.is_some() && t > window { base.max((t - window) / 200.0) } else { base };
            dt = (1.1 * dt).min(grown);
            t = (t + dt).min(t_max);
            if let Err(e) = s.advance_to(t) {
                let limits = at_limits(self.plant, s.state());
                let why = if limits.is_empty() { e.to_string() } else { format!("{e} (at a limit then: {limits})") };
                return Ok((tr, Ending::Failed(why)));
            }
            let (y, op) = (s.state()[self.pv] - y0, s.state()[self.op]);
            tr.times.push(t);
            tr.deviation.push(y);
            tr.outflow.push(op);
            let Some((y_end, op_end)) = end else {
                if t >= t_min {
                    return Ok((tr, Ending::Settled));
                }
                continue;
            };
            let off = ((y - (y_end - y0)).abs() / self.scale.0, (op - op_end).abs() / self.scale.1);
            if t >= t_min && off.0 <= SETTLED && off.1 <= SETTLED {
                return Ok((tr, Ending::Settled));
            }
            if t >= t_max {
                let asked = r.duration.map_or(String::new(), |_| {
                    "; the run's length was asked (`duration`): its peaks are not known before it settles, so \
                     give a longer one, or none to run until settled"
                        .to_string()
                });
                let why = format!(
                    "not settled after {t:.0} s: the level is still {:.2e} of the band and the outflow {:.2e} of its \
                     steady change from the steady state after the disturbance (settled: both within {SETTLED:e}){asked}",
                    off.0, off.1
                );
                return Ok((tr, Ending::Unsettled(why)));
            }
        }
    }

    /// A sinusoid does not settle: it runs its fixed length (at least 10 periods), and the
    /// integrator follows every period of it, so the work is bounded by refusing more than
    /// [`MAX_PERIODS`] of them.
    fn sine_length(&self, r: &SizeCriteria, period: f64) -> Result<f64, SizeError> {
        let duration = self.t_min;
        if duration / period > MAX_PERIODS {
            return Err(SizeError::Disturbance {
                path: r.disturbance.path.clone(),
                why: format!(
                    "a sinusoid of period {period:e} s would need {:.3e} periods to show the periodic steady state \
                     of {} ({duration:.4e} s, its settling time); at most {MAX_PERIODS} are simulated: a disturbance \
                     this fast is filtered by the vessel itself — give a period of at least {:.4e} s",
                    duration / period,
                    self.what,
                    duration / MAX_PERIODS
                ),
            });
        }
        Ok(duration.max(10.0 * period))
    }

    /// The largest sampling interval over the window, and the window: `T/200` (and 1/200 of a
    /// ramp's duration or a sinusoid's period), but at most [`MAX_SAMPLES`] over the window, which
    /// is the run's minimum or the ramp, whichever is longer.
    fn sampling(&self, shape: Shape, t_min: f64) -> (f64, f64) {
        let (base, window) = match shape {
            Shape::Sine { period } => ((self.t_char / 200.0).min(period / 200.0), t_min),
            Shape::Ramp { duration: ramp } => ((self.t_char / 200.0).min(ramp / 200.0), t_min.max(ramp)),
            Shape::Step => (self.t_char / 200.0, t_min),
        };
        (base.max(window / MAX_SAMPLES), window)
    }
}

/// The PID controllers whose output sits on one of its limits at state `x`, as `name at op_min
/// (value SI)`: what a run that stopped had run out of.
fn at_limits(plant: &Plant, x: &[f64]) -> String {
    near_limits(plant, x, 0.0)
}

/// The PID controllers whose output at state `x` is within `within` of its range (`op_max −
/// op_min`, else the limit's magnitude) of a limit: `name at op_min (value SI)`, or with
/// `within > 0` `name within 0.4 % of op_max (value SI)`.
pub(super) fn near_limits(plant: &Plant, x: &[f64], within: f64) -> String {
    use plantwide_model::ControllerSpec;
    let mut out = Vec::new();
    for (name, c) in &plant.spec().controllers {
        let (ControllerSpec::Pid(cfg), Some(op)) = (c, plant.var(VarPath::controller_output(name, 0))) else {
            continue;
        };
        let dim = plant.vars()[op].spec.dim;
        let si = |l: &Option<plantwide_units::QuantityValue>| l.as_ref().and_then(|l| l.to_si(dim).ok());
        let (lo, hi) = (si(&cfg.op_min), si(&cfg.op_max));
        for (which, limit) in [("op_min", lo), ("op_max", hi)] {
            let Some(l) = limit else { continue };
            let span = match (lo, hi) {
                (Some(lo), Some(hi)) if hi > lo => hi - lo,
                _ => l.abs().max(1e-12),
            };
            let off = (x[op] - l).abs();
            if off <= 1e-9 * l.abs().max(1e-12) {
                out.push(format!("`{name}` at {which} ({l:.6e})"));
            } else if off <= within * span {
                out.push(format!("`{name}` within {:.2} % of {which} ({l:.6e})", 100.0 * off / span));
            }
        }
    }
    out.join(", ")
}

/// The largest `|deviation|` and the largest `|Δoutflow/Δt|` of a record.
pub(super) fn peaks(tr: &Trace) -> (f64, f64) {
    let dev = tr.deviation.iter().map(|d| d.abs()).fold(0.0, f64::max);
    let rate = tr
        .times
        .windows(2)
        .zip(tr.outflow.windows(2))
        .map(|(t, q)| (q[1] - q[0]).abs() / (t[1] - t[0]))
        .fold(0.0, f64::max);
    (dev, rate)
}

/// Half the peak-to-peak swing of the level and of the outflow over the record's last `window` s.
pub(super) fn swings(tr: &Trace, window: f64) -> (f64, f64) {
    let end = tr.times.last().copied().unwrap_or(0.0);
    let from = tr.times.partition_point(|&t| t < end - window);
    let half = |v: &[f64]| {
        let (lo, hi) = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        0.5 * (hi - lo)
    };
    (half(&tr.deviation[from..]), half(&tr.outflow[from..]))
}
