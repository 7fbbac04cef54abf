//! Tray hydraulics of the rigorous column: the Francis weir on the clear liquid.
//!
//! Liquid over the outlet weir `Q = 1.84 l_w h_ow^{3/2}` [m³/s] (Francis's formula in SI; 3.33 ft^½/s
//! in US units), `h_ow` [m] the crest over a weir of length `l_w` [m]. The crest is the clear-liquid
//! height on the tray above the weir height, `M v_L / A − h_w`, smoothed where it crosses zero.

use crate::Scalar;

/// Francis-weir coefficient [m^½/s]: `Q = 1.84 l_w h_ow^{3/2}` (SI form of Francis's 3.33 ft^½/s).
pub const FRANCIS: f64 = 1.84;
/// Half-width δ [m] of the band where the crest `max(0, z)` is smoothed (exact for |z| ≥ δ).
pub const CREST_SMOOTH: f64 = 1e-3;

/// Tray hydraulics: the Francis weir on the clear liquid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weir {
    /// Weir length l_w [m].
    pub length: f64,
    /// Weir height h_w [m].
    pub height: f64,
    /// Tray active area A [m²].
    pub area: f64,
}

impl Weir {
    /// Liquid flow [mol/s] over the weir from a holdup `m` [mol] of molar volume `v` [m³/mol]:
    /// `1.84 l_w ĥ^{3/2} / v` with `ĥ = smax(m v / A − h_w)`; `smax(z) = z` for `z ≥ δ`, 0 for
    /// `z ≤ −δ` and `(z + δ)²/(4δ)` between (C¹), `δ` = [`CREST_SMOOTH`].
    pub fn flow<S: Scalar>(&self, m: S, v: S) -> S {
        let z = m * v / self.area - self.height;
        let d = CREST_SMOOTH;
        let crest15 = if z.re() >= d {
            z * z.sqrt()
        } else if z.re() <= -d {
            S::from(0.0)
        } else {
            let w = z + d;
            w * w * w / (8.0 * d * d.sqrt())
        };
        crest15 * (FRANCIS * self.length) / v
    }
    /// Holdup [mol] at which the weir passes `l` [mol/s] of molar volume `v` [m³/mol] (the inverse
    /// of [`Weir::flow`]; `A (h_w − δ) / v` for no flow).
    pub fn holdup(&self, l: f64, v: f64) -> f64 {
        let d = CREST_SMOOTH;
        let crest15 = (l * v / (FRANCIS * self.length)).max(0.0);
        let z = if crest15 >= d * d.sqrt() { crest15.powf(2.0 / 3.0) } else { 2.0 * d.sqrt() * crest15.cbrt() - d };
        (z + self.height) * self.area / v
    }
}
