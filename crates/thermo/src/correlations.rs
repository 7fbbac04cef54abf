//! Evaluation of the pure-component correlations of [`crate::component`], generic over [`Scalar`].
//!
//! Every branch decision (above/below the critical temperature, unused terms) looks at the real
//! part only; the returned value is always built with `Scalar` arithmetic so that dual numbers
//! carry exact derivatives. Powers are taken as `exp(n ln x)` of a positive base only (num-dual's
//! `powf` of a dual number with zero or tiny real part is NaN), and the hyperbolic functions of
//! DIPPR 107 are written with `exp(−2u)` so that dual numbers do not overflow at low temperature.

use crate::component::{CpIdealGas, CpLiquid, HeatOfVaporization, LiquidVolume, VapourPressure};
use crate::{R_GAS, Scalar, T_REF};

/// `x^n` for `x > 0` as `exp(n ln x)` (num-dual's `powf` multiplies `x^(n−3)` by `x³`, which
/// overflows for tiny `x`).
fn pow_pos<S: Scalar>(x: S, n: f64) -> S {
    (x.ln() * n).exp()
}

/// `tanh u` without overflow for duals (num-dual evaluates `sinh/cosh`, NaN beyond |u| ≈ 710):
/// `tanh u = σ (1 − e^{−2σu}) / (1 + e^{−2σu})`, `σ = sign u`. Not recursive, so that a NaN
/// argument (which is neither `> 0` nor `< 0`) gives NaN instead of recursing until the stack
/// overflows.
fn tanh_safe<S: Scalar>(u: S) -> S {
    let r = u.re();
    if r.abs() < 0.5 {
        return u.tanh();
    }
    let sign = if r < 0.0 { -1.0 } else { 1.0 };
    let e = (u * (-2.0 * sign)).exp();
    (S::from(1.0) - e) / (e + 1.0) * sign
}

/// `u / sinh u` without overflow (even in `u`; `u ≠ 0`).
fn u_over_sinh<S: Scalar>(u: S) -> S {
    let r = u.re();
    if r.abs() < 0.5 {
        u / u.sinh()
    } else {
        let a = if r > 0.0 { u } else { -u };
        let e = (-a).exp();
        a * e * 2.0 / (S::from(1.0) - e * e)
    }
}

/// `u / cosh u` without overflow (odd in `u`).
fn u_over_cosh<S: Scalar>(u: S) -> S {
    if u.re().abs() < 0.5 {
        u / u.cosh()
    } else {
        let e = (-u.abs()).exp();
        u * e * 2.0 / (e * e + 1.0)
    }
}

impl VapourPressure {
    /// Vapour pressure [Pa] at `t` [K]; the correlations are evaluated (and extrapolated) as
    /// written, `tmin`/`tmax` are informational.
    pub fn eval<S: Scalar>(&self, t: S) -> S {
        match self {
            // p_ref · exp(hvap/R · (T − t_ref)/(T·t_ref)), which is −hvap/R · (1/T − 1/t_ref) with
            // one division instead of three (the model's hottest call: every stage's bubble point);
            // without `ln p_ref` per call.
            VapourPressure::ClausiusClapeyron { p_ref, t_ref, hvap } => {
                ((t - *t_ref) / (t * *t_ref) * (*hvap * (1.0 / R_GAS))).exp() * *p_ref
            }
            _ => self.ln_psat(t).exp(),
        }
    }

    /// `ln(P_sat / Pa)` at `t` [K].
    pub fn ln_psat<S: Scalar>(&self, t: S) -> S {
        match self {
            VapourPressure::Dippr101 { c, .. } => {
                // ln P = c0 + c1/T + c2 ln T + c3 T^c4
                let mut v = S::from(c[0]) + t.recip() * c[1] + t.ln() * c[2];
                if c[3] != 0.0 {
                    v += pow_pos(t, c[4]) * c[3];
                }
                v
            }
            VapourPressure::ExtendedAntoine { c, .. } => {
                // ln P = c0 + c1/(T + c2) + c3 T + c4 ln T + c5 T^c6
                let mut v = S::from(c[0]) + (t + c[2]).recip() * c[1] + t * c[3] + t.ln() * c[4];
                if c[5] != 0.0 {
                    v += pow_pos(t, c[6]) * c[5];
                }
                v
            }
            VapourPressure::Antoine { a, b, c, .. } => {
                // log10 P = a − b/(T + c)  ⇒  ln P = ln 10 · (a − b/(T + c))
                (S::from(*a) - (t + *c).recip() * *b) * std::f64::consts::LN_10
            }
            VapourPressure::ClausiusClapeyron { p_ref, t_ref, hvap } => {
                // ln P = ln p_ref − hvap/R · (1/T − 1/t_ref)
                S::from(p_ref.ln()) - (t.recip() - t_ref.recip()) * (*hvap / R_GAS)
            }
        }
    }
}

impl CpIdealGas {
    /// Ideal-gas heat capacity [J/(mol·K)] at `t` [K].
    pub fn cp<S: Scalar>(&self, t: S) -> S {
        match self {
            CpIdealGas::Dippr107 { c } => {
                // cp = c0 + c1 ((c2/T)/sinh(c2/T))² + c3 ((c4/T)/cosh(c4/T))²
                let mut v = S::from(c[0]);
                if c[2] != 0.0 {
                    let r = u_over_sinh(t.recip() * c[2]);
                    v += r * r * c[1];
                } else {
                    // lim_{u→0} u/sinh u = 1
                    v += c[1];
                }
                if c[4] != 0.0 {
                    let r = u_over_cosh(t.recip() * c[4]);
                    v += r * r * c[3];
                }
                // lim_{u→0} u/cosh u = 0: the c3 term vanishes when c4 = 0.
                v
            }
            CpIdealGas::Polynomial { c } => S::from(c[0]) + t * (S::from(c[1]) + t * (S::from(c[2]) + t * c[3])),
            CpIdealGas::Constant { cp } => S::from(*cp),
        }
    }

