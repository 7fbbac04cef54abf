//! Low-order process models fitted to a step response: first order plus dead time (FOPTD),
//! second order plus dead time (SOPTD) and integrating plus dead time (IPDT).
//!
//! Models, for a step `Δu` at `t = 0` and `t' = t − θ ≥ 0` (zero response before the dead time):
//! - FOPTD `k e^(−θs)/(τ s + 1)`: `y = k Δu (1 − e^(−t'/τ))`;
//! - SOPTD `k e^(−θs)/((τ₁ s + 1)(τ₂ s + 1))`, `τ₁ ≥ τ₂`:
//!   `y = k Δu (1 − (τ₁ e^(−t'/τ₁) − τ₂ e^(−t'/τ₂))/(τ₁ − τ₂))`, and `y = k Δu (1 − (1 + t'/τ) e^(−t'/τ))` for `τ₁ = τ₂ = τ`;
//! - IPDT `k e^(−θs)/s`: `y = k Δu t'` (`k` per second).
//!
//! The fit minimises the sum of squared errors over all recorded points. The gain enters linearly,
//! so it is eliminated in closed form (variable projection, Golub & Pereyra 1973): for a shape
//! `s(t; p)`, `k = Σ y s / (Δu Σ s²)`; the shape parameters `p` (log time constants, `|θ|`) are
//! found by Nelder–Mead from several starts, the first from the 28.3 % / 63.2 % times of the
//! response (Smith 1972: `τ = 1.5 (t₆₃ − t₂₈)`, `θ = t₆₃ − τ`).

use serde::Serialize;

use crate::numeric::nelder_mead;

/// A recorded step response.
#[derive(Debug, Clone, PartialEq)]
pub struct StepResponse {
    /// Times since the step \[s\], increasing, starting at 0.
    pub t: Vec<f64>,
    /// The output's deviation from its value before the step (output units).
    pub y: Vec<f64>,
    /// Size of the input step (input units), nonzero.
    pub du: f64,
}

/// Least overshoot or inverse response, as a fraction of the final change, that
/// [`lagless_shape`] reports: an overdamped second-order lag has neither, and a sampled response
/// that has settled within 2e-3 of its end does not reach this by noise.
pub const SHAPE_THRESHOLD: f64 = 0.05;

/// What a settled step response does that no overdamped lag (first or second order, with a dead
/// time) can: overshoot its final value (an underdamped element: a loop or a recycle that rings)
/// or first move the other way (an inverse response), by more than [`SHAPE_THRESHOLD`] of its
/// final change; `None` otherwise or when it has no final change.
pub fn lagless_shape(r: &StepResponse) -> Option<String> {
    let last = *r.y.last()?;
    if !(last != 0.0 && last.is_finite()) {
        return None;
    }
    let along = |y: f64| y / last;
    let peak = r.y.iter().copied().map(along).fold(f64::MIN, f64::max);
    let dip = r.y.iter().copied().map(along).fold(f64::MAX, f64::min);
    if peak - 1.0 > SHAPE_THRESHOLD {
        Some(format!("overshoots its final value by {:.0} % (an underdamped element)", 100.0 * (peak - 1.0)))
    } else if -dip > SHAPE_THRESHOLD {
        Some(format!("first moves the other way, by {:.0} % of its final change (an inverse response)", -100.0 * dip))
    } else {
        None
    }
}

/// Which model to fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelOrder {
    /// First order plus dead time.
    Foptd,
    /// Second order plus dead time.
    Soptd,
    /// Integrating plus dead time.
    Integrating,
}

impl ModelOrder {
    /// The model's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            ModelOrder::Foptd => "first-order-plus-dead-time",
            ModelOrder::Soptd => "second-order-plus-dead-time",
            ModelOrder::Integrating => "integrating-plus-dead-time",
        }
    }
}

