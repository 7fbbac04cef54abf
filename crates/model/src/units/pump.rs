//! Pump: raises the pressure of a liquid stream; no holdup.
//!
//! Ports: inlet `in`, outlet `out`. Input: `dp` [Pa] (pressure rise, mode `dp`) or `p_out` [Pa]
//! (outlet pressure, mode `p_out`). Internal variable `power` [W], the shaft power.
//!
//! Equations (own block `[F, T, P, h, z…, power]`):
//! - `F_out = F_in` [mol/s], `z_out,i = z_in,i` [-];
//! - `P_out = P_in + dp` or `P_out = p_out` [Pa];
//! - energy `h_out = h_in + v_L(T_in, z_in) ΔP / η` [J/mol], with `ΔP = P_out − P_in` [Pa],
//!   `v_L` [m³/mol] the liquid molar volume and `η` [-] the efficiency: this is `h_out = h_in + W/F`
//!   written without dividing by `F` (defined at zero flow);
//! - `power`: `W = F v_L ΔP / η` [W];
//! - outlet temperature from `h_out = h_L(T_out, z_out)` [J/mol].
//!
//! The liquid enthalpy of the thermodynamic package does not depend on pressure, so all of the work,
//! including its reversible part `v ΔP`, appears as a temperature rise `ΔT = v ΔP/(η c_p)` (an
//! overestimate by `v ΔP / c_p`, e.g. 0.7 K for 10 bar at `v = 1e-4 m³/mol`, `c_p = 150 J/(mol K)`);
//! energy balances downstream close exactly. A `p_out` below the inlet pressure gives negative
//! power (not a turbine model).

use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::Phase;
use crate::stream::{F, H, P, T, Z0};
use crate::{BuildCx, FieldError, InputSpec, Scalar, UnitIo, UnitModel, VarSpec};

fn default_efficiency() -> f64 {
    0.75
}

/// Flowsheet description of a pump; give exactly one of `dp` and `p_out`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PumpConfig {
    /// Pressure rise [Pa] (e.g. `"5 bar"`; input `dp`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dp: Option<QuantityValue>,
    /// Outlet pressure [Pa] (e.g. `"6 bar"`; input `p_out`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub p_out: Option<QuantityValue>,
    /// Overall efficiency [-] in (0, 1] (default 0.75).
    #[serde(default = "default_efficiency")]
    pub efficiency: f64,
}

