//! Controller tuning from a transfer-function model (issue 16, first part).
//!
//! - [`mod@ultimate`]: ultimate gain `K_u` and period `P_u` of a SISO element from `g(jω)`.
//! - [`PiRule`]: Ziegler–Nichols PI, `K_c = K_u/2.2`, `τ_I = P_u/1.2` (Ziegler & Nichols 1942), and
//!   Tyreus–Luyben PI, `K_c = K_u/3.2`, `τ_I = 2.2 P_u` (Tyreus & Luyben 1992, Ind. Eng. Chem. Res.
//!   31, 2625).
//! - [`relay`]: relay-feedback (ATV) test on a linear element, `K_u ≈ 4h/(πa)` (Åström &
//!   Hägglund 1984).
//! - [`mod@blt`]: Luyben's biggest-log-modulus tuning of n diagonal PI loops (Luyben 1986, Ind. Eng.
//!   Chem. Process Des. Dev. 25, 654).
//!
//! The PI controller is `c(s) = K_c (1 + 1/(τ_I s))`. Results are in SI (times in seconds) until
//! [`Tuning::in_time_unit`] converts them; gains are in the model's units (input per output).

pub mod averaging;
pub mod bench;
pub mod blt;
pub mod fit;
pub mod flowsheet;
pub mod loops;
pub mod margins;
pub mod plant_tests;
pub mod relay;
pub mod request;
pub mod room;
pub mod rules;
pub mod ultimate;

use plantwide_analysis::tf::TfModel;
use serde::Serialize;

pub use blt::{BltSettings, LoopSystem, blt, blt_detuning, blt_system, max_log_modulus};
pub use relay::{RelayReport, RelaySettings, relay_test};
pub use ultimate::{Ultimate, element_ultimate, ultimate};

use crate::TuneError;

/// A PI tuning rule applied to the ultimate gain and period.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PiRule {
    /// Ziegler–Nichols: `K_c = K_u/2.2`, `τ_I = P_u/1.2`.
    ZieglerNichols,
    /// Tyreus–Luyben: `K_c = K_u/3.2`, `τ_I = 2.2 P_u`.
    TyreusLuyben,
}

impl PiRule {
    /// `(K_c, τ_I)` from the ultimate gain and period.
    pub fn settings(self, u: &Ultimate) -> (f64, f64) {
        match self {
            PiRule::ZieglerNichols => (u.ku / 2.2, u.pu / 1.2),
            PiRule::TyreusLuyben => (u.ku / 3.2, 2.2 * u.pu),
        }
    }
}

/// Which method produced a [`Tuning`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum TuneMethod {
    /// Luyben's BLT: ZN settings detuned by one factor F.
    #[serde(rename = "blt")]
    Blt,
    /// Ziegler–Nichols PI of each loop alone.
    #[serde(rename = "zn")]
    ZieglerNichols,
    /// Tyreus–Luyben PI of each loop alone.
    #[serde(rename = "tl")]
    TyreusLuyben,
}

/// The settings of one loop.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LoopTuning {
    /// Controlled output.
    pub output: String,
    /// Manipulated input.
    pub input: String,
    /// Ultimate gain of the paired element (input units per output unit).
    pub ku: f64,
    /// Ultimate period \[s, or the unit of [`Tuning::in_time_unit`]\].
    pub pu: f64,
    /// Controller gain (input units per output unit).
    pub kc: f64,
    /// Reset (integral) time \[s, or the unit of [`Tuning::in_time_unit`]\].
    pub tau_i: f64,
    /// Gain and phase margins of the loop alone, `g_ii c_i` ([`with_margins`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub margins: Option<margins::Margins>,
}

/// Tuning of a set of loops; serializes to
/// `{"method", "detuning_factor" (BLT only), "loops": [{"output", "input", "ku", "pu", "kc", "tau_i", "margins"}]}`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tuning {
    /// Method.
    pub method: TuneMethod,
    /// BLT detuning factor F ≥ 1 (`None` for a single-loop rule).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub detuning_factor: Option<f64>,
    /// BLT: the factor that met the log-modulus target but left the loops unstable, when the
    /// detuning was raised from it for a stable closed loop.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unstable_at: Option<f64>,
    /// One entry per loop, in the model's output order.
    pub loops: Vec<LoopTuning>,
    /// BLT: the biggest log modulus reached at F \[dB\] (not serialized).
    #[serde(skip)]
    pub max_lcm_db: Option<f64>,
    /// BLT: the frequency of that peak \[rad/s\] (not serialized).
    #[serde(skip)]
    pub peak_omega: Option<f64>,
}

impl Tuning {
    /// The same tuning with times (`pu`, `tau_i`, the peak frequency) in a unit of `seconds` s.
    pub fn in_time_unit(mut self, seconds: f64) -> Tuning {
        for l in &mut self.loops {
            l.pu /= seconds;
            l.tau_i /= seconds;
            l.margins = l.margins.map(|m| m.in_time_unit(seconds));
        }
        self.peak_omega = self.peak_omega.map(|w| w * seconds);
        self
    }
}