/// A fitted low-order model; gains in output units per input unit, times in seconds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum ProcessModel {
    /// `k e^(−θs)/(τ s + 1)`.
    Foptd {
        /// Steady-state gain.
        k: f64,
        /// Time constant \[s\].
        tau: f64,
        /// Dead time \[s\].
        theta: f64,
    },
    /// `k e^(−θs)/((τ₁ s + 1)(τ₂ s + 1))`, `τ₁ ≥ τ₂`.
    Soptd {
        /// Steady-state gain.
        k: f64,
        /// Dominant time constant \[s\].
        tau1: f64,
        /// Second time constant \[s\].
        tau2: f64,
        /// Dead time \[s\].
        theta: f64,
    },
    /// `k e^(−θs)/s`.
    Integrating {
        /// Slope per unit input \[output units per input unit per s\].
        k: f64,
        /// Dead time \[s\].
        theta: f64,
    },
}

impl ProcessModel {
    /// The model seen through a measurement (an analyzer) with dead time `θ_m` and lag `τ_m`:
    /// `θ_m` adds to the dead time; `τ_m` by Skogestad's half rule (*J. Process Control* 13,
    /// 2003, §2): half to the dead time and half to the smallest lag kept, or all of it to the
    /// dead time of an integrating model (which keeps no lag). A lag above the model's own
    /// smallest kept one takes its place, that one then split instead.
    pub fn measured(&self, dead_time: f64, lag: f64) -> ProcessModel {
        match *self {
            ProcessModel::Foptd { k, tau, theta } => {
                let (big, small) = (tau.max(lag), tau.min(lag));
                ProcessModel::Foptd { k, tau: big + 0.5 * small, theta: theta + dead_time + 0.5 * small }
            }
            ProcessModel::Soptd { k, tau1, tau2, theta } => {
                let mut lags = [tau1, tau2, lag];
                lags.sort_by(|a, b| b.total_cmp(a));
                let (tau1, tau2) = (lags[0], lags[1] + 0.5 * lags[2]);
                ProcessModel::Soptd { k, tau1, tau2, theta: theta + dead_time + 0.5 * lags[2] }
            }
            ProcessModel::Integrating { k, theta } => ProcessModel::Integrating { k, theta: theta + dead_time + lag },
        }
    }

    /// The unit-gain step response shape at `t` \[s\] (the response to a unit step divided by `k`).
    pub fn shape(&self, t: f64) -> f64 {
        match *self {
            ProcessModel::Foptd { tau, theta, .. } => foptd_shape(t - theta, tau),
            ProcessModel::Soptd { tau1, tau2, theta, .. } => soptd_shape(t - theta, tau1, tau2),
            ProcessModel::Integrating { theta, .. } => (t - theta).max(0.0),
        }
    }

    /// The gain `k`.
    pub fn gain(&self) -> f64 {
        match *self {
            ProcessModel::Foptd { k, .. } | ProcessModel::Soptd { k, .. } | ProcessModel::Integrating { k, .. } => k,
        }
    }

    /// The dead time θ \[s\].
    pub fn dead_time(&self) -> f64 {
        match *self {
            ProcessModel::Foptd { theta, .. }
            | ProcessModel::Soptd { theta, .. }
            | ProcessModel::Integrating { theta, .. } => theta,
        }
    }

    /// The model with its times divided by `seconds` (and an integrating gain multiplied by it).
    pub fn in_time_unit(self, seconds: f64) -> ProcessModel {
        match self {
            ProcessModel::Foptd { k, tau, theta } => {
                ProcessModel::Foptd { k, tau: tau / seconds, theta: theta / seconds }
            }
            ProcessModel::Soptd { k, tau1, tau2, theta } => {
                ProcessModel::Soptd { k, tau1: tau1 / seconds, tau2: tau2 / seconds, theta: theta / seconds }
            }
            ProcessModel::Integrating { k, theta } => {
                ProcessModel::Integrating { k: k * seconds, theta: theta / seconds }
            }
        }
    }
}

