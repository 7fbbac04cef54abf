//! What the vessels (`tank`, `flash`, `cstr`) share: the liquid outflow law and the liquid holdup.
//!
//! **Outflow.** The vessel owns its liquid outlet stream; the law is the equation for its molar flow
//! `F` [mol/s]. `v_L` [m³/mol] and `M_w` [kg/mol] are the liquid's molar volume and molar mass,
//! `ρ = M_w/v_L` [kg/m³] its density, `L` [m] the level, `g = 9.80665 m/s²`.
//! - `valve` to a downstream pressure `p_out` [Pa]: volumetric flow `Q = C_v f(op) √(ΔP/ρ)` [m³/s],
//!   `ΔP = P + ρ g L − p_out` [Pa], i.e. `F = C_v f(op) ŝ(ΔP) / √(M_w v_L)`. `C_v` [m²] is the SI
//!   coefficient (one US Cv, gpm of water per √psi, is 2.40e-5 m²). `f = op` (linear) or
//!   `f = R^(op − 1)` (equal percentage, rangeability `R`, default 50); the opening `op` [-] (input
//!   `opening`) is clamped to [0, 1]. `ŝ(ΔP) = sign(ΔP) √|ΔP|` for `|ΔP| ≥ δ = 10 Pa` and
//!   `√δ u (3 − |u|)/2`, `u = ΔP/δ`, inside: exact beyond ~1 mm of liquid head, odd and C¹, with a
//!   finite slope (at most `1.5/√δ`) through `ΔP = 0`. Reverse flow is only a smooth continuation;
//!   the bound `F ≥ 0` keeps Newton on the forward branch. The outlet stream is at `p_out`.
//! - `flow`: a pump on flow control, `F = F_set` (input `outflow` [mol/s]); outlet at `P`. With its
//!   outflow set, a vessel's holdup is undetermined at steady state unless a level controller moves
//!   `outflow`.
//! - `free`: a downstream unit (a `valve` unit) sets `F`; the vessel owns `F` and writes no equation
//!   for it (`extra_equations() = −1`). The outlet is at the drain-nozzle pressure `P + ρ g L` [Pa].
//!
//! **Holdup.** Variables `N[c]` [mol] (differential), `M` [mol], `level` [m], `V` [m³] (liquid
//! volume); equations `M = Σ_i N_i`, `x_i M = N_i` [mol], `V = M v_L(T, x)`, `A · level = V` [m³], `A`
//! [m²] the cross-section of a vertical cylinder of `diameter` [m] or a given `area`.

use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::stream::{F, P};
use crate::{BuildCx, InputSpec, Scalar, UnitIo, VarSpec};

/// Standard gravity [m/s²].
pub const GRAVITY: f64 = 9.80665;
/// Half-width [Pa] of the regularised band of the valve's square root.
pub const DP_SMOOTH: f64 = 10.0;
/// One standard atmosphere [Pa].
pub const ATM: f64 = 101_325.0;

fn default_rangeability() -> f64 {
    50.0
}

/// Inherent valve characteristic.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Characteristic {
    /// `f = op`.
    #[default]
    Linear,
    /// `f = R^(op − 1)`, `R` the rangeability.
    EqualPercentage,
}

impl Characteristic {
    /// Fraction of the full-open flow coefficient at opening `op` (clamped to [0, 1]) for
    /// rangeability `e^ln_r`.
    pub fn fraction<S: Scalar>(self, op: S, ln_r: f64) -> S {
        let op = if op.re() < 0.0 {
            S::from(0.0)
        } else if op.re() > 1.0 {
            S::from(1.0)
        } else {
            op
        };
        match self {
            Characteristic::Linear => op,
            Characteristic::EqualPercentage => ((op - 1.0) * ln_r).exp(),
        }
    }
}

/// How the liquid leaves a vessel (`"type": "valve" | "flow" | "free"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Outflow {
    /// Control valve to a fixed downstream pressure.
    Valve {
        /// SI valve coefficient [m²]: `Q [m³/s] = cv·f(op)·√(ΔP [Pa]/ρ [kg/m³])` (e.g. `"2.4e-3 m2"`).
        cv: QuantityValue,
        /// Characteristic (default `linear`).
        #[serde(default)]
        characteristic: Characteristic,
        /// Rangeability `R` [-] of an equal-percentage valve (default 50).
        #[serde(default = "default_rangeability")]
        rangeability: f64,
        /// Opening [-], 0 … 1 (input `opening`).
        opening: f64,
        /// Downstream pressure [Pa] (e.g. `"1.2 bar"`; default 1 atm).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        p_out: Option<QuantityValue>,
    },
    /// Pump on flow control: the outflow [mol/s] is the input `outflow`.
    Flow {
        /// Molar outflow [mol/s] (e.g. `"1 kmol/min"`).
        flow: QuantityValue,
    },
    /// A downstream unit sets the outflow [mol/s]; the vessel writes no equation for it.
    Free {},
}

