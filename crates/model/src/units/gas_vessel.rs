//! Gas vessel (a header, a receiver, a knock-out drum run dry): a fixed volume of ideal gas, its
//! pressure a state of the plant, drained by a gas control valve or by a downstream unit.
//!
//! Ports: inlet `in` (one; put a mixer upstream for more), outlet `out`. Inputs: `duty` [W] (heat
//! into the gas, default 0) and, with a `valve` outflow, its `opening` [-].
//!
//! Variables: the outlet stream `[F, T, P, h, y…]`, then `N[c]` [mol] and `U` [J]
//! (differential), and the vessel pressure `P` [Pa]. The gas is well mixed, at the outlet's `T`
//! and composition.
//!
//! Equations (ideal gas; `R` = 8.314462618 J/(mol·K), `N = Σ N_i`, `V` [m³] the volume):
//! - `dN_i/dt = F_in z_in,i − F y_i` [mol/s];
//! - `dU/dt = F_in h_in − F h + Q` [W], `Q` the input `duty`;
//! - `N_i = y_i N` (gives `y`);
//! - `U = N (h_V(T, y) − R T)` (gives `T`: the internal energy of the ideal gas), `h = h_V(T, y)`;
//! - `P V = N R T` (gives the vessel pressure);
//! - the outflow: `free`, the outlet at `P` and `F` set by a downstream unit (a `valve` unit in
//!   vapour service; the vessel writes no equation for it); or `valve`, the outlet throttled to
//!   `p_out` (isenthalpic: an ideal gas keeps its temperature) and `F` from the gas-service valve
//!   equation of IEC 60534-2-1 in SI form:
//!   `F M = C_v f(op) Y √(x P ρ)`, `x = min(ΔP/P, F_γ x_T)`, `Y = 1 − x/(3 F_γ x_T)`,
//!   `ΔP = P − p_out`, `ρ = P M/(R T)` [kg/m³], `M = Σ y_i M_i` [kg/mol], `F_γ = γ/1.4` with
//!   `γ = c_p/(c_p − R)` of the ideal gas at `T`, `x_T` the valve's pressure-differential ratio
//!   factor (default 0.70, a globe valve). At `x = F_γ x_T` the flow chokes: it no longer grows as
//!   `p_out` falls (`Y = 2/3`). `Y √x` has zero slope there, so the choked branch joins C¹.
//!   `C_v` [m²] is the coefficient of the liquid valves (`Q [m³/s] = C_v f √(ΔP/ρ)`); `f(op)` its
//!   characteristic. A pressure below `p_out` reverses the flow through the same square root
//!   (`x` < 0, `Y` = 1), which the `F ≥ 0` bound rejects.

use plantwide_thermo::R_GAS;
use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::outflow::{ATM, Characteristic, signed_sqrt};
use crate::capability::{Booking, Duty, DutySource, FlowLaw, InventoryPhase, MaterialFlows, Shape};
use crate::stream::{F, H, P, T, Z0};
use crate::{BuildCx, FieldError, InputSpec, Scalar, UnitIo, UnitModel, VarSpec};

fn default_rangeability() -> f64 {
    50.0
}

fn default_xt() -> f64 {
    0.70
}

/// How the gas leaves the vessel (`"type": "valve" | "free"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum GasOutflow {
    /// Gas control valve to a fixed downstream pressure (IEC 60534-2-1, choked flow included).
    Valve {
        /// SI valve coefficient [m²] (`Q [m³/s] = cv·f(op)·√(ΔP/ρ)` for an incompressible fluid).
        cv: QuantityValue,
        /// Characteristic (default `linear`).
        #[serde(default)]
        characteristic: Characteristic,
        /// Rangeability `R` [-] of an equal-percentage valve (default 50).
        #[serde(default = "default_rangeability")]
        rangeability: f64,
        /// Pressure-differential ratio factor `x_T` [-] (default 0.70; 0.2–0.85 by valve style).
        #[serde(default = "default_xt")]
        xt: f64,
        /// Opening [-], 0 … 1 (input `opening`).
        opening: f64,
        /// Downstream pressure [Pa] (e.g. `"1.2 bar"`; default 1 atm).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        p_out: Option<QuantityValue>,
    },
    /// A downstream unit sets the outflow [mol/s]; the outlet is at the vessel's pressure.
    Free {},
}

/// Flowsheet description of a gas vessel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GasVesselConfig {
    /// Volume [m³] (e.g. `"5 m3"`).
    pub volume: QuantityValue,
    /// Heat input [W] (input `duty`; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duty: Option<QuantityValue>,
    /// Gas outflow law.
    pub outflow: GasOutflow,
}

