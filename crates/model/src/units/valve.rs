//! Control valve between an upstream unit and a downstream unit: adiabatic, no holdup.
//!
//! Ports: inlet `in`, outlet `out`. Input: `flow` [mol/s] (mode `flow_set`) or `opening` [-]
//! (mode `pressure_drop`). No internal variables.
//!
//! **The valve sets its inlet flow.** It owns its outlet stream and writes, besides the `nc + 4`
//! outlet equations, one extra equation (`extra_equations() = +1`) that fixes `F_in`, a variable owned
//! by the upstream unit. The upstream unit must therefore own `F` without writing an equation for it:
//! a vessel with `outflow: {"type": "free"}`. Connecting a valve behind a unit that already fixes its
//! outlet flow (feed, mixer, heater …) over-determines the plant.
//!
//! Equations (own outlet block `[F, T, P, h, z…]`, then the extra row):
//! - `F_out = F_in` [mol/s];
//! - `P_out = p_out` [Pa] (given outlet pressure);
//! - `h_out = h_in` [J/mol] (adiabatic, isenthalpic throttling);
//! - `z_out,i = z_in,i` [-];
//! - `h_out = h_phase(T_out, z_out)` (`phase` liquid or vapour) gives `T_out` [K];
//! - extra row, mode `flow_set`: `F_in = flow` (the valve is the final element of a flow
//!   controller; `flow` is the input, usually the controller output);
//! - extra row, mode `pressure_drop`: `F_in = Cv · f(op) · √(ΔP/ρ) · ρ / M`, with
//!   - `ΔP = P_in − p_out` [Pa],
//!   - `ρ` [kg/m³] the inlet mass density: `M / v_L(T_in, z_in)` for a liquid valve, the ideal gas
//!     `P_in M / (R T_in)` for a vapour valve (incompressible formula with inlet density: good for
//!     `ΔP ≪ P_in`; choked flow is not modelled),
//!   - `M = Σ z_i M_i` [kg/mol] the molar mass,
//!   - `Cv` [m²] the SI flow coefficient: the volumetric flow [m³/s] is `Cv f(op) √(ΔP/ρ)` at full
//!     opening, `√(Pa / (kg/m³))` being a velocity [m/s]. One US Cv (gpm of water per √psi) is
//!     `6.309e-5 m³/s · √(1000 kg/m³ / 6894.76 Pa) = 2.4027e-5 m²`;
//!   - `op` the opening, clamped to `[0, 1]` (a saturated valve);
//!   - `f(op) = op` (linear) or `f(op) = R^(op − 1)` (equal percentage, rangeability `R`, default
//!     50; `f(0) = 1/R`: the ideal characteristic does not shut off).
//!
//!   The square root is smoothed as `√ΔP ≈ ΔP / (ΔP² + δ²)^(1/4)`, `δ = 1 Pa`: odd, slope `δ^(−1/2)`
//!   (finite) at `ΔP = 0`, relative deviation `≈ δ²/(4 ΔP²)` (`2.5e-11` at 0.1 bar). A reversed
//!   pressure difference gives a negative (reverse) flow, which the `F ≥ 0` bounds reject.
//!
//! The package's enthalpies do not depend on pressure, so the throttling is isothermal within the
//! declared phase; a liquid that would flash is not split (put a flash unit downstream).

use plantwide_thermo::R_GAS;
use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::Phase;
use super::outflow::Characteristic;
use crate::capability::{FlowLaw, FlowVia, MaterialFlows};
use crate::stream::{F, H, P, Stream, T, Z0};
use crate::{BuildCx, FieldError, InputSpec, Scalar, UnitIo, UnitModel};

/// Smoothing pressure of the square root near `ΔP = 0` [Pa].
pub const DP_SMOOTH: f64 = 1.0;

/// How the valve sets its flow.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ValveMode {
    /// Final element of a flow controller: the flow is the input `flow`.
    FlowSet {
        /// Molar flow [mol/s] (e.g. `"2 kmol/h"`; input `flow`).
        flow: QuantityValue,
    },
    /// Flow from the pressure drop: `F = Cv f(op) √(ΔP/ρ) ρ/M`.
    PressureDrop {
        /// SI flow coefficient [m²] (`"2.4e-4 m2"`; one US Cv is 2.4027e-5 m²).
        cv: QuantityValue,
        /// Trim characteristic (default `linear`).
        #[serde(default)]
        characteristic: Characteristic,
        /// Rangeability `R` [-] of an equal-percentage trim, > 1 (default 50).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        rangeability: Option<f64>,
        /// Opening [-] in [0, 1] (input `opening`).
        opening: f64,
    },
}

