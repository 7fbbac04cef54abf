//! PID controller in ISA (standard) form with derivative filter, output limits with back-calculation
//! anti-windup, bias, auto/manual with bumpless transfer, and local or remote (cascade) setpoint.
//!
//! Error `e = sp − pv` (reverse action) or `pv − sp` (direct action). Variables, in order:
//! - `I` (differential, present when `tau_i` is given): `dI/dt = e + (op − u)/Kc` in auto, where
//!   `u = bias + Kc (e + I/τ_I + D)` is the unclamped output; the back-calculation term stops windup and
//!   vanishes while the output is inside its limits. In manual `dI/dt = ((op_man − bias)/Kc − e − I/τ_I)·τ_I/τ_t`
//!   tracks the manual output, `τ_t = τ_I`.
//! - `xf` (differential, present when `tau_d` is given): filtered error, `dxf/dt = (e − xf)/τ_f`,
//!   `τ_f = τ_D/N`; the derivative term is `D = τ_D (e − xf)/τ_f`.
//! - `op` (algebraic): `op = clamp(u, op_min, op_max)` in auto, `op = op_man` in manual.
//!
//! At steady state with integral action `e = 0` (the measurement sits on its setpoint); a P-only
//! controller leaves the offset `e = (op − bias)/Kc`.

use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{gain_dimension, Action, ControllerLinks, Mode, Setpoint};
use crate::{BuildCx, FieldError, InputSpec, Scalar, SignalSpec, UnitIo, UnitModel, VarSpec};

/// Flowsheet description of a PID controller.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PidConfig {
    /// Variable path of the measurement, e.g. `"tank.level"`.
    pub pv: String,
    /// Input driven by the output, e.g. `"tank.outflow"` or `"column.reflux"`.
    pub output: String,
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
        super::ControllerPaths { measured, driven: vec![("output".to_string(), self.output.clone())] }
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

impl Pid {
    /// Build from the flowsheet description and the resolved links.
    pub fn build(c: &PidConfig, mut cx: BuildCx<'_>, links: &ControllerLinks) -> Result<Pid, Vec<FieldError>> {
        let (remote_sp, sp) = match &c.sp {
            Setpoint::Value(v) => (None, cx.quantity("sp", v, links.pv_dim)),
            Setpoint::Remote { from } => (Some(from.clone()), f64::NAN),
        };
        let kc = cx.positive("kc", &c.kc, gain_dimension(links));
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

    fn error<S: Scalar>(&self, io: &UnitIo<'_, S>) -> S {
        let pv = io.signal(0);
        let sp = if self.remote_sp.is_some() { io.signal(1) } else { io.input(0) };
        match self.action {
            Action::Reverse => sp - pv,
            Action::Direct => pv - sp,
        }
    }
}

fn clamp<S: Scalar>(u: S, lo: f64, hi: f64) -> S {
    if u.re() < lo {
        S::from(lo)
    } else if u.re() > hi {
        S::from(hi)
    } else {
        u
    }
}

impl UnitModel for Pid {
    fn type_name(&self) -> &'static str {
        "pid"
    }
    fn inlet_ports(&self) -> Vec<String> {
        Vec::new()
    }
    fn outlet_ports(&self) -> Vec<String> {
        Vec::new()
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
        v
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
        let mut k = 0;
        if let Some((i, ti)) = integral {
            r[k] = match self.mode {
                Mode::Auto => e + (op - u) / self.kc,
                Mode::Manual => (op_manual - self.bias) / self.kc - e - i / ti,
            };
            k += 1;
        }
        if let Some((xf, tf, _)) = derivative {
            r[k] = (e - xf) / tf;
        }
        r[n_diff] = match self.mode {
            Mode::Auto => op - clamp(u, self.op_min, self.op_max),
            Mode::Manual => op - op_manual,
        };
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
        own[n_diff] = match self.mode {
            Mode::Auto => clamp(self.bias + self.kc * e, self.op_min, self.op_max),
            Mode::Manual => self.op_manual,
        };
    }
}
