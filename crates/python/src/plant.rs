//! Plants loaded the way the CLI loads them, and the library calls behind each Python method.
//! Every function here runs without the GIL (the callers in `lib.rs` detach) and touches no file:
//! flowsheet and scenario text arrive read, so that a task sent to another process carries
//! everything it needs.

use plantwide_analysis::plant_model::{GainMethod, PlantGains, PlantModel, plant_gains};
use plantwide_analysis::report::ReportOptions;
use plantwide_analysis::select::{Signal, parse_pairing, select_output, select_outputs};
use plantwide_analysis::sensitivity::{Curve, Disturbance, SweepSettings, sweep};
use plantwide_analysis::shard::{Shard, Share};
use plantwide_flowsheet::scenario::{Limits, parse_scenario, resolve_with};
use plantwide_flowsheet::{Override, Plant};
use plantwide_solve::dynamic::{SimulationResult, Start, simulate};
use plantwide_solve::{Method, Solution, StrategySettings, converge, fix_design_point};
use plantwide_studies::compare::CompareRequest;
use plantwide_studies::identify::IdentifyRequest;
use plantwide_studies::screen::pairings::CandidateTask;
use plantwide_studies::screen::{ScreenRequest, Screened};
use plantwide_studies::size::SizeRequest;
use plantwide_studies::tune::request::TuneRequest;
use plantwide_units::UnitSystem;

use crate::error::FaceError;

/// A flowsheet's text and the name messages call it by (the path as given, as the CLI's).
#[derive(Debug, Clone)]
pub struct Source {
    /// The flowsheet (JSON).
    pub text: String,
    /// Its name in messages.
    pub name: String,
}

impl Source {
    /// The plant with `sets` (`PATH=VALUE`, as `--set`) applied; design specs still to be met.
    pub fn load(&self, sets: &[String]) -> Result<Plant, FaceError> {
        let overrides = sets.iter().map(|s| s.parse::<Override>()).collect::<Result<Vec<_>, _>>()?;
        Ok(plantwide_flowsheet::load_str_with(&self.text, &self.name, &overrides)?)
    }

    /// The plant at its design point (specs met, their inputs fixed) and its steady state there:
    /// where `gains`, `linearize`, `run` and `sensitivity` start.
    pub fn at_steady_state(&self, sets: &[String]) -> Result<(Plant, Solution), FaceError> {
        let mut plant = self.load(sets)?;
        fix_design_point(&mut plant)?;
        let sol = converge(&plant, &StrategySettings::default())?;
        Ok((plant, sol))
    }
}

/// `--method`: `auto`, `eo` or `sm`.
pub fn method(name: &str) -> Result<Method, FaceError> {
    match name {
        "auto" => Ok(Method::Auto),
        "eo" => Ok(Method::Eo),
        "sm" => Ok(Method::Sm),
        _ => Err(FaceError::Input(format!("method `{name}`: expected `auto`, `eo` or `sm`"))),
    }
}

/// `units=`: `si`, `metric` or `field`, the CLI's `--units`.
pub fn units(name: &str) -> Result<UnitSystem, FaceError> {
    match name {
        "si" => Ok(UnitSystem::Si),
        "metric" => Ok(UnitSystem::Metric),
        "field" => Ok(UnitSystem::Field),
        _ => Err(FaceError::Input(format!("units `{name}`: expected `si`, `metric` or `field`"))),
    }
}

/// A steady state as the Python face returns it: `(path, SI value)` of every variable and free
/// input, and the warnings' messages.
pub type Steady = (Vec<(String, f64)>, Vec<String>);

/// `plantwide steady --set …`: every variable and free input (SI), and the warnings.
pub fn steady(src: &Source, sets: &[String], method: Method) -> Result<Steady, FaceError> {
    let plant = src.load(sets)?;
    let sol = converge(&plant, &StrategySettings { method, ..StrategySettings::default() })?;
    Ok((sol.values(&plant), sol.warnings.iter().map(|w| w.message.clone()).collect()))
}

