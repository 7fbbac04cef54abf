//! System identification for plantwide control (spec: reference chapter 7, *Practical
//! Distillation Control*, §7-2 to §7-6; see `shared/reference/control-rules-and-identification.md`
//! §2.1–2.10).
//!
//! * [`signals`]: PRBS design (Eq 7-5 to 7-10), LFSR PRBS, GBN, white noise, and the
//!   Koung & MacGregor directional design for ill-conditioned plants.
//! * [`fir`], [`arx`], [`oe`]: MISO prediction-error estimation (Eq 7-27 to 7-38, 7-50, 7-51,
//!   7-66), FOPTD fits and step responses.
//! * [`validate`]: fit percentage, residual auto- and cross-correlation tests (Eq 7-17,
//!   7-59, 7-60).
//!
//! All data are deviation variables (see [`data::detrend`]). Results serialize to JSON.

pub mod arx;
pub mod data;
pub mod error;
pub mod fir;
pub mod foptd;
pub mod linalg;
pub mod oe;
pub mod signals;
pub mod validate;

pub use arx::{ArxModel, OrderScore, arx, arx_select, predict_arx, simulate_arx};
pub use data::{detrend, detrend_all};
pub use error::IdentError;
pub use fir::{FirModel, fir};
pub use foptd::{Foptd, foptd};
pub use linalg::stabilized;
pub use oe::{OeModel, OeOptions, oe, oe_with_options, simulate_oe};
pub use signals::{DirectionalDesign, PrbsDesign, design_prbs, directional, gbn, prbs, prbs_spectrum, white_noise};
pub use validate::{Validation, autocorrelation, cross_correlation, fit_percent, validate};

/// Step response of a fitted model, one series per input (response of y to a unit step in
/// that input at t = 0, the other inputs held at zero).
pub trait StepResponse {
    /// Step response over `n` samples (`n` ≤ [`data::MAX_LEN`]).
    fn step_response(&self, n: usize) -> Result<Vec<Vec<f64>>, IdentError>;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_serialize_to_json() {
        let n = 400;
        let u = vec![gbn(n, 6.0, 1).unwrap()];
        let e = white_noise(n, 0.05, 2).unwrap();
        let mut y = vec![0.0; n];
        for t in 1..n {
            y[t] = 0.7 * y[t - 1] + 0.3 * u[0][t - 1];
        }
        y.iter_mut().zip(&e).for_each(|(a, b)| *a += b);
        let m = oe(&u, &y, 1, 1, &[1], None).unwrap();
        let a = arx(&u, &y, 1, 1, &[1]).unwrap();
        let f = fir(&u, &y, 20, 1, 0.0).unwrap();
        let yhat = simulate_oe(&m, &u).unwrap();
        let v = validate(&y, &yhat, &u, 10).unwrap();
        let d = design_prbs(100.0, 20.0, 1.0, 3.0, 1.0, 2, 0.0).unwrap();
        for s in [
            serde_json::to_string(&m).unwrap(),
            serde_json::to_string(&a).unwrap(),
            serde_json::to_string(&f).unwrap(),
            serde_json::to_string(&v).unwrap(),
            serde_json::to_string(&d).unwrap(),
            serde_json::to_string(&IdentError::ConstantInput { input: 2 }).unwrap(),
        ] {
            assert!(s.starts_with('{'), "{s}");
        }
        let back: PrbsDesign = serde_json::from_str(&serde_json::to_string(&d).unwrap()).unwrap();
        assert_eq!(back, d);
        let back: OeModel = serde_json::from_str(&serde_json::to_string(&m).unwrap()).unwrap();
        assert_eq!(back.nk, m.nk);
        assert!((back.gain[0] - 1.0).abs() < 0.05, "{}", back.gain[0]);
    }
}
