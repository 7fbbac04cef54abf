//! The rigorous column model: component, total and energy balances per stage, VLE from the thermo
//! package (activity coefficients allowed), Murphree vapour efficiency, Francis-weir tray hydraulics
//! and a fixed tray pressure drop — Grassi's model 2a (Luyben (ed.) 1992, ch. 3).
//!
//! **Stages** as in [`super`]: 1 = reboiler (sump, an equilibrium stage heated by the input
//! `reboiler_duty`, or by steam, below), 2 … N−1 = trays from the bottom, N = condenser with its
//! reflux drum (total, or partial with a vapour distillate).
//! Pressures are fixed: `P_i = P + (N − i) ΔP` [Pa], `P` the top (drum) pressure and `ΔP` the
//! pressure drop per tray (`rigorous.tray_pressure_drop`, default 0).
//!
//! # Variables
//! Per stage i: `n[i][c]` [mol] component holdups (differential), `x[i][c]`, `y[i][c]` [-], `T[i]`
//! [K], `M[i]` [mol], `L[i]`, `V[i]` [mol/s] (liquid and vapour leaving the stage); then `Qc` [W],
//! the heat removed in the condenser. Inputs: `reflux` L_N, `reboiler_duty` Q_R [W] (or
//! `steam_flow` m_s [kg/s]), `distillate` D, `bottoms` B [mol/s], `condenser_duty` Q_C [W]
//! (duty-specified condenser only) or `coolant_flow` m_c [kg/s] (water-cooled condenser only), and
//! each side draw's flow [mol/s].
//!
//! # Equations (stage i; `h_L,i = h_liq(T_i, x_i)`, `h_V,i = h_vap(T_i, y_i)` [J/mol])
//! - component balances `dn_ij/dt = L_{i+1} x_{i+1,j} + V_{i−1} y_{i−1,j} + Σ_feeds F z_j
//!   − (L_i + S_i + D δ_iN) x_ij − (V_i + S^V_i) y_ij` (S_i liquid, S^V_i vapour side draws; the
//!   `D δ_iN` term for a total condenser only);
//! - holdup `M_i = Σ_j n_ij`, `x_ij M_i = n_ij`;
//! - bubble point `Σ_j K_ij(T_i, P_i, x_i) x_ij = 1` (the liquid is saturated on every stage);
//! - vapour: reboiler and drum `y_ij = K_ij x_ij`; trays, Murphree vapour efficiency E,
//!   `y_ij = y_{i−1,j} + E (K_ij x_ij − y_{i−1,j})`;
//! - liquid: trays, Francis weir on the clear liquid,
//!   `L_i = 1.84 l_w ĥ_ow^{3/2} / v_L` with `ĥ_ow = smax(M_i v_L / A − h_w)` [m],
//!   `v_L = v_liq(T_i, x_i)` [m³/mol], `l_w`, `h_w`, `A` the weir length, weir height and tray
//!   area ([`Weir`]); drum `L_N = reflux`; reboiler `L_1 = B`;
//! - energy (quasi-steady, below), giving `V_i` on the reboiler and trays and `Qc` (drum at its
//!   bubble point) or `T_N` (duty-specified or water-cooled condenser); a total condenser's drum
//!   sends no vapour on, `V_N = 0`, and its `y_N = K x_N` is the equilibrium vapour of the drum
//!   liquid; a partial condenser's vapour is the distillate, `V_N = D`;
//! - products: distillate, bottoms and liquid draws carry `(T_i, P_i, x_i, h_L,i)` of their stage,
//!   a partial condenser's distillate and vapour draws `(T_i, P_i, y_i, h_V,i)`.
//!
//! # Energy balance and why the model is index 1
//! The stage energy balance is
//! `d(M_i h_L,i)/dt = Σ_in F h − (L_i + S_i + D δ_iN) h_L,i − (V_i + S^V_i) h_V,i + Q_i`
//! with `Q_1 = Q_R`, `Q_N = −Qc`. At fixed pressure the liquid sits at its bubble point, so
//! `h_L,i` is a function of `x_i`: `U = M h_L` is not an independent state. Model 2a neglects the
//! specific-enthalpy accumulation, `M_i dh_L,i/dt ≈ 0`; subtracting `h_L,i` times the total
//! balance then leaves the algebraic equation
//!
//! `0 = Σ_in F (h_in − h_L,i) + Q_i − (V_i + S^V_i) (h_V,i − h_L,i)`,
//!
//! in which the liquid outflows drop out. Given the differential states `n`, the algebraic
//! variables follow in order — `M, x` (holdup), `T` (bubble point), `y` (equilibrium or Murphree,
//! from the stage below), `L` (weir), then `V_i` from the energy balance sweeping up from the
//! reboiler (its coefficient `h_V,i − h_L,i`, the latent heat, is nonzero) — so the algebraic
//! Jacobian is nonsingular: index 1. Keeping `M h_L` as a differential state instead would
//! over-determine `T` (energy and bubble point) and make the system index 2. At steady state the
//! total balance vanishes and the equation is the exact energy balance, so steady states close
//! energy to solver precision: `Q_R + Σ F h_F = Qc + D h_D + B h_B + Σ S h_S`.
//!
//! A duty-specified condenser (`condenser_duty` given) returns a subcooled reflux: its energy
//! balance `V_{N−1} (h_V,N−1 − h_L,N) = Q_C` fixes `T_N` (the heated-tank case of ch. 3, index 1).
//! At fixed pressure the duty has a narrow window: at least the bubble-point duty (below it the
//! "liquid" would be superheated), and at most what the subcooled reflux allows — the colder the
//! reflux, the more vapour it condenses on the top tray, so the less reaches the condenser;
//! outside the window there is no steady state.
//!
//! **Steam reboiler** (`rigorous.reboiler = {"steam_flow", "steam_latent_heat"}` instead of
//! `reboiler_duty`): the input is the steam flow m_s [kg/s] (`steam_flow`), and the reboiler duty
//! is the heat the saturated steam gives up condensing, `Q_R = m_s λ_s` [W] with λ_s [J/kg]; the
//! column equations are otherwise unchanged, so a steam flow `Q_R / λ_s` gives the steady state of
//! the duty-specified reboiler.
//!
//! **Water-cooled condenser** (`rigorous.condenser = {"coolant_flow", "coolant_T_in", "ua", "cp"}`
//! instead of `condenser_duty`): the drum is the duty-specified one (its energy balance fixes
//! `T_N`), with the duty taken up by the coolant, input `coolant_flow` m_c [kg/s], entering at
//! `T_in` [K]: `Qc = m_c c_p (T_c,out − T_in) = UA ΔT_lm` against the isothermal drum at `T_N`,
//! which solves to `Qc = m_c c_p (T_N − T_in) (1 − exp(−UA / (m_c c_p)))` [W] (UA [W/K], c_p
//! [J/(kg K)], default 4184). The duty window above applies: too little coolant for the
//! bubble-point duty has no steady state.
//!
//! **Auxiliary reboiler and condenser** (`rigorous.auxiliary_reboiler_duty` Q_aux,R,
//! `rigorous.auxiliary_condenser_duty` Q_aux,C [W], inputs of those names): a second heat source on
//! the reboiler and a second heat sink on the condenser, for a column whose `reboiler_duty` or
//! `condenser_duty` another unit sets (a condenser–reboiler coupling it to another column): the
//! reboiler receives `Q_R + Q_aux,R` and the condenser removes `Qc = Q_C + Q_aux,C` (with a
//! coolant, `Qc` = the coolant's duty + Q_aux,C). The auxiliary condenser needs a condenser whose
//! duty is an input.
//!
//! **Partial condenser** (`rigorous.condenser_type = "partial"`): the drum liquid (the reflux) is
//! at its bubble point, the distillate is its equilibrium vapour, `D = V_N` with `y_D = y_N =
//! K(T_N, P_N, x_N) x_N` and `h_D = h_V,N`, and the drum energy balance gives
//! `Qc = V_{N−1} h_V,N−1 − L_N h_L,N − D h_V,N + Σ F h_F` (written relative to `h_L,N` as above).
//!
//! **Vapour side draws** (`side_draws[k].phase = "vapour"`, trays only): the draw S^V_i is part of
//! the vapour leaving tray i, at its `y_i` and `h_V,i`; `V_i` is what goes on to tray i + 1.
//!
//! Not modelled: partial condensers with a specified duty or coolant, froth density, downcomer
//! holdup.
//!
//! # Initial guess
//! The bubble-point (Wang–Henke) method solves the steady column at the current inputs `reflux`
//! and `reboiler_duty` (D and B follow from the balances); Newton on the column's own equations,
//! with a pseudo-transient fallback, finishes it. See [`profile`] and [`polish`].
//!
//! # References
//! - V. G. Grassi II, "Rigorous modeling and conventional simulation", in W. L. Luyben (ed.),
//!   *Practical Distillation Control*, Van Nostrand Reinhold 1992, ch. 3 (model 2a, Figs 3-8, 3-10).
//! - J. C. Wang, G. E. Henke, *Tridiagonal matrix for distillation*, Hydrocarbon Processing 45(8)
//!   (1966) 155–163.