impl crate::registry::UnitConfig for PumpConfig {
    fn ports() -> &'static str {
        "inlet `in`, outlet `out`"
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Mode {
    Rise(f64),
    Outlet(f64),
}

/// A pump.
#[derive(Debug, Clone)]
pub struct Pump {
    mode: Mode,
    efficiency: f64,
}

/// Index of `power` among the internal variables.
const W: usize = 0;

impl Pump {
    /// Build from the flowsheet description.
    pub fn build(config: &PumpConfig, mut cx: BuildCx<'_>, _links: ()) -> Result<Pump, Vec<FieldError>> {
        let mode = match (&config.dp, &config.p_out) {
            (Some(dp), None) => Mode::Rise(cx.non_negative("dp", dp, Dimension::PRESSURE)),
            (None, Some(p)) => Mode::Outlet(cx.positive("p_out", p, Dimension::PRESSURE)),
            _ => {
                cx.error("", "give exactly one of `dp` (pressure rise, e.g. \"5 bar\") and `p_out` (e.g. \"6 bar\")");
                Mode::Rise(0.0)
            }
        };
        if !(config.efficiency > 0.0 && config.efficiency <= 1.0) {
            cx.error("efficiency", format!("must lie in (0, 1] (got {})", config.efficiency));
        }
        cx.finish(Pump { mode, efficiency: config.efficiency })
    }
}

impl UnitModel for Pump {
    fn type_name(&self) -> &'static str {
        "pump"
    }
    fn inlet_ports(&self) -> Vec<String> {
        vec!["in".into()]
    }
    fn outlet_ports(&self) -> Vec<String> {
        vec!["out".into()]
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        vec![VarSpec::algebraic("power", Dimension::POWER, 1e4)]
    }
    fn inputs(&self) -> Vec<InputSpec> {
        vec![match self.mode {
            Mode::Rise(dp) => InputSpec { name: "dp".into(), dim: Dimension::PRESSURE, value: dp },
            Mode::Outlet(p) => InputSpec { name: "p_out".into(), dim: Dimension::PRESSURE, value: p },
        }]
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let (inlet, out) = (io.inlet(0), io.outlet(0));
        let len = io.layout.stream.len();
        r[F] = out.f() - inlet.f();
        for (i, (zo, zi)) in out.z().iter().zip(inlet.z()).enumerate() {
            r[Z0 + i] = *zo - *zi;
        }
        r[P] = match self.mode {
            Mode::Rise(_) => out.p() - inlet.p() - io.input(0),
            Mode::Outlet(_) => out.p() - io.input(0),
        };
        // specific work W/F = v ΔP / η [J/mol]
        let work = io.thermo.v_liq(inlet.t(), inlet.z()) * (out.p() - inlet.p()) / self.efficiency;
        r[H] = out.h() - inlet.h() - work;
        r[T] = out.h() - Phase::Liquid.enthalpy(io.thermo, out.t(), out.p(), out.z());
        r[len + W] = io.var(W) - out.f() * work;
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let inlet = io.inlet(0);
        let len = io.layout.stream.len();
        own[F] = inlet.f();
        own[Z0..len].copy_from_slice(inlet.z());
        own[P] = match self.mode {
            Mode::Rise(_) => inlet.p() + io.input(0),
            Mode::Outlet(_) => io.input(0),
        };
        let work = io.thermo.v_liq(inlet.t(), inlet.z()) * (own[P] - inlet.p()) / self.efficiency;
        own[H] = inlet.h() + work;
        own[T] = Phase::Liquid.temperature(io.thermo, own[H], own[P], inlet.z(), inlet.t());
        own[len + W] = inlet.f() * work;
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use plantwide_thermo::ThermoPackage;
    use serde_json::json;

    use super::*;
    use crate::testing::{binary_package, jacobian_error};
    use crate::{LocalLayout, StreamLayout, Unit};

    /// Local layout of `unit` for the binary package (no signals).
    pub(crate) fn layout_of(unit: &dyn Unit) -> LocalLayout {
        LocalLayout {
            stream: StreamLayout { n_comp: 2 },
            n_outlets: unit.outlet_ports().len(),
            n_internal: unit.internal_vars().len(),
            n_inlets: unit.inlet_ports().len(),
            n_inputs: unit.inputs().len(),
            n_signals: 0,
        }
    }

    /// Number of equations of `unit` in `layout`.
    pub(crate) fn n_eq(unit: &dyn Unit, layout: &LocalLayout) -> usize {
        (layout.n_own() as isize + unit.extra_equations()) as usize
    }

    /// Dense Newton on all residuals of `unit` over the local entries `unknowns` (the rest fixed), with
    /// row equilibration and partial pivoting. Returns the final max |residual|.
    pub(crate) fn newton(
        unit: &dyn Unit,
        layout: &LocalLayout,
        thermo: &ThermoPackage,
        x: &mut [f64],
        unknowns: &[usize],
    ) -> f64 {
        let (m, n) = (n_eq(unit, layout), x.len());
        assert_eq!(m, unknowns.len(), "square subsystem");
        let (mut r, mut jac) = (vec![0.0; m], vec![0.0; m * n]);
        for _ in 0..100 {
            unit.jacobian(&UnitIo { local: x, layout, thermo, time: 0.0 }, &mut r, &mut jac);
            let mut a: Vec<Vec<f64>> = (0..m)
                .map(|k| {
                    let mut row: Vec<f64> = unknowns.iter().map(|&j| jac[k * n + j]).collect();
                    row.push(-r[k]);
                    let s = row[..m].iter().fold(0.0_f64, |s, v| s.max(v.abs())).max(1e-300);
                    row.iter_mut().for_each(|v| *v /= s);
                    row
                })
                .collect();
            for c in 0..m {
                let p = (c..m).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs())).unwrap_or(c);
                a.swap(c, p);
                let (top, bottom) = a.split_at_mut(c + 1);
                for row in bottom {
                    let f = row[c] / top[c][c];
                    row[c..].iter_mut().zip(&top[c][c..]).for_each(|(v, p)| *v -= f * p);
                }
            }
            let mut dx = vec![0.0; m];
            for c in (0..m).rev() {
                dx[c] = (a[c][m] - (c + 1..m).map(|j| a[c][j] * dx[j]).sum::<f64>()) / a[c][c];
            }
            let mut step: f64 = 0.0;
            for (&j, d) in unknowns.iter().zip(&dx) {
                x[j] += d;
                step = step.max(d.abs() / x[j].abs().max(1e-3));
            }
            if step < 1e-15 {
                break;
            }
        }
        unit.residual(&UnitIo { local: x, layout, thermo, time: 0.0 }, &mut r);
        r.iter().fold(0.0, |s, v| s.max(v.abs()))
    }

    fn pump(config: serde_json::Value) -> (Pump, ThermoPackage) {
        let thermo = binary_package();
        let names = vec!["light".to_string(), "heavy".to_string()];
        let cfg: PumpConfig = serde_json::from_value(config).expect("valid config");
        let p = Pump::build(&cfg, BuildCx::new(&names, &thermo, "units.p"), ()).expect("builds");
        (p, thermo)
    }

    /// Inlet 5 mol/s, 320 K, 1.5 bar, z = (0.3, 0.7); outlet from the guess.
    fn local(p: &Pump, thermo: &ThermoPackage, input: f64) -> (LocalLayout, Vec<f64>) {
        let layout = layout_of(p);
        let z = [0.3, 0.7];
        let h = thermo.h_liq(320.0, &z);
        let mut x = vec![0.0; layout.len()];
        x[layout.inlets_offset()..layout.inputs_offset()].copy_from_slice(&[5.0, 320.0, 1.5e5, h, z[0], z[1]]);
        x[layout.inputs_offset()] = input;
        let mut own = vec![0.0; layout.n_own()];
        Unit::guess(p, &UnitIo { local: &x, layout: &layout, thermo, time: 0.0 }, &mut own);
        x[..layout.n_own()].copy_from_slice(&own);
        (layout, x)
    }

    fn cases() -> Vec<(serde_json::Value, f64)> {
        vec![(json!({"dp": "8 bar"}), 8e5), (json!({"p_out": "12 bar", "efficiency": 0.6}), 12e5)]
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        for (cfg, input) in cases() {
            let (p, thermo) = pump(cfg.clone());
            let (layout, mut x) = local(&p, &thermo, input);
            x[T] += 2.0;
            x[P] *= 1.1;
            x[layout.n_own() - 1] *= 0.9;
            let err = jacobian_error(&p, &layout, &thermo, &x, n_eq(&p, &layout));
            println!("pump {cfg}: jacobian error {err:.2e}");
            assert!(err < 1e-6, "{cfg}: {err}");
        }
    }

    #[test]
    fn converged_power_and_balances() {
        for (cfg, input) in cases() {
            let (p, thermo) = pump(cfg.clone());
            let (layout, mut x) = local(&p, &thermo, input);
            let len = layout.stream.len();
            // start away from the guess
            x[T] += 5.0;
            x[H] += 500.0;
            x[len + W] = 0.0;
            let unknowns: Vec<usize> = (0..layout.n_own()).collect();
            let res = newton(&p, &layout, &thermo, &mut x, &unknowns);
            let i0 = layout.inlets_offset();
            let (f_in, p_in, h_in) = (x[i0 + F], x[i0 + P], x[i0 + H]);
            let dp = x[P] - p_in;
            let expected = f_in * 1e-4 * dp / p.efficiency;
            let power = x[len + W];
            let rel_power = (power - expected).abs() / expected;
            let energy = (x[F] * x[H] - f_in * h_in - power).abs() / (f_in * h_in).abs();
            let mass = (x[F] - f_in).abs() / f_in;
            let dt = x[T] - x[i0 + T];
            println!(
                "pump {cfg}: W = {power:.9} W (F v ΔP/η = {expected:.9}), rel {rel_power:.1e}, energy {energy:.1e}, ΔT = {dt:.6} K"
            );
            assert!(res < 1e-8 && rel_power < 1e-9 && energy < 1e-9 && mass < 1e-12, "{cfg}");
            assert!((dp - 8e5).abs() < 1e-6 || (x[P] - 12e5).abs() < 1e-6);
            assert!((dt - 1e-4 * dp / p.efficiency / 150.0).abs() < 1e-9);
        }
    }

    #[test]
    fn rejects_bad_descriptions() {
        let thermo = binary_package();
        let names = vec!["light".to_string(), "heavy".to_string()];
        let cfg: PumpConfig =
            serde_json::from_value(json!({"dp": "5 bar", "p_out": "6 bar", "efficiency": 1.2})).expect("parses");
        let errs = Pump::build(&cfg, BuildCx::new(&names, &thermo, "units.p"), ()).expect_err("invalid");
        assert_eq!(errs.len(), 2, "{errs:?}");
        let cfg: PumpConfig = serde_json::from_value(json!({"dp": "5 K"})).expect("parses");
        assert!(Pump::build(&cfg, BuildCx::new(&names, &thermo, "units.p"), ()).is_err());
        assert!(serde_json::from_value::<PumpConfig>(json!({"dp": 1e5, "head": 3})).is_err());
    }
}
