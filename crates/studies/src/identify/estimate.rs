//! Estimation and validation per output: FIR (ridge), ARX (order by AIC), OE (Levenberg–Marquardt
//! from the ARX fit), each simulated on the fresh validation inputs and judged there.

use plantwide_analysis::select::Signal;
use plantwide_ident::{StepResponse, arx_select, fir, fit_percent, oe, simulate_arx, simulate_oe, validate};
use serde::Serialize;

use super::IdentifyError;
use super::design::TestDesign;
use super::plant_test::TestData;

/// Highest ARX order tried, and the OE order's cap.
const MAX_ARX_ORDER: usize = 4;
const MAX_OE_ORDER: usize = 2;
/// Lags of the residual correlation tests.
const MAX_LAG: usize = 20;

/// One fitted model of one output.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelSummary {
    /// Output path.
    pub output: String,
    /// Structure: `fir`, `arx` or `oe`.
    pub model: String,
    /// Orders as in Eq. 7-27: `na`/`nb`/`nf` (and `n` coefficients of a FIR), `nk` per input.
    pub orders: String,
    /// Steady-state gain per input (display units).
    pub gain: Vec<f64>,
    /// Standard error of each gain from the parameter covariance (delta method; OE only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gain_std: Option<Vec<f64>>,
    /// Whether this model of this output passes the verdict's criteria of one output
    /// ([`super::verdict`]): a denominator away from zero at z = 1 (`|F(1)|`, `|A(1)| ≥ 1e-3`: a
    /// pole at the unit circle makes the gain meaningless), every gain of the sign of the exact
    /// linearization's and within its tolerance, and the fit to the plant's response at least the
    /// least accepted.
    pub reliable: bool,
    /// Fit on the validation data \[%\] (the measured output, with its noise).
    pub fit_percent: f64,
    /// Fit to the plant's own response on the validation test \[%\] (the noise left out).
    pub fit_noise_free: f64,
    /// Residuals white at 95 % (validation data).
    pub white: bool,
    /// Residuals uncorrelated with every input at 95 % (validation data).
    pub independent: bool,
}

/// Validation of the chosen structure on one output.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OutputValidation {
    /// Output path.
    pub output: String,
    /// Fit on the validation data \[%\]: `100 (1 − ‖y − ŷ‖/‖y − ȳ‖)`, `y` measured (with the noise).
    pub fit_percent: f64,
    /// The same fit with `y` the plant's own response on the validation test (the noise left out):
    /// how well the model simulates the plant, which the verdict judges.
    pub fit_noise_free: f64,
    /// Residual autocorrelation at lags 0 … 20 (Eq. 7-59).
    pub autocorrelation: Vec<f64>,
    /// Residual–input cross-correlation per input at lags 0 … 20 (Eq. 7-60).
    pub cross_correlation: Vec<Vec<f64>>,
    /// The 95 % bound `1.96/√N`.
    pub bound: f64,
    /// Residuals white at 95 %.
    pub white: bool,
    /// Residuals uncorrelated with the inputs at 95 %.
    pub independent: bool,
    /// The model's simulated output on the validation inputs (deviation from the steady state,
    /// SI), for plots.
    #[serde(skip)]
    pub predicted: Vec<f64>,
}

fn fit_error(e: impl std::fmt::Display) -> IdentifyError {
    IdentifyError::Estimation(format!("identification: {e}"))
}

/// One structure fitted to one output: its gains (SI) and validation.
pub(super) struct Fitted {
    pub model: &'static str,
    pub orders: String,
    pub gain: Vec<f64>,
    pub gain_std: Option<Vec<f64>>,
    /// Its denominator at z = 1, `|A(1)|` (ARX) or the least `|F_j(1)|` (OE), 1 for a FIR: near
    /// zero, a pole at the unit circle makes the gain meaningless.
    pub denominator: f64,
    pub validation: OutputValidation,
    /// Step response per input over the settling samples (SI).
    pub step: Vec<Vec<f64>>,
}

