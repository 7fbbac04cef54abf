//! The transfer-function model file (`*.tf.json`), read into a
//! [`TfModel`](plantwide_analysis::tf::TfModel): the form plant tests and identification produce.
//!
//! Each element from input (or disturbance) `j` to output `i` is
//! `g_ij(s) = K · Π_k (τ_lead,k s + 1) / Π_k (τ_lag,k s + 1) · e^(−θ s)`, with the gain `K` in
//! output units per input unit (the units the file declares for its signals), lags `τ_lag > 0`,
//! leads `τ_lead ≠ 0` (negative: a right-half-plane zero, inverse response) and dead time `θ ≥ 0`.
//! Times are quantities (`"16.7 min"`) or bare numbers in seconds. A missing element is zero.
//! Every mistake is reported with its JSON path ([`IoError::TfFile`]).
//!
//! ```json
//! {
//!   "format_version": 1,
//!   "name": "wood_berry",
//!   "inputs":  [{"name": "R", "unit": "lb/min", "description": "reflux"}],
//!   "outputs": [{"name": "xD", "unit": "mol%"}],
//!   "disturbances": [{"name": "F", "unit": "lb/min"}],
//!   "elements": [
//!     {"output": "xD", "input": "R", "gain": 12.8, "lags": ["16.7 min"], "dead_time": "1 min"},
//!     {"output": "xD", "input": "F", "gain": 3.8, "lags": ["14.9 min"], "dead_time": "8.1 min"}
//!   ]
//! }
//! ```

use plantwide_analysis::tf::{Element, TfModel, TfSignal};
use plantwide_units::{Dimension, QuantityValue};
use serde::Deserialize;

use crate::error::IoError;

/// A transfer-function file as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct TfFile {
    format_version: u32,
    name: String,
    #[serde(default)]
    description: String,
    inputs: Vec<SignalSpec>,
    outputs: Vec<SignalSpec>,
    #[serde(default)]
    disturbances: Vec<SignalSpec>,
    elements: Vec<ElementSpec>,
}

/// An input, output or disturbance as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SignalSpec {
    name: String,
    #[serde(default)]
    unit: String,
    #[serde(default)]
    description: String,
}

impl From<SignalSpec> for TfSignal {
    fn from(s: SignalSpec) -> TfSignal {
        TfSignal { name: s.name, unit: s.unit, description: s.description }
    }
}

/// An element as written: signal names, gain, times as quantities.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct ElementSpec {
    output: String,
    input: String,
    gain: f64,
    #[serde(default)]
    lags: Vec<QuantityValue>,
    #[serde(default)]
    leads: Vec<QuantityValue>,
    #[serde(default)]
    dead_time: Option<QuantityValue>,
}

fn tf_error(file: &str, path: impl Into<String>, message: impl Into<String>) -> IoError {
    IoError::TfFile { file: file.to_string(), path: path.into(), message: message.into() }
}

fn times(file: &str, path: &str, values: &[QuantityValue]) -> Result<Vec<f64>, IoError> {
    values
        .iter()
        .enumerate()
        .map(|(k, v)| v.to_si(Dimension::TIME).map_err(|e| tf_error(file, format!("{path}[{k}]"), e.to_string())))
        .collect()
}

/// Parse and check a transfer-function file (`file` names it in messages).
pub fn parse(text: &str, file: &str) -> Result<TfModel, IoError> {
    // Keys given twice and overlong strings first, as a flowsheet's: serde keeps one of two keys
    // unseen, and would quote a 100 kB name in its message.
    if serde_json::from_str::<serde::de::IgnoredAny>(text).is_ok()
        && let Some(d) = plantwide_flowsheet::parse::walk_diagnostics(text).into_iter().next()
    {
        return Err(tf_error(file, if d.path.is_empty() { "(top level)".to_string() } else { d.path }, d.message));
    }
    let de = &mut serde_json::Deserializer::from_str(text);
    let spec: TfFile = serde_path_to_error::deserialize(&mut *de).map_err(|e| {
        let path = e.path().to_string();
        tf_error(file, if path == "." { "(top level)".to_string() } else { path }, e.into_inner().to_string())
    })?;
    de.end().map_err(|e| tf_error(file, "(top level)", e.to_string()))?;
    if spec.elements.is_empty() {
        return Err(tf_error(
            file,
            "elements",
            "a model needs at least one element (an output's response to an input)",
        ));
    }
    if spec.format_version != 1 {
        return Err(tf_error(
            file,
            "format_version",
            format!("version {} is not supported (this build reads version 1)", spec.format_version),
        ));
    }
    check_names(&spec, file)?;
    if spec.inputs.is_empty() || spec.outputs.is_empty() {
        return Err(tf_error(file, "inputs", "a model needs at least one input and one output"));
    }
    let elements = elements(&spec, file)?;
    let signals = |list: Vec<SignalSpec>| list.into_iter().map(TfSignal::from).collect();
    TfModel::new(
        spec.name,
        spec.description,
        signals(spec.inputs),
        signals(spec.outputs),
        signals(spec.disturbances),
        elements,
    )
    .map_err(|e| tf_error(file, "elements", e.to_string()))
}

