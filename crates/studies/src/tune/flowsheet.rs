//! Tuning the PID loops of a flowsheet, and writing the settings back into its file.
//!
//! Each result names the controller, its measurement (`output`) and output (`input`), the
//! settings in SI (gains in the controller's output unit per measurement unit, times in s), and
//! the action they require: a process gain `k > 0` needs reverse action (`e = sp − pv`), `k < 0`
//! direct; the file's `kc` is the magnitude. [`edits`] turns a result into field edits of the
//! flowsheet text, each in the unit the file wrote the field in, so a reviewer's diff shows only
//! the new settings.

use plantwide_flowsheet::edit::FieldEdit;
use plantwide_flowsheet::{Plant, VarPath};
use plantwide_model::ControllerSpec;
use plantwide_model::controllers::Action;
use plantwide_units::{QuantityValue, convert_from_si};
use serde::Serialize;

use super::PiRule;
use super::averaging::{AveragingForm, AveragingSettings, averaging, check_swing};
use super::bench::RelayCycle;
use super::blt::BltSettings;
use super::fit::{ModelFit, ProcessModel};
use super::loops::{LoopResponse, Measurement, PlantLoop, canonical_order, loop_model, low_frequency_probe, plant_blt};
use super::margins::{Bode, Margins, bode, pid};
use super::plant_tests::{Linearity, StepResult};
use super::rules::{ModelRule, model_rule, tuned_dead_time};
use super::ultimate::Ultimate;
use crate::TuneError;

/// The tuning of one loop of a flowsheet.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FlowsheetLoop {
    /// Controller.
    pub controller: String,
    /// Its measurement's path.
    pub output: String,
    /// Its output (`<ctrl>.op`).
    pub input: String,
    /// Ultimate gain (relay, ZN, TL, BLT).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ku: Option<f64>,
    /// Ultimate period \[s or the time unit asked for\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pu: Option<f64>,
    /// Signed controller gain (the sign of the process gain), SI.
    pub kc: f64,
    /// Reset time (`None`: P only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tau_i: Option<f64>,
    /// Derivative time.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tau_d: Option<f64>,
    /// The action the sign of `kc` requires.
    pub action: &'static str,
    /// The action the file has, when it differs (the loop would run away).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file_action: Option<&'static str>,
    /// Averaging-level details.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub averaging: Option<AveragingSettings>,
    /// The relay cycle the settings come from.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relay: Option<RelayCycle>,
    /// The model fitted to the step test, and its fit.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fit: Option<ModelFit>,
    /// Whether the step response settled within the test (an unsettled fit is extrapolated).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub settled: Option<bool>,
    /// The step tests run and the linearized gain their fitted gains were checked against.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub linearity: Option<Linearity>,
    /// A lag-dominant element's integrating model fitted to its response's start, whose dead time
    /// `fit` takes ([`super::plant_tests::LAG_DOMINANT`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub initial_fit: Option<ModelFit>,
    /// SIMC's τc or IMC's λ used \[s or the time unit asked for\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tau_c: Option<f64>,
    /// The default τc (the fitted dead time) when the plant's exact linear model refuted its
    /// settings and τc was raised from it to keep [`MIN_PHASE_MARGIN`] ([`raise_tau_c`]) \[s or the
    /// time unit asked for\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tau_c_raised_from: Option<f64>,
    /// Gain and phase margins of the loop with these settings on the plant's exact linear model
    /// ([`flowsheet_margins`]); frequencies in rad per second or per the time unit asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub margins: Option<Margins>,
    /// Why these settings cannot be used, where the study's own check refutes them: a negative
    /// phase margin on the plant's exact linear model is a loop these settings make unstable.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
}

impl FlowsheetLoop {
    /// The failure its margins show: a negative phase margin (the element open-loop stable, its
    /// Nyquist curve then encircles −1: the loop alone is unstable with these settings).
    fn refuted(&self) -> Option<String> {
        let m = self.margins?;
        let pm = m.phase_margin.filter(|pm| *pm < 0.0)?;
        let fit = match self.tau_c {
            Some(_) => {
                "; the fitted model does not describe the response at the loop's time scale: tune for a larger \
                 closed-loop time constant τc, or by the BLT or relay method"
            }
            None => "",
        };
        Some(format!(
            "these settings leave the loop unstable on the plant's exact linear model: phase margin {pm:.1}° at \
             ω = {:.4e} rad/s{fit}",
            m.gain_crossover.unwrap_or(f64::NAN)
        ))
    }
}

