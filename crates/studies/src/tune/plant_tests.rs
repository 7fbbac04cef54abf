//! Relay and step tests of a flowsheet's loop on its nonlinear dynamic model, the other loops
//! as the file has them: the loop goes to manual at its steady state and its `op_manual` is moved
//! by the test ([`super::bench`]) through a [`Session`] of the plant.
//!
//! Defaults come from the loop's exact linear model at the steady state: the relay's scan is
//! `P_u/200` of the linear ultimate period (so that the scan's delay, ~`Δ/2`, moves `P_u` by about
//! 0.25 %), and a step test samples at `T/100` for up to `30 T`, `T` the element's mean residence
//! time `−g'(0)/g(0)` (for an integrating element, that of `s g(s)`), both read from `g(jω)` at a
//! frequency far below the element's dynamics.

use faer::c64;
use plantwide_flowsheet::Plant;
use plantwide_solve::dynamic::{Session, SessionError};
use serde::Serialize;

use super::bench::{Bench, RelayCycle, SampledRelay, StepTest, relay, step};
use super::fit::{ModelFit, ModelOrder, ProcessModel, StepResponse, assess, fit_step};
use super::loops::{LoopResponse, Measurement, PlantLoop, in_manual, loop_model, loop_ultimates, low_frequency_probe};
use super::room::{DEFAULT_ROOM_FRACTION, Room, room};
use crate::TuneError;

/// The plant with one loop in manual, run by a [`Session`], its measurement seen through the
/// transmitter the model leaves out: a dead time of whole scans (`round(θ_m/Δ)` samples old) and a
/// first-order lag updated exactly for a sample held over each step (`z += (1 − e^(−Δt/τ_m))(y − z)`).
struct PlantBench<'a> {
    session: Session,
    l: &'a PlantLoop,
    measurement: Measurement,
    scan: f64,
    /// Raw samples, oldest first, the dead time's worth of them.
    delayed: std::collections::VecDeque<f64>,
    /// The lag's output.
    seen: f64,
}

impl Bench for PlantBench<'_> {
    type Error = SessionError;
    fn time(&self) -> f64 {
        self.session.time()
    }
    fn measurement(&self) -> f64 {
        self.seen
    }
    fn set_output(&mut self, u: f64) {
        self.session.set_input(self.l.op_manual, u);
    }
    fn advance_to(&mut self, t: f64) -> Result<(), SessionError> {
        let dt = t - self.session.time();
        self.session.advance_to(t)?;
        self.delayed.push_back(self.session.state()[self.l.pv]);
        let steps = (self.measurement.dead_time / self.scan).round() as usize;
        while self.delayed.len() > steps + 1 {
            self.delayed.pop_front();
        }
        let y = self.delayed.front().copied().unwrap_or(self.seen);
        self.seen = if self.measurement.lag > 0.0 {
            self.seen + (1.0 - (-dt / self.measurement.lag).exp()) * (y - self.seen)
        } else {
            y
        };
        Ok(())
    }
}

fn bench<'a>(
    plant: &Plant,
    x: &[f64],
    l: &'a PlantLoop,
    measurement: Measurement,
    scan: f64,
) -> Result<PlantBench<'a>, TuneError> {
    let manual = in_manual(plant, x, std::slice::from_ref(l));
    let session = Session::new(&manual, x).map_err(|e| TuneError::Simulation(Box::new(e)))?;
    let y0 = x[l.pv];
    let steps = (measurement.dead_time / scan).round() as usize;
    Ok(PlantBench { session, l, measurement, scan, delayed: std::iter::repeat_n(y0, steps + 1).collect(), seen: y0 })
}

/// Options of a relay test; `None` takes the default.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RelayOptions {
    /// Relay amplitude (output units; default 5 % of the output's steady value, or less where that
    /// would take a flow past half its room: [`super::room`]).
    pub amplitude: Option<f64>,
    /// Hysteresis (measurement units; default 0).
    pub hysteresis: Option<f64>,
    /// Scan \[s\] (default `P_u/200` of the linear model).
    pub scan: Option<f64>,
    /// The measurement's dead time and lag that the model leaves out.
    pub measurement: Measurement,
}

