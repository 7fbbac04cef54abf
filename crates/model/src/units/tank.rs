//! Surge tank: a perfectly mixed liquid holdup under a gas blanket at pressure `P`.
//!
//! Ports: inlet `in` (one; put a mixer upstream for more), outlet `out`. Inputs: `P` [Pa] (default
//! 1 atm), `duty` [W] (heat input, default 0) and the outflow law's `opening` [-] (valve) or
//! `outflow` [mol/s] (flow); see [`super::outflow`].
//!
//! Variables: the outlet stream `[F, T, P, h, x…]`, then `N[c]` [mol] and `U` [J] (differential),
//! `M` [mol], `level` [m], `V` [m³].
//!
//! Equations (the liquid's internal energy is taken as its enthalpy, `U ≈ H`: `P v_L` is negligible):
//! - `dN_i/dt = F_in z_in,i − F x_i` [mol/s];
//! - `dU/dt = F_in h_in − F h + Q` [W], `Q` the input `duty`;
//! - `U = M h_L(T, x)` [J] (gives `T`), `h = h_L(T, x)` [J/mol];
//! - the holdup equations `M = Σ N_i`, `x_i M = N_i`, `V = M v_L(T, x)`, `A · level = V`;
//! - the outflow law for `F` [mol/s] and the outlet pressure [Pa] (see [`super::outflow`]).
//!
//! With a `flow` outflow the tank is a pure integrator: at steady state its holdup is undetermined
//! unless a level controller moves `outflow`.

use crate::capability::{Booking, Duty, DutySource, MaterialFlows, Shape};
use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::Phase;
use super::outflow::{ATM, Holdup, LiquidState, Outflow, OutflowLaw, normalized};
use crate::stream::{H, T, Z0};
use crate::{BuildCx, FieldError, InputSpec, Scalar, UnitIo, UnitModel, VarSpec};

/// Flowsheet description of a surge tank; give exactly one of `diameter` and `area`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TankConfig {
    /// Diameter [m] of a vertical cylinder (e.g. `"2 m"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diameter: Option<QuantityValue>,
    /// Cross-sectional area [m²] (e.g. `"3 m2"`), instead of `diameter`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub area: Option<QuantityValue>,
    /// Height [m] (e.g. `"4 m"`); the default level guess is half of it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<QuantityValue>,
    /// Gas-blanket pressure [Pa] (input `P`; default 1 atm).
    #[serde(rename = "P", default, skip_serializing_if = "Option::is_none")]
    pub pressure: Option<QuantityValue>,
    /// Heat input [W] (input `duty`; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duty: Option<QuantityValue>,
    /// Liquid outflow law.
    pub outflow: Outflow,
    /// Initial level guess [m] (default: the valve's steady level, else half the height, else 1 m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub level: Option<QuantityValue>,
}

impl crate::registry::UnitConfig for TankConfig {
    fn ports() -> &'static str {
        "inlet `in`, outlet `out`"
    }
    fn vessel(&self) -> Option<crate::registry::VesselGeometry<'_>> {
        Some(crate::registry::VesselGeometry {
            diameter: self.diameter.as_ref(),
            area: self.area.as_ref(),
            height: self.height.as_ref(),
        })
    }
}

/// A surge tank.
#[derive(Debug, Clone)]
pub struct Tank {
    holdup: Holdup,
    pressure: f64,
    duty: f64,
    law: OutflowLaw,
}

/// Inputs before the outflow law's: `P`, `duty`.
const N_FIXED_INPUTS: usize = 2;

impl Tank {
    /// Build from the flowsheet description.
    pub fn build(c: &TankConfig, mut cx: BuildCx<'_>, _links: ()) -> Result<Tank, Vec<FieldError>> {
        let holdup = Holdup::build(&mut cx, c.diameter.as_ref(), c.area.as_ref(), c.height.as_ref(), c.level.as_ref());
        let pressure = c.pressure.as_ref().map_or(ATM, |p| cx.positive("P", p, Dimension::PRESSURE));
        let duty = c.duty.as_ref().map_or(0.0, |q| cx.quantity("duty", q, Dimension::POWER));
        let law = OutflowLaw::build(&c.outflow, &mut cx, "outflow");
        cx.finish(Tank { holdup, pressure, duty, law })
    }
}

