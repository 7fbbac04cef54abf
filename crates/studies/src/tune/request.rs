//! Tuning a flowsheet's loops as a user asks for it: [`TuneRequest`], read from the same
//! unit-bearing JSON as a flowsheet file (`"measurement_dead_time": "1 min"`, a bare number is
//! SI), and [`tune`], the one call every face makes. Messages name the request's fields
//! (`` `scan` ``, `` `method` relay ``); a face that calls them otherwise maps them
//! ([`TuneRequest::FIELDS`]).
//!
//! ```json
//! {"loops": ["lc"], "method": "simc", "measurement_dead_time": "30 s", "time_unit": "min"}
//! ```

use plantwide_flowsheet::{Plant, StructureEdit};
use plantwide_model::ControllerSpec;
use plantwide_solve::{StrategySettings, converge};
use plantwide_units::{Dimension, QuantityValue, Unit};
use serde::{Deserialize, Serialize};

use super::PiRule;
use super::averaging::AveragingForm;
use super::fit::ModelOrder;
use super::flowsheet::{
    FlowsheetTuning, averaging_loop, blt_loops, edits, flowsheet_margins, from_relay, from_step, raise_detuning,
    raise_tau_c, written,
};
use super::loops::{Measurement, PlantLoop, inner_first, plant_loop, plant_loops};
use super::margins::Bode;
use super::plant_tests::{RelayOptions, StepOptions, relay_loop, step_loop};
use super::rules::ModelRule;
use crate::TuneError;

/// How a flowsheet's loops are tuned.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Luyben's biggest-log-modulus tuning of the loops together on the linear model.
    Blt,
    /// Ziegler–Nichols PI from a relay test.
    Zn,
    /// Tyreus–Luyben PI from a relay test.
    Tl,
    /// A relay test and Tyreus–Luyben settings.
    Relay,
    /// A step test, a model fit and Skogestad's SIMC settings.
    Simc,
    /// A step test, a model fit and internal-model-control settings.
    Imc,
    /// Averaging level control of a level loop.
    Averaging,
}

/// What `plantwide tune FILE` and `Plant.tune` ask: the loops and how to tune them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TuneRequest {
    /// The PID controllers to tune: together (blt) or one after another, cascade slaves before
    /// their masters, each tested with those before it tuned (the other methods).
    pub loops: Vec<String>,
    /// How.
    pub method: Method,
    /// Measurement dead time of every loop that the model leaves out (simc and imc add it to the
    /// fitted model's dead time).
    #[serde(default)]
    pub measurement_dead_time: Option<QuantityValue>,
    /// Measurement first-order lag of every loop (simc and imc by Skogestad's half rule).
    #[serde(default)]
    pub measurement_lag: Option<QuantityValue>,
    /// Relay amplitude in the controller's output unit (default: 5 % of the output's value).
    #[serde(default)]
    pub relay_amplitude: Option<QuantityValue>,
    /// Relay hysteresis in the measurement's unit (default 0).
    #[serde(default)]
    pub hysteresis: Option<QuantityValue>,
    /// Scan (sampling) interval of the relay and step tests (default: from the loop's linear model).
    #[serde(default)]
    pub scan: Option<QuantityValue>,
    /// Step of the output in a step test, in its unit (default: 5 % of its value).
    #[serde(default)]
    pub step: Option<QuantityValue>,
    /// Model fitted to the step test (default foptd; integrating for a level).
    #[serde(default)]
    pub model: Option<ModelOrder>,
    /// Closed-loop time constant τc (SIMC) or filter time λ (IMC) (default: the fitted dead time).
    #[serde(default)]
    pub tau_c: Option<QuantityValue>,
    /// PID instead of PI (SIMC on a SOPTD fit, IMC).
    #[serde(default)]
    pub pid: bool,
    /// Averaging: the largest allowed level deviation (default: a quarter of the level).
    #[serde(default)]
    pub level_band: Option<QuantityValue>,
    /// Averaging: the output change that balances the design disturbance (default: 10 % of the
    /// output).
    #[serde(default)]
    pub flow_change: Option<QuantityValue>,
    /// Averaging: P only (default) or critically damped PI.
    #[serde(default = "p_only")]
    pub form: AveragingForm,
    /// The unit times are written in: the reset and derivative times a tuned plant gains where
    /// its file had none (default `s`); the faces also show times in it.
    #[serde(default = "seconds")]
    pub time_unit: String,
}

