//! PID controller in ISA (standard) form with derivative filter, output limits with back-calculation
//! anti-windup, bias, auto/manual with bumpless transfer, and local or remote (cascade) setpoint.
//!
//! Error `e = sp − pv` (reverse action) or `pv − sp` (direct action). Variables, in order:
//! - `I` (differential, present when `tau_i` is given): `dI/dt = e + (clamp(u) − u)/Kc` in auto, where
//!   `u = bias + Kc (e + I/τ_I + D)` is the unclamped output; the back-calculation term stops windup and
//!   vanishes while the output is inside its limits. In manual `dI/dt = ((op_man − bias)/Kc − e − I/τ_I)·τ_I/τ_t`
//!   tracks the manual output, `τ_t = τ_I`.
//! - `xf` (differential, present when `tau_d` is given): filtered error, `dxf/dt = (e − xf)/τ_f`,
//!   `τ_f = τ_D/N`; the derivative term is `D = τ_D (e − xf)/τ_f`.
//! - `op` (algebraic): `op = clamp(u, op_min, op_max)` in auto, `op = op_man` in manual.
//!
//! Inputs: `sp` (local setpoint only), `op_manual`, and `auto` [-] (1 = auto, 0 = manual; its
//! flowsheet value comes from `mode`): the mode is an input so that a dynamic scenario can switch
//! it while the plant runs.
//!
//! At steady state with integral action `e = 0` (the measurement sits on its setpoint); a P-only
//! controller leaves the offset `e = (op − bias)/Kc`.

use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{Action, ControllerLinks, Mode, Setpoint, clamp, gain_dimension};
use crate::{BuildCx, FieldError, InputSpec, Scalar, SignalSpec, UnitIo, UnitModel, VarSpec};

/// Flowsheet description of a PID controller.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PidConfig {
    /// Variable path of the measurement, e.g. `"tank.level"`.
    pub pv: String,
    /// Input driven by the output, e.g. `"tank.outflow"` or `"column.reflux"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output: Option<String>,
    /// Setpoint: a value (e.g. `"1.2 m"`) or `{"from": "<master>.op"}`.
    pub sp: Setpoint,
    /// Controller gain in output units per measurement unit (e.g. `"10 kmol/min/kmol"`); > 0.
    pub kc: QuantityValue,
    /// Reset (integral) time; omit for P or PD control.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tau_i: Option<QuantityValue>,
    /// Derivative time; omit for no derivative action.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tau_d: Option<QuantityValue>,
    /// Derivative filter ratio `N = τ_D/τ_f` (default 10).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filter_ratio: Option<f64>,
    /// Direct or reverse action (default reverse).
    #[serde(default)]
    pub action: Action,
    /// Output at zero error; default: the driven input's value in the flowsheet (bumpless start).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bias: Option<QuantityValue>,
    /// Lower output limit (default: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub op_min: Option<QuantityValue>,
    /// Upper output limit (default: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub op_max: Option<QuantityValue>,
    /// Auto or manual (default auto).
    #[serde(default)]
    pub mode: Mode,
    /// Output in manual mode; default: the bias.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub op_manual: Option<QuantityValue>,
}

impl super::ControllerConfig for PidConfig {
    fn paths(&self) -> super::ControllerPaths {
        let mut measured = vec![("pv".to_string(), self.pv.clone())];
        if let Setpoint::Remote { from } = &self.sp {
            measured.push(("sp.from".to_string(), from.clone()));
        }
        let driven = self.output.iter().map(|o| ("output".to_string(), o.clone())).collect();
        super::ControllerPaths { measured, driven }
    }
    fn op_dimension(&self, pv_dim: Dimension) -> Option<Dimension> {
        match &self.kc {
            QuantityValue::Text(t) => plantwide_units::parse_quantity(t).ok().map(|q| q.dim * pv_dim),
            QuantityValue::Number(_) => None,
        }
    }
}

/// A PID controller.
#[derive(Debug, Clone)]
pub struct Pid {
    pv_path: String,
    remote_sp: Option<String>,
    sp: f64,
    kc: f64,
    tau_i: Option<f64>,
    tau_d: Option<f64>,
    filter_ratio: f64,
    action: Action,
    bias: f64,
    op_min: f64,
    op_max: f64,
    mode: Mode,
    op_manual: f64,
    links: ControllerLinks,
}

