//! Nonlinear averaging level controllers: a level held inside a band while the flow it moves
//! changes as slowly as the band allows (Buckley's averaging level control, *Practical
//! Distillation Control* ch. 2; the surge rule R4.1 of ch. 1).
//!
//! Notation: `y` the level (or holdup) measurement, `sp` its setpoint, `e_y = y − sp`, `Δ` the
//! `level_band`, `σ = +1` for direct action (the output is an outflow: raising it lowers the level)
//! and `−1` for reverse action (an inflow). `op` is the driven flow.
//!
//! **`"law": "optimal"`** — the optimal predictive controller of McDonald, McAvoy & Tits (1986,
//! *AIChE J.* 32, 75–86): at every instant the outflow changes at the constant rate that brings it
//! to the inflow just as the level reaches the edge of its band. With `C` the `capacity` (output ×
//! time per unit of measurement: `C = A/v_L` for a vessel of cross-section `A` whose flows are
//! molar, the measurement in m; 1 for a holdup measured in mol), the imbalance is `q = C ẏ` and the
//! level has `z = Δ − |e_y|` left before the edge, so the rate is `q|q|/(2 C z)`; along the
//! resulting ramp `q²/z` is constant (`d(q²/z)/dt = 0` with `dz/dt = −q/C`, `dq/dt = −q²/(2Cz)`),
//! so the rate stays constant, `q` and `z` vanish together, and for a step of size `Δu` the rate is
//! `Δu²/(2 C Δ)` — half that of the best P-only controller and `e/4` of the critically damped PI
//! (`plantwide_studies::size`). Here `ẏ` is estimated by a first-order filter of time `τ_f`
//! (`filter`): `dx_f/dt = (y − x_f)/τ_f`, `ẏ ≈ v = (y − x_f)/τ_f`. Once the level stops (or
//! moves back towards its setpoint, `v·e_y ≤ 0`) it returns to the setpoint critically damped with
//! the `return_time` `τ_R`: `ÿ = −(2v/τ_R + e_y/τ_R²)`. The output's rate is therefore
//! - `dop/dt = σ C · (whichever is larger in magnitude of `v|v| / (2 max(Δ − |e_y|, 10⁻⁶ Δ))` and
//!   `e_y/τ_R² + 2 v/τ_R`)` while `v·e_y > 0`,
//! - `dop/dt = σ C (e_y/τ_R² + 2 v/τ_R)` otherwise.
//!
//! The larger of the two while the level moves away: the ramp brakes the level to a stop at the
//! edge, and the return law, which dominates once the ramp's braking has faded (`v → 0`), turns
//! it back in finite time. With `τ_R ≥ 2.3 t*`, `t* = 2Δ/ẏ₀` the ramp's duration after a step
//! that starts the level at `ẏ₀`, the return law stays below the ramp's constant deceleration
//! `ẏ₀²/(2Δ)` for the whole ramp (`e_y ≤ Δ`, `v ≤ ẏ₀`: `Δ/τ_R² + 2ẏ₀/τ_R ≤ ẏ₀²/(2Δ)` ⇔
//! `t*/τ_R ≤ √6 − 2`), so the ramp is the paper's. The rate is
//!
//! limited to `±max_rate` (optional) and held at `op_min`/`op_max` (optional) when it would leave
//! them. At steady state `v = 0` and the second branch forces `e_y = 0`: the level rests on its
//! setpoint. Variables: `xf` (differential, units of the measurement), `op` (differential). The
//! return law is this crate's own (the paper's return phase is not reproduced here).
//!
//! **`"law": "error_squared"`** — a PI controller whose proportional gain grows with the error
//! (Buckley 1986; Shinskey): `u = bias + K_c (e|e|/Δ + I/τ_I)`, `e = σ e_y`, so the gain is `K_c`
//! at the band's edge and vanishes at the setpoint; `dI/dt = e + (op − u)/K_c` (back-calculation,
//! as in [`super::pid`]); `op = clamp(u, op_min, op_max)` (algebraic). Without `tau_i` it is P-only
//! and settles at `|e_y| = √(Δ |op − bias| / K_c)`.
//!
//! Input: `sp` (so that a scenario can move it).