impl crate::registry::UnitConfig for GasVesselConfig {
    fn ports() -> &'static str {
        "inlet `in`, outlet `out`"
    }
}

/// A built gas outflow law (SI).
#[derive(Debug, Clone, PartialEq)]
enum GasLaw {
    Valve { cv: f64, characteristic: Characteristic, ln_r: f64, xt: f64, opening: f64, p_out: f64 },
    Free,
}

/// A gas vessel.
#[derive(Debug, Clone)]
pub struct GasVessel {
    volume: f64,
    duty: f64,
    law: GasLaw,
    components: Vec<String>,
}

impl GasVessel {
    /// Build from the flowsheet description.
    pub fn build(c: &GasVesselConfig, mut cx: BuildCx<'_>, _links: ()) -> Result<GasVessel, Vec<FieldError>> {
        let volume = cx.positive("volume", &c.volume, Dimension::VOLUME);
        let duty = c.duty.as_ref().map_or(0.0, |q| cx.quantity("duty", q, Dimension::POWER));
        let law = match &c.outflow {
            GasOutflow::Free {} => GasLaw::Free,
            GasOutflow::Valve { cv, characteristic, rangeability, xt, opening, p_out } => {
                let cv = cx.positive("outflow.cv", cv, Dimension::AREA);
                let p_out = p_out.as_ref().map_or(ATM, |p| cx.positive("outflow.p_out", p, Dimension::PRESSURE));
                if !(*rangeability > 1.0 && rangeability.is_finite()) {
                    cx.error("outflow.rangeability", "must be a number above 1 (50 is usual)");
                }
                if !(*xt > 0.0 && *xt <= 1.0) {
                    cx.error("outflow.xt", "must lie in (0, 1] (0.70 for a globe valve, 0.2–0.85 by style)");
                }
                if !(0.0..=1.0).contains(opening) {
                    cx.error("outflow.opening", "must lie in [0, 1]");
                }
                let ln_r = rangeability.ln();
                GasLaw::Valve { cv, characteristic: *characteristic, ln_r, xt: *xt, opening: *opening, p_out }
            }
        };
        let components = cx.components.to_vec();
        cx.finish(GasVessel { volume, duty, law, components })
    }

    /// Molar flow [mol/s] through the valve from a vessel at `p` [Pa] and `t` [K] of composition
    /// `y`, at opening `op`: the module's IEC 60534-2-1 equation.
    fn valve_flow<S: Scalar>(&self, io: &UnitIo<'_, S>, p: S, t: S, y: &[S], op: S) -> S {
        let GasLaw::Valve { cv, characteristic, ln_r, xt, p_out, .. } = &self.law else { return S::from(0.0) };
        let mw = io.thermo.mw(y);
        let mut cp = S::from(0.0);
        for (yi, c) in y.iter().zip(&io.thermo.components) {
            cp += *yi * c.cp_gas(t);
        }
        let f_gamma = cp / (cp - R_GAS) / 1.4;
        let choke = f_gamma * *xt;
        let dp = p - *p_out;
        let dp_eff = if dp.re() > (choke * p).re() { choke * p } else { dp };
        let y_exp = if dp_eff.re() > 0.0 { -(dp_eff / p) / (choke * 3.0) + 1.0 } else { S::from(1.0) };
        let rho = p * mw / (t * R_GAS);
        characteristic.fraction(op, *ln_r) * y_exp * signed_sqrt(dp_eff) * rho.sqrt() * *cv / mw
    }
}