impl UnitModel for Tank {
    fn type_name(&self) -> &'static str {
        "tank"
    }
    fn shape(&self) -> Shape {
        Shape::Vessel
    }
    /// The liquid, filled by `in` and drained by `out` under the outflow law.
    fn material_flows(&self) -> MaterialFlows {
        MaterialFlows::vessel(&["in"], vec![("out", self.law.flow_law())])
    }
    /// The input `duty` \[W\], heat put into the liquid: heating when positive.
    fn duties(&self) -> Vec<Duty> {
        vec![Duty { source: DutySource::Input("duty".into()), booking: Booking::Utility }]
    }
    fn inlet_ports(&self) -> Vec<String> {
        vec!["in".into()]
    }
    fn outlet_ports(&self) -> Vec<String> {
        vec!["out".into()]
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        let mut v = self.holdup.component_vars();
        v.push(VarSpec::differential("U", Dimension::ENERGY, self.holdup.m_nominal * 3e4));
        v.extend(self.holdup.volume_vars());
        v
    }
    fn inputs(&self) -> Vec<InputSpec> {
        let mut v = vec![
            InputSpec { name: "P".into(), dim: Dimension::PRESSURE, value: self.pressure },
            InputSpec { name: "duty".into(), dim: Dimension::POWER, value: self.duty },
        ];
        v.extend(self.law.inputs());
        v
    }
    fn extra_equations(&self) -> isize {
        self.law.extra_equations()
    }
    fn holdup(&self, io: &UnitIo<'_, f64>) -> Option<Vec<f64>> {
        Some(io.vars(0, io.n_comp()).to_vec())
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let (nc, len) = (io.n_comp(), io.layout.stream.len());
        let (out, inlet) = (io.outlet(0), io.inlet(0));
        let (u, mlv) = (io.var(nc), io.vars(nc + 1, 3));
        let (p, q) = (io.input(0), io.input(1));
        let (x, t) = (out.z(), out.t());
        let (hl, vl) = (io.thermo.h_liq(t, x), io.thermo.v_liq(t, x));
        let mut res = vec![S::from(0.0); io.layout.n_own()];
        for i in 0..nc {
            res[len + i] = inlet.f() * inlet.z()[i] - out.f() * x[i];
        }
        res[len + nc] = inlet.f() * inlet.h() - out.f() * out.h() + q;
        self.holdup.residuals(io.vars(0, nc), x, mlv, vl, &mut res, (Z0, len + nc + 1));
        res[T] = u - mlv[0] * hl;
        res[H] = out.h() - hl;
        let liq = LiquidState { p, level: mlv[1], mw: io.thermo.mw(x), v: vl };
        self.law.close(io, 0, N_FIXED_INPUTS, &liq, res, r);
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let (nc, len) = (io.n_comp(), io.layout.stream.len());
        let inlet = io.inlet(0);
        let (p, q) = (io.input(0), io.input(1));
        let x = normalized(inlet.z());
        let h = if inlet.f() > 0.0 { inlet.h() + q / inlet.f() } else { inlet.h() };
        let t = Phase::Liquid.temperature(io.thermo, h, inlet.p(), &x, inlet.t());
        let (f, op) = self.law.guess_flow(io, N_FIXED_INPUTS, inlet.f());
        let mut liq = LiquidState { p, level: 0.0, mw: io.thermo.mw(&x), v: io.thermo.v_liq(t, &x) };
        let mlv = self.holdup.guess(&self.law, f, op, &liq);
        liq.level = mlv[1];
        own[..Z0].copy_from_slice(&[f, t, self.law.outlet_pressure(&liq), h]);
        own[Z0..len].copy_from_slice(&x);
        (0..nc).for_each(|i| own[len + i] = mlv[0] * x[i]);
        own[len + nc] = mlv[0] * h;
        own[len + nc + 1..].copy_from_slice(&mlv);
    }
}

#[cfg(test)]
mod tests {
    use super::super::outflow::test_support::{Lcg, at_guess, build_unit, solve_own, worst_jacobian_error};
    use super::super::outflow::{Characteristic, GRAVITY};
    use super::*;
    use crate::testing::{binary_package, jacobian_error};