/// Every signal name is used once across inputs, outputs and disturbances.
fn check_names(spec: &TfFile, file: &str) -> Result<(), IoError> {
    let mut names: Vec<(&str, String)> = Vec::new();
    for (list, key) in [(&spec.inputs, "inputs"), (&spec.outputs, "outputs"), (&spec.disturbances, "disturbances")] {
        for (k, s) in list.iter().enumerate() {
            if let Some((_, other)) = names.iter().find(|(n, _)| *n == s.name) {
                return Err(tf_error(
                    file,
                    format!("{key}[{k}].name"),
                    format!("`{}` is already used by {other}", s.name),
                ));
            }
            names.push((&s.name, format!("{key}[{k}]")));
        }
    }
    Ok(())
}

/// The element matrix, outputs × (inputs then disturbances), each element checked.
fn elements(spec: &TfFile, file: &str) -> Result<Vec<Vec<Option<Element>>>, IoError> {
    let n_cols = spec.inputs.len() + spec.disturbances.len();
    let mut elements = vec![vec![None; n_cols]; spec.outputs.len()];
    let col_names: Vec<&str> = spec.inputs.iter().chain(&spec.disturbances).map(|s| s.name.as_str()).collect();
    for (k, e) in spec.elements.iter().enumerate() {
        let at = |field: &str| format!("elements[{k}].{field}");
        let i = spec.outputs.iter().position(|s| s.name == e.output).ok_or_else(|| {
            let outs: Vec<&str> = spec.outputs.iter().map(|s| s.name.as_str()).collect();
            tf_error(file, at("output"), format!("no output `{}` (outputs: {})", e.output, outs.join(", ")))
        })?;
        let j = col_names.iter().position(|n| *n == e.input).ok_or_else(|| {
            tf_error(
                file,
                at("input"),
                format!("no input or disturbance `{}` (declared: {})", e.input, col_names.join(", ")),
            )
        })?;
        if elements[i][j].is_some() {
            return Err(tf_error(file, at("input"), format!("a second element from `{}` to `{}`", e.input, e.output)));
        }
        elements[i][j] = Some(element(e, file, &at)?);
    }
    Ok(elements)
}

/// Most lags and leads one element may have: far above what identification or a column's
/// response needs (the shipped 90-lag test model passes), and a bound on the work of every
/// analysis, which grows with the square of an element's order (10 000 lags took minutes).
pub const MAX_ELEMENT_ORDER: usize = 200;

/// One element in seconds: a finite gain, positive lags, non-zero leads, a dead time ≥ 0.
fn element(e: &ElementSpec, file: &str, at: &dyn Fn(&str) -> String) -> Result<Element, IoError> {
    if !e.gain.is_finite() {
        return Err(tf_error(file, at("gain"), "must be a finite number"));
    }
    if e.lags.len() + e.leads.len() > MAX_ELEMENT_ORDER {
        return Err(tf_error(
            file,
            at("lags"),
            format!(
                "{} lags and {} leads are more than the {MAX_ELEMENT_ORDER} an element may have: fit a model of lower order",
                e.lags.len(),
                e.leads.len()
            ),
        ));
    }
    let lags = times(file, &at("lags"), &e.lags)?;
    if let Some(k2) = lags.iter().position(|t| !(t.is_finite() && *t > 0.0)) {
        return Err(tf_error(
            file,
            format!("{}[{k2}]", at("lags")),
            "a lag time constant must be positive (an unstable pole is not supported)",
        ));
    }
    let leads = times(file, &at("leads"), &e.leads)?;
    if let Some(k2) = leads.iter().position(|t| !(t.is_finite() && *t != 0.0)) {
        return Err(tf_error(
            file,
            format!("{}[{k2}]", at("leads")),
            "a lead time constant must be non-zero (negative for inverse response)",
        ));
    }
    let dead_time = match &e.dead_time {
        Some(v) => v.to_si(Dimension::TIME).map_err(|err| tf_error(file, at("dead_time"), err.to_string()))?,
        None => 0.0,
    };
    if !(dead_time.is_finite() && dead_time >= 0.0) {
        return Err(tf_error(file, at("dead_time"), "must be zero or positive"));
    }
    Ok(Element { gain: e.gain, lags, leads, dead_time })
}

