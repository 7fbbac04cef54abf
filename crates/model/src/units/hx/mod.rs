//! Two-stream counter-current heat exchanger; no holdup, no phase change.
//!
//! Ports: inlets `hot_in`, `cold_in`; outlets `hot_out`, `cold_out`. Input: `ua` [W/K], the overall
//! conductance. Internal variable `Q` [W], heat from the hot to the cold side; with `method: cells`
//! also `T_hot[k]` [K], `h_hot[k]` [J/mol], `T_cold[k]`, `h_cold[k]` at the boundaries
//! `k = 1 … n−1` between cell `k` and cell `k+1`, counted from the hot-inlet end.
//!
//! Equations, each side `s ∈ {hot, cold}` (own block `[hot_out | cold_out | Q | cell states…]`):
//! - `F_s,out = F_s,in` [mol/s], `z_s,out = z_s,in` [-], `P_s,out = P_s,in − dp_s` [Pa];
//! - `h_s,out = h_phase_s(T_s,out, z_s)` [J/mol] (`hot_phase`, `cold_phase`: liquid or vapour; each
//!   side keeps its phase: sensible heat only, put a flash downstream for condensing or boiling);
//! - energy `F_hot (h_hot,in − h_hot,out) = Q = F_cold (h_cold,out − h_cold,in)` [W].
//!
//! Rate, `method: lmtd`: `Q = UA · ΔT_lm(ΔT1, ΔT2)`, `ΔT1 = T_hot,in − T_cold,out`,
//! `ΔT2 = T_hot,out − T_cold,in` [K], `ΔT_lm = (ΔT1 − ΔT2)/ln(ΔT1/ΔT2) = ΔT2 · u/ln(1+u)`,
//! `u = ΔT1/ΔT2 − 1`; for `|u| < 1e-6` the series `u/ln(1+u) = 1 + u/2 − u²/12 + u³/24` (error
//! < 1e-19; dual numbers stay exact). A temperature cross (`ΔT ≤ 0`) has no logarithmic mean: an
//! argument below `δ = 1e-3 K` is clipped to `δ` and the mean continued linearly,
//! `ΔT_lm(δ, ΔT2) + ∂ΔT_lm/∂ΔT1 · (ΔT1 − δ)` (likewise `ΔT2`): C¹, finite and steep
//! (`≈ (ΔT2/δ)/ln²(ΔT2/δ)`), so Newton iterates that cross are pushed back; both below `δ` give the
//! arithmetic mean `(ΔT1 + ΔT2)/2` (reversed inlets give `Q < 0`). Only an approach below `δ`
//! (NTU ≳ 1000) is inexact, by `O(10 δ)`. Exact for constant heat capacities: it reproduces
//! `ε = (1 − e^(−NTU(1−Cr)))/(1 − Cr e^(−NTU(1−Cr)))`, `NTU = UA/C_min`, `Cr = C_min/C_max`
//! (`C = F ∂h/∂T` [W/K]; the guess uses it with `C` at the inlets).
//!
//! Rate, `method: cells {n}`: `n` well-mixed cells in counter-current series, hot through cells
//! `1 → n`, cold `n → 1`. Hot boundary 0 is the hot inlet and `n` the hot outlet; cold boundary 0 is
//! the cold outlet and `n` the cold inlet. Cell `k` exchanges `Q_k = (UA/n)(T_hot[k] − T_cold[k−1])`
//! (its two outlet temperatures), `F_hot (h_hot[k−1] − h_hot[k]) = Q_k = F_cold (h_cold[k−1] −
//! h_cold[k])`, `h_s[k] = h_phase_s(T_s[k], z_s)`, `Q = Σ Q_k`. First order: the effectiveness error
//! is `≈ −0.44/n` at NTU 2, `Cr = 2/3`; crosses and reversed inlets need no special care.
//!
//! With `holdup_hot` and `holdup_cold` (and optionally `wall_heat_capacity`), `cells` carry
//! holdups and the exchanger has dynamics; its variables are then per cell, not per boundary
//! (see [`dynamic`]). Its steady state is the static `cells` model's.

pub mod dynamic;