/// A relay test of loop `l` at the steady state `x`.
///
/// # Errors
/// [`TuneError::NoPhaseCrossover`] when the linear model already shows that no cycle exists,
/// [`TuneError::Relay`] when the test finds none or the plant cannot be integrated.
pub fn relay_loop(plant: &Plant, x: &[f64], l: &PlantLoop, o: RelayOptions) -> Result<RelayCycle, TuneError> {
    let model = loop_model(plant, x, std::slice::from_ref(l))?;
    let gain_sign = model.ss.steady_gain().map(|g| g[(0, 0)].signum()).unwrap_or(1.0);
    let response = LoopResponse::new(model, o.measurement);
    let linear = loop_ultimates(&response, std::slice::from_ref(l))?[0];
    let u0 = x[l.op];
    if let Some(a) = o.amplitude {
        // The output's own range first: the plainer reason.
        within_range(plant, l, u0 + a)?;
        within_range(plant, l, u0 - a)?;
    }
    let room = room(plant, x, l);
    let (amplitude, limited_by) = move_within_room(plant, l, o.amplitude, 0.05 * u0.abs(), room.as_ref())?;
    let settings = SampledRelay {
        amplitude,
        hysteresis: o.hysteresis.unwrap_or(0.0),
        scan: o.scan.unwrap_or(linear.pu / 200.0),
        sign: if linear.ku.is_finite() { linear.ku.signum() } else { gain_sign },
        n_cycles: 3,
        tolerance: 1e-2,
        max_switches: 60,
        // Twenty times the ~100 scans of the half cycle the default scan (P_u/200) expects.
        max_quiet_scans: if o.scan.is_some() { 100_000 } else { 2000 },
    };
    if !(settings.amplitude.is_finite() && settings.amplitude > 0.0) {
        return Err(TuneError::RelayAmplitude { controller: l.name.clone(), amplitude: settings.amplitude });
    }
    check_scan(l, settings.scan, linear.pu, "the loop's linear ultimate period")?;
    within_range(plant, l, u0 + settings.amplitude)?;
    within_range(plant, l, u0 - settings.amplitude)?;
    let mut b = bench(plant, x, l, o.measurement, settings.scan)?;
    let mut cycle = relay(&mut b, u0, &settings)
        .map_err(|e| TuneError::Relay { controller: l.name.clone(), source: Box::new(e) })?;
    cycle.limited_by = limited_by;
    Ok(cycle)
}

/// The move a test makes of loop `l`'s output: the one asked for, refused when it takes a flow past its
/// bound at the new steady state ([`TuneError::BeyondRoom`]); else `default`,
/// shrunk to [`DEFAULT_ROOM_FRACTION`] of the room, with the path that shrank it.
fn move_within_room(
    plant: &Plant,
    l: &PlantLoop,
    asked: Option<f64>,
    default: f64,
    room: Option<&Room>,
) -> Result<(f64, Option<String>), TuneError> {
    match (asked, room) {
        (Some(a), Some(r)) if a.abs() > r.limit => Err(TuneError::BeyondRoom {
            controller: l.name.clone(),
            unit: plant.vars()[l.op].spec.dim.to_string(),
            amplitude: a.abs(),
            path: r.path.clone(),
            limit: r.limit,
        }),
        (Some(a), _) => Ok((a, None)),
        (None, Some(r)) if default > DEFAULT_ROOM_FRACTION * r.limit => {
            Ok((DEFAULT_ROOM_FRACTION * r.limit, Some(r.path.clone())))
        }
        (None, _) => Ok((default, None)),
    }
}

/// The least fraction of a step response's variance a fitted model must explain for settings to
/// be drawn from it (a FOPTD fit of a well-damped high-order response explains over 0.99).
pub const MIN_R2: f64 = 0.9;

