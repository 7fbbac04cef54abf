//! Model-based PI/PID rules on a fitted low-order model ([`super::fit::ProcessModel`]).
//!
//! **SIMC** (Skogestad 2003, J. Process Control 13, 291–309, Table 3), with closed-loop time
//! constant `τ_c` (default `τ_c = θ`, "tight control" with good robustness):
//! - FOPTD, PI: `K_c = τ₁ / (k (τ_c + θ))`, `τ_I = min(τ₁, 4 (τ_c + θ))`;
//! - SOPTD, PID in series form `K_c (1 + 1/(τ_I s)) (τ_D s + 1)`: the same `K_c`, `τ_I` and
//!   `τ_D = τ₂`; a PI of a SOPTD model uses Skogestad's half rule first (`τ₁ + τ₂/2`, `θ + τ₂/2`);
//! - integrating `k' e^(−θs)/s`: `K_c = 1 / (k' (τ_c + θ))`, `τ_I = 4 (τ_c + θ)`.
//!
//! **IMC** (Rivera, Morari & Skogestad 1986, Ind. Eng. Chem. Process Des. Dev. 25, 252), filter
//! `1/(λ s + 1)` (default `λ = θ`):
//! - FOPTD, PI from `e^(−θs) ≈ 1 − θs`: `K_c = τ / (k (λ + θ))`, `τ_I = τ`;
//! - FOPTD, PID from the first-order Padé approximation: `K_c = (τ + θ/2) / (k (λ + θ/2))`,
//!   `τ_I = τ + θ/2`, `τ_D = τθ / (2τ + θ)` (ideal form);
//! - SOPTD, PID from `1 − θs`: `K_c = (τ₁ + τ₂) / (k (λ + θ))`, `τ_I = τ₁ + τ₂`,
//!   `τ_D = τ₁τ₂ / (τ₁ + τ₂)` (ideal form); a SOPTD PI uses the half rule first;
//! - integrating, from `1 − θs` with the filter `((2λ + θ) s + 1)/(λ s + 1)²` (the lead makes
//!   `1 − g̃q` vanish twice at `s = 0`, so a ramp disturbance leaves no offset):
//!   `K_c = (2λ + θ) / (k' (λ + θ)²)`, `τ_I = 2λ + θ`.
//!
//! The plant's PID is in ideal (ISA) form `K_c (1 + 1/(τ_I s) + τ_D s)`; series settings convert
//! exactly by `K_c' = K_c (1 + τ_D/τ_I)`, `τ_I' = τ_I + τ_D`, `τ_D' = τ_I τ_D / (τ_I + τ_D)`.

use serde::Serialize;

use super::fit::ProcessModel;

/// Which model-based rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelRule {
    /// Skogestad's SIMC.
    Simc,
    /// Internal model control.
    Imc,
}

/// PI or PID settings in ideal (ISA) form: `K_c (1 + 1/(τ_I s) + τ_D s)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PidSettings {
    /// Controller gain (input units per output unit; the sign of the process gain).
    pub kc: f64,
    /// Reset time \[s\].
    pub tau_i: f64,
    /// Derivative time \[s\] (`None` for PI).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tau_d: Option<f64>,
    /// The closed-loop time constant `τ_c` (SIMC) or filter time `λ` (IMC) used \[s\].
    pub tau_c: f64,
}

/// Why a rule cannot be applied.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RuleError {
    /// The model has no dead time (below a thousandth of its lag) and no `τ_c` was given.
    #[error(
        "the fitted model has no dead time, so the default closed-loop time constant τc = θ is zero; give \
         the loop's measurement dead time (`measurement_dead_time`, an analyzer's: it adds to θ) or `tau_c` \
         (a time about the dead time of the loop's measurement and valve, or a fraction of τ)"
    )]
    NoDeadTime,
    /// A gain or time of the model or `τ_c` is zero, negative or not finite.
    #[error("{what} = {} cannot be tuned for; {fix}", plantwide_model::limits::number(*.value))]
    Degenerate {
        /// The quantity.
        what: &'static str,
        /// Its value.
        value: f64,
        /// What to change.
        fix: &'static str,
    },
}