use crate::capability::{Booking, Duty, DutySource};
use num_dual::Dual64;
use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::Phase;
use crate::stream::{F, H, P, T, Z0};
use crate::{BuildCx, FieldError, InputSpec, Scalar, UnitIo, UnitModel, VarSpec};

/// Smallest temperature difference [K] used in the logarithmic mean (see the module documentation).
pub const DT_MIN: f64 = 1e-3;
/// Most cells allowed in `method: cells`.
pub const MAX_CELLS: usize = 1000;

/// How the heat-transfer rate is computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum HxMethod {
    /// `Q = UA ΔT_lm` (exact for constant heat capacities).
    Lmtd {},
    /// `n` well-mixed counter-current cells in series.
    Cells {
        /// Number of cells [-], 1 … 1000.
        n: usize,
    },
}

impl Default for HxMethod {
    fn default() -> HxMethod {
        HxMethod::Lmtd {}
    }
}

/// Flowsheet description of a two-stream heat exchanger.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HeatExchangerConfig {
    /// Overall conductance UA [W/K] (e.g. `"5 kW/K"`; input `ua`).
    pub ua: QuantityValue,
    /// Rate model (default `{"type": "lmtd"}`; or `{"type": "cells", "n": 20}`).
    #[serde(default)]
    pub method: HxMethod,
    /// Phase of the hot side [-] (default `liquid`).
    #[serde(default)]
    pub hot_phase: Phase,
    /// Phase of the cold side [-] (default `liquid`).
    #[serde(default)]
    pub cold_phase: Phase,
    /// Pressure drop of the hot side [Pa] (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dp_hot: Option<QuantityValue>,
    /// Pressure drop of the cold side [Pa] (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dp_cold: Option<QuantityValue>,
    /// Liquid holdup of the hot side [mol] (e.g. `"2 kmol"`): with `holdup_cold`, gives `cells`
    /// their dynamics (default: none, the exchanger is algebraic).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub holdup_hot: Option<QuantityValue>,
    /// Liquid holdup of the cold side [mol].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub holdup_cold: Option<QuantityValue>,
    /// Heat capacity of the tube wall [J/K] (e.g. `"500 kJ/K"`; dynamic cells only; default: no
    /// wall, the two fluids exchange directly).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wall_heat_capacity: Option<QuantityValue>,
}

impl crate::registry::UnitConfig for HeatExchangerConfig {
    fn ports() -> &'static str {
        "inlets `hot_in` and `cold_in`, outlets `hot_out` and `cold_out`"
    }
}

/// A two-stream counter-current heat exchanger.
#[derive(Debug, Clone)]
pub struct HeatExchanger {
    ua: f64,
    method: HxMethod,
    phase: [Phase; 2],
    dp: [f64; 2],
    holdups: Option<dynamic::Holdups>,
}

/// Index of `Q` among the internal variables; cell boundary `k` starts at `1 + 4 (k − 1)`.
const Q: usize = 0;

/// `ΔT_lm` and its partial derivatives `(∂/∂ΔT1, ∂/∂ΔT2)` for `a, b ≥ DT_MIN`.
fn lmtd_core<S: Scalar>(a: S, b: S) -> (S, S, S) {
    let u = (a - b) / b;
    if u < 1e-6 && u > -1e-6 {
        let g = b * (u * (u * (u / 24.0 - 1.0 / 12.0) + 0.5) + 1.0);
        (g, u * (u / 8.0 - 1.0 / 6.0) + 0.5, u * (u / -24.0 + 1.0 / 6.0) + 0.5)
    } else {
        let l = u.ln_1p();
        let g = (a - b) / l;
        (g, (-g / a + 1.0) / l, (g / b - 1.0) / l)
    }
}

/// Logarithmic mean temperature difference [K] of `dt1`, `dt2` [K], continued linearly below
/// `DT_MIN` (see the module documentation).
pub fn lmtd<S: Scalar>(dt1: S, dt2: S) -> S {
    let clip = |dt: S| if dt >= DT_MIN { dt } else { S::from(DT_MIN) };
    let (g, ga, gb) = lmtd_core(clip(dt1), clip(dt2));
    let extend = |d: S, dt: S| if dt < DT_MIN { d * (dt - DT_MIN) } else { S::from(0.0) };
    g + extend(ga, dt1) + extend(gb, dt2)
}

