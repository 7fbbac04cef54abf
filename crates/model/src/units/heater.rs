//! Heater / cooler: one stream heated (or cooled) by a given duty or to a given outlet temperature.
//!
//! Ports: inlet `in`, outlet `out`. Input: `duty` [W] (duty mode) or `T_out` [K] (temperature
//! mode). Internal variable `Q` [W], the duty (positive heats).
//!
//! Equations: `F_out = F_in`, `z_out = z_in`, `P_out = P_in − ΔP`, energy `F (h_out − h_in) = Q`,
//! outlet state `h_out = h_phase(T_out, z)`, and either `Q = duty` or `T_out = T_set`.

use crate::capability::{Booking, Duty, DutySource};
use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::Phase;
use crate::stream::{F, H, P, T, Z0};
use crate::{BuildCx, FieldError, InputSpec, Scalar, UnitIo, UnitModel, VarSpec};

/// Flowsheet description of a heater; give exactly one of `duty` and `T_out`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HeaterConfig {
    /// Heat duty, positive to heat (e.g. `"2 MW"`, `"1e6 Btu/h"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duty: Option<QuantityValue>,
    /// Outlet temperature (e.g. `"80 degC"`).
    #[serde(rename = "T_out", default, skip_serializing_if = "Option::is_none")]
    pub outlet_temperature: Option<QuantityValue>,
    /// Pressure drop (default 0).
    #[serde(rename = "dP", default, skip_serializing_if = "Option::is_none")]
    pub pressure_drop: Option<QuantityValue>,
    /// Phase of the outlet (default `liquid`).
    #[serde(default)]
    pub phase: Phase,
}

impl crate::registry::UnitConfig for HeaterConfig {
    fn ports() -> &'static str {
        "inlet `in`, outlet `out`"
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Mode {
    Duty(f64),
    Temperature(f64),
}

/// A heater or cooler.
#[derive(Debug, Clone)]
pub struct Heater {
    mode: Mode,
    dp: f64,
    phase: Phase,
}

const Q: usize = 0;

impl Heater {
    /// Build from the flowsheet description.
    pub fn build(config: &HeaterConfig, mut cx: BuildCx<'_>, _links: ()) -> Result<Heater, Vec<FieldError>> {
        let mode = match (&config.duty, &config.outlet_temperature) {
            (Some(q), None) => Mode::Duty(cx.quantity("duty", q, Dimension::POWER)),
            (None, Some(t)) => Mode::Temperature(cx.positive("T_out", t, Dimension::TEMPERATURE)),
            _ => {
                cx.error("", "give exactly one of `duty` (e.g. \"1 MW\") and `T_out` (e.g. \"350 K\")");
                Mode::Duty(0.0)
            }
        };
        let dp = match &config.pressure_drop {
            Some(d) => cx.non_negative("dP", d, Dimension::PRESSURE),
            None => 0.0,
        };
        cx.finish(Heater { mode, dp, phase: config.phase })
    }
}

impl UnitModel for Heater {
    fn type_name(&self) -> &'static str {
        "heater"
    }
    /// `Q` \[W\], heating when positive.
    fn duties(&self) -> Vec<Duty> {
        vec![Duty { source: DutySource::Var("Q".into()), booking: Booking::Utility }]
    }
    fn inlet_ports(&self) -> Vec<String> {
        vec!["in".into()]
    }
    fn outlet_ports(&self) -> Vec<String> {
        vec!["out".into()]
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        vec![VarSpec::algebraic("Q", Dimension::POWER, 1e5)]
    }
    fn inputs(&self) -> Vec<InputSpec> {
        vec![match self.mode {
            Mode::Duty(q) => InputSpec { name: "duty".into(), dim: Dimension::POWER, value: q },
            Mode::Temperature(t) => InputSpec { name: "T_out".into(), dim: Dimension::TEMPERATURE, value: t },
        }]
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let (inlet, out) = (io.inlet(0), io.outlet(0));
        let len = io.layout.stream.len();
        let q = io.var(Q);
        r[F] = out.f() - inlet.f();
        r[P] = out.p() - inlet.p() + self.dp;
        for (i, (zo, zi)) in out.z().iter().zip(inlet.z()).enumerate() {
            r[Z0 + i] = *zo - *zi;
        }
        let state = out.h() - self.phase.enthalpy(io.thermo, out.t(), out.p(), out.z());
        let energy = out.f() * (out.h() - inlet.h()) - q;
        match self.mode {
            Mode::Duty(_) => {
                r[T] = state;
                r[H] = energy;
                r[len + Q] = q - io.input(0);
            }
            Mode::Temperature(_) => {
                r[T] = out.t() - io.input(0);
                r[H] = state;
                r[len + Q] = energy;
            }
        }
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let inlet = io.inlet(0);
        let len = io.layout.stream.len();
        own[F] = inlet.f();
        own[P] = inlet.p() - self.dp;
        own[Z0..len].copy_from_slice(inlet.z());
        let z = inlet.z().to_vec();
        match self.mode {
            Mode::Duty(_) => {
                let q = io.input(0);
                own[H] = inlet.h() + if inlet.f() > 0.0 { q / inlet.f() } else { 0.0 };
                own[T] = self.phase.temperature(io.thermo, own[H], own[P], &z, inlet.t());
                own[len + Q] = q;
            }
            Mode::Temperature(_) => {
                own[T] = io.input(0);
                own[H] = self.phase.enthalpy(io.thermo, own[T], own[P], &z);
                own[len + Q] = inlet.f() * (own[H] - inlet.h());
            }
        }
    }
}