/// Options of a step test; `None` takes the default.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepOptions {
    /// Output step (output units), the first one tried; default 5 % of its steady value, or less
    /// where the linear response would take over a tenth of the measurement's room to its bound, or
    /// a flow past half its room ([`super::room`]).
    pub step: Option<f64>,
    /// Sampling interval \[s\].
    pub scan: Option<f64>,
    /// Model to fit (default FOPTD, IPDT for an integrating element).
    pub order: Option<ModelOrder>,
    /// The measurement's dead time and lag that the model leaves out: with them the loop's
    /// ultimate period, the time scale a lag-dominant element's start is sampled at.
    pub measurement: Measurement,
}

/// Largest relative difference between the gain fitted to a step test and the element's gain
/// from the exact linearization for settings to be drawn from the fit: a step that moves the plant
/// out of its linear range fits the secant of a curved response, whose gain can be several times
/// off (plantwide's tolerance; SIMC's `kc` is inversely proportional to the gain).
pub const MAX_GAIN_ERROR: f64 = 0.1;

/// Most step tests of one loop: the step asked for and up to four smaller ones.
const MAX_STEP_TESTS: usize = 5;

/// One step test: the step, the gain fitted to it, and its relative difference from the
/// linearized gain.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StepTry {
    /// Output step (output units).
    pub step: f64,
    /// Fitted gain (for an integrating element per s, or per the time unit asked for).
    pub gain: f64,
    /// `|gain − linear_gain| / |linear_gain|`.
    pub gain_error: f64,
}

/// The check of a step test's fitted gain against the exact linearization.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Linearity {
    /// The element's gain from the exact linearization at the steady state: `G(0)`, or for an
    /// integrating element the slope `lim s→0 s G(s)` (per s, or per the time unit asked for).
    pub linear_gain: f64,
    /// The tests run, in order; the last is the one the fit comes from.
    pub tests: Vec<StepTry>,
}

impl Linearity {
    /// Times in a unit of `seconds` s: an integrating element's gains are per that unit.
    pub fn in_time_unit(mut self, seconds: f64, integrating: bool) -> Linearity {
        if integrating {
            self.linear_gain *= seconds;
            for t in &mut self.tests {
                t.gain *= seconds;
            }
        }
        self
    }
}

/// A step test of a loop whose fitted gain agrees with the linearization.
#[derive(Debug, Clone, PartialEq)]
pub struct StepResult {
    /// The model fitted to the last test.
    pub fit: ModelFit,
    /// Whether its response settled within the test (an integrating one always counts as settled).
    pub settled: bool,
    /// The tests run and the gain they were checked against; `None` when the model asked for is not
    /// of the element's kind (an integrating model of a lag-dominant element, SIMC's approximation,
    /// has a slope, not `G(0)`), so that one test is run with the step asked for, unchecked.
    pub linearity: Option<Linearity>,
    /// For a lag-dominant element, the integrating model fitted to the response's start, whose
    /// dead time the model `fit` takes (see [`LAG_DOMINANT`]).
    pub initial: Option<ModelFit>,
}

/// A step test of loop `l` at the steady state `x` and the model fitted to it. The fitted gain is
/// compared with the element's exact linearized gain; while they differ by more than
/// [`MAX_GAIN_ERROR`] the step is shrunk (by `MAX_GAIN_ERROR/(4 e)` for an error `e`, between 1/32
/// and 1/2, since a secant's error shrinks about in proportion to the step) and the test repeated.
///
/// # Errors
/// [`TuneError::Simulation`] when the plant cannot be integrated, [`TuneError::Fit`] when the
/// record determines no model, [`TuneError::OutsideLinearRange`] when no step tried gives the
/// linearized gain, [`TuneError::PoorFit`] when the model does not describe the response.
pub fn step_loop(plant: &Plant, x: &[f64], l: &PlantLoop, o: StepOptions) -> Result<StepResult, TuneError> {
    match step_loop_of(plant, x, l, o) {
        // The default first-order model not explaining the response (a composition behind two
        // lags: R² 0.885 on generated train 0xfca5508aa3d0ffeb): the test again for a second-order
        // model, which Skogestad's SIMC rules take too, when that one explains it.
        Err(poor @ TuneError::PoorFit { .. }) if o.order.is_none() => {
            step_loop_of(plant, x, l, StepOptions { order: Some(ModelOrder::Soptd), ..o }).or(Err(poor))
        }
        other => other,
    }
}