impl HeatExchanger {
    /// Build from the flowsheet description.
    pub fn build(
        config: &HeatExchangerConfig,
        mut cx: BuildCx<'_>,
        _links: (),
    ) -> Result<HeatExchanger, Vec<FieldError>> {
        let ua = cx.non_negative("ua", &config.ua, Dimension::UA);
        if let HxMethod::Cells { n } = config.method
            && !(1..=MAX_CELLS).contains(&n)
        {
            cx.error("method.n", format!("number of cells must lie in 1 … {MAX_CELLS} (got {n})"));
        }
        let mut dp = [0.0; 2];
        for (d, (field, v)) in dp.iter_mut().zip([("dp_hot", &config.dp_hot), ("dp_cold", &config.dp_cold)]) {
            *d = v.as_ref().map_or(0.0, |v| cx.non_negative(field, v, Dimension::PRESSURE));
        }
        let holdups = holdups(config, &mut cx);
        cx.finish(HeatExchanger {
            ua,
            method: config.method,
            phase: [config.hot_phase, config.cold_phase],
            dp,
            holdups,
        })
    }

    fn n_cells(&self) -> usize {
        match self.method {
            HxMethod::Lmtd {} => 0,
            HxMethod::Cells { n } => n,
        }
    }
}

/// The holdups of a dynamic `cells` exchanger, if the description gives them.
fn holdups(config: &HeatExchangerConfig, cx: &mut BuildCx<'_>) -> Option<dynamic::Holdups> {
    let (hot, cold) = (config.holdup_hot.as_ref(), config.holdup_cold.as_ref());
    if hot.is_none() && cold.is_none() {
        if config.wall_heat_capacity.is_some() {
            cx.error("wall_heat_capacity", "a wall needs the fluids' holdups: give holdup_hot and holdup_cold too");
        }
        return None;
    }
    if !matches!(config.method, HxMethod::Cells { .. }) {
        cx.error("method", "holdups need cells: give \"method\": {\"type\": \"cells\", \"n\": 10}");
    }
    let mut side = [0.0; 2];
    for (m, (field, v)) in side.iter_mut().zip([("holdup_hot", hot), ("holdup_cold", cold)]) {
        match v {
            Some(v) => *m = cx.positive(field, v, Dimension::AMOUNT),
            None => cx.error(field, "give both holdups (e.g. \"2 kmol\"), or neither for an algebraic exchanger"),
        }
    }
    let wall =
        config.wall_heat_capacity.as_ref().map(|c| cx.positive("wall_heat_capacity", c, Dimension::HEAT_CAPACITY));
    Some(dynamic::Holdups { side, wall })
}

