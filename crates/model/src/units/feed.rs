//! Feed: a source stream of given flow, temperature (or saturated liquid), pressure and composition.
//!
//! Port: outlet `out`. Inputs (all may be moved by controllers or analyses):
//! `F` [mol/s], `T` [K] (not for a saturated-liquid feed), `P` [Pa], and `z[c]` for every component
//! but the last, which makes up the balance `z_n = 1 − Σ_{i<n} z_i`.
//!
//! Equations: `F = F_in`, `P = P_in`, `z_i = z_in,i`, and either `T = T_in` or, for a saturated
//! liquid, the bubble-point condition `Σ K_i(T, P, z) z_i = 1`; `h = h_phase(T, z)`.

use crate::capability::{Boundary, FlowLaw, FlowVia, MaterialFlows, Shape};
use std::collections::BTreeMap;

use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use plantwide_thermo::ThermoPackage;

use super::Phase;
use crate::stream::{F, H, P, T, Z0};
use crate::{BuildCx, FieldError, InputError, InputSpec, Scalar, UnitIo, UnitModel};

/// Thermal condition of a feed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum FeedCondition {
    /// Liquid at the given temperature.
    #[default]
    Liquid,
    /// Vapour at the given temperature.
    Vapour,
    /// Saturated liquid at its bubble point (no temperature given).
    SaturatedLiquid,
}

/// Flowsheet description of a feed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FeedConfig {
    /// Molar flow (e.g. `"1 kmol/min"`; bare numbers in mol/s).
    #[serde(rename = "F")]
    pub flow: QuantityValue,
    /// Temperature (e.g. `"350 K"`, `"80 degC"`): required for a `liquid` or `vapour` feed; omit it
    /// when `condition` is `saturated_liquid` (the feed is then at its bubble point).
    #[serde(rename = "T", default, skip_serializing_if = "Option::is_none")]
    pub temperature: Option<QuantityValue>,
    /// Pressure (e.g. `"1 atm"`; bare numbers in Pa).
    #[serde(rename = "P")]
    pub pressure: QuantityValue,
    /// Mole fractions by component name; missing components are 0.
    pub z: BTreeMap<String, f64>,
    /// Thermal condition (default `liquid`).
    #[serde(default)]
    pub condition: FeedCondition,
}

impl crate::registry::UnitConfig for FeedConfig {
    fn ports() -> &'static str {
        "outlet `out`"
    }
}

/// A feed source.
#[derive(Debug, Clone)]
pub struct Feed {
    flow: f64,
    temperature: f64,
    pressure: f64,
    z: Vec<f64>,
    condition: FeedCondition,
    comp_names: Vec<String>,
}

impl Feed {
    /// Build from the flowsheet description.
    pub fn build(config: &FeedConfig, mut cx: BuildCx<'_>, _links: ()) -> Result<Feed, Vec<FieldError>> {
        let flow = cx.non_negative("F", &config.flow, Dimension::MOLAR_FLOW);
        let pressure = cx.positive("P", &config.pressure, Dimension::PRESSURE);
        let temperature = match (&config.temperature, config.condition) {
            (Some(t), FeedCondition::Liquid | FeedCondition::Vapour) => cx.positive("T", t, Dimension::TEMPERATURE),
            (None, FeedCondition::SaturatedLiquid) => f64::NAN,
            (Some(_), FeedCondition::SaturatedLiquid) => {
                cx.error(
                    "T",
                    "a saturated-liquid feed is at its bubble point: remove `T` or set `condition` to `liquid`",
                );
                f64::NAN
            }
            (None, _) => {
                cx.error(
                    "T",
                    "missing: give the feed temperature (e.g. \"350 K\") or set `condition` to `saturated_liquid`",
                );
                f64::NAN
            }
        };
        let z = cx.composition("z", &config.z);
        let comp_names = cx.components.to_vec();
        cx.finish(Feed { flow, temperature, pressure, z, condition: config.condition, comp_names })
    }

    fn has_t_input(&self) -> bool {
        self.condition != FeedCondition::SaturatedLiquid
    }
}

