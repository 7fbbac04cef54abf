//! Ratio station: the driven input follows a measured ("wild") variable in a set ratio, e.g. a
//! second feed kept at 0.5 mol per mol of the first, or a reboiler duty kept per mol of feed.
//!
//! `op = clamp(R · w + b, op_min, op_max)` where
//! - `w` is the wild measurement (signal 0) in its SI unit (mol/s for a molar flow),
//! - `R` is the ratio in SI output units per SI wild unit (mol/mol for flow to flow, J/mol for a
//!   duty per molar flow, W/K for a duty per temperature): the input `ratio`, or, with a remote
//!   ratio `{"from": "<ctrl>.op"}`, signal 1 (read as that SI ratio), so a master controller (e.g. a
//!   composition controller) can trim it,
//! - `b` is the bias in SI output units: the input `bias` (default 0).
//!
//! Variable: `op` (algebraic, the driven input's dimension). Inputs, in order: `ratio` (local ratio
//! only) and `bias`. Signals: `wild`, then `ratio.from` (remote ratio only). The station has no
//! dynamics; it is a static algebraic relation.

use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::ControllerLinks;
use super::clamp;
use crate::{BuildCx, FieldError, InputSpec, Scalar, SignalSpec, UnitIo, UnitModel, VarSpec};

/// A ratio: a value (an input `ratio` that analyses and scenarios may move) or another controller's
/// output (a remote ratio, trimmed by a master).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum RatioValue {
    /// A local ratio, output per wild measurement, e.g. `"0.5 mol/mol"`, `"40 kJ/mol"`, or a bare
    /// number in SI units (output SI unit per wild SI unit).
    Value(QuantityValue),
    /// A remote ratio: `{"from": "ac1.op"}`; the master's output is read as the SI ratio.
    Remote {
        /// Variable path of the master controller's output.
        from: String,
    },
}

/// Flowsheet description of a ratio station.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RatioConfig {
    /// Variable path of the wild (uncontrolled) measurement, e.g. `"s1.F"`.
    pub wild: String,
    /// Input driven by the station, e.g. `"feed2.F"` or `"reboiler.duty"`.
    pub output: String,
    /// Output per unit of the wild measurement (e.g. `"0.5 mol/mol"`, `"40 kJ/mol"`), or
    /// `{"from": "<master>.op"}`.
    pub ratio: RatioValue,
    /// Added to `ratio · wild`, in output units (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bias: Option<QuantityValue>,
    /// Lower output limit (default: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub op_min: Option<QuantityValue>,
    /// Upper output limit (default: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub op_max: Option<QuantityValue>,
}

impl super::ControllerConfig for RatioConfig {
    fn paths(&self) -> super::ControllerPaths {
        let mut measured = vec![("wild".to_string(), self.wild.clone())];
        if let RatioValue::Remote { from } = &self.ratio {
            measured.push(("ratio.from".to_string(), from.clone()));
        }
        super::ControllerPaths { measured, driven: vec![("output".to_string(), self.output.clone())] }
    }
}

/// A ratio station.
#[derive(Debug, Clone)]
pub struct Ratio {
    wild: String,
    remote: Option<String>,
    ratio: f64,
    bias: f64,
    op_min: f64,
    op_max: f64,
    links: ControllerLinks,
}

impl Ratio {
    /// Build from the flowsheet description and the resolved links (`pv_dim` is the wild
    /// measurement's dimension, `op_dim` the driven input's).
    pub fn build(c: &RatioConfig, mut cx: BuildCx<'_>, links: &ControllerLinks) -> Result<Ratio, Vec<FieldError>> {
        let ratio_dim = links.op_dim / links.pv_dim;
        let (remote, ratio) = match &c.ratio {
            RatioValue::Value(v) => {
                let why = format!(
                    "the ratio is output per wild measurement: `output` `{}` is {} and `wild` `{}` is {}, \
                     so the ratio needs {} (a bare number is taken in {})",
                    c.output,
                    links.op_dim.describe(),
                    c.wild,
                    links.pv_dim.describe(),
                    ratio_dim.describe(),
                    ratio_dim
                );
                (None, quantity_in(&mut cx, "ratio", v, ratio_dim, &why))
            }
            RatioValue::Remote { from } => (Some(from.clone()), f64::NAN),
        };
        let bias = c.bias.as_ref().map_or(0.0, |b| cx.quantity("bias", b, links.op_dim));
        let op_min = c.op_min.as_ref().map_or(f64::NEG_INFINITY, |v| cx.quantity("op_min", v, links.op_dim));
        let op_max = c.op_max.as_ref().map_or(f64::INFINITY, |v| cx.quantity("op_max", v, links.op_dim));
        if op_min >= op_max {
            cx.error("op_max", format!("must exceed op_min ({op_min} ≥ {op_max} in SI units)"));
        }
        cx.finish(Ratio { wild: c.wild.clone(), remote, ratio, bias, op_min, op_max, links: links.clone() })
    }