/// The tuning of a set of loops of a flowsheet.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FlowsheetTuning {
    /// Method (`blt`, `zn`, `tl`, `relay`, `simc`, `imc`, `averaging`).
    pub method: &'static str,
    /// BLT detuning factor.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub detuning_factor: Option<f64>,
    /// BLT: the factor that met the log-modulus target but left the loops unstable, when the
    /// detuning was raised from it for a stable closed loop.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unstable_at: Option<f64>,
    /// BLT: the factor (after any raise for a stable closed loop) whose settings the plant's exact
    /// linear model refuted loop by loop, when the detuning was raised from it ([`raise_detuning`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub detuning_raised_from: Option<f64>,
    /// One entry per loop, in the order asked for.
    pub loops: Vec<FlowsheetLoop>,
}

impl FlowsheetTuning {
    /// Times (`pu`, `tau_i`, `tau_d`, averaging times) in a unit of `seconds` s; gains unchanged
    /// except an averaging `time`.
    pub fn in_time_unit(mut self, seconds: f64) -> FlowsheetTuning {
        for l in &mut self.loops {
            l.pu = l.pu.map(|p| p / seconds);
            l.tau_i = l.tau_i.map(|t| t / seconds);
            l.tau_d = l.tau_d.map(|t| t / seconds);
            l.margins = l.margins.map(|m| m.in_time_unit(seconds));
            l.tau_c = l.tau_c.map(|t| t / seconds);
            l.tau_c_raised_from = l.tau_c_raised_from.map(|t| t / seconds);
            if let Some(r) = &mut l.relay {
                r.pu /= seconds;
            }
            if let Some(f) = &mut l.fit {
                let integrating = matches!(f.model, ProcessModel::Integrating { .. });
                l.linearity = l.linearity.take().map(|c| c.in_time_unit(seconds, integrating));
                f.model = f.model.in_time_unit(seconds);
            }
            if let Some(f) = &mut l.initial_fit {
                f.model = f.model.in_time_unit(seconds);
            }
            if let Some(a) = &mut l.averaging {
                a.time /= seconds;
                a.tau_i = a.tau_i.map(|t| t / seconds);
            }
        }
        self
    }
}

fn action_name(a: Action) -> &'static str {
    match a {
        Action::Reverse => "reverse",
        Action::Direct => "direct",
    }
}

/// The entry of `l` with signed gain `kc` and reset/derivative times.
fn entry(l: &PlantLoop, kc: f64, tau_i: Option<f64>, tau_d: Option<f64>) -> FlowsheetLoop {
    let needed = if kc >= 0.0 { Action::Reverse } else { Action::Direct };
    FlowsheetLoop {
        controller: l.name.clone(),
        output: l.pv_path.clone(),
        input: VarPath::controller_output(&l.name, 0).into(),
        ku: None,
        pu: None,
        kc,
        tau_i,
        tau_d: tau_d.filter(|t| *t > 0.0),
        action: action_name(needed),
        file_action: (needed != l.action).then(|| action_name(l.action)),
        averaging: None,
        relay: None,
        fit: None,
        settled: None,
        linearity: None,
        initial_fit: None,
        tau_c: None,
        tau_c_raised_from: None,
        failure: None,
        margins: None,
    }
}

/// Luyben's BLT of `loops` at the steady state `x` ([`plant_blt`]), computed in the file's order
/// of the loops ([`canonical_order`]) and reported in the order of `loops`.
///
/// # Errors
/// As [`plant_blt`].
pub fn blt_loops(
    plant: &Plant,
    x: &[f64],
    loops: &[PlantLoop],
    measurement: Measurement,
) -> Result<FlowsheetTuning, TuneError> {
    let order = canonical_order(plant, &loops.iter().map(|l| l.name.as_str()).collect::<Vec<_>>());
    let computed: Vec<PlantLoop> = order.iter().map(|&k| loops[k].clone()).collect();
    let t = plant_blt(plant, x, &computed, measurement, &BltSettings::default())?;
    let mut settings: Vec<_> = order.iter().zip(&t.loops).collect();
    settings.sort_by_key(|(k, _)| **k);
    let entries = loops
        .iter()
        .zip(settings)
        .map(|(l, (_, s))| FlowsheetLoop { ku: Some(s.ku), pu: Some(s.pu), ..entry(l, s.kc, Some(s.tau_i), None) })
        .collect();
    Ok(FlowsheetTuning {
        method: "blt",
        detuning_factor: t.detuning_factor,
        unstable_at: t.unstable_at,
        detuning_raised_from: None,
        loops: entries,
    })
}