/// [`step_loop`] for the model order `o` asks (its default when none).
fn step_loop_of(plant: &Plant, x: &[f64], l: &PlantLoop, o: StepOptions) -> Result<StepResult, TuneError> {
    let (element, response) = element(plant, x, l)?;
    let order = o.order.unwrap_or(if element.integrating { ModelOrder::Integrating } else { ModelOrder::Foptd });
    let comparable = (order == ModelOrder::Integrating) == element.integrating;
    let u0 = x[l.op];
    // A pure integrator has no time of its own: the test then runs 500 scans of the scan given.
    let (scan, max_duration) = match (o.scan, element.residence_time) {
        (scan, Some(t)) => {
            let scan = scan.unwrap_or(t / 100.0);
            (scan, if element.integrating { (5.0 * t).max(500.0 * scan) } else { (30.0 * t).max(100.0 * scan) })
        }
        (Some(scan), None) => (scan, 500.0 * scan),
        (None, None) => return Err(TuneError::ResidenceTime { controller: l.name.clone() }),
    };
    check_scan(l, scan, max_duration / 100.0, "a hundredth of the test's length")?;
    let fine = match (o.scan, order) {
        (None, ModelOrder::Foptd) if !element.integrating => {
            lag_dominant_start(response.seen_through(o.measurement), l, scan)
        }
        _ => None,
    };
    if let Some(step) = o.step {
        within_range(plant, l, u0 + step)?;
    }
    let room = room(plant, x, l);
    let (first, _) = move_within_room(plant, l, o.step, default_step(plant, x, l, &element), room.as_ref())?;
    if !(first != 0.0 && first.is_finite()) {
        return Err(TuneError::RelayAmplitude { controller: l.name.clone(), amplitude: first });
    }
    within_range(plant, l, u0 + first)?;
    let mut settings = StepTest { step: first, scan, max_duration, settle: 2e-3, fine };
    let mut tests: Vec<StepTry> = Vec::new();
    loop {
        let mut b = bench(plant, x, l, Measurement::default(), settings.scan)?;
        let (record, settled) = step(&mut b, u0, &settings).map_err(|e| TuneError::Simulation(Box::new(e)))?;
        let (fit, initial) = fit_test(&record, order, settings.fine_samples())?;
        let gain = fit.model.gain();
        let gain_error = ((gain - element.gain) / element.gain).abs();
        tests.push(StepTry {
            step: settings.step,
            gain,
            gain_error: if gain_error.is_nan() { f64::INFINITY } else { gain_error },
        });
        if !comparable || gain_error <= MAX_GAIN_ERROR {
            if fit.r2.is_nan() || fit.r2 < MIN_R2 {
                return Err(TuneError::PoorFit {
                    controller: l.name.clone(),
                    model: order.name(),
                    r2: fit.r2,
                    min_r2: MIN_R2,
                    shape: settled.then(|| super::fit::lagless_shape(&record)).flatten(),
                });
            }
            let linearity = comparable.then_some(Linearity { linear_gain: element.gain, tests });
            return Ok(StepResult { fit, settled: settled || element.integrating, linearity, initial });
        }
        let stalled = tests.len() >= 2 && gain_error > 0.8 * tests[tests.len() - 2].gain_error;
        if stalled || tests.len() == MAX_STEP_TESTS {
            return Err(TuneError::OutsideLinearRange {
                controller: l.name.clone(),
                model: order.name(),
                linear_gain: element.gain,
                tests,
                settled,
                stalled,
            });
        }
        settings.step *= (MAX_GAIN_ERROR / (4.0 * gain_error)).clamp(1.0 / 32.0, 0.5);
    }
}