/// A built outflow law (SI).
#[derive(Debug, Clone, PartialEq)]
pub enum OutflowLaw {
    /// See [`Outflow::Valve`].
    Valve {
        /// SI valve coefficient [m²].
        cv: f64,
        /// Valve characteristic.
        characteristic: Characteristic,
        /// Rangeability `R` [-] of an equal-percentage valve.
        rangeability: f64,
        /// Opening [-], 0 … 1 (the initial value of input `opening`).
        opening: f64,
        /// Downstream pressure [Pa].
        p_out: f64,
    },
    /// See [`Outflow::Flow`].
    Flow {
        /// Molar outflow [mol/s] (the initial value of input `outflow`).
        flow: f64,
    },
    /// See [`Outflow::Free`].
    Free,
}

/// The vessel-liquid state an outflow law reads.
#[derive(Debug, Clone, Copy)]
pub struct LiquidState<S> {
    /// Vessel (gas-space) pressure [Pa].
    pub p: S,
    /// Level [m].
    pub level: S,
    /// Molar mass [kg/mol].
    pub mw: S,
    /// Molar volume [m³/mol].
    pub v: S,
}

impl OutflowLaw {
    /// Build from the description at `field` of the current unit.
    pub fn build(config: &Outflow, cx: &mut BuildCx<'_>, field: &str) -> OutflowLaw {
        match config {
            Outflow::Valve { cv, characteristic, rangeability, opening, p_out } => {
                let cv = cx.positive(&format!("{field}.cv"), cv, Dimension::AREA);
                let eq = *characteristic == Characteristic::EqualPercentage;
                if eq && !(rangeability.is_finite() && *rangeability > 1.0) {
                    cx.error(&format!("{field}.rangeability"), format!("must be a number > 1 (got {rangeability})"));
                }
                let opening = cx.in_range(&format!("{field}.opening"), *opening, 0.0, 1.0);
                let p_out =
                    p_out.as_ref().map_or(ATM, |p| cx.positive(&format!("{field}.p_out"), p, Dimension::PRESSURE));
                OutflowLaw::Valve { cv, characteristic: *characteristic, rangeability: *rangeability, opening, p_out }
            }
            Outflow::Flow { flow } => {
                OutflowLaw::Flow { flow: cx.non_negative(&format!("{field}.flow"), flow, Dimension::MOLAR_FLOW) }
            }
            Outflow::Free {} => OutflowLaw::Free,
        }
    }
    /// The inputs the law adds: `opening` [-] (valve) or `outflow` [mol/s] (flow).
    pub fn inputs(&self) -> Vec<InputSpec> {
        match self {
            OutflowLaw::Valve { opening, .. } => {
                vec![InputSpec { name: "opening".into(), dim: Dimension::DIMENSIONLESS, value: *opening }]
            }
            OutflowLaw::Flow { flow } => {
                vec![InputSpec { name: "outflow".into(), dim: Dimension::MOLAR_FLOW, value: *flow }]
            }
            OutflowLaw::Free => Vec::new(),
        }
    }
    /// What sets the outflow, for the consistency check of inventory control: the holdup through
    /// the valve (moved by `opening`: the vessel regulates itself), the input `outflow` (a pumped
    /// outflow: a pure integrator unless a level loop moves it), or `None` for `free` (the
    /// downstream unit sets it).
    pub fn flow_law(&self) -> Option<crate::capability::FlowLaw> {
        use crate::capability::FlowLaw;
        match self {
            OutflowLaw::Valve { .. } => Some(FlowLaw::Holdup { input: Some("opening".into()) }),
            OutflowLaw::Flow { .. } => Some(FlowLaw::Input("outflow".into())),
            OutflowLaw::Free => None,
        }
    }
    /// Equations relative to own variables: −1 for `free`, else 0.
    pub fn extra_equations(&self) -> isize {
        if matches!(self, OutflowLaw::Free) { -1 } else { 0 }
    }
    /// Outlet-stream pressure [Pa]: `p_out` (valve), `P` (flow) or `P + ρ g L` (free).
    pub fn outlet_pressure<S: Scalar>(&self, liq: &LiquidState<S>) -> S {
        match self {
            OutflowLaw::Valve { p_out, .. } => S::from(*p_out),
            OutflowLaw::Flow { .. } => liq.p,
            OutflowLaw::Free => liq.p + liq.mw / liq.v * liq.level * GRAVITY,
        }
    }
    /// Residual [mol/s] of the law for the outflow `f`, the law's inputs starting at `inputs[0]`;
    /// None for `free`.
    pub fn outflow_residual<S: Scalar>(&self, f: S, liq: &LiquidState<S>, inputs: &[S]) -> Option<S> {
        match self {
            OutflowLaw::Valve { cv, characteristic, rangeability, p_out, .. } => {
                let dp = liq.p + liq.mw / liq.v * liq.level * GRAVITY - *p_out;
                let fop = characteristic.fraction(inputs[0], rangeability.ln());
                Some(f - fop * *cv * signed_sqrt(dp) / (liq.mw * liq.v).sqrt())
            }
            OutflowLaw::Flow { .. } => Some(f - inputs[0]),
            OutflowLaw::Free => None,
        }
    }
    /// Copy a vessel's own residuals `res` into `r` after writing the pressure and flow equations of
    /// the outlet stream that starts at own index `at` (the law's inputs start at input `first_input`).
    /// For `free` the last residual takes the flow slot and `r` is one shorter: the vessel's last own
    /// variable must be algebraic.
    pub fn close<S: Scalar>(
        &self,
        io: &UnitIo<'_, S>,
        at: usize,
        first_input: usize,
        liq: &LiquidState<S>,
        mut res: Vec<S>,
        r: &mut [S],
    ) {
        res[at + P] = io.local[at + P] - self.outlet_pressure(liq);
        let inputs = &io.local[io.layout.inputs_offset() + first_input..];
        if let Some(v) = self.outflow_residual(io.local[at + F], liq, inputs).or_else(|| res.last().copied()) {
            res[at + F] = v;
        }
        r.iter_mut().zip(res).for_each(|(ri, v)| *ri = v);
    }
    /// Outflow [mol/s] and opening [-] for a guess: the input `outflow` for `flow`, else `flow`.
    pub fn guess_flow(&self, io: &UnitIo<'_, f64>, first_input: usize, flow: f64) -> (f64, f64) {
        match self {
            OutflowLaw::Valve { .. } => (flow, io.input(first_input)),
            OutflowLaw::Flow { .. } => (io.input(first_input), 0.0),
            OutflowLaw::Free => (flow, 0.0),
        }
    }
    /// Level [m] at which a valve passes `flow` [mol/s] at opening `op` (`√ΔP = F √(M_w v_L)/(C_v f)`);
    /// None for other laws, no flow, or a level ≤ 0.
    pub fn steady_level(&self, flow: f64, op: f64, liq: &LiquidState<f64>) -> Option<f64> {
        let OutflowLaw::Valve { cv, characteristic, rangeability, p_out, .. } = self else { return None };
        let s = flow * (liq.mw * liq.v).sqrt() / (cv * characteristic.fraction(op, rangeability.ln()));
        let level = (s * s - liq.p + p_out) / (liq.mw / liq.v * GRAVITY);
        (flow > 0.0 && level.is_finite() && level > 0.0).then_some(level)
    }
}