/// The design swing of an averaging level: the input change `du` a disturbance needs (input units)
/// and the level band `band` the measurement may use (measurement units), both positive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LevelSwing {
    /// Input change \[input unit\].
    pub du: f64,
    /// Level band \[measurement unit\].
    pub band: f64,
}

/// Largest `|Im(s g)/Re(s g)|` at the loop's frequency for which the element counts as an
/// integrator there: a first-order self-regulation `K/(τ s + 1)` gives `1/(ω τ)`, so this accepts
/// a level whose self-regulation moves the averaging filter time `1/ω` by under 1 %.
const INTEGRATING_PHASE: f64 = 1e-2;

/// The integrating gain `k` of a level loop's element at `x` (level units per output unit per
/// second) over the loop's own time scale, with the loop in manual.
///
/// The time scale is the frequency `ω*` at which a swing of the output of amplitude `du` moves the
/// level by `band`: `|g(jω*)| = band/du`, the lowest such on a log grid from a thousandth of the
/// slowest nonzero eigenvalue up, refined by bisection in `ln ω`. For an integrator `k/s` it is
/// `ω* = |k| du/band`, the inverse of the P-only averaging filter time `τ_F = band/(|k| du)`
/// ([`super::averaging`]). There `s g(s) = k` to `O((ω* T)²)` for lags `T ≪ 1/ω*` and to
/// `O((ω* τ)⁻²)` for a self-regulation `τ ≫ 1/ω*`: `k = Re(jω* g(jω*))`. A level held by another
/// loop through a trace composition settles at a gain of 1e12 s, an integrator over any time an
/// averaging loop acts on; a temperature settles within the band or well inside `1/ω*`.
///
/// # Errors
/// [`TuneError::NotIntegrating`] when the element never leaves the band (`|g| < band/du` at every
/// frequency), or when `s g` is not real within [`INTEGRATING_PHASE`] at `ω*` nor at the lowest
/// frequency (it settles); [`TuneError::Interacting`] when it integrates at the lowest frequency but
/// other loops make `s g(jω*)` complex, with the bands at which it would not be.
pub fn integrating_gain(plant: &Plant, x: &[f64], l: &PlantLoop, swing: LevelSwing) -> Result<f64, TuneError> {
    let not = || TuneError::NotIntegrating { controller: l.name.clone(), measurement: l.pv_path.clone() };
    let (response, lo, _) = low_frequency_probe(plant, x, l)?;
    let sg = |w: f64| response.at(w)[(0, 0)] * faer::c64::new(0.0, w);
    let w = band_frequency(|w| sg(w).norm() / w, swing.band / swing.du, lo).ok_or_else(not)?;
    let at = sg(w);
    if !at.re.is_finite() {
        return Err(not());
    }
    if one_integrator(at) {
        return Ok(at.re);
    }
    let slow = sg(lo);
    if !one_integrator(slow) {
        return Err(not());
    }
    // Where on either side of ω* the element is one integrator again, as the band putting the
    // loop there, |k| du / ω: a band the level has room for (less than its whole value).
    let clear = |dir: f64| {
        let grid = (1..=40).map(|k| w * 10f64.powf(dir * k as f64 / 4.0)).take_while(|&v| v >= lo);
        let points: Vec<f64> = grid.collect();
        (0..points.len().saturating_sub(2))
            .find(|&k| points[k..k + 3].iter().all(|&v| one_integrator(sg(v))))
            .map(|k| sg(points[k]).re.abs() * swing.du / points[k])
            .filter(|&band| band < x[l.pv].abs())
    };
    let unit = plant.vars()[l.pv].spec.dim;
    let faster_band = clear(1.0);
    let bands: Vec<String> = [(faster_band, "a faster loop"), (clear(-1.0), "a slower one")]
        .into_iter()
        .filter_map(|(b, what)| b.map(|b| format!("{b:.4e} {unit} ({what})")))
        .collect();
    let suggestion = match bands.is_empty() {
        true => "Use `method` simc or relay.".to_string(),
        false => {
            format!("A `level_band` of {} keeps it clear of them; or use `method` simc or relay.", bands.join(" or "))
        }
    };
    Err(TuneError::Interacting {
        controller: l.name.clone(),
        measurement: l.pv_path.clone(),
        slow: slow.re,
        time: 1.0 / w,
        re: at.re,
        im: at.im,
        suggestion,
        faster_band,
    })
}

