//! The dynamic check of a column's configurations: each configuration that converged and is not
//! singular is taken as the open plant of the pairing screen's dynamic test
//! ([`crate::screen::pairings::dynamic`]) with one candidate, its recommended pairing: PI loops
//! `pair1` (top quality) and `pair2` (bottom quality) added, tuned together by Luyben's BLT on the
//! exact linearization with the measurement dead time given, each loop's output bounded to
//! `[0, 2 u₀]`; then every disturbance stepped on the nonlinear plant from its steady state.
//!
//! Every run has the same length so that IAEs compare: given, or 20 times the longest reset time
//! of all the configurations' tuned loops (each configuration then has time to settle). The
//! disturbances default to the rate ±10 % of every feed upstream of the column (walked back
//! through heaters, tanks, reactors and recycles to the units whose rate `F` is a free input) and
//! its mole fraction of the top quality's component ± a tenth of its distance to 0 or 1
//! (0.45 ± 0.045), one run each way.
//! Configurations are tuned, then run, in parallel (rayon); each is a pure function of its plant
//! and the request, so nothing depends on the thread count.

use plantwide_analysis::shard::Share;
use plantwide_flowsheet::scenario::ScenarioSpec;
use plantwide_flowsheet::{Plant, VarPath};
use rayon::prelude::*;

use super::{ColumnStructure, Scaling, Variant, input_value};
use crate::disturbance::{Direction, Disturbance, StepSize};
use crate::screen::ScreenError;
use crate::screen::pairings::dynamic::{TunedCandidate, candidate, pair_outputs, scenario, tuned_plant};
use crate::screen::pairings::{DynamicSettings, OpenPlant, Pair, PairingRequest, PairingStructure};
use crate::tune::loops::Measurement;

/// Settings of the dynamic check.
#[derive(Debug, Clone, PartialEq)]
pub struct ColumnDynamic {
    /// The disturbances (empty: the column's feed rate ±10 % and feed composition ± a tenth of its
    /// room, see the module's documentation).
    pub disturbances: Vec<Disturbance>,
    /// Length of each run \[s\] (default: 20 × the longest reset time of the tuned loops).
    pub duration: Option<f64>,
    /// Measurement delay and lag of every loop, for the tuning.
    pub measurement: Measurement,
    /// Keep each configuration's tuned flowsheet and the runs' scenarios (to write them).
    pub keep_flowsheets: bool,
}

impl Default for ColumnDynamic {
    fn default() -> Self {
        ColumnDynamic {
            disturbances: Vec::new(),
            duration: None,
            measurement: Measurement { dead_time: 60.0, lag: 0.0 },
            keep_flowsheets: false,
        }
    }
}

/// What the check ran: its steps, the length of every run and, when kept, the scenarios.
#[derive(Debug, Default)]
pub(super) struct Check {
    pub steps: Vec<String>,
    pub duration: Option<f64>,
    pub scenarios: Vec<(String, ScenarioSpec)>,
}

/// The disturbances of the check, each judged against `plant`: those given, or the defaults of
/// the column's feed.
///
/// # Errors
/// [`ScreenError::BadDisturbance`] for a step the plant refuses; [`ScreenError::NoFeed`] when
/// there are no defaults.
pub(super) fn disturbances(
    plant: &Plant,
    column: &str,
    outputs: &[String],
    d: &ColumnDynamic,
) -> Result<Vec<Disturbance>, ScreenError> {
    let list = match d.disturbances.is_empty() {
        true => defaults(plant, column, outputs)?,
        false => d.disturbances.clone(),
    };
    for x in &list {
        x.check(plant)?;
    }
    Ok(list)
}

