//! The test design: PRBS clock and register length from `τ_dom`, α and β (Eq. 7-8, 7-9), delayed
//! copies for several inputs (Eq. 7-10), generalized binary noise, or signals along the input
//! singular directions of the prior gain (Koung & MacGregor 1991); and the fresh validation signals.

use faer::Mat;
use plantwide_analysis::select::Signal;
use plantwide_flowsheet::Plant;
use plantwide_flowsheet::overrides::check_input_value;
use plantwide_ident::signals::{design_prbs, directional, gbn, prbs};
use serde::Serialize;

use super::{IdentifyError, IdentifySettings};

/// How the inputs are moved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Design {
    /// Delayed copies of one PRBS, `D = N T_cl/p` apart (Eq. 7-10).
    Prbs,
    /// Independent generalized binary noise per input (Tulleken 1990), mean switching time `T_cl`.
    Gbn,
    /// Independent PRBS copies along the input singular directions of the prior gain, the
    /// low-gain direction amplified by `σ_max/σ_min` within the inputs' amplitudes.
    Directional,
}

/// The singular directions a directional design excites.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Directions {
    /// Singular values of the prior gain scaled by the input amplitudes (outputs in SI).
    pub singular_values: Vec<f64>,
    /// Its condition number.
    pub condition_number: f64,
    /// Relative amplitude of each direction's signal (the high-gain one is the smallest).
    pub scales: Vec<f64>,
    /// Output amplitude of the high-gain directions relative to the low-gain one's.
    pub high_gain_boost: f64,
}

/// The test as designed (times in seconds, frequencies in rad/s, amplitudes in display units).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TestDesign {
    /// The design family.
    pub design: Design,
    /// Dominant time constant used \[s\].
    pub tau_dom: f64,
    /// Closed-loop speed factor α.
    pub alpha: f64,
    /// Settling factor β.
    pub beta: f64,
    /// Sample time \[s\].
    pub sample_time: f64,
    /// PRBS clock period `T_cl` \[s\] (GBN: mean switching time).
    pub clock_period: f64,
    /// Shift registers `n`.
    pub registers: usize,
    /// Period in clocks, `N = 2^n − 1`.
    pub period_clocks: usize,
    /// Period `N T_cl` \[s\].
    pub period: f64,
    /// Excited band `[2π/(N T_cl), 2.8/T_cl]` \[rad/s\] (Eq. 7-6).
    pub band: [f64; 2],
    /// Delay between the inputs' copies \[s\] (Eq. 7-10).
    pub shift: f64,
    /// Estimation test length \[s\].
    pub duration: f64,
    /// Validation test length \[s\].
    pub validation_duration: f64,
    /// Largest move of each input (display units).
    pub amplitude: Vec<f64>,
    /// The directions of a directional design.
    pub directions: Option<Directions>,
}

/// A designed test: the design and the input moves (SI deviations, per input per sample).
pub(super) struct Test {
    pub design: TestDesign,
    pub estimation: Vec<Vec<f64>>,
    pub validation: Vec<Vec<f64>>,
}

/// The most samples one test may have (a cap on what the options can allocate).
const MAX_SAMPLES: usize = 200_000;

fn ident_error(e: impl std::fmt::Display) -> IdentifyError {
    IdentifyError::Request(e.to_string())
}

/// Amplitudes (SI): the settings' or 1 % of each input's steady value (1 SI unit at 0), each
/// checked against the input's physical range.
fn amplitudes(plant: &Plant, u: &[f64], inputs: &[Signal], s: &IdentifySettings) -> Result<Vec<f64>, IdentifyError> {
    let a: Vec<f64> = match &s.amplitude {
        Some(a) if a.len() == inputs.len() => a.clone(),
        Some(a) if a.len() == 1 => vec![a[0]; inputs.len()],
        Some(a) => {
            return Err(IdentifyError::Request(format!(
                "`amplitude` gives {} values for {} inputs: give one per input",
                a.len(),
                inputs.len()
            )));
        }
        None => inputs.iter().map(|sig| if u[sig.index] != 0.0 { 0.01 * u[sig.index].abs() } else { 1.0 }).collect(),
    };
    for (sig, &ai) in inputs.iter().zip(&a) {
        if !(ai.is_finite() && ai > 0.0) {
            return Err(IdentifyError::Request(format!("`amplitude` of `{}` must be > 0", sig.path)));
        }
        let v = u[sig.index];
        for moved in [v - ai, v + ai] {
            if let Err(e) = check_input_value(plant, sig.index, moved) {
                let why = e.to_string();
                return Err(IdentifyError::CannotMove { input: sig.path.clone(), amplitude: ai, value: v, why });
            }
        }
    }
    Ok(a)
}

/// Base ±1 signals: delayed copies of one PRBS (`prbs`, `directional`) or seeded GBN.
fn base_signals(
    design: Design,
    p: &plantwide_ident::signals::PrbsDesign,
    n_inputs: usize,
    len: usize,
    seed: u64,
) -> Result<Vec<Vec<f64>>, IdentifyError> {
    (0..n_inputs)
        .map(|j| match design {
            Design::Gbn => gbn(len, p.clock_samples as f64, seed.wrapping_add(j as u64)).map_err(ident_error),
            _ => prbs(p.registers, p.clock_samples, len, j * p.shift_samples).map_err(ident_error),
        })
        .collect()
}

