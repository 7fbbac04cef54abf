//! Distillation columns against published steady states.

use crate::harness::{component_balance_error, converge, value};

/// Skogestad column A (S&P 2005 §12.4): yD = 0.99 and xB = 0.01 at L = 2.70629, V = 3.20629
/// kmol/min; the published model is the same model, so 1e-6 absolute.
#[test]
fn column_a_reproduces_published_compositions() {
    let (plant, ss) = converge("column_a.json");
    let yd = value(&plant, &ss.x, "distillate.x[light]");
    let xb = value(&plant, &ss.x, "bottoms.x[light]");
    assert!((yd - 0.99).abs() < 1e-6, "yD = {yd}");
    assert!((xb - 0.01).abs() < 1e-6, "xB = {xb}");
    // Level loops are P-only at their bias: holdups sit exactly at M0 = 0.5 kmol, D = B = 0.5 kmol/min.
    assert!((value(&plant, &ss.x, "column.M[41]") - 500.0).abs() < 1e-6);
    assert!((value(&plant, &ss.x, "distillate.F") - 1000.0 / 60.0 * 0.5).abs() < 1e-9);
    assert!(component_balance_error(&plant, &ss.x, &[]) < 1e-10);
    assert!(ss.report.iterations <= 10, "cold start took {} iterations", ss.report.iterations);
}

/// Luyben (ed.) 1992, Example 4-1, Table 4-2: xD = 0.992849, xB = 0.004767.
#[test]
fn example_4_1_reproduces_published_compositions() {
    let (plant, ss) = converge("example_4_1.json");
    let xd = value(&plant, &ss.x, "distillate.x[light]");
    let xb = value(&plant, &ss.x, "bottoms.x[light]");
    assert!((xd - 0.992849).abs() < 1e-6, "xD = {xd}");
    assert!((xb - 0.004767).abs() < 1e-6, "xB = {xb}");
    assert!(component_balance_error(&plant, &ss.x, &[]) < 1e-10);
}