mod build;
mod polish;
mod profile;
#[cfg(test)]
mod tests;
mod weir;

use plantwide_thermo::VleModel;
use plantwide_units::Dimension;

use super::{Draw, StageIdx};
use crate::stream::{F, H, P, T, Z0};
use crate::{InputSpec, LocalLayout, Scalar, UnitIo, UnitModel, VarSpec};

pub use build::{CondenserType, CoolantCondenser, EXAMPLE, RigorousConfig, SteamReboiler};
pub use weir::{CREST_SMOOTH, FRANCIS, Weir};

/// How the condenser duty is set.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Condenser {
    /// Drum at the bubble point of its liquid; `Qc` follows from the drum energy balance.
    BubblePoint,
    /// `Qc` is the input `condenser_duty` [W] (this value its nominal); the drum energy balance
    /// gives `T_N`.
    Duty(f64),
    /// Cooling water: `Qc = m_c c_p (T_N − T_in) (1 − exp(−UA / (m_c c_p)))`, `m_c` the input
    /// `coolant_flow` [kg/s] (`flow` its nominal); the drum energy balance gives `T_N`.
    Coolant {
        /// Nominal coolant flow [kg/s].
        flow: f64,
        /// Coolant inlet temperature [K].
        t_in: f64,
        /// UA [W/K].
        ua: f64,
        /// Coolant heat capacity [J/(kg K)].
        cp: f64,
    },
}