impl UnitModel for HeatExchanger {
    fn type_name(&self) -> &'static str {
        "heat_exchanger"
    }
    /// `Q` \[W\], moved from the hot side to the cold.
    fn duties(&self) -> Vec<Duty> {
        vec![Duty { source: DutySource::Var("Q".into()), booking: Booking::Recovered }]
    }
    fn inlet_ports(&self) -> Vec<String> {
        vec!["hot_in".into(), "cold_in".into()]
    }
    fn outlet_ports(&self) -> Vec<String> {
        vec!["hot_out".into(), "cold_out".into()]
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        let mut v = vec![VarSpec::algebraic("Q", Dimension::POWER, 1e5)];
        if let Some(h) = &self.holdups {
            v.extend(h.vars(self.n_cells()));
            return v;
        }
        for k in 1..self.n_cells() {
            for side in ["hot", "cold"] {
                v.push(
                    VarSpec::algebraic(format!("T_{side}[{k}]"), Dimension::TEMPERATURE, 350.0).bounded(1.0, 5000.0),
                );
                v.push(VarSpec::algebraic(format!("h_{side}[{k}]"), Dimension::MOLAR_ENERGY, 3e4));
            }
        }
        v
    }
    fn inputs(&self) -> Vec<InputSpec> {
        vec![InputSpec { name: "ua".into(), dim: Dimension::UA, value: self.ua }]
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let len = io.layout.stream.len();
        let ua = io.input(0);
        let q = io.var(Q);
        // stream relations of both sides; rows H are filled below
        for s in 0..2 {
            let (inlet, out, rs) = (io.inlet(s), io.outlet(s), &mut r[s * len..(s + 1) * len]);
            rs[F] = out.f() - inlet.f();
            rs[P] = out.p() - inlet.p() + self.dp[s];
            for (i, (zo, zi)) in out.z().iter().zip(inlet.z()).enumerate() {
                rs[Z0 + i] = *zo - *zi;
            }
            rs[T] = out.h() - self.phase[s].enthalpy(io.thermo, out.t(), out.p(), out.z());
        }
        if let Some(h) = &self.holdups {
            return dynamic::eval(self, h, io, r);
        }
        let (hi, ci, ho, co) = (io.inlet(0), io.inlet(1), io.outlet(0), io.outlet(1));
        let (q_row, hot_row, cold_row) = (2 * len + Q, H, len + H);
        let n = self.n_cells();
        if n == 0 {
            r[hot_row] = ho.f() * (hi.h() - ho.h()) - q;
            r[cold_row] = co.f() * (co.h() - ci.h()) - q;
            r[q_row] = q - ua * lmtd(hi.t() - co.t(), ho.t() - ci.t());
            return;
        }
        // boundary states (T, h): hot 0 = hot inlet, n = hot outlet; cold 0 = cold outlet, n = cold inlet
        let cell = |k: usize, side: usize| 2 * len + 1 + 4 * (k - 1) + 2 * side;
        let hot = |k: usize| match k {
            0 => (hi.t(), hi.h()),
            k if k == n => (ho.t(), ho.h()),
            k => (io.local[cell(k, 0)], io.local[cell(k, 0) + 1]),
        };
        let cold = |k: usize| match k {
            0 => (co.t(), co.h()),
            k if k == n => (ci.t(), ci.h()),
            k => (io.local[cell(k, 1)], io.local[cell(k, 1) + 1]),
        };
        let uak = ua / n as f64;
        let mut q_sum = S::from(0.0);
        for k in 1..=n {
            let q_k = uak * (hot(k).0 - cold(k - 1).0);
            q_sum += q_k;
            // hot energy of cell k defines h_hot[k]; cold energy of cell k defines h_cold[k−1]
            r[if k == n { hot_row } else { cell(k, 0) + 1 }] = ho.f() * (hot(k - 1).1 - hot(k).1) - q_k;
            r[if k == 1 { cold_row } else { cell(k - 1, 1) + 1 }] = co.f() * (cold(k - 1).1 - cold(k).1) - q_k;
        }
        for k in 1..n {
            let ((th, hh), (tc, hc)) = (hot(k), cold(k));
            r[cell(k, 0)] = hh - self.phase[0].enthalpy(io.thermo, th, hi.p() - self.dp[0], hi.z());
            r[cell(k, 1)] = hc - self.phase[1].enthalpy(io.thermo, tc, ci.p() - self.dp[1], ci.z());
        }
        r[q_row] = q - q_sum;
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let len = io.layout.stream.len();
        let (hi, ci) = (io.inlet(0), io.inlet(1));
        for s in 0..2 {
            let inlet = io.inlet(s);
            let o = &mut own[s * len..(s + 1) * len];
            o[F] = inlet.f();
            o[P] = inlet.p() - self.dp[s];
            o[Z0..].copy_from_slice(inlet.z());
        }
        // ε-NTU with F ∂h/∂T at the inlets (exact for constant c_p and method lmtd)
        let c = |s: usize| {
            let (st, z) = (io.inlet(s), io.inlet(s).z().iter().map(|&v| Dual64::from_re(v)).collect::<Vec<_>>());
            st.f() * self.phase[s].enthalpy(io.thermo, Dual64::new(st.t(), 1.0), Dual64::from_re(st.p()), &z).eps
        };
        let (c_min, c_max, ua) = (c(0).min(c(1)), c(0).max(c(1)), io.input(0));
        let (ntu, cr) = (ua / c_min, c_min / c_max);
        let e = (-ntu * (1.0 - cr)).exp();
        let eff = if (1.0 - cr).abs() < 1e-9 { ntu / (1.0 + ntu) } else { (1.0 - e) / (1.0 - cr * e) };
        let q = eff * c_min * (hi.t() - ci.t());
        let q = if q.is_finite() && c_min > 0.0 { q } else { 0.0 };
        let dh_hot = if hi.f() > 0.0 { q / hi.f() } else { 0.0 };
        let dh_cold = if ci.f() > 0.0 { q / ci.f() } else { 0.0 };
        let n = self.n_cells().max(1);
        // hot boundary k and cold boundary k, each cell carrying Q/n
        for k in 1..=n {
            let f = k as f64 / n as f64;
            let h_hot = hi.h() - f * dh_hot;
            let h_cold = ci.h() + (1.0 - f) * dh_cold;
            let t_hot = self.phase[0].temperature(io.thermo, h_hot, hi.p() - self.dp[0], hi.z(), hi.t());
            let t_cold = self.phase[1].temperature(io.thermo, h_cold, ci.p() - self.dp[1], ci.z(), ci.t());
            if let Some(h) = &self.holdups {
                // cell k: hot boundary k, cold boundary k − 1 (one cell's width warmer)
                let h_c = h_cold + dh_cold / n as f64;
                let t_c = self.phase[1].temperature(io.thermo, h_c, ci.p() - self.dp[1], ci.z(), ci.t());
                dynamic::guess(h, len, k, (t_hot, h_hot), (t_c, h_c), own);
            }
            if k == n {
                own[H] = h_hot;
                own[T] = t_hot;
            } else if self.holdups.is_none() {
                own[2 * len + 1 + 4 * (k - 1)..2 * len + 5 + 4 * (k - 1)]
                    .copy_from_slice(&[t_hot, h_hot, t_cold, h_cold]);
            }
            if k == 1 {
                own[len + H] = ci.h() + dh_cold;
                own[len + T] = self.phase[1].temperature(io.thermo, own[len + H], ci.p() - self.dp[1], ci.z(), ci.t());
            }
        }
        own[2 * len + Q] = q;
    }
}