/// The steady values of `outputs` (variables or free inputs) with `sets` applied.
pub fn steady_outputs(
    src: &Source,
    sets: &[String],
    outputs: &[String],
    method: Method,
) -> Result<Vec<f64>, FaceError> {
    let (values, _) = steady(src, sets, method)?;
    outputs
        .iter()
        .map(|o| match values.iter().rev().find(|(p, _)| p == o) {
            Some((_, v)) => Ok(*v),
            // Not a path of the steady state: the library says why, with the nearest names.
            None => match src.load(sets).map(|p| select_output(&p, o).map(|_| ())) {
                Ok(Err(e)) => Err(FaceError::input(e)),
                Ok(Ok(())) | Err(_) => Err(FaceError::Input(format!("`{o}`: not a variable or free input"))),
            },
        })
        .collect()
}

/// The chosen inputs and outputs (`PATH[@unit]`) of `plant`.
fn signals(plant: &Plant, inputs: &[String], outputs: &[String]) -> Result<(Vec<Signal>, Vec<Signal>), FaceError> {
    let i = plantwide_analysis::select::select_inputs(plant, inputs)?;
    let o = select_outputs(plant, outputs)?;
    Ok((i, o))
}

/// `plantwide gains`: the gain report by `method` (`pairing` as `--pairing`).
pub fn gains(
    src: &Source,
    sets: &[String],
    (inputs, outputs): (&[String], &[String]),
    method: GainMethod,
    pairing: Option<&str>,
) -> Result<PlantGains, FaceError> {
    let (plant, ss) = src.at_steady_state(sets)?;
    let (ins, outs) = signals(&plant, inputs, outputs)?;
    let pairing = pairing.map(|p| parse_pairing(p, outputs, inputs)).transpose()?;
    let options = ReportOptions { pairing, ..ReportOptions::default() };
    Ok(plant_gains(&plant, (&ss.x, &ss.u), (&ins, &outs), method, &options)?)
}

/// `plantwide linearize`: the model and its signals, with the plant's name.
pub fn linearize(
    src: &Source,
    sets: &[String],
    (inputs, outputs): (&[String], &[String]),
) -> Result<(String, PlantModel, Vec<Signal>, Vec<Signal>), FaceError> {
    let (plant, ss) = src.at_steady_state(sets)?;
    let (ins, outs) = signals(&plant, inputs, outputs)?;
    let model = PlantModel::at(&plant, (&ss.x, &ss.u), (&ins, &outs), &[])?;
    Ok((plant.name().to_string(), model, ins, outs))
}

/// `plantwide run`: the scenario (text, named `scenario_name`) from the steady state.
pub fn run(src: &Source, sets: &[String], scenario: &Source) -> Result<SimulationResult, FaceError> {
    let (plant, ss) = src.at_steady_state(sets)?;
    let spec = parse_scenario(&scenario.text, &scenario.name).map_err(FaceError::input)?;
    let sc = resolve_with(&spec, &plant, &scenario.name, Limits::get()).map_err(FaceError::input)?;
    simulate(&plant, &sc, Start::Steady(&ss.x), "", &mut |_| {}).map_err(|e| {
        let user = e.is_user_error();
        FaceError::classify(e, user)
    })
}

/// `plantwide sensitivity`: each `disturb` (`PATH=LOW:HIGH`) swept over `points` values.
pub fn sensitivity(
    src: &Source,
    sets: &[String],
    disturb: &[String],
    outputs: &[String],
    points: usize,
) -> Result<(Vec<Curve>, Vec<Signal>), FaceError> {
    let (plant, ss) = src.at_steady_state(sets)?;
    let u = plant.input_values();
    let disturbances = disturb.iter().map(|d| Disturbance::parse(&plant, &u, d)).collect::<Result<Vec<_>, _>>()?;
    let outs = select_outputs(&plant, outputs)?;
    let idx: Vec<usize> = outs.iter().map(|s| s.index).collect();
    let settings = SweepSettings { points, ..SweepSettings::default() };
    Ok((sweep(&plant, &ss.x, &ss.u, &disturbances, &idx, &settings)?, outs))
}