/// Report `field` = `v` (SI) outside `range`, `what` naming whose range it is.
fn within(cx: &mut BuildCx<'_>, field: &str, v: f64, range: (f64, f64), dim: Dimension, what: &str) {
    if let Some(why) = crate::limits::outside(v, range, dim) {
        cx.error(field, format!("{why}; the range is {what}"));
    }
}

impl Pid {
    /// Build from the flowsheet description and the resolved links.
    pub fn build(c: &PidConfig, mut cx: BuildCx<'_>, links: &ControllerLinks) -> Result<Pid, Vec<FieldError>> {
        let (remote_sp, sp) = match &c.sp {
            Setpoint::Value(v) => (None, cx.quantity("sp", v, links.pv_dim)),
            Setpoint::Remote { from } => (Some(from.clone()), f64::NAN),
        };
        let kc = cx.gain("kc", &c.kc, gain_dimension(links));
        let tau_i = c.tau_i.as_ref().map(|t| cx.positive("tau_i", t, Dimension::TIME));
        let tau_d = c.tau_d.as_ref().map(|t| cx.positive("tau_d", t, Dimension::TIME));
        let filter_ratio = c.filter_ratio.unwrap_or(10.0);
        if !(filter_ratio.is_finite() && filter_ratio > 0.0) {
            cx.error("filter_ratio", format!("must be positive (got {filter_ratio})"));
        }
        let bias = c.bias.as_ref().map_or(links.op_value, |b| cx.quantity("bias", b, links.op_dim));
        let op_min = c.op_min.as_ref().map_or(f64::NEG_INFINITY, |v| cx.quantity("op_min", v, links.op_dim));
        let op_max = c.op_max.as_ref().map_or(f64::INFINITY, |v| cx.quantity("op_max", v, links.op_dim));
        if op_min >= op_max {
            cx.error("op_max", format!("must exceed op_min ({op_min} ≥ {op_max} in SI units)"));
        }
        let op_manual = c.op_manual.as_ref().map_or(bias, |v| cx.quantity("op_manual", v, links.op_dim));
        if remote_sp.is_none() {
            within(&mut cx, "sp", sp, links.pv_range(), links.pv_dim, "the measurement's");
        }
        for (field, v) in [("op_min", op_min), ("op_max", op_max), ("op_manual", op_manual)] {
            if v.is_finite() {
                within(&mut cx, field, v, links.op_range(), links.op_dim, "that of the input it drives");
            }
        }
        let pid = Pid {
            pv_path: c.pv.clone(),
            remote_sp,
            sp,
            kc,
            tau_i,
            tau_d,
            filter_ratio,
            action: c.action,
            bias,
            op_min,
            op_max,
            mode: c.mode,
            op_manual,
            links: links.clone(),
        };
        cx.finish(pid)
    }

    fn n_diff(&self) -> usize {
        usize::from(self.tau_i.is_some()) + usize::from(self.tau_d.is_some())
    }

    /// The mode from the input `auto` (≥ 0.5: auto, else manual), so that a scenario can switch it.
    fn is_auto<S: Scalar>(&self, io: &UnitIo<'_, S>) -> bool {
        io.input(usize::from(self.remote_sp.is_none()) + 1).re() >= 0.5
    }

    fn error<S: Scalar>(&self, io: &UnitIo<'_, S>) -> S {
        let pv = io.signal(0);
        let sp = if self.remote_sp.is_some() { io.signal(1) } else { io.input(0) };
        match self.action {
            Action::Reverse => sp - pv,
            Action::Direct => pv - sp,
        }
    }
}

