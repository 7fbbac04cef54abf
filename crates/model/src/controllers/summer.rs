//! Feedforward summer: a bias plus gains times the deviations of measured signals from their
//! references, e.g. a steam duty moved with the feed flow (feedforward) plus a temperature
//! controller's output (feedback trim).
//!
//! `op = clamp(b + Σ_k K_k · (s_k − s_k,ref), op_min, op_max)` where
//! - `s_k` is signal `k` (the variable at `inputs[k].path`, possibly another controller's `op`) in
//!   its SI unit,
//! - `K_k` is its gain in SI output units per SI signal unit (`inputs[k].gain`; dimension
//!   `output / signal`, e.g. J/mol for a duty per molar flow, 1 for a feedback controller whose output
//!   has the driven input's dimension),
//! - `s_k,ref` is its reference (`inputs[k].reference`, default 0), the signal value at which the
//!   term contributes nothing (the design point of a feedforward),
//! - `b` is the bias in SI output units: the input `bias`, default the driven input's value in the
//!   flowsheet (bumpless: at the references the output equals the flowsheet value).
//!
//! Variable: `op` (algebraic, the driven input's dimension). Input: `bias`. Signals: one per entry
//! of `inputs`, roles `inputs[k].path`. No dynamics (add lead-lag dynamics upstream if needed).
//!
//! Dimension checks: the flowsheet resolves the dimension of the first signal only
//! ([`ControllerLinks::pv_dim`]), so `inputs[0].gain` and `inputs[0].reference` are checked against
//! it. For `k ≥ 1` the signal's dimension is taken from the gain's unit (`output / gain`) when the
//! gain is written with a unit, and the reference must agree with it; a bare-number gain is taken
//! as SI as written.

use plantwide_units::{Dimension, QuantityValue, parse_quantity};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::ControllerLinks;
use super::clamp;
use crate::{BuildCx, FieldError, InputSpec, Scalar, SignalSpec, UnitIo, UnitModel, VarSpec};

/// One term of a summer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SummerInput {
    /// Variable path of the signal, e.g. `"s1.F"` or `"tc1.op"`.
    pub path: String,
    /// Output per unit of the signal, e.g. `"30 kJ/mol"` (duty per feed flow) or `1` (a feedback
    /// controller's output); a bare number is in SI units (output SI unit per signal SI unit).
    pub gain: QuantityValue,
    /// Signal value at which this term is zero (default 0), e.g. the design feed flow `"1 kmol/min"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<QuantityValue>,
}

/// Flowsheet description of a feedforward summer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SummerConfig {
    /// The terms `gain · (signal − reference)`; at least one.
    pub inputs: Vec<SummerInput>,
    /// Output when every signal sits at its reference; default: the driven input's value in the
    /// flowsheet (bumpless start).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bias: Option<QuantityValue>,
    /// Input driven by the summer, e.g. `"reboiler.duty"`.
    pub output: String,
    /// Lower output limit (default: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub op_min: Option<QuantityValue>,
    /// Upper output limit (default: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub op_max: Option<QuantityValue>,
}

impl super::ControllerConfig for SummerConfig {
    fn paths(&self) -> super::ControllerPaths {
        let measured =
            self.inputs.iter().enumerate().map(|(k, i)| (format!("inputs[{k}].path"), i.path.clone())).collect();
        super::ControllerPaths { measured, driven: vec![("output".to_string(), self.output.clone())] }
    }
}

/// A feedforward summer.
#[derive(Debug, Clone)]
pub struct Summer {
    paths: Vec<String>,
    gains: Vec<f64>,
    references: Vec<f64>,
    bias: f64,
    op_min: f64,
    op_max: f64,
    links: ControllerLinks,
}