    fn ratio_and_bias<S: Scalar>(&self, io: &UnitIo<'_, S>) -> (S, S) {
        match self.remote {
            Some(_) => (io.signal(1), io.input(0)),
            None => (io.input(0), io.input(1)),
        }
    }

    fn output<S: Scalar>(&self, io: &UnitIo<'_, S>) -> S {
        let (ratio, bias) = self.ratio_and_bias(io);
        clamp(ratio * io.signal(0) + bias, self.op_min, self.op_max)
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

impl UnitModel for Ratio {
    fn type_name(&self) -> &'static str {
        "ratio"
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        let nominal = self.links.op_value.abs().max(self.bias.abs()).max(1e-6);
        vec![VarSpec::algebraic("op", self.links.op_dim, nominal)]
    }
    fn inputs(&self) -> Vec<InputSpec> {
        let mut v = Vec::new();
        if self.remote.is_none() {
            v.push(InputSpec { name: "ratio".into(), dim: self.links.op_dim / self.links.pv_dim, value: self.ratio });
        }
        v.push(InputSpec { name: "bias".into(), dim: self.links.op_dim, value: self.bias });
        v
    }
    fn signals(&self) -> Vec<SignalSpec> {
        let mut v = vec![SignalSpec { role: "wild".into(), path: self.wild.clone() }];
        if let Some(from) = &self.remote {
            v.push(SignalSpec { role: "ratio.from".into(), path: from.clone() });
        }
        v
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        r[0] = io.var(0) - self.output(io);
    }
    fn without_limits(&self) -> Option<Self> {
        let limited = self.op_min > f64::NEG_INFINITY || self.op_max < f64::INFINITY;
        limited.then(|| Ratio { op_min: f64::NEG_INFINITY, op_max: f64::INFINITY, ..self.clone() })
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let op = self.output(io);
        own[0] = if op.is_finite() { op } else { self.links.op_value };
    }
}

#[cfg(test)]
mod tests {
    use plantwide_units::Dimension;
    use serde_json::json;

    use super::*;
    use crate::ControllerSpec;
    use crate::testing::{binary_package, jacobian_error};
    use crate::testing::{controller_eval as eval, controller_layout as layout};

    fn links(pv_dim: Dimension, op_dim: Dimension) -> ControllerLinks {
        ControllerLinks {
            measured_dims: Vec::new(),
            driven: Vec::new(),
            pv_dim,
            op_dim,
            op_value: 3.0,
            pv_nominal: 1.0,
            measured_ranges: Vec::new(),
            driven_ranges: Vec::new(),
        }
    }

    fn build(config: serde_json::Value, links: &ControllerLinks) -> Result<Ratio, Vec<FieldError>> {
        let c: RatioConfig = serde_json::from_value(config).expect("valid ratio description");
        let thermo = binary_package();
        let comps = vec!["light".to_string(), "heavy".to_string()];
        Ratio::build(&c, BuildCx::new(&comps, &thermo, "controllers.fr"), links)
    }

    fn jac_err(u: &dyn crate::Unit, local: &[f64]) -> f64 {
        let layout = layout(u);
        jacobian_error(u, &layout, &binary_package(), local, layout.n_own())
    }

    #[test]
    fn output_is_ratio_times_wild_plus_bias() {
        let flow = links(Dimension::MOLAR_FLOW, Dimension::MOLAR_FLOW);
        let u = build(json!({"wild": "s1.F", "output": "feed2.F", "ratio": "0.5 mol/mol", "bias": "0.1 mol/s"}), &flow)
            .unwrap();
        assert_eq!(u.internal_vars()[0].name, "op");
        let names: Vec<_> = u.inputs().iter().map(|i| i.name.clone()).collect();
        assert_eq!(names, ["ratio", "bias"]);
        assert_eq!(u.inputs()[0].dim, Dimension::DIMENSIONLESS);
        // local = [op | ratio, bias | wild]
        let (r, guess) = eval(&u, &[0.0, 0.5, 0.1, 4.0]);
        assert!((guess[0] - 2.1).abs() < 1e-14);
        assert!((r[0] + 2.1).abs() < 1e-14);
        let (r, _) = eval(&u, &[2.1, 0.5, 0.1, 4.0]);
        assert!(r[0].abs() < 1e-14);
        // The ratio is an input: moving it moves the output.
        let (_, guess) = eval(&u, &[0.0, 0.75, 0.0, 4.0]);
        assert!((guess[0] - 3.0).abs() < 1e-14);
    }

    #[test]
    fn duty_per_flow_ratio_converts_units() {
        let duty = links(Dimension::MOLAR_FLOW, Dimension::POWER);
        let u = build(json!({"wild": "s1.F", "output": "reb.duty", "ratio": "40 kJ/mol"}), &duty).unwrap();
        assert_eq!(u.inputs()[0].value, 4.0e4);
        let (_, guess) = eval(&u, &[0.0, 4.0e4, 0.0, 2.0]);
        assert!((guess[0] - 8.0e4).abs() < 1e-9);
    }