impl Condenser {
    /// Whether the condenser declares an input (`condenser_duty` or `coolant_flow`).
    fn has_input(&self) -> bool {
        !matches!(self, Condenser::BubblePoint)
    }
}

/// Heat [W] a coolant flow `m` [kg/s] entering at `t_in` [K] with heat capacity `cp` [J/(kg K)]
/// takes from a condensing drum at `t_hot` [K] through `ua` [W/K]: the effectiveness relation of an
/// exchanger with an isothermal hot side, `m c_p (T_hot − T_in) (1 − exp(−UA / (m c_p)))`.
fn coolant_duty<S: Scalar>(m: S, t_hot: S, t_in: f64, ua: f64, cp: f64) -> S {
    let c = m * S::from(cp);
    c * (t_hot - S::from(t_in)) * (S::from(1.0) - (S::from(-ua) / c).exp())
}

/// A distillation column, rigorous model.
#[derive(Debug, Clone)]
pub struct RigorousColumn {
    n_stages: usize,
    /// Stage (0-based) of each feed.
    feeds: Vec<usize>,
    feed_ports: Vec<String>,
    draws: Vec<Draw>,
    draw_ports: Vec<String>,
    /// Stage pressures [Pa], 0-based from the reboiler.
    pressure: Vec<f64>,
    efficiency: f64,
    weir: Weir,
    m_condenser: f64,
    m_reboiler: f64,
    m_tray: f64,
    reflux: f64,
    /// Value of input 1: the reboiler duty [W], or the steam flow [kg/s] with a steam reboiler.
    reboiler_duty: f64,
    /// Latent heat of the reboiler steam λ_s [J/kg] (steam reboiler only).
    steam_latent_heat: Option<f64>,
    distillate: f64,
    bottoms: f64,
    condenser: Condenser,
    /// Partial condenser: the distillate is the drum's vapour, `V_N = D`.
    partial: bool,
    /// Auxiliary reboiler duty [W] (its input `auxiliary_reboiler_duty`), if the column has one.
    aux_reboiler: Option<f64>,
    /// Auxiliary condenser duty [W] (its input `auxiliary_condenser_duty`), if the column has one.
    aux_condenser: Option<f64>,
    /// Vapour space of condenser and drum [m³]: its component holdups `nV[c]` are states and the top
    /// pressure `P` their ideal-gas pressure at `T_N`.
    vapour_volume: Option<f64>,
    comp_names: Vec<String>,
}