/// What a study returns to Python: its JSON as the CLI prints it (`--json`), and the message of
/// its parts without an answer, the CLI's exit 2 (none when every part has its answer).
pub type Answer = (String, Option<String>);

/// A study's request from its JSON text (the Python keywords), refused naming the study.
fn study_request<T: serde::de::DeserializeOwned>(study: &str, text: &str) -> Result<T, FaceError> {
    serde_json::from_str(text).map_err(|e| FaceError::Input(format!("{study}: the request: {e}")))
}

/// How much of a pairing screen's dynamic tests this call runs.
pub enum PairingShare {
    /// All of them.
    All,
    /// Shard `I` of `N`.
    Shard(Shard),
    /// None: every task's result, as the shards returned them (JSON by task number).
    Merge(String),
}

/// `plantwide screen … --json [--report DIR]`: `request` is a [`ScreenRequest`] as JSON (the
/// fields of `Plant.screen`), a column's configurations or the pairings, `share` of a pairing
/// screen's dynamic tests run here. Returns the screen as the CLI prints it (for a shard,
/// `{"tasks": N, "results": {t: …}}`) and the message of its failed parts. No digit depends on
/// the thread count or on the shard a candidate ran in.
pub fn screen(
    src: &Source,
    sets: &[String],
    request: &str,
    share: PairingShare,
    report: Option<(&str, UnitSystem)>,
) -> Result<Answer, FaceError> {
    let request: ScreenRequest = study_request("screen", request)?;
    let share = match share {
        PairingShare::All => Share::All,
        PairingShare::Shard(s) => Share::Shard(s),
        PairingShare::Merge(text) => {
            let given: std::collections::BTreeMap<usize, CandidateTask> = serde_json::from_str(&text)
                .map_err(|e| FaceError::Input(format!("screen: the shards' results: {e}")))?;
            Share::Merge(given.into_iter().map(|(t, c)| (t, c.into())).collect())
        }
    };
    let (sharded, merging) = (share.is_shard(), matches!(share, Share::Merge(_)));
    let mut plant = src.load(sets)?;
    fix_design_point(&mut plant)?;
    let screened = plantwide_studies::screen::study(&plant, &request, share)?;
    let io = |e: plantwide_io::IoError| FaceError::Input(e.to_string());
    if let Screened::Pairings(p) = &screened {
        if sharded {
            let results: std::collections::BTreeMap<usize, CandidateTask> = p
                .tested
                .iter()
                .enumerate()
                .filter_map(|(t, &k)| p.structures[k].dynamic.as_ref().map(|d| (t, CandidateTask::from(d))))
                .collect();
            return Ok((to_json(&serde_json::json!({"tasks": p.tested.len(), "results": results}))?, None));
        }
        if let Some(t) = (0..p.tested.len()).find(|&t| merging && p.structures[p.tested[t]].dynamic.is_none()) {
            return Err(FaceError::Input(format!("screen: the shards' results miss task {t} of {}", p.tested.len())));
        }
    }
    if let Some((dir, system)) = report {
        use plantwide_io::report::screen::{shown, write_column_report, write_pairing_report};
        let dir = std::path::Path::new(dir);
        match &screened {
            Screened::Column(c) => write_column_report(dir, &src.name, c).map(|_| ()),
            Screened::Pairings(p) => {
                shown(&plant, &request, system).and_then(|s| write_pairing_report(dir, p, &s).map(|_| ()))
            }
        }
        .map_err(io)?;
    }
    let failed = plantwide_studies::request::failed_parts("screen", screened.failed());
    Ok((plantwide_io::report::json(&screened).map_err(io)?, failed))
}

