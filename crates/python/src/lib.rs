//! `plantwide._plantwide`: the extension module under the Python package `plantwide`
//! (`python/plantwide`). Each function takes flowsheet text and `--set` assignments, calls the
//! library the way the CLI does (`plant.rs`), releases the GIL while it works, and hands back
//! plain Python values (`convert.rs`); numpy arrays, DataFrames, python-control systems and Dask
//! tasks are built on the Python side. Library errors arrive as `InputError` or
//! `ConvergenceError` (both `PlantwideError`) with the library's message.

mod convert;
mod error;
mod plant;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

use error::{ConvergenceError, FaceError, InputError, PlantwideError};
use plant::Source;
use plantwide_analysis::plant_model::GainMethod;

/// The flowsheet file at `path`, read by the library (its size limit, its messages).
#[pyfunction]
fn read_text(py: Python<'_>, path: String) -> PyResult<String> {
    py.detach(|| plantwide_flowsheet::read_text(std::path::Path::new(&path)).map_err(|e| FaceError::input(e).into()))
}

/// Load and validate (every problem with its JSON path); returns the plant's name, its free
/// inputs and its variable paths.
#[pyfunction]
fn check(py: Python<'_>, text: String, name: String) -> PyResult<(String, Vec<String>, Vec<String>)> {
    py.detach(|| {
        let plant = Source { text, name }.load(&[])?;
        let free = plant.inputs().iter().filter(|i| i.driven_by.is_none()).map(|i| i.path.clone()).collect();
        let vars = plant.vars().iter().map(|v| v.path.clone()).collect();
        Ok((plant.name().to_string(), free, vars))
    })
    .map_err(|e: FaceError| e.into())
}

/// `plantwide steady --set …`: `(path, SI value)` of every variable and free input, and the
/// warnings.
#[pyfunction]
#[pyo3(signature = (text, name, sets, method = "auto"))]
fn steady(py: Python<'_>, text: String, name: String, sets: Vec<String>, method: &str) -> PyResult<plant::Steady> {
    let method = plant::method(method)?;
    Ok(py.detach(|| plant::steady(&Source { text, name }, &sets, method))?)
}

/// One steady state per entry of `sets` (in parallel, rayon), the values of `outputs` in each, in
/// order. A point that fails raises, naming it.
#[pyfunction]
#[pyo3(signature = (text, name, sets, outputs, method = "auto"))]
fn sweep(
    py: Python<'_>,
    text: String,
    name: String,
    sets: Vec<Vec<String>>,
    outputs: Vec<String>,
    method: &str,
) -> PyResult<Vec<Vec<f64>>> {
    let method = plant::method(method)?;
    let src = Source { text, name };
    let results: Vec<Result<Vec<f64>, FaceError>> =
        py.detach(|| sets.par_iter().map(|s| plant::steady_outputs(&src, s, &outputs, method)).collect());
    let named = |k: usize, e: FaceError| match e {
        FaceError::Input(m) => FaceError::Input(format!("sweep point {k} ({}): {m}", sets[k].join(", "))),
        FaceError::Convergence(m) => FaceError::Convergence(format!("sweep point {k} ({}): {m}", sets[k].join(", "))),
    };
    Ok(results.into_iter().enumerate().map(|(k, r)| r.map_err(|e| named(k, e))).collect::<Result<_, _>>()?)
}

/// `plantwide gains`: the gains and every measure, as a dict.
#[pyfunction]
#[pyo3(signature = (text, name, sets, inputs, outputs, method = "linear", step = None, pairing = None))]
#[allow(clippy::too_many_arguments)] // one per keyword of the Python method
fn gains<'py>(
    py: Python<'py>,
    text: String,
    name: String,
    sets: Vec<String>,
    inputs: Vec<String>,
    outputs: Vec<String>,
    method: &str,
    step: Option<f64>,
    pairing: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let method = match method {
        "linear" => GainMethod::Linear,
        "perturb" => GainMethod::Perturb { step },
        _ => return Err(InputError::new_err(format!("method `{method}`: expected `linear` or `perturb`"))),
    };
    let src = Source { text, name };
    let g = py.detach(|| plant::gains(&src, &sets, (&inputs, &outputs), method, pairing.as_deref()))?;
    convert::gains(py, &g)
}

/// `plantwide linearize`: `A, B, C, D` (per second, display units), labels and the export.
#[pyfunction]
fn linearize<'py>(
    py: Python<'py>,
    text: String,
    name: String,
    sets: Vec<String>,
    inputs: Vec<String>,
    outputs: Vec<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let src = Source { text, name };
    let (plant_name, model, ins, outs) = py.detach(|| plant::linearize(&src, &sets, (&inputs, &outputs)))?;
    convert::linear_model(py, &plant_name, &model, &ins, &outs)
}