impl UnitModel for GasVessel {
    fn type_name(&self) -> &'static str {
        "gas_vessel"
    }
    fn shape(&self) -> Shape {
        Shape::Vessel
    }
    /// The gas, filled by `in` and drained by `out`: by its valve under the vessel's pressure, or
    /// by a downstream unit; measured by the pressure `P`.
    fn material_flows(&self) -> MaterialFlows {
        let law = match self.law {
            GasLaw::Valve { .. } => Some(FlowLaw::Holdup { input: Some("opening".into()) }),
            GasLaw::Free => None,
        };
        let mut flows = MaterialFlows::vessel(&["in"], vec![("out", law)]);
        for inventory in &mut flows.inventories {
            inventory.phase = InventoryPhase::Gas;
            inventory.measured = vec!["P".into()];
        }
        flows
    }
    /// The input `duty` \[W\], heat put into the gas.
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
        // Nominal holdup: the gas at 10 bar and 300 K.
        let n = 10.0 * 1e5 * self.volume / (R_GAS * 300.0);
        let per = n / self.components.len().max(1) as f64;
        let held = |c| VarSpec::differential(format!("N[{c}]"), Dimension::AMOUNT, per).bounded(0.0, f64::INFINITY);
        let mut v: Vec<VarSpec> = self.components.iter().map(held).collect();
        v.push(VarSpec::differential("U", Dimension::ENERGY, n * 1e4));
        v.push(VarSpec::algebraic("P", Dimension::PRESSURE, 1e6).bounded(0.0, f64::INFINITY));
        v
    }
    fn inputs(&self) -> Vec<InputSpec> {
        let mut v = vec![InputSpec { name: "duty".into(), dim: Dimension::POWER, value: self.duty }];
        if let GasLaw::Valve { opening, .. } = self.law {
            v.push(InputSpec { name: "opening".into(), dim: Dimension::DIMENSIONLESS, value: opening });
        }
        v
    }
    fn extra_equations(&self) -> isize {
        if self.law == GasLaw::Free { -1 } else { 0 }
    }
    fn holdup(&self, io: &UnitIo<'_, f64>) -> Option<Vec<f64>> {
        Some(io.vars(0, io.n_comp()).to_vec())
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let (nc, len) = (io.n_comp(), io.layout.stream.len());
        let (out, inlet) = (io.outlet(0), io.inlet(0));
        let (n, u, p) = (io.vars(0, nc), io.var(nc), io.var(nc + 1));
        let (y, t) = (out.z(), out.t());
        let total = n.iter().fold(S::from(0.0), |a, b| a + *b);
        let h = io.thermo.h_vap(t, y);
        let mut res = vec![S::from(0.0); io.layout.n_own()];
        for i in 0..nc {
            res[len + i] = inlet.f() * inlet.z()[i] - out.f() * y[i];
            res[Z0 + i] = n[i] - y[i] * total;
        }
        res[len + nc] = inlet.f() * inlet.h() - out.f() * out.h() + io.input(0);
        res[T] = (u - total * (h - t * R_GAS)) / total;
        res[H] = out.h() - h;
        let state = (p * self.volume - total * t * R_GAS) / self.volume;
        match self.law {
            // No flow equation: the pressure's takes the flow's row (one row fewer).
            GasLaw::Free => {
                res[P] = out.p() - p;
                res[F] = state;
            }
            GasLaw::Valve { p_out, .. } => {
                res[P] = out.p() - p_out;
                res[F] = out.f() - self.valve_flow(io, p, t, y, io.input(1));
                res[len + nc + 1] = state;
            }
        }
        r.iter_mut().zip(res).for_each(|(ri, v)| *ri = v);
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let (nc, len) = (io.n_comp(), io.layout.stream.len());
        let inlet = io.inlet(0);
        let y = super::outflow::normalized(inlet.z());
        let (f, t) = (inlet.f(), inlet.t());
        let h = io.thermo.h_vap(t, &y);
        let p = match self.law {
            GasLaw::Free => inlet.p(),
            GasLaw::Valve { p_out, .. } => self.steady_pressure(io, f, t, &y).unwrap_or(inlet.p().max(p_out)),
        };
        let total = p * self.volume / (R_GAS * t);
        let p_stream = if let GasLaw::Valve { p_out, .. } = self.law { p_out } else { p };
        own[..Z0].copy_from_slice(&[f, t, p_stream, h]);
        own[Z0..len].copy_from_slice(&y);
        (0..nc).for_each(|i| own[len + i] = total * y[i]);
        own[len + nc] = total * (h - R_GAS * t);
        own[len + nc + 1] = p;
    }
}

impl GasVessel {
    /// The vessel pressure [Pa] at which the valve passes `f` [mol/s] at `t` and `y`, by bisection
    /// between `p_out` and 1000 × it; `None` for another law or a flow it cannot pass.
    fn steady_pressure(&self, io: &UnitIo<'_, f64>, f: f64, t: f64, y: &[f64]) -> Option<f64> {
        let GasLaw::Valve { p_out, opening, .. } = self.law else { return None };
        let flow = |p: f64| self.valve_flow(io, p, t, y, opening) - f;
        let (mut lo, mut hi) = (p_out, 1000.0 * p_out);
        if !(flow(lo) <= 0.0 && flow(hi) >= 0.0) {
            return None;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if flow(mid) > 0.0 { hi = mid } else { lo = mid }
        }
        Some(0.5 * (lo + hi))
    }
}