/// PI settings (`derivative = false`) or PID settings of `model` by `rule`, with closed-loop
/// time constant `tau_c` (default: the model's dead time).
///
/// # Errors
/// [`RuleError`] for a degenerate model or closed-loop time.
pub fn model_rule(
    rule: ModelRule,
    model: &ProcessModel,
    tau_c: Option<f64>,
    derivative: bool,
) -> Result<PidSettings, RuleError> {
    let k = model.gain();
    if !(k.is_finite() && k != 0.0) {
        return Err(RuleError::Degenerate {
            what: "the model gain",
            value: k,
            fix: "check that the input reaches the output",
        });
    }
    let model = if derivative { *model } else { half_rule(model) };
    let theta = model.dead_time();
    let tc = match tau_c {
        Some(t) => t,
        None if theta > 1e-3 * lag(&model) => theta,
        None => return Err(RuleError::NoDeadTime),
    };
    if !(tc.is_finite() && tc > 0.0) {
        return Err(RuleError::Degenerate { what: "τc", value: tc, fix: "give a positive closed-loop time constant" });
    }
    let (kc, tau_i, tau_d) = match rule {
        ModelRule::Simc => simc(&model, tc),
        ModelRule::Imc => imc(&model, tc, derivative),
    };
    Ok(PidSettings { kc, tau_i, tau_d, tau_c: tc })
}

/// The model's dominant lag \[s\]: a fitted dead time below a thousandth of it is no dead time to
/// tune for. An integrator has no lag of its own; there a dead time under a millisecond is the
/// fit's rounding (1 ms = 1e-3 × 1 s).
fn lag(model: &ProcessModel) -> f64 {
    match *model {
        ProcessModel::Foptd { tau, .. } => tau,
        ProcessModel::Soptd { tau1, .. } => tau1,
        ProcessModel::Integrating { .. } => 1.0,
    }
}

/// The dead time a rule tunes `model` for \[s\]: `θ` after Skogestad's half rule for a PI
/// (`derivative` false), `θ` as fitted for a PID, the default `τc`.
pub fn tuned_dead_time(model: &ProcessModel, derivative: bool) -> f64 {
    if derivative { model.dead_time() } else { half_rule(model).dead_time() }
}

/// Skogestad's half rule on a SOPTD model (half of `τ₂` to `τ₁`, half to the dead time); other
/// models unchanged.
fn half_rule(model: &ProcessModel) -> ProcessModel {
    match *model {
        ProcessModel::Soptd { k, tau1, tau2, theta } => {
            ProcessModel::Foptd { k, tau: tau1 + 0.5 * tau2, theta: theta + 0.5 * tau2 }
        }
        m => m,
    }
}

/// SIMC `(K_c, τ_I, τ_D)`, ideal form.
fn simc(model: &ProcessModel, tc: f64) -> (f64, f64, Option<f64>) {
    match *model {
        ProcessModel::Foptd { k, tau, theta } => (tau / (k * (tc + theta)), tau.min(4.0 * (tc + theta)), None),
        ProcessModel::Soptd { k, tau1, tau2, theta } => {
            let (kc, ti, td) = (tau1 / (k * (tc + theta)), tau1.min(4.0 * (tc + theta)), tau2);
            let (kc, ti, td) = series_to_ideal(kc, ti, td);
            (kc, ti, Some(td))
        }
        ProcessModel::Integrating { k, theta } => (1.0 / (k * (tc + theta)), 4.0 * (tc + theta), None),
    }
}

/// IMC `(K_c, τ_I, τ_D)`, ideal form.
fn imc(model: &ProcessModel, lambda: f64, derivative: bool) -> (f64, f64, Option<f64>) {
    match *model {
        ProcessModel::Foptd { k, tau, theta } if derivative => {
            let ti = tau + 0.5 * theta;
            (ti / (k * (lambda + 0.5 * theta)), ti, Some(tau * theta / (2.0 * tau + theta)))
        }
        ProcessModel::Foptd { k, tau, theta } => (tau / (k * (lambda + theta)), tau, None),
        ProcessModel::Soptd { k, tau1, tau2, theta } => {
            let ti = tau1 + tau2;
            (ti / (k * (lambda + theta)), ti, Some(tau1 * tau2 / ti))
        }
        ProcessModel::Integrating { k, theta } => {
            let ti = 2.0 * lambda + theta;
            (ti / (k * (lambda + theta).powi(2)), ti, None)
        }
    }
}

