//! An identification as a user asks for it: [`IdentifyRequest`], read from the same unit-bearing
//! JSON as a flowsheet file, and [`study`], the one call every face makes. Messages name the
//! request's fields (`` `duration` ``, `` `design` prbs ``); a face maps them to its own names
//! ([`IdentifyRequest::FIELDS`]).
//!
//! ```json
//! {"inputs": ["column.reflux@kmol/min"], "outputs": ["distillate.x[light]"], "noise": [1e-4]}
//! ```

use plantwide_analysis::select::{Signal, in_system, select_inputs, select_outputs};
use plantwide_flowsheet::Plant;
use plantwide_units::{Dimension, QuantityValue, UnitSystem};
use serde::{Deserialize, Serialize};

use super::{Design, Identification, IdentifyError, IdentifySettings, identify, select_driven};

/// What `plantwide identify` and `Plant.identify` ask: a plant test of `inputs` on `outputs`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IdentifyRequest {
    /// Inputs moved by the test, each `PATH[@unit]` (with `closed_loop`, inputs a PID drives).
    pub inputs: Vec<String>,
    /// Outputs measured, each `PATH[@unit]`.
    pub outputs: Vec<String>,
    /// Test signals (default directional).
    #[serde(default = "directional")]
    pub design: Design,
    /// White measurement noise σ per output, in the output's display unit (one for all, or one
    /// per output; default none).
    #[serde(default)]
    pub noise: Vec<f64>,
    /// Seed of the test signals and the noise (default 1).
    #[serde(default = "one")]
    pub seed: u64,
    /// Length of the estimation test (default four PRBS periods).
    #[serde(default)]
    pub duration: Option<QuantityValue>,
    /// Sample time (default τ_dom/20).
    #[serde(default)]
    pub sample_time: Option<QuantityValue>,
    /// Dominant time constant (default: the slowest of the exact linear model).
    #[serde(default)]
    pub tau_dom: Option<QuantityValue>,
    /// Largest move per input, in the input's display unit (one for all, or one per input;
    /// default 1 % of its steady value).
    #[serde(default)]
    pub amplitude: Vec<f64>,
    /// Closed-loop speed factor α of the PRBS design (Eq. 7-7; default 2).
    #[serde(default = "two")]
    pub alpha: f64,
    /// Settling factor β of the PRBS design (3: 95 %, 4: 98 %, 5: 99 %; default 3).
    #[serde(default = "three")]
    pub beta: f64,
    /// Directional design: output amplitude of the high-gain directions relative to the low-gain
    /// one's (default 2; 1 is Koung & MacGregor's equal amplitudes).
    #[serde(default = "two")]
    pub high_gain_boost: f64,
    /// Test in closed loop by setpoint injection: the inputs are the outputs of PID loops.
    #[serde(default)]
    pub closed_loop: bool,
    /// The display units of a signal that names none, which `noise` and `amplitude` are given
    /// in (default si).
    #[serde(default)]
    pub units: UnitSystem,
}

fn directional() -> Design {
    Design::Directional
}
fn one() -> u64 {
    1
}
fn two() -> f64 {
    2.0
}
fn three() -> f64 {
    3.0
}

/// The answer of an [`IdentifyRequest`]: the identification and the signals it was made on (their
/// display units).
#[derive(Debug, Clone, PartialEq)]
pub struct Identified {
    /// The test, the models, their validation and the verdict.
    pub identification: Identification,
    /// The inputs moved.
    pub inputs: Vec<Signal>,
    /// The outputs measured.
    pub outputs: Vec<Signal>,
}

impl IdentifyRequest {
    /// The fields a message names in backticks (`` give a smaller `amplitude` ``), for a face to
    /// map to its own names.
    pub const FIELDS: &'static [&'static str] =
        &["design", "noise", "duration", "sample_time", "tau_dom", "amplitude", "high_gain_boost", "closed_loop"];
}

/// Identify `request`'s inputs and outputs of `plant` at its steady state `(x, u)`.
///
/// # Errors
/// [`IdentifyError`]: a bad request (exit 1 at the faces, [`IdentifyError::is_user_error`]) or a
/// test that could not be run or fitted. A model the verdict finds not usable is an answer
/// ([`Identification::verdict`]), not an error.
pub fn study(plant: &Plant, x: &[f64], u: &[f64], request: &IdentifyRequest) -> Result<Identified, IdentifyError> {
    let r = request;
    // A path or unit the plant does not have is the request's fault, said as the selection says it.
    let selection = |e: plantwide_analysis::AnalysisError| IdentifyError::Request(e.to_string());
    let outputs = select_outputs(plant, &in_system(plant, &r.outputs, r.units)).map_err(selection)?;
    let asked = in_system(plant, &r.inputs, r.units);
    let inputs = match r.closed_loop {
        true => select_driven(plant, &asked)?,
        false => select_inputs(plant, &asked).map_err(selection)?,
    };
    let settings = IdentifySettings {
        design: r.design,
        noise: in_si(&r.noise, &outputs),
        seed: r.seed,
        duration: time("duration", &r.duration)?,
        sample_time: time("sample_time", &r.sample_time)?,
        amplitude: (!r.amplitude.is_empty()).then(|| in_si(&r.amplitude, &inputs)),
        tau_dom: time("tau_dom", &r.tau_dom)?,
        alpha: r.alpha,
        beta: r.beta,
        closed_loop: r.closed_loop,
        high_gain_boost: r.high_gain_boost,
    };
    let identification = identify(plant, x, u, &inputs, &outputs, &settings)?;
    Ok(Identified { identification, inputs, outputs })
}

/// A time field in SI.
fn time(field: &str, value: &Option<QuantityValue>) -> Result<Option<f64>, IdentifyError> {
    let si =
        |v: &QuantityValue| v.to_si(Dimension::TIME).map_err(|e| IdentifyError::Request(format!("`{field}` {v}: {e}")));
    value.as_ref().map(si).transpose()
}

/// Per-signal values in display units to SI (one value for all signals, or one per signal; extra
/// values are kept for the settings' own count check).
fn in_si(values: &[f64], signals: &[Signal]) -> Vec<f64> {
    match values {
        [one] => signals.iter().map(|s| one * s.factor).collect(),
        many => many
            .iter()
            .zip(signals)
            .map(|(v, s)| v * s.factor)
            .chain(many.iter().skip(signals.len()).copied())
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_request_takes_the_clis_defaults() {
        let r: IdentifyRequest = serde_json::from_str(r#"{"inputs": ["a"], "outputs": ["b"]}"#).unwrap();
        assert_eq!((r.design, r.seed, r.alpha, r.beta, r.high_gain_boost), (Design::Directional, 1, 2.0, 3.0, 2.0));
        assert_eq!(r.units, UnitSystem::Si);
        let e = serde_json::from_str::<IdentifyRequest>(r#"{"inputs": [], "outputs": [], "design": "chirp"}"#);
        assert!(e.unwrap_err().to_string().contains("unknown variant `chirp`"));
        let e = time("duration", &Some("3 kg".into())).unwrap_err();
        assert!(e.to_string().starts_with("`duration` 3 kg: "), "{e}");
    }
}
