//! The sensitivity-plot test of *Practical Distillation Control* ch. 6 (fig. 6-6): with the CVs held
//! on their setpoints, each disturbance is swept over ± its step by natural-parameter continuation
//! ([`plantwide_analysis::sensitivity::sweep`], 9 points), and every watched (uncontrolled)
//! variable must stay in its band over the whole sweep. At steady state the integral loops hold
//! the CVs whatever the pairing, so the test depends on the CVs and the throughput choice only: it
//! is run once per throughput choice and applies to all its pairings.

use plantwide_analysis::sensitivity::{Disturbance, SweepSettings, sweep};
use serde::Serialize;

use super::dynamic::trial_plant;
use super::{OpenPlant, PairingRequest, PairingStructure};
use crate::screen::ScreenError;

/// A variable that must stay in a band (SI).
#[derive(Debug, Clone, PartialEq)]
pub struct Watch {
    /// Variable path.
    pub path: String,
    /// Lowest allowed value.
    pub low: f64,
    /// Highest allowed value.
    pub high: f64,
}

/// A watched variable over one disturbance's sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WatchResult {
    /// Variable path.
    pub path: String,
    /// The disturbance swept, `path ±x %`.
    pub disturbance: String,
    /// Lowest value over the sweep.
    pub min: f64,
    /// Highest value over the sweep.
    pub max: f64,
    /// The band.
    pub band: [f64; 2],
    /// Whether every point converged and stayed in the band.
    pub within: bool,
}

/// Run the test for each throughput choice among `structures` and reject the structures whose
/// watched variables leave their bands.
pub(super) fn test(
    open: &OpenPlant,
    r: &PairingRequest,
    structures: &mut [PairingStructure],
) -> Result<(), ScreenError> {
    let mut done: Vec<(Option<String>, Vec<WatchResult>)> = Vec::new();
    for s in structures.iter_mut() {
        let tpm = s.throughput.clone();
        let results = match done.iter().find(|(t, _)| *t == tpm) {
            Some((_, w)) => w.clone(),
            None => {
                let w = choice(open, r, s)?;
                done.push((tpm, w.clone()));
                w
            }
        };
        if let Some(w) = results.iter().find(|w| !w.within)
            && s.passed
        {
            s.passed = false;
            s.rejected = Some(format!(
                "sensitivity: {} goes over {:.6e} … {:.6e} for {}, outside its band {:.6e} … {:.6e}",
                w.path, w.min, w.max, w.disturbance, w.band[0], w.band[1]
            ));
        }
        s.sensitivity = results;
    }
    Ok(())
}

/// The sweeps of one throughput choice, on the plant with `s`'s loops closed.
fn choice(open: &OpenPlant, r: &PairingRequest, s: &PairingStructure) -> Result<Vec<WatchResult>, ScreenError> {
    let fail = |why: String| ScreenError::Sensitivity { throughput: s.throughput.clone().unwrap_or_default(), why };
    let (plant, x) = trial_plant(open, r, s).map_err(|e| fail(e.to_string()))?;
    let u = plant.input_values();
    let outputs: Vec<usize> = r.watch.iter().filter_map(|w| plant.var(&w.path)).collect();
    let mut out = Vec::new();
    for d in r.sweeps() {
        let u0 = plantwide_flowsheet::overrides::resolve_input(&plant, &d.path).map_or(f64::NAN, |i| u[i]);
        let dist = Disturbance::parse(&plant, &u, &d.sweep_range(u0)).map_err(|e| fail(e.to_string()))?;
        let settings = SweepSettings { points: 9, ..SweepSettings::default() };
        let curves = sweep(&plant, &x, &u, &[dist], &outputs, &settings).map_err(|e| fail(e.to_string()))?;
        for (j, w) in r.watch.iter().enumerate() {
            let values: Vec<Option<f64>> = curves[0].outputs.iter().map(|o| o.as_ref().map(|v| v[j])).collect();
            let seen = values.iter().flatten();
            let (min, max) =
                (seen.clone().copied().fold(f64::INFINITY, f64::min), seen.copied().fold(f64::NEG_INFINITY, f64::max));
            let converged = values.iter().all(Option::is_some);
            out.push(WatchResult {
                path: w.path.clone(),
                disturbance: d.sweep_label(),
                min,
                max,
                band: [w.low, w.high],
                within: converged && min >= w.low && max <= w.high,
            });
        }
    }
    Ok(out)
}