/// `sign(x) √|x|` for `|x| ≥ δ`, else `√δ u (3 − |u|)/2` with `u = x/δ` (`δ = DP_SMOOTH` [Pa]).
pub fn signed_sqrt<S: Scalar>(x: S) -> S {
    if x.re() >= DP_SMOOTH {
        x.sqrt()
    } else if x.re() <= -DP_SMOOTH {
        -(-x).sqrt()
    } else {
        let u = x / DP_SMOOTH;
        u * (-u.abs() + 3.0) * (0.5 * DP_SMOOTH.sqrt())
    }
}

/// A vessel's liquid holdup: geometry, level guess and nominal holdup (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Holdup {
    /// Cross-sectional area [m²].
    pub area: f64,
    /// Level [m] used when nothing better is known: `level`, else half the height, else 1 m.
    pub level: f64,
    /// Nominal holdup [mol] (scaling).
    pub m_nominal: f64,
    names: Vec<String>,
}

impl Holdup {
    /// Exactly one of `diameter` [m] and `area` [m²]; optional `height` [m] and initial `level` [m].
    pub fn build(
        cx: &mut BuildCx<'_>,
        diameter: Option<&QuantityValue>,
        area: Option<&QuantityValue>,
        height: Option<&QuantityValue>,
        level: Option<&QuantityValue>,
    ) -> Holdup {
        let area = match (diameter, area) {
            (Some(d), None) => std::f64::consts::PI * cx.positive("diameter", d, Dimension::LENGTH).powi(2) / 4.0,
            (None, Some(a)) => cx.positive("area", a, Dimension::AREA),
            _ => {
                cx.error(
                    "",
                    "give exactly one of `diameter` (vertical cylinder, e.g. \"2 m\") and `area` (e.g. \"3 m2\")",
                );
                1.0
            }
        };
        let height = height.map(|h| cx.positive("height", h, Dimension::LENGTH));
        let level =
            level.map(|l| cx.positive("level", l, Dimension::LENGTH)).or(height.map(|h| 0.5 * h)).unwrap_or(1.0);
        let n = cx.thermo.n().max(1) as f64;
        let v = cx.thermo.components.iter().map(|c| c.v_liq(298.15)).sum::<f64>() / n;
        let m_nominal = area * level / if v.is_finite() && v > 0.0 { v } else { 1e-4 };
        Holdup { area, level, m_nominal, names: cx.components.to_vec() }
    }
    /// `N[c]` [mol], differential.
    pub fn component_vars(&self) -> Vec<VarSpec> {
        let nominal = self.m_nominal / self.names.len().max(1) as f64;
        let spec = |c| VarSpec::differential(format!("N[{c}]"), Dimension::AMOUNT, nominal).bounded(0.0, f64::INFINITY);
        self.names.iter().map(spec).collect()
    }
    /// `M` [mol], `level` [m], `V` [m³], algebraic.
    pub fn volume_vars(&self) -> Vec<VarSpec> {
        vec![
            VarSpec::algebraic("M", Dimension::AMOUNT, self.m_nominal).bounded(0.0, f64::INFINITY).inventory(),
            VarSpec::algebraic("level", Dimension::LENGTH, self.level).bounded(0.0, f64::INFINITY),
            VarSpec::algebraic("V", Dimension::VOLUME, self.level * self.area).bounded(0.0, f64::INFINITY),
        ]
    }
    /// `x_i M − N_i` into `res[x_at + i]`; `M − Σ N_i`, `A level − V`, `V − M v_L` into `res[v_at..]`,
    /// with `mlv = [M, level, V]` and `(x_at, v_at) = at`.
    pub fn residuals<S: Scalar>(&self, n: &[S], x: &[S], mlv: &[S], v_l: S, res: &mut [S], at: (usize, usize)) {
        let (x_at, v_at) = at;
        let (m, level, vol) = (mlv[0], mlv[1], mlv[2]);
        let mut sum = S::from(0.0);
        for (i, (ni, xi)) in n.iter().zip(x).enumerate() {
            res[x_at + i] = *xi * m - *ni;
            sum += *ni;
        }
        res[v_at] = m - sum;
        res[v_at + 1] = level * self.area - vol;
        res[v_at + 2] = vol - m * v_l;
    }
    /// Guess `[M, level, V]`: the level at which the law passes `flow` [mol/s] at opening `op`, else
    /// the default level.
    pub fn guess(&self, law: &OutflowLaw, flow: f64, op: f64, liq: &LiquidState<f64>) -> [f64; 3] {
        let level = law.steady_level(flow, op, liq).unwrap_or(self.level);
        [level * self.area / liq.v, level, level * self.area]
    }
}

