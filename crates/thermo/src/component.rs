//! Pure-component data and property correlations.
//!
//! The forms follow the DIPPR equation numbers used by Perry's Chemical Engineers' Handbook
//! (8th ed., section 2), so published coefficients can be entered as printed (after conversion to
//! the SI units stated on each variant).

use serde::{Deserialize, Serialize};

use num_dual::Dual64;

use crate::{R_GAS, Scalar, ThermoError};

/// One pure component. Fields carry SI units; the library file stores exactly this structure.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Component {
    /// Name used in flowsheets (lower case, e.g. `"ethanol"`).
    pub name: String,
    /// Chemical formula (informational), e.g. `"C2H6O"`.
    #[serde(default)]
    pub formula: String,
    /// CAS registry number (informational).
    #[serde(default)]
    pub cas: String,
    /// Molar mass [kg/mol].
    pub mw: f64,
    /// Normal boiling point at 101 325 Pa [K].
    pub tb: f64,
    /// Critical temperature [K] (None for hypothetical components).
    #[serde(default)]
    pub tc: Option<f64>,
    /// Critical pressure [Pa].
    #[serde(default)]
    pub pc: Option<f64>,
    /// Acentric factor [-].
    #[serde(default)]
    pub omega: Option<f64>,
    /// Vapour pressure correlation.
    pub psat: VapourPressure,
    /// Ideal-gas heat capacity.
    pub cp_ig: CpIdealGas,
    /// Liquid heat capacity (reported and checked; the liquid enthalpy itself is built from the
    /// ideal-gas enthalpy minus the heat of vaporization so that it is consistent with the VLE).
    pub cp_liq: CpLiquid,
    /// Heat of vaporization.
    pub hvap: HeatOfVaporization,
    /// Liquid molar volume.
    pub vliq: LiquidVolume,
    /// Where the numbers come from (book, table, page).
    #[serde(default)]
    pub source: String,
}

/// Vapour pressure `P_sat(T)` [Pa], `T` in K.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(tag = "form", rename_all = "snake_case", deny_unknown_fields)]
pub enum VapourPressure {
    /// DIPPR 101: `ln P = c[0] + c[1]/T + c[2] ln T + c[3] T^c[4]`, P in Pa.
    Dippr101 {
        /// Coefficients `c[0] … c[4]` (P in Pa, T in K).
        c: [f64; 5],
        /// Lowest temperature of the data [K].
        tmin: f64,
        /// Highest temperature of the data [K].
        tmax: f64,
    },
    /// Extended Antoine (Aspen PLXANT form): `ln P = c[0] + c[1]/(T + c[2]) + c[3] T + c[4] ln T + c[5] T^c[6]`, P in Pa.
    ExtendedAntoine {
        /// Coefficients `c[0] … c[6]` (P in Pa, T in K).
        c: [f64; 7],
        /// Lowest temperature of the data [K].
        tmin: f64,
        /// Highest temperature of the data [K].
        tmax: f64,
    },
    /// Classic Antoine: `log10 P = a − b/(T + c)`, P in Pa, T in K.
    Antoine {
        /// Constant term (log10 of Pa).
        a: f64,
        /// Slope [K].
        b: f64,
        /// Temperature offset [K].
        c: f64,
        /// Lowest temperature of the data [K].
        tmin: f64,
        /// Highest temperature of the data [K].
        tmax: f64,
    },
    /// Clausius–Clapeyron with constant heat of vaporization, for hypothetical components:
    /// `P = p_ref · exp(−hvap/R · (1/T − 1/t_ref))`. Components sharing `hvap` and `t_ref` have a
    /// constant relative volatility equal to the ratio of their `p_ref`.
    ClausiusClapeyron {
        /// Vapour pressure at `t_ref` [Pa].
        p_ref: f64,
        /// Reference temperature [K].
        t_ref: f64,
        /// Heat of vaporization [J/mol].
        hvap: f64,
    },
}