impl Summer {
    /// Build from the flowsheet description and the resolved links (`pv_dim` is the first signal's
    /// dimension, `op_dim` the driven input's).
    pub fn build(c: &SummerConfig, mut cx: BuildCx<'_>, links: &ControllerLinks) -> Result<Summer, Vec<FieldError>> {
        if c.inputs.is_empty() {
            cx.error(
                "inputs",
                "give at least one term, \
                 e.g. [{\"path\": \"s1.F\", \"gain\": \"30 kJ/mol\", \"reference\": \"1 kmol/min\"}]",
            );
        }
        let mut gains = Vec::with_capacity(c.inputs.len());
        let mut references = Vec::with_capacity(c.inputs.len());
        for (k, input) in c.inputs.iter().enumerate() {
            let (gain, reference) = term(&mut cx, k, input, c, links);
            gains.push(gain);
            references.push(reference);
        }
        let bias = c.bias.as_ref().map_or(links.op_value, |b| cx.quantity("bias", b, links.op_dim));
        let op_min = c.op_min.as_ref().map_or(f64::NEG_INFINITY, |v| cx.quantity("op_min", v, links.op_dim));
        let op_max = c.op_max.as_ref().map_or(f64::INFINITY, |v| cx.quantity("op_max", v, links.op_dim));
        if op_min >= op_max {
            cx.error("op_max", format!("must exceed op_min ({op_min} ≥ {op_max} in SI units)"));
        }
        let paths = c.inputs.iter().map(|i| i.path.clone()).collect();
        cx.finish(Summer { paths, gains, references, bias, op_min, op_max, links: links.clone() })
    }

    fn output<S: Scalar>(&self, io: &UnitIo<'_, S>) -> S {
        let mut u = io.input(0);
        for (k, (&g, &s_ref)) in self.gains.iter().zip(&self.references).enumerate() {
            u += (io.signal(k) - s_ref) * g;
        }
        clamp(u, self.op_min, self.op_max)
    }
}

/// Gain and reference of term `k` in SI units, with their dimensions checked where known.
fn term(cx: &mut BuildCx<'_>, k: usize, input: &SummerInput, c: &SummerConfig, links: &ControllerLinks) -> (f64, f64) {
    let gain_field = format!("inputs[{k}].gain");
    let ref_field = format!("inputs[{k}].reference");
    // The signal's dimension: resolved by the flowsheet for the first term, implied by the gain's
    // unit (or else the reference's unit) for the others.
    let signal_dim = if k == 0 {
        Some(links.pv_dim)
    } else {
        unit_dimension_of(&input.gain)
            .map(|g| links.op_dim / g)
            .or_else(|| input.reference.as_ref().and_then(unit_dimension_of))
    };
    let Some(signal_dim) = signal_dim else {
        // Bare numbers throughout: SI values as written.
        let gain = cx.quantity(&gain_field, &input.gain, Dimension::DIMENSIONLESS);
        let reference = input.reference.as_ref().map_or(0.0, |r| cx.quantity(&ref_field, r, Dimension::DIMENSIONLESS));
        return (gain, reference);
    };
    let gain_dim = links.op_dim / signal_dim;
    let why = format!(
        "a gain is output per signal: `output` `{}` is {} and `{}` is {}, \
         so the gain needs {} (a bare number is taken in {})",
        c.output,
        links.op_dim.describe(),
        input.path,
        signal_dim.describe(),
        gain_dim.describe(),
        gain_dim
    );
    let gain = quantity_in(cx, &gain_field, &input.gain, gain_dim, &why);
    let reference = input.reference.as_ref().map_or(0.0, |r| {
        let why = format!("the reference is a value of `{}`, {}", input.path, signal_dim.describe());
        quantity_in(cx, &ref_field, r, signal_dim, &why)
    });
    (gain, reference)
}

/// The dimension of a quantity written with a unit; `None` for a bare number (JSON or text) or an
/// unparsable text (reported when it is converted).
fn unit_dimension_of(value: &QuantityValue) -> Option<Dimension> {
    match value {
        QuantityValue::Number(_) => None,
        QuantityValue::Text(t) if t.trim().parse::<f64>().is_ok() => None,
        QuantityValue::Text(t) => parse_quantity(t).ok().map(|q| q.dim),
    }
}

/// Convert `value` to SI in `dim`, adding `why` (where the dimension comes from) to a failure.
fn quantity_in(cx: &mut BuildCx<'_>, field: &str, value: &QuantityValue, dim: Dimension, why: &str) -> f64 {
    let before = cx.errors.len();
    let v = cx.quantity(field, value, dim);
    if cx.errors.len() > before
        && let Some(e) = cx.errors.last_mut()
    {
        e.message = format!("{}; {why}", e.message);
    }
    v
}