/// Scale ±1 signals to the amplitudes, or rotate them onto the singular directions: direction `i`
/// (input singular vector `v_i`) carries `c_i s_i(t)` with `c_i ∝ 1/σ_i` (each direction moves the
/// outputs equally, Koung & MacGregor 1991), every direction but the weakest multiplied by `boost`,
/// the whole scaled so that the largest move of input `j` is `amplitude[j]`.
fn shape(
    base: Vec<Vec<f64>>,
    amplitude: &[f64],
    scaled_gain: &[Vec<f64>],
    directional_design: bool,
    boost: f64,
) -> Result<(Vec<Vec<f64>>, Option<Directions>), IdentifyError> {
    if !directional_design {
        let moves = base.into_iter().zip(amplitude).map(|(s, a)| s.into_iter().map(|v| v * a).collect()).collect();
        return Ok((moves, None));
    }
    let unit = vec![1.0; amplitude.len()];
    let d = directional(scaled_gain, &base, &unit).map_err(|e| match e {
        plantwide_ident::IdentError::BadDesign { field: "gain", value, .. } => {
            IdentifyError::SingularDesign { smallest: value }
        }
        e => ident_error(e),
    })?;
    let k = d.scale.len();
    let scale: Vec<f64> = (0..k).map(|i| if i + 1 < k { d.scale[i] * boost } else { d.scale[i] }).collect();
    let len = base.first().map_or(0, Vec::len);
    let mut inputs = vec![vec![0.0; len]; amplitude.len()];
    for (j, uj) in inputs.iter_mut().enumerate() {
        for (t, v) in uj.iter_mut().enumerate() {
            *v = (0..k).map(|i| d.v[i][j] * scale[i] * base[i][t]).sum();
        }
    }
    let peak = inputs.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let d = plantwide_ident::DirectionalDesign { scale: scale.iter().map(|c| c / peak).collect(), ..d };
    let moves = inputs.into_iter().zip(amplitude).map(|(s, a)| s.into_iter().map(|v| v / peak * a).collect()).collect();
    let dirs = Directions {
        singular_values: d.singular_values,
        condition_number: d.condition_number,
        scales: d.scale,
        high_gain_boost: boost,
    };
    Ok((moves, Some(dirs)))
}

/// Design the test of `inputs` at the steady inputs `u`, with `gain` the prior `G(0)` (SI) and
/// `tau_dom` the dominant time constant \[s\].
pub(super) fn design(
    plant: &Plant,
    u: &[f64],
    inputs: &[Signal],
    gain: &Mat<f64>,
    tau_dom: f64,
    s: &IdentifySettings,
) -> Result<Test, IdentifyError> {
    let ts = s.sample_time.unwrap_or(tau_dom / 20.0);
    let t99 = 4.6 * tau_dom;
    let p = design_prbs(tau_dom, 0.0, s.alpha, s.beta, ts, inputs.len(), t99).map_err(ident_error)?;
    let period = p.period as f64 * p.clock_period;
    let duration = s.duration.unwrap_or(4.0 * period);
    if duration < period {
        return Err(IdentifyError::Request(format!(
            "a test of {:.4e} s is shorter than one PRBS period N·T_cl = {} × {:.4e} s = {period:.4e} s \
             (τ_dom = {tau_dom:.4e} s, α = {}, β = {}): give a `duration` of at least one period, or a larger α",
            duration, p.period, p.clock_period, s.alpha, s.beta
        )));
    }
    let n_est = (duration / ts).round() as usize;
    let n_val = ((period.max(3.0 * t99)) / ts).round() as usize;
    if n_est.max(n_val) > MAX_SAMPLES {
        return Err(IdentifyError::Request(format!(
            "the test would take {} samples (most {MAX_SAMPLES}): give a longer `sample_time` or a shorter `duration`",
            n_est.max(n_val)
        )));
    }
    let amplitude = amplitudes(plant, u, inputs, s)?;
    let scaled: Vec<Vec<f64>> =
        (0..gain.nrows()).map(|i| (0..gain.ncols()).map(|j| gain[(i, j)] * amplitude[j]).collect()).collect();
    let directional_design = s.design == Design::Directional;
    let (estimation, directions) = shape(
        base_signals(s.design, &p, inputs.len(), n_est, s.seed)?,
        &amplitude,
        &scaled,
        directional_design,
        s.high_gain_boost,
    )?;
    let fresh = base_signals(Design::Gbn, &p, inputs.len(), n_val, s.seed.wrapping_mul(7919).wrapping_add(17))?;
    let (validation, _) = shape(fresh, &amplitude, &scaled, directional_design, s.high_gain_boost)?;
    let design = TestDesign {
        design: s.design,
        tau_dom,
        alpha: s.alpha,
        beta: s.beta,
        sample_time: ts,
        clock_period: p.clock_period,
        registers: p.registers,
        period_clocks: p.period,
        period,
        band: [p.band.0, p.band.1],
        shift: p.shift_samples as f64 * ts,
        duration: n_est as f64 * ts,
        validation_duration: n_val as f64 * ts,
        amplitude: inputs.iter().zip(&amplitude).map(|(sig, a)| a / sig.factor).collect(),
        directions,
    };
    Ok(Test { design, estimation, validation })
}