/// Whether `s g(jω)` is a real, nonzero gain within [`INTEGRATING_PHASE`]: the element is one
/// integrator at that frequency.
fn one_integrator(sg: faer::c64) -> bool {
    sg.re.is_finite() && sg.re != 0.0 && sg.im.abs() <= INTEGRATING_PHASE * sg.re.abs()
}

/// The lowest frequency `ω ≥ lo` at which `magnitude(ω)` falls through `target`: the first step
/// down through it on a grid of four points a decade from `lo` over 40 decades, refined by 60
/// bisections in `ln ω` (to rounding). `None` when `magnitude(lo)` is below `target` or not a
/// number (the level never leaves the band), or it never falls through.
fn band_frequency(magnitude: impl Fn(f64) -> f64, target: f64, lo: f64) -> Option<f64> {
    let above = |w: f64| magnitude(w) >= target;
    if !above(lo) {
        return None;
    }
    let step = 10f64.powf(0.25);
    let k = (1..=160).find(|&i| !above(lo * step.powi(i)))?;
    let (mut a, mut b) = ((lo * step.powi(k - 1)).ln(), (lo * step.powi(k)).ln());
    for _ in 0..60 {
        let m = 0.5 * (a + b);
        if above(m.exp()) { a = m } else { b = m }
    }
    Some((0.5 * (a + b)).exp())
}

/// Averaging-level settings of level loop `l`: a disturbance that the output must move by
/// `flow_change` to balance (default: 10 % of the output's steady value) within a level band
/// (default: a quarter of the measurement's steady value). Where the default band would put the
/// loop at a time scale at which other loops move the level too ([`TuneError::Interacting`]), the
/// band of a faster loop that sees one integrator is used instead, and the settings say so
/// ([`AveragingSettings::band_narrowed_from`]); a band the user gave is kept or refused.
///
/// # Errors
/// [`TuneError::NotIntegrating`] for a loop whose measurement does not integrate; bad bands;
/// [`TuneError::Interacting`] for a band given, or a default with no faster band that works.
pub fn averaging_loop(
    plant: &Plant,
    x: &[f64],
    l: &PlantLoop,
    flow_change: Option<f64>,
    band: Option<f64>,
    form: AveragingForm,
) -> Result<FlowsheetTuning, TuneError> {
    let du = flow_change.unwrap_or(0.1 * x[l.op].abs());
    let default = 0.25 * x[l.pv].abs();
    let given = band.is_some();
    let band = band.unwrap_or(default);
    check_swing(du, band).map_err(TuneError::from)?;
    let (k, band, narrowed) = match integrating_gain(plant, x, l, LevelSwing { du, band }) {
        Err(TuneError::Interacting { faster_band: Some(b), .. }) if !given => {
            (integrating_gain(plant, x, l, LevelSwing { du, band: b })?, b, Some(default))
        }
        k => (k?, band, None),
    };
    let mut a = averaging(k, du, band, form).map_err(TuneError::from)?;
    a.band_narrowed_from = narrowed;
    let mut e = entry(l, a.kc, a.tau_i, None);
    e.averaging = Some(a);
    Ok(FlowsheetTuning {
        method: "averaging",
        detuning_factor: None,
        unstable_at: None,
        detuning_raised_from: None,
        loops: vec![e],
    })
}

/// Ziegler–Nichols or Tyreus–Luyben PI settings of loop `l` from its relay `cycle`; `method`
/// names the result (`relay`, `zn`, `tl`).
pub fn from_relay(l: &PlantLoop, cycle: &RelayCycle, rule: PiRule, method: &'static str) -> FlowsheetTuning {
    let ultimate = Ultimate { ku: cycle.ku, omega_u: 2.0 * std::f64::consts::PI / cycle.pu, pu: cycle.pu };
    let (kc, tau_i) = rule.settings(&ultimate);
    let e = FlowsheetLoop {
        ku: Some(cycle.ku),
        pu: Some(cycle.pu),
        relay: Some(cycle.clone()),
        ..entry(l, kc, Some(tau_i), None)
    };
    FlowsheetTuning { method, detuning_factor: None, unstable_at: None, detuning_raised_from: None, loops: vec![e] }
}