/// `plantwide size --json [--report DIR]`: `request` is a [`SizeRequest`] as JSON (the fields of
/// `Plant.size`); the report, when asked, is written in `report.1`'s display units, as the CLI's.
pub fn size(
    src: &Source,
    sets: &[String],
    request: &str,
    report: Option<(&str, UnitSystem)>,
) -> Result<Answer, FaceError> {
    let request: SizeRequest = study_request("size", request)?;
    let (plant, ss) = src.at_steady_state(sets)?;
    let sizing =
        plantwide_studies::size::size(&plant, &ss.x, &request, &|_| {}).map_err(plantwide_studies::Error::from)?;
    let io = |e: plantwide_io::IoError| {
        let missing = e.is_missing_result();
        FaceError::classify(e, !missing)
    };
    if let Some((dir, system)) = report {
        plantwide_io::report::size::write_report(std::path::Path::new(dir), &sizing, &plant, system).map_err(io)?;
    }
    let failed = plantwide_studies::request::failed_parts("size", sizing.failed());
    Ok((plantwide_io::report::json(&sizing).map_err(io)?, failed))
}

/// `plantwide tune FILE --json [--report DIR] [--write OUT]`: `request` is a
/// [`TuneRequest`] as JSON (the fields of `Plant.tune`). Returns the tuning as the CLI prints
/// it and the message of the loops its margins refute (none when all hold); `write` gets the
/// tuned flowsheet only when none is refuted.
pub fn tune(
    src: &Source,
    sets: &[String],
    request: &str,
    report: Option<&str>,
    write: Option<&str>,
) -> Result<Answer, FaceError> {
    let request: TuneRequest = study_request("tune", request)?;
    let (name, seconds) = request.time_unit()?;
    let tu = plantwide_io::report::tune::TimeUnit { name, seconds };
    let (plant, ss) = src.at_steady_state(sets)?;
    let tuned = plantwide_studies::tune::request::tune(&plant, &ss.x, &request)?;
    let io = |e: plantwide_io::IoError| FaceError::Input(e.to_string());
    if let Some(dir) = report {
        plantwide_io::report::tune::write_report(std::path::Path::new(dir), &tuned, &plant, &tu).map_err(io)?;
    }
    let failed = tuned.failed();
    if let Some(out) = write.filter(|_| failed.is_empty()) {
        let text = plantwide_studies::tune::request::tuned_text(&src.text, &src.name, &plant, &tuned.tuning, &tu.name)?;
        std::fs::write(out, text).map_err(|e| FaceError::Input(format!("{out}: cannot write: {e}")))?;
    }
    let failed = (!failed.is_empty())
        .then(|| format!("{}{}", failed.join("\n"), if write.is_some() { "\nnothing written" } else { "" }));
    Ok((plantwide_io::report::tune::json(&tuned, &tu).map_err(io)?, failed))
}

/// `plantwide compare A.json B.json … --json [--report DIR]`: `request` is a
/// [`CompareRequest`] as JSON (the fields of `plantwide.compare`), each scheme loaded as the CLI
/// loads it (at its design point). Returns the comparison as the CLI prints it and the message of
/// its failed parts (none when every part has its answer); the report, when asked, is written in
/// `report.1`'s display units.
pub fn compare(schemes: &[Source], request: &str, report: Option<(&str, UnitSystem)>) -> Result<Answer, FaceError> {
    let request: CompareRequest = study_request("compare", request)?;
    let plants = schemes
        .iter()
        .map(|s| {
            let mut p = s.load(&[])?;
            fix_design_point(&mut p)?;
            Ok(p)
        })
        .collect::<Result<Vec<_>, FaceError>>()?;
    let c = plantwide_studies::compare::study(&plants, &request).map_err(plantwide_studies::Error::from)?;
    let io = |e: plantwide_io::IoError| FaceError::Input(e.to_string());
    if let Some((dir, system)) = report {
        let shown = plantwide_io::report::compare::shown(&plants, &request.outputs, &c, system).map_err(io)?;
        plantwide_io::report::compare::write_report(std::path::Path::new(dir), &c, &shown).map_err(io)?;
    }
    let failed = plantwide_studies::request::failed_parts("compare", &c.failed);
    Ok((plantwide_io::report::json(&c).map_err(io)?, failed))
}