impl VapourPressure {
    /// Lowest temperature [K] of the correlation's data (its triple-point region for the DIPPR and
    /// Antoine forms; `None` for the Clausius–Clapeyron form of hypothetical components): below it
    /// the correlation is an extrapolation to where no liquid exists.
    pub fn t_min(&self) -> Option<f64> {
        match self {
            VapourPressure::Dippr101 { tmin, .. }
            | VapourPressure::ExtendedAntoine { tmin, .. }
            | VapourPressure::Antoine { tmin, .. } => Some(*tmin),
            VapourPressure::ClausiusClapeyron { .. } => None,
        }
    }
}

/// Ideal-gas heat capacity [J/(mol·K)].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(tag = "form", rename_all = "snake_case", deny_unknown_fields)]
pub enum CpIdealGas {
    /// DIPPR 107 (Aly–Lee): `cp = c[0] + c[1]·((c[2]/T)/sinh(c[2]/T))² + c[3]·((c[4]/T)/cosh(c[4]/T))²`, J/(mol·K).
    Dippr107 {
        /// Coefficients `c[0] … c[4]` (cp in J/(mol·K), `c[2]`, `c[4]` in K).
        c: [f64; 5],
    },
    /// Polynomial `cp = c[0] + c[1] T + c[2] T² + c[3] T³`, J/(mol·K).
    Polynomial {
        /// Coefficients `c[0] … c[3]` (cp in J/(mol·K), T in K).
        c: [f64; 4],
    },
    /// Constant, J/(mol·K).
    Constant {
        /// Heat capacity [J/(mol·K)].
        cp: f64,
    },
}

/// Liquid heat capacity [J/(mol·K)].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(tag = "form", rename_all = "snake_case", deny_unknown_fields)]
pub enum CpLiquid {
    /// DIPPR 100: `cp = c[0] + c[1] T + c[2] T² + c[3] T³ + c[4] T⁴`, J/(mol·K).
    Dippr100 {
        /// Coefficients `c[0] … c[4]` (cp in J/(mol·K), T in K).
        c: [f64; 5],
    },
    /// Constant, J/(mol·K).
    Constant {
        /// Heat capacity [J/(mol·K)].
        cp: f64,
    },
}

/// Heat of vaporization `ΔH_vap(T)` [J/mol].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(tag = "form", rename_all = "snake_case", deny_unknown_fields)]
pub enum HeatOfVaporization {
    /// Watson: `ΔH = h_ref · ((tc − T)/(tc − t_ref))^n`, usually `n = 0.38` and `t_ref = tb`; 0 above tc.
    Watson {
        /// Heat of vaporization at `t_ref` [J/mol].
        h_ref: f64,
        /// Reference temperature [K], usually the normal boiling point.
        t_ref: f64,
        /// Critical temperature [K].
        tc: f64,
        /// Watson exponent [-], usually 0.38.
        n: f64,
    },
    /// DIPPR 106: `ΔH = c[0] (1 − Tr)^(c[1] + c[2] Tr + c[3] Tr² + c[4] Tr³)`, `Tr = T/tc`, J/mol.
    Dippr106 {
        /// Coefficients `c[0]` [J/mol] and `c[1] … c[4]` [-].
        c: [f64; 5],
        /// Critical temperature [K].
        tc: f64,
    },
    /// Constant, J/mol (hypothetical components).
    Constant {
        /// Heat of vaporization [J/mol].
        h: f64,
    },
}

/// Liquid molar volume [m³/mol].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(tag = "form", rename_all = "snake_case", deny_unknown_fields)]
pub enum LiquidVolume {
    /// DIPPR 105 density: `ρ = c[0] / c[1]^(1 + (1 − T/c[2])^c[3])` in mol/m³; volume = 1/ρ.
    Dippr105 {
        /// Coefficients: `c[0]` [mol/m³], `c[1]` [-], `c[2]` [K], `c[3]` [-].
        c: [f64; 4],
    },
    /// Rackett: `V = (R tc / pc) · zra^(1 + (1 − T/tc)^(2/7))`.
    Rackett {
        /// Critical temperature [K].
        tc: f64,
        /// Critical pressure [Pa].
        pc: f64,
        /// Rackett compressibility factor [-].
        zra: f64,
    },
    /// Constant, m³/mol.
    Constant {
        /// Molar volume [m³/mol].
        v: f64,
    },
}