    /// Antiderivative of `cp` [J/mol] (arbitrary constant).
    fn antiderivative<S: Scalar>(&self, t: S) -> S {
        match self {
            CpIdealGas::Dippr107 { c } => {
                // ∫cp dT = c0 T + c1 c2 coth(c2/T) − c3 c4 tanh(c4/T)
                let mut v = t * c[0];
                if c[2] != 0.0 {
                    v += tanh_safe(t.recip() * c[2]).recip() * (c[1] * c[2]);
                } else {
                    v += t * c[1];
                }
                if c[4] != 0.0 {
                    v -= tanh_safe(t.recip() * c[4]) * (c[3] * c[4]);
                }
                v
            }
            CpIdealGas::Polynomial { c } => {
                t * (S::from(c[0]) + t * (S::from(c[1] / 2.0) + t * (S::from(c[2] / 3.0) + t * (c[3] / 4.0))))
            }
            CpIdealGas::Constant { cp } => t * *cp,
        }
    }

    /// Ideal-gas enthalpy `∫_{298.15 K}^{T} cp dT` [J/mol] (closed-form integral).
    pub fn h<S: Scalar>(&self, t: S) -> S {
        match self {
            // Exact differences for the polynomial forms avoid cancellation near T_REF.
            CpIdealGas::Constant { cp } => (t - T_REF) * *cp,
            CpIdealGas::Polynomial { c } => {
                let d = t - T_REF;
                // T^k − Tr^k = (T − Tr) Σ_{m<k} T^m Tr^(k−1−m)
                let s2 = t + T_REF;
                let s3 = t * t + t * T_REF + T_REF * T_REF;
                let s4 = (t * t + T_REF * T_REF) * s2;
                d * (S::from(c[0]) + s2 * (c[1] / 2.0) + s3 * (c[2] / 3.0) + s4 * (c[3] / 4.0))
            }
            CpIdealGas::Dippr107 { .. } => self.antiderivative(t) - self.antiderivative(S::from(T_REF)),
        }
    }
}

impl CpLiquid {
    /// Liquid heat capacity [J/(mol·K)] at `t` [K].
    pub fn cp<S: Scalar>(&self, t: S) -> S {
        match self {
            CpLiquid::Dippr100 { c } => {
                S::from(c[0]) + t * (S::from(c[1]) + t * (S::from(c[2]) + t * (S::from(c[3]) + t * c[4])))
            }
            CpLiquid::Constant { cp } => S::from(*cp),
        }
    }
}

impl HeatOfVaporization {
    /// Heat of vaporization [J/mol] at `t` [K]; 0 at and above the critical temperature.
    pub fn eval<S: Scalar>(&self, t: S) -> S {
        match self {
            HeatOfVaporization::Watson { h_ref, t_ref, tc, n } => {
                // ΔH = h_ref ((tc − T)/(tc − t_ref))^n, computed only where the base is > 0.
                let base = (S::from(*tc) - t) / (*tc - *t_ref);
                if base.re() > 0.0 && base.re().is_finite() { pow_pos(base, *n) * *h_ref } else { S::from(0.0) }
            }
            HeatOfVaporization::Dippr106 { c, tc } => {
                // ΔH = c0 (1 − Tr)^(c1 + c2 Tr + c3 Tr² + c4 Tr³), Tr = T/tc
                let tr = t / *tc;
                let one_m = S::from(1.0) - tr;
                if one_m.re() > 0.0 && one_m.re().is_finite() {
                    let e = S::from(c[1]) + tr * (S::from(c[2]) + tr * (S::from(c[3]) + tr * c[4]));
                    (one_m.ln() * e).exp() * c[0]
                } else {
                    S::from(0.0)
                }
            }
            HeatOfVaporization::Constant { h } => S::from(*h),
        }
    }
}

impl LiquidVolume {
    /// Liquid molar volume [m³/mol] at `t` [K]. Above the critical temperature of the correlation
    /// the temperature term `(1 − T/Tc)^k` is taken as 0 (the critical volume is returned).
    pub fn eval<S: Scalar>(&self, t: S) -> S {
        match self {
            LiquidVolume::Dippr105 { c } => {
                // ρ = c0 / c1^(1 + (1 − T/c2)^c3) [mol/m³]  ⇒  V = c1^(1 + τ^c3) / c0
                let tau = S::from(1.0) - t / c[2];
                let expo = if tau.re() > 0.0 { pow_pos(tau, c[3]) + 1.0 } else { S::from(1.0) };
                (expo * c[1].ln()).exp() / c[0]
            }
            LiquidVolume::Rackett { tc, pc, zra } => {
                // V = (R tc/pc) zra^(1 + (1 − T/tc)^(2/7))
                let tau = S::from(1.0) - t / *tc;
                let expo = if tau.re() > 0.0 { pow_pos(tau, 2.0 / 7.0) + 1.0 } else { S::from(1.0) };
                (expo * zra.ln()).exp() * (R_GAS * *tc / *pc)
            }
            LiquidVolume::Constant { v } => S::from(*v),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tanh_safe_matches_tanh_and_passes_nan_through() {
        for u in [-800.0f64, -3.0, -0.7, -0.2, 0.0, 0.3, 0.6, 5.0, 800.0] {
            assert!((tanh_safe(u) - u.tanh()).abs() <= 1e-15, "{u}");
        }
        assert!(tanh_safe(f64::NAN).is_nan());
        assert!(tanh_safe(num_dual::Dual64::new(f64::NAN, 1.0)).re.is_nan());
    }
}