/// SIMC or IMC settings of loop `l` from the model fitted to its step test, seen through
/// `measurement` (its dead time and lag, which the plant's model leaves out, added to the fitted
/// model by [`ProcessModel::measured`]).
///
/// # Errors
/// [`TuneError::Rule`] for a degenerate model.
pub fn from_step(
    l: &PlantLoop,
    test: StepResult,
    rule: ModelRule,
    (tau_c, derivative): (Option<f64>, bool),
    measurement: Measurement,
) -> Result<FlowsheetTuning, TuneError> {
    let model = test.fit.model.measured(measurement.dead_time, measurement.lag);
    // A measurement's dead time or lag is a delay of the loop however slow the process: `τc = θ`
    // then, where a fitted dead time under a thousandth of the lag alone counts as none.
    let measured = measurement.dead_time > 0.0 || measurement.lag > 0.0;
    let tau_c = tau_c.or_else(|| measured.then(|| tuned_dead_time(&model, derivative)));
    let p = model_rule(rule, &model, tau_c, derivative)?;
    let e = FlowsheetLoop {
        fit: Some(test.fit),
        settled: Some(test.settled),
        linearity: test.linearity,
        initial_fit: test.initial,
        tau_c: Some(p.tau_c),
        ..entry(l, p.kc, Some(p.tau_i), p.tau_d)
    };
    let method = match rule {
        ModelRule::Simc => "simc",
        ModelRule::Imc => "imc",
    };
    Ok(FlowsheetTuning { method, detuning_factor: None, unstable_at: None, detuning_raised_from: None, loops: vec![e] })
}

/// The controller gain `|kc|` as the file of `plant` would write it (in the unit of its `kc`).
pub fn kc_text(plant: &Plant, controller: &str, kc: f64) -> String {
    let old = match plant.spec().controllers.get(controller) {
        Some(ControllerSpec::Pid(cfg)) => Some(cfg.kc.clone()),
        _ => None,
    };
    quantity(kc.abs(), old.as_ref(), None).trim_matches('"').to_string()
}

/// Field edits writing `tuning` into the flowsheet text of `plant`: `kc` as the magnitude, and
/// `tau_i`/`tau_d` set, or removed when the tuning has none (a P-only averaging level replaces a
/// PI), each in the unit the file wrote it in (SI numbers when it wrote a number; `time_unit` for a
/// time the file did not have).
///
/// # Errors
/// [`TuneError::WrongAction`] when the file's action would make a tuned loop run away.
pub fn edits(plant: &Plant, tuning: &FlowsheetTuning, time_unit: &str) -> Result<Vec<FieldEdit>, TuneError> {
    let mut out = Vec::new();
    for l in &tuning.loops {
        if let Some(file) = l.file_action {
            return Err(TuneError::WrongAction { controller: l.controller.clone(), file, needed: l.action });
        }
        let Some(ControllerSpec::Pid(cfg)) = plant.spec().controllers.get(&l.controller) else { continue };
        let path = |f: &str| vec!["controllers".to_string(), l.controller.clone(), f.to_string()];
        out.push(FieldEdit { path: path("kc"), value: Some(quantity(l.kc.abs(), Some(&cfg.kc), None)) });
        let time = |v: Option<f64>, old: Option<&QuantityValue>| v.map(|v| quantity(v, old, Some(time_unit)));
        out.push(FieldEdit { path: path("tau_i"), value: time(l.tau_i, cfg.tau_i.as_ref()) });
        out.push(FieldEdit { path: path("tau_d"), value: time(l.tau_d, cfg.tau_d.as_ref()) });
    }
    Ok(out)
}

/// The JSON text of SI value `v` in the unit of `old` (a quantity string), else `fallback`, else
/// the bare SI number; six significant digits.
pub fn quantity(v: f64, old: Option<&QuantityValue>, fallback: Option<&str>) -> String {
    match written(v, old, fallback) {
        QuantityValue::Text(t) => format!("\"{t}\""),
        QuantityValue::Number(_) => significant(v),
    }
}