impl UnitModel for Summer {
    fn type_name(&self) -> &'static str {
        "summer"
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        let nominal = self.links.op_value.abs().max(self.bias.abs()).max(1e-6);
        vec![VarSpec::algebraic("op", self.links.op_dim, nominal)]
    }
    fn inputs(&self) -> Vec<InputSpec> {
        vec![InputSpec { name: "bias".into(), dim: self.links.op_dim, value: self.bias }]
    }
    fn signals(&self) -> Vec<SignalSpec> {
        self.paths
            .iter()
            .enumerate()
            .map(|(k, p)| SignalSpec { role: format!("inputs[{k}].path"), path: p.clone() })
            .collect()
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        r[0] = io.var(0) - self.output(io);
    }
    fn without_limits(&self) -> Option<Self> {
        let limited = self.op_min > f64::NEG_INFINITY || self.op_max < f64::INFINITY;
        limited.then(|| Summer { op_min: f64::NEG_INFINITY, op_max: f64::INFINITY, ..self.clone() })
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let op = self.output(io);
        own[0] = if op.is_finite() { op } else { io.input(0) };
    }
}

#[cfg(test)]
mod tests {
    use plantwide_units::Dimension;
    use serde_json::json;

    use super::*;
    use crate::ControllerSpec;
    use crate::testing::controller_layout as layout;
    use crate::testing::{binary_package, jacobian_error};

    fn links(pv_dim: Dimension, op_dim: Dimension) -> ControllerLinks {
        ControllerLinks {
            measured_dims: Vec::new(),
            driven: Vec::new(),
            pv_dim,
            op_dim,
            op_value: 1.0e6,
            pv_nominal: 1.0,
            measured_ranges: Vec::new(),
            driven_ranges: Vec::new(),
        }
    }

    fn build(config: serde_json::Value, links: &ControllerLinks) -> Result<Summer, Vec<FieldError>> {
        let c: SummerConfig = serde_json::from_value(config).expect("valid summer description");
        let thermo = binary_package();
        let comps = vec!["light".to_string(), "heavy".to_string()];
        Summer::build(&c, BuildCx::new(&comps, &thermo, "controllers.ff"), links)
    }

    /// Residuals and guess at `local = [op | bias | signals]`.
    fn eval(u: &dyn crate::Unit, local: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let thermo = binary_package();
        let layout = layout(u);
        assert_eq!(layout.len(), local.len());
        let io = UnitIo { local, layout: &layout, thermo: &thermo, time: 0.0 };
        let mut r = vec![0.0; layout.n_own()];
        u.residual(&io, &mut r);
        let mut own = local[..layout.n_own()].to_vec();
        u.guess(&io, &mut own);
        (r, own)
    }

    fn jac_err(u: &dyn crate::Unit, local: &[f64]) -> f64 {
        let layout = layout(u);
        jacobian_error(u, &layout, &binary_package(), local, layout.n_own())
    }

    /// Duty = bias + 30 kJ/mol · (F − 20 mol/s) + 2 kW/K · (T − 350 K) + 1 · (tc1.op).
    fn duty_summer() -> Summer {
        let l = links(Dimension::MOLAR_FLOW, Dimension::POWER);
        build(
            json!({
                "inputs": [
                    {"path": "s1.F", "gain": "30 kJ/mol", "reference": "1.2 kmol/min"},
                    {"path": "s1.T", "gain": "2 kW/K", "reference": "76.85 degC"},
                    {"path": "tc1.op", "gain": "1 W/W"}
                ],
                "output": "reb.duty"
            }),
            &l,
        )
        .unwrap()
    }

    #[test]
    fn output_is_the_bias_plus_weighted_deviations() {
        let u = duty_summer();
        assert_eq!(u.internal_vars()[0].name, "op");
        assert_eq!(u.internal_vars()[0].dim, Dimension::POWER);
        assert_eq!(u.inputs()[0].name, "bias");
        assert_eq!(u.inputs()[0].value, 1.0e6, "default bias is the driven input's flowsheet value");
        assert!((u.references[0] - 20.0).abs() < 1e-12);
        assert!((u.references[1] - 350.0).abs() < 1e-9);
        let roles: Vec<_> = u.signals().iter().map(|s| s.role.clone()).collect();
        assert_eq!(roles, ["inputs[0].path", "inputs[1].path", "inputs[2].path"]);
        // At the references and zero trim: the bias.
        let (_, g) = eval(&u, &[0.0, 1.0e6, 20.0, 350.0, 0.0]);
        assert!((g[0] - 1.0e6).abs() < 1e-6);
        // 1e6 + 3e4·(22 − 20) + 2e3·(345 − 350) + 5e3 = 1.055e6.
        let (_, g) = eval(&u, &[0.0, 1.0e6, 22.0, 345.0, 5.0e3]);
        assert!((g[0] - 1.055e6).abs() < 1e-6, "{}", g[0]);
        let (r, _) = eval(&u, &[1.055e6, 1.0e6, 22.0, 345.0, 5.0e3]);
        assert!(r[0].abs() < 1e-6);
    }

