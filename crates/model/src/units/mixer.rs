//! Mixer: adiabatic mixing of `n` inlet streams into one outlet.
//!
//! Ports: inlets `in1 … inN`, outlet `out`.
//!
//! Equations (no holdup):
//! - total balance `F = Σ_k F_k`;
//! - component balances `F z_i = Σ_k F_k z_k,i`;
//! - energy balance `F h = Σ_k F_k h_k`;
//! - pressure `P = P_in1` (the first inlet sets the pressure; put the lowest-pressure stream there),
//!   or a given outlet pressure;
//! - temperature from the outlet phase: `h = h_phase(T, z)`.
//!
//! At zero flow the composition and energy balances read `0 = 0`: the outlet's `z` and `h` are
//! undetermined and the Jacobian singular (a mixer all of whose feeds are lost stopped the run,
//! "iteration matrix singular"). Below a flow of [`STOPPED`] they are written
//! `(F + ε) z_i = Σ_k F_k z_k,i + ε z̄_i` and `(F + ε) h = Σ_k F_k h_k + ε h̄` with the inlets'
//! unweighted means `z̄`, `h̄` and `ε = STOPPED (1 − F/STOPPED)²` (continuous with its slope at
//! `STOPPED`, zero above it): a stopped mixer carries the mean of its inlets, and a flowing one
//! the exact balances. The component flow it passes differs from the inlets' by
//! `εF (z̄_i − z_i*)/(F + ε)` (`z*` the exact mixture), at most `F ≤ 1e-9 mol/s` and only while
//! the flow passes through `(0, 1e-9)` mol/s.

use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::Phase;
use crate::stream::{F, H, P, T, Z0};
use crate::{BuildCx, FieldError, Scalar, UnitIo, UnitModel};

fn default_inlets() -> usize {
    2
}

/// Flowsheet description of a mixer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MixerConfig {
    /// Number of inlets (ports `in1 … inN`, default 2).
    #[serde(default = "default_inlets")]
    pub inlets: usize,
    /// Phase of the outlet (default `liquid`).
    #[serde(default)]
    pub phase: Phase,
    /// Outlet pressure; default: the pressure of `in1`.
    #[serde(rename = "P", default, skip_serializing_if = "Option::is_none")]
    pub pressure: Option<QuantityValue>,
}

impl crate::registry::UnitConfig for MixerConfig {
    fn ports() -> &'static str {
        "inlets `in1`, `in2`, … (`inlets` of them), outlet `out`"
    }
}

/// Flow [mol/s] below which a mixer's outlet leans on its inlets' mean (see the module text).
pub const STOPPED: f64 = 1e-9;

/// A mixer.
#[derive(Debug, Clone)]
pub struct Mixer {
    n_in: usize,
    phase: Phase,
    pressure: Option<f64>,
}

impl Mixer {
    /// Build from the flowsheet description.
    pub fn build(config: &MixerConfig, mut cx: BuildCx<'_>, _links: ()) -> Result<Mixer, Vec<FieldError>> {
        if config.inlets < 1 {
            cx.error("inlets", "a mixer needs at least one inlet");
        }
        if !cx.count("inlets", config.inlets, crate::limits::Limits::get().inlets()) {
            return Err(cx.errors);
        }
        let pressure = config.pressure.as_ref().map(|p| cx.positive("P", p, Dimension::PRESSURE));
        cx.finish(Mixer { n_in: config.inlets, phase: config.phase, pressure })
    }
}

impl Mixer {
    /// The stopped-flow terms: `ε (h − h̄)` and `ε (z_i − z̄_i)` added to the balances, with
    /// `ε = STOPPED (1 − F/STOPPED)²` (for `F < STOPPED`).
    fn lean_on_inlets<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let out = io.outlet(0);
        let gap = S::from(1.0) - out.f() / STOPPED;
        let eps = gap * gap * STOPPED;
        let share = 1.0 / self.n_in as f64;
        let mean = |value: &dyn Fn(usize) -> S| (0..self.n_in).fold(S::from(0.0), |acc, k| acc + value(k) * share);
        r[H] += eps * (out.h() - mean(&|k| io.inlet(k).h()));
        for i in 0..io.n_comp() {
            r[Z0 + i] += eps * (out.z()[i] - mean(&|k| io.inlet(k).z()[i]));
        }
    }
}

impl UnitModel for Mixer {
    fn type_name(&self) -> &'static str {
        "mixer"
    }
    fn inlet_ports(&self) -> Vec<String> {
        (1..=self.n_in).map(|k| format!("in{k}")).collect()
    }
    fn outlet_ports(&self) -> Vec<String> {
        vec!["out".into()]
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let out = io.outlet(0);
        let n = io.n_comp();
        let mut f = S::from(0.0);
        let mut fh = S::from(0.0);
        let mut fz = vec![S::from(0.0); n];
        for k in 0..self.n_in {
            let s = io.inlet(k);
            f += s.f();
            fh += s.f() * s.h();
            for (acc, zi) in fz.iter_mut().zip(s.z()) {
                *acc += s.f() * *zi;
            }
        }
        r[F] = out.f() - f;
        r[H] = out.f() * out.h() - fh;
        for i in 0..n {
            r[Z0 + i] = out.f() * out.z()[i] - fz[i];
        }
        if out.f().re() < STOPPED {
            self.lean_on_inlets(io, r);
        }
        r[P] = match self.pressure {
            Some(p) => out.p() - p,
            None => out.p() - io.inlet(0).p(),
        };
        r[T] = out.h() - self.phase.enthalpy(io.thermo, out.t(), out.p(), out.z());
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let n = io.n_comp();
        let (mut f, mut fh) = (0.0, 0.0);
        let mut fz = vec![0.0; n];
        for k in 0..self.n_in {
            let s = io.inlet(k);
            f += s.f();
            fh += s.f() * s.h();
            fz.iter_mut().zip(s.z()).for_each(|(a, z)| *a += s.f() * z);
        }
        let s0 = io.inlet(0);
        own[F] = f;
        own[P] = self.pressure.unwrap_or(s0.p());
        if f > 0.0 {
            own[H] = fh / f;
            fz.iter().zip(&mut own[Z0..]).for_each(|(a, z)| *z = a / f);
        } else {
            own[H] = s0.h();
            own[Z0..].copy_from_slice(s0.z());
        }
        own[T] = self.phase.temperature(io.thermo, own[H], own[P], &own[Z0..], s0.t());
    }
}