/// SI value `v` as a tuned file holds it: in the unit of `old` (a quantity string), else
/// `fallback`, else the bare SI number; six significant digits (the value [`quantity`] writes).
pub fn written(v: f64, old: Option<&QuantityValue>, fallback: Option<&str>) -> QuantityValue {
    let unit = match old {
        Some(QuantityValue::Text(t)) => t.trim().split_once(char::is_whitespace).map(|(_, u)| u.trim().to_string()),
        _ => None,
    };
    let unit = unit.or_else(|| fallback.filter(|u| *u != "s").map(str::to_string));
    match unit.as_deref().and_then(|u| convert_from_si(v, u).ok().map(|x| (x, u))) {
        Some((x, u)) => QuantityValue::Text(format!("{} {u}", significant(x))),
        None => QuantityValue::Number(significant(v).parse().unwrap_or(v)),
    }
}

/// `v` to six significant digits, as JSON.
fn significant(v: f64) -> String {
    let s = format!("{v:.5e}");
    s.parse::<f64>().map_or(s, |x| x.to_string())
}

/// The gain and phase margins of each tuned loop of `tuning` (SI, before [`FlowsheetTuning::in_time_unit`])
/// on the exact linear model of `plant` at its steady state `x`: each loop alone, `g_ii(jω)`
/// seen through `measurement` times its PID, with the tuned loops open (in manual) and every
/// other loop as in the file — the single-loop margins python-control's `stability_margins`
/// gives for `g_ii c_i`. Written into each loop's `margins`; returned with each loop's Bode
/// diagram ([`bode`], SI: ω in rad/s), in the order of `tuning.loops`; the loops' model is computed
/// in the file's order of the loops ([`canonical_order`]), so their order in `tuning` does not move a
/// margin.
///
/// # Errors
/// As [`super::loops::loop_model`].
pub fn flowsheet_margins(
    plant: &Plant,
    x: &[f64],
    tuning: &mut FlowsheetTuning,
    measurement: Measurement,
) -> Result<Vec<Bode>, TuneError> {
    let names: Vec<&str> = tuning.loops.iter().map(|l| l.controller.as_str()).collect();
    let order = canonical_order(plant, &names);
    let computed: Vec<&str> = order.iter().map(|&k| names[k]).collect();
    let loops = super::loops::plant_loops(plant, &computed)?;
    let response = LoopResponse::new(loop_model(plant, x, &loops)?, measurement);
    let (lo, hi) = super::loops::frequency_range(&response.model().ss, &loops)?;
    let mut diagrams = Vec::new();
    for (i, l) in tuning.loops.iter_mut().enumerate() {
        let at = order.iter().position(|&k| k == i).unwrap_or(i);
        let c = |w: f64| pid(l.kc, l.tau_i, l.tau_d, w);
        let b = bode(|w| response.at(w)[(at, at)] * c(w), lo, hi);
        l.margins = Some(b.margins);
        l.failure = l.refuted();
        diagrams.push(b);
    }
    Ok(diagrams)
}

/// The phase margin \[deg\] a loop tuned by SIMC or IMC with the default τc must keep on the
/// plant's exact linear model; below it τc is raised ([`raise_tau_c`]). SIMC's τc = θ gives about
/// 47° on the first-order-plus-dead-time model it assumes (Skogestad 2003, Table 2 with τc = θ);
/// 30° is the least commonly accepted for a loop that must tolerate model error (Seborg et al.,
/// *Process Dynamics and Control*, §14: PM 30°–45°).
pub const MIN_PHASE_MARGIN: f64 = 30.0;

/// Most doublings of τc tried (up to 2¹⁰ θ, past the slowest closed loop anyone would take).
const MAX_DOUBLINGS: usize = 10;