/// `z` normalised to sum 1 (uniform if it sums to 0), for guesses.
pub fn normalized(z: &[f64]) -> Vec<f64> {
    let s: f64 = z.iter().sum();
    if s > 0.0 { z.iter().map(|v| v / s).collect() } else { vec![1.0 / z.len().max(1) as f64; z.len()] }
}

#[cfg(test)]
pub(crate) mod test_support {
    //! Test helpers shared by the vessels.

    use plantwide_thermo::ThermoPackage;

    use crate::{BuildCx, FieldError, LocalLayout, StreamLayout, Unit, UnitIo};

    /// Build a unit from its JSON description.
    pub fn build_unit<C: serde::de::DeserializeOwned, U>(
        json: &str,
        thermo: &ThermoPackage,
        build: fn(&C, BuildCx<'_>, ()) -> Result<U, Vec<FieldError>>,
    ) -> U {
        let names: Vec<String> = thermo.components.iter().map(|c| c.name.clone()).collect();
        build(&serde_json::from_str(json).unwrap(), BuildCx::new(&names, thermo, "units.u"), ()).unwrap()
    }

    /// Layout and local vector of a one-inlet unit: `inlet`, inputs at their values, own block at the guess.
    pub fn at_guess(unit: &dyn Unit, thermo: &ThermoPackage, inlet: &[f64]) -> (LocalLayout, Vec<f64>) {
        let (n_outlets, n_internal, n_inputs) =
            (unit.outlet_ports().len(), unit.internal_vars().len(), unit.inputs().len());
        let lay = LocalLayout {
            stream: StreamLayout { n_comp: thermo.n() },
            n_outlets,
            n_internal,
            n_inlets: 1,
            n_inputs,
            n_signals: 0,
        };
        let mut local = vec![0.0; lay.len()];
        local[lay.inlets_offset()..lay.inputs_offset()].copy_from_slice(inlet);
        unit.inputs().iter().enumerate().for_each(|(k, i)| local[lay.inputs_offset() + k] = i.value);
        let mut own = vec![0.0; lay.n_own()];
        unit.guess(&UnitIo { local: &local, layout: &lay, thermo, time: 0.0 }, &mut own);
        local[..lay.n_own()].copy_from_slice(&own);
        (lay, local)
    }

    /// Solve the (square) own block with inlets and inputs fixed: Newton with partial-pivoting
    /// elimination, steps cut to the variable bounds (fraction to the boundary 0.995) and halved until
    /// the scaled residual falls. Returns the max-norm of the residual, each row relative to
    /// `max_j |J_kj x_j|`.
    pub fn solve_own(unit: &dyn Unit, layout: &LocalLayout, thermo: &ThermoPackage, local: &mut [f64]) -> f64 {
        let (n, len) = (layout.n_own(), local.len());
        let names: Vec<String> = thermo.components.iter().map(|c| c.name.clone()).collect();
        let mut specs: Vec<_> = (0..layout.n_outlets).flat_map(|_| layout.stream.var_specs(&names, 1.0)).collect();
        specs.extend(unit.internal_vars());
        let (mut r, mut trial, mut jac) = (vec![0.0; n], vec![0.0; n], vec![0.0; n * len]);
        let mut norm = f64::INFINITY;
        for _ in 0..200 {
            unit.jacobian(&UnitIo { local, layout, thermo, time: 0.0 }, &mut r, &mut jac);
            let scale: Vec<f64> =
                (0..n).map(|k| (0..len).fold(1e-300, |s: f64, j| s.max((jac[k * len + j] * local[j]).abs()))).collect();
            let merit = |r: &[f64]| r.iter().zip(&scale).map(|(v, s)| (v / s).powi(2)).sum::<f64>();
            norm = r.iter().zip(&scale).fold(0.0, |m: f64, (v, s)| m.max(v.abs() / s));
            if norm < 1e-15 {
                break;
            }
            let mut a: Vec<Vec<f64>> =
                (0..n).map(|k| (0..n).map(|j| jac[k * len + j]).chain([-r[k]]).collect()).collect();
            for c in 0..n {
                let p = (c..n).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs())).unwrap_or(c);
                a.swap(c, p);
                for i in c + 1..n {
                    let m = a[i][c] / a[c][c];
                    (c..=n).for_each(|j| a[i][j] -= m * a[c][j]);
                }
            }
            let mut dx = vec![0.0; n];
            for c in (0..n).rev() {
                dx[c] = (a[c][n] - (c + 1..n).map(|j| a[c][j] * dx[j]).sum::<f64>()) / a[c][c];
            }
            let mut tau: f64 = 1.0;
            for ((x, d), v) in local.iter().zip(&dx).zip(&specs) {
                let room = if *d < 0.0 { v.lower - x } else { v.upper - x };
                if *d != 0.0 && (room / d).is_finite() {
                    tau = tau.min(0.995 * room / d);
                }
            }
            let x0 = local[..n].to_vec();
            for _ in 0..30 {
                local.iter_mut().zip(&x0).zip(&dx).for_each(|((x, x0), d)| *x = x0 + tau * d);
                unit.residual(&UnitIo { local, layout, thermo, time: 0.0 }, &mut trial);
                if merit(&trial) < merit(&r) || tau < 1e-6 {
                    break;
                }
                tau *= 0.5;
            }
            if dx.iter().zip(&x0).all(|(d, x)| (tau * d).abs() <= 1e-15 * x.abs()) {
                break;
            }
        }
        norm
    }

    /// A seeded linear congruential generator.
    pub struct Lcg(pub u64);

    /// The largest [`crate::testing::jacobian_error`] of `unit` over five points around its guess
    /// from `inlet`: each local value scaled by a factor in `[1 − spread, 1 + spread)`, a zero
    /// replaced by a number in `[0.01, 0.1)`.
    pub fn worst_jacobian_error(
        unit: &dyn Unit,
        thermo: &ThermoPackage,
        inlet: &[f64],
        rng: &mut Lcg,
        spread: f64,
    ) -> f64 {
        let (lay, base) = at_guess(unit, thermo, inlet);
        let n_eq = (lay.n_own() as isize + unit.extra_equations()) as usize;
        let mut worst: f64 = 0.0;
        for _ in 0..5 {
            let local: Vec<f64> = base
                .iter()
                .map(|&v| if v == 0.0 { rng.range(0.01, 0.1) } else { v * rng.range(1.0 - spread, 1.0 + spread) })
                .collect();
            worst = worst.max(crate::testing::jacobian_error(unit, &lay, thermo, &local, n_eq));
        }
        worst
    }

    impl Lcg {
        /// Next number in [lo, hi).
        pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
            self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signed_sqrt_is_c1_and_exact_outside_band() {
        for x in [10.0f64, 11.0, 1e4, -10.0, -1e3] {
            assert!((signed_sqrt(x) - x.signum() * x.abs().sqrt()).abs() < 1e-15 * x.abs().sqrt());
        }
        let d = |x: f64| signed_sqrt(num_dual::Dual64::new(x, 1.0)).eps;
        assert!((signed_sqrt(DP_SMOOTH - 1e-12) - DP_SMOOTH.sqrt()).abs() < 1e-9);
        assert!((d(DP_SMOOTH - 1e-12) - d(DP_SMOOTH + 1e-12)).abs() < 1e-9);
        assert!((d(0.0) - 1.5 / DP_SMOOTH.sqrt()).abs() < 1e-12 && signed_sqrt(0.0f64).abs() < 1e-300);
    }

    #[test]
    fn valve_law_and_json_forms() {
        let v: Outflow = serde_json::from_str(
            r#"{"type": "valve", "cv": "1e-3 m2", "characteristic": "equal_percentage", "opening": 0.5}"#,
        )
        .unwrap();
        let names = ["a".to_string()];
        let thermo = crate::testing::binary_package();
        let law = OutflowLaw::build(&v, &mut BuildCx::new(&names, &thermo, "u"), "outflow");
        assert!(matches!(law, OutflowLaw::Valve { rangeability, .. } if rangeability == 50.0));
        let liq = LiquidState { p: 2e5 + ATM, level: 0.0, mw: 0.05, v: 1e-4 };
        let flow = |op: f64| -law.outflow_residual(0.0, &liq, &[op]).unwrap_or(f64::NAN);
        assert!((flow(0.5) / flow(1.0) - 50f64.powf(-0.5)).abs() < 1e-14);
        assert!((flow(1.0) - 1e-3 * 2e5f64.sqrt() / 5e-6f64.sqrt()).abs() < 1e-12 * flow(1.0));
        assert!((flow(1.5) - flow(1.0)).abs() < 1e-15 * flow(1.0));
        assert!(matches!(serde_json::from_str(r#"{"type": "flow", "flow": "1 kmol/min"}"#), Ok(Outflow::Flow { .. })));
        assert!(matches!(serde_json::from_str(r#"{"type": "free"}"#), Ok(Outflow::Free {})));
        assert!(serde_json::from_str::<Outflow>(r#"{"type": "flow", "flow": 1, "cv": 2}"#).is_err());
    }
}