/// The feed rate ±10 % and a feed mole fraction ± a tenth of its distance to 0 or 1 (that of the
/// top quality's component, or else of the component with the most room), of every feed upstream
/// of the column whose rate is free; and ±10 % of every free outflow upstream (a reactor's or a
/// tank's `outflow` that no controller drives: the throughput manipulator of a plant whose fresh
/// feed a level loop sets, Luyben's snowball structure 2).
fn defaults(plant: &Plant, column: &str, outputs: &[String]) -> Result<Vec<Disturbance>, ScreenError> {
    let free = |p: &str| plant.input(p).filter(|&i| plant.inputs()[i].driven_by.is_none());
    let top = VarPath::parse(&outputs[0]);
    let component = top.field().and_then(|f| Some(f.split_once('[')?.1.trim_end_matches(']')));
    let (feeds, sources, outflows) = upstream_feeds(plant, column);
    let mut list: Vec<Disturbance> = outflows
        .iter()
        .map(|u| Disturbance {
            path: VarPath::new(u, "outflow").into(),
            size: StepSize::Fraction(0.1),
            direction: Direction::Both,
            shown: "10 %".into(),
        })
        .collect();
    for unit in &feeds {
        list.push(Disturbance {
            path: VarPath::new(unit, "F").into(),
            size: StepSize::Fraction(0.1),
            direction: Direction::Both,
            shown: "10 %".into(),
        });
        let room = |p: &String| free(p).map_or(0.0, |i| plant.inputs()[i].value.min(1.0 - plant.inputs()[i].value));
        let z = VarPath::new(unit, "z");
        let own = component.map(|c| String::from(z.clone().index(c))).filter(|p| room(p) > 0.0);
        let widest = || {
            let paths = plant.inputs().iter().map(|i| i.path.clone()).filter(|p| z.has_element(p));
            paths.filter(|p| room(p) > 0.0).max_by(|a, b| room(a).total_cmp(&room(b)))
        };
        if let Some(z) = own.or_else(widest) {
            let step = 0.1 * room(&z);
            let shown = plantwide_model::limits::number(step);
            list.push(Disturbance {
                path: z,
                size: StepSize::Amount { si: step, dim: None },
                direction: Direction::Both,
                shown,
            });
        }
    }
    if list.is_empty() {
        let why = match sources.is_empty() {
            true => "no stream enters it".to_string(),
            false => format!("it is fed by {}", sources.join(", ")),
        };
        return Err(ScreenError::NoFeed { column: column.into(), why });
    }
    Ok(list)
}

/// The units with a free feed rate (`unit.F`, an input no controller drives) upstream of `column`,
/// found by walking its inlet streams back through every unit (heaters, tanks, splits, reactors,
/// other columns; a recycle is walked once), in the flowsheet's stream order; the units
/// feeding the column directly; and the units upstream whose `outflow` is a free input.
fn upstream_feeds<'a>(plant: &'a Plant, column: &'a str) -> (Vec<&'a str>, Vec<&'a str>, Vec<&'a str>) {
    let free = |path: VarPath| plant.input(path).is_some_and(|i| plant.inputs()[i].driven_by.is_none());
    let is_feed = |u: &str| free(VarPath::new(u, "F"));
    let sources_of = |unit: &str| -> Vec<&'a str> {
        // A stream's ends are `unit.port`, or `unit` alone for a unit of one inlet or outlet.
        let owner = |end: &'a str| end.split('.').next().unwrap_or(end);
        let streams = plant.spec().streams.values().filter(|s| owner(&s.to) == unit);
        streams.map(|s| owner(&s.from)).collect()
    };
    let direct = sources_of(column);
    let (mut seen, mut feeds, mut outflows, mut queue) = (vec![column], Vec::new(), Vec::new(), direct.clone());
    while !queue.is_empty() {
        let unit = queue.remove(0);
        if seen.contains(&unit) {
            continue;
        }
        seen.push(unit);
        if free(VarPath::new(unit, "outflow")) {
            outflows.push(unit);
        }
        match is_feed(unit) {
            true => feeds.push(unit),
            false => queue.extend(sources_of(unit)),
        }
    }
    (feeds, direct, outflows)
}

/// A configuration ready for the pairing screen's dynamic test.
struct Prepared {
    /// Its index among the structures.
    k: usize,
    open: OpenPlant,
    request: PairingRequest,
    structure: PairingStructure,
}

/// Configuration `s` (converged as `v`) as an open plant with one candidate, its recommended
/// pairing; `None` when it has none.
fn prepare(
    k: usize,
    s: &ColumnStructure,
    v: &Variant,
    outputs: &[String],
    steps: &[Disturbance],
    d: &ColumnDynamic,
) -> Option<Prepared> {
    let (pairing, lambda) = (s.pairing.as_ref()?, s.relative_gain?);
    let mv_values = s.inputs.iter().map(|p| input_value(&v.plant, &v.x, p)).collect();
    let cv_values = outputs.iter().filter_map(|o| v.plant.var(o)).map(|i| v.x[i]).collect();
    let open = OpenPlant {
        plant: v.plant.clone(),
        x: v.x.clone(),
        mv_values,
        cv_values,
        gain: v.gain.clone(),
        opened: Vec::new(),
    };
    let request = PairingRequest {
        cvs: outputs.to_vec(),
        mvs: s.inputs.clone(),
        throughput: Vec::new(),
        disturbances: steps.to_vec(),
        watch: Vec::new(),
        dynamic: DynamicSettings { candidates: 1, duration: d.duration, measurement: d.measurement },
        record: Vec::new(),
        mpc: None,
        share: Share::All,
    };
    let pairs =
        outputs.iter().zip(pairing).map(|(cv, mv)| Pair { cv: cv.clone(), mv: mv.clone(), relative_gain: lambda });
    // A 2 × 2's paired Niederlinski index is 1/λ and its RGA number 2|1 − λ| + 2|λ − 1|.
    let structure = PairingStructure {
        throughput: None,
        pairs: pairs.collect(),
        niederlinski: 1.0 / lambda,
        rga_number: 4.0 * (1.0 - lambda).abs(),
        dic: lambda > 0.0,
        passed: true,
        rejected: None,
        sensitivity: Vec::new(),
        dynamic: None,
        rank: None,
    };
    Some(Prepared { k, open, request, structure })
}

