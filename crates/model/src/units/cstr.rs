//! Liquid-phase CSTR: a perfectly mixed liquid holdup with reactions, cooled by a jacket or given a
//! duty.
//!
//! Ports: inlet `in`, outlet `out`. Inputs: `P` [Pa] (vessel pressure, default 1 atm); `duty` [W]
//! (no jacket; default 0) or `coolant_flow` [kg/s] and `coolant_T` [K] (jacket); and the outflow
//! law's input (`opening` [-] or `outflow` [mol/s]; see [`super::outflow`]).
//!
//! Variables: the outlet stream `[F, T, P, h, x…]`, then `N[c]` [mol] (differential), `U` [J]
//! (differential), `Tj` [K] (jacket temperature, differential, jacket only), `M` [mol], `level` [m],
//! `V` [m³] (liquid volume), `Q` [W] (heat into the reactor) and `rate[k]` [mol/(m³·s)], k = 1…R.
//!
//! Equations, with `ν_ik` the stoichiometric coefficients (negative for reactants):
//! - `dN_i/dt = F_in z_in,i − F x_i + V Σ_k ν_ik r_k` [mol/s];
//! - `dU/dt = F_in h_in − F h + Q − V Σ_k Δh_k r_k` [W];
//! - `r_k = k0_k exp(−Ea_k/(R T)) Π_i C_i^o_ik` [mol/(m³·s)], `C_i = N_i/V` [mol/m³]; integer orders
//!   are integer powers, a non-integer order gives `C^o` for `C > 0` and 0 otherwise;
//! - `U = M h_L(T, x)` [J] (gives `T`), `h = h_L(T, x)` [J/mol];
//! - the holdup equations `M = Σ N_i`, `x_i M = N_i`, `V = M v_L(T, x)`, `A · level = V`, the
//!   outflow law for `F` [mol/s] and the outlet pressure [Pa] (see [`super::outflow`]);
//! - jacket (perfectly mixed coolant of holdup `ρ_c V_j` [kg]):
//!   `dTj/dt = (F_c c_p (T_c,in − Tj) + UA (T − Tj)) / (ρ_c V_j c_p)` [K/s] and `Q = UA (Tj − T)`
//!   [W]; without a jacket `Q = duty`.
//!
//! Enthalpy basis: the thermodynamic package's molar enthalpies are sensible (ideal gas at
//! 298.15 K as datum, no enthalpies of formation), so a reaction releases no heat through them and
//! its heat appears explicitly as `−V Σ_k Δh_k r_k`. `Δh_k` [J/mol of extent, negative when
//! exothermic] is then the heat of reaction *beyond* what the component enthalpies carry: the
//! reaction enthalpy at `T` is `Δh_k + Σ_i ν_ik h_L,i(T)`, which is `Δh_k` when the components share
//! their enthalpy function (e.g. isomers in a constant-cp model).

use crate::capability::{Booking, Duty, DutySource, MaterialFlows, Shape};
use std::collections::BTreeMap;

use num_dual::Dual64;
use plantwide_thermo::R_GAS;
use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::Phase;
use super::outflow::{ATM, Holdup, LiquidState, Outflow, OutflowLaw, normalized};
use crate::stream::{H, T, Z0};
use crate::{BuildCx, FieldError, InputSpec, Scalar, Stream, UnitIo, UnitModel, VarSpec};

/// One reaction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ReactionConfig {
    /// Stoichiometric coefficients [-] by component, negative for reactants (`{"A": -1, "B": 1}`).
    pub stoichiometry: BTreeMap<String, f64>,
    /// Pre-exponential factor [1/s·(m³/mol)^(n−1)], `n` the total order (e.g. `"0.5 1/min"`, or
    /// `"1e-3 m3/(mol*s)"` for second order; a non-integer total order needs a bare SI number).
    pub k0: QuantityValue,
    /// Activation energy [J/mol] (e.g. `"60 kJ/mol"`; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ea: Option<QuantityValue>,
    /// Reaction orders [-] by component; default `−ν` for reactants, 0 for products. When given,
    /// unlisted components have order 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orders: Option<BTreeMap<String, f64>>,
    /// Heat of reaction [J/mol of extent], negative when exothermic (e.g. `"-50 kJ/mol"`; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dh: Option<QuantityValue>,
}