impl Component {
    /// Vapour pressure [Pa] at `t` [K] (see [`VapourPressure`] for the forms).
    pub fn psat<S: Scalar>(&self, t: S) -> S {
        self.psat.eval(t)
    }
    /// Ideal-gas molar enthalpy relative to the ideal gas at 298.15 K [J/mol] (analytic integral of `cp_ig`).
    pub fn h_ig<S: Scalar>(&self, t: S) -> S {
        self.cp_ig.h(t)
    }
    /// Ideal-gas heat capacity [J/(mol·K)] at `t` [K].
    pub fn cp_gas<S: Scalar>(&self, t: S) -> S {
        self.cp_ig.cp(t)
    }
    /// Heat of vaporization [J/mol] at `t` [K].
    pub fn dh_vap<S: Scalar>(&self, t: S) -> S {
        self.hvap.eval(t)
    }
    /// Liquid molar enthalpy [J/mol]: `h_ig(T) − ΔH_vap(T)`.
    pub fn h_liq<S: Scalar>(&self, t: S) -> S {
        self.h_ig(t) - self.dh_vap(t)
    }
    /// Liquid heat capacity from the `cp_liq` correlation [J/(mol·K)].
    pub fn cp_liquid<S: Scalar>(&self, t: S) -> S {
        self.cp_liq.cp(t)
    }
    /// Liquid molar volume [m³/mol] at `t` [K].
    pub fn v_liq<S: Scalar>(&self, t: S) -> S {
        self.vliq.eval(t)
    }
    /// Saturation temperature [K] at pressure `p` [Pa]: the root of `P_sat(T) = p`, converged to
    /// machine precision by bracketed Newton on `ln P_sat(T) − ln p`.
    pub fn tsat(&self, p: f64) -> Result<f64, ThermoError> {
        if !(p.is_finite() && p > 0.0) {
            return Err(ThermoError::BadInput {
                routine: "tsat",
                reason: format!("pressure must be positive and finite, got {p} Pa"),
            });
        }
        let ln_p = p.ln();
        let t0 = if self.tb.is_finite() && self.tb > 0.0 { self.tb } else { 300.0 };
        let f = |t: f64| {
            let d = self.psat.ln_psat(Dual64::new(t, 1.0));
            (d.re - ln_p, d.eps)
        };
        crate::solve1d::solve_increasing(f, t0, crate::solve1d::T_MIN, crate::solve1d::T_MAX).map(|(t, _)| t).map_err(
            |it| ThermoError::NoConvergence {
                routine: "tsat",
                iterations: it,
                residual: f64::NAN,
                conditions: format!("component `{}`, P = {p} Pa", self.name),
            },
        )
    }
    /// A hypothetical component for constant-relative-volatility studies: vapour pressure by
    /// Clausius–Clapeyron with `p_sat(t_ref) = alpha · 101 325 Pa`, constant `hvap` [J/mol],
    /// constant liquid heat capacity `cp` [J/(mol·K)] (ideal-gas heat capacity set equal, so `hvap` is
    /// temperature independent), molar mass `mw` [kg/mol] and liquid volume `v` [m³/mol].
    ///
    /// The normal boiling point follows from Clausius–Clapeyron at 101 325 Pa:
    /// `1/tb = 1/t_ref + R ln(alpha)/hvap`; it is `f64::INFINITY` when that is not positive (no
    /// finite temperature reaches 1 atm).
    pub fn hypothetical(name: &str, alpha: f64, mw: f64, hvap: f64, t_ref: f64, cp: f64, v: f64) -> Component {
        let inv_tb = t_ref.recip() + R_GAS * alpha.ln() / hvap;
        let tb = if inv_tb > 0.0 && inv_tb.is_finite() { inv_tb.recip() } else { f64::INFINITY };
        Component {
            name: name.to_string(),
            formula: String::new(),
            cas: String::new(),
            mw,
            tb,
            tc: None,
            pc: None,
            omega: None,
            psat: VapourPressure::ClausiusClapeyron { p_ref: alpha * 101_325.0, t_ref, hvap },
            cp_ig: CpIdealGas::Constant { cp },
            cp_liq: CpLiquid::Constant { cp },
            hvap: HeatOfVaporization::Constant { h: hvap },
            vliq: LiquidVolume::Constant { v },
            source: "hypothetical".to_string(),
        }
    }
}