use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{Action, ControllerLinks, clamp, gain_dimension};
use crate::{BuildCx, FieldError, InputSpec, Scalar, SignalSpec, UnitIo, UnitModel, VarSpec};

/// Which averaging law.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum AveragingLaw {
    /// McDonald, McAvoy & Tits' optimal predictive controller (a constant-rate ramp of the output).
    Optimal,
    /// PI with a proportional gain proportional to the error (gain `kc` at the band's edge).
    ErrorSquared,
}

/// Flowsheet description of a nonlinear averaging level controller.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AveragingLevelConfig {
    /// Variable path of the level (or holdup) measurement, e.g. `"tank.level"`.
    pub pv: String,
    /// Input driven by the output, e.g. `"tank.outflow"`.
    pub output: String,
    /// Setpoint, e.g. `"1 m"`.
    pub sp: QuantityValue,
    /// `optimal` or `error_squared`.
    pub law: AveragingLaw,
    /// The band `Δ`: the largest level deviation the optimal law plans for, or the error at which
    /// the error-squared gain equals `kc` (units of the measurement); > 0.
    pub level_band: QuantityValue,
    /// Optimal law: output × time per unit of measurement, `A/v_L` for a vessel with molar flows
    /// (e.g. `"3.14 kmol/m"`); > 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub capacity: Option<QuantityValue>,
    /// Optimal law: time of the critically damped return to the setpoint (e.g. `"30 min"`); > 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub return_time: Option<QuantityValue>,
    /// Optimal law: largest rate of change of the output (output per time; default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_rate: Option<QuantityValue>,
    /// Optimal law: filter time of the level-rate estimate (default 1 s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filter: Option<QuantityValue>,
    /// Error-squared law: gain at the band's edge (output per unit of measurement); > 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kc: Option<QuantityValue>,
    /// Error-squared law: reset time (omit for P-only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tau_i: Option<QuantityValue>,
    /// Direct (the output is an outflow) or reverse (an inflow); default reverse, as a PID's.
    #[serde(default)]
    pub action: Action,
    /// Error-squared law: output at zero error; default the driven input's value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bias: Option<QuantityValue>,
    /// Lower output limit (default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub op_min: Option<QuantityValue>,
    /// Upper output limit (default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub op_max: Option<QuantityValue>,
}

impl super::ControllerConfig for AveragingLevelConfig {
    fn paths(&self) -> super::ControllerPaths {
        super::ControllerPaths {
            measured: vec![("pv".to_string(), self.pv.clone())],
            driven: vec![("output".to_string(), self.output.clone())],
        }
    }
}

/// The law's own settings (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Law {
    Optimal { capacity: f64, return_time: f64, max_rate: f64, filter: f64 },
    ErrorSquared { kc: f64, tau_i: Option<f64>, bias: f64 },
}

/// A nonlinear averaging level controller.
#[derive(Debug, Clone)]
pub struct AveragingLevel {
    pv_path: String,
    sp: f64,
    band: f64,
    law: Law,
    sign: f64,
    op_min: f64,
    op_max: f64,
    links: ControllerLinks,
}

/// Fields that belong to one law only: `(field, given, law)`.
fn misplaced(c: &AveragingLevelConfig) -> Vec<(&'static str, bool, AveragingLaw)> {
    use AveragingLaw::{ErrorSquared, Optimal};
    vec![
        ("capacity", c.capacity.is_some(), Optimal),
        ("return_time", c.return_time.is_some(), Optimal),
        ("max_rate", c.max_rate.is_some(), Optimal),
        ("filter", c.filter.is_some(), Optimal),
        ("kc", c.kc.is_some(), ErrorSquared),
        ("tau_i", c.tau_i.is_some(), ErrorSquared),
        ("bias", c.bias.is_some(), ErrorSquared),
    ]
}