/// The ultimate gain and period of each diagonal element `g_ii` of a square model, named.
///
/// # Errors
/// [`TuneError::NotSquare`]; [`TuneError::NoPhaseCrossover`] naming the first diagonal element
/// (missing, pure gain, or of too low an order without dead time) that has no ultimate gain.
pub fn diagonal_ultimates(model: &TfModel) -> Result<Vec<Ultimate>, TuneError> {
    let (n_outputs, n_inputs) = (model.outputs.len(), model.inputs.len());
    if n_outputs != n_inputs {
        return Err(TuneError::NotSquare { model: model.name.clone(), n_outputs, n_inputs });
    }
    (0..n_outputs)
        .map(|i| {
            let no_crossover = |detail: String| TuneError::NoPhaseCrossover {
                output: model.outputs[i].name.clone(),
                input: model.inputs[i].name.clone(),
                detail,
            };
            let Some(e) = model.element(i, i) else {
                return Err(no_crossover(", the element is missing (zero)".into()));
            };
            let u = element_ultimate(e).ok_or_else(|| {
                let detail = match (e.lags.len(), e.leads.len(), e.dead_time > 0.0) {
                    (_, _, _) if e.gain == 0.0 => ", the element's gain is zero".to_string(),
                    (0, 0, false) => ", a pure gain".to_string(),
                    (n, 0, false) if n <= 2 => format!(", a lag of order {n} without dead time"),
                    _ => String::new(),
                };
                no_crossover(detail)
            })?;
            if !u.ku.is_finite() || u.ku == 0.0 {
                return Err(TuneError::UltimateOutOfRange {
                    output: model.outputs[i].name.clone(),
                    input: model.inputs[i].name.clone(),
                    gain: e.gain,
                    ku: u.ku,
                });
            }
            Ok(u)
        })
        .collect()
}

/// Ziegler–Nichols or Tyreus–Luyben PI settings of each diagonal loop of a square model, each
/// tuned alone (no detuning for interaction).
///
/// # Errors
/// As [`diagonal_ultimates`].
pub fn single_loop(model: &TfModel, rule: PiRule) -> Result<Tuning, TuneError> {
    let ultimates = diagonal_ultimates(model)?;
    let method = match rule {
        PiRule::ZieglerNichols => TuneMethod::ZieglerNichols,
        PiRule::TyreusLuyben => TuneMethod::TyreusLuyben,
    };
    let loops = ultimates
        .iter()
        .enumerate()
        .map(|(i, u)| {
            let (kc, tau_i) = rule.settings(u);
            LoopTuning {
                output: model.outputs[i].name.clone(),
                input: model.inputs[i].name.clone(),
                ku: u.ku,
                pu: u.pu,
                kc,
                tau_i,
                margins: None,
            }
        })
        .collect();
    let tuning = Tuning { method, detuning_factor: None, unstable_at: None, loops, max_lcm_db: None, peak_omega: None };
    Ok(with_margins(model, tuning))
}

/// `tuning` of the diagonal loops of `model` (SI times) with each loop's margins: its element
/// `g_ii` under its PI, the other loops open.
pub fn with_margins(model: &TfModel, mut tuning: Tuning) -> Tuning {
    for (i, l) in tuning.loops.iter_mut().enumerate() {
        if let Some((response, lo, hi)) = loop_response(model, i, l) {
            l.margins = Some(margins::margins(response, lo, hi));
        }
    }
    tuning
}

/// The Bode diagram of each loop of `tuning` (SI times; `None` where its element has no
/// frequency range): the loop [`with_margins`] judges, drawn by [`margins::bode`].
pub fn bode_diagrams(model: &TfModel, tuning: &Tuning) -> Vec<Option<margins::Bode>> {
    let diagram = |(i, l)| loop_response(model, i, l).map(|(response, lo, hi)| margins::bode(response, lo, hi));
    tuning.loops.iter().enumerate().map(diagram).collect()
}

/// Loop `i`'s open-loop response `L(jω) = g_ii(jω) c_i(jω)` (ω in rad/s) and the frequency range
/// its margins are searched in; `None` where the element is missing or has no range.
fn loop_response<'a>(
    model: &'a TfModel,
    i: usize,
    l: &LoopTuning,
) -> Option<(impl Fn(f64) -> faer::c64 + 'a, f64, f64)> {
    let e = model.element(i, i)?;
    let (lo, hi) = ultimate::element_frequency_range(e)?;
    let (kc, tau_i) = (l.kc, l.tau_i);
    Some((move |w: f64| e.response(w) * margins::pid(kc, Some(tau_i), None, w), lo, hi))
}