fn p_only() -> AveragingForm {
    AveragingForm::P
}

fn seconds() -> String {
    "s".to_string()
}

/// The answer of a [`TuneRequest`]: the settings (SI) and, in the same order, each loop's Bode
/// diagram on the plant's linear model.
#[derive(Debug, Clone, PartialEq)]
pub struct TunedLoops {
    /// The settings and the tests behind them, SI.
    pub tuning: FlowsheetTuning,
    /// Each loop's diagram (ω in rad/s).
    pub bode: Vec<Bode>,
}

impl TunedLoops {
    /// The loops whose settings their own margins refute (`` `lc`: … ``), each with its reason;
    /// empty when every loop holds. Such settings are shown, never written into a flowsheet.
    pub fn failed(&self) -> Vec<String> {
        let loops = self.tuning.loops.iter();
        loops.filter_map(|l| l.failure.as_ref().map(|f| format!("`{}`: {f}", l.controller))).collect()
    }
}

impl TuneRequest {
    /// The fields a message names in backticks (`` give a longer `scan` ``), for a face to map to
    /// its own names; a field a message only starts with is [`TuneError::field`]'s.
    pub const FIELDS: &'static [&'static str] = &[
        "method",
        "measurement_dead_time",
        "relay_amplitude",
        "scan",
        "step",
        "model",
        "tau_c",
        "level_band",
        "flow_change",
    ];

    /// The time unit's name and its length in seconds.
    ///
    /// # Errors
    /// [`TuneError::Field`] when `time_unit` is no unit of time.
    pub fn time_unit(&self) -> Result<(String, f64), TuneError> {
        let name = self.time_unit.as_str();
        let u = Unit::parse(name).map_err(|e| field("time_unit", format!("{name}: {e}")))?;
        if u.dimension() != Dimension::TIME {
            return Err(field("time_unit", format!("{name}: not a unit of time (e.g. s, min, h)")));
        }
        Ok((name.to_string(), u.factor()))
    }

    /// The measurement dynamics every loop shares.
    ///
    /// # Errors
    /// [`TuneError::Field`] for a value that is no time or is negative.
    pub fn measurement(&self) -> Result<Measurement, TuneError> {
        let dead_time = quantity("measurement_dead_time", &self.measurement_dead_time, Dimension::TIME)?;
        let lag = quantity("measurement_lag", &self.measurement_lag, Dimension::TIME)?;
        let (dead_time, lag) = (dead_time.unwrap_or(0.0), lag.unwrap_or(0.0));
        if dead_time < 0.0 || lag < 0.0 {
            let name = if dead_time < 0.0 { "measurement_dead_time" } else { "measurement_lag" };
            return Err(field(name, "must not be negative".into()));
        }
        Ok(Measurement { dead_time, lag })
    }
}

/// Tune `request`'s loops of `plant` at its steady state `x`; then each loop's margins on the
/// plant's linear model, the tuned loops open, refute settings that would not hold (the loop's
/// `failure`, [`TunedLoops::failed`]).
///
/// # Errors
/// [`TuneError`]: a bad request (exit 1 at the faces, [`TuneError::is_user_error`]) or a test
/// that failed.
pub fn tune(plant: &Plant, x: &[f64], request: &TuneRequest) -> Result<TunedLoops, TuneError> {
    if request.loops.is_empty() {
        return Err(field("loops", "is empty: give the loops to tune".into()));
    }
    let (unit, _) = request.time_unit()?;
    let measurement = request.measurement()?;
    let loops: Vec<PlantLoop> = plant_loops(plant, &request.loops)?;
    let mut tuning = match request.method {
        Method::Blt => blt_loops(plant, x, &loops, measurement)?,
        _ => in_sequence(request, plant, &loops, &unit)?,
    };
    let bode = match (request.method, request.tau_c.is_none()) {
        (Method::Simc, true) => raise_tau_c(plant, x, &mut tuning, (ModelRule::Simc, request.pid), measurement)?,
        (Method::Imc, true) => raise_tau_c(plant, x, &mut tuning, (ModelRule::Imc, request.pid), measurement)?,
        (Method::Blt, _) => raise_detuning(plant, x, &mut tuning, measurement)?,
        _ => flowsheet_margins(plant, x, &mut tuning, measurement)?,
    };
    Ok(TunedLoops { tuning, bode })
}