/// `plantwide run`: the recorded trends of the scenario (text `scenario`, named `scenario_name`).
#[pyfunction]
fn run<'py>(
    py: Python<'py>,
    text: String,
    name: String,
    sets: Vec<String>,
    scenario: String,
    scenario_name: String,
) -> PyResult<Bound<'py, PyDict>> {
    let (src, scen) = (Source { text, name }, Source { text: scenario, name: scenario_name });
    let res = py.detach(|| plant::run(&src, &sets, &scen))?;
    convert::trends(py, &res)
}

/// `plantwide sensitivity`: one curve per disturbance.
#[pyfunction]
#[pyo3(signature = (text, name, sets, disturb, outputs, points = 21))]
fn sensitivity<'py>(
    py: Python<'py>,
    text: String,
    name: String,
    sets: Vec<String>,
    disturb: Vec<String>,
    outputs: Vec<String>,
    points: usize,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let src = Source { text, name };
    let (curves, outs) = py.detach(|| plant::sensitivity(&src, &sets, &disturb, &outputs, points))?;
    curves.iter().map(|c| convert::curve(py, c, &outs)).collect()
}

/// `plantwide screen … --json`: the screen's JSON text (a column's configurations or the
/// pairings) and the message of its failed parts; `request` is the study's request as JSON.
/// `shard = (I, N)` runs that share of a pairing screen's dynamic tests (their results as JSON);
/// `merged` (JSON by task number, as a Dask sweep gathers the shards') finishes it; `report` a
/// folder for the CLI's report in `units`.
#[pyfunction]
#[pyo3(signature = (text, name, sets, request, shard = None, merged = None, report = None, units = "si"))]
#[allow(clippy::too_many_arguments)] // one per keyword of the Python function
fn screen(
    py: Python<'_>,
    text: String,
    name: String,
    sets: Vec<String>,
    request: String,
    shard: Option<(usize, usize)>,
    merged: Option<String>,
    report: Option<String>,
    units: &str,
) -> PyResult<plant::Answer> {
    let share = match (shard, merged) {
        (Some(_), Some(_)) => return Err(InputError::new_err("screen: a shard or merged results, not both")),
        (Some((index, count)), None) => {
            let s: plantwide_analysis::shard::Shard =
                format!("{index}/{count}").parse().map_err(|e| InputError::new_err(format!("{e}")))?;
            plant::PairingShare::Shard(s)
        }
        (None, Some(m)) => plant::PairingShare::Merge(m),
        (None, None) => plant::PairingShare::All,
    };
    let system = plant::units(units)?;
    let src = Source { text, name };
    Ok(py.detach(|| plant::screen(&src, &sets, &request, share, report.as_deref().map(|d| (d, system))))?)
}

/// `plantwide size --json`: the sizing's JSON text and the message of its failed parts (none
/// when all have their answer); `request` is the study's request as JSON, `report` a folder to
/// write the CLI's report to, in `units` (`si`, `metric` or `field`).
#[pyfunction]
#[pyo3(signature = (text, name, sets, request, report = None, units = "si"))]
fn size(
    py: Python<'_>,
    text: String,
    name: String,
    sets: Vec<String>,
    request: String,
    report: Option<String>,
    units: &str,
) -> PyResult<plant::Answer> {
    let system = plant::units(units)?;
    let src = Source { text, name };
    Ok(py.detach(|| plant::size(&src, &sets, &request, report.as_deref().map(|d| (d, system))))?)
}

/// `plantwide tune FILE --json`: the tuning's JSON text (times in the request's `time_unit`) and
/// the message of the loops their margins refute (none when all hold); `report` a folder for the
/// CLI's report, `write` a file for the tuned flowsheet (written only when no loop is refuted).
#[pyfunction]
#[pyo3(signature = (text, name, sets, request, report = None, write = None))]
fn tune(
    py: Python<'_>,
    text: String,
    name: String,
    sets: Vec<String>,
    request: String,
    report: Option<String>,
    write: Option<String>,
) -> PyResult<plant::Answer> {
    let src = Source { text, name };
    Ok(py.detach(|| plant::tune(&src, &sets, &request, report.as_deref(), write.as_deref()))?)
}

/// `plantwide compare A.json B.json … --json`: the comparison's JSON text and the message of its
/// failed parts (none when all have their answer); `schemes` are `(text, name)` of each flowsheet,
/// `request` the study's request as JSON, `report` a folder for the CLI's report in `units`.
#[pyfunction]
#[pyo3(signature = (schemes, request, report = None, units = "si"))]
fn compare(
    py: Python<'_>,
    schemes: Vec<(String, String)>,
    request: String,
    report: Option<String>,
    units: &str,
) -> PyResult<plant::Answer> {
    let system = plant::units(units)?;
    let sources: Vec<Source> = schemes.into_iter().map(|(text, name)| Source { text, name }).collect();
    Ok(py.detach(|| plant::compare(&sources, &request, report.as_deref().map(|d| (d, system))))?)
}