// Inputs, in declaration order; `condenser_duty` (if any) follows, then the side draws.
/// What every stage's balances of one evaluation read: the flows and duties set by the inputs and
/// the stage enthalpies.
struct Shared<S> {
    /// Reflux L [mol/s].
    l_in: S,
    /// Reboiler duty Q_R [W].
    q_r: S,
    /// Distillate D [mol/s].
    d_in: S,
    /// Bottoms B [mol/s].
    b_in: S,
    /// Condenser duty Q_C [W] (a variable).
    qc: S,
    /// Side-draw flows [mol/s], in draw order.
    draw_flow: Vec<S>,
    /// Liquid enthalpy of every stage [J/mol].
    h_l: Vec<S>,
    /// Vapour enthalpy of every stage [J/mol].
    h_v: Vec<S>,
}

const IN_REFLUX: usize = 0;
const IN_REBOILER_DUTY: usize = 1;
const IN_DISTILLATE: usize = 2;
const IN_BOTTOMS: usize = 3;
const IN_CONDENSER_DUTY: usize = 4;

impl RigorousColumn {
    /// Number of stages, condenser and reboiler included.
    pub(crate) fn n_stages(&self) -> usize {
        self.n_stages
    }
    fn nc(&self) -> usize {
        self.comp_names.len()
    }
    /// Variables per stage: n (nc), x (nc), y (nc), T, M, L, V.
    fn per_stage(&self) -> usize {
        3 * self.nc() + 4
    }
    fn n_outlets(&self) -> usize {
        2 + self.draws.len()
    }
    /// Offset of stage `s` (0-based) in the internal variables.
    fn stage(&self, s: usize) -> usize {
        s * self.per_stage()
    }
    /// Offset of `Qc` in the internal variables.
    fn qc(&self) -> usize {
        self.n_stages * self.per_stage()
    }
    /// Offset of the vapour space's component holdups `nV[c]` (pressure state only).
    fn nv_var(&self) -> usize {
        self.qc() + 1
    }
    /// Offset of `P` (pressure state only) in the internal variables.
    fn p_var(&self) -> usize {
        self.nv_var() + self.nc()
    }
    /// Pressure of stage `s` [Pa]: fixed, or the top-pressure state plus the trays' drops.
    fn stage_pressure<S: Scalar>(&self, io: &UnitIo<'_, S>, s: usize) -> S {
        match self.vapour_volume {
            Some(_) => io.var(self.p_var()) + (self.pressure[s] - self.pressure[self.n_stages - 1]),
            None => S::from(self.pressure[s]),
        }
    }
    /// The vapour the condenser condenses [mol/s] and its composition, the vapour space's
    /// `yv = nV / Σ nV` (pressure state only): its duty over the latent heat of that vapour as it
    /// arrives, `W = Qc / (h_V(T_N−1, yv) − h_L,N)`; at steady state `W = V_{N−1}`, `yv = y_{N−1}`.
    fn condensed<S: Scalar>(&self, io: &UnitIo<'_, S>, sh: &Shared<S>) -> (S, Vec<S>) {
        let n = self.n_stages;
        let nv = io.vars(self.nv_var(), self.nc());
        let total = nv.iter().fold(S::from(0.0), |a, b| a + *b);
        let yv: Vec<S> = nv.iter().map(|v| *v / total).collect();
        let t_below = io.vars(self.stage(n - 2), self.per_stage())[StageIdx { nc: self.nc() }.t()];
        (sh.qc / (io.thermo.h_vap(t_below, &yv) - sh.h_l[n - 1]), yv)
    }
    /// Input index of side draw `k`.
    fn draw_input(&self, k: usize) -> usize {
        IN_CONDENSER_DUTY + usize::from(self.condenser.has_input()) + k
    }
    /// Input index of the auxiliary reboiler duty (after the draws), then of the auxiliary
    /// condenser duty.
    fn aux_inputs(&self) -> (usize, usize) {
        let first = self.draw_input(self.draws.len());
        (first, first + usize::from(self.aux_reboiler.is_some()))
    }
    /// The heat the reboiler receives [W]: from input 1 (the duty itself, or `m_s λ_s` for a
    /// steam reboiler) plus the auxiliary reboiler's duty.
    fn q_r<S: Scalar>(&self, io: &UnitIo<'_, S>) -> S {
        let input = io.input(IN_REBOILER_DUTY);
        let main = match self.steam_latent_heat {
            Some(lambda) => input * S::from(lambda),
            None => input,
        };
        match self.aux_reboiler {
            Some(_) => main + io.input(self.aux_inputs().0),
            None => main,
        }
    }
    /// The auxiliary condenser's duty [W] (0 without one).
    fn q_aux_c<S: Scalar>(&self, io: &UnitIo<'_, S>) -> S {
        match self.aux_condenser {
            Some(_) => io.input(self.aux_inputs().1),
            None => S::from(0.0),
        }
    }
    /// Whether outlet `k` is vapour: the distillate of a partial condenser, a vapour side draw.
    fn outlet_is_vapour(&self, k: usize) -> bool {
        match k {
            0 => self.partial,
            1 => false,
            _ => self.draws[k - 2].vapour,
        }
    }
    /// Outlet `k`'s stage: distillate from the drum, bottoms from the reboiler, draws from trays.
    fn outlet_stage(&self, k: usize) -> usize {
        match k {
            0 => self.n_stages - 1,
            1 => 0,
            _ => self.draws[k - 2].stage,
        }
    }