/// Flowsheet description of a control valve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ValveConfig {
    /// How the flow is set: `{"type": "flow_set", …}` or `{"type": "pressure_drop", …}`.
    pub mode: ValveMode,
    /// Outlet pressure [Pa] (e.g. `"1.2 bar"`).
    pub p_out: QuantityValue,
    /// Phase of the fluid [-] (default `liquid`): fixes the enthalpy function and the density.
    #[serde(default)]
    pub phase: Phase,
}

impl crate::registry::UnitConfig for ValveConfig {
    fn ports() -> &'static str {
        "inlet `in`, outlet `out`"
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Mode {
    FlowSet { flow: f64 },
    PressureDrop { cv: f64, characteristic: Characteristic, ln_r: f64, opening: f64 },
}

/// A control valve.
#[derive(Debug, Clone)]
pub struct Valve {
    mode: Mode,
    p_out: f64,
    phase: Phase,
}

/// `√x` smoothed as `x / (x² + δ²)^(1/4)`, `δ = DP_SMOOTH` (odd, finite slope at 0).
fn smooth_sqrt<S: Scalar>(x: S) -> S {
    x / (x * x + DP_SMOOTH * DP_SMOOTH).powf(0.25)
}

impl Valve {
    /// Build from the flowsheet description.
    pub fn build(config: &ValveConfig, mut cx: BuildCx<'_>, _links: ()) -> Result<Valve, Vec<FieldError>> {
        let p_out = cx.positive("p_out", &config.p_out, Dimension::PRESSURE);
        let mode = match &config.mode {
            ValveMode::FlowSet { flow } => {
                Mode::FlowSet { flow: cx.non_negative("mode.flow", flow, Dimension::MOLAR_FLOW) }
            }
            ValveMode::PressureDrop { cv, characteristic, rangeability, opening } => {
                let cv = cx.positive("mode.cv", cv, Dimension::AREA);
                let opening = cx.in_range("mode.opening", *opening, 0.0, 1.0);
                let r = match (characteristic, rangeability) {
                    (Characteristic::Linear, Some(_)) => {
                        cx.error("mode.rangeability", "only an `equal_percentage` trim has a rangeability: remove it");
                        1.0
                    }
                    (Characteristic::Linear, None) => 1.0,
                    (Characteristic::EqualPercentage, r) => {
                        let r = r.unwrap_or(50.0);
                        if !(r.is_finite() && r > 1.0) {
                            cx.error(
                                "mode.rangeability",
                                format!("must be a finite number > 1 (got {r}); typical 20–50"),
                            );
                        }
                        r
                    }
                };
                Mode::PressureDrop { cv, characteristic: *characteristic, ln_r: r.ln(), opening }
            }
        };
        cx.finish(Valve { mode, p_out, phase: config.phase })
    }