/// A perfectly mixed cooling jacket.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct JacketConfig {
    /// Heat-transfer coefficient times area [W/K] (e.g. `"50 kW/K"`).
    pub ua: QuantityValue,
    /// Coolant holdup volume [m³] (e.g. `"0.2 m3"`).
    pub volume: QuantityValue,
    /// Coolant mass flow [kg/s] (input `coolant_flow`; e.g. `"5 kg/s"`).
    pub coolant_flow: QuantityValue,
    /// Coolant inlet temperature [K] (input `coolant_T`; e.g. `"25 degC"`).
    #[serde(rename = "coolant_T")]
    pub coolant_t: QuantityValue,
    /// Coolant heat capacity [J/(kg·K)] (default 4184).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cp: Option<QuantityValue>,
    /// Coolant density [kg/m³] (default 1000).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rho: Option<QuantityValue>,
}

/// Flowsheet description of a CSTR; give exactly one of `diameter` and `area`, and at most one of
/// `jacket` and `duty`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CstrConfig {
    /// Diameter [m] of a vertical cylinder (e.g. `"1.5 m"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diameter: Option<QuantityValue>,
    /// Cross-sectional area [m²] (e.g. `"2 m2"`), instead of `diameter`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub area: Option<QuantityValue>,
    /// Height [m]; the default level guess is half of it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<QuantityValue>,
    /// Vessel pressure [Pa] (input `P`; default 1 atm).
    #[serde(rename = "P", default, skip_serializing_if = "Option::is_none")]
    pub pressure: Option<QuantityValue>,
    /// Liquid outflow law.
    pub outflow: Outflow,
    /// Reactions (may be empty).
    #[serde(default)]
    pub reactions: Vec<ReactionConfig>,
    /// Cooling jacket.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jacket: Option<JacketConfig>,
    /// Heat input [W] without a jacket (input `duty`; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duty: Option<QuantityValue>,
    /// Initial level guess [m] (default: the valve's steady level, else half the height, else 1 m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub level: Option<QuantityValue>,
    /// Initial temperature guess [K] (default: the energy balance without reaction). An exothermic
    /// reactor can have several steady states; give the operating temperature (e.g. `"350 K"`) so that
    /// Newton starts on the intended (usually the hot, temperature-controlled) branch.
    #[serde(rename = "T_guess", default, skip_serializing_if = "Option::is_none")]
    pub t_guess: Option<QuantityValue>,
}