impl UnitModel for Pid {
    fn type_name(&self) -> &'static str {
        "pid"
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        let pv_scale = self.links.pv_nominal.abs().max(1e-6);
        let mut v = Vec::new();
        if let Some(ti) = self.tau_i {
            v.push(VarSpec::differential("I", self.links.pv_dim * Dimension::TIME, pv_scale * ti));
        }
        if self.tau_d.is_some() {
            v.push(VarSpec::differential("xf", self.links.pv_dim, pv_scale));
        }
        v.push(VarSpec::algebraic("op", self.links.op_dim, self.bias.abs().max(1e-6)));
        v
    }
    fn inputs(&self) -> Vec<InputSpec> {
        let mut v = Vec::new();
        if self.remote_sp.is_none() {
            v.push(InputSpec { name: "sp".into(), dim: self.links.pv_dim, value: self.sp });
        }
        v.push(InputSpec { name: "op_manual".into(), dim: self.links.op_dim, value: self.op_manual });
        let auto = f64::from(u8::from(self.mode == Mode::Auto));
        v.push(InputSpec { name: "auto".into(), dim: Dimension::DIMENSIONLESS, value: auto });
        v
    }
    /// The setpoint takes the measurement's range, the manual output the driven input's.
    fn input_range(&self, k: usize) -> Option<(f64, f64)> {
        let k = k + usize::from(self.remote_sp.is_some());
        match k {
            0 => Some(self.links.pv_range()),
            1 => Some(self.links.op_range()),
            _ => None,
        }
    }
    fn signals(&self) -> Vec<SignalSpec> {
        let mut v = vec![SignalSpec { role: "pv".into(), path: self.pv_path.clone() }];
        if let Some(from) = &self.remote_sp {
            v.push(SignalSpec { role: "sp".into(), path: from.clone() });
        }
        v
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let e = self.error(io);
        let n_diff = self.n_diff();
        let op = io.var(n_diff);
        let op_manual = io.input(usize::from(self.remote_sp.is_none()));
        let auto = self.is_auto(io);
        let mut k = 0;
        let integral = self.tau_i.map(|ti| {
            let i = io.var(k);
            k += 1;
            (i, ti)
        });
        let derivative = self.tau_d.map(|td| {
            let xf = io.var(k);
            let tf = td / self.filter_ratio;
            (xf, tf, td)
        });
        let mut u = e;
        if let Some((i, ti)) = integral {
            u += i / ti;
        }
        if let Some((xf, tf, td)) = derivative {
            u += (e - xf) * (td / tf);
        }
        let u = u * self.kc + self.bias;
        let clamped = clamp(u, self.op_min, self.op_max);
        let mut k = 0;
        if let Some((i, ti)) = integral {
            // `clamp(u)` for `op`: the two are equal by the `op` row, so the dynamics are the same
            // (the row is the old one minus the `op` row over Kc, a constant row operation that
            // leaves Newton's steps unchanged), but inside the limits the back-calculation term is
            // identically zero and the row reads `e` itself. Written with `op`, `e` cancels in it
            // (e + (op − bias)/Kc − e − I/τ_I) and the steady state's `e = 0` lives only in the
            // `op` row as `Kc·e` beside the output's own size: a bottoms loop at 1e-9 with Kc =
            // 34 MW per unit mole fraction weighs its measurement 1e-11 of that row, which the
            // degrees-of-freedom probe took for a free direction.
            r[k] = if auto { e + (clamped - u) / self.kc } else { (op_manual - self.bias) / self.kc - e - i / ti };
            k += 1;
        }
        if let Some((xf, tf, _)) = derivative {
            r[k] = (e - xf) / tf;
        }
        r[n_diff] = if auto { op - clamped } else { op - op_manual };
    }
    fn without_limits(&self) -> Option<Self> {
        let limited = self.op_min > f64::NEG_INFINITY || self.op_max < f64::INFINITY;
        limited.then(|| Pid { op_min: f64::NEG_INFINITY, op_max: f64::INFINITY, ..self.clone() })
    }
    fn output_limits(&self) -> Option<(f64, f64)> {
        let limited = self.op_min > f64::NEG_INFINITY || self.op_max < f64::INFINITY;
        limited.then_some((self.op_min, self.op_max))
    }
    /// In auto with the output within 1e-9 (relative) of a limit and the error beyond 1e-6 of the
    /// measurement's scale: the loop has lost control of its measurement.
    fn saturation(&self, io: &UnitIo<'_, f64>) -> Option<crate::Saturation> {
        if !self.is_auto(io) {
            return None;
        }
        let op = io.var(self.n_diff());
        let at = |lim: f64| lim.is_finite() && (op - lim).abs() <= 1e-9 * lim.abs().max(self.bias.abs()).max(1e-12);
        let limit = if at(self.op_max) {
            ("op_max", self.op_max)
        } else if at(self.op_min) {
            ("op_min", self.op_min)
        } else {
            return None;
        };
        let e = self.error(io);
        let offset = match self.action {
            Action::Reverse => -e,
            Action::Direct => e,
        };
        let scale = self.links.pv_nominal.abs().max(io.signal(0).abs()).max(1e-12);
        (offset.abs() > 1e-6 * scale).then_some(crate::Saturation { limit: limit.0, value: limit.1, offset })
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let e = self.error(io);
        let mut k = 0;
        if self.tau_i.is_some() {
            own[k] = 0.0;
            k += 1;
        }
        if self.tau_d.is_some() {
            own[k] = e;
        }
        let n_diff = self.n_diff();
        // The manual output is an input (`--set ctrl.op_manual=…` moves it, the description does not).
        let op_manual = io.input(usize::from(self.remote_sp.is_none()));
        own[n_diff] =
            if self.is_auto(io) { clamp(self.bias + self.kc * e, self.op_min, self.op_max) } else { op_manual };
    }
}

