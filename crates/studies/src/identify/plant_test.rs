//! The plant test: the nonlinear model run from its steady state by a [`Session`], each input held
//! at its designed move over a sample (zero-order hold), each output sampled at the start of the
//! sample with seeded white measurement noise.

use plantwide_flowsheet::Plant;
use plantwide_ident::signals::white_noise;
use plantwide_solve::dae::BdfSettings;
use plantwide_solve::dynamic::Session;

use super::IdentifyError;

/// Test data as deviations from the pre-test steady state (SI): `u[j][k]` is input `j` over
/// `[t_k, t_k+1)`, `y[i][k]` output `i` measured at `t_k` (with the noise), `clean[i][k]` the
/// plant's own output there (without it: what a model is judged against, since a model study
/// knows it).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct TestData {
    pub u: Vec<Vec<f64>>,
    pub y: Vec<Vec<f64>>,
    pub clean: Vec<Vec<f64>>,
}

/// What a test moves and reads: the inputs it sets (the plant's inputs in open loop, the loops'
/// setpoints in closed loop), the outputs, and in closed loop the controller outputs read as the
/// test's inputs (sampled at the start of each sample).
pub(super) struct Probe {
    pub set: Vec<usize>,
    pub outputs: Vec<usize>,
    pub measured_inputs: Option<Vec<usize>>,
    /// Per output, the smallest move the data must resolve (SI): in open loop the smallest
    /// `|G_ij| a_j` of its row (see [`resolve`]); `None`: the output's whole excursion in the test.
    pub resolve: Option<Vec<f64>>,
}

/// Per output `i`, the smallest `|G_ij| a_j` of its row that is at least 1e-3 of the row's
/// largest: the move one input alone makes in it at the test's amplitude `a` (SI), which the data
/// must resolve for that element's gain to be identified (smaller elements are below any test's
/// resolution beside the others, with or without noise).
pub(super) fn resolve(gain: &faer::Mat<f64>, amplitude: &[f64]) -> Vec<f64> {
    (0..gain.nrows())
        .map(|i| {
            let moves: Vec<f64> = (0..gain.ncols()).map(|j| (gain[(i, j)] * amplitude[j]).abs()).collect();
            let largest = moves.iter().copied().fold(0.0, f64::max);
            moves.into_iter().filter(|&m| m >= 1e-3 * largest && m > 0.0).fold(f64::INFINITY, f64::min)
        })
        .collect()
}

/// How far below the smallest move the test must resolve in an output the integrator's error
/// weight `rtol·|y| + atol·nominal` must lie: local errors of the BDF stay under that weight, and
/// a global error ten of them deep still leaves that move 1 % off.
const ACCURACY_MARGIN: f64 = 1e3;

/// The tightest relative tolerance the test will integrate at; an output that moves less than
/// [`ACCURACY_MARGIN`] times this (relative to its size) cannot be identified from the model.
const TIGHTEST_RTOL: f64 = 1e-12;

/// Run the test `moves` (per set input, per sample) on `plant` from its steady state `x`,
/// sampling every `ts` seconds; `noise[i]` is output `i`'s measurement σ (SI).
///
/// The run is integrated at the default tolerances first; where the move an output must resolve
/// ([`Probe::resolve`]) is not [`ACCURACY_MARGIN`] times the integrator's error weight on it (a
/// composition moved by 1e-6 at a relative tolerance of 1e-6: the data would be integration
/// error), the test is run again at tolerances tightened by the shortfall.
///
/// # Errors
/// [`IdentifyError::Simulation`] when a run fails; [`IdentifyError::Estimation`] when an output
/// moves too little to be resolved even at [`TIGHTEST_RTOL`].
pub(super) fn run(
    plant: &Plant,
    x: &[f64],
    probe: &Probe,
    moves: &[Vec<f64>],
    noise: &[f64],
    (ts, seed): (f64, u64),
) -> Result<TestData, IdentifyError> {
    let default = BdfSettings::default();
    let (rtol, atol) = (default.rtol, default.atol);
    let (mut u, mut y) = sampled(plant, x, probe, moves, ts, default)?;
    let shortfall = shortfall(plant, x, probe, &y, (rtol, atol));
    if shortfall < 1.0 {
        if rtol * shortfall < TIGHTEST_RTOL {
            return Err(IdentifyError::Estimation(too_small(plant, &probe.outputs, &y, shortfall)));
        }
        let tighter = BdfSettings { rtol: rtol * shortfall, atol: atol * shortfall, ..BdfSettings::default() };
        (u, y) = sampled(plant, x, probe, moves, ts, tighter)?;
    }
    let n = y.first().map_or(0, Vec::len);
    let clean = y.clone();
    for (i, yi) in y.iter_mut().enumerate() {
        if noise[i] > 0.0 {
            let e = white_noise(n, noise[i], seed.wrapping_add(1000 + i as u64))
                .map_err(|e| IdentifyError::Estimation(format!("measurement noise: {e}")))?;
            yi.iter_mut().zip(e).for_each(|(v, e)| *v += e);
        }
    }
    let u = if probe.measured_inputs.is_some() { u } else { moves.to_vec() };
    Ok(TestData { u, y, clean })
}

