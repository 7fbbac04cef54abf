//! A model zoo shared by the tests and the benchmark: the jacketed CSTR with a first-order
//! exothermic reaction A → B, as text and as hand-written Rust.
//!
//! ```text
//! der(CA) = F/V*(CAf - CA) - k0*exp(-E/(R*T))*CA
//! der(T)  = F/V*(Tf - T) + (-dH)*k0*exp(-E/(R*T))*CA/(rho*cp) + UA*(Tj - T)/(V*rho*cp)
//! ```
//!
//! Parameter values follow the classic example of Seborg, Edgar, Mellichamp & Doyle,
//! *Process Dynamics and Control* (3rd ed.), Example 2.5 / Appendix E, converted to SI:
//! V = 100 L, k0 = 7.2·10¹⁰ min⁻¹, E/R = 8750 K, −ΔH = 5·10⁴ J/mol, ρ = 1000 kg/m³,
//! cp = 239 J/(kg·K), UA = 5·10⁴ J/(min·K), CAf = 1 mol/L, Tf = 350 K.

use crate::Scalar;
use plantwide_units::Dimension;

use crate::{SymbolTable, VarKind};

/// Slots of the CSTR's variables in `x` (and `dx`).
pub mod slot {
    /// Concentration of A [mol/m³], differential.
    pub const CA: usize = 0;
    /// Reactor temperature [K], differential.
    pub const T: usize = 1;
    /// Volumetric feed flow [m³/s], algebraic.
    pub const F: usize = 2;
    /// Jacket temperature [K], algebraic.
    pub const TJ: usize = 3;
}

/// The CSTR's parameters in SI units.
#[derive(Debug, Clone, Copy)]
pub struct CstrParams {
    /// Volume [m³].
    pub v: f64,
    /// Feed concentration [mol/m³].
    pub caf: f64,
    /// Pre-exponential factor [1/s].
    pub k0: f64,
    /// Activation energy [J/mol].
    pub e: f64,
    /// Gas constant [J/(mol·K)].
    pub r: f64,
    /// Heat of reaction [J/mol] (negative: exothermic).
    pub dh: f64,
    /// Density [kg/m³].
    pub rho: f64,
    /// Heat capacity [J/(kg·K)].
    pub cp: f64,
    /// Conductance [W/K].
    pub ua: f64,
    /// Feed temperature [K].
    pub tf: f64,
}

/// Seborg et al.'s values in SI.
pub const CSTR: CstrParams = CstrParams {
    v: 0.1,
    caf: 1000.0,
    k0: 7.2e10 / 60.0,
    e: 8750.0 * 8.314,
    r: 8.314,
    dh: -5.0e4,
    rho: 1000.0,
    cp: 239.0,
    ua: 5.0e4 / 60.0,
    tf: 350.0,
};

/// The two balances as equation text.
pub const CSTR_EQUATIONS: [&str; 2] = [
    "der(CA) = F/V*(CAf - CA) - k0*exp(-E/(R*T))*CA",
    "der(T) = F/V*(Tf - T) + (-dH)*k0*exp(-E/(R*T))*CA/(rho*cp) + UA*(Tj - T)/(V*rho*cp)",
];

/// The symbols of the CSTR: parameters from `p`, variables at [`slot`].
///
/// # Panics
/// Never for these fixed, valid names.
pub fn cstr_symbols(p: &CstrParams) -> SymbolTable {
    let mut s = SymbolTable::new();
    let params = [
        ("V", p.v, Dimension::VOLUME),
        ("CAf", p.caf, Dimension::CONCENTRATION),
        ("k0", p.k0, Dimension::INVERSE_TIME),
        ("E", p.e, Dimension::MOLAR_ENERGY),
        ("R", p.r, Dimension::HEAT_CAPACITY_MOLAR),
        ("dH", p.dh, Dimension::MOLAR_ENERGY),
        ("rho", p.rho, Dimension::DENSITY_MASS),
        ("cp", p.cp, Dimension::HEAT_CAPACITY_MASS),
        ("UA", p.ua, Dimension::UA),
        ("Tf", p.tf, Dimension::TEMPERATURE),
    ];
    for (name, value, dim) in params {
        s.add_parameter(name, value, dim).expect("valid parameter");
    }
    let vars = [
        ("CA", slot::CA, Dimension::CONCENTRATION, VarKind::Differential),
        ("T", slot::T, Dimension::TEMPERATURE, VarKind::Differential),
        ("F", slot::F, Dimension::VOLUMETRIC_FLOW, VarKind::Algebraic),
        ("Tj", slot::TJ, Dimension::TEMPERATURE, VarKind::Algebraic),
    ];
    for (name, index, dim, kind) in vars {
        s.add_variable(name, index, dim, kind).expect("valid variable");
    }
    s
}

/// The same two residuals written by hand, as a built-in unit would write them.
pub fn cstr_hand<S: Scalar>(p: &CstrParams, x: &[S], dx: &[S]) -> [S; 2] {
    let (ca, t, f, tj) = (x[slot::CA], x[slot::T], x[slot::F], x[slot::TJ]);
    let rate = (t * p.r).recip() * (-p.e);
    let rate = rate.exp() * p.k0 * ca;
    let dilution = f / p.v;
    let r_ca = dx[slot::CA] - (dilution * (-ca + p.caf) - rate);
    let heat = rate * (-p.dh) / (p.rho * p.cp);
    let jacket = (tj - t) * p.ua / (p.v * p.rho * p.cp);
    let r_t = dx[slot::T] - (dilution * (-t + p.tf) + heat + jacket);
    [r_ca, r_t]
}
