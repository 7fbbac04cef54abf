//! Split range: one controller output drives two inputs in sequence, e.g. a pressure controller
//! that first closes a vent and then opens a nitrogen make-up valve, or a temperature controller on
//! cooling water below mid-range and steam above it.
//!
//! The signal `s` (signal 0, usually `<ctrl>.op`) is normalised over `signal_range = [s_lo, s_hi]`
//! (default `[0, 1]` in the signal's SI unit) and limited to `[0, 1]`:
//! `σ = clamp((s − s_lo)/(s_hi − s_lo), 0, 1)`. With the split point `σ_s = split` (default 0.5):
//! - output 1 moves over `σ ∈ [0, σ_s]`: `f₁ = σ/σ_s`, and holds its end value above `σ_s`;
//! - output 2 moves over `σ ∈ [σ_s, 1]`: `f₂ = (σ − σ_s)/(1 − σ_s)`, and holds its start value
//!   below `σ_s`;
//! - `op_k = lo_k + (hi_k − lo_k)·f_k` for an `increasing` output, `op_k = hi_k − (hi_k − lo_k)·f_k`
//!   for a `decreasing` one, with `ranges[k] = [lo_k, hi_k]` in the output's SI unit (default
//!   `[0, 1]` for dimensionless outputs such as valve openings; required otherwise).
//!
//! The default directions `["increasing", "increasing"]` are sequential (staged) valves: valve 1
//! opens over the first part of the signal, then valve 2. `["decreasing", "increasing"]` is the
//! exclusive heat/cool or vent/make-up arrangement: output 1 closes as the signal rises to the
//! split, then output 2 opens; at the split both sit at their `lo`.
//!
//! Variables: `op` (output 1, drives `outputs[0]`) and `op2` (output 2, drives `outputs[1]`), both
//! algebraic. No inputs. Signal: `signal`. The map is piecewise linear; dual numbers follow the
//! active piece, and at a breakpoint the moving one (at the split both outputs carry their slope).
//!
//! Dimensions: `signal_range` has the signal's dimension and `ranges[0]` output 1's, both resolved
//! by the flowsheet. Output 2's dimension is taken from the unit of `ranges[1]` when written with
//! one (e.g. `["0 W", "2 MW"]`), and is otherwise assumed equal to output 1's.

use plantwide_units::{Dimension, QuantityValue, parse_quantity};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::ControllerLinks;
use super::clamp;
use crate::{BuildCx, FieldError, Scalar, SignalSpec, UnitIo, UnitModel, VarSpec};

/// How an output moves over its part of the signal.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// From `lo` to `hi` as the signal rises.
    #[default]
    Increasing,
    /// From `hi` to `lo` as the signal rises.
    Decreasing,
}

/// Flowsheet description of a split-range block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SplitRangeConfig {
    /// Variable path of the signal split, usually a controller's output, e.g. `"pc1.op"`.
    pub signal: String,
    /// The two driven inputs, e.g. `["vent.opening", "n2.opening"]`: the first acts on the low part
    /// of the signal, the second on the high part.
    pub outputs: [String; 2],
    /// Split point as a fraction of the signal range, in (0, 1) (default 0.5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub split: Option<f64>,
    /// Signal values mapped to 0 and 1 (default `[0, 1]` in the signal's SI unit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub signal_range: Option<[QuantityValue; 2]>,
    /// `[lo, hi]` of each output, `lo < hi`; default `[0, 1]` each, for fractions (valve openings),
    /// required otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ranges: Option<[[QuantityValue; 2]; 2]>,
    /// Direction of each output (default both `increasing`: sequential valves); use
    /// `["decreasing", "increasing"]` for heat/cool or vent/make-up.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub directions: Option<[Direction; 2]>,
}

impl super::ControllerConfig for SplitRangeConfig {
    fn paths(&self) -> super::ControllerPaths {
        super::ControllerPaths {
            measured: vec![("signal".to_string(), self.signal.clone())],
            driven: self.outputs.iter().enumerate().map(|(k, o)| (format!("outputs[{k}]"), o.clone())).collect(),
        }
    }
}

/// A split-range block.
#[derive(Debug, Clone)]
pub struct SplitRange {
    signal: String,
    split: f64,
    signal_range: [f64; 2],
    ranges: [[f64; 2]; 2],
    directions: [Direction; 2],
    dims: [Dimension; 2],
}