/// `1 − e^(−t/τ)` for `t > 0`, else 0.
fn foptd_shape(t: f64, tau: f64) -> f64 {
    if t <= 0.0 { 0.0 } else { -(-t / tau).exp_m1() }
}

/// The SOPTD unit step response at `t` after the dead time; the double-pole limit when the two
/// time constants agree to 1e-6 (where the difference formula loses half the digits).
fn soptd_shape(t: f64, tau1: f64, tau2: f64) -> f64 {
    if t <= 0.0 {
        return 0.0;
    }
    if (tau1 - tau2).abs() <= 1e-6 * tau1.max(tau2) {
        let tau = 0.5 * (tau1 + tau2);
        return 1.0 - (1.0 + t / tau) * (-t / tau).exp();
    }
    1.0 - (tau1 * (-t / tau1).exp() - tau2 * (-t / tau2).exp()) / (tau1 - tau2)
}

/// A fitted model and how well it fits.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelFit {
    /// The model.
    pub model: ProcessModel,
    /// Root-mean-square error of the fit (output units).
    pub rmse: f64,
    /// `rmse` over the largest absolute deviation of the response.
    pub nrmse: f64,
    /// Fraction of the response's variance the model explains, `1 − SSE/SST`.
    pub r2: f64,
    /// Number of points fitted.
    pub points: usize,
}

/// Why a step response cannot be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// Too few points, times not increasing, lengths differ, or non-finite values.
    #[error("step response: {0}")]
    Data(&'static str),
    /// The input step is zero.
    #[error("step response: the input step is zero; step the input by a few percent of its range")]
    NoStep,
    /// The output did not move.
    #[error(
        "step response: the output did not move (largest deviation {largest:.3e}); the input may not reach it, \
         or the step is too small or the test too short"
    )]
    NoResponse {
        /// Largest absolute deviation.
        largest: f64,
    },
}

/// Fit a model of `order` to `data` by least squares.
///
/// # Errors
/// [`FitError`] for data that cannot determine a model.
pub fn fit_step(data: &StepResponse, order: ModelOrder) -> Result<ModelFit, FitError> {
    check(data)?;
    let horizon = *data.t.last().unwrap_or(&1.0);
    let (tau0, theta0) = smith_start(data);
    let starts: Vec<Vec<f64>> = match order {
        ModelOrder::Foptd => vec![vec![tau0.ln(), theta0], vec![(0.3 * horizon).ln(), 0.0]],
        ModelOrder::Soptd => vec![
            vec![(0.8 * tau0).ln(), (0.2 * tau0).ln(), theta0],
            vec![(0.5 * tau0).ln(), (0.5 * tau0).ln(), 0.5 * theta0],
            vec![tau0.ln(), (0.05 * tau0).ln(), theta0],
        ],
        ModelOrder::Integrating => vec![vec![theta0], vec![0.0]],
    };
    let model_at = |p: &[f64]| shape_model(order, p);
    let sse = |p: &[f64]| projected(data, &model_at(p)).1;
    let mut best: Option<(Vec<f64>, f64)> = None;
    for x0 in starts {
        let step: Vec<f64> =
            x0.iter().enumerate().map(|(i, _)| if i + 1 == x0.len() { 0.05 * horizon } else { 0.3 }).collect();
        let (x, _, _) = nelder_mead(sse, &x0, &step, (0.0, 1e-10), 4000);
        let (x, f, _) = nelder_mead(sse, &x, &step.iter().map(|s| 0.1 * s).collect::<Vec<_>>(), (0.0, 1e-12), 4000);
        if best.as_ref().is_none_or(|b| f < b.1) {
            best = Some((x, f));
        }
    }
    let Some((p, _)) = best else { unreachable!("at least one start") };
    let (k, sse) = projected(data, &model_at(&p));
    let model = with_gain(model_at(&p), k / data.du);
    Ok(quality(data, model, sse))
}

