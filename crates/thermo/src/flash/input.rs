//! Input validation shared by the bubble/dew points and flashes.

use crate::ThermoError;

/// Pressure must be positive and finite.
pub(crate) fn pressure(routine: &'static str, p: f64) -> Result<(), ThermoError> {
    if p.is_finite() && p > 0.0 {
        Ok(())
    } else {
        Err(ThermoError::BadInput { routine, reason: format!("pressure must be positive and finite, got P = {p} Pa") })
    }
}

/// Temperature must be positive and finite.
pub(crate) fn temperature(routine: &'static str, t: f64) -> Result<(), ThermoError> {
    if t.is_finite() && t > 0.0 {
        Ok(())
    } else {
        Err(ThermoError::BadInput {
            routine,
            reason: format!("temperature must be positive and finite, got T = {t} K"),
        })
    }
}

/// A composition of `n` mole fractions: finite, non-negative (entries in `[-1e-12, 0)` are taken as
/// 0), summing to 1 within 1e-8; returned normalised to unit sum.
pub(crate) fn composition(routine: &'static str, n: usize, z: &[f64]) -> Result<Vec<f64>, ThermoError> {
    let bad = |reason: String| Err(ThermoError::BadInput { routine, reason });
    if n == 0 {
        return bad("the package has no components".to_string());
    }
    if z.len() != n {
        return bad(format!("composition has {} entries for {n} components: {z:?}", z.len()));
    }
    if let Some(v) = z.iter().find(|v| !v.is_finite() || **v < -1e-12) {
        return bad(format!("mole fractions must be finite and non-negative, got {v} in {z:?}"));
    }
    let mut out: Vec<f64> = z.iter().map(|v| v.max(0.0)).collect();
    let s: f64 = out.iter().sum();
    if (s - 1.0).abs() > 1e-8 {
        return bad(format!("mole fractions must sum to 1 (within 1e-8), got Σ = {s} for {z:?}"));
    }
    out.iter_mut().for_each(|v| *v /= s);
    Ok(out)
}

/// `"T = … K, P = … Pa, z = […]"` for error messages.
pub(crate) fn conditions(t: Option<f64>, p: Option<f64>, h: Option<f64>, label: &str, z: &[f64]) -> String {
    let mut s = String::new();
    if let Some(t) = t {
        s.push_str(&format!("T = {t} K, "));
    }
    if let Some(p) = p {
        s.push_str(&format!("P = {p} Pa, "));
    }
    if let Some(h) = h {
        s.push_str(&format!("h = {h} J/mol, "));
    }
    s.push_str(&format!("{label} = {z:?}"));
    s
}