/// Series-form PID `K_c (1 + 1/(τ_I s))(τ_D s + 1)` as ideal form: expanding,
/// `K_c [(1 + τ_D/τ_I) + 1/(τ_I s) + τ_D s]`.
pub fn series_to_ideal(kc: f64, tau_i: f64, tau_d: f64) -> (f64, f64, f64) {
    let f = 1.0 + tau_d / tau_i;
    (kc * f, tau_i * f, tau_d / f)
}

#[cfg(test)]
mod tests {
    use faer::c64;

    use super::*;
    use crate::tune::margins::{margins, pid};

    /// `g(jω)` of a model.
    fn g(model: &ProcessModel, w: f64) -> c64 {
        let s = c64::new(0.0, w);
        let delay = (-s * model.dead_time()).exp();
        let one = c64::new(1.0, 0.0);
        match *model {
            ProcessModel::Foptd { k, tau, .. } => delay * k / (s * tau + one),
            ProcessModel::Soptd { k, tau1, tau2, .. } => delay * k / ((s * tau1 + one) * (s * tau2 + one)),
            ProcessModel::Integrating { k, .. } => delay * k / s,
        }
    }

    /// The ideal-form PID `c(jω)` (no derivative filter).
    fn c(p: &PidSettings, w: f64) -> c64 {
        pid(p.kc, Some(p.tau_i), p.tau_d, w)
    }

    #[test]
    fn simc_on_a_lag_dominant_foptd_gives_its_published_margins() {
        // τ₁ ≤ 8θ: τ_I = τ₁ cancels the lag and the loop is e^(−θs)/(2θ s), whatever k and τ₁:
        // phase crossover at ω = π/(2θ) where |L| = 1/π, so GM = π; |L| = 1 at ω = 1/(2θ) with
        // phase −π/2 − 1/2, so PM = 90° − 28.65° = 61.35° (Skogestad 2003, Table 4: GM 3.14, PM 61.4°).
        let model = ProcessModel::Foptd { k: 2.0, tau: 10.0, theta: 2.0 };
        let p = model_rule(ModelRule::Simc, &model, None, false).unwrap();
        assert!((p.kc - 10.0 / (2.0 * 4.0)).abs() < 1e-15 && p.tau_i == 10.0 && p.tau_c == 2.0, "{p:?}");
        let gm = margins(|w| g(&model, w) * c(&p, w), 0.5, 1.0).gain_margin.expect("a phase crossover");
        assert!((gm - std::f64::consts::PI).abs() < 1e-9, "{gm}");
        let w = 1.0 / (2.0 * 2.0);
        let l = g(&model, w) * c(&p, w);
        assert!((l.norm() - 1.0).abs() < 1e-12, "{l}");
        let pm = 180.0 + l.arg().to_degrees();
        assert!((pm - (90.0 - 0.5f64.to_degrees())).abs() < 1e-9, "{pm}");
    }

    #[test]
    fn simc_clips_the_reset_time_of_a_slow_lag() {
        let model = ProcessModel::Foptd { k: -0.5, tau: 100.0, theta: 1.0 };
        let p = model_rule(ModelRule::Simc, &model, Some(2.0), false).unwrap();
        assert_eq!(p.tau_i, 12.0);
        assert!((p.kc - 100.0 / (-0.5 * 3.0)).abs() < 1e-12, "{p:?}");
    }

    #[test]
    fn simc_pid_of_a_soptd_is_the_series_form_converted() {
        let model = ProcessModel::Soptd { k: 1.0, tau1: 20.0, tau2: 5.0, theta: 1.0 };
        let p = model_rule(ModelRule::Simc, &model, None, true).unwrap();
        // Series: K_c = 20/2 = 10, τ_I = min(20, 8) = 8, τ_D = 5; ideal: ×(1 + 5/8).
        let f = 1.0 + 5.0 / 8.0;
        assert!((p.kc - 10.0 * f).abs() < 1e-12 && (p.tau_i - 8.0 * f).abs() < 1e-12, "{p:?}");
        assert!((p.tau_d.unwrap() - 5.0 / f).abs() < 1e-12, "{p:?}");
        // The ideal form equals the series form at every frequency.
        for w in [1e-3, 0.1, 1.0, 10.0] {
            let s = c64::new(0.0, w);
            let one = c64::new(1.0, 0.0);
            let series = (one + (s * 8.0).inv()) * (s * 5.0 + one) * 10.0;
            assert!((series - c(&p, w)).norm() < 1e-12 * series.norm());
        }
    }