#[cfg(test)]
mod tests {
    use plantwide_units::Dimension;
    use serde_json::json;

    use super::*;
    use crate::testing::{binary_package, jacobian_error};
    use crate::{LocalLayout, StreamLayout};

    /// A level (m) controller moving a molar flow (mol/s) whose flowsheet value is 5 mol/s.
    fn links() -> ControllerLinks {
        ControllerLinks {
            measured_dims: Vec::new(),
            driven: Vec::new(),
            pv_dim: Dimension::LENGTH,
            op_dim: Dimension::MOLAR_FLOW,
            op_value: 5.0,
            pv_nominal: 1.2,
            measured_ranges: Vec::new(),
            driven_ranges: Vec::new(),
        }
    }

    fn build(extra: serde_json::Value) -> Pid {
        let mut config = json!({"pv": "tank.level", "output": "drain.F", "sp": "1.2 m", "kc": "10 mol/s/m"});
        if let (Some(c), Some(e)) = (config.as_object_mut(), extra.as_object()) {
            c.extend(e.clone());
        }
        let c: PidConfig = serde_json::from_value(config).expect("valid PID description");
        let thermo = binary_package();
        let comps = vec!["light".to_string(), "heavy".to_string()];
        Pid::build(&c, BuildCx::new(&comps, &thermo, "controllers.lc"), &links()).expect("PID builds")
    }

    fn layout(u: &dyn crate::Unit) -> LocalLayout {
        LocalLayout {
            stream: StreamLayout { n_comp: 2 },
            n_outlets: 0,
            n_internal: u.internal_vars().len(),
            n_inlets: 0,
            n_inputs: u.inputs().len(),
            n_signals: u.signals().len(),
        }
    }

    fn residual(u: &dyn crate::Unit, local: &[f64]) -> Vec<f64> {
        let thermo = binary_package();
        let layout = layout(u);
        assert_eq!(layout.len(), local.len());
        let mut r = vec![f64::NAN; layout.n_own()];
        u.residual(&UnitIo { local, layout: &layout, thermo: &thermo, time: 0.0 }, &mut r);
        r
    }

    fn jac_err(u: &dyn crate::Unit, local: &[f64]) -> f64 {
        let layout = layout(u);
        jacobian_error(u, &layout, &binary_package(), local, layout.n_own())
    }

    fn names(u: &dyn crate::Unit) -> (Vec<String>, Vec<String>, Vec<String>) {
        (
            u.internal_vars().into_iter().map(|v| v.name).collect(),
            u.inputs().into_iter().map(|i| i.name).collect(),
            u.signals().into_iter().map(|s| s.role).collect(),
        )
    }