    /// Stage `s`'s outflows and inflows: returns (liquid leaving, vapour leaving, energy balance),
    /// with the components flowing in into `comp_in`. Liquid and vapour leave to the neighbours (or
    /// the bottoms), as distillate and as side draws; the energy balance counts the enthalpy of the
    /// vaporized stream and of every inflow relative to the stage liquid, less the condenser duty
    /// on the top stage, plus the reboiler duty on the bottom one.
    fn stage_flows<S: Scalar>(&self, io: &UnitIo<'_, S>, sh: &Shared<S>, s: usize, comp_in: &mut [S]) -> (S, S, S) {
        let n = self.n_stages;
        let ix = StageIdx { nc: self.nc() };
        let st = |s: usize| io.vars(self.stage(s), self.per_stage());
        let v = st(s);
        let (l, vap) = (v[ix.l()], v[ix.v()]);
        let (h_l, h_v) = (&sh.h_l, &sh.h_v);
        comp_in.iter_mut().for_each(|c| *c = S::from(0.0));
        let (mut liquid_out, mut vapour_out) = (l, vap);
        if s + 1 == n && !self.partial {
            liquid_out += sh.d_in;
        }
        for (d, fl) in self.draws.iter().zip(&sh.draw_flow).filter(|(d, _)| d.stage == s) {
            if d.vapour {
                vapour_out += *fl;
            } else {
                liquid_out += *fl;
            }
        }
        let mut energy = -vapour_out * (h_v[s] - h_l[s]);
        if s + 1 < n {
            let up = st(s + 1);
            comp_in.iter_mut().enumerate().for_each(|(j, c)| *c += up[ix.l()] * up[ix.x(j)]);
            energy += up[ix.l()] * (h_l[s + 1] - h_l[s]);
        }
        if s > 0 {
            let dn = st(s - 1);
            // With a pressure state the drum takes in what the condenser condenses; the rest of
            // the vapour accumulates in the vapour space (the `P` equation).
            if s + 1 == n && self.vapour_volume.is_some() {
                let (w, yv) = self.condensed(io, sh);
                comp_in.iter_mut().zip(&yv).for_each(|(c, y)| *c += w * *y);
                energy += w * (io.thermo.h_vap(dn[ix.t()], &yv) - h_l[s]);
            } else {
                comp_in.iter_mut().enumerate().for_each(|(j, c)| *c += dn[ix.v()] * dn[ix.y(j)]);
                energy += dn[ix.v()] * (h_v[s - 1] - h_l[s]);
            }
        }
        for (f, _) in self.feeds.iter().enumerate().filter(|(_, st)| **st == s) {
            let feed = io.inlet(f);
            comp_in.iter_mut().zip(feed.z()).for_each(|(c, z)| *c += feed.f() * *z);
            energy += feed.f() * (feed.h() - h_l[s]);
        }
        if s + 1 == n {
            energy -= sh.qc;
        }
        if s == 0 {
            energy += sh.q_r;
        }
        (liquid_out, vapour_out, energy)
    }