/// The standard error of each OE gain `g_j = B_j(1)/F_j(1)` by the delta method,
/// `∂g/∂b = 1/F(1)`, `∂g/∂f = −B(1)/F(1)²`, over the input's block of the covariance.
fn oe_gain_std(m: &plantwide_ident::OeModel) -> Option<Vec<f64>> {
    let p = m.covariance.as_ref()?;
    let block = m.nb + m.nf;
    let std = (0..m.b.len())
        .map(|j| {
            let (bs, fs) = (m.b[j].iter().sum::<f64>(), 1.0 + m.f[j].iter().sum::<f64>());
            let grad: Vec<f64> =
                std::iter::repeat_n(1.0 / fs, m.nb).chain(std::iter::repeat_n(-bs / (fs * fs), m.nf)).collect();
            let o = j * block;
            let var: f64 =
                (0..block).map(|a| (0..block).map(|b| grad[a] * p[o + a][o + b] * grad[b]).sum::<f64>()).sum();
            var.max(0.0).sqrt()
        })
        .collect();
    Some(std)
}

/// Ridge parameters tried for the FIR fit, relative to the mean input energy per column of X
/// (`c = c_rel Σu²/n_u`): the one with the best validation fit is kept.
const FIR_RIDGE: [f64; 4] = [0.0, 1e-8, 1e-6, 1e-4];

type Judge<'a> = dyn Fn(Result<Vec<f64>, plantwide_ident::IdentError>) -> Result<OutputValidation, IdentifyError> + 'a;

/// The FIR fit of output `i` whose ridge parameter validates best, its validation and `c_rel`.
fn best_fir(
    est: &TestData,
    val: &TestData,
    i: usize,
    n_fir: usize,
    judge: &Judge<'_>,
) -> Result<(plantwide_ident::FirModel, OutputValidation, f64), IdentifyError> {
    let power: f64 = est.u.iter().flatten().map(|v| v * v).sum::<f64>() / est.u.len().max(1) as f64;
    let mut best: Option<(plantwide_ident::FirModel, OutputValidation, f64)> = None;
    for c in FIR_RIDGE {
        let m = fir(&est.u, &est.y[i], n_fir, 1, c * power).map_err(fit_error)?;
        let v = judge(m.simulate(&val.u))?;
        if best.as_ref().is_none_or(|b| v.fit_percent > b.1.fit_percent) {
            best = Some((m, v, c));
        }
    }
    best.ok_or_else(|| IdentifyError::Estimation("identification: no FIR fit".into()))
}

/// Fit FIR, ARX and OE to output `i`.
fn fit_output(
    est: &TestData,
    val: &TestData,
    i: usize,
    n_fir: usize,
    output: &str,
) -> Result<Vec<Fitted>, IdentifyError> {
    let nu = est.u.len();
    let nk = vec![1; nu];
    let (ye, yv) = (&est.y[i], &val.y[i]);
    let judge = |yhat: Result<Vec<f64>, plantwide_ident::IdentError>| -> Result<OutputValidation, IdentifyError> {
        let yhat = yhat.map_err(fit_error)?;
        let v = validate(yv, &yhat, &val.u, MAX_LAG).map_err(fit_error)?;
        Ok(OutputValidation {
            output: output.to_string(),
            fit_percent: v.fit_percent,
            fit_noise_free: fit_percent(&val.clean[i], &yhat).map_err(fit_error)?,
            autocorrelation: v.autocorrelation,
            cross_correlation: v.cross_correlation,
            bound: v.bound,
            white: v.white,
            independent: v.independent,
            predicted: yhat,
        })
    };
    let (arx, _) = arx_select((&est.u, ye), (&val.u, yv), MAX_ARX_ORDER, &nk).map_err(fit_error)?;
    let n = arx.na.clamp(1, MAX_OE_ORDER);
    let mut init =
        if arx.na == n { arx.clone() } else { plantwide_ident::arx(&est.u, ye, n, n, &nk).map_err(fit_error)? };
    // OE starts from the ARX denominator with its unstable roots reflected inside the unit circle
    // (a slow plant sampled coarsely gives an ARX pole at 1 by a hair); the ARX model itself is
    // reported and judged as fitted.
    if let Some(f) = plantwide_ident::stabilized(&init.a).filter(|f| *f != init.a) {
        init.a = f;
    }
    let oe_model = oe(&est.u, ye, n, n, &nk, Some(&init)).map_err(fit_error)?;
    let (fir_model, fir_validation, ridge) = best_fir(est, val, i, n_fir, &judge)?;
    Ok(vec![
        Fitted {
            model: "fir",
            orders: format!("n={n_fir}, nk=1, ridge={ridge:.0e}"),
            gain: fir_model.gain.clone(),
            gain_std: None,
            denominator: 1.0,
            step: fir_model.step_response(n_fir).map_err(fit_error)?,
            validation: fir_validation,
        },
        Fitted {
            model: "arx",
            orders: format!("na={}, nb={}, nk=1", arx.na, arx.nb),
            gain: arx.gain.clone(),
            gain_std: None,
            denominator: (1.0 + arx.a.iter().sum::<f64>()).abs(),
            step: arx.step_response(n_fir).map_err(fit_error)?,
            validation: judge(simulate_arx(&arx, &val.u))?,
        },
        Fitted {
            model: "oe",
            orders: format!("nb={n}, nf={n}, nk=1"),
            gain: oe_model.gain.clone(),
            gain_std: oe_gain_std(&oe_model),
            denominator: oe_model.f.iter().map(|f| (1.0 + f.iter().sum::<f64>()).abs()).fold(f64::INFINITY, f64::min),
            step: oe_model.step_response(n_fir).map_err(fit_error)?,
            validation: judge(simulate_oe(&oe_model, &val.u))?,
        },
    ])
}

