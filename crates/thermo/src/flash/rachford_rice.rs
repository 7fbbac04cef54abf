//! The Rachford–Rice equation of an isothermal flash with given K-values.

use crate::ThermoError;

/// Solution of the Rachford–Rice equation restricted to `0 ≤ β ≤ 1`.
#[derive(Debug, Clone, PartialEq)]
pub struct RachfordRice {
    /// Vapour fraction β [-].
    pub beta: f64,
    /// Liquid composition `x_i = z_i / (1 + β (K_i − 1))` (normalised).
    pub x: Vec<f64>,
    /// Vapour composition `y_i = K_i x_i` (normalised).
    pub y: Vec<f64>,
    /// Newton/bisection iterations used (0 for a single phase).
    pub iterations: usize,
}

/// `f(β) = Σ z_i (K_i − 1) / (1 + β (K_i − 1))` and `f'(β)`.
fn rr(z: &[f64], k: &[f64], beta: f64) -> (f64, f64) {
    let mut f = 0.0;
    let mut df = 0.0;
    for (zi, ki) in z.iter().zip(k) {
        if *zi == 0.0 {
            continue;
        }
        let km1 = ki - 1.0;
        let d = 1.0 + beta * km1;
        let t = zi * km1 / d;
        f += t;
        df -= t * km1 / d;
    }
    (f, df)
}

/// Solve `Σ z_i (K_i − 1) / (1 + β (K_i − 1)) = 0` for the vapour fraction β.
///
/// `f(β)` decreases monotonically, so: `f(0) = Σ z_i K_i − 1 ≤ 0` means subcooled or saturated
/// liquid (β = 0, `y` is the incipient vapour `K_i z_i` normalised); `f(1) = 1 − Σ z_i/K_i ≥ 0` means
/// superheated or saturated vapour (β = 1, `x` is the incipient liquid `z_i/K_i` normalised);
/// otherwise the root in (0, 1) is found by Newton's method safeguarded by bisection and converged
/// until the step is below `1e-16` or the bracket is two ulps wide. By construction
/// `β y_i + (1 − β) x_i = z_i` up to rounding.
///
/// `z` must be a normalised composition and every `K_i` non-negative and finite (else
/// `BadInput`); a zero K-value is a non-volatile component.
pub fn rachford_rice(z: &[f64], k: &[f64]) -> Result<RachfordRice, ThermoError> {
    let bad = |reason: String| ThermoError::BadInput { routine: "rachford_rice", reason };
    if z.len() != k.len() || z.is_empty() {
        return Err(bad(format!("{} mole fractions but {} K-values", z.len(), k.len())));
    }
    if let Some(ki) = k.iter().find(|ki| !(ki.is_finite() && **ki >= 0.0)) {
        return Err(bad(format!("K-values must be non-negative and finite, got {ki} in {k:?}")));
    }
    if let Some(zi) = z.iter().find(|zi| !(zi.is_finite() && **zi >= 0.0)) {
        return Err(bad(format!("mole fractions must be non-negative and finite, got {zi} in {z:?}")));
    }
    let split = |beta: f64| {
        let mut x: Vec<f64> =
            z.iter().zip(k).map(|(zi, ki)| if *zi > 0.0 { zi / (1.0 + beta * (ki - 1.0)) } else { 0.0 }).collect();
        let mut y: Vec<f64> = x.iter().zip(k).map(|(xi, ki)| xi * ki).collect();
        normalise(&mut x);
        normalise(&mut y);
        (x, y)
    };
    let (f0, _) = rr(z, k, 0.0);
    if f0 <= 0.0 {
        let (x, y) = split(0.0);
        return Ok(RachfordRice { beta: 0.0, x, y, iterations: 0 });
    }
    let (f1, _) = rr(z, k, 1.0);
    if f1 >= 0.0 {
        let (x, y) = split(1.0);
        return Ok(RachfordRice { beta: 1.0, x, y, iterations: 0 });
    }
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    // Start from the linear interpolation of f between the ends.
    let mut beta = (f0 / (f0 - f1)).clamp(1e-3, 1.0 - 1e-3);
    for it in 1..=200 {
        let (f, df) = rr(z, k, beta);
        if f == 0.0 {
            let (x, y) = split(beta);
            return Ok(RachfordRice { beta, x, y, iterations: it });
        }
        if f > 0.0 {
            lo = beta;
        } else {
            hi = beta;
        }
        let mut next = beta - f / df;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        let step = (next - beta).abs();
        beta = next;
        if step <= 1e-16 || hi - lo <= 2.0 * f64::EPSILON * beta.max(f64::MIN_POSITIVE) {
            let (x, y) = split(beta);
            return Ok(RachfordRice { beta, x, y, iterations: it });
        }
    }
    Err(ThermoError::NoConvergence {
        routine: "rachford_rice",
        iterations: 200,
        residual: rr(z, k, beta).0,
        conditions: format!("z = {z:?}, K = {k:?}"),
    })
}

/// Scale `v` to unit sum (left unchanged when the sum is not positive).
pub(crate) fn normalise(v: &mut [f64]) {
    let s: f64 = v.iter().sum();
    if s > 0.0 && s.is_finite() {
        v.iter_mut().for_each(|x| *x /= s);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn binary_closed_form() {
        // Binary closed form: x1 = (1 − K2)/(K1 − K2), y1 = K1 x1, β = (z1 − x1)/(y1 − x1).
        let (k1, k2, z1) = (2.5, 0.4, 0.45);
        let r = rachford_rice(&[z1, 1.0 - z1], &[k1, k2]).unwrap();
        let x1 = (1.0 - k2) / (k1 - k2);
        let beta = (z1 - x1) / (k1 * x1 - x1);
        assert!((r.x[0] - x1).abs() < 1e-15);
        assert!((r.beta - beta).abs() < 1e-14);
    }
}