    /// Outlet residuals: each outlet takes its flow (distillate `D`, bottoms `L_1`, a draw's input)
    /// and the state of its stage, as liquid or vapour.
    fn outlet_residuals<S: Scalar>(&self, io: &UnitIo<'_, S>, sh: &Shared<S>, r: &mut [S]) {
        let ix = StageIdx { nc: self.nc() };
        let slen = io.layout.stream.len();
        let st = |s: usize| io.vars(self.stage(s), self.per_stage());
        for k in 0..self.n_outlets() {
            let s = self.outlet_stage(k);
            let flow = match k {
                0 => sh.d_in,
                1 => st(0)[ix.l()],
                _ => sh.draw_flow[k - 2],
            };
            let out = io.outlet(k);
            let v = st(s);
            let (h, z0) = if self.outlet_is_vapour(k) { (sh.h_v[s], ix.y(0)) } else { (sh.h_l[s], ix.x(0)) };
            let rr = &mut r[k * slen..(k + 1) * slen];
            rr[F] = out.f() - flow;
            rr[T] = out.t() - v[ix.t()];
            rr[P] = out.p() - self.stage_pressure(io, s);
            rr[H] = out.h() - h;
            for j in 0..self.nc() {
                rr[Z0 + j] = out.z()[j] - v[z0 + j];
            }
        }
    }
}