/// The largest fraction of the measurement's room to its nearer bound that a default step's
/// linear response may take: a high-purity composition (1 − x of 3e-4) would otherwise be driven
/// into the bound, where its response saturates and the fit sees a secant 100 times below `G(0)`.
/// Near a bound a composition is about linear in `ln(1 − x)`, so a response of a tenth of the room
/// fits a gain within ~5 % of the tangent's, inside [`MAX_GAIN_ERROR`].
const MAX_ROOM_FRACTION: f64 = 0.1;

/// The default first step: 5 % of the output's steady value, shrunk so that the linear response
/// `|G(0) Δu|` of a stable element stays within [`MAX_ROOM_FRACTION`] of the measurement's room to
/// its nearer bound (a mole fraction's 0 or 1).
fn default_step(plant: &Plant, x: &[f64], l: &PlantLoop, element: &Element) -> f64 {
    let step = 0.05 * x[l.op].abs();
    let spec = &plant.vars()[l.pv].spec;
    let room = (x[l.pv] - spec.lower).min(spec.upper - x[l.pv]);
    if element.integrating || !(room.is_finite() && room > 0.0) {
        return step;
    }
    step.min(MAX_ROOM_FRACTION * room / element.gain.abs())
}

/// A stable element is lag-dominant for a step test when its default scan (`T/100`) is coarser
/// than this fraction of the loop's ultimate period: a record sampled so sparsely cannot show the
/// lags and delays that limit the loop (a high-purity column's composition with its other loop
/// open: `T` of 200 h, `P_u` of 12 min), and SIMC's `τc = θ` on its fit (`θ ≈ 0`) tunes an
/// unstable loop. Its start is then sampled at `P_u/50` for `10 P_u`, and the model takes the
/// dead time of the integrating model fitted there: Skogestad's integrating approximation of a
/// lag-dominant process (SIMC, 2003, §3.3: `k' = k/τ₁`, read from the initial response), whose
/// settings are those of the FOPTD model with that dead time (`k/τ₁ · τ₁ = k`).
pub const LAG_DOMINANT: f64 = 1.0 / 20.0;

/// The finer sampling `(P_u/50, 10 P_u)` of a lag-dominant element's start (see
/// [`LAG_DOMINANT`]), or `None` for one that is not, or has no phase crossover to size it by.
fn lag_dominant_start(response: LoopResponse, l: &PlantLoop, scan: f64) -> Option<(f64, f64)> {
    let pu = loop_ultimates(&response, std::slice::from_ref(l)).ok()?[0].pu;
    (pu.is_finite() && pu > 0.0 && scan > LAG_DOMINANT * pu).then_some((pu / 50.0, 10.0 * pu))
}

/// The model fitted to a step test's record and, where its first `fine` samples are a finer
/// start, the integrating model fitted to that start, whose dead time the model takes.
fn fit_test(record: &StepResponse, order: ModelOrder, fine: usize) -> Result<(ModelFit, Option<ModelFit>), TuneError> {
    let fit = fit_step(record, order).map_err(TuneError::from)?;
    if fine == 0 || record.t.len() <= fine + 1 {
        return Ok((fit, None));
    }
    let start = StepResponse { t: record.t[..=fine].to_vec(), y: record.y[..=fine].to_vec(), du: record.du };
    let initial = fit_step(&start, ModelOrder::Integrating).map_err(TuneError::from)?;
    let model = match fit.model {
        ProcessModel::Foptd { k, tau, .. } => ProcessModel::Foptd { k, tau, theta: initial.model.dead_time() },
        m => m,
    };
    Ok((assess(record, model), Some(initial)))
}

/// Most scans a plant test's characteristic time may span (a relay's cycle, a step response's
/// length): the work of a test is bounded by it.
const MAX_SCANS_PER_TIME: f64 = 1e4;

