//! Library results as plain Python values (dicts of lists and floats); the Python package turns
//! them into numpy arrays, DataFrames and python-control systems.

use plantwide_analysis::measures::rows;
use plantwide_analysis::plant_model::{PlantGains, PlantModel};
use plantwide_analysis::select::{Signal, SignalLabel};
use plantwide_analysis::sensitivity::Curve;
use plantwide_io::export::ModelExport;
use plantwide_solve::dynamic::SimulationResult;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// `(path, unit)` of each label.
fn pairs(labels: &[SignalLabel]) -> Vec<(String, String)> {
    labels.iter().map(|s| (s.path.clone(), s.unit.clone())).collect()
}

/// `(path, unit)` of each signal.
fn signal_pairs(signals: &[Signal]) -> Vec<(String, String)> {
    signals.iter().map(|s| (s.path.clone(), s.unit.clone())).collect()
}

/// The gain report: `gain`, `rga` (None when singular), `singular_values`, `u`, `v`,
/// `condition_number`, `niederlinski`, `rga_number`, `pairing`, `inputs`/`outputs` as
/// `(path, unit)`, and for perturbation gains `perturbation` (JSON text of the check).
pub fn gains<'py>(py: Python<'py>, g: &PlantGains) -> PyResult<Bound<'py, PyDict>> {
    let r = &g.report;
    let d = PyDict::new(py);
    d.set_item("method", &r.method)?;
    d.set_item("inputs", pairs(&r.inputs))?;
    d.set_item("outputs", pairs(&r.outputs))?;
    d.set_item("gain", rows(r.gain.as_ref()))?;
    d.set_item("rga", r.rga.as_ref().map(|l| rows(l.as_ref())))?;
    d.set_item("singular_values", &r.svd.singular_values)?;
    d.set_item("u", rows(r.svd.u.as_ref()))?;
    d.set_item("v", rows(r.svd.v.as_ref()))?;
    d.set_item("condition_number", r.condition_number)?;
    d.set_item("min_condition_number", r.min_condition_number)?;
    d.set_item("niederlinski", r.niederlinski)?;
    d.set_item("rga_number", r.rga_number)?;
    d.set_item("pairing", r.pairing.clone())?;
    let check = g.perturbation.as_ref().map(|p| serde_json::to_string(&p.check)).transpose();
    d.set_item("perturbation", check.map_err(|e| crate::error::PlantwideError::new_err(e.to_string()))?)?;
    Ok(d)
}

/// The linear model as the export writes it (time in seconds): `A, B, C, D`,
/// `steady_state_gain`, the paths and units of states, inputs and outputs, their
/// python-control-safe `names` and steady values, the eigenvalues `(re, im)` [1/s], and the JSON
/// export itself (`json`).
pub fn linear_model<'py>(
    py: Python<'py>,
    name: &str,
    model: &PlantModel,
    inputs: &[Signal],
    outputs: &[Signal],
) -> PyResult<Bound<'py, PyDict>> {
    let export = ModelExport { name, model, inputs, outputs, time_unit: ("s", 1.0) };
    let m = export.matrices();
    let names = export.names();
    let d = PyDict::new(py);
    d.set_item("name", name)?;
    for (k, v) in [("A", m.a), ("B", m.b), ("C", m.c), ("D", m.d)] {
        d.set_item(k, v)?;
    }
    d.set_item("steady_state_gain", m.steady_state_gain)?;
    d.set_item("states", &model.states)?;
    d.set_item("inputs", signal_pairs(inputs))?;
    d.set_item("outputs", signal_pairs(outputs))?;
    d.set_item("state_names", names.states)?;
    d.set_item("input_names", names.inputs)?;
    d.set_item("output_names", names.outputs)?;
    d.set_item("state_values", &model.state_values)?;
    d.set_item("input_values", &model.input_values)?;
    d.set_item("output_values", &model.output_values)?;
    d.set_item("eigenvalues", model.eigenvalues.iter().map(|l| (l.re, l.im)).collect::<Vec<_>>())?;
    d.set_item("json", export.to_json_string())?;
    Ok(d)
}

/// A run's trends: `time` [s], `columns` as `(path, si_unit)`, `rows` (SI, one per time) and the
/// scenario events `(time, origin)`.
pub fn trends<'py>(py: Python<'py>, r: &SimulationResult) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("time", &r.times)?;
    d.set_item("columns", r.columns.iter().map(|c| (c.path.clone(), c.si_unit.clone())).collect::<Vec<_>>())?;
    d.set_item("rows", r.rows.iter().collect::<Vec<&[f64]>>())?;
    d.set_item("events", &r.events)?;
    Ok(d)
}

/// One sensitivity curve: the disturbance's `path` and `base` (SI), its `values` (SI), the
/// `outputs` (SI; None where a point did not converge), the output paths and the failures.
pub fn curve<'py>(py: Python<'py>, c: &Curve, outputs: &[Signal]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("path", &c.disturbance.signal.path)?;
    d.set_item("base", c.disturbance.base)?;
    d.set_item("values", &c.values)?;
    d.set_item("outputs", &c.outputs)?;
    d.set_item("output_paths", outputs.iter().map(|s| s.path.clone()).collect::<Vec<_>>())?;
    d.set_item("failures", c.failures.iter().map(|f| f.to_string()).collect::<Vec<_>>())?;
    Ok(d)
}
