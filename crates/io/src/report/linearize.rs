//! The report of a linear model: a plant's state-space model at its steady state ([`PlantModel`]:
//! its size, slowest time constants, unstable modes and steady-state gain, checked against
//! `−C J⁻¹ B`) or a transfer-function model's elements and poles, in the time unit asked for.
//! `plantwide linearize` prints these pieces as it finds them, and what it wrote.

use std::path::Path;

use plantwide_analysis::faer::{Mat, c64};
use plantwide_analysis::plant_model::{PlantModel, display_gain};
use plantwide_analysis::select::Signal;
use plantwide_analysis::tf::TfModel;

use super::sig6 as sig;

/// The model's size: states, inputs and outputs of the plant `name`.
pub fn heading(name: &str, pm: &PlantModel, inputs: usize, outputs: usize) -> String {
    format!(
        "linear model of `{name}` at its steady state: {} states, {inputs} inputs, {outputs} outputs\n",
        pm.model.states.len()
    )
}

/// The five slowest time constants (`time_constants` \[s\]) and the integrating or unstable modes
/// (`unstable` \[1/s\]), in `time_unit` (name, seconds per unit).
pub fn modes(time_constants: &[f64], unstable: &[c64], time_unit: (&str, f64)) -> String {
    let (name, seconds) = time_unit;
    let slow: Vec<String> = time_constants.iter().take(5).map(|t| sig(t / seconds)).collect();
    let mut t = format!("slowest time constants [{name}]: {}\n", slow.join(", "));
    if !unstable.is_empty() {
        let ev: Vec<String> =
            unstable.iter().map(|l| format!("{:.4e}{:+.4e}j", l.re * seconds, l.im * seconds)).collect();
        t.push_str(&format!("integrating or unstable modes [1/{name}]: {}\n", ev.join(", ")));
    }
    t
}

/// The steady-state gain `D − C A⁻¹ B` (`gain`, SI) in display units, output unit per input
/// unit, with how far it is from `−C J⁻¹ B` (`direct`, SI).
pub fn gain(gain: &Mat<f64>, direct: &Mat<f64>, inputs: &[Signal], outputs: &[Signal]) -> String {
    let g = display_gain(gain, inputs, outputs);
    let gd = display_gain(direct, inputs, outputs);
    // Relative to the largest gain: an output held by integral action has a gain of rounding size,
    // which no relative difference of its own describes.
    let cells = || (0..g.nrows()).flat_map(|i| (0..g.ncols()).map(move |j| (i, j)));
    let largest = cells().map(|(i, j)| gd[(i, j)].abs()).fold(0.0, f64::max);
    let diff = cells().map(|(i, j)| (g[(i, j)] - gd[(i, j)]).abs()).fold(0.0, f64::max);
    // Below 1e-10 in display units a gain is zero to rounding: an output held by integral action.
    let check = if largest > 1e-10 {
        format!("agrees with −C J⁻¹ B to {:.1e} of its largest entry", diff / largest)
    } else {
        format!(
            "−C J⁻¹ B is 0 to rounding ({largest:.1e}), so the outputs are held at steady state; these are {diff:.1e} off it"
        )
    };
    let mut t = format!("steady-state gain D − C A⁻¹ B ({check}), output unit per input unit:\n");
    let heads: Vec<String> = inputs.iter().map(|i| format!("{:>14}", format!("{} [{}]", i.path, i.unit))).collect();
    t.push_str(&format!("  {:<28} {}\n", "", heads.join(" ")));
    for (i, o) in outputs.iter().enumerate() {
        let cells: Vec<String> = (0..g.ncols()).map(|j| format!("{:>14}", sig(g[(i, j)]))).collect();
        t.push_str(&format!("  {:<28} {}\n", format!("{} [{}]", o.path, o.unit), cells.join(" ")));
    }
    t
}

/// That the model was written to `out`, and how to load it: a NumPy archive (`npz`) or JSON.
pub fn written(out: &Path, npz: bool) -> String {
    let how = match npz {
        true => {
            "numpy `np.load`; `state_names`, `input_names`, `output_names` are python-control-safe, `*_paths` the paths they stand for"
        }
        false => {
            "A, B, C, D; load with python-control `control.ss(A, B, C, D)` or MATLAB `ss(m.A, m.B, m.C, m.D)`; `names` are python-control-safe signal names, `labels` their paths"
        }
    };
    format!("wrote {} ({how})\n", out.display())
}

/// A transfer-function model's elements (numerator, denominator and dead time, from its export
/// `doc`, [`crate::tf::export`]) and poles, with `s` in rad per `time_unit` and times in it.
pub fn tf_text(model: &TfModel, doc: &serde_json::Value, time_unit: &str) -> String {
    let mut t = format!(
        "transfer-function model `{}`: {} inputs, {} outputs (s in rad/{time_unit}, times in {time_unit})\n",
        model.name,
        model.inputs.len(),
        model.outputs.len(),
    );
    for (i, o) in model.outputs.iter().enumerate() {
        for (j, inp) in model.inputs.iter().enumerate() {
            let e = &doc["elements"][i][j];
            if e.is_null() {
                continue;
            }
            t.push_str(&format!(
                "  {} ← {}: num {} / den {} · e^(−{} s)\n",
                o.name,
                inp.name,
                e["num"],
                e["den"],
                sig(e["dead_time"].as_f64().unwrap_or(f64::NAN))
            ));
        }
    }
    let poles: Vec<String> =
        doc["poles"].as_array().into_iter().flatten().filter_map(|p| p.as_f64()).map(sig).collect();
    t.push_str(&format!("poles [1/{time_unit}]: {}\n", poles.join(", ")));
    t
}

/// That the transfer-function model's export was written to `out`, and how to load it.
pub fn tf_written(out: &Path) -> String {
    format!("wrote {} (per element `num`, `den`, `dead_time`: python-control `control.tf(num, den)`)\n", out.display())
}
