//! Splitter: divides one stream into `n` outlets of the inlet's state.
//!
//! Ports: inlet `in`, outlets `out1 … outN`. Inputs `split[k]` (k = 1 … N−1): the fraction of the
//! inlet flow sent to `outk`; the last outlet takes the rest, `1 − Σ split[k]`.
//!
//! Equations: `F_k = s_k F_in`, and `T, P, h, z` of every outlet equal to the inlet's.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use plantwide_units::Dimension;

use crate::stream::{F, H, P, T, Z0, copy_stream};
use crate::{BuildCx, FieldError, InputSpec, Scalar, UnitIo, UnitModel};

/// Flowsheet description of a splitter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SplitterConfig {
    /// Fractions of the inlet flow to `out1 … out(N−1)` (each in [0, 1], sum ≤ 1); the last outlet
    /// `outN` takes the rest. `N` is one more than the number of fractions given.
    pub fractions: Vec<f64>,
}

impl crate::registry::UnitConfig for SplitterConfig {
    fn ports() -> &'static str {
        "inlet `in`, outlets `out1`, `out2`, … (one more than `fractions` has entries)"
    }
}

/// A splitter.
#[derive(Debug, Clone)]
pub struct Splitter {
    fractions: Vec<f64>,
}

impl Splitter {
    /// Build from the flowsheet description.
    pub fn build(config: &SplitterConfig, mut cx: BuildCx<'_>, _links: ()) -> Result<Splitter, Vec<FieldError>> {
        if config.fractions.is_empty() {
            cx.error("fractions", "give at least one fraction (a splitter has at least two outlets)");
        }
        for (k, &s) in config.fractions.iter().enumerate() {
            cx.in_range(&format!("fractions[{k}]"), s, 0.0, 1.0);
        }
        let sum: f64 = config.fractions.iter().sum();
        if sum > 1.0 + 1e-12 {
            cx.error("fractions", format!("fractions sum to {sum} > 1: the last outlet would get a negative flow"));
        }
        cx.finish(Splitter { fractions: config.fractions.clone() })
    }
    fn n_out(&self) -> usize {
        self.fractions.len() + 1
    }
}

impl UnitModel for Splitter {
    fn type_name(&self) -> &'static str {
        "splitter"
    }
    fn inlet_ports(&self) -> Vec<String> {
        vec!["in".into()]
    }
    fn outlet_ports(&self) -> Vec<String> {
        (1..=self.n_out()).map(|k| format!("out{k}")).collect()
    }
    fn inputs(&self) -> Vec<InputSpec> {
        self.fractions
            .iter()
            .enumerate()
            .map(|(k, &s)| InputSpec { name: format!("split[{}]", k + 1), dim: Dimension::DIMENSIONLESS, value: s })
            .collect()
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let inlet = io.inlet(0);
        let len = io.layout.stream.len();
        let mut rest = S::from(1.0);
        for k in 0..self.n_out() {
            let s = if k + 1 < self.n_out() { io.input(k) } else { rest };
            rest -= s;
            copy_stream(io.outlet(k), inlet, s * inlet.f(), &mut r[k * len..(k + 1) * len]);
        }
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let inlet = io.inlet(0);
        let len = io.layout.stream.len();
        let mut rest = 1.0;
        for k in 0..self.n_out() {
            let s = if k + 1 < self.n_out() { io.input(k) } else { rest };
            rest -= s;
            let o = &mut own[k * len..(k + 1) * len];
            o[F] = s * inlet.f();
            o[T] = inlet.t();
            o[P] = inlet.p();
            o[H] = inlet.h();
            o[Z0..].copy_from_slice(inlet.z());
        }
    }
}
