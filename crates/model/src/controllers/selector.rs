//! High/low selector (override control): the driven input takes the lowest (or highest) of several
//! signals, usually the outputs of a normal controller and of one or more constraint controllers,
//! e.g. a feed valve held by a flow controller unless a pressure controller asks for less.
//!
//! `op = min_k s_k` (`"kind": "low"`) or `op = max_k s_k` (`"kind": "high"`), `s_k` being signal `k`
//! (the variable at `inputs[k]`, typically `<ctrl>.op`) in the driven input's SI unit. The min/max
//! is exact, not smoothed: dual numbers follow the selected signal (on a tie, the first listed),
//! so Newton and the linearization see the active loop only.
//!
//! Variable: `op` (algebraic, the driven input's dimension). No inputs. Signals: `inputs[k]`.
//!
//! # Windup of the controllers that are not selected
//! A PI controller whose output is not selected keeps integrating its error: dynamically it winds
//! up, and at steady state its integral equation `dI/dt = e = 0` cannot hold together with the
//! selected loop's, so the steady state has no solution. Give each controller behind a selector
//! an output limit on the side it is deselected from — `op_max` behind a low selector, `op_min`
//! behind a high selector (e.g. the normal operating limit of the valve). The deselected
//! controller then saturates there, where its back-calculation anti-windup stops the integral
//! (`dI/dt = (op_max − bias)/Kc − I/τ_I = 0` with `e ≠ 0`), a steady state exists, and the
//! controller takes over as soon as its proportional action drops its output below the selected
//! one. External reset feedback — each PID tracking the *selected* output (`"tracking": true`) —
//! is not implemented.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::ControllerLinks;
use crate::{BuildCx, FieldError, Scalar, SignalSpec, UnitIo, UnitModel, VarSpec};

/// Which signal a selector passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum SelectorKind {
    /// The lowest signal (low select).
    Low,
    /// The highest signal (high select).
    High,
}

/// Flowsheet description of a high/low selector.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SelectorConfig {
    /// `"low"` (minimum) or `"high"` (maximum).
    pub kind: SelectorKind,
    /// Variable paths of the signals, at least two, e.g. `["fc1.op", "pc1.op"]`; they must have the
    /// driven input's dimension.
    pub inputs: Vec<String>,
    /// Input driven by the selected signal, e.g. `"feed.F"`.
    pub output: String,
}

impl super::ControllerConfig for SelectorConfig {
    fn paths(&self) -> super::ControllerPaths {
        let measured = self.inputs.iter().enumerate().map(|(k, p)| (format!("inputs[{k}]"), p.clone())).collect();
        super::ControllerPaths { measured, driven: vec![("output".to_string(), self.output.clone())] }
    }
}

/// A high/low selector.
#[derive(Debug, Clone)]
pub struct Selector {
    kind: SelectorKind,
    inputs: Vec<String>,
    links: ControllerLinks,
}

impl Selector {
    /// Build from the flowsheet description and the resolved links (`pv_dim` is the first signal's
    /// dimension, `op_dim` the driven input's; the flowsheet resolves only the first signal's).
    pub fn build(
        c: &SelectorConfig,
        mut cx: BuildCx<'_>,
        links: &ControllerLinks,
    ) -> Result<Selector, Vec<FieldError>> {
        if c.inputs.len() < 2 {
            cx.error(
                "inputs",
                format!(
                    "a selector needs at least two signals (got {}), e.g. [\"fc1.op\", \"pc1.op\"]",
                    c.inputs.len()
                ),
            );
        }
        if let Some(first) = c.inputs.first()
            && links.pv_dim != links.op_dim
        {
            cx.error(
                "inputs[0]",
                format!(
                    "`{first}` is {} ({}) but the driven input `{}` is {} ({}): \
                     a selector passes a signal through unchanged",
                    links.pv_dim.describe(),
                    links.pv_dim,
                    c.output,
                    links.op_dim.describe(),
                    links.op_dim
                ),
            );
        }
        cx.finish(Selector { kind: c.kind, inputs: c.inputs.clone(), links: links.clone() })
    }

    /// Index of the selected signal (the first on a tie, or if any value is NaN the first such).
    fn selected<S: Scalar>(&self, io: &UnitIo<'_, S>) -> usize {
        let mut best = 0;
        for k in 1..self.inputs.len() {
            let (v, b) = (io.signal(k).re(), io.signal(best).re());
            let better = match self.kind {
                SelectorKind::Low => v < b,
                SelectorKind::High => v > b,
            };
            if better {
                best = k;
            }
        }
        best
    }
}

