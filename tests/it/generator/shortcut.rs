//! The shortcut design a process engineer does before writing a column into a flowsheet (binary,
//! constant relative volatility): Fenske's minimum stages, Underwood's minimum reflux, Gilliland's
//! correlation (Molokanov's form) for the stages a reflux needs, Kirkbride's feed location.

/// The two products' purities (light key in the distillate, in the bottoms).
#[derive(Debug, Clone, Copy)]
pub struct Split {
    /// Light mole fraction of the distillate.
    pub xd: f64,
    /// Light mole fraction of the bottoms.
    pub xb: f64,
}

/// Fenske: `N_min = ln[(xD/(1−xD)) ((1−xB)/xB)] / ln α` (equilibrium stages at total reflux).
pub fn fenske(alpha: f64, s: Split) -> f64 {
    ((s.xd / (1.0 - s.xd)) * ((1.0 - s.xb) / s.xb)).ln() / alpha.ln()
}

/// Underwood's minimum reflux ratio for a binary feed `zf` of quality `q`: θ in (1, α) solves
/// `α zF/(α − θ) + (1 − zF)/(1 − θ) = 1 − q`, then `R_min + 1 = α xD/(α − θ) + (1 − xD)/(1 − θ)`,
/// at least 0.1.
pub fn underwood(alpha: f64, zf: f64, q: f64, xd: f64) -> f64 {
    let f = |t: f64| alpha * zf / (alpha - t) + (1.0 - zf) / (1.0 - t) - (1.0 - q);
    // f rises from −∞ just above 1 to +∞ just below α: bisection.
    let (mut lo, mut hi) = (1.0 + 1e-12, alpha - 1e-12);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) < 0.0 { lo = mid } else { hi = mid }
    }
    let t = 0.5 * (lo + hi);
    // A rich feed whose equilibrium vapour is already purer than the distillate gives R_min ≤ 0
    // (methanol–water at zF 0.68 for xD 0.90); a column still refluxes, at least a tenth of its
    // distillate.
    (alpha * xd / (alpha - t) + (1.0 - xd) / (1.0 - t) - 1.0).max(0.1)
}

/// Gilliland (Molokanov 1972): the equilibrium stages a reflux ratio `r` needs, given `n_min` and
/// `r_min`: `Y = 1 − exp[(1 + 54.4X)/(11 + 117.2X) · (X − 1)/√X]`, `X = (R − R_min)/(R + 1)`,
/// `N = (N_min + Y)/(1 − Y)`.
pub fn gilliland(n_min: f64, r_min: f64, r: f64) -> f64 {
    let x = ((r - r_min) / (r + 1.0)).max(1e-9);
    let y = 1.0 - (((1.0 + 54.4 * x) / (11.0 + 117.2 * x)) * ((x - 1.0) / x.sqrt())).exp();
    (n_min + y) / (1.0 - y)
}

/// Kirkbride: the ratio of rectifying to stripping stages,
/// `(B/D · (1 − zF)/zF · (xB/(1 − xD))²)^0.206`.
pub fn kirkbride(zf: f64, s: Split, d_over_b: f64) -> f64 {
    ((1.0 / d_over_b) * ((1.0 - zf) / zf) * (s.xb / (1.0 - s.xd)).powi(2)).powf(0.206)
}

/// The purest impurity a generated design asks for: 99.99 %, the high-purity specifications users
/// write. Below it (the stages and reflux ranges allow 1e-6 and less) users put a column that
/// would reach further on temperature control or fewer stages; such designs are not what the
/// suite is for. (At 1e-5 and below it found the steady solver stalling at a scaled residual of
/// 1e-7, and composition gains beyond the 1e6 mol/s a `kc` may have: reported, not hidden.)
pub const PUREST: f64 = 1e-4;

/// The purest symmetric-in-log split (impurities `δ` at the top, `δ·skew` at the bottom, each
/// at least [`PUREST`]) that `stages` equilibrium stages reach at `m` times the minimum reflux
/// with the margin `margin` (the stages Gilliland asks for over those there are), `δ` kept in
/// `[PUREST, 0.1]`.
pub fn reachable_split(alpha: f64, zf: f64, q: f64, m: f64, stages: f64, skew: f64, margin: f64) -> Split {
    let split = |ln_d: f64| {
        let d = ln_d.exp();
        Split { xd: 1.0 - d, xb: (d * skew).clamp(PUREST, 0.45 * zf) }
    };
    let needs =
        |s: Split| gilliland(fenske(alpha, s), underwood(alpha, zf, q, s.xd), m * underwood(alpha, zf, q, s.xd));
    let (mut lo, mut hi) = (PUREST.ln(), 0.1f64.ln());
    if needs(split(hi)) > margin * stages {
        return split(hi);
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if needs(split(mid)) > margin * stages { lo = mid } else { hi = mid }
    }
    split(hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn column_a_by_the_shortcut() {
        // Column A: α = 1.5, zF = 0.5, q = 1, 99 % / 1 %: N_min = ln(99²)/ln 1.5 = 22.66;
        // R_min = (1/(α − 1)) (xD/zF − α (1 − xD)/(1 − zF)) = 3.9 for a saturated-liquid feed.
        let s = Split { xd: 0.99, xb: 0.01 };
        assert!((fenske(1.5, s) - 22.666).abs() < 1e-3);
        let r_min = (0.99 / 0.5 - 1.5 * 0.01 / 0.5) / 0.5;
        assert!((underwood(1.5, 0.5, 1.0, 0.99) - r_min).abs() < 1e-9, "{}", underwood(1.5, 0.5, 1.0, 0.99));
        // Skogestad's column runs at L/D = 5.41 = 1.39 R_min on 40 equilibrium stages (reboiler
        // and 39 trays): Gilliland's estimate is within two of them.
        let n = gilliland(fenske(1.5, s), r_min, 5.41);
        assert!((n - 40.0).abs() < 2.0, "{n}");
        assert!((gilliland(10.0, 1.0, 1e6) - 10.0).abs() < 0.1);
        let reached = reachable_split(1.5, 0.5, 1.0, 1.39, 40.0, 1.0, 0.8);
        let r_min = underwood(1.5, 0.5, 1.0, reached.xd);
        assert!(
            gilliland(fenske(1.5, reached), r_min, 1.39 * r_min) <= 32.0 + 1e-6 && reached.xd > 0.97,
            "{reached:?}"
        );
    }
}
