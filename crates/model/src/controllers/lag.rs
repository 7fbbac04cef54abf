//! First-order lag with an optional rate limit: a measurement lag (transmitter, thermowell,
//! sample line) when a controller reads its output `<lag>.op` as its measurement, or a valve
//! actuator when it reads a controller's output and drives the valve's input.
//!
//! Variable `op` (differential, units of the measurement):
//! `dop/dt = clamp((pv − op)/τ, −r, r)` with `τ` [s] the time constant and `r` the rate limit
//! (units of the measurement per second; default none). At steady state `op = pv`.
//! Declare a lag before the controller that reads its output, so that the measurement's dimension
//! is known when that controller is built.

use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::ControllerLinks;
use crate::{BuildCx, FieldError, InputSpec, Scalar, SignalSpec, UnitIo, UnitModel, VarSpec};

/// Flowsheet description of a first-order lag.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LagConfig {
    /// Variable path of the lagged signal, e.g. `"tank.level"` or `"lc.op"`.
    pub pv: String,
    /// Input driven by the lagged signal (valve actuator), e.g. `"tank.outflow"`; omit for a
    /// measurement lag read as `<lag>.op`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output: Option<String>,
    /// Time constant τ (e.g. `"10 s"`); > 0.
    pub tau: QuantityValue,
    /// Largest rate of change (units of the signal per time, e.g. `"0.1 kmol/min/min"`; default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_limit: Option<QuantityValue>,
}

impl super::ControllerConfig for LagConfig {
    fn paths(&self) -> super::ControllerPaths {
        let driven = self.output.iter().map(|o| ("output".to_string(), o.clone())).collect();
        super::ControllerPaths { measured: vec![("pv".to_string(), self.pv.clone())], driven }
    }
    fn op_dimension(&self, pv_dim: Dimension) -> Option<Dimension> {
        Some(pv_dim)
    }
}

/// A first-order lag.
#[derive(Debug, Clone)]
pub struct Lag {
    pv_path: String,
    tau: f64,
    rate: f64,
    dim: Dimension,
    scale: f64,
}

impl Lag {
    /// Build from the flowsheet description and the resolved links.
    pub fn build(c: &LagConfig, mut cx: BuildCx<'_>, links: &ControllerLinks) -> Result<Lag, Vec<FieldError>> {
        if links.op_dim != links.pv_dim {
            cx.error(
                "output",
                format!(
                    "the lagged signal is {} but the driven input is {}",
                    links.pv_dim.describe(),
                    links.op_dim.describe()
                ),
            );
        }
        let tau = cx.positive("tau", &c.tau, Dimension::TIME);
        let rate = c
            .rate_limit
            .as_ref()
            .map_or(f64::INFINITY, |r| cx.positive("rate_limit", r, links.pv_dim / Dimension::TIME));
        let scale = links.op_value.abs().max(links.pv_nominal.abs()).max(1e-6);
        cx.finish(Lag { pv_path: c.pv.clone(), tau, rate, dim: links.pv_dim, scale })
    }
}

impl UnitModel for Lag {
    fn type_name(&self) -> &'static str {
        "lag"
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        vec![VarSpec::differential("op", self.dim, self.scale)]
    }
    fn inputs(&self) -> Vec<InputSpec> {
        Vec::new()
    }
    fn signals(&self) -> Vec<SignalSpec> {
        vec![SignalSpec { role: "pv".into(), path: self.pv_path.clone() }]
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let rate = (io.signal(0) - io.var(0)) / self.tau;
        r[0] = if rate.re() > self.rate {
            S::from(self.rate)
        } else if rate.re() < -self.rate {
            S::from(-self.rate)
        } else {
            rate
        };
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        own[0] = io.signal(0);
    }
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    use super::*;
    use crate::testing::{binary_package, jacobian_error};
    use crate::{LocalLayout, StreamLayout, Unit};

    fn build(extra: serde_json::Value) -> Result<Lag, Vec<FieldError>> {
        let mut config = json!({"pv": "lc.op", "output": "valve.opening", "tau": "4 s"});
        if let (Some(c), Some(e)) = (config.as_object_mut(), extra.as_object()) {
            c.extend(e.clone());
        }
        let c: LagConfig = serde_json::from_value(config).expect("valid lag description");
        let thermo = binary_package();
        let comps = vec!["light".to_string(), "heavy".to_string()];
        let links = ControllerLinks {
            measured_dims: Vec::new(),
            driven: Vec::new(),
            pv_dim: Dimension::DIMENSIONLESS,
            op_dim: Dimension::DIMENSIONLESS,
            op_value: 0.5,
            pv_nominal: 0.5,
            measured_ranges: Vec::new(),
            driven_ranges: Vec::new(),
        };
        Lag::build(&c, BuildCx::new(&comps, &thermo, "controllers.actuator"), &links)
    }

    fn residual(u: &Lag, local: &[f64]) -> (f64, f64) {
        let layout = LocalLayout {
            stream: StreamLayout { n_comp: 2 },
            n_outlets: 0,
            n_internal: 1,
            n_inlets: 0,
            n_inputs: 0,
            n_signals: 1,
        };
        let thermo = binary_package();
        let mut r = [f64::NAN];
        Unit::residual(u, &UnitIo { local, layout: &layout, thermo: &thermo, time: 0.0 }, &mut r);
        (r[0], jacobian_error(u, &layout, &thermo, local, 1))
    }

    #[test]
    fn first_order_law_and_rate_limit() {
        let lag = build(json!({})).unwrap();
        // [op | pv]: dop/dt = (pv − op)/τ, zero at op = pv.
        let (r, jac) = residual(&lag, &[0.3, 0.7]);
        assert!((r - 0.1).abs() < 1e-15 && jac < 1e-7, "{r} {jac}");
        assert_eq!(residual(&lag, &[0.7, 0.7]).0, 0.0);
        let limited = build(json!({"rate_limit": "0.01 1/s"})).unwrap();
        let (r, jac) = residual(&limited, &[0.3, 0.7]);
        assert!((r - 0.01).abs() < 1e-15 && jac < 1e-7, "{r}");
        assert!((residual(&limited, &[0.7, 0.3]).0 + 0.01).abs() < 1e-15);
        assert!((residual(&limited, &[0.69, 0.7]).0 - 0.0025).abs() < 1e-15, "inside the limit: the lag law");
    }

    #[test]
    fn bad_time_constant_and_rate_are_reported_with_their_paths() {
        let errs = build(json!({"tau": "-1 s", "rate_limit": "3 K"})).unwrap_err();
        let paths: Vec<&str> = errs.iter().map(|e| e.path.as_str()).collect();
        assert_eq!(paths, ["controllers.actuator.tau", "controllers.actuator.rate_limit"]);
    }
}