#[cfg(test)]
mod tests {
    use plantwide_thermo::ThermoPackage;
    use serde_json::json;

    use super::*;
    use crate::testing::{binary_package, jacobian_error};
    use crate::units::pump::tests::{layout_of, n_eq, newton};
    use crate::{LocalLayout, Unit};

    fn build(config: serde_json::Value) -> Result<HeatExchanger, Vec<FieldError>> {
        let names = ["light".to_string(), "heavy".to_string()];
        let cfg: HeatExchangerConfig = serde_json::from_value(config).expect("parses");
        HeatExchanger::build(&cfg, BuildCx::new(&names, &binary_package(), "units.hx"), ())
    }

    /// Hot inlet `fh` mol/s at `th` K, 3 bar, z = (0.2, 0.8); cold `fc` at `tc`, 2 bar, z = (0.6, 0.4);
    /// own block from the guess.
    fn local(
        u: &HeatExchanger,
        thermo: &ThermoPackage,
        (fh, fc, ua): (f64, f64, f64),
        (th, tc): (f64, f64),
    ) -> (LocalLayout, Vec<f64>) {
        let layout = layout_of(u);
        let mut x = vec![0.0; layout.len()];
        let (hh, hc) =
            (u.phase[0].enthalpy(thermo, th, 1e5, &[0.2, 0.8]), u.phase[1].enthalpy(thermo, tc, 1e5, &[0.6, 0.4]));
        let i0 = layout.inlets_offset();
        x[i0..i0 + 12].copy_from_slice(&[fh, th, 3e5, hh, 0.2, 0.8, fc, tc, 2e5, hc, 0.6, 0.4]);
        x[layout.inputs_offset()] = ua;
        let mut own = vec![0.0; layout.n_own()];
        Unit::guess(u, &UnitIo { local: &x, layout: &layout, thermo, time: 0.0 }, &mut own);
        x[..layout.n_own()].copy_from_slice(&own);
        (layout, x)
    }

