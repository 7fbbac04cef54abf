//! The plant test: the nonlinear model run from its steady state by a [`Session`], each input held
//! at its designed move over a sample (zero-order hold), each output sampled at the start of the
//! sample with seeded white measurement noise.

use plantwide_flowsheet::Plant;
use plantwide_ident::signals::white_noise;
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
}

/// Run the test `moves` (per set input, per sample) on `plant` from its steady state `x`,
/// sampling every `ts` seconds; `noise[i]` is output `i`'s measurement σ (SI).
pub(super) fn run(
    plant: &Plant,
    x: &[f64],
    probe: &Probe,
    moves: &[Vec<f64>],
    noise: &[f64],
    (ts, seed): (f64, u64),
) -> Result<TestData, IdentifyError> {
    let (inputs, outputs) = (&probe.set, &probe.outputs);
    let n = moves.first().map_or(0, Vec::len);
    let mut session = Session::new(plant, x).map_err(|e| IdentifyError::Simulation(Box::new(e)))?;
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