    #[test]
    fn simc_pi_of_a_soptd_uses_the_half_rule() {
        let model = ProcessModel::Soptd { k: 1.0, tau1: 20.0, tau2: 4.0, theta: 1.0 };
        let p = model_rule(ModelRule::Simc, &model, None, false).unwrap();
        // FOPTD τ = 22, θ = 3; τ_c = 3: K_c = 22/6, τ_I = min(22, 24) = 22.
        assert!((p.kc - 22.0 / 6.0).abs() < 1e-12 && p.tau_i == 22.0 && p.tau_d.is_none(), "{p:?}");
    }

    #[test]
    fn imc_pi_and_pid_cancel_the_lags() {
        let model = ProcessModel::Foptd { k: 2.0, tau: 10.0, theta: 2.0 };
        let pi = model_rule(ModelRule::Imc, &model, Some(3.0), false).unwrap();
        assert!((pi.kc - 10.0 / (2.0 * 5.0)).abs() < 1e-15 && pi.tau_i == 10.0, "{pi:?}");
        // The Padé PID makes the loop with the Padé model exactly (1 − θs/2)/((λ + θ/2) s):
        // check that identity with the Padé approximant in place of the delay.
        let pid = model_rule(ModelRule::Imc, &model, Some(3.0), true).unwrap();
        for w in [0.01, 0.3, 2.0] {
            let s = c64::new(0.0, w);
            let one = c64::new(1.0, 0.0);
            let pade = (one - s * 1.0) / (one + s * 1.0);
            let loop_ = pade * 2.0 / (s * 10.0 + one) * c(&pid, w);
            let target = (one - s * 1.0) / (s * (3.0 + 1.0));
            assert!((loop_ - target).norm() < 1e-12 * target.norm(), "{w}: {loop_} vs {target}");
        }
    }

    #[test]
    fn imc_on_an_integrator_gives_the_critically_damped_target() {
        // With 1 − θs and the filter ((2λ+θ)s + 1)/(λs + 1)², the nominal closed loop without delay
        // (θ = 0) is ((2λ)s + 1)/(λs + 1)²: its characteristic polynomial is (λs + 1)².
        let model = ProcessModel::Integrating { k: 0.01, theta: 0.0 };
        let p = model_rule(ModelRule::Imc, &model, Some(5.0), false).unwrap();
        // 1 + k c(s)/s = 0 → τ_I s² + k K_c τ_I s + k K_c = 0, compare with τ_I (λs + 1)²/λ².
        let (a, b) = (0.01 * p.kc, 0.01 * p.kc / p.tau_i);
        assert!((a - 2.0 / 5.0).abs() < 1e-14 && (b - 1.0 / 25.0).abs() < 1e-14, "{p:?}");
    }

    #[test]
    fn degenerate_models_are_refused() {
        let no_delay = ProcessModel::Foptd { k: 1.0, tau: 5.0, theta: 0.0 };
        assert_eq!(model_rule(ModelRule::Simc, &no_delay, None, false), Err(RuleError::NoDeadTime));
        // A fitted dead time of rounding size is none either (it would make τc = θ absurd).
        let fitted = ProcessModel::Foptd { k: 1.0, tau: 700.0, theta: 2e-12 };
        assert_eq!(model_rule(ModelRule::Simc, &fitted, None, false), Err(RuleError::NoDeadTime));
        assert!(model_rule(ModelRule::Simc, &no_delay, Some(1.0), false).is_ok());
        let dead = ProcessModel::Foptd { k: 0.0, tau: 5.0, theta: 1.0 };
        assert!(matches!(model_rule(ModelRule::Imc, &dead, None, false), Err(RuleError::Degenerate { .. })));
    }
}