impl AveragingLevel {
    /// Build from the flowsheet description and the resolved links.
    pub fn build(
        c: &AveragingLevelConfig,
        mut cx: BuildCx<'_>,
        links: &ControllerLinks,
    ) -> Result<AveragingLevel, Vec<FieldError>> {
        for (field, given, law) in misplaced(c) {
            if given && law != c.law {
                cx.error(field, format!("applies to \"law\": \"{}\" only", law_name(law)));
            }
        }
        let sp = cx.quantity("sp", &c.sp, links.pv_dim);
        let band = cx.positive("level_band", &c.level_band, links.pv_dim);
        let law = match c.law {
            AveragingLaw::Optimal => optimal(c, &mut cx, links),
            AveragingLaw::ErrorSquared => error_squared(c, &mut cx, links),
        };
        let op_min = c.op_min.as_ref().map_or(f64::NEG_INFINITY, |v| cx.quantity("op_min", v, links.op_dim));
        let op_max = c.op_max.as_ref().map_or(f64::INFINITY, |v| cx.quantity("op_max", v, links.op_dim));
        if op_min >= op_max {
            cx.error("op_max", format!("must exceed op_min ({op_min} ≥ {op_max} in SI units)"));
        }
        let sign = match c.action {
            Action::Direct => 1.0,
            Action::Reverse => -1.0,
        };
        let a = AveragingLevel { pv_path: c.pv.clone(), sp, band, law, sign, op_min, op_max, links: links.clone() };
        cx.finish(a)
    }

    /// The optimal law's rate `dop/dt` before the rate and output limits, from the level's error
    /// `e` and its rate estimate `v` (see the module documentation).
    fn optimal_rate<S: Scalar>(&self, e: S, v: S, capacity: f64, return_time: f64) -> S {
        let planned = if v.re() * e.re() > 0.0 {
            let room = self.band - e.re().abs();
            let left = if room <= 1e-6 * self.band {
                S::from(1e-6 * self.band)
            } else if e.re() > 0.0 {
                S::from(self.band) - e
            } else {
                S::from(self.band) + e
            };
            let v_abs = if v.re() < 0.0 { -v } else { v };
            let ramp = v * v_abs / (left * 2.0);
            let back = e / (return_time * return_time) + v * (2.0 / return_time);
            if ramp.re().abs() >= back.re().abs() { ramp } else { back }
        } else {
            e / (return_time * return_time) + v * (2.0 / return_time)
        };
        planned * (self.sign * capacity)
    }
}

fn law_name(law: AveragingLaw) -> &'static str {
    match law {
        AveragingLaw::Optimal => "optimal",
        AveragingLaw::ErrorSquared => "error_squared",
    }
}

fn optimal(c: &AveragingLevelConfig, cx: &mut BuildCx<'_>, links: &ControllerLinks) -> Law {
    let mut required = |field: &str, v: &Option<QuantityValue>, dim: Dimension| match v {
        Some(v) => cx.positive(field, v, dim),
        None => {
            cx.error(field, "is required by \"law\": \"optimal\"");
            f64::NAN
        }
    };
    let capacity = required("capacity", &c.capacity, links.op_dim * Dimension::TIME / links.pv_dim);
    let return_time = required("return_time", &c.return_time, Dimension::TIME);
    let max_rate =
        c.max_rate.as_ref().map_or(f64::INFINITY, |r| cx.positive("max_rate", r, links.op_dim / Dimension::TIME));
    let filter = c.filter.as_ref().map_or(1.0, |f| cx.positive("filter", f, Dimension::TIME));
    Law::Optimal { capacity, return_time, max_rate, filter }
}

fn error_squared(c: &AveragingLevelConfig, cx: &mut BuildCx<'_>, links: &ControllerLinks) -> Law {
    let kc = match &c.kc {
        Some(k) => cx.gain("kc", k, gain_dimension(links)),
        None => {
            cx.error("kc", "is required by \"law\": \"error_squared\"");
            f64::NAN
        }
    };
    let tau_i = c.tau_i.as_ref().map(|t| cx.positive("tau_i", t, Dimension::TIME));
    let bias = c.bias.as_ref().map_or(links.op_value, |b| cx.quantity("bias", b, links.op_dim));
    Law::ErrorSquared { kc, tau_i, bias }
}