impl SplitRange {
    /// Build from the flowsheet description and the resolved links (`pv_dim` is the signal's
    /// dimension, `op_dim` the first output's).
    pub fn build(
        c: &SplitRangeConfig,
        mut cx: BuildCx<'_>,
        links: &ControllerLinks,
    ) -> Result<SplitRange, Vec<FieldError>> {
        let split = c.split.unwrap_or(0.5);
        if !(split.is_finite() && split > 0.0 && split < 1.0) {
            cx.error("split", format!("must lie strictly between 0 and 1 (got {split})"));
        }
        let signal_range = match &c.signal_range {
            Some([lo, hi]) => {
                let lo = cx.quantity("signal_range[0]", lo, links.pv_dim);
                let hi = cx.quantity("signal_range[1]", hi, links.pv_dim);
                if lo >= hi {
                    cx.error(
                        "signal_range",
                        format!("the first value must be below the second ({lo} ≥ {hi} in SI units)"),
                    );
                }
                [lo, hi]
            }
            None => [0.0, 1.0],
        };
        let dim2 = c.ranges.as_ref().and_then(|r| r[1].iter().find_map(unit_dimension_of)).unwrap_or(links.op_dim);
        let dims = [links.op_dim, dim2];
        let mut ranges = [[0.0, 1.0]; 2];
        if c.ranges.is_none() && !links.op_dim.is_dimensionless() {
            cx.error(
                "ranges",
                format!(
                    "`outputs[0]` `{}` is {}, not a fraction: give `ranges`, \
                     e.g. [[\"0 mol/s\", \"2 mol/s\"], [\"0 mol/s\", \"5 mol/s\"]]",
                    c.outputs[0],
                    links.op_dim.describe()
                ),
            );
        }
        if let Some(given) = &c.ranges {
            for k in 0..2 {
                let lo = cx.quantity(&format!("ranges[{k}][0]"), &given[k][0], dims[k]);
                let hi = cx.quantity(&format!("ranges[{k}][1]"), &given[k][1], dims[k]);
                if lo >= hi {
                    cx.error(
                        &format!("ranges[{k}]"),
                        format!(
                            "give [lo, hi] with lo < hi ({lo} ≥ {hi} in SI units); \
                             set `directions` to make the output close as the signal rises"
                        ),
                    );
                }
                ranges[k] = [lo, hi];
            }
        }
        let directions = c.directions.unwrap_or_default();
        cx.finish(SplitRange { signal: c.signal.clone(), split, signal_range, ranges, directions, dims })
    }

    /// The two outputs at signal `s`.
    fn outputs<S: Scalar>(&self, s: S) -> [S; 2] {
        let [s_lo, s_hi] = self.signal_range;
        let sigma = clamp((s - s_lo) / (s_hi - s_lo), 0.0, 1.0);
        let f1 = clamp(sigma / self.split, 0.0, 1.0);
        let f2 = clamp((sigma - self.split) / (1.0 - self.split), 0.0, 1.0);
        let out = |k: usize, f: S| {
            let [lo, hi] = self.ranges[k];
            match self.directions[k] {
                Direction::Increasing => f * (hi - lo) + lo,
                Direction::Decreasing => -f * (hi - lo) + hi,
            }
        };
        [out(0, f1), out(1, f2)]
    }
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

impl UnitModel for SplitRange {
    fn type_name(&self) -> &'static str {
        "split_range"
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        let nominal = |k: usize| self.ranges[k][0].abs().max(self.ranges[k][1].abs()).max(1e-6);
        vec![VarSpec::algebraic("op", self.dims[0], nominal(0)), VarSpec::algebraic("op2", self.dims[1], nominal(1))]
    }
    fn signals(&self) -> Vec<SignalSpec> {
        vec![SignalSpec { role: "signal".into(), path: self.signal.clone() }]
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let [o1, o2] = self.outputs(io.signal(0));
        r[0] = io.var(0) - o1;
        r[1] = io.var(1) - o2;
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let s = io.signal(0);
        // An unset signal (NaN) starts at the split point.
        let s = if s.is_finite() {
            s
        } else {
            self.signal_range[0] + self.split * (self.signal_range[1] - self.signal_range[0])
        };
        let [o1, o2] = self.outputs(s);
        own[0] = o1;
        own[1] = o2;
    }
}