/// The entry of an element the model does not have: the zero transfer function 0/1, written out
/// (not `null`) so that a reader building a transfer-function matrix (python-control's `tf`,
/// MATLAB's `tf`) gets a full, finite matrix.
fn zero_element() -> serde_json::Value {
    serde_json::json!({"gain": 0.0, "num": [0.0], "den": [1.0], "dead_time": 0.0, "poles": []})
}

/// A transfer-function model as JSON for python-control and MATLAB: per element its numerator
/// and denominator in descending powers of `s` (rad per `time_unit`) and its dead time (in
/// `time_unit`), with the poles, the steady-state gain and, if asked, `G(jω)`; an element the
/// model does not have is the zero transfer function 0/1:
///
/// ```python
/// import json, control
/// m = json.load(open("wood_berry.model.json")); e = m["elements"][0][0]
/// g11 = control.tf(e["num"], e["den"])          # times e^(-e["dead_time"] s), e.g. control.pade
/// ```
///
/// # Errors
/// [`IoError::Overflow`] when an element's coefficients are not finite in `time_unit`.
pub fn export(
    model: &TfModel,
    time_unit: (&str, f64),
    frequency: Option<&plantwide_analysis::frequency::FrequencyResults>,
) -> Result<serde_json::Value, IoError> {
    let (unit, per) = time_unit;
    let signal = |s: &TfSignal| serde_json::json!({"name": s.name, "unit": s.unit});
    let element = |i: usize, j: usize, e: &Element| {
        let (num, den) = (e.numerator(per), e.denominator(per));
        if num.iter().chain(&den).all(|c| c.is_finite()) {
            return Ok(serde_json::json!({
                "gain": e.gain,
                "num": num,
                "den": den,
                "dead_time": e.dead_time / per,
                "poles": e.poles().iter().map(|p| p * per).collect::<Vec<_>>(),
            }));
        }
        Err(IoError::Overflow {
            model: model.name.clone(),
            element: format!("{} ← {}", model.outputs[i].name, model.inputs[j].name),
            time_unit: unit.to_string(),
            order: e.lags.len() + e.leads.len(),
            slowest: e.lags.iter().chain(&e.leads).map(|t| t.abs()).fold(0.0, f64::max) / per,
        })
    };
    let elements: Vec<Vec<serde_json::Value>> = (0..model.outputs.len())
        .map(|i| {
            (0..model.inputs.len())
                .map(|j| model.element(i, j).map_or(Ok(zero_element()), |e| element(i, j, e)))
                .collect::<Result<_, _>>()
        })
        .collect::<Result<_, _>>()?;
    let mut poles: Vec<f64> = (0..model.outputs.len())
        .flat_map(|i| (0..model.inputs.len()).filter_map(move |j| model.element(i, j)))
        .flat_map(|e| e.poles())
        .map(|p| p * per)
        .collect();
    poles.sort_by(|a, b| b.total_cmp(a));
    poles.dedup();
    let mut doc = serde_json::json!({
        "name": model.name,
        "time_unit": unit,
        "inputs": model.inputs.iter().map(signal).collect::<Vec<_>>(),
        "outputs": model.outputs.iter().map(signal).collect::<Vec<_>>(),
        "steady_state_gain": plantwide_analysis::measures::rows(model.gain().as_ref()),
        "elements": elements,
        "poles": poles,
    });
    if let Some(f) = frequency {
        doc["frequency"] = serde_json::to_value(f).unwrap_or(serde_json::Value::Null);
    }
    Ok(doc)
}

#[cfg(test)]
mod tests {
    use faer::c64;

    use super::*;

