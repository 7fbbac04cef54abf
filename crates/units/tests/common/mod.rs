//! Shared helpers for the integration tests.

/// Asserts `|actual - expected| <= rel * |expected|` (or `<= rel` when `expected` is 0).
#[track_caller]
pub fn assert_close(actual: f64, expected: f64, rel: f64, what: &str) {
    let scale = expected.abs().max(f64::MIN_POSITIVE);
    let ok = if expected == 0.0 { actual.abs() <= rel } else { (actual - expected).abs() <= rel * scale };
    assert!(ok, "{what}: got {actual:e}, expected {expected:e} (rel {rel:e})");
}