    #[test]
    fn remote_ratio_reads_the_master_output() {
        let flow = links(Dimension::MOLAR_FLOW, Dimension::MOLAR_FLOW);
        let u = build(json!({"wild": "s1.F", "output": "feed2.F", "ratio": {"from": "ac.op"}}), &flow).unwrap();
        let paths = super::super::ControllerConfig::paths(
            &serde_json::from_value::<RatioConfig>(
                json!({"wild": "s1.F", "output": "feed2.F", "ratio": {"from": "ac.op"}}),
            )
            .unwrap(),
        );
        assert_eq!(
            paths.measured,
            [("wild".to_string(), "s1.F".to_string()), ("ratio.from".to_string(), "ac.op".to_string())]
        );
        let names: Vec<_> = u.inputs().iter().map(|i| i.name.clone()).collect();
        assert_eq!(names, ["bias"]);
        let roles: Vec<_> = u.signals().iter().map(|s| s.role.clone()).collect();
        assert_eq!(roles, ["wild", "ratio.from"]);
        // local = [op | bias | wild, ratio]
        let (_, guess) = eval(&u, &[0.0, 0.0, 4.0, 0.3]);
        assert!((guess[0] - 1.2).abs() < 1e-14);
        assert!(jac_err(&u, &[1.0, 0.2, 4.0, 0.3]) < 1e-7);
    }

    #[test]
    fn output_limits_clamp() {
        let flow = links(Dimension::MOLAR_FLOW, Dimension::MOLAR_FLOW);
        let u = build(
            json!({"wild": "s1.F", "output": "feed2.F", "ratio": 0.5, "op_min": 0.5, "op_max": "1 mol/s"}),
            &flow,
        )
        .unwrap();
        let (_, guess) = eval(&u, &[0.0, 0.5, 0.0, 4.0]);
        assert_eq!(guess[0], 1.0);
        let (_, guess) = eval(&u, &[0.0, 0.5, 0.0, 0.2]);
        assert_eq!(guess[0], 0.5);
        // Saturated: the output no longer depends on the wild flow or the ratio.
        let thermo = binary_package();
        let layout = layout(&u);
        let local = [1.0, 0.5, 0.0, 4.0];
        let mut r = [0.0];
        let mut jac = [0.0; 4];
        (&u as &dyn crate::Unit).jacobian(
            &UnitIo { local: &local, layout: &layout, thermo: &thermo, time: 0.0 },
            &mut r,
            &mut jac,
        );
        assert_eq!(jac, [1.0, 0.0, 0.0, 0.0]);
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let flow = links(Dimension::MOLAR_FLOW, Dimension::MOLAR_FLOW);
        let u = build(json!({"wild": "s1.F", "output": "feed2.F", "ratio": 0.5, "bias": 0.1}), &flow).unwrap();
        assert!(jac_err(&u, &[1.7, 0.5, 0.1, 4.0]) < 1e-7);
        let limited = build(json!({"wild": "s1.F", "output": "feed2.F", "ratio": 0.5, "op_max": 10.0}), &flow).unwrap();
        assert!(jac_err(&limited, &[1.7, 0.5, 0.1, 4.0]) < 1e-7);
    }

    #[test]
    fn temperature_wild_with_flow_output_reports_the_dimension_mismatch() {
        let mixed = links(Dimension::TEMPERATURE, Dimension::MOLAR_FLOW);
        let errs = build(json!({"wild": "s1.T", "output": "feed2.F", "ratio": "0.5 mol/mol"}), &mixed).unwrap_err();
        assert_eq!(errs.len(), 1, "{errs:?}");
        assert_eq!(errs[0].path, "controllers.fr.ratio");
        let m = &errs[0].message;
        assert!(m.contains("`0.5 mol/mol`"), "{m}");
        assert!(m.contains("`wild` `s1.T` is a temperature"), "{m}");
        assert!(m.contains("`output` `feed2.F` is a molar flow"), "{m}");
    }

    #[test]
    fn bad_bias_and_limits_are_reported() {
        let flow = links(Dimension::MOLAR_FLOW, Dimension::MOLAR_FLOW);
        let errs = build(
            json!({"wild": "s1.F", "output": "feed2.F", "ratio": 0.5, "bias": "3 K", "op_min": 2.0, "op_max": 1.0}),
            &flow,
        )
        .unwrap_err();
        let paths: Vec<_> = errs.iter().map(|e| e.path.as_str()).collect();
        assert_eq!(paths, ["controllers.fr.bias", "controllers.fr.op_max"]);
    }

    #[test]
    fn unknown_fields_are_rejected_and_the_registry_knows_the_type() {
        assert!(
            serde_json::from_value::<RatioConfig>(json!({"wild": "a.F", "output": "b.F", "ratio": 1.0, "gain": 2}))
                .is_err()
        );
        let spec: ControllerSpec =
            serde_json::from_value(json!({"type": "ratio", "wild": "a.F", "output": "b.F", "ratio": "2 mol/mol"}))
                .unwrap();
        assert_eq!(spec.type_name(), "ratio");
    }
}