/// Tune and run every regular configuration of `structures` (converged as `variants`) on `steps`,
/// score each by its scaled IAE and keep, when asked, its tuned flowsheet and the scenarios.
///
/// # Errors
/// [`ScreenError::Write`] when a tuned flowsheet cannot be written back to a description.
pub(super) fn check(
    plant: &Plant,
    outputs: &[String],
    steps: &[Disturbance],
    d: &ColumnDynamic,
    scaling: &Scaling,
    structures: &mut [ColumnStructure],
    variants: &[Option<Variant>],
) -> Result<Check, ScreenError> {
    let prepared: Vec<Prepared> = variants
        .iter()
        .enumerate()
        .filter(|(k, _)| structures[*k].failure.is_none())
        .filter_map(|(k, v)| prepare(k, &structures[k], v.as_ref()?, outputs, steps, d))
        .collect();
    let tuned: Vec<TunedCandidate> =
        prepared.par_iter().map(|p| tuned_plant(&p.open, &p.request, &p.structure)).collect();
    let longest = tuned.iter().filter_map(|t| t.as_ref().ok()).map(|t| t.2.tau_i_max).fold(0.0, f64::max);
    // One length for every run, so that IAEs compare (an hour if no loop has a finite reset time).
    let duration = d.duration.unwrap_or(if longest > 0.0 { 20.0 * longest } else { 3600.0 });
    let done: Vec<_> = prepared
        .par_iter()
        .zip(&tuned)
        .map(|(p, t)| {
            let result = candidate(t, &p.request, &pair_outputs(&p.open, &p.structure), duration);
            let file = match (d.keep_flowsheets, t) {
                (true, Ok((tuned, ..))) => Some(super::write::flowsheet(tuned, &structures[p.k], &result, d)),
                _ => None,
            };
            (p.k, result, file)
        })
        .collect();
    for (k, result, file) in done {
        structures[k].flowsheet = file.transpose()?;
        structures[k].dynamic = Some(result);
    }
    score(structures, &scaling.allowed_deviation);
    let step_list: Vec<Disturbance> = steps.iter().flat_map(Disturbance::steps).collect();
    let scenarios = match d.keep_flowsheets {
        true => scenarios(plant, outputs, &step_list, duration),
        false => Vec::new(),
    };
    Ok(Check { steps: step_list.iter().map(Disturbance::label).collect(), duration: Some(duration), scenarios })
}

/// The scenario of each step, as the check ran it: file name and text.
fn scenarios(plant: &Plant, outputs: &[String], steps: &[Disturbance], duration: f64) -> Vec<(String, ScenarioSpec)> {
    let ops = ["pair1.op".to_string(), "pair2.op".to_string()];
    let record: Vec<&String> = outputs.iter().chain(&ops).collect();
    steps
        .iter()
        .enumerate()
        .map(|(n, s)| {
            let u0 = plantwide_flowsheet::overrides::resolve_input(plant, &s.path)
                .map_or(f64::NAN, |i| plant.inputs()[i].value);
            let mut spec = scenario(s, s.change(u0), duration, &record);
            spec.name = s.label();
            (format!("step{}.scenario.json", n + 1), spec)
        })
        .collect()
}

/// Each checked configuration's scaled IAE (`Σ_runs Σ_qualities IAE/Δy`) and its score (that over
/// the best one's); a configuration whose check failed is marked failed with the reasons, one that
/// lost the plant in a run is marked lost with where and how.
fn score(structures: &mut [ColumnStructure], allowed: &[f64]) {
    for s in structures.iter_mut() {
        let Some(d) = s.dynamic.as_ref() else { continue };
        if !d.completed() {
            s.failure = Some(d.failures("dynamic check").join("; "));
            continue;
        }
        if !d.rides_through() {
            s.lost = Some(d.losses("dynamic check").join("; "));
            continue;
        }
        let iae = d.runs.iter().map(|r| r.cvs.iter().zip(allowed).map(|(c, dy)| c.iae / dy).sum::<f64>()).sum();
        s.iae_scaled = Some(iae);
    }
    let best = structures.iter().filter_map(|s| s.iae_scaled).fold(f64::INFINITY, f64::min);
    for s in structures.iter_mut() {
        if let Some(d) = s.dynamic.as_mut() {
            d.score = s.iae_scaled.map_or(f64::INFINITY, |v| v / best.max(f64::MIN_POSITIVE));
        }
    }
}
