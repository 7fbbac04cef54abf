//! Closed-loop tests by setpoint injection (§2.6): the inputs to identify are driven by PID loops
//! of the file; the test moves the loops' setpoints, the loops move the inputs, and the fits read
//! the controller outputs as the inputs (the direct method: strongly system identifiable with an
//! external persistently exciting signal, Eq. 7-x of §7-3-5).
//!
//! The setpoint moves are the designed input moves mapped through the gain from the inputs to the
//! loops' measurements, `δr = G_pv(0) δu`: at low frequency the loops then move the inputs by the
//! designed `δu`, so a directional design keeps its directions in closed loop. The exact
//! comparison is the open-loop gain, the loops in manual.

use faer::Mat;
use plantwide_analysis::linear::Linearization;
use plantwide_analysis::select::{Signal, select_outputs};
use plantwide_flowsheet::{Plant, VarPath};

use super::IdentifyError;
use crate::tune::loops::{PlantLoop, in_manual, plant_loop};

/// The inputs (`PATH[@unit]`) of a closed-loop test: each must be driven by a PID loop. The
/// signal's index is the input's.
///
/// # Errors
/// [`IdentifyError::Request`] for a path that names no input or a free one.
pub fn select_driven(plant: &Plant, texts: &[String]) -> Result<Vec<Signal>, IdentifyError> {
    texts
        .iter()
        .map(|t| {
            let path = plantwide_analysis::select::split_unit(t).0;
            let Some(i) = plant.input(path) else {
                return Err(IdentifyError::Request(format!("with `closed_loop`, `{path}` is no input of the plant")));
            };
            if plant.inputs()[i].driven_by.is_none() {
                return Err(IdentifyError::Request(format!(
                    "with `closed_loop`, `{path}` is not driven by a controller: identify it in open loop (without `closed_loop`)"
                )));
            }
            let mut s = select_outputs(plant, std::slice::from_ref(t))?.remove(0);
            s.index = i;
            Ok(s)
        })
        .collect()
}

/// The loops driving the inputs, their setpoint inputs, the plant with them in manual and the
/// open-loop gains from their outputs to `outputs` and to their own measurements.
pub(super) struct Loops {
    pub loops: Vec<PlantLoop>,
    pub setpoints: Vec<usize>,
    pub gain: Mat<f64>,
    pub gain_pv: Mat<f64>,
}

/// The PID loops driving `inputs` at the steady state `x`.
pub(super) fn loops(plant: &Plant, x: &[f64], inputs: &[Signal], outputs: &[usize]) -> Result<Loops, IdentifyError> {
    let mut loops = Vec::new();
    let mut setpoints = Vec::new();
    for s in inputs {
        let v = plant.inputs()[s.index].driven_by.ok_or_else(|| {
            IdentifyError::Request(format!("with `closed_loop`, `{}` is not driven by a controller", s.path))
        })?;
        let name = plant.blocks()[plant.vars()[v].block].name.clone();
        let l = plant_loop(plant, &name).map_err(|_| {
            IdentifyError::Request(format!(
                "with `closed_loop`, `{}` is driven by `{name}`, which is no PID loop with a setpoint: setpoint injection needs one",
                s.path
            ))
        })?;
        let sp = plant.input(VarPath::setpoint(&name)).ok_or_else(|| {
            IdentifyError::Request(format!(
                "with `closed_loop`, loop `{name}` has a remote setpoint: inject at its master's setpoint instead"
            ))
        })?;
        loops.push(l);
        setpoints.push(sp);
    }
    let manual = in_manual(plant, x, &loops);
    let lin = Linearization::new(&manual, x, &manual.input_values());
    let ops: Vec<usize> = loops.iter().map(|l| l.op_manual).collect();
    let pvs: Vec<usize> = loops.iter().map(|l| l.pv).collect();
    let gain = lin.steady_gain(&ops, outputs)?;
    let gain_pv = lin.steady_gain(&ops, &pvs)?;
    Ok(Loops { loops, setpoints, gain, gain_pv })
}

/// Setpoint moves `δr = G_pv δu` per loop and sample.
pub(super) fn setpoint_moves(gain_pv: &Mat<f64>, moves: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = moves.first().map_or(0, Vec::len);
    (0..gain_pv.nrows())
        .map(|i| (0..n).map(|k| (0..moves.len()).map(|j| gain_pv[(i, j)] * moves[j][k]).sum()).collect())
        .collect()
}