/// A single-loop method on each of `loops` in turn, cascade slaves before their masters
/// ([`inner_first`]): each loop's test runs on the plant with the loops tuned before it at their
/// new settings, written as a tuned file would have them (`unit` for a time the file had none
/// of), and converged again (a P-only loop given reset action moves the steady state).
fn in_sequence(r: &TuneRequest, plant: &Plant, loops: &[PlantLoop], unit: &str) -> Result<FlowsheetTuning, TuneError> {
    let mut tuned: Option<FlowsheetTuning> = None;
    let mut current = plant.clone();
    for l in inner_first(plant, loops) {
        if let Some(t) = &tuned {
            current = with_settings(plant, t, unit)?;
        }
        let x = converge(&current, &StrategySettings::default())
            .map_err(|e| TuneError::Steady { controller: l.name.clone(), source: Box::new(e) })?
            .x;
        let l = plant_loop(&current, &l.name)?;
        let one = match r.method {
            Method::Averaging => averaging(r, &current, &x, &l)?,
            _ => plant_test(r, &current, &x, &l)?,
        };
        match &mut tuned {
            Some(t) => t.loops.extend(one.loops),
            None => tuned = Some(one),
        }
    }
    tuned.ok_or_else(|| field("loops", "is empty: give the loops to tune".into()))
}

/// `plant` with `tuning`'s settings written into its controllers, each value as a tuned file
/// writes it ([`written`]: six significant digits in the file's unit).
fn with_settings(plant: &Plant, tuning: &FlowsheetTuning, unit: &str) -> Result<Plant, TuneError> {
    let mut changes = Vec::new();
    for l in &tuning.loops {
        if let Some(file) = l.file_action {
            return Err(TuneError::WrongAction { controller: l.controller.clone(), file, needed: l.action });
        }
        let Some(ControllerSpec::Pid(cfg)) = plant.spec().controllers.get(&l.controller) else { continue };
        let mut cfg = cfg.clone();
        cfg.kc = written(l.kc.abs(), Some(&cfg.kc), None);
        cfg.tau_i = l.tau_i.map(|v| written(v, cfg.tau_i.as_ref(), Some(unit)));
        cfg.tau_d = l.tau_d.map(|v| written(v, cfg.tau_d.as_ref(), Some(unit)));
        changes.push(StructureEdit::SetController {
            name: l.controller.clone(),
            spec: Box::new(ControllerSpec::Pid(cfg)),
        });
    }
    plant.restructure(&changes).map_err(|e| TuneError::Structure(Box::new(e)))
}

/// The test `r.method` asks for on loop `l` at the steady state `x`: a relay test (relay, zn,
/// tl) or a step test with a model fit (simc, imc).
fn plant_test(r: &TuneRequest, plant: &Plant, x: &[f64], l: &PlantLoop) -> Result<FlowsheetTuning, TuneError> {
    let (out_dim, pv_dim) = (plant.vars()[l.op].spec.dim, plant.vars()[l.pv].spec.dim);
    let scan = quantity("scan", &r.scan, Dimension::TIME)?;
    let measurement = r.measurement()?;
    let relay = |name: &'static str, rule: PiRule| -> Result<FlowsheetTuning, TuneError> {
        let o = RelayOptions {
            amplitude: quantity("relay_amplitude", &r.relay_amplitude, out_dim)?,
            hysteresis: quantity("hysteresis", &r.hysteresis, pv_dim)?,
            scan,
            measurement,
        };
        Ok(from_relay(l, &relay_loop(plant, x, l, o)?, rule, name))
    };
    match r.method {
        Method::Zn => relay("zn", PiRule::ZieglerNichols),
        Method::Tl => relay("tl", PiRule::TyreusLuyben),
        Method::Relay => relay("relay", PiRule::TyreusLuyben),
        Method::Simc | Method::Imc | Method::Blt | Method::Averaging => {
            let o = StepOptions { step: quantity("step", &r.step, out_dim)?, scan, order: r.model, measurement };
            let test = step_loop(plant, x, l, o)?;
            let tau_c = quantity("tau_c", &r.tau_c, Dimension::TIME)?;
            let rule = if r.method == Method::Imc { ModelRule::Imc } else { ModelRule::Simc };
            from_step(l, test, rule, (tau_c, r.pid), measurement)
        }
    }
}