#[cfg(test)]
mod tests {
    use super::super::outflow::test_support::{Lcg, at_guess, build_unit, solve_own, worst_jacobian_error};
    use super::*;
    use crate::testing::binary_package;

    const SUBCRITICAL: &str = r#"{"volume": "2 m3", "duty": "5 kW",
        "outflow": {"type": "valve", "cv": "2e-4 m2", "opening": 0.6, "p_out": "4 bar"}}"#;
    const CHOKED: &str = r#"{"volume": "2 m3", "outflow": {"type": "valve", "cv": "2e-4 m2", "opening": 0.6,
        "characteristic": "equal_percentage", "p_out": "1 bar"}}"#;
    const FREE: &str = r#"{"volume": "3 m3", "outflow": {"type": "free"}}"#;

    /// 2 mol/s of gas at 400 K and 6 bar, y = (0.3, 0.7).
    fn feed(thermo: &plantwide_thermo::ThermoPackage) -> [f64; 6] {
        [2.0, 400.0, 6e5, thermo.h_vap(400.0, &[0.3, 0.7]), 0.3, 0.7]
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let thermo = binary_package();
        let mut rng = Lcg(3);
        for json in [SUBCRITICAL, CHOKED, FREE] {
            let u = build_unit(json, &thermo, GasVessel::build);
            let worst = worst_jacobian_error(&u, &thermo, &feed(&thermo), &mut rng, 0.1);
            assert!(worst < 1e-6, "{json}: {worst}");
        }
    }

    /// At steady state the vessel passes its feed (moles per component and energy, the duty
    /// added), holds the ideal gas `P V = N R T`, and a choked valve's flow does not depend on the
    /// pressure downstream: the same vessel pressure for `p_out` = 1 bar and 0.5 bar. A
    /// subcritical valve's does (a lower `p_out`, a lower vessel pressure).
    #[test]
    fn steady_state_conserves_and_a_choked_valve_ignores_the_pressure_downstream() {
        let thermo = binary_package();
        let solved = |json: &str| {
            let u = build_unit(json, &thermo, GasVessel::build);
            let (lay, mut local) = at_guess(&u, &thermo, &feed(&thermo));
            let mut rng = Lcg(5);
            local[..lay.n_own()].iter_mut().for_each(|v| *v *= rng.range(0.95, 1.05));
            assert!(solve_own(&u, &lay, &thermo, &mut local) < 1e-12, "{json}");
            let io = UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 };
            let (out, inlet) = (io.outlet(0), io.inlet(0));
            for i in 0..2 {
                assert!((out.f() * out.z()[i] - inlet.f() * inlet.z()[i]).abs() < 1e-12 * inlet.f());
            }
            let e = inlet.f() * inlet.h() + io.input(0);
            assert!((out.f() * out.h() - e).abs() < 1e-9 * e.abs().max(1.0));
            let (n, t, p) = (io.var(0) + io.var(1), out.t(), io.var(3));
            assert!((p * 2.0 - n * R_GAS * t).abs() < 1e-9 * p, "{json}");
            p
        };
        let p1 = solved(CHOKED);
        let p2 = solved(&CHOKED.replace("1 bar", "0.5 bar"));
        assert!(p1 > 3e5 && (p1 - p2).abs() < 1e-9 * p1, "choked: {p1} against {p2}");
        let s1 = solved(SUBCRITICAL);
        let s2 = solved(&SUBCRITICAL.replace("4 bar", "3.5 bar"));
        assert!(s2 < s1 - 1e3, "subcritical: {s1} then {s2}");
    }

    #[test]
    fn structure_and_build_errors() {
        let thermo = binary_package();
        let u = build_unit(FREE, &thermo, GasVessel::build);
        assert_eq!(UnitModel::extra_equations(&u), -1);
        let vars: Vec<String> = UnitModel::internal_vars(&u).into_iter().map(|v| v.name).collect();
        assert_eq!(vars, ["N[light]", "N[heavy]", "U", "P"]);
        let names = ["light".to_string(), "heavy".to_string()];
        let bad = r#"{"volume": "-1 m3", "outflow": {"type": "valve", "cv": "1 m", "opening": 2, "xt": 1.5}}"#;
        let errs = GasVessel::build(&serde_json::from_str(bad).unwrap(), BuildCx::new(&names, &thermo, "units.g"), ())
            .unwrap_err();
        let paths: Vec<&str> = errs.iter().map(|e| e.path.as_str()).collect();
        assert_eq!(paths, ["units.g.volume", "units.g.outflow.cv", "units.g.outflow.xt", "units.g.outflow.opening"]);
    }
}