/// Samples per signal.
type Series = Vec<Vec<f64>>;

/// The test's samples `(u, y)`: the measured inputs (closed loop) and the outputs, as deviations,
/// without noise, integrated at `settings`.
fn sampled(
    plant: &Plant,
    x: &[f64],
    probe: &Probe,
    moves: &[Vec<f64>],
    ts: f64,
    settings: BdfSettings,
) -> Result<(Series, Series), IdentifyError> {
    let (inputs, outputs) = (&probe.set, &probe.outputs);
    let n = moves.first().map_or(0, Vec::len);
    let mut session = Session::with_settings(plant, x, settings).map_err(|e| IdentifyError::Simulation(Box::new(e)))?;
    let u0: Vec<f64> = inputs.iter().map(|&i| plant.inputs()[i].value).collect();
    let y0: Vec<f64> = outputs.iter().map(|&v| x[v]).collect();
    let mut y = vec![Vec::with_capacity(n); outputs.len()];
    let mvs = probe.measured_inputs.as_deref().unwrap_or(&[]);
    let mut u = vec![Vec::with_capacity(n); mvs.len()];
    for (k, t_next) in (1..=n).map(|k| (k - 1, k as f64 * ts)) {
        let state = session.state();
        for (i, &v) in outputs.iter().enumerate() {
            y[i].push(state[v] - y0[i]);
        }
        for (j, &v) in mvs.iter().enumerate() {
            u[j].push(state[v] - x[v]);
        }
        for (j, &inp) in inputs.iter().enumerate() {
            session.set_input(inp, u0[j] + moves[j][k]);
        }
        session.advance_to(t_next).map_err(|e| IdentifyError::Simulation(Box::new(e)))?;
    }
    Ok((u, y))
}

/// `min_i resolve_i / (ACCURACY_MARGIN · (rtol·|y_i| + atol·nominal_i))` over the outputs that
/// move (`resolve_i` from the probe, or output `i`'s excursion in `y`): below 1, the factor the
/// tolerances must shrink by for the data to resolve every output.
fn shortfall(plant: &Plant, x: &[f64], probe: &Probe, y: &[Vec<f64>], (rtol, atol): (f64, f64)) -> f64 {
    probe
        .outputs
        .iter()
        .zip(y)
        .enumerate()
        .map(|(i, (&v, yi))| {
            let excursion = yi.iter().fold(0.0f64, |m, d| m.max(d.abs()));
            let needed = probe.resolve.as_ref().map_or(excursion, |r| r[i]);
            let weight = rtol * x[v].abs() + atol * plant.vars()[v].spec.nominal.abs();
            needed / (ACCURACY_MARGIN * weight)
        })
        .filter(|r| r.is_finite() && *r > 0.0)
        .fold(f64::INFINITY, f64::min)
}

/// The message for outputs that move too little to be resolved at [`TIGHTEST_RTOL`].
fn too_small(plant: &Plant, outputs: &[usize], y: &[Vec<f64>], shortfall: f64) -> String {
    let moves: Vec<String> = outputs
        .iter()
        .zip(y)
        .map(|(&v, yi)| format!("`{}` by {:.3e}", plant.vars()[v].path, yi.iter().fold(0.0f64, |m, d| m.max(d.abs()))))
        .collect();
    format!(
        "the test moves the outputs too little to be told from integration error (largest moves: {}): at the \
         tightest relative tolerance, {TIGHTEST_RTOL:e}, each output must move {ACCURACY_MARGIN:e} times that \
         tolerance of its size, and one moves {:.1e} of it; raise the test's amplitude",
        moves.join(", "),
        shortfall * BdfSettings::default().rtol / TIGHTEST_RTOL
    )
}