    const VALVE: &str = r#"{"diameter": "1.2 m", "height": "5 m", "P": "1.2 bar", "duty": "20 kW",
        "outflow": {"type": "valve", "cv": "2.5e-4 m2", "opening": 0.5, "p_out": "1 bar"}}"#;
    const VALVE_EQP: &str = r#"{"area": 1.0, "outflow": {"type": "valve", "cv": 2e-3, "characteristic": "equal_percentage", "opening": 0.7}}"#;
    const FLOW: &str = r#"{"area": "2 m2", "duty": "10 kW", "outflow": {"type": "flow", "flow": "0.5 kmol/min"}}"#;
    const FREE: &str = r#"{"area": "2 m2", "outflow": {"type": "free"}}"#;

    /// 10 mol/s of liquid at 320 K and 2 bar, z = (0.4, 0.6).
    fn feed(thermo: &plantwide_thermo::ThermoPackage) -> [f64; 6] {
        [10.0, 320.0, 2e5, thermo.h_liq(320.0, &[0.4, 0.6]), 0.4, 0.6]
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let thermo = binary_package();
        let mut rng = Lcg(7);
        for json in [VALVE, VALVE_EQP, FLOW, FREE] {
            let u = build_unit(json, &thermo, Tank::build);
            let worst = worst_jacobian_error(&u, &thermo, &feed(&thermo), &mut rng, 0.2);
            eprintln!("tank jacobian_error {worst:.1e}: {json}");
            assert!(worst < 1e-6, "{json}: {worst}");
        }
        // Inside the regularised band of the valve law (|ΔP| < 10 Pa: level 0.5 mm, P = p_out).
        let u = build_unit(
            r#"{"area": 1, "outflow": {"type": "valve", "cv": 1e-3, "opening": 0.5}}"#,
            &thermo,
            Tank::build,
        );
        let (lay, mut local) = at_guess(&u, &thermo, &feed(&thermo));
        local[lay.n_own() - 2] = 5e-4;
        let err = jacobian_error(&u, &lay, &thermo, &local, lay.n_own());
        eprintln!("tank jacobian_error {err:.1e} at ΔP = 3.3 Pa");
        assert!(err < 1e-6, "band: {err}");
    }

    #[test]
    fn steady_state_closes_and_level_obeys_valve_law() {
        let thermo = binary_package();
        for json in [VALVE, VALVE_EQP] {
            let u = build_unit(json, &thermo, Tank::build);
            let (lay, mut local) = at_guess(&u, &thermo, &feed(&thermo));
            let mut rng = Lcg(11);
            local[..lay.n_own()].iter_mut().for_each(|v| *v *= rng.range(0.9, 1.1));
            let norm = solve_own(&u, &lay, &thermo, &mut local);
            assert!(norm < 1e-12, "{norm}");
            let io = UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 };
            let (out, inlet) = (io.outlet(0), io.inlet(0));
            let d_f = (out.f() - inlet.f()).abs() / inlet.f();
            let d_c =
                (0..2).map(|i| (out.f() * out.z()[i] - inlet.f() * inlet.z()[i]).abs() / inlet.f()).fold(0.0, f64::max);
            let e_in = inlet.f() * inlet.h() + io.input(1);
            let d_e = (e_in - out.f() * thermo.h_liq(out.t(), out.z())).abs() / e_in.abs();
            // Closed form of the valve law: ΔP = (F √(M_w v_L) / (C_v f))², level = (ΔP − P + p_out)/(ρ g).
            let OutflowLaw::Valve { cv, characteristic, rangeability, p_out, .. } = u.law else { unreachable!() };
            let op = io.input(2);
            let f = if characteristic == Characteristic::Linear { op } else { rangeability.powf(op - 1.0) };
            let (v, mw) = (thermo.v_liq(out.t(), out.z()), thermo.mw(out.z()));
            let dp = (out.f() * (mw * v).sqrt() / (cv * f)).powi(2);
            let level = (dp - io.input(0) + p_out) / (mw / v * GRAVITY);
            let d_l = (io.var(4) - level).abs() / level;
            eprintln!(
                "tank level {level:.6} m, T {:.3} K: |ΔF| {d_f:.1e} comp {d_c:.1e} energy {d_e:.1e} level {d_l:.1e}",
                out.t()
            );
            assert!(level > 0.0 && d_f < 1e-12 && d_c < 1e-12 && d_e < 1e-9 && d_l < 1e-9);
        }
    }

    #[test]
    fn structure_and_build_errors() {
        let thermo = binary_package();
        let u = build_unit(FREE, &thermo, Tank::build);
        assert_eq!(UnitModel::extra_equations(&u), -1);
        assert_eq!(UnitModel::inputs(&u).len(), 2);
        let vars: Vec<String> = UnitModel::internal_vars(&u).into_iter().map(|v| v.name).collect();
        assert_eq!(vars, ["N[light]", "N[heavy]", "U", "M", "level", "V"]);
        let names = ["light".to_string(), "heavy".to_string()];
        let bad = r#"{"area": 1, "diameter": 1, "outflow": {"type": "valve", "cv": "1 m", "opening": 2}}"#;
        let errs =
            Tank::build(&serde_json::from_str(bad).unwrap(), BuildCx::new(&names, &thermo, "units.t"), ()).unwrap_err();
        let paths: Vec<&str> = errs.iter().map(|e| e.path.as_str()).collect();
        assert_eq!(paths, ["units.t", "units.t.outflow.cv", "units.t.outflow.opening"]);
        assert!(
            serde_json::from_str::<TankConfig>(r#"{"area": 1, "outflow": {"type": "free"}, "volume": 3}"#).is_err()
        );
    }
}