/// SIMC or IMC loops whose default τc (the fitted dead time) the plant's exact linear model
/// refutes (a negative phase margin: a fitted model that does not describe the response at the
/// loop's time scale), retuned from the same fit with τc doubled until each has
/// [`MIN_PHASE_MARGIN`]: the smallest `θ·2^k` that gives it, with `tau_c_raised_from` recording θ.
/// Loops the exact model accepts keep SIMC's τc = θ, whatever their margin (shown beside them). A
/// loop that has no such τc within 2¹⁰ θ keeps its refutation ([`FlowsheetLoop::failure`]). The
/// margins are those of the final settings, as [`flowsheet_margins`] gives them.
///
/// # Errors
/// [`TuneError`] from the margins' linear model, or [`TuneError::Rule`] for a degenerate model.
pub fn raise_tau_c(
    plant: &Plant,
    x: &[f64],
    tuning: &mut FlowsheetTuning,
    (rule, derivative): (ModelRule, bool),
    measurement: Measurement,
) -> Result<Vec<Bode>, TuneError> {
    let mut bode = flowsheet_margins(plant, x, tuning, measurement)?;
    // Only loops the exact model refutes are retuned; once retuned, until they have the margin.
    let mut retune: Vec<bool> = tuning.loops.iter().map(|l| l.failure.is_some()).collect();
    for _ in 0..MAX_DOUBLINGS {
        let mut raised = false;
        for (l, retune) in tuning.loops.iter_mut().zip(&mut retune) {
            let pm = l.margins.and_then(|m| m.phase_margin);
            *retune &= pm.is_none_or(|pm| pm < MIN_PHASE_MARGIN);
            let (Some(fit), Some(tc), true) = (&l.fit, l.tau_c, *retune) else { continue };
            let model = fit.model.measured(measurement.dead_time, measurement.lag);
            let p = model_rule(rule, &model, Some(2.0 * tc), derivative)?;
            l.tau_c_raised_from.get_or_insert(tc);
            (l.kc, l.tau_i, l.tau_d, l.tau_c) = (p.kc, Some(p.tau_i), p.tau_d.filter(|t| *t > 0.0), Some(p.tau_c));
            raised = true;
        }
        if !raised {
            break;
        }
        bode = flowsheet_margins(plant, x, tuning, measurement)?;
    }
    Ok(bode)
}

/// BLT settings that the plant's exact linear model refutes loop by loop (a negative phase margin
/// of a loop alone, [`flowsheet_margins`]), detuned further: the factor doubled (each `K_c`
/// halved, each `τ_I` doubled, Luyben's detuning) until every refuted loop has
/// [`MIN_PHASE_MARGIN`], with `detuning_raised_from` recording the factor BLT chose. BLT's factor
/// meets its log-modulus target for the loops together; a loop whose element crosses −180°
/// more than once can still be unstable alone at it (generated plant 0x6a83d4ab9bc169d6: −2.3°
/// at 3.1e-3 rad/s), which a user of the file meets when another loop is put in manual. Settings
/// the exact model accepts keep BLT's factor; after [`MAX_DOUBLINGS`] the refutation stays.
///
/// # Errors
/// [`TuneError`] from the margins' linear model.
pub fn raise_detuning(
    plant: &Plant,
    x: &[f64],
    tuning: &mut FlowsheetTuning,
    measurement: Measurement,
) -> Result<Vec<Bode>, TuneError> {
    let mut bode = flowsheet_margins(plant, x, tuning, measurement)?;
    let watched: Vec<bool> = tuning.loops.iter().map(|l| l.failure.is_some()).collect();
    for _ in 0..MAX_DOUBLINGS {
        let short = tuning
            .loops
            .iter()
            .zip(&watched)
            .any(|(l, &w)| w && l.margins.and_then(|m| m.phase_margin).is_none_or(|pm| pm < MIN_PHASE_MARGIN));
        let Some(f) = tuning.detuning_factor.filter(|_| short) else { break };
        tuning.detuning_raised_from.get_or_insert(f);
        tuning.detuning_factor = Some(2.0 * f);
        for l in &mut tuning.loops {
            l.kc /= 2.0;
            l.tau_i = l.tau_i.map(|t| 2.0 * t);
        }
        bode = flowsheet_margins(plant, x, tuning, measurement)?;
    }
    Ok(bode)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantities_are_written_in_the_files_unit() {
        let old = QuantityValue::Text("20 kmol/h/K".into());
        // 1 kmol/h/K = 1000/3600 mol/(s K).
        assert_eq!(quantity(2.5 * 1000.0 / 3600.0, Some(&old), None), "\"2.5 kmol/h/K\"");
        assert_eq!(quantity(1234.5678, Some(&QuantityValue::Number(3.0)), None), "1234.57");
        assert_eq!(quantity(600.0, None, Some("min")), "\"10 min\"");
        assert_eq!(quantity(600.0, None, Some("s")), "600");
    }
}