/// The model of `order` with unit gain at shape parameters `p` (log time constants, then `θ`,
/// whose sign is dropped so that the search is unconstrained).
fn shape_model(order: ModelOrder, p: &[f64]) -> ProcessModel {
    match order {
        ModelOrder::Foptd => ProcessModel::Foptd { k: 1.0, tau: p[0].exp(), theta: p[1].abs() },
        ModelOrder::Soptd => {
            let (a, b) = (p[0].exp(), p[1].exp());
            ProcessModel::Soptd { k: 1.0, tau1: a.max(b), tau2: a.min(b), theta: p[2].abs() }
        }
        ModelOrder::Integrating => ProcessModel::Integrating { k: 1.0, theta: p[0].abs() },
    }
}

/// `model` with gain `k`.
fn with_gain(model: ProcessModel, k: f64) -> ProcessModel {
    match model {
        ProcessModel::Foptd { tau, theta, .. } => ProcessModel::Foptd { k, tau, theta },
        ProcessModel::Soptd { tau1, tau2, theta, .. } => ProcessModel::Soptd { k, tau1, tau2, theta },
        ProcessModel::Integrating { theta, .. } => ProcessModel::Integrating { k, theta },
    }
}

/// The best amplitude `a = Σ y s / Σ s²` of the shape of `model`, and the sum of squared errors there.
fn projected(data: &StepResponse, model: &ProcessModel) -> (f64, f64) {
    let s: Vec<f64> = data.t.iter().map(|&t| model.shape(t)).collect();
    let ss: f64 = s.iter().map(|v| v * v).sum();
    if ss == 0.0 {
        return (0.0, data.y.iter().map(|y| y * y).sum());
    }
    let a = s.iter().zip(&data.y).map(|(s, y)| s * y).sum::<f64>() / ss;
    (a, s.iter().zip(&data.y).map(|(s, y)| (y - a * s).powi(2)).sum())
}

/// Smith's two-point start: `τ = 1.5 (t₆₃ − t₂₈)`, `θ = t₆₃ − τ` on the response scaled by its
/// last value (for an integrating response, whose last value is its largest, the same points give
/// a usable dead time).
fn smith_start(data: &StepResponse) -> (f64, f64) {
    let last = *data.y.last().unwrap_or(&1.0);
    let crossing = |frac: f64| {
        let i = data.y.iter().position(|y| y / last >= frac).unwrap_or(data.y.len() - 1).max(1);
        let (y0, y1) = (data.y[i - 1] / last, data.y[i] / last);
        let w = if y1 > y0 { ((frac - y0) / (y1 - y0)).clamp(0.0, 1.0) } else { 1.0 };
        data.t[i - 1] + w * (data.t[i] - data.t[i - 1])
    };
    let (t28, t63) = (crossing(0.283), crossing(0.632));
    let horizon = *data.t.last().unwrap_or(&1.0);
    let tau = (1.5 * (t63 - t28)).max(1e-3 * horizon);
    (tau, (t63 - tau).max(0.0))
}

/// The fit statistics of `model` on `data` with sum of squared errors `sse`.
/// How well a given `model` (its gain as given) describes the record `data`.
pub fn assess(data: &StepResponse, model: ProcessModel) -> ModelFit {
    let k = model.gain() * data.du;
    let sse = data.t.iter().zip(&data.y).map(|(&t, y)| (y - k * model.shape(t)).powi(2)).sum();
    quality(data, model, sse)
}

fn quality(data: &StepResponse, model: ProcessModel, sse: f64) -> ModelFit {
    let n = data.y.len() as f64;
    let mean = data.y.iter().sum::<f64>() / n;
    let sst: f64 = data.y.iter().map(|y| (y - mean).powi(2)).sum();
    let largest = data.y.iter().fold(0.0f64, |m, y| m.max(y.abs()));
    let rmse = (sse / n).sqrt();
    ModelFit { model, rmse, nrmse: rmse / largest, r2: 1.0 - sse / sst, points: data.y.len() }
}