/// The averaging-level design of loop `l` (band and flow change in the measurement's and the
/// output's units).
fn averaging(r: &TuneRequest, plant: &Plant, x: &[f64], l: &PlantLoop) -> Result<FlowsheetTuning, TuneError> {
    let dim = |v: usize| plant.vars()[v].spec.dim;
    let du = quantity("flow_change", &r.flow_change, dim(l.op))?;
    let band = quantity("level_band", &r.level_band, dim(l.pv))?;
    averaging_loop(plant, x, l, du, band, r.form)
}

/// The flowsheet `text` (file `file`) with `tuned`'s settings written in, only those fields
/// changed: what `--write` writes.
///
/// # Errors
/// [`TuneError::WrongAction`] when the file's action would make a tuned loop run away;
/// [`TuneError::Edit`] when the text cannot be edited.
pub fn tuned_text(
    text: &str,
    file: &str,
    plant: &Plant,
    tuned: &FlowsheetTuning,
    unit: &str,
) -> Result<String, TuneError> {
    let edits = edits(plant, tuned, unit)?;
    plantwide_flowsheet::edit::edit_fields(text, file, &edits).map_err(|e| TuneError::Edit(Box::new(e)))
}

fn field(name: &'static str, why: String) -> TuneError {
    TuneError::Field { field: name, why }
}

/// A field's quantity in SI, checked against the largest magnitude a quantity of its dimension
/// may have anywhere in a flowsheet ([`plantwide_model::limits::max_magnitude`]: 10⁶ mol/s for a
/// flow), the rule every value of a file and of `--set` passes.
fn quantity(name: &'static str, value: &Option<QuantityValue>, dim: Dimension) -> Result<Option<f64>, TuneError> {
    let Some(value) = value else { return Ok(None) };
    let v = value.to_si(dim).map_err(|e| field(name, format!("{value}: {e}")))?;
    let max = plantwide_model::limits::max_magnitude(dim);
    if v.is_nan() || v.abs() > max {
        let n = plantwide_model::limits::number;
        return Err(field(
            name,
            format!("{value}: {} {dim} is beyond ±{} {dim}, the range in which the models hold", n(v), n(max)),
        ));
    }
    Ok(Some(v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_request_reads_its_method_and_quantities_and_refuses_unknown_fields() {
        let r: TuneRequest =
            serde_json::from_str(r#"{"loops": ["lc"], "method": "simc", "scan": "2 s", "model": "soptd"}"#).unwrap();
        assert_eq!(
            (r.method, r.model, r.form, r.time_unit.as_str()),
            (Method::Simc, Some(ModelOrder::Soptd), AveragingForm::P, "s")
        );
        assert_eq!(quantity("scan", &r.scan, Dimension::TIME).unwrap(), Some(2.0));
        let e = serde_json::from_str::<TuneRequest>(r#"{"loops": [], "method": "simc", "tauc": 1}"#).unwrap_err();
        assert!(e.to_string().contains("unknown field `tauc`"), "{e}");
        let e = serde_json::from_str::<TuneRequest>(r#"{"loops": [], "method": "fast"}"#).unwrap_err();
        assert!(e.to_string().contains("unknown variant `fast`"), "{e}");
    }

    #[test]
    fn a_bad_quantity_names_its_field() {
        let e = quantity("scan", &Some("3 kg".into()), Dimension::TIME).unwrap_err();
        assert!(e.to_string().starts_with("scan 3 kg: "), "{e}");
        let e = quantity("step", &Some("2e7 mol/s".into()), Dimension::MOLAR_FLOW).unwrap_err();
        assert!(e.to_string().contains("beyond ±"), "{e}");
        let r: TuneRequest = serde_json::from_str(r#"{"loops": ["x"], "method": "zn", "time_unit": "kg"}"#).unwrap();
        assert!(r.time_unit().unwrap_err().to_string().starts_with("time_unit kg: not a unit of time"));
    }
}