/// `plantwide identify FILE --json`: the identification's JSON text and, when the verdict finds
/// the model not usable, the CLI's exit-2 message; `report` a folder for the CLI's report, `force`
/// writes its step model even then.
#[pyfunction]
#[pyo3(signature = (text, name, sets, request, report = None, force = false))]
fn identify(
    py: Python<'_>,
    text: String,
    name: String,
    sets: Vec<String>,
    request: String,
    report: Option<String>,
    force: bool,
) -> PyResult<plant::Answer> {
    let src = Source { text, name };
    Ok(py.detach(|| plant::identify(&src, &sets, &request, report.as_deref().map(|d| (d, force))))?)
}

/// `plantwide select --matrices FILE --json`: the JSON text of the best measurement subsets of
/// `size` from published linear data (`criterion` `worst` or `average`).
#[pyfunction]
#[pyo3(signature = (matrices, size, best = 5, criterion = "worst", max_nodes = plantwide_soc::DEFAULT_MAX_NODES))]
fn select(
    py: Python<'_>,
    matrices: String,
    size: usize,
    best: usize,
    criterion: &str,
    max_nodes: u64,
) -> PyResult<String> {
    let criterion = match criterion {
        "worst" => plantwide_soc::Criterion::Worst,
        "average" => plantwide_soc::Criterion::Average,
        _ => return Err(InputError::new_err(format!("criterion `{criterion}`: expected `worst` or `average`"))),
    };
    let search = plantwide_soc::Search { size, best, criterion, max_nodes };
    let answer = py.detach(|| -> Result<String, FaceError> {
        let soc = |e: plantwide_soc::SocError| {
            let user = e.is_user_error();
            FaceError::classify(e, user)
        };
        let model = plantwide_soc::matrices::read(std::path::Path::new(&matrices)).map_err(soc)?;
        let ranking = plantwide_soc::branch_and_bound(&model, &search).map_err(soc)?;
        plantwide_io::report::select::json(&model, size, criterion, &ranking).map_err(FaceError::input)
    });
    Ok(answer?)
}

/// `plantwide optimize FILE --json`: the optimum's JSON text; `request` the `"optimization"`
/// section as JSON.
#[pyfunction]
fn optimize(py: Python<'_>, text: String, name: String, sets: Vec<String>, request: String) -> PyResult<String> {
    let src = Source { text, name };
    Ok(py.detach(|| plant::optimize(&src, &sets, &request))?)
}

/// `plantwide select FILE --json`: the selection's JSON text at the optimum of `problem` (the
/// `"optimization"` section as JSON) and the message of the verification points without an
/// answer.
#[pyfunction]
#[pyo3(signature = (text, name, sets, problem, disturbances, candidates, errors, size, best = 5, criterion = "worst", max_nodes = plantwide_soc::DEFAULT_MAX_NODES))]
#[allow(clippy::too_many_arguments)] // one per keyword of the Python method
fn select_plant(
    py: Python<'_>,
    text: String,
    name: String,
    sets: Vec<String>,
    problem: String,
    disturbances: Vec<String>,
    candidates: Vec<String>,
    errors: Vec<String>,
    size: usize,
    best: usize,
    criterion: &str,
    max_nodes: u64,
) -> PyResult<plant::Answer> {
    let criterion = match criterion {
        "worst" => plantwide_soc::Criterion::Worst,
        "average" => plantwide_soc::Criterion::Average,
        _ => return Err(InputError::new_err(format!("criterion `{criterion}`: expected `worst` or `average`"))),
    };
    let search = plantwide_soc::Search { size, best, criterion, max_nodes };
    let request = plantwide_studies::optimize::local::LocalRequest { disturbances, candidates, errors };
    let src = Source { text, name };
    Ok(py.detach(|| plant::select(&src, &sets, &problem, request, &search))?)
}

/// The module `plantwide._plantwide`.
#[pymodule]
fn _plantwide(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    // The environment is read here, once: a variable that holds no limit is refused at import.
    let limits = plantwide_flowsheet::scenario::Limits::from_env().map_err(|e| InputError::new_err(e.to_string()))?;
    plantwide_flowsheet::scenario::Limits::install(limits);
    m.add("PlantwideError", py.get_type::<PlantwideError>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("ConvergenceError", py.get_type::<ConvergenceError>())?;
    m.add_function(wrap_pyfunction!(read_text, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(steady, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(gains, m)?)?;
    m.add_function(wrap_pyfunction!(linearize, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(sensitivity, m)?)?;
    m.add_function(wrap_pyfunction!(screen, m)?)?;
    m.add_function(wrap_pyfunction!(size, m)?)?;
    m.add_function(wrap_pyfunction!(tune, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(optimize, m)?)?;
    m.add_function(wrap_pyfunction!(select_plant, m)?)?;
    m.add_function(wrap_pyfunction!(identify, m)?)?;
    m.add_function(wrap_pyfunction!(select, m)?)?;
    Ok(())
}