/// Reject data that cannot determine a model.
fn check(data: &StepResponse) -> Result<(), FitError> {
    if data.t.len() != data.y.len() {
        return Err(FitError::Data("times and values differ in number"));
    }
    if data.t.len() < 8 {
        return Err(FitError::Data("fewer than 8 points; record the response more densely"));
    }
    if data.t.iter().chain(&data.y).any(|v| !v.is_finite()) || !data.du.is_finite() {
        return Err(FitError::Data("a time or value is not finite"));
    }
    if data.t.windows(2).any(|w| w[1] <= w[0]) {
        return Err(FitError::Data("times must increase"));
    }
    if data.du == 0.0 {
        return Err(FitError::NoStep);
    }
    let largest = data.y.iter().fold(0.0f64, |m, y| m.max(y.abs()));
    if largest == 0.0 {
        return Err(FitError::NoResponse { largest });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    /// Skogestad's half rule for a measurement in series: its dead time adds to θ; its lag is split
    /// half to θ and half to the smallest lag kept (or becomes the lag, when larger), all of it to
    /// θ of an integrating model.
    #[test]
    fn a_measurement_adds_its_dead_time_and_half_its_lag() {
        let f = ProcessModel::Foptd { k: 2.0, tau: 10.0, theta: 1.0 };
        assert_eq!(f.measured(3.0, 2.0), ProcessModel::Foptd { k: 2.0, tau: 11.0, theta: 5.0 });
        assert_eq!(f.measured(0.0, 20.0), ProcessModel::Foptd { k: 2.0, tau: 25.0, theta: 6.0 });
        assert_eq!(f.measured(0.0, 0.0), f);
        let s = ProcessModel::Soptd { k: 1.0, tau1: 10.0, tau2: 4.0, theta: 0.5 };
        assert_eq!(s.measured(1.0, 2.0), ProcessModel::Soptd { k: 1.0, tau1: 10.0, tau2: 5.0, theta: 2.5 });
        let i = ProcessModel::Integrating { k: 0.1, theta: 2.0 };
        assert_eq!(i.measured(1.0, 3.0), ProcessModel::Integrating { k: 0.1, theta: 6.0 });
    }

    use super::*;

    fn record(model: &ProcessModel, du: f64, horizon: f64, n: usize) -> StepResponse {
        let t: Vec<f64> = (0..n).map(|i| horizon * i as f64 / (n - 1) as f64).collect();
        let y = t.iter().map(|&t| model.gain() * du * model.shape(t)).collect();
        StepResponse { t, y, du }
    }

    #[test]
    fn exact_foptd_data_give_back_the_model() {
        let truth = ProcessModel::Foptd { k: -2.5, tau: 40.0, theta: 7.0 };
        let fit = fit_step(&record(&truth, 0.1, 300.0, 301), ModelOrder::Foptd).unwrap();
        let ProcessModel::Foptd { k, tau, theta } = fit.model else { panic!("{fit:?}") };
        assert!((k + 2.5).abs() < 1e-6 && (tau - 40.0).abs() < 1e-5 && (theta - 7.0).abs() < 1e-5, "{fit:?}");
        assert!(fit.nrmse < 1e-7 && fit.r2 > 1.0 - 1e-12, "{fit:?}");
    }

    #[test]
    fn exact_soptd_data_give_back_the_model() {
        let truth = ProcessModel::Soptd { k: 0.8, tau1: 30.0, tau2: 9.0, theta: 4.0 };
        let fit = fit_step(&record(&truth, 2.0, 400.0, 401), ModelOrder::Soptd).unwrap();
        let ProcessModel::Soptd { k, tau1, tau2, theta } = fit.model else { panic!("{fit:?}") };
        assert!((k - 0.8).abs() < 1e-5 && (tau1 - 30.0).abs() < 1e-3, "{fit:?}");
        assert!((tau2 - 9.0).abs() < 1e-3 && (theta - 4.0).abs() < 1e-3, "{fit:?}");
    }

    #[test]
    fn exact_integrating_data_give_back_the_model() {
        let truth = ProcessModel::Integrating { k: 0.004, theta: 12.0 };
        let fit = fit_step(&record(&truth, -0.5, 200.0, 201), ModelOrder::Integrating).unwrap();
        let ProcessModel::Integrating { k, theta } = fit.model else { panic!("{fit:?}") };
        assert!((k - 0.004).abs() < 1e-10 && (theta - 12.0).abs() < 1e-6, "{fit:?}");
    }

    #[test]
    fn a_foptd_fit_of_two_lags_reports_its_misfit() {
        // Two equal lags of 10 s are no first-order lag: the fit must say it is imperfect, and
        // the sum of its time constant and dead time stays near the area-based mean residence
        // time of the true response, τ₁ + τ₂ = 20 s (the first moment of a lag chain).
        let truth = ProcessModel::Soptd { k: 1.0, tau1: 10.0, tau2: 10.0, theta: 0.0 };
        let fit = fit_step(&record(&truth, 1.0, 150.0, 301), ModelOrder::Foptd).unwrap();
        let ProcessModel::Foptd { tau, theta, .. } = fit.model else { panic!("{fit:?}") };
        assert!(fit.nrmse > 1e-3 && fit.nrmse < 0.03, "{fit:?}");
        assert!((tau + theta - 20.0).abs() < 2.0, "{fit:?}");
    }

    #[test]
    fn data_that_cannot_determine_a_model_are_refused() {
        let flat = StepResponse { t: (0..20).map(f64::from).collect(), y: vec![0.0; 20], du: 1.0 };
        assert!(matches!(fit_step(&flat, ModelOrder::Foptd), Err(FitError::NoResponse { .. })));
        let no_step =
            StepResponse { du: 0.0, ..record(&ProcessModel::Foptd { k: 1.0, tau: 1.0, theta: 0.0 }, 1.0, 5.0, 20) };
        assert_eq!(fit_step(&no_step, ModelOrder::Foptd), Err(FitError::NoStep));
        let short = StepResponse { t: vec![0.0, 1.0], y: vec![0.0, 1.0], du: 1.0 };
        assert!(matches!(fit_step(&short, ModelOrder::Foptd), Err(FitError::Data(_))));
    }

    /// The shapes against closed forms: a second-order lag with ζ = 0.3 overshoots by
    /// `exp(−πζ/√(1 − ζ²))` = 37.2 %; `(1 − 3s)/(1 + s)²` dips to `1 − 4e^(−3/4)` = −0.8895 at
    /// t = 3/4; an overdamped lag (ζ = 1.5) and a first-order one have neither.
    #[test]
    fn lagless_shapes_against_closed_forms() {
        let t: Vec<f64> = (0..=8000).map(|k| f64::from(k) * 0.005).collect();
        let record =
            |f: &dyn Fn(f64) -> f64| StepResponse { t: t.clone(), y: t.iter().map(|&t| f(t)).collect(), du: 1.0 };
        let z: f64 = 0.3;
        let wd = (1.0 - z * z).sqrt();
        let under = record(&|t| 1.0 - (-z * t).exp() * ((wd * t).cos() + z / wd * (wd * t).sin()));
        let expected = (-std::f64::consts::PI * z / wd).exp();
        assert!((expected - 0.372).abs() < 1e-3);
        assert_eq!(
            lagless_shape(&under).unwrap(),
            format!("overshoots its final value by {:.0} % (an underdamped element)", 100.0 * expected)
        );
        let inverse = record(&|t| 1.0 - (-t).exp() * (1.0 + 4.0 * t));
        assert_eq!(
            lagless_shape(&inverse).unwrap(),
            "first moves the other way, by 89 % of its final change (an inverse response)"
        );
        let over = record(&|t| 1.0 - ((-0.38 * t).exp() * 2.618 - (-2.62 * t).exp() * 0.382) / 2.236);
        assert_eq!(lagless_shape(&over), None);
        assert_eq!(lagless_shape(&record(&|t| 1.0 - (-t).exp())), None);
    }
}