/// Fit FIR, ARX and OE to every output of the estimation data and validate them on the validation
/// data: per output, per structure (the same structures in the same order for every output).
pub(super) fn fit_all(
    est: &TestData,
    val: &TestData,
    design: &TestDesign,
    inputs: &[Signal],
    outputs: &[Signal],
) -> Result<Vec<Vec<Fitted>>, IdentifyError> {
    let t99 = 4.6 * design.tau_dom;
    let n_samples = est.y.first().map_or(0, Vec::len);
    // The settling time in samples, at most a quarter of the data per input and the FIR fit's cap.
    let n_fir = ((t99 / design.sample_time).ceil() as usize)
        .clamp(5, (n_samples / (4 * inputs.len().max(1))).max(5))
        .min(plantwide_ident::data::MAX_FIR);
    let explain = |o: &Signal, e: IdentifyError| match e {
        IdentifyError::Estimation(m) => IdentifyError::Estimation(format!(
            "{m}; output `{}`, sample time {:.4e} s against τ_dom {:.4e} s: a test that does not excite the plant \
             (a sample time far above its dynamics, an input that does not move this output, noise swamping the \
             response) leaves the regression singular",
            o.path, design.sample_time, design.tau_dom
        )),
        e => e,
    };
    outputs
        .iter()
        .enumerate()
        .map(|(i, o)| fit_output(est, val, i, n_fir, &o.path).map_err(|e| explain(o, e)))
        .collect()
}

/// The table of every model: per output and structure, its gains (display units), fit and
/// whether it passes the criteria of one output (`reliable(i, s)` for output `i`, structure `s`).
pub(super) fn summaries(
    per_output: &[Vec<Fitted>],
    inputs: &[Signal],
    outputs: &[Signal],
    reliable: &dyn Fn(usize, usize) -> bool,
) -> Vec<ModelSummary> {
    let display =
        |o: &Signal, g: &[f64]| -> Vec<f64> { g.iter().zip(inputs).map(|(g, s)| g * s.factor / o.factor).collect() };
    let mut models = Vec::new();
    for (i, (fits, o)) in per_output.iter().zip(outputs).enumerate() {
        for (s, f) in fits.iter().enumerate() {
            models.push(ModelSummary {
                output: o.path.clone(),
                model: f.model.to_string(),
                orders: f.orders.clone(),
                gain: display(o, &f.gain),
                gain_std: f.gain_std.as_ref().map(|g| display(o, g)),
                reliable: reliable(i, s),
                fit_percent: f.validation.fit_percent,
                fit_noise_free: f.validation.fit_noise_free,
                white: f.validation.white,
                independent: f.validation.independent,
            });
        }
    }
    models
}