    #[test]
    fn explicit_bias_and_limits() {
        let l = links(Dimension::MOLAR_FLOW, Dimension::MOLAR_FLOW);
        let u =
            build(json!({"inputs": [{"path": "s1.F", "gain": 0.5}], "bias": 1.0, "output": "f2.F", "op_max": 3.0}), &l)
                .unwrap();
        let (_, g) = eval(&u, &[0.0, 1.0, 2.0]);
        assert!((g[0] - 2.0).abs() < 1e-14);
        let (_, g) = eval(&u, &[0.0, 1.0, 10.0]);
        assert_eq!(g[0], 3.0);
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let u = duty_summer();
        assert!(jac_err(&u, &[1.0e6, 1.0e6, 22.0, 345.0, 5.0e3]) < 1e-7);
        let l = links(Dimension::MOLAR_FLOW, Dimension::MOLAR_FLOW);
        let limited =
            build(json!({"inputs": [{"path": "s1.F", "gain": 0.5}], "bias": 1.0, "output": "f2.F", "op_max": 3.0}), &l)
                .unwrap();
        assert!(jac_err(&limited, &[2.0, 1.0, 2.0]) < 1e-7);
        assert!(jac_err(&limited, &[3.0, 1.0, 10.0]) < 1e-7);
    }

    #[test]
    fn gain_with_the_wrong_dimension_is_reported() {
        let l = links(Dimension::TEMPERATURE, Dimension::MOLAR_FLOW);
        let errs =
            build(json!({"inputs": [{"path": "s1.T", "gain": "0.5 mol/mol"}], "output": "f2.F"}), &l).unwrap_err();
        assert_eq!(errs.len(), 1, "{errs:?}");
        assert_eq!(errs[0].path, "controllers.ff.inputs[0].gain");
        assert!(errs[0].message.contains("`s1.T` is a temperature"), "{}", errs[0].message);
        assert!(errs[0].message.contains("`output` `f2.F` is a molar flow"), "{}", errs[0].message);
    }

    #[test]
    fn reference_must_agree_with_the_gain() {
        let l = links(Dimension::MOLAR_FLOW, Dimension::POWER);
        let errs = build(
            json!({
                "inputs": [
                    {"path": "s1.F", "gain": "30 kJ/mol", "reference": "3 K"},
                    {"path": "s1.T", "gain": "2 kW/K", "reference": "1 mol/s"}
                ],
                "output": "reb.duty"
            }),
            &l,
        )
        .unwrap_err();
        let paths: Vec<_> = errs.iter().map(|e| e.path.as_str()).collect();
        assert_eq!(paths, ["controllers.ff.inputs[0].reference", "controllers.ff.inputs[1].reference"]);
        assert!(errs[1].message.contains("a temperature"), "{}", errs[1].message);
    }

    #[test]
    fn empty_inputs_are_reported() {
        let l = links(Dimension::MOLAR_FLOW, Dimension::POWER);
        let errs = build(json!({"inputs": [], "output": "reb.duty"}), &l).unwrap_err();
        assert_eq!(errs[0].path, "controllers.ff.inputs");
    }

    #[test]
    fn unknown_fields_are_rejected_and_the_registry_knows_the_type() {
        assert!(
            serde_json::from_value::<SummerConfig>(
                json!({"inputs": [{"path": "a.F", "gain": 1, "ref": 2}], "output": "b.F"})
            )
            .is_err()
        );
        let spec: ControllerSpec =
            serde_json::from_value(json!({"type": "summer", "inputs": [{"path": "a.F", "gain": 1}], "output": "b.F"}))
                .unwrap();
        assert_eq!(spec.type_name(), "summer");
        let paths = spec.config().paths();
        assert_eq!(paths.measured, [("inputs[0].path".to_string(), "a.F".to_string())]);
    }
}