    const TWO_BY_TWO: &str = r#"{
      "format_version": 1, "name": "t",
      "inputs": [{"name": "u1"}, {"name": "u2"}],
      "outputs": [{"name": "y1"}, {"name": "y2", "unit": "K"}],
      "disturbances": [{"name": "d"}],
      "elements": [
        {"output": "y1", "input": "u1", "gain": 2.0, "lags": ["10 s", 5], "leads": ["-3 s"], "dead_time": "2 s"},
        {"output": "y2", "input": "u2", "gain": -1.5},
        {"output": "y2", "input": "d", "gain": 0.5, "lags": ["1 min"]}
      ]
    }"#;

    #[test]
    fn elements_evaluate_their_transfer_functions() {
        let m = parse(TWO_BY_TWO, "t.tf.json").unwrap();
        let g = m.gain();
        assert_eq!((g[(0, 0)], g[(0, 1)], g[(1, 0)], g[(1, 1)]), (2.0, 0.0, 0.0, -1.5));
        assert_eq!(m.disturbance_gain()[(1, 0)], 0.5);
        // g11(jω) = 2 (1 − 3jω) e^(−2jω) / ((1 + 10jω)(1 + 5jω)) at ω = 0.1 rad/s.
        let w = 0.1;
        let exact = c64::new(1.0, -3.0 * w) * c64::new(0.0, -2.0 * w).exp() * 2.0
            / (c64::new(1.0, 10.0 * w) * c64::new(1.0, 5.0 * w));
        assert!((m.response(w)[(0, 0)] - exact).norm() < 1e-15);
        // |e^(−jωθ)| = 1 and the phase of the delay is −ωθ.
        let delay_only = Element { gain: 1.0, lags: vec![], leads: vec![], dead_time: 7.0 };
        assert!((delay_only.response(0.3).arg() - (-2.1)).abs() < 1e-14);
    }

    #[test]
    fn export_writes_a_missing_element_as_the_zero_transfer_function() {
        let m = parse(TWO_BY_TWO, "t.tf.json").unwrap();
        let doc = export(&m, ("s", 1.0), None).unwrap();
        assert!(!doc.to_string().contains("null"), "{doc}");
        let e = &doc["elements"][0][1];
        assert_eq!((e["gain"].as_f64(), e["num"][0].as_f64(), e["den"][0].as_f64()), (Some(0.0), Some(0.0), Some(1.0)));
        // y1 <- u1 = 2 (1 - 3s) / ((1 + 10s)(1 + 5s)): den 50 s^2 + 15 s + 1, poles -0.1 and -0.2.
        let g11 = &doc["elements"][0][0];
        assert_eq!(g11["den"], serde_json::json!([50.0, 15.0, 1.0]));
        assert_eq!(g11["num"], serde_json::json!([-6.0, 2.0]));
    }

    #[test]
    fn mistakes_are_reported_with_their_json_path() {
        let bad_input = TWO_BY_TWO.replace(r#""input": "u2""#, r#""input": "u3""#);
        let e = parse(&bad_input, "t.tf.json").unwrap_err().to_string();
        assert!(e.starts_with("t.tf.json: elements[1].input: no input or disturbance `u3`"), "{e}");
        let bad_lag = TWO_BY_TWO.replace(r#""lags": ["1 min"]"#, r#""lags": ["-1 min"]"#);
        let e = parse(&bad_lag, "t.tf.json").unwrap_err().to_string();
        assert!(e.contains("elements[2].lags[0]: a lag time constant must be positive"), "{e}");
        let bad_unit = TWO_BY_TWO.replace(r#""dead_time": "2 s""#, r#""dead_time": "2 K""#);
        let e = parse(&bad_unit, "t.tf.json").unwrap_err().to_string();
        assert!(e.contains("elements[0].dead_time: `2 K` is a temperature"), "{e}");
        let unknown = TWO_BY_TWO.replace(r#""gain": -1.5"#, r#""gain": -1.5, "gian": 1"#);
        let e = parse(&unknown, "t.tf.json").unwrap_err().to_string();
        assert!(e.contains("elements[1]") && e.contains("unknown field `gian`"), "{e}");
        let twice = TWO_BY_TWO.replace(r#"{"name": "d"}"#, r#"{"name": "u1"}"#);
        assert!(parse(&twice, "t").unwrap_err().to_string().contains("already used by inputs[0]"));
    }
}