impl crate::registry::UnitConfig for CstrConfig {
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

#[derive(Debug, Clone)]
struct Reaction {
    nu: Vec<f64>,
    k0: f64,
    ea: f64,
    orders: Vec<f64>,
    dh: f64,
}

#[derive(Debug, Clone)]
struct Jacket {
    ua: f64,
    volume: f64,
    flow: f64,
    t_in: f64,
    cp: f64,
    rho: f64,
}

/// A liquid-phase CSTR.
#[derive(Debug, Clone)]
pub struct Cstr {
    holdup: Holdup,
    pressure: f64,
    duty: f64,
    law: OutflowLaw,
    reactions: Vec<Reaction>,
    jacket: Option<Jacket>,
    t_guess: Option<f64>,
}

/// The largest magnitude of a reaction's order in one component.
const MAX_ORDER: f64 = 20.0;

fn by_component(cx: &mut BuildCx<'_>, field: &str, map: &BTreeMap<String, f64>) -> Vec<f64> {
    let mut v = vec![0.0; cx.components.len()];
    for (name, &c) in map {
        match cx.components.iter().position(|n| n == name) {
            Some(i) if c.is_finite() => v[i] = c,
            Some(_) => cx.error(&format!("{field}.{name}"), format!("must be a finite number (got {c})")),
            None => cx.error(
                &format!("{field}.{name}"),
                format!("`{name}` is not a component of this flowsheet (components: {})", cx.components.join(", ")),
            ),
        }
    }
    v
}

fn build_reaction(cx: &mut BuildCx<'_>, f: &str, c: &ReactionConfig) -> Reaction {
    let nu = by_component(cx, &format!("{f}.stoichiometry"), &c.stoichiometry);
    if nu.iter().all(|v| *v == 0.0) {
        cx.error(&format!("{f}.stoichiometry"), "give at least one non-zero coefficient (negative for reactants)");
    }
    // Σ_i ν_i·MW_i = 0: a reaction creates no mass (to 1e-6 of its largest term).
    let terms: Vec<f64> = nu.iter().zip(&cx.thermo.components).map(|(v, c)| v * c.mw).collect();
    let (net, big) = (terms.iter().sum::<f64>(), terms.iter().fold(0.0_f64, |a, t| a.max(t.abs())));
    if net.abs() > 1e-6 * big {
        cx.error(
            &format!("{f}.stoichiometry"),
            format!(
                "the reaction does not conserve mass: Σ ν·MW = {net:.6e} kg/mol (the products weigh {} of the reactants); adjust the coefficients or the components' molar masses",
                crate::limits::number(1.0 + net / terms.iter().filter(|t| **t < 0.0).map(|t| -t).sum::<f64>().max(1e-300))
            ),
        );
    }
    let orders = match &c.orders {
        Some(o) => by_component(cx, &format!("{f}.orders"), o),
        None => nu.iter().map(|v| (-v).max(0.0)).collect(),
    };
    if let Some(i) = orders.iter().position(|o| o.is_nan() || o.abs() > MAX_ORDER) {
        let order = crate::limits::number(orders[i]);
        let field = format!("{f}.orders.{}", cx.components[i]);
        cx.error(&field, format!("an order of {order} is beyond ±{MAX_ORDER}, where no rate law lies"));
    }
    let (n, fk0): (f64, String) = (orders.iter().sum(), format!("{f}.k0"));
    let whole = n.fract() == 0.0 && n.abs() <= MAX_ORDER * orders.len() as f64;
    let dim = whole.then(|| (Dimension::VOLUME / Dimension::AMOUNT).checked_pow(n as i32 - 1)).flatten();
    let k0 = match (dim, &c.k0) {
        (Some(d), q) => cx.non_negative(&fk0, q, Dimension::INVERSE_TIME * d),
        (None, q @ QuantityValue::Number(_)) => cx.non_negative(&fk0, q, Dimension::DIMENSIONLESS),
        (None, _) => {
            cx.error(
                &fk0,
                format!(
                    "the total order {} is not an integer: give k0 as a bare number in SI units",
                    crate::limits::number(n)
                ),
            );
            f64::NAN
        }
    };
    let ea = c.ea.as_ref().map_or(0.0, |e| cx.quantity(&format!("{f}.ea"), e, Dimension::MOLAR_ENERGY));
    let dh = c.dh.as_ref().map_or(0.0, |e| cx.quantity(&format!("{f}.dh"), e, Dimension::MOLAR_ENERGY));
    Reaction { nu, k0, ea, orders, dh }
}

impl Cstr {
    /// Build from the flowsheet description.
    pub fn build(c: &CstrConfig, mut cx: BuildCx<'_>, _links: ()) -> Result<Cstr, Vec<FieldError>> {
        let holdup = Holdup::build(&mut cx, c.diameter.as_ref(), c.area.as_ref(), c.height.as_ref(), c.level.as_ref());
        let pressure = c.pressure.as_ref().map_or(ATM, |p| cx.positive("P", p, Dimension::PRESSURE));
        let law = OutflowLaw::build(&c.outflow, &mut cx, "outflow");
        if !cx.count("reactions", c.reactions.len(), crate::limits::Limits::get().reactions()) {
            return Err(cx.errors);
        }
        let reactions = c
            .reactions
            .iter()
            .enumerate()
            .map(|(k, r)| build_reaction(&mut cx, &format!("reactions[{k}]"), r))
            .collect();
        let duty = c.duty.as_ref().map_or(0.0, |q| cx.quantity("duty", q, Dimension::POWER));
        let jacket = c.jacket.as_ref().map(|j| Jacket {
            ua: cx.non_negative("jacket.ua", &j.ua, Dimension::UA),
            volume: cx.positive("jacket.volume", &j.volume, Dimension::VOLUME),
            flow: cx.non_negative("jacket.coolant_flow", &j.coolant_flow, Dimension::MASS_FLOW),
            t_in: cx.positive("jacket.coolant_T", &j.coolant_t, Dimension::TEMPERATURE),
            cp: j.cp.as_ref().map_or(4184.0, |v| cx.positive("jacket.cp", v, Dimension::HEAT_CAPACITY_MASS)),
            rho: j.rho.as_ref().map_or(1000.0, |v| cx.positive("jacket.rho", v, Dimension::DENSITY_MASS)),
        });
        if jacket.is_some() && c.duty.is_some() {
            cx.error("duty", "give either `jacket` or `duty`, not both");
        }
        let t_guess = c.t_guess.as_ref().map(|t| cx.positive("T_guess", t, Dimension::TEMPERATURE));
        cx.finish(Cstr { holdup, pressure, duty, law, reactions, jacket, t_guess })
    }
    /// Inputs before the outflow law's: `P`, then `duty` or `coolant_flow`, `coolant_T`.
    fn n_fixed_inputs(&self) -> usize {
        if self.jacket.is_some() { 3 } else { 2 }
    }
    /// Index of `M` among the internal variables (`N[c]`, `U`, `Tj`?, `M`, `level`, `V`, `Q`, `rate[k]`).
    fn i_m(&self, nc: usize) -> usize {
        nc + 1 + usize::from(self.jacket.is_some())
    }
    /// Outlet composition for a guess: the component balances `F_in z_i − F x_i + V Σ_k ν_ik r_k = 0`
    /// for outflow `f` [mol/s] at temperature `t` [K] and `mlv = [M, level, V]` ([mol], [m], [m³]),
    /// by the positive iteration `x_i ← (F_in z_i + V·made_i) / (F + V·used_i/x_i)` (production
    /// explicit, consumption implicit; exact in one step for a first-order reactant), normalised.
    /// Starts from the inlet composition.
    fn reacted_composition(&self, inlet: Stream<'_, f64>, f: f64, t: f64, mlv: [f64; 3]) -> Vec<f64> {
        let (f_in, z_in, m, vol) = (inlet.f(), inlet.z(), mlv[0], mlv[2]);
        let mut x = normalized(z_in);
        if self.reactions.is_empty() || !(f > 0.0 && m > 0.0 && vol > 0.0) {
            return x;
        }
        for _ in 0..30 {
            let c: Vec<f64> = x.iter().map(|xi| xi * m / vol).collect();
            let rates: Vec<f64> = self.reactions.iter().map(|rx| Self::rate(rx, t, &c)).collect();
            let next: Vec<f64> = (0..x.len())
                .map(|i| {
                    let (mut made, mut used) = (0.0, 0.0);
                    for (rx, rk) in self.reactions.iter().zip(&rates) {
                        if rx.nu[i] > 0.0 { made += rx.nu[i] * rk } else { used -= rx.nu[i] * rk }
                    }
                    let sink = if x[i] > 0.0 { vol * used / x[i] } else { 0.0 };
                    (f_in * z_in[i] + vol * made) / (f + sink)
                })
                .collect();
            if next.iter().any(|v| !v.is_finite()) {
                break;
            }
            x = normalized(&next);
        }
        x
    }
    /// Rate [mol/(m³·s)] of `r` at `t` [K] and concentrations `c` [mol/m³].
    fn rate<S: Scalar>(r: &Reaction, t: S, c: &[S]) -> S {
        let mut v = (t.recip() * (-r.ea / R_GAS)).exp() * r.k0;
        for (ci, &o) in c.iter().zip(&r.orders) {
            if o == 0.0 {
                continue;
            } else if o.fract() == 0.0 && o.abs() < 64.0 {
                v *= ci.powi(o as i32);
            } else if ci.re() > 0.0 {
                v *= ci.powf(o);
            } else {
                return S::from(0.0);
            }
        }
        v
    }
}

impl UnitModel for Cstr {
    fn type_name(&self) -> &'static str {
        "cstr"
    }
    fn shape(&self) -> Shape {
        Shape::Vessel
    }
    /// The liquid, filled by `in` and drained by `out` under the outflow law.
    fn material_flows(&self) -> MaterialFlows {
        MaterialFlows::vessel(&["in"], vec![("out", self.law.flow_law())])
    }
    /// The jacket's `Q` \[W\], heating when positive.
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
        let mut v = self.holdup.component_vars();
        v.push(VarSpec::differential("U", Dimension::ENERGY, self.holdup.m_nominal * 3e4));
        if self.jacket.is_some() {
            v.push(VarSpec::differential("Tj", Dimension::TEMPERATURE, 300.0).bounded(1.0, 5000.0));
        }
        v.extend(self.holdup.volume_vars());
        v.push(VarSpec::algebraic("Q", Dimension::POWER, 1e5));
        let rate = |k| VarSpec::algebraic(format!("rate[{k}]"), Dimension::REACTION_RATE, 1.0);
        v.extend((1..=self.reactions.len()).map(rate));
        v
    }
    fn inputs(&self) -> Vec<InputSpec> {
        let mut v = vec![InputSpec { name: "P".into(), dim: Dimension::PRESSURE, value: self.pressure }];
        match &self.jacket {
            Some(j) => {
                v.push(InputSpec { name: "coolant_flow".into(), dim: Dimension::MASS_FLOW, value: j.flow });
                v.push(InputSpec { name: "coolant_T".into(), dim: Dimension::TEMPERATURE, value: j.t_in });
            }
            None => v.push(InputSpec { name: "duty".into(), dim: Dimension::POWER, value: self.duty }),
        }
        v.extend(self.law.inputs());
        v
    }
    fn extra_equations(&self) -> isize {
        self.law.extra_equations()
    }
    fn holdup(&self, io: &UnitIo<'_, f64>) -> Option<Vec<f64>> {
        Some(io.vars(0, io.n_comp()).to_vec())
    }
    fn reacts(&self) -> bool {
        !self.reactions.is_empty()
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let (nc, len) = (io.n_comp(), io.layout.stream.len());
        let (out, inlet) = (io.outlet(0), io.inlet(0));
        let im = self.i_m(nc);
        let (n, u, mlv, q) = (io.vars(0, nc), io.var(nc), io.vars(im, 3), io.var(im + 3));
        let rates = io.vars(im + 4, self.reactions.len());
        let (x, t, vol) = (out.z(), out.t(), mlv[2]);
        let (hl, vl) = (io.thermo.h_liq(t, x), io.thermo.v_liq(t, x));
        let mut res = vec![S::from(0.0); io.layout.n_own()];
        for i in 0..nc {
            let made = self.reactions.iter().zip(rates).fold(S::from(0.0), |a, (rx, rk)| a + *rk * rx.nu[i]);
            res[len + i] = inlet.f() * inlet.z()[i] - out.f() * x[i] + vol * made;
        }
        let heat = self.reactions.iter().zip(rates).fold(S::from(0.0), |a, (rx, rk)| a + *rk * rx.dh);
        res[len + nc] = inlet.f() * inlet.h() - out.f() * out.h() + q - vol * heat;
        self.holdup.residuals(n, x, mlv, vl, &mut res, (Z0, len + im));
        res[len + im + 3] = match &self.jacket {
            Some(j) => {
                let (tj, fc, tc) = (io.var(nc + 1), io.input(1), io.input(2));
                res[len + nc + 1] = ((tc - tj) * fc * j.cp + (t - tj) * j.ua) / (j.rho * j.volume * j.cp);
                q - (tj - t) * j.ua
            }
            None => q - io.input(1),
        };
        let c: Vec<S> = n.iter().map(|ni| *ni / vol).collect();
        for (k, (rx, rk)) in self.reactions.iter().zip(rates).enumerate() {
            res[len + im + 4 + k] = *rk - Self::rate(rx, t, &c);
        }
        res[T] = u - mlv[0] * hl;
        res[H] = out.h() - hl;
        let liq = LiquidState { p: io.input(0), level: mlv[1], mw: io.thermo.mw(x), v: vl };
        self.law.close(io, 0, self.n_fixed_inputs(), &liq, res, r);
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let (nc, len) = (io.n_comp(), io.layout.stream.len());
        let inlet = io.inlet(0);
        let x = normalized(inlet.z());
        let (f, op) = self.law.guess_flow(io, self.n_fixed_inputs(), inlet.f());
        // The given temperature, else the energy balance without reaction:
        // F_in (h_L(T) − h_in) = UA_eff (T_c − T), or = duty.
        let (t, tj, q) = match &self.jacket {
            Some(j) => {
                let (fcp, tc) = (io.input(1) * j.cp, io.input(2));
                let ua_eff = if fcp + j.ua > 0.0 { j.ua * fcp / (fcp + j.ua) } else { 0.0 };
                // One Newton step from the inlet temperature (exact for a constant heat capacity).
                let xd: Vec<Dual64> = x.iter().map(|&v| v.into()).collect();
                let td = Dual64::new(inlet.t(), 1.0);
                let g = (io.thermo.h_liq(td, &xd) - inlet.h()) * inlet.f() + (td - tc) * ua_eff;
                let t_balance =
                    if g.eps > 0.0 { (td.re - g.re / g.eps).clamp(0.5 * td.re, 2.0 * td.re) } else { td.re };
                let t = self.t_guess.unwrap_or(t_balance);
                let tj = if fcp + j.ua > 0.0 { (fcp * tc + j.ua * t) / (fcp + j.ua) } else { t };
                (t, tj, j.ua * (tj - t))
            }
            None => {
                let h = if inlet.f() > 0.0 { inlet.h() + io.input(1) / inlet.f() } else { inlet.h() };
                let t =
                    self.t_guess.unwrap_or_else(|| Phase::Liquid.temperature(io.thermo, h, inlet.p(), &x, inlet.t()));
                (t, 0.0, io.input(1))
            }
        };
        let mut liq = LiquidState { p: io.input(0), level: 0.0, mw: io.thermo.mw(&x), v: io.thermo.v_liq(t, &x) };
        let mlv = self.holdup.guess(&self.law, f, op, &liq);
        liq.level = mlv[1];
        let x = self.reacted_composition(inlet, f, t, mlv);
        let h = io.thermo.h_liq(t, &x);
        own[..Z0].copy_from_slice(&[f, t, self.law.outlet_pressure(&liq), h]);
        own[Z0..len].copy_from_slice(&x);
        (0..nc).for_each(|i| own[len + i] = mlv[0] * x[i]);
        own[len + nc] = mlv[0] * h;
        let im = len + self.i_m(nc);
        if self.jacket.is_some() {
            own[len + nc + 1] = tj;
        }
        own[im..im + 3].copy_from_slice(&mlv);
        own[im + 3] = q;
        let c: Vec<f64> = x.iter().map(|xi| xi / liq.v).collect();
        for (k, rx) in self.reactions.iter().enumerate() {
            own[im + 4 + k] = Self::rate(rx, t, &c);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::outflow::test_support::{Lcg, at_guess, build_unit, solve_own, worst_jacobian_error};
    use super::*;

    /// The binary test package with `heavy` an isomer of `light` (both 50 g/mol), so that the test
    /// reactions conserve mass.
    fn binary_package() -> plantwide_thermo::ThermoPackage {
        let mut p = crate::testing::binary_package();
        p.components[1].mw = p.components[0].mw;
        p
    }

    const ISO: &str = r#"{"area": 1, "outflow": {"type": "valve", "cv": 5e-4, "opening": 0.8},
        "reactions": [{"stoichiometry": {"light": -1, "heavy": 1}, "k0": "0.3 1/min", "dh": "-40 kJ/mol"}], "duty": "-300 kW"}"#;
    const JACKET: &str = r#"{"diameter": "1.2 m", "height": "2 m", "outflow": {"type": "valve", "cv": 5e-4, "opening": 0.6, "characteristic": "equal_percentage"},
        "reactions": [{"stoichiometry": {"light": -2, "heavy": 2}, "k0": 0.2, "ea": "40 kJ/mol", "dh": "-30 kJ/mol"},
                      {"stoichiometry": {"heavy": -1, "light": 1}, "orders": {"heavy": 1.5}, "k0": 5e2, "ea": "50 kJ/mol", "dh": "10 kJ/mol"}],
        "jacket": {"ua": "40 kW/K", "volume": "0.3 m3", "coolant_flow": "4 kg/s", "coolant_T": "30 degC"}}"#;
    const FLOW: &str = r#"{"area": 1, "outflow": {"type": "flow", "flow": 8}, "reactions": [{"stoichiometry": {"light": -1, "heavy": 1}, "k0": 1e-3}]}"#;
    const FREE: &str = r#"{"area": 1, "outflow": {"type": "free"}, "jacket": {"ua": 1e4, "volume": 0.1, "coolant_flow": 1, "coolant_T": 300}}"#;

    /// Pure `light` (A) feed, 10 mol/s, liquid at 310 K.
    fn feed(thermo: &plantwide_thermo::ThermoPackage) -> [f64; 6] {
        [10.0, 310.0, 2e5, thermo.h_liq(310.0, &[1.0, 0.0]), 1.0, 0.0]
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let thermo = binary_package();
        let mut rng = Lcg(17);
        for json in [ISO, JACKET, FLOW, FREE] {
            let u = build_unit(json, &thermo, Cstr::build);
            let worst = worst_jacobian_error(&u, &thermo, &feed(&thermo), &mut rng, 0.2);
            eprintln!("cstr jacobian_error {worst:.2e}: {json}");
            assert!(worst < 1e-6, "{json}: {worst}");
        }
    }

    #[test]
    fn steady_state_balances_and_first_order_conversion() {
        let thermo = binary_package();
        for json in [ISO, JACKET] {
            let u = build_unit(json, &thermo, Cstr::build);
            let (lay, mut local) = at_guess(&u, &thermo, &feed(&thermo));
            let norm = solve_own(&u, &lay, &thermo, &mut local);
            assert!(norm < 1e-12, "{norm}");
            let io = UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 };
            let (out, inlet) = (io.outlet(0), io.inlet(0));
            let im = u.i_m(2);
            let (vol, q) = (io.var(im + 2), io.var(im + 3));
            let rates = io.vars(im + 4, u.reactions.len());
            let mut worst_c: f64 = 0.0;
            for i in 0..2 {
                let prod: f64 = u.reactions.iter().zip(rates).map(|(rx, r)| rx.nu[i] * r * vol).sum();
                worst_c = worst_c.max((inlet.f() * inlet.z()[i] + prod - out.f() * out.z()[i]).abs() / inlet.f());
            }
            let heat: f64 = u.reactions.iter().zip(rates).map(|(rx, r)| rx.dh * r * vol).sum();
            let e_in = inlet.f() * inlet.h() + q - heat;
            let worst_e = (e_in - out.f() * thermo.h_liq(out.t(), out.z())).abs() / e_in.abs().max(heat.abs());
            eprintln!(
                "cstr T {:.3} K, Q {q:.1} W, rates {rates:?}: component {worst_c:.1e}, energy {worst_e:.1e}",
                out.t()
            );
            assert!(worst_c < 1e-12 && worst_e < 1e-9);
            if let Some(j) = &u.jacket {
                let tj = io.var(3);
                let jac = (io.input(2) - tj) * io.input(1) * j.cp + (out.t() - tj) * j.ua;
                assert!(jac.abs() < 1e-9 * j.ua * out.t(), "{jac}");
            } else {
                // First order, Ea = 0, equal molar volumes: X = kτ/(1 + kτ), τ = V/(F v_L).
                let k = 0.3 / 60.0;
                let tau = vol / (out.f() * thermo.v_liq(out.t(), out.z()));
                let x = 1.0 - out.f() * out.z()[0] / inlet.f();
                let exact = k * tau / (1.0 + k * tau);
                eprintln!("cstr conversion {x:.12} vs kτ/(1+kτ) {exact:.12} (τ = {tau:.3} s)");
                assert!((x - exact).abs() < 1e-9, "{x} vs {exact}");
            }
        }
    }

    #[test]
    fn a_reaction_that_creates_mass_is_refused() {
        // light (50 g/mol) → heavy (80 g/mol): the products would weigh 1.6 times the reactants.
        let thermo = crate::testing::binary_package();
        let names = ["light".to_string(), "heavy".to_string()];
        let c: CstrConfig = serde_json::from_str(ISO).unwrap();
        let errs = Cstr::build(&c, BuildCx::new(&names, &thermo, "units.r"), ()).unwrap_err();
        assert_eq!(errs[0].path, "units.r.reactions[0].stoichiometry");
        assert!(errs[0].message.contains("does not conserve mass") && errs[0].message.contains("1.6 of"), "{errs:?}");
    }

    #[test]
    fn build_errors_and_variables() {
        let thermo = binary_package();
        let names = ["light".to_string(), "heavy".to_string()];
        let bad: CstrConfig = serde_json::from_str(
            r#"{"area": 1, "outflow": {"type": "free"}, "duty": 1, "jacket": {"ua": 1, "volume": 1, "coolant_flow": 1, "coolant_T": 300},
            "reactions": [{"stoichiometry": {"C": -1}, "k0": "1 1/s", "orders": {"light": 0.5}}]}"#,
        )
        .unwrap();
        let errs = Cstr::build(&bad, BuildCx::new(&names, &thermo, "units.r"), ()).unwrap_err();
        let paths: Vec<&str> = errs.iter().map(|e| e.path.as_str()).collect();
        assert_eq!(
            paths,
            [
                "units.r.reactions[0].stoichiometry.C",
                "units.r.reactions[0].stoichiometry",
                "units.r.reactions[0].k0",
                "units.r.duty"
            ]
        );
        let u = build_unit(JACKET, &thermo, Cstr::build);
        let vars: Vec<String> = UnitModel::internal_vars(&u).into_iter().map(|v| v.name).collect();
        assert_eq!(vars, ["N[light]", "N[heavy]", "U", "Tj", "M", "level", "V", "Q", "rate[1]", "rate[2]"]);
        let inputs: Vec<String> = UnitModel::inputs(&u).into_iter().map(|v| v.name).collect();
        assert_eq!(inputs, ["P", "coolant_flow", "coolant_T", "opening"]);
    }
}