impl UnitModel for Selector {
    fn type_name(&self) -> &'static str {
        "selector"
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        vec![VarSpec::algebraic("op", self.links.op_dim, self.links.op_value.abs().max(1e-6))]
    }
    fn signals(&self) -> Vec<SignalSpec> {
        self.inputs
            .iter()
            .enumerate()
            .map(|(k, p)| SignalSpec { role: format!("inputs[{k}]"), path: p.clone() })
            .collect()
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        r[0] = if self.inputs.is_empty() { io.var(0) } else { io.var(0) - io.signal(self.selected(io)) };
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let op = if self.inputs.is_empty() { f64::NAN } else { io.signal(self.selected(io)) };
        own[0] = if op.is_finite() { op } else { self.links.op_value };
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
            op_value: 2.0,
            pv_nominal: 1.0,
            measured_ranges: Vec::new(),
            driven_ranges: Vec::new(),
        }
    }

    fn build(config: serde_json::Value, links: &ControllerLinks) -> Result<Selector, Vec<FieldError>> {
        let c: SelectorConfig = serde_json::from_value(config).expect("valid selector description");
        let thermo = binary_package();
        let comps = vec!["light".to_string(), "heavy".to_string()];
        Selector::build(&c, BuildCx::new(&comps, &thermo, "controllers.sel"), links)
    }

    /// Guess and the local Jacobian row at `local = [op | signals]`.
    fn eval(u: &dyn crate::Unit, local: &[f64]) -> (f64, f64, Vec<f64>) {
        let thermo = binary_package();
        let layout = layout(u);
        let io = UnitIo { local, layout: &layout, thermo: &thermo, time: 0.0 };
        let mut own = [0.0];
        u.guess(&io, &mut own);
        let mut r = [0.0];
        let mut jac = vec![0.0; local.len()];
        u.jacobian(&io, &mut r, &mut jac);
        (own[0], r[0], jac)
    }

    fn three(kind: &str) -> Selector {
        let flow = links(Dimension::MOLAR_FLOW, Dimension::MOLAR_FLOW);
        build(json!({"kind": kind, "inputs": ["fc.op", "pc.op", "lc.op"], "output": "feed.F"}), &flow).unwrap()
    }

    #[test]
    fn low_selector_picks_the_minimum() {
        let u = three("low");
        assert_eq!(u.internal_vars()[0].name, "op");
        assert!(u.inputs().is_empty());
        let roles: Vec<_> = u.signals().iter().map(|s| s.role.clone()).collect();
        assert_eq!(roles, ["inputs[0]", "inputs[1]", "inputs[2]"]);
        let (g, r, jac) = eval(&u, &[0.0, 3.0, 1.5, 2.0]);
        assert_eq!(g, 1.5);
        assert_eq!(r, -1.5);
        assert_eq!(jac, [1.0, 0.0, -1.0, 0.0]);
        let (g, _, jac) = eval(&u, &[1.0, 1.0, 1.5, 0.5]);
        assert_eq!(g, 0.5);
        assert_eq!(jac, [1.0, 0.0, 0.0, -1.0]);
    }

    #[test]
    fn high_selector_picks_the_maximum() {
        let u = three("high");
        let (g, r, jac) = eval(&u, &[3.0, 3.0, 1.5, 2.0]);
        assert_eq!(g, 3.0);
        assert_eq!(r, 0.0);
        assert_eq!(jac, [1.0, -1.0, 0.0, 0.0]);
        // A tie selects the first listed.
        let (g, _, jac) = eval(&u, &[0.0, 1.0, 2.0, 2.0]);
        assert_eq!(g, 2.0);
        assert_eq!(jac, [1.0, 0.0, -1.0, 0.0]);
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        for kind in ["low", "high"] {
            let u = three(kind);
            let layout = layout(&u);
            for local in [[1.0, 3.0, 1.5, 2.0], [0.7, 0.4, 1.5, 0.9], [2.0, 0.4, 0.5, 2.5]] {
                assert!(jacobian_error(&u, &layout, &binary_package(), &local, 1) < 1e-7, "{kind} {local:?}");
            }
        }
    }

    #[test]
    fn wrong_dimension_and_too_few_inputs_are_reported() {
        let mixed = links(Dimension::TEMPERATURE, Dimension::MOLAR_FLOW);
        let errs = build(json!({"kind": "low", "inputs": ["tc.op"], "output": "feed.F"}), &mixed).unwrap_err();
        let paths: Vec<_> = errs.iter().map(|e| e.path.as_str()).collect();
        assert_eq!(paths, ["controllers.sel.inputs", "controllers.sel.inputs[0]"]);
        assert!(errs[1].message.contains("`tc.op` is a temperature"), "{}", errs[1].message);
        assert!(errs[1].message.contains("`feed.F` is a molar flow"), "{}", errs[1].message);
    }

    #[test]
    fn registry_knows_the_type() {
        let spec: ControllerSpec = serde_json::from_value(
            json!({"type": "selector", "kind": "high", "inputs": ["a.op", "b.op"], "output": "v.opening"}),
        )
        .unwrap();
        assert_eq!(spec.type_name(), "selector");
        assert!(
            serde_json::from_value::<SelectorConfig>(
                json!({"kind": "mid", "inputs": ["a.op", "b.op"], "output": "v.opening"})
            )
            .is_err()
        );
        assert!(
            serde_json::from_value::<SelectorConfig>(
                json!({"kind": "low", "inputs": ["a.op", "b.op"], "output": "v.opening", "tracking": true})
            )
            .is_err()
        );
    }
}