#[cfg(test)]
mod tests {
    use approx::assert_abs_diff_eq;
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
            op_value: 0.5,
            pv_nominal: 1.0,
            measured_ranges: Vec::new(),
            driven_ranges: Vec::new(),
        }
    }

    fn build(config: serde_json::Value, links: &ControllerLinks) -> Result<SplitRange, Vec<FieldError>> {
        let c: SplitRangeConfig = serde_json::from_value(config).expect("valid split-range description");
        let thermo = binary_package();
        let comps = vec!["light".to_string(), "heavy".to_string()];
        SplitRange::build(&c, BuildCx::new(&comps, &thermo, "controllers.sr"), links)
    }

    /// The guessed outputs at signal `s`, checked to zero the residuals.
    fn at(u: &dyn crate::Unit, s: f64) -> [f64; 2] {
        let thermo = binary_package();
        let layout = layout(u);
        let mut local = vec![0.0, 0.0, s];
        let io = UnitIo { local: &local, layout: &layout, thermo: &thermo, time: 0.0 };
        let mut own = [0.0; 2];
        u.guess(&io, &mut own);
        local[..2].copy_from_slice(&own);
        let mut r = [1.0; 2];
        u.residual(&UnitIo { local: &local, layout: &layout, thermo: &thermo, time: 0.0 }, &mut r);
        assert!(r[0].abs() < 1e-14 && r[1].abs() < 1e-14, "{r:?}");
        own
    }

    fn jac_err(u: &dyn crate::Unit, s: f64) -> f64 {
        let layout = layout(u);
        let local = [0.3, 0.4, s];
        jacobian_error(u, &layout, &binary_package(), &local, 2)
    }

    #[test]
    fn sequential_valves_are_piecewise_linear() {
        let frac = links(Dimension::DIMENSIONLESS, Dimension::DIMENSIONLESS);
        let u =
            build(json!({"signal": "pc.op", "outputs": ["v1.opening", "v2.opening"], "split": 0.4}), &frac).unwrap();
        let names: Vec<_> = u.internal_vars().iter().map(|v| v.name.clone()).collect();
        assert_eq!(names, ["op", "op2"]);
        assert!(u.inputs().is_empty());
        assert_abs_diff_eq!(at(&u, 0.0)[..], [0.0, 0.0][..], epsilon = 1e-12);
        assert_abs_diff_eq!(at(&u, 0.2)[..], [0.5, 0.0][..], epsilon = 1e-12);
        assert_abs_diff_eq!(at(&u, 0.4)[..], [1.0, 0.0][..], epsilon = 1e-12);
        assert_abs_diff_eq!(at(&u, 0.7)[..], [1.0, 0.5][..], epsilon = 1e-12);
        assert_abs_diff_eq!(at(&u, 1.0)[..], [1.0, 1.0][..], epsilon = 1e-12);
        // Outside the signal range the outputs hold.
        assert_abs_diff_eq!(at(&u, -0.5)[..], [0.0, 0.0][..], epsilon = 1e-12);
        assert_abs_diff_eq!(at(&u, 1.5)[..], [1.0, 1.0][..], epsilon = 1e-12);
    }

    #[test]
    fn heat_cool_with_ranges_and_signal_range() {
        // Signal 0..100 (a percentage written in SI as 0..100), cooling water 0..2 mol/s closing,
        // steam 0..5 mol/s opening, split at 0.5.
        let flow = links(Dimension::DIMENSIONLESS, Dimension::MOLAR_FLOW);
        let u = build(
            json!({
                "signal": "tc.op", "outputs": ["cw.F", "steam.F"], "signal_range": [0, 100],
                "ranges": [["0 mol/s", "2 mol/s"], [0, 5]], "directions": ["decreasing", "increasing"]
            }),
            &flow,
        )
        .unwrap();
        assert_eq!(u.internal_vars()[1].dim, Dimension::MOLAR_FLOW);
        assert_abs_diff_eq!(at(&u, 0.0)[..], [2.0, 0.0][..], epsilon = 1e-12);
        assert_abs_diff_eq!(at(&u, 25.0)[..], [1.0, 0.0][..], epsilon = 1e-12);
        assert_abs_diff_eq!(at(&u, 50.0)[..], [0.0, 0.0][..], epsilon = 1e-12);
        assert_abs_diff_eq!(at(&u, 75.0)[..], [0.0, 2.5][..], epsilon = 1e-12);
        assert_abs_diff_eq!(at(&u, 100.0)[..], [0.0, 5.0][..], epsilon = 1e-12);
    }

    #[test]
    fn second_output_dimension_comes_from_its_range_units() {
        let flow = links(Dimension::DIMENSIONLESS, Dimension::MOLAR_FLOW);
        let u = build(
            json!({"signal": "tc.op", "outputs": ["cw.F", "reb.duty"], "ranges": [[0, 2], ["0 W", "2 MW"]]}),
            &flow,
        )
        .unwrap();
        assert_eq!(u.internal_vars()[1].dim, Dimension::POWER);
        assert_abs_diff_eq!(at(&u, 1.0)[..], [2.0, 2.0e6][..], epsilon = 1e-12);
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let frac = links(Dimension::DIMENSIONLESS, Dimension::DIMENSIONLESS);
        let u = build(
            json!({
                "signal": "pc.op", "outputs": ["v1.opening", "v2.opening"], "split": 0.4,
                "directions": ["decreasing", "increasing"]
            }),
            &frac,
        )
        .unwrap();
        for s in [-0.2, 0.1, 0.3, 0.55, 0.9, 1.3] {
            assert!(jac_err(&u, s) < 1e-7, "s = {s}");
        }
        // Exact slopes: dop/ds = −1/0.4 below the split, dop2/ds = 1/0.6 above it.
        let thermo = binary_package();
        let layout = layout(&u);
        let mut r = [0.0; 2];
        let mut jac = [0.0; 6];
        (&u as &dyn crate::Unit).jacobian(
            &UnitIo { local: &[0.0, 0.0, 0.1], layout: &layout, thermo: &thermo, time: 0.0 },
            &mut r,
            &mut jac,
        );
        assert!((jac[2] - 2.5).abs() < 1e-12 && jac[5] == 0.0, "{jac:?}");
        (&u as &dyn crate::Unit).jacobian(
            &UnitIo { local: &[0.0, 0.0, 0.7], layout: &layout, thermo: &thermo, time: 0.0 },
            &mut r,
            &mut jac,
        );
        assert!(jac[2] == 0.0 && (jac[5] + 1.0 / 0.6).abs() < 1e-12, "{jac:?}");
    }

    #[test]
    fn bad_split_ranges_and_dimensions_are_reported() {
        let flow = links(Dimension::DIMENSIONLESS, Dimension::MOLAR_FLOW);
        let errs = build(
            json!({
                "signal": "tc.op", "outputs": ["cw.F", "st.F"], "split": 1.0, "signal_range": [1, 0],
                "ranges": [["3 K", "5 K"], [2, 1]]
            }),
            &flow,
        )
        .unwrap_err();
        let paths: Vec<_> = errs.iter().map(|e| e.path.as_str()).collect();
        assert_eq!(
            paths,
            [
                "controllers.sr.split",
                "controllers.sr.signal_range",
                "controllers.sr.ranges[0][0]",
                "controllers.sr.ranges[0][1]",
                "controllers.sr.ranges[1]"
            ]
        );
        assert!(
            errs[2].message.contains("temperature") && errs[2].message.contains("molar flow"),
            "{}",
            errs[2].message
        );
    }

    #[test]
    fn registry_knows_the_type_and_both_driven_inputs() {
        let spec: ControllerSpec = serde_json::from_value(
            json!({"type": "split_range", "signal": "pc.op", "outputs": ["a.opening", "b.opening"]}),
        )
        .unwrap();
        assert_eq!(spec.type_name(), "split_range");
        let paths = spec.config().paths();
        assert_eq!(
            paths.driven,
            [("outputs[0]".to_string(), "a.opening".to_string()), ("outputs[1]".to_string(), "b.opening".to_string())]
        );
        assert!(
            serde_json::from_value::<SplitRangeConfig>(json!({"signal": "pc.op", "outputs": ["a.opening"]})).is_err()
        );
    }

    #[test]
    fn ranges_are_required_for_outputs_that_are_not_fractions() {
        let flow = links(Dimension::DIMENSIONLESS, Dimension::MOLAR_FLOW);
        let errs = build(json!({"signal": "tc.op", "outputs": ["cw.F", "st.F"]}), &flow).unwrap_err();
        assert_eq!(errs.len(), 1);
        assert_eq!(errs[0].path, "controllers.sr.ranges");
        assert!(errs[0].message.contains("`cw.F` is a molar flow"), "{}", errs[0].message);
    }
}