    /// Converge the own block from a crossed start (ΔT1 < 0 < ΔT2 … or worse), check both energy
    /// balances to 1e-9, return (Q, ε-NTU Q for c_p = 150 J/(mol K)).
    fn solve(u: &HeatExchanger, case: (f64, f64, f64), temps: (f64, f64)) -> (f64, f64) {
        let thermo = binary_package();
        let (layout, mut x) = local(u, &thermo, case, temps);
        let len = layout.stream.len();
        (x[T], x[len + T], x[2 * len + Q]) = (temps.1 - 10.0, temps.0 + 10.0, 0.0);
        let res = newton(u, &layout, &thermo, &mut x, &(0..layout.n_own()).collect::<Vec<_>>());
        let i0 = layout.inlets_offset();
        let q = x[2 * len + Q];
        let (q_hot, q_cold) = (x[F] * (x[i0 + H] - x[H]), x[len + F] * (x[len + H] - x[i0 + len + H]));
        assert!(
            res < 1e-7 && (q_hot - q).abs() < 1e-9 * q.abs() && (q_cold - q).abs() < 1e-9 * q.abs(),
            "{res} {q} {q_hot} {q_cold}"
        );
        assert!((x[P] - 3e5 + u.dp[0]).abs() < 1e-6 && (x[len + P] - 2e5 + u.dp[1]).abs() < 1e-6);
        let (c_min, c_max) = (150.0 * case.0.min(case.1), 150.0 * case.0.max(case.1));
        let (ntu, cr) = (case.2 / c_min, c_min / c_max);
        let e = (-ntu * (1.0 - cr)).exp();
        let eff = if cr == 1.0 { ntu / (1.0 + ntu) } else { (1.0 - e) / (1.0 - cr * e) };
        (q, eff * c_min * (temps.0 - temps.1))
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let thermo = binary_package();
        let lmtd_cfg = json!({"ua": "300 W/K"});
        let cells =
            json!({"ua": 300.0, "method": {"type": "cells", "n": 4}, "dp_hot": "0.1 bar", "cold_phase": "vapour"});
        // off-solution states; for lmtd also a cross (ΔT1 < 0) and ΔT1 ≈ ΔT2 (series branch)
        let states =
            [(lmtd_cfg.clone(), None), (cells, None), (json!({"ua": 300, "method": {"type": "cells", "n": 1}}), None)]
                .into_iter()
                .chain([(lmtd_cfg.clone(), Some((350.0, 410.0))), (lmtd_cfg, Some((350.0 + 1e-5, 350.0)))]);
        for (cfg, outlets) in states {
            let u = build(cfg.clone()).expect("builds");
            let (layout, mut x) = local(&u, &thermo, (1.0, 1.0, 300.0), (400.0, 300.0));
            let len = layout.stream.len();
            (x[T], x[len + T]) = outlets.unwrap_or((x[T] - 4.0, x[len + T] + 3.0));
            let err = jacobian_error(&u, &layout, &thermo, &x, n_eq(&u, &layout));
            println!("hx {cfg} outlets {outlets:?}: jacobian error {err:.2e}");
            assert!(err < 1e-6, "{cfg}: {err}");
        }
    }

    #[test]
    fn lmtd_reproduces_effectiveness_ntu() {
        let u = build(json!({"ua": 300.0, "dp_hot": 1e4, "dp_cold": "0.05 bar"})).expect("builds");
        // C_min hot, C_min cold, balanced (series branch), NTU 5
        for case in [(1.0, 1.5, 300.0), (2.0, 0.7, 250.0), (1.0, 1.0, 300.0), (0.5, 3.0, 375.0)] {
            let (q, q_ntu) = solve(&u, case, (400.0, 300.0));
            let rel = (q - q_ntu).abs() / q_ntu;
            println!("hx lmtd (F_hot, F_cold, UA) = {case:?}: Q = {q:.9} W, ε-NTU {q_ntu:.9} W, rel {rel:.1e}");
            assert!(rel < 1e-9, "{rel}");
        }
        let (q, _) = solve(&u, (1.0, 1.5, 300.0), (300.0, 400.0)); // reversed inlets
        assert!(q < 0.0);
    }