    #[test]
    fn pi_at_steady_state_holds_zero_error() {
        let u = build(json!({"tau_i": "100 s"}));
        assert_eq!(
            names(&u),
            (vec!["I".into(), "op".into()], vec!["sp".into(), "op_manual".into(), "auto".into()], vec!["pv".into()])
        );
        let (sp, bias, kc, ti) = (1.2, 5.0, 10.0, 100.0);
        // local = [I, op | sp, op_manual, auto | pv]; op = u (inside the limits).
        let at = |i: f64, pv: f64| {
            let op = bias + kc * (sp - pv + i / ti);
            residual(&u, &[i, op, sp, bias, 1.0, pv])
        };
        // On setpoint: a steady state for any integral (the integral carries the output's offset).
        for i in [-30.0, 0.0, 42.0] {
            let r = at(i, sp);
            assert!(r[0].abs() < 1e-14 && r[1].abs() < 1e-12, "{r:?}");
        }
        // Off setpoint: dI/dt = e = sp − pv (reverse action), so no steady state.
        let r = at(12.0, 1.0);
        assert!((r[0] - 0.2).abs() < 1e-12 && r[1].abs() < 1e-12, "{r:?}");
        let direct = build(json!({"tau_i": "100 s", "action": "direct"}));
        let op = bias + kc * (1.0 - sp);
        let r = residual(&direct, &[0.0, op, sp, bias, 1.0, 1.0]);
        assert!((r[0] + 0.2).abs() < 1e-12 && r[1].abs() < 1e-12, "{r:?}");
    }

    #[test]
    fn p_only_leaves_the_offset_op_minus_bias_over_kc() {
        let u = build(json!({}));
        assert_eq!(
            names(&u),
            (vec!["op".into()], vec!["sp".into(), "op_manual".into(), "auto".into()], vec!["pv".into()])
        );
        let (sp, bias, kc) = (1.2, 5.0, 10.0);
        // The process needs op = 7 mol/s: the loop settles with e = (op − bias)/Kc = 0.2 m.
        let op = 7.0;
        let e = (op - bias) / kc;
        let r = residual(&u, &[op, sp, bias, 1.0, sp - e]);
        assert!(r[0].abs() < 1e-12, "{r:?}");
        // Any other level leaves a residual Kc·Δe.
        let r = residual(&u, &[op, sp, bias, 1.0, sp]);
        assert!((r[0] - 2.0).abs() < 1e-12, "{r:?}");
        // The guess puts op on the P law.
        let thermo = binary_package();
        let layout = layout(&u);
        let mut own = [0.0];
        u.guess(
            &UnitIo { local: &[0.0, sp, bias, 1.0, sp - e], layout: &layout, thermo: &thermo, time: 0.0 },
            &mut own,
        );
        assert!((own[0] - op).abs() < 1e-12);
    }

    #[test]
    fn saturated_output_with_back_calculation_stops_the_integral() {
        let u = build(json!({"tau_i": "100 s", "op_max": "6 mol/s", "op_min": 0.0}));
        let (sp, bias, kc, ti, op_max) = (1.2, 5.0, 10.0, 100.0, 6.0);
        // At the upper limit the integral settles at I = τ_I (op_max − bias)/Kc whatever the error.
        let i_sat = ti * (op_max - bias) / kc;
        for e in [0.5, 2.0] {
            let pv = sp - e;
            let unclamped = bias + kc * (e + i_sat / ti);
            assert!(unclamped > op_max);
            let r = residual(&u, &[i_sat, op_max, sp, bias, 1.0, pv]);
            assert!(r[0].abs() < 1e-12 && r[1].abs() < 1e-12, "e = {e}: {r:?}");
            // Away from that integral, it relaxes towards it: dI/dt = (op_max − bias)/Kc − I/τ_I.
            let r = residual(&u, &[i_sat + 5.0, op_max, sp, bias, 1.0, pv]);
            assert!((r[0] + 5.0 / ti).abs() < 1e-12, "{r:?}");
        }
        // Inside the limits the back-calculation term vanishes: dI/dt = e.
        let r = residual(&u, &[0.0, bias + kc * 0.05, sp, bias, 1.0, sp - 0.05]);
        assert!((r[0] - 0.05).abs() < 1e-12 && r[1].abs() < 1e-12, "{r:?}");
    }

    #[test]
    fn manual_mode_holds_op_manual_and_tracks_it_with_the_integral() {
        let u = build(json!({"tau_i": "100 s", "mode": "manual", "op_manual": "4 mol/s"}));
        let (sp, bias, kc, ti) = (1.2, 5.0, 10.0, 100.0);
        assert_eq!(u.inputs()[1].value, 4.0);
        assert_eq!(u.inputs()[2].value, 0.0, "manual in the file: input `auto` = 0");
        // At the tracking steady state the unclamped auto output equals op_manual (bumpless).
        let pv = 1.0;
        let i = ti * ((4.0 - bias) / kc - (sp - pv));
        let r = residual(&u, &[i, 4.0, sp, 4.0, 0.0, pv]);
        assert!(r[0].abs() < 1e-12 && r[1].abs() < 1e-14, "{r:?}");
        assert!((bias + kc * (sp - pv + i / ti) - 4.0).abs() < 1e-12);
    }

