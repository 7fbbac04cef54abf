//! Data checks and pre-processing (§2.10: remove sample means, "detrend").

use crate::error::IdentError;

/// Maximum length of any generated or simulated series (samples).
pub const MAX_LEN: usize = 10_000_000;
/// Maximum number of inputs of a MISO model.
pub const MAX_INPUTS: usize = 16;
/// Maximum polynomial order (na, nb, nf) of ARX / OE models.
pub const MAX_ORDER: usize = 50;
/// Maximum number of FIR coefficients per input (the book uses 30–100, §2.4).
pub const MAX_FIR: usize = 500;
/// Maximum input delay nk (samples).
pub const MAX_DELAY: usize = 1000;
/// Maximum number of elements of a regression matrix (rows × parameters).
pub const MAX_REGRESSION: usize = 40_000_000;

/// Removes the sample mean: x'(t) = x(t) − x̄ (§2.10, "detrend").
pub fn detrend(x: &[f64]) -> Vec<f64> {
    if x.is_empty() {
        return Vec::new();
    }
    let m = x.iter().sum::<f64>() / x.len() as f64;
    x.iter().map(|v| v - m).collect()
}

/// [`detrend`] applied to every series of a multi-input record.
pub fn detrend_all(u: &[Vec<f64>]) -> Vec<Vec<f64>> {
    u.iter().map(|s| detrend(s)).collect()
}

/// Checks that a series is finite.
pub(crate) fn check_finite(x: &[f64], name: &str) -> Result<(), IdentError> {
    match x.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(IdentError::NonFinite { name: name.to_string(), index }),
        None => Ok(()),
    }
}

/// Validates MISO data: 1..=[`MAX_INPUTS`] inputs, every input as long as `y`, all finite,
/// and no input constant (an input that does not move makes the regression rank deficient;
/// "constant" = max − min ≤ 1e-12·max(1, max|u|)). Returns N.
pub(crate) fn check_miso(u: &[Vec<f64>], y: &[f64]) -> Result<usize, IdentError> {
    if u.is_empty() || u.len() > MAX_INPUTS {
        return Err(IdentError::BadOrder {
            field: "u (number of inputs)".into(),
            value: u.len(),
            reason: "must be 1..=16",
        });
    }
    let n = y.len();
    check_finite(y, "y")?;
    for (j, uj) in u.iter().enumerate() {
        if uj.len() != n {
            return Err(IdentError::LengthMismatch { name: format!("u[{j}]"), expected: n, got: uj.len() });
        }
        check_finite(uj, &format!("u[{j}]"))?;
        if n > 0 && is_constant(uj) {
            return Err(IdentError::ConstantInput { input: j });
        }
    }
    Ok(n)
}

/// True if the series does not move (see [`check_miso`]).
pub(crate) fn is_constant(x: &[f64]) -> bool {
    let (lo, hi) = x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let scale = lo.abs().max(hi.abs()).max(1.0);
    hi - lo <= 1e-12 * scale
}

/// Checks a per-input delay vector: one entry per input, each ≤ [`MAX_DELAY`].
pub(crate) fn check_nk(nk: &[usize], nu: usize) -> Result<(), IdentError> {
    if nk.len() != nu {
        return Err(IdentError::LengthMismatch { name: "nk".into(), expected: nu, got: nk.len() });
    }
    for (j, &d) in nk.iter().enumerate() {
        if d > MAX_DELAY {
            return Err(IdentError::BadOrder {
                field: format!("nk[{j}]"),
                value: d,
                reason: "delay must be <= 1000 samples",
            });
        }
    }
    Ok(())
}

/// Checks an order against 0..=[`MAX_ORDER`] (or 1..= if `min1`).
pub(crate) fn check_order(field: &str, value: usize, min1: bool) -> Result<(), IdentError> {
    if value > MAX_ORDER || (min1 && value == 0) {
        return Err(IdentError::BadOrder {
            field: field.into(),
            value,
            reason: if min1 { "must be 1..=50" } else { "must be 0..=50" },
        });
    }
    Ok(())
}

/// Requires `rows` regression rows for `d` parameters with a margin:
/// rows ≥ d + max(d, 10), i.e. at least as many residual degrees of freedom as parameters.
pub(crate) fn check_rows(what: &'static str, rows: usize, d: usize) -> Result<(), IdentError> {
    let needed = d + d.max(10);
    if rows < needed {
        return Err(IdentError::TooShort { what, needed, got: rows });
    }
    match rows.checked_mul(d) {
        Some(e) if e <= MAX_REGRESSION => Ok(()),
        _ => Err(IdentError::TooLarge {
            what: "regression matrix (rows x parameters)",
            limit: MAX_REGRESSION,
            got: rows.saturating_mul(d),
        }),
    }
}

/// Checks a requested series length against [`MAX_LEN`].
pub(crate) fn check_len(len: usize) -> Result<(), IdentError> {
    if len > MAX_LEN {
        return Err(IdentError::TooLarge { what: "series length", limit: MAX_LEN, got: len });
    }
    Ok(())
}