impl UnitModel for Feed {
    fn type_name(&self) -> &'static str {
        "feed"
    }
    fn shape(&self) -> Shape {
        Shape::Source
    }
    fn boundary(&self) -> Boundary {
        Boundary::Source
    }
    /// The input `F` sets the outflow.
    fn material_flows(&self) -> MaterialFlows {
        MaterialFlows::one(FlowVia::Outlet("out".into()), FlowLaw::Input("F".into()))
    }
    fn inlet_ports(&self) -> Vec<String> {
        Vec::new()
    }
    fn outlet_ports(&self) -> Vec<String> {
        vec!["out".into()]
    }
    fn inputs(&self) -> Vec<InputSpec> {
        let mut v = vec![InputSpec { name: "F".into(), dim: Dimension::MOLAR_FLOW, value: self.flow }];
        v.push(InputSpec { name: "P".into(), dim: Dimension::PRESSURE, value: self.pressure });
        if self.has_t_input() {
            v.push(InputSpec { name: "T".into(), dim: Dimension::TEMPERATURE, value: self.temperature });
        }
        let n = self.z.len();
        for (name, &z) in self.comp_names.iter().zip(&self.z).take(n - 1) {
            v.push(InputSpec { name: format!("z[{name}]"), dim: Dimension::DIMENSIONLESS, value: z });
        }
        v
    }
    /// A saturated-liquid feed must boil within its components' vapour-pressure data: below the
    /// lowest temperature of a present component's correlation (its triple-point region) there is
    /// no liquid, and the bubble point would be an extrapolation (a feed at 1.3 Pa instead of
    /// 1.3 atm).
    fn check_inputs(&self, thermo: &ThermoPackage, inputs: &[f64]) -> Result<(), InputError> {
        if self.has_t_input() {
            return Ok(());
        }
        let p = inputs[1];
        let mut z: Vec<f64> = inputs[2..].to_vec();
        z.push(1.0 - z.iter().sum::<f64>());
        let t = thermo
            .bubble_t(p, &z)
            .map_err(|source| InputError::NoBubblePoint { input: "P".into(), pressure: p, source })?
            .t;
        for (c, _) in thermo.components.iter().zip(&z).filter(|(_, zi)| **zi > 0.0) {
            if let Some(t_min) = c.psat.t_min().filter(|&t_min| t < t_min) {
                return Err(InputError::BelowVapourPressureData {
                    input: "P".into(),
                    pressure: p,
                    bubble_t: t,
                    t_min,
                    component: c.name.clone(),
                });
            }
        }
        Ok(())
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let out = io.outlet(0);
        let n = io.n_comp();
        let z0 = if self.has_t_input() { 3 } else { 2 };
        r[F] = out.f() - io.input(0);
        r[P] = out.p() - io.input(1);
        let mut rest = S::from(1.0);
        for i in 0..n - 1 {
            let zi = io.input(z0 + i);
            r[Z0 + i] = out.z()[i] - zi;
            rest -= zi;
        }
        r[Z0 + n - 1] = out.z()[n - 1] - rest;
        let z = out.z();
        r[T] = match self.condition {
            FeedCondition::SaturatedLiquid => io.thermo.bubble_residual(out.t(), out.p(), z),
            _ => out.t() - io.input(2),
        };
        let phase = if self.condition == FeedCondition::Vapour { Phase::Vapour } else { Phase::Liquid };
        r[H] = out.h() - phase.enthalpy(io.thermo, out.t(), out.p(), z);
    }
    /// The feed's outlet at its input values (the guess is made at the inputs it is given, which
    /// `--set` or an analysis may have moved from the file's), the last fraction making up the
    /// balance as in [`UnitModel::eval`].
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let n = io.n_comp();
        let z0 = if self.has_t_input() { 3 } else { 2 };
        let mut z: Vec<f64> = (0..n - 1).map(|i| io.input(z0 + i)).collect();
        z.push((1.0 - z.iter().sum::<f64>()).max(0.0));
        own[F] = io.input(0);
        own[P] = io.input(1);
        own[Z0..].copy_from_slice(&z);
        own[T] =
            if self.has_t_input() { io.input(2) } else { io.thermo.bubble_t(own[P], &z).map(|s| s.t).unwrap_or(350.0) };
        let phase = if self.condition == FeedCondition::Vapour { Phase::Vapour } else { Phase::Liquid };
        own[H] = phase.enthalpy(io.thermo, own[T], own[P], &z);
    }
}