    #[test]
    fn cells_converge_to_effectiveness_ntu() {
        let mut errs = Vec::new();
        for n in [1, 2, 5, 10, 20, 50, 100, 200] {
            let u = build(json!({"ua": 300.0, "method": {"type": "cells", "n": n}})).expect("builds");
            let (q, q_ntu) = solve(&u, (1.0, 1.5, 300.0), (400.0, 300.0));
            let d_eff = (q - q_ntu) / 15000.0;
            println!(
                "hx cells NTU 2, n = {n}: Q = {q:.6} W, ε-NTU {q_ntu:.6} W, ε error {d_eff:.3e}, n·error {:.4}",
                n as f64 * d_eff
            );
            errs.push(d_eff);
        }
        assert!(errs.windows(2).all(|w| w[1].abs() < w[0].abs()), "monotone");
        // first order (n·error → −0.44), Richardson extrapolation recovers ε-NTU
        assert!(errs[5].abs() < 1e-2 && (2.0 * errs[6] / errs[5] - 1.0).abs() < 0.05);
        assert!((2.0 * errs[7] - errs[6]).abs() < 1e-4, "{}", 2.0 * errs[7] - errs[6]);
        // the error grows with NTU: n = 50 meets 1e-3 at NTU 0.25 (7.1e-4), not at NTU 2 (8.7e-3)
        let u = build(json!({"ua": 37.5, "method": {"type": "cells", "n": 50}})).expect("builds");
        let (q, q_ntu) = solve(&u, (1.0, 1.5, 37.5), (400.0, 300.0));
        println!("hx cells NTU 0.25, n = 50: ε error {:.3e}", (q - q_ntu) / 15000.0);
        assert!(((q - q_ntu) / 15000.0).abs() < 1e-3);
    }

    #[test]
    fn lmtd_helper_is_safe() {
        assert!(
            (lmtd(20.0_f64, 10.0) - 10.0 / 2f64.ln()).abs() < 1e-12
                && (lmtd(10.0_f64 + 1e-9, 10.0) - 10.0).abs() < 1e-8
        );
        for (a, b) in [(-5.0, 10.0), (0.0, 0.0), (-3.0, -4.0), (1e-3, 1e-3), (10.0, 1e-4)] {
            let d = lmtd(Dual64::new(a, 1.0), Dual64::from_re(b));
            assert!(d.re.is_finite() && d.eps.is_finite() && d.eps > 0.0, "{a} {b}: {d}");
        }
        assert!((lmtd(-3.0_f64, -4.0) + 3.5).abs() < 1e-12, "both clipped: arithmetic mean");
        let (below, at) = (lmtd(DT_MIN * (1.0 - 1e-9), 10.0), lmtd(DT_MIN, 10.0));
        assert!((below - at).abs() < 1e-9 * at, "continuous at δ");
    }

    const DYNAMIC: &str = r#"{"ua": 300.0, "method": {"type": "cells", "n": 5}, "holdup_hot": "50 mol", "holdup_cold": "0.08 kmol", "dp_hot": "0.1 bar"}"#;

    fn dynamic_configs() -> [serde_json::Value; 2] {
        let plain: serde_json::Value = serde_json::from_str(DYNAMIC).unwrap();
        let mut wall = plain.clone();
        wall["wall_heat_capacity"] = json!("20 kJ/K");
        [plain, wall]
    }

    #[test]
    fn dynamic_cells_jacobian_matches_finite_differences() {
        let thermo = binary_package();
        for cfg in dynamic_configs() {
            let u = build(cfg.clone()).expect("builds");
            let (layout, mut x) = local(&u, &thermo, (1.0, 1.5, 300.0), (400.0, 300.0));
            // off the steady state: every cell state moved
            x.iter_mut().take(layout.n_own()).enumerate().skip(2 * layout.stream.len() + 1).for_each(|(i, v)| {
                *v += if i % 2 == 0 { 3.0 } else { -150.0 };
            });
            let err = jacobian_error(&u, &layout, &thermo, &x, n_eq(&u, &layout));
            assert!(err < 1e-6, "{cfg}: {err}");
        }
    }