/// A scan must be a positive time, and at least `time / MAX_SCANS_PER_TIME` of the loop's
/// characteristic `time` (named by `what`), so that a test takes a bounded number of scans.
fn check_scan(l: &PlantLoop, scan: f64, time: f64, what: &str) -> Result<(), TuneError> {
    let bad = |why: String| Err(TuneError::Scan { controller: l.name.clone(), scan, why });
    if !(scan.is_finite() && scan > 0.0) {
        return bad("is not a positive time: give `scan` a positive time, or leave it out for the default".into());
    }
    if time.is_finite() && scan < time / MAX_SCANS_PER_TIME {
        return bad(format!(
            "is below 1/{MAX_SCANS_PER_TIME:e} of {what} ({time:.4e} s): the test would take over {MAX_SCANS_PER_TIME:e} \
             scans; give a scan of at least {:.4e} s",
            time / MAX_SCANS_PER_TIME
        ));
    }
    Ok(())
}

/// A test output `u` must be a value the driven input can take (a valve opening within [0, 1], a
/// flow not negative): a test that saturates its valve measures the limit, not the plant.
fn within_range(plant: &Plant, l: &PlantLoop, u: f64) -> Result<(), TuneError> {
    let Some(b) = plant.block_index(&l.name) else { return Ok(()) };
    for i in plant.inputs_driven_by(b) {
        if let Err(why) = plantwide_flowsheet::overrides::check_input_value(plant, i, u) {
            return Err(TuneError::Saturates {
                controller: l.name.clone(),
                input: plant.inputs()[i].path.clone(),
                value: u,
                why: why.to_string(),
            });
        }
    }
    Ok(())
}

/// What the exact linear model says of a loop's element at the steady state.
struct Element {
    /// Mean residence time `T = −g'(0)/g(0)` \[s\]; `None` for a pure integrator.
    residence_time: Option<f64>,
    /// Whether it integrates.
    integrating: bool,
    /// `g(0)`, or for an integrating element `lim s→0 s g(s)` \[per s\].
    gain: f64,
}

/// The element's mean residence time `T = −g'(0)/g(0)` \[s\], whether it integrates and its gain:
/// from `g(jω) ≈ g(0)(1 − jωT)` at ω a thousand times below the slowest nonzero eigenvalue (for an
/// integrating element, `s g(s)` in place of `g`), the gain the real part, exact to `O((ωT)²)`;
/// `T` is `None` when it has none (a pure integrator). For a stable element whose `T` comes out
/// negative or nil, the slowest time constant.
fn element(plant: &Plant, x: &[f64], l: &PlantLoop) -> Result<(Element, LoopResponse), TuneError> {
    let (response, w, slow) = low_frequency_probe(plant, x, l)?;
    let g = response.at(w)[(0, 0)];
    let integrating = g.im.abs() > g.re.abs();
    // A quadrature response that shrinks with the frequency is a washout (g(0) = 0), not an integrator.
    if integrating && response.at(0.1 * w)[(0, 0)].norm() < g.norm() {
        return Err(TuneError::NoSteadyGain { controller: l.name.clone() });
    }
    let h = if integrating { g * c64::new(0.0, w) } else { g };
    let t = -h.im / (w * h.re);
    // Below a millionth of the slowest time scale it is rounding, not a lag. An element whose fast
    // response exceeds its steady one (a loop closed around it cancels most of its gain) has T < 0:
    // its slowest time constant sizes the test instead.
    let t = match (t.is_finite() && t > 1e-6 / slow, integrating) {
        (true, _) => Some(t),
        (false, true) => None,
        (false, false) => Some(1.0 / slow),
    };
    if !(h.re.is_finite() && h.re != 0.0) {
        return Err(TuneError::NoSteadyGain { controller: l.name.clone() });
    }
    Ok((Element { residence_time: t, integrating, gain: h.re }, response))
}