    /// Molar flow [mol/s] through the valve in `pressure_drop` mode at inlet state `inlet` and
    /// opening `op` (0 in `flow_set` mode).
    fn dp_flow<S: Scalar>(&self, io: &UnitIo<'_, S>, inlet: Stream<'_, S>, op: S) -> S {
        let Mode::PressureDrop { cv, characteristic, ln_r, .. } = self.mode else {
            return S::from(0.0);
        };
        let z = inlet.z();
        let mw = io.thermo.mw(z);
        let rho = match self.phase {
            // A flashing valve (outlet in equilibrium) still meters the liquid that enters it.
            Phase::Liquid | Phase::Equilibrium => mw / io.thermo.v_liq(inlet.t(), z),
            Phase::Vapour => inlet.p() * mw / (inlet.t() * R_GAS),
        };
        let f_op = characteristic.fraction(op, ln_r);
        // Q ρ / M = Cv f √(ΔP/ρ) ρ/M = Cv f √ΔP √ρ / M
        f_op * cv * smooth_sqrt(inlet.p() - self.p_out) * rho.sqrt() / mw
    }
}

impl UnitModel for Valve {
    fn type_name(&self) -> &'static str {
        "valve"
    }
    fn inlet_ports(&self) -> Vec<String> {
        vec!["in".into()]
    }
    fn outlet_ports(&self) -> Vec<String> {
        vec!["out".into()]
    }
    fn inputs(&self) -> Vec<InputSpec> {
        vec![match self.mode {
            Mode::FlowSet { flow } => InputSpec { name: "flow".into(), dim: Dimension::MOLAR_FLOW, value: flow },
            Mode::PressureDrop { opening, .. } => {
                InputSpec { name: "opening".into(), dim: Dimension::DIMENSIONLESS, value: opening }
            }
        }]
    }
    fn extra_equations(&self) -> isize {
        1
    }
    /// The valve sets its inlet flow: to the input `flow` (`flow_set`), or from the pressure of the
    /// vessel it drains, moved by `opening` (`pressure_drop`: that vessel regulates itself).
    fn material_flows(&self) -> MaterialFlows {
        let law = match self.mode {
            Mode::FlowSet { .. } => FlowLaw::Input("flow".into()),
            Mode::PressureDrop { .. } => FlowLaw::UpstreamHoldup { input: Some("opening".into()) },
        };
        MaterialFlows::one(FlowVia::Inlet("in".into()), law)
    }
    fn equation_name(&self, k: usize, own_names: &[String]) -> String {
        match (own_names.get(k), self.mode) {
            (Some(n), _) => format!("equation for {n}"),
            (None, Mode::FlowSet { .. }) => "valve inlet flow F_in = flow".into(),
            (None, Mode::PressureDrop { .. }) => "valve inlet flow F_in = Cv f(opening) sqrt(dP/rho) rho/M".into(),
        }
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let (inlet, out) = (io.inlet(0), io.outlet(0));
        let len = io.layout.stream.len();
        r[F] = out.f() - inlet.f();
        r[P] = out.p() - self.p_out;
        r[H] = out.h() - inlet.h();
        for (i, (zo, zi)) in out.z().iter().zip(inlet.z()).enumerate() {
            r[Z0 + i] = *zo - *zi;
        }
        r[T] = out.h() - self.phase.enthalpy(io.thermo, out.t(), out.p(), out.z());
        r[len] = match self.mode {
            Mode::FlowSet { .. } => inlet.f() - io.input(0),
            Mode::PressureDrop { .. } => inlet.f() - self.dp_flow(io, inlet, io.input(0)),
        };
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let inlet = io.inlet(0);
        let len = io.layout.stream.len();
        let flow = match self.mode {
            Mode::FlowSet { .. } => io.input(0),
            Mode::PressureDrop { .. } => self.dp_flow(io, inlet, io.input(0)),
        };
        own[F] = if flow.is_finite() { flow.max(0.0) } else { inlet.f() };
        own[P] = self.p_out;
        own[H] = inlet.h();
        own[Z0..len].copy_from_slice(inlet.z());
        own[T] = self.phase.temperature(io.thermo, inlet.h(), own[P], inlet.z(), inlet.t());
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

    fn valve(config: serde_json::Value) -> (Valve, ThermoPackage) {
        let thermo = binary_package();
        let names = vec!["light".to_string(), "heavy".to_string()];
        let cfg: ValveConfig = serde_json::from_value(config).expect("valid config");
        let v = Valve::build(&cfg, BuildCx::new(&names, &thermo, "units.v"), ()).expect("builds");
        (v, thermo)
    }

    /// Local vector: outlet guess, inlet `[F, T, P, h, z]` at 340 K, 3 bar, z = (0.4, 0.6), input.
    fn local(v: &Valve, thermo: &ThermoPackage, input: f64) -> (LocalLayout, Vec<f64>) {
        let layout = layout_of(v);
        let z = [0.4, 0.6];
        let h = v.phase.enthalpy(thermo, 340.0, 101_325.0, &z);
        let mut x = vec![0.0; layout.len()];
        x[layout.inlets_offset()..layout.inputs_offset()].copy_from_slice(&[7.0, 340.0, 3e5, h, z[0], z[1]]);
        x[layout.inputs_offset()] = input;
        let mut own = vec![0.0; layout.n_own()];
        Unit::guess(v, &UnitIo { local: &x, layout: &layout, thermo, time: 0.0 }, &mut own);
        x[..layout.n_own()].copy_from_slice(&own);
        (layout, x)
    }

    fn cases() -> Vec<(serde_json::Value, f64)> {
        vec![
            (json!({"mode": {"type": "flow_set", "flow": "3 mol/s"}, "p_out": "1.2 bar"}), 3.0),
            (json!({"mode": {"type": "pressure_drop", "cv": "2e-4 m2", "opening": 0.6}, "p_out": "1 bar"}), 0.6),
            (
                json!({"mode": {"type": "pressure_drop", "cv": 2e-4, "characteristic": "equal_percentage",
                    "rangeability": 30, "opening": 0.7}, "p_out": 1e5, "phase": "liquid"}),
                0.7,
            ),
            (
                json!({"mode": {"type": "pressure_drop", "cv": 3e-3, "opening": 0.5}, "p_out": 2e5, "phase": "vapour"}),
                0.5,
            ),
        ]
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        for (cfg, input) in cases() {
            let (v, thermo) = valve(cfg.clone());
            let (layout, mut x) = local(&v, &thermo, input);
            x[T] += 3.0; // off the solution
            x[H] -= 50.0;
            let err = jacobian_error(&v, &layout, &thermo, &x, n_eq(&v, &layout));
            println!("valve {cfg}: jacobian error {err:.2e}");
            assert!(err < 1e-6, "{cfg}: {err}");
        }
    }

    #[test]
    fn converged_balances_and_closed_form_flow() {
        for (cfg, input) in cases() {
            let (v, thermo) = valve(cfg.clone());
            let (layout, mut x) = local(&v, &thermo, input);
            let i0 = layout.inlets_offset();
            // own variables plus the inlet flow the valve sets
            let unknowns: Vec<usize> = (0..layout.n_own()).chain([i0 + F]).collect();
            let res = newton(&v, &layout, &thermo, &mut x, &unknowns);
            let (f_in, t_in, p_in, h_in) = (x[i0 + F], x[i0 + T], x[i0 + P], x[i0 + H]);
            let z = [x[i0 + Z0], x[i0 + Z0 + 1]];
            let mass = (x[F] - f_in).abs() / f_in;
            let energy = (x[F] * x[H] - f_in * h_in).abs() / (f_in * h_in).abs();
            assert!(res < 1e-8 && mass < 1e-9 && energy < 1e-9, "{cfg}: {res} {mass} {energy}");
            assert!((x[P] - v.p_out).abs() < 1e-9 * v.p_out);
            let expected = match v.mode {
                Mode::FlowSet { .. } => input,
                Mode::PressureDrop { cv, characteristic, ln_r, .. } => {
                    let mw = 0.05 * z[0] + 0.08 * z[1];
                    let rho = match v.phase {
                        Phase::Liquid | Phase::Equilibrium => mw / 1e-4,
                        Phase::Vapour => p_in * mw / (R_GAS * t_in),
                    };
                    let f = match characteristic {
                        Characteristic::Linear => input,
                        Characteristic::EqualPercentage => ln_r.exp().powf(input - 1.0),
                    };
                    cv * f * ((p_in - v.p_out) / rho).sqrt() * rho / mw
                }
            };
            let rel = (f_in - expected).abs() / expected;
            println!(
                "valve {cfg}: F = {f_in:.12} mol/s, closed form {expected:.12}, rel {rel:.1e}, mass {mass:.1e}, energy {energy:.1e}"
            );
            assert!(rel < 1e-9, "{cfg}: F {f_in} vs {expected}");
        }
    }

    #[test]
    fn finite_jacobian_at_zero_pressure_drop() {
        let (v, thermo) = valve(cases()[1].0.clone());
        let (layout, mut x) = local(&v, &thermo, 0.6);
        x[layout.inlets_offset() + P] = v.p_out;
        let n = x.len();
        let m = n_eq(&v, &layout);
        let (mut r, mut jac) = (vec![0.0; m], vec![0.0; m * n]);
        Unit::jacobian(&v, &UnitIo { local: &x, layout: &layout, thermo: &thermo, time: 0.0 }, &mut r, &mut jac);
        assert!(r.iter().chain(&jac).all(|v| v.is_finite()));
        assert!(jac[(m - 1) * n + layout.inlets_offset() + P] < 0.0);
    }

    #[test]
    fn rejects_bad_descriptions() {
        let thermo = binary_package();
        let names = vec!["light".to_string(), "heavy".to_string()];
        let bad = json!({"mode": {"type": "pressure_drop", "cv": "1 m3", "opening": 1.5, "rangeability": 20}, "p_out": "1 bar"});
        let cfg: ValveConfig = serde_json::from_value(bad).expect("parses");
        let errs = Valve::build(&cfg, BuildCx::new(&names, &thermo, "units.v"), ()).expect_err("invalid");
        assert_eq!(errs.len(), 3, "{errs:?}");
        let unknown = json!({"mode": {"type": "flow_set", "flow": 1.0, "cv": 1.0}, "p_out": 1e5});
        assert!(serde_json::from_value::<ValveConfig>(unknown).is_err());
    }
}