    /// Σ m_s dh_s/dt + Σ c_w dT_wall/dt = F_hot (h_hot,in − h_hot,out) + F_cold (h_cold,in −
    /// h_cold,out) at any state, to round-off: the cells neither make nor lose energy.
    #[test]
    fn dynamic_cells_conserve_energy_at_every_state() {
        let thermo = binary_package();
        for cfg in dynamic_configs() {
            let u = build(cfg.clone()).expect("builds");
            let (layout, mut x) = local(&u, &thermo, (1.0, 1.5, 300.0), (400.0, 300.0));
            let len = layout.stream.len();
            let h = u.holdups.unwrap();
            for (i, v) in x.iter_mut().enumerate().take(layout.n_own()).skip(2 * len + 1) {
                *v *= 1.0 + 0.01 * ((i * 7919 % 13) as f64 - 6.0);
            }
            let mut r = vec![0.0; n_eq(&u, &layout)];
            Unit::residual(&u, &UnitIo { local: &x, layout: &layout, thermo: &thermo, time: 0.0 }, &mut r);
            let n = u.n_cells();
            let mut accumulation = 0.0;
            for k in 1..=n {
                let at = h.at(len, k, 0);
                accumulation += h.side[0] / n as f64 * r[at + 1] + h.side[1] / n as f64 * r[at + 3];
                if let Some(c) = h.wall {
                    accumulation += c / n as f64 * r[at + 4];
                }
            }
            let i0 = layout.inlets_offset();
            let (hot_out, cold_out) = (x[h.at(len, n, 1)], x[h.at(len, 1, 3)]);
            let flows = x[i0 + F] * (x[i0 + H] - hot_out) + x[i0 + len + F] * (x[i0 + len + H] - cold_out);
            assert!((accumulation - flows).abs() < 1e-9 * flows.abs().max(1.0), "{cfg}: {accumulation} vs {flows}");
        }
    }

    /// At steady state the holdups and the wall drop out: the dynamic exchanger's outlets and duty
    /// are the static `cells` model's.
    #[test]
    fn dynamic_cells_steady_state_is_the_static_cells_steady_state() {
        let thermo = binary_package();
        let static_cells =
            build(json!({"ua": 300.0, "method": {"type": "cells", "n": 5}, "dp_hot": "0.1 bar"})).unwrap();
        let solve_own = |u: &HeatExchanger| {
            let (layout, mut x) = local(u, &thermo, (1.0, 1.5, 300.0), (400.0, 300.0));
            let res = newton(u, &layout, &thermo, &mut x, &(0..layout.n_own()).collect::<Vec<_>>());
            assert!(res < 1e-9, "{res}");
            let len = layout.stream.len();
            (x[T], x[len + T], x[2 * len + Q])
        };
        let reference = solve_own(&static_cells);
        for cfg in dynamic_configs() {
            let got = solve_own(&build(cfg.clone()).unwrap());
            let (a, b) = (reference, got);
            assert!(
                (a.0 - b.0).abs() < 1e-9 * a.0 && (a.1 - b.1).abs() < 1e-9 * a.1 && (a.2 - b.2).abs() < 1e-9 * a.2,
                "{cfg}: static {a:?}, dynamic {b:?}"
            );
        }
    }

    #[test]
    fn holdups_need_cells_and_each_other() {
        let errs = build(json!({"ua": 300.0, "holdup_hot": "1 kmol"})).expect_err("lmtd with holdup");
        assert!(errs.iter().any(|e| e.to_string().contains("holdups need cells")), "{errs:?}");
        assert!(errs.iter().any(|e| e.to_string().contains("give both holdups")), "{errs:?}");
        let errs = build(json!({"ua": 300.0, "wall_heat_capacity": "1 kJ/K"})).expect_err("wall alone");
        assert!(errs.iter().any(|e| e.to_string().contains("a wall needs")), "{errs:?}");
        let errs =
            build(json!({"ua": 1.0, "method": {"type": "cells", "n": 2}, "holdup_hot": 0.0, "holdup_cold": 1.0}))
                .expect_err("zero holdup");
        assert_eq!(errs.len(), 1, "{errs:?}");
    }

    #[test]
    fn rejects_bad_descriptions() {
        let errs =
            build(json!({"ua": "3 kW", "method": {"type": "cells", "n": 0}, "dp_cold": -1.0})).expect_err("invalid");
        assert_eq!(errs.len(), 3, "{errs:?}");
        assert!(
            serde_json::from_value::<HeatExchangerConfig>(json!({"ua": 1.0, "method": {"type": "lmtd", "n": 3}}))
                .is_err()
        );
    }
}