impl UnitModel for RigorousColumn {
    fn type_name(&self) -> &'static str {
        "column"
    }
    fn inlet_ports(&self) -> Vec<String> {
        self.feed_ports.clone()
    }
    fn outlet_ports(&self) -> Vec<String> {
        let mut v = vec!["distillate".to_string(), "bottoms".to_string()];
        v.extend(self.draw_ports.iter().cloned());
        v
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        let mut v = Vec::with_capacity(self.qc() + 1);
        let flow_nom = (self.reflux + self.distillate + self.bottoms).max(1e-3);
        let nc = self.nc().max(1) as f64;
        for s in 0..self.n_stages {
            let st = s + 1;
            let m0 = match s {
                0 => self.m_reboiler,
                _ if s + 1 == self.n_stages => self.m_condenser,
                _ => self.m_tray,
            };
            for c in &self.comp_names {
                let spec = VarSpec::differential(format!("n[{st}][{c}]"), Dimension::AMOUNT, m0 / nc);
                v.push(spec.bounded(0.0, f64::INFINITY));
            }
            for c in &self.comp_names {
                v.push(VarSpec::algebraic(format!("x[{st}][{c}]"), Dimension::DIMENSIONLESS, 1.0).bounded(0.0, 1.0));
            }
            for c in &self.comp_names {
                v.push(VarSpec::algebraic(format!("y[{st}][{c}]"), Dimension::DIMENSIONLESS, 1.0).bounded(0.0, 1.0));
            }
            v.push(VarSpec::algebraic(format!("T[{st}]"), Dimension::TEMPERATURE, 350.0).bounded(1.0, 5000.0));
            v.push(
                VarSpec::algebraic(format!("M[{st}]"), Dimension::AMOUNT, m0)
                    .bounded(1e-12 * m0, f64::INFINITY)
                    .inventory(),
            );
            v.push(VarSpec::algebraic(format!("L[{st}]"), Dimension::MOLAR_FLOW, flow_nom).bounded(0.0, f64::INFINITY));
            v.push(VarSpec::algebraic(format!("V[{st}]"), Dimension::MOLAR_FLOW, flow_nom).bounded(0.0, f64::INFINITY));
        }
        let q_nominal = self.reboiler_duty * self.steam_latent_heat.unwrap_or(1.0) + self.aux_reboiler.unwrap_or(0.0);
        v.push(VarSpec::algebraic("Qc", Dimension::POWER, q_nominal.max(1.0)));
        if let Some(volume) = self.vapour_volume {
            let p_top = self.pressure[self.n_stages - 1];
            let moles = p_top * volume / (plantwide_thermo::R_GAS * 350.0) / nc;
            for c in &self.comp_names {
                let spec = VarSpec::differential(format!("nV[{c}]"), Dimension::AMOUNT, moles);
                v.push(spec.bounded(0.0, f64::INFINITY));
            }
            v.push(VarSpec::algebraic("P", Dimension::PRESSURE, p_top).bounded(1.0, f64::INFINITY));
        }
        v
    }
    fn inputs(&self) -> Vec<InputSpec> {
        let flow = Dimension::MOLAR_FLOW;
        let mut v = vec![
            InputSpec { name: "reflux".into(), dim: flow, value: self.reflux },
            match self.steam_latent_heat {
                Some(_) => {
                    InputSpec { name: "steam_flow".into(), dim: Dimension::MASS_FLOW, value: self.reboiler_duty }
                }
                None => InputSpec { name: "reboiler_duty".into(), dim: Dimension::POWER, value: self.reboiler_duty },
            },
            InputSpec { name: "distillate".into(), dim: flow, value: self.distillate },
            InputSpec { name: "bottoms".into(), dim: flow, value: self.bottoms },
        ];
        match self.condenser {
            Condenser::BubblePoint => {}
            Condenser::Duty(q) => v.push(InputSpec { name: "condenser_duty".into(), dim: Dimension::POWER, value: q }),
            Condenser::Coolant { flow, .. } => {
                v.push(InputSpec { name: "coolant_flow".into(), dim: Dimension::MASS_FLOW, value: flow })
            }
        }
        for (d, p) in self.draws.iter().zip(&self.draw_ports) {
            v.push(InputSpec { name: p.clone(), dim: flow, value: d.flow });
        }
        let power = Dimension::POWER;
        if let Some(q) = self.aux_reboiler {
            v.push(InputSpec { name: "auxiliary_reboiler_duty".into(), dim: power, value: q });
        }
        if let Some(q) = self.aux_condenser {
            v.push(InputSpec { name: "auxiliary_condenser_duty".into(), dim: power, value: q });
        }
        v
    }
    fn holdup(&self, io: &UnitIo<'_, f64>) -> Option<Vec<f64>> {
        let mut n = super::summed_holdups(io, self.n_stages, self.nc(), |s| self.stage(s));
        if self.vapour_volume.is_some() {
            n.iter_mut().zip(io.vars(self.nv_var(), self.nc())).for_each(|(t, v)| *t += v);
        }
        Some(n)
    }
    fn pattern(&self, layout: &LocalLayout) -> Option<Vec<(usize, usize)>> {
        let slen = layout.stream.len();
        let internal0 = self.n_outlets() * slen;
        let ps = self.per_stage();
        let n = self.n_stages;
        let qc = internal0 + self.qc();
        let shared: Vec<usize> = (layout.n_own()..layout.len()).collect();
        let stage_cols = |s: usize| internal0 + self.stage(s)..internal0 + self.stage(s) + ps;
        let mut p = Vec::new();
        for k in 0..self.n_outlets() {
            for row in k * slen..(k + 1) * slen {
                p.extend((k * slen..(k + 1) * slen).map(|c| (row, c)));
                p.extend(stage_cols(self.outlet_stage(k)).map(|c| (row, c)));
                p.extend(shared.iter().map(|&c| (row, c)));
            }
        }
        for s in 0..n {
            for row in stage_cols(s) {
                for t in s.saturating_sub(1)..=(s + 1).min(n - 1) {
                    p.extend(stage_cols(t).map(|c| (row, c)));
                }
                if s + 1 == n {
                    p.push((row, qc));
                }
                p.extend(shared.iter().map(|&c| (row, c)));
            }
        }
        for t in n.saturating_sub(2)..n {
            p.extend(stage_cols(t).map(|c| (qc, c)));
        }
        p.push((qc, qc));
        p.extend(shared.iter().map(|&c| (qc, c)));
        if self.vapour_volume.is_some() {
            // The pressure enters every stage's VLE and every outlet; its own row reads the top
            // two stages and the duty.
            let space: Vec<usize> = (internal0 + self.nv_var()..=internal0 + self.p_var()).collect();
            let rows: Vec<usize> = p.iter().map(|e| e.0).collect();
            let mut seen = std::collections::BTreeSet::new();
            let rows: Vec<usize> = rows.into_iter().filter(|r| seen.insert(*r)).chain(space.iter().copied()).collect();
            for &row in &rows {
                p.extend(space.iter().map(|&c| (row, c)));
            }
            for &row in &space {
                for t in n.saturating_sub(2)..n {
                    p.extend(stage_cols(t).map(|c| (row, c)));
                }
                p.push((row, qc));
                p.extend(shared.iter().map(|&c| (row, c)));
            }
        }
        Some(p)
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let nc = self.nc();
        let n = self.n_stages;
        let internal0 = self.n_outlets() * io.layout.stream.len();
        let ix = StageIdx { nc };
        let th = io.thermo;
        let st = |s: usize| io.vars(self.stage(s), self.per_stage());
        let sh = Shared {
            l_in: io.input(IN_REFLUX),
            q_r: self.q_r(io),
            d_in: io.input(IN_DISTILLATE),
            b_in: io.input(IN_BOTTOMS),
            qc: io.var(self.qc()),
            draw_flow: (0..self.draws.len()).map(|k| io.input(self.draw_input(k))).collect(),
            h_l: (0..n).map(|s| th.h_liq(st(s)[ix.t()], &st(s)[ix.x(0)..ix.x(0) + nc])).collect(),
            h_v: (0..n).map(|s| th.h_vap(st(s)[ix.t()], &st(s)[ix.y(0)..ix.y(0) + nc])).collect(),
        };
        let mut k = vec![S::from(0.0); nc];
        let mut comp_in = vec![S::from(0.0); nc];
        let mut condenser_energy = S::from(0.0);
        for s in 0..n {
            let v = st(s);
            let o = internal0 + self.stage(s);
            let (t, m, l, vap) = (v[ix.t()], v[ix.m()], v[ix.l()], v[ix.v()]);
            let x = &v[ix.x(0)..ix.x(0) + nc];
            let p = self.stage_pressure(io, s);
            let (liquid_out, vapour_out, energy) = self.stage_flows(io, &sh, s, &mut comp_in);
            if s + 1 == n {
                condenser_energy = energy;
            }
            for j in 0..nc {
                r[o + ix.n(j)] = comp_in[j] - liquid_out * x[j] - vapour_out * v[ix.y(j)];
                r[o + ix.x(j)] = x[j] * m - v[ix.n(j)];
            }
            th.k_values(t, p, x, &mut k);
            let tray = s > 0 && s + 1 < n;
            for j in 0..nc {
                r[o + ix.y(j)] = if tray {
                    let below = st(s - 1)[ix.y(j)];
                    v[ix.y(j)] - below - (k[j] * x[j] - below) * self.efficiency
                } else {
                    v[ix.y(j)] - k[j] * x[j]
                };
            }
            // A duty-set drum at fixed pressure is subcooled (its energy balance gives T_N); with a
            // pressure state it sits at its bubble point and the pressure moves instead.
            let duty_condenser = s + 1 == n && self.condenser.has_input() && self.vapour_volume.is_none();
            r[o + ix.t()] = if duty_condenser {
                energy
            } else if let VleModel::ConstantAlpha { .. } = th.vle {
                th.bubble_residual(t, p, x)
            } else {
                // Σ K x − 1 with the K-values already at hand (what `bubble_residual` computes).
                k.iter().zip(x).fold(S::from(-1.0), |acc, (k, x)| acc + *k * *x)
            };
            r[o + ix.m()] = m - v[ix.n(0)..ix.n(0) + nc].iter().fold(S::from(0.0), |a, b| a + *b);
            r[o + ix.l()] = if s + 1 == n {
                l - sh.l_in
            } else if s == 0 {
                l - sh.b_in
            } else {
                l - self.weir.flow(m, th.v_liq(t, x))
            };
            r[o + ix.v()] = match (s + 1 == n, self.partial) {
                (true, true) => vap - sh.d_in,
                (true, false) => vap,
                _ => energy,
            };
        }
        r[internal0 + self.qc()] = match self.condenser {
            Condenser::BubblePoint => condenser_energy,
            Condenser::Duty(_) => sh.qc - io.input(IN_CONDENSER_DUTY) - self.q_aux_c(io),
            Condenser::Coolant { t_in, ua, cp, .. } => {
                sh.qc - coolant_duty(io.input(IN_CONDENSER_DUTY), st(n - 1)[ix.t()], t_in, ua, cp) - self.q_aux_c(io)
            }
        };
        if let Some(volume) = self.vapour_volume {
            // The vapour space: its component holdups take in the vapour from the top tray and
            // give the condensed part to the drum; its pressure is the ideal gas's at T_N.
            let (below, top) = (st(n - 2), st(n - 1));
            let (w, yv) = self.condensed(io, &sh);
            for j in 0..nc {
                r[internal0 + self.nv_var() + j] = below[ix.v()] * below[ix.y(j)] - w * yv[j];
            }
            let moles = io.vars(self.nv_var(), nc).iter().fold(S::from(0.0), |a, b| a + *b);
            r[internal0 + self.p_var()] = io.var(self.p_var()) - moles * top[ix.t()] * plantwide_thermo::R_GAS / volume;
        }
        self.outlet_residuals(io, &sh, r);
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        profile::guess(self, io, own);
    }
}