impl UnitModel for AveragingLevel {
    fn type_name(&self) -> &'static str {
        "averaging_level"
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        let pv_scale = self.links.pv_nominal.abs().max(1e-6);
        let op_scale = self.links.op_value.abs().max(1e-6);
        match self.law {
            Law::Optimal { .. } => vec![
                VarSpec::differential("xf", self.links.pv_dim, pv_scale),
                VarSpec::differential("op", self.links.op_dim, op_scale),
            ],
            Law::ErrorSquared { tau_i, .. } => {
                let mut v = Vec::new();
                if let Some(ti) = tau_i {
                    v.push(VarSpec::differential("I", self.links.pv_dim * Dimension::TIME, pv_scale * ti));
                }
                v.push(VarSpec::algebraic("op", self.links.op_dim, op_scale));
                v
            }
        }
    }
    fn inputs(&self) -> Vec<InputSpec> {
        vec![InputSpec { name: "sp".into(), dim: self.links.pv_dim, value: self.sp }]
    }
    fn signals(&self) -> Vec<SignalSpec> {
        vec![SignalSpec { role: "pv".into(), path: self.pv_path.clone() }]
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let e = io.signal(0) - io.input(0);
        match self.law {
            Law::Optimal { capacity, return_time, max_rate, filter } => {
                let (xf, op) = (io.var(0), io.var(1));
                let v = (io.signal(0) - xf) / filter;
                r[0] = v;
                let rate = clamp(self.optimal_rate(e, v, capacity, return_time), -max_rate, max_rate);
                let blocked =
                    (op.re() >= self.op_max && rate.re() > 0.0) || (op.re() <= self.op_min && rate.re() < 0.0);
                r[1] = if blocked { S::from(0.0) } else { rate };
            }
            Law::ErrorSquared { kc, tau_i, bias } => {
                let e = e * self.sign;
                let e_abs = if e.re() < 0.0 { -e } else { e };
                let mut u = e * e_abs / self.band;
                if let Some(ti) = tau_i {
                    u += io.var(0) / ti;
                }
                let u = u * kc + bias;
                let n = usize::from(tau_i.is_some());
                let op = io.var(n);
                if tau_i.is_some() {
                    r[0] = e + (op - u) / kc;
                }
                r[n] = op - clamp(u, self.op_min, self.op_max);
            }
        }
    }
    fn without_limits(&self) -> Option<Self> {
        let limited = self.op_min > f64::NEG_INFINITY || self.op_max < f64::INFINITY;
        limited.then(|| AveragingLevel { op_min: f64::NEG_INFINITY, op_max: f64::INFINITY, ..self.clone() })
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        match self.law {
            Law::Optimal { .. } => {
                own[0] = io.signal(0);
                own[1] = self.links.op_value.clamp(self.op_min, self.op_max);
            }
            Law::ErrorSquared { tau_i, .. } => {
                let n = usize::from(tau_i.is_some());
                if n == 1 {
                    own[0] = 0.0;
                }
                own[n] = self.links.op_value.clamp(self.op_min, self.op_max);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use plantwide_units::Dimension;
    use serde_json::json;

    use super::*;
    use crate::testing::{binary_package, jacobian_error};
    use crate::{LocalLayout, StreamLayout, Unit};

    /// A level (m) controller moving a molar flow (mol/s) whose flowsheet value is 5 mol/s.
    fn links() -> ControllerLinks {
        ControllerLinks {
            measured_dims: Vec::new(),
            driven: Vec::new(),
            pv_dim: Dimension::LENGTH,
            op_dim: Dimension::MOLAR_FLOW,
            op_value: 5.0,
            pv_nominal: 1.0,
            measured_ranges: Vec::new(),
            driven_ranges: Vec::new(),
        }
    }

    fn build(config: serde_json::Value) -> Result<AveragingLevel, Vec<FieldError>> {
        let mut base = json!({"pv": "tank.level", "output": "tank.outflow", "sp": "1 m", "action": "direct"});
        if let (Some(b), Some(e)) = (base.as_object_mut(), config.as_object()) {
            b.extend(e.clone());
        }
        let c: AveragingLevelConfig = serde_json::from_value(base).expect("valid description");
        let thermo = binary_package();
        let comps = vec!["light".to_string(), "heavy".to_string()];
        AveragingLevel::build(&c, BuildCx::new(&comps, &thermo, "controllers.lc"), &links())
    }

    /// The optimal law as the surge sizing writes it: the rate limited to the design's own rate
    /// (here `Δu²/(2 C Δ)` = 0.002 mol/s² for a 2 mol/s step on 5000 mol/m and a 0.2 m band).
    fn optimal() -> AveragingLevel {
        build(json!({"law": "optimal", "level_band": "0.2 m", "capacity": "5000 mol/m", "return_time": "4000 s",
                     "filter": "0.1 s", "max_rate": "0.002 mol/s/s"}))
        .expect("builds")
    }

    fn layout(u: &dyn Unit) -> LocalLayout {
        LocalLayout {
            stream: StreamLayout { n_comp: 2 },
            n_outlets: 0,
            n_internal: u.internal_vars().len(),
            n_inlets: 0,
            n_inputs: u.inputs().len(),
            n_signals: u.signals().len(),
        }
    }

    fn residual(u: &dyn Unit, local: &[f64]) -> Vec<f64> {
        let thermo = binary_package();
        let layout = layout(u);
        let mut r = vec![f64::NAN; layout.n_own()];
        u.residual(&UnitIo { local, layout: &layout, thermo: &thermo, time: 0.0 }, &mut r);
        r
    }

    /// The closed loop of the optimal law on a pure integrator `C dy/dt = F_in − op`, inflow
    /// stepped by `du` at t = 0, integrated by RK4 with step `dt`: (largest |y − sp|, largest
    /// |dop/dt|, final y − sp, final op − op₀).
    fn integrate(u: &AveragingLevel, capacity: f64, du: f64, dt: f64, t_end: f64) -> (f64, f64, f64, f64) {
        let f = |s: [f64; 3]| {
            // s = [y, xf, op]; local = [xf, op | sp | pv]
            let r = residual(u, &[s[1], s[2], 1.0, s[0]]);
            [(5.0 + du - s[2]) / capacity, r[0], r[1]]
        };
        let (mut s, mut peak, mut rate) = ([1.0, 1.0, 5.0], 0.0f64, 0.0f64);
        for _ in 0..(t_end / dt).round() as usize {
            let k1 = f(s);
            let k2 = f(std::array::from_fn(|i| s[i] + 0.5 * dt * k1[i]));
            let k3 = f(std::array::from_fn(|i| s[i] + 0.5 * dt * k2[i]));
            let k4 = f(std::array::from_fn(|i| s[i] + dt * k3[i]));
            let before = s[2];
            for i in 0..3 {
                s[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            peak = peak.max((s[0] - 1.0).abs());
            rate = rate.max((s[2] - before).abs() / dt);
        }
        (peak, rate, s[0] - 1.0, s[2] - 5.0)
    }

    #[test]
    fn optimal_law_ramps_at_the_closed_form_rate_and_stops_at_the_band() {
        let u = optimal();
        // Step of 2 mol/s on a capacity of 5000 mol/m with a 0.2 m band: rate Δu²/(2 C Δ) = 0.002
        // mol/s², reached after the ramp time Δu/rate = 1000 s.
        let (capacity, du, band) = (5000.0, 2.0, 0.2);
        let rate = du * du / (2.0 * capacity * band);
        let (peak, max_rate, _, dop) = integrate(&u, capacity, du, 0.05, 1000.0);
        // The level stops at the band's edge (within the filter's lag, τ_f/t* = 1e-4, and the
        // braking it defers) just as the outflow meets the inflow.
        assert!((peak / band - 1.0).abs() < 1e-3, "peak {peak}");
        assert!(max_rate <= rate * (1.0 + 1e-9) && max_rate > rate * (1.0 - 1e-3), "rate {max_rate} vs {rate}");
        assert!((dop / du - 1.0).abs() < 1e-3, "{dop}");
        // Then the level returns to its setpoint and the outflow matches the inflow.
        let (peak, _, e, dop) = integrate(&u, capacity, du, 0.05, 60_000.0);
        assert!(peak < band * (1.0 + 1e-3), "the return does not carry it beyond the band: {peak}");
        assert!(e.abs() < 1e-4 * band && (dop - du).abs() < 1e-4 * du, "{e} {dop}");
    }

    #[test]
    fn a_rate_limit_below_the_design_rate_lets_the_level_pass_the_band() {
        let u = build(json!({"law": "optimal", "level_band": "0.2 m", "capacity": "5000 mol/m",
                             "return_time": "4000 s", "filter": "0.1 s", "max_rate": "0.001 mol/s/s"}))
        .unwrap();
        let (peak, max_rate, _, _) = integrate(&u, 5000.0, 2.0, 0.05, 3000.0);
        assert!(max_rate <= 0.001 * (1.0 + 1e-9), "{max_rate}");
        // Braking at half the needed rate: the level passes the band.
        assert!(peak > 0.2, "{peak}");
    }

    #[test]
    fn steady_state_rests_on_the_setpoint() {
        let u = optimal();
        // [xf, op | sp | pv]: on setpoint and still, any outflow is a steady state.
        let r = residual(&u, &[1.0, 7.0, 1.0, 1.0]);
        assert!(r.iter().all(|v| v.abs() < 1e-15), "{r:?}");
        // Off setpoint and still: the return law moves the output, C e/τ_R².
        let r = residual(&u, &[1.1, 7.0, 1.0, 1.1]);
        assert!((r[1] - 5000.0 * 0.1 / 16e6).abs() < 1e-12, "{r:?}");
    }

    #[test]
    fn error_squared_gain_grows_with_the_error() {
        let u = build(json!({"law": "error_squared", "level_band": "0.5 m", "kc": "10 mol/s/m"})).unwrap();
        // P-only: op = bias + Kc e|e|/Δ; at e = 0.25 m: 5 + 10·0.0625/0.5 = 6.25 mol/s.
        let r = residual(&u, &[6.25, 1.0, 1.25]);
        assert!(r[0].abs() < 1e-12, "{r:?}");
        // It settles where Kc e²/Δ balances the flow change: √(Δ |op − bias|/Kc).
        let e = (0.5f64 * 2.0 / 10.0).sqrt();
        assert!(residual(&u, &[7.0, 1.0, 1.0 + e])[0].abs() < 1e-12);
        let pi = build(json!({"law": "error_squared", "level_band": "0.5 m", "kc": "10 mol/s/m", "tau_i": "100 s"}))
            .unwrap();
        // [I, op | sp | pv]: off setpoint the integral moves, dI/dt = e.
        let r = residual(&pi, &[0.0, 5.0 + 10.0 * 0.01 / 0.5, 1.0, 1.1]);
        assert!((r[0] - 0.1).abs() < 1e-12 && r[1].abs() < 1e-12, "{r:?}");
    }

    #[test]
    fn jacobians_match_finite_differences() {
        let u = optimal();
        let thermo = binary_package();
        for local in [[1.02, 6.0, 1.0, 1.05], [1.1, 6.0, 1.0, 1.05], [1.0, 6.0, 1.0, 1.0]] {
            let l = layout(&u);
            assert!(jacobian_error(&u, &l, &thermo, &local, l.n_own()) < 1e-7, "{local:?}");
        }
        let pi = build(json!({"law": "error_squared", "level_band": "0.5 m", "kc": "10 mol/s/m", "tau_i": "100 s"}))
            .unwrap();
        let l = layout(&pi);
        assert!(jacobian_error(&pi, &l, &thermo, &[3.0, 6.0, 1.0, 0.7], l.n_own()) < 1e-7);
    }

    #[test]
    fn fields_of_the_other_law_and_missing_ones_are_named() {
        let errs = build(json!({"law": "optimal", "level_band": "0.2 m", "kc": "1 mol/s/m"})).unwrap_err();
        let paths: Vec<&str> = errs.iter().map(|e| e.path.as_str()).collect();
        assert!(paths.contains(&"controllers.lc.kc"), "{paths:?}");
        assert!(paths.contains(&"controllers.lc.capacity") && paths.contains(&"controllers.lc.return_time"));
        let errs = build(json!({"law": "error_squared", "level_band": "-1 m", "kc": "1 mol/s/m"})).unwrap_err();
        assert_eq!(errs[0].path, "controllers.lc.level_band");
    }
}