/// `plantwide identify FILE --json [--report DIR [--force]]`: `request` is an
/// [`IdentifyRequest`] as JSON (the fields of `Plant.identify`). Returns the identification as the
/// CLI prints it and, when the verdict finds the model not usable, the CLI's exit-2 message.
pub fn identify(
    src: &Source,
    sets: &[String],
    request: &str,
    report: Option<(&str, bool)>,
) -> Result<Answer, FaceError> {
    use plantwide_io::report::identify::{StepModel, not_usable, write_report};
    let request: IdentifyRequest = study_request("identify", request)?;
    let (plant, ss) = src.at_steady_state(sets)?;
    let identified =
        plantwide_studies::identify::study(&plant, &ss.x, &ss.u, &request).map_err(plantwide_studies::Error::from)?;
    let id = &identified.identification;
    let step_model = match (report, id.verdict.reliable) {
        (None, _) => StepModel::NoReport,
        (Some(_), true) => StepModel::Written,
        (Some((_, true)), false) => StepModel::Forced,
        (Some((_, false)), false) => StepModel::Withheld,
    };
    let dir = report.map(|(d, _)| std::path::Path::new(d));
    let failed = not_usable(id, step_model, dir);
    let io = |e: plantwide_io::IoError| FaceError::Input(e.to_string());
    if let Some(dir) = dir {
        write_report(dir, &src.name, &identified, step_model).map_err(io)?;
    }
    Ok((plantwide_io::report::json(id).map_err(io)?, failed))
}

/// `v` as JSON text.
fn to_json(v: &impl serde::Serialize) -> Result<String, FaceError> {
    serde_json::to_string(v).map_err(|e| FaceError::Input(e.to_string()))
}

/// `plantwide optimize FILE --json`: `request` is the `"optimization"` section as JSON (the file's
/// with `Plant.optimize`'s keywords applied, merged by the caller).
pub fn optimize(src: &Source, sets: &[String], request: &str) -> Result<String, FaceError> {
    let spec: plantwide_flowsheet::optimization::OptimizationSpec = study_request("optimize", request)?;
    let (plant, ss) = src.at_steady_state(sets)?;
    let start = plantwide_studies::optimize::State { x: ss.x, u: ss.u };
    let optimum = plantwide_studies::optimize::optimize(&plant, &spec, &start)?;
    plantwide_io::report::json(&optimum).map_err(FaceError::input)
}

/// `plantwide select FILE --json`: the selection on the plant at the optimum of `problem` (an
/// `"optimization"` section as JSON), and the message of the verification points without an
/// answer.
pub fn select(
    src: &Source,
    sets: &[String],
    problem: &str,
    request: plantwide_studies::optimize::local::LocalRequest,
    search: &plantwide_soc::Search,
) -> Result<Answer, FaceError> {
    let spec: plantwide_flowsheet::optimization::OptimizationSpec = study_request("select", problem)?;
    let (plant, ss) = src.at_steady_state(sets)?;
    let start = plantwide_studies::optimize::State { x: ss.x, u: ss.u };
    let sel = plantwide_studies::optimize::select::select_on_plant(&plant, &spec, &start, &request, search)?;
    let failed = sel.failed();
    let text =
        plantwide_io::report::select::plant_json(&sel, search.size, search.criterion).map_err(FaceError::input)?;
    Ok((text, plantwide_studies::request::failed_parts("select", &failed)))
}