    #[test]
    fn the_auto_input_switches_the_mode_at_run_time() {
        let u = build(json!({"tau_i": "100 s"}));
        let (sp, bias, kc, ti, pv, i) = (1.2, 5.0, 10.0, 100.0, 1.0, 3.0);
        // [I, op | sp, op_manual, auto | pv]: in manual op = op_manual and the integral tracks it.
        let manual = residual(&u, &[i, 4.0, sp, 4.0, 0.0, pv]);
        assert!(manual[1].abs() < 1e-14, "{manual:?}");
        assert!((manual[0] - ((4.0 - bias) / kc - (sp - pv) - i / ti)).abs() < 1e-14, "{manual:?}");
        // The same point in auto: op must follow the PI law.
        let auto = residual(&u, &[i, 4.0, sp, 4.0, 1.0, pv]);
        assert!((auto[1] - (4.0 - (bias + kc * (sp - pv + i / ti)))).abs() < 1e-12, "{auto:?}");
    }

    #[test]
    fn jacobians_match_finite_differences() {
        // P: [op | sp, op_manual, auto | pv]
        let p = build(json!({}));
        assert!(jac_err(&p, &[6.0, 1.2, 5.0, 1.0, 1.1]) < 1e-7);
        // PI: [I, op | sp, op_manual, auto | pv]
        let pi = build(json!({"tau_i": "5 min"}));
        assert!(jac_err(&pi, &[3.0, 6.0, 1.2, 5.0, 1.0, 1.1]) < 1e-7);
        // PI saturated at op_max.
        let sat = build(json!({"tau_i": "100 s", "op_max": 6.0}));
        assert!(jac_err(&sat, &[10.0, 6.0, 1.2, 5.0, 1.0, 0.7]) < 1e-7);
        // PID: [I, xf, op | sp, op_manual, auto | pv]
        let pid = build(json!({"tau_i": "100 s", "tau_d": "20 s", "filter_ratio": 8.0, "action": "direct"}));
        assert_eq!(names(&pid).0, ["I", "xf", "op"]);
        assert!(jac_err(&pid, &[3.0, 0.05, 6.0, 1.2, 5.0, 1.0, 1.1]) < 1e-7);
        // Manual PI.
        let manual = build(json!({"tau_i": "100 s", "mode": "manual"}));
        assert!(jac_err(&manual, &[3.0, 6.0, 1.2, 5.5, 0.0, 1.1]) < 1e-7);
        // Remote setpoint: [I, op | op_manual, auto | pv, sp]
        let remote = build(json!({"tau_i": "100 s", "sp": {"from": "master.op"}}));
        assert_eq!(
            names(&remote),
            (vec!["I".into(), "op".into()], vec!["op_manual".into(), "auto".into()], vec!["pv".into(), "sp".into()])
        );
        assert!(jac_err(&remote, &[3.0, 6.0, 5.0, 1.0, 1.1, 1.3]) < 1e-7);
        let r = residual(&remote, &[0.0, 5.0 + 10.0 * 0.2, 5.0, 1.0, 1.1, 1.3]);
        assert!((r[0] - 0.2).abs() < 1e-12 && r[1].abs() < 1e-12, "remote sp is signal 1: {r:?}");
    }

    #[test]
    fn gain_with_the_wrong_dimension_is_reported() {
        let c: PidConfig =
            serde_json::from_value(json!({"pv": "tank.level", "output": "drain.F", "sp": "1.2 m", "kc": "10 mol/s/K"}))
                .unwrap();
        let thermo = binary_package();
        let comps = vec!["light".to_string(), "heavy".to_string()];
        let errs = Pid::build(&c, BuildCx::new(&comps, &thermo, "controllers.lc"), &links()).unwrap_err();
        assert_eq!(errs.len(), 1);
        assert_eq!(errs[0].path, "controllers.lc.kc");
    }
}
