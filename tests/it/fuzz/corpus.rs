//! The shipped flowsheets and scenarios the mutants start from, and the mutant a seed makes.

use std::path::{Path, PathBuf};

use serde_json::Value;

use super::doc::Doc;
use super::kinds;
use super::mutate::{Names, mutate};
use super::rng::Rng;
use super::targeted;
use plantwide::flowsheet::scenario::{parse_scenario, resolve};
use plantwide::flowsheet::{Plant, load_str};

/// Plants up to this many variables get steady and run mutants (the rest load only).
const STEADY_MAX_VARS: usize = 450;
/// Run mutants simulate this fraction of the shipped scenario's duration.
pub const RUN_FRACTION: f64 = 0.1;

/// One shipped flowsheet.
pub struct Flowsheet {
    /// Path relative to the repository.
    pub file: String,
    /// Parsed JSON.
    pub value: Value,
    /// Its names.
    pub names: Names,
    /// The plant as shipped.
    pub plant: Plant,
}

/// One shipped scenario and the flowsheets it runs on.
pub struct Scenario {
    /// Path relative to the repository.
    pub file: String,
    /// Parsed JSON, the duration cut to [`RUN_FRACTION`].
    pub value: Value,
    /// Indices of the (small) flowsheets it resolves against.
    pub flowsheets: Vec<usize>,
}

/// Everything the mutants are made from.
pub struct Corpus {
    /// Flowsheets, sorted by file.
    pub flowsheets: Vec<Flowsheet>,
    /// Indices of the flowsheets small enough for steady and run mutants.
    pub small: Vec<usize>,
    /// Scenarios with at least one flowsheet.
    pub scenarios: Vec<Scenario>,
    /// The other inputs' starting points (models, a snapshot).
    pub seeds: kinds::Seeds,
}

fn json_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            json_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "json") {
            out.push(p);
        }
    }
}

impl Corpus {
    /// Read `flowsheets/` (and its subfolders): flowsheets have `units`, scenarios `events`.
    pub fn load() -> Corpus {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut files = Vec::new();
        json_files(&root.join("flowsheets"), &mut files);
        files.sort();
        let (mut flowsheets, mut scen) = (Vec::new(), Vec::new());
        for p in files {
            let file = p.strip_prefix(root).unwrap_or(&p).display().to_string();
            let text = std::fs::read_to_string(&p).expect("shipped file readable");
            let Ok(value) = serde_json::from_str::<Value>(&text) else { continue };
            if value.get("units").is_some() {
                let plant = load_str(&text, &file).unwrap_or_else(|e| panic!("shipped {file} must load: {e}"));
                flowsheets.push(Flowsheet { file, names: Names::of(&value), value, plant });
            } else if value.get("events").is_some() {
                scen.push((file, text, value));
            }
        }
        let small: Vec<usize> =
            (0..flowsheets.len()).filter(|&i| flowsheets[i].plant.n_vars() <= STEADY_MAX_VARS).collect();
        let scenarios = scen
            .into_iter()
            .map(|(file, text, value)| {
                let fits = |i: &usize| {
                    parse_scenario(&text, &file).is_ok_and(|s| resolve(&s, &flowsheets[*i].plant, &file).is_ok())
                };
                let on: Vec<usize> = small.iter().copied().filter(fits).collect();
                Scenario { file, value: shortened(value), flowsheets: on }
            })
            .filter(|s| !s.flowsheets.is_empty())
            .collect();
        Corpus { flowsheets, small, scenarios, seeds: kinds::Seeds::load() }
    }
}

/// `value` with its duration cut to [`RUN_FRACTION`] (same unit).
fn shortened(mut value: Value) -> Value {
    let cut = value.get("duration").and_then(Value::as_str).and_then(|d| {
        let (x, unit) = d.trim().split_once(' ')?;
        Some(format!("{} {unit}", x.parse::<f64>().ok()? * RUN_FRACTION))
    });
    if let Some(d) = cut {
        // Events after the shortened end would be refused (an event after the end of a run is an
        // error); keep those within it.
        let secs = |q: &Value| {
            q.as_str().and_then(|t| plantwide::units::parse_quantity_as(t, plantwide::units::Dimension::TIME).ok())
        };
        let end = secs(&Value::String(d.clone())).unwrap_or(f64::INFINITY);
        if let Some(Value::Array(events)) = value.get_mut("events") {
            events.retain(|e| e.get("at").and_then(secs).is_none_or(|t| t <= end));
        }
        value["duration"] = Value::String(d);
    }
    value
}

/// What a mutant exercises.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Parse, assemble, `--set`, structural DOF check.
    Load,
    /// Also the numerical DOF probe and the steady solver, its answer certified.
    Steady,
    /// Also a (short) scenario through the integrator.
    Run,
    /// A transfer-function model file: parsed, tuned, exported.
    Tf,
    /// An MPC step-model file read by its controller.
    StepModel,
    /// A snapshot resumed.
    Snapshot,
    /// A study command line (`gains`, `tune`, `size`, `screen`, `sensitivity`, `steady --spec`).
    Study,
    /// A request to the live server.
    Serve,
}

impl Mode {
    /// Every mode, in the order of the report.
    pub const ALL: [Mode; 8] =
        [Mode::Load, Mode::Steady, Mode::Run, Mode::Tf, Mode::StepModel, Mode::Snapshot, Mode::Study, Mode::Serve];
}

/// The input of a mutant of a kind beyond flowsheets and scenarios.
#[derive(Debug, Clone)]
pub enum Other {
    /// A transfer-function model: (file it came from, text).
    Tf(String, String),
    /// A step-model file's text.
    StepModel(String),
    /// A snapshot's text.
    Snapshot(String),
    /// A study's command line.
    Study(Vec<String>),
    /// An HTTP request (`{port}` and `{token}` filled in when sent).
    Serve(String),
}

/// One mutant: everything needed to run it, and what was changed.
pub struct Mutant {
    /// Its seed (`PLANTWIDE_FUZZ_SEED=<seed> PLANTWIDE_FUZZ_MUTANTS=1` replays it).
    pub seed: u64,
    /// What it exercises.
    pub mode: Mode,
    /// Flowsheet file it came from.
    pub file: String,
    /// Flowsheet text.
    pub text: String,
    /// Scenario file and text (run mutants).
    pub scenario: Option<(String, String)>,
    /// `--set` assignments.
    pub sets: Vec<String>,
    /// The changes made, one line each (`path: before -> after [class]`).
    pub changes: Vec<String>,
    /// The input of the other kinds.
    pub other: Option<Other>,
}

impl Mutant {
    /// Make the mutant of `seed`: 70 % load, 12 % steady, 4 % run, 4 % transfer-function
    /// models, 2 % step models, 2 % snapshots, 1 % studies, 5 % server requests; 1-3 changes
    /// (3 % none).
    pub fn new(seed: u64, corpus: &Corpus) -> Mutant {
        let mut rng = Rng::new(seed);
        let r = rng.unit();
        let mode = if r < 0.70 {
            Mode::Load
        } else if r < 0.82 || (r < 0.86 && corpus.scenarios.is_empty()) {
            Mode::Steady
        } else if r < 0.86 {
            Mode::Run
        } else {
            let kind = [(0.90, Mode::Tf), (0.92, Mode::StepModel), (0.94, Mode::Snapshot), (0.95, Mode::Study)];
            let mode = kind.iter().find(|&&(p, _)| r < p).map_or(Mode::Serve, |&(_, m)| m);
            return Mutant::other(seed, mode, &mut rng, corpus);
        };
        let (fi, scenario) = match mode {
            Mode::Load => (rng.below(corpus.flowsheets.len()), None),
            Mode::Steady => (*rng.pick(&corpus.small), None),
            _ => {
                let s = rng.pick(&corpus.scenarios);
                (*rng.pick(&s.flowsheets), Some(s))
            }
        };
        let base = &corpus.flowsheets[fi];
        let mut m = Mutant {
            seed,
            mode,
            file: base.file.clone(),
            text: String::new(),
            scenario: None,
            sets: Vec::new(),
            changes: Vec::new(),
            other: None,
        };
        let mut doc = Doc::new(base.value.clone());
        let n = if rng.chance(0.03) { 0 } else { *rng.pick(&[1, 1, 1, 1, 1, 1, 1, 2, 2, 3]) };
        if let Some(s) = scenario {
            let mut sdoc = Doc::new(s.value.clone());
            for _ in 0..n {
                let line = if rng.chance(0.6) {
                    targeted::scenario(&mut rng, &mut sdoc, &base.names)
                } else {
                    mutate(&mut rng, &mut sdoc, &base.names)
                };
                m.changes.push(format!("scenario {line}"));
            }
            m.scenario = Some((s.file.clone(), sdoc.render()));
        } else {
            for _ in 0..n {
                let r = rng.unit();
                if r < 0.12 {
                    let (a, class) = targeted::assignment(&mut rng, &base.plant, &base.value, &base.names);
                    m.changes.push(format!("--set {a} [{class}]"));
                    m.sets.push(a);
                } else if r < 0.4 {
                    m.changes.push(targeted::flowsheet(&mut rng, &mut doc, &base.names));
                } else {
                    m.changes.push(mutate(&mut rng, &mut doc, &base.names));
                }
            }
        }
        m.text = doc.render();
        m
    }

    /// The shipped flowsheet `fi` unchanged: steady, or run with `scenario` (the warm-up).
    pub fn shipped(corpus: &Corpus, fi: usize, scenario: Option<&Scenario>) -> Mutant {
        let f = &corpus.flowsheets[fi];
        Mutant {
            seed: 0,
            mode: if scenario.is_some() { Mode::Run } else { Mode::Steady },
            file: f.file.clone(),
            text: Doc::new(f.value.clone()).render(),
            scenario: scenario.map(|s| (s.file.clone(), Doc::new(s.value.clone()).render())),
            sets: Vec::new(),
            changes: Vec::new(),
            other: None,
        }
    }

    /// A mutant of the other kinds: its input made from the corpus's seeds.
    fn other(seed: u64, mode: Mode, rng: &mut Rng, corpus: &Corpus) -> Mutant {
        let seeds = &corpus.seeds;
        let (file, other, changes) = match mode {
            Mode::Tf => {
                let (file, value) = rng.pick(&seeds.tf);
                let (text, lines) = kinds::mutated(rng, value);
                (file.clone(), Other::Tf(file.clone(), text), lines)
            }
            Mode::StepModel => {
                let (text, lines) = kinds::mutated(rng, &seeds.step_model);
                ("docs/identify_column_a/step_model.json".into(), Other::StepModel(text), lines)
            }
            Mode::Snapshot => {
                let (text, lines) = kinds::mutated(rng, &seeds.snapshot.0);
                ("flowsheets/surge_tank_pi.json".into(), Other::Snapshot(text), lines)
            }
            Mode::Study => {
                let (args, lines) = kinds::study_args(rng);
                (args.get(1).cloned().unwrap_or_default(), Other::Study(args), lines)
            }
            _ => {
                let (raw, lines) = kinds::serve_request(rng);
                ("flowsheets/surge_tank_pi.json".into(), Other::Serve(raw), lines)
            }
        };
        Mutant {
            seed,
            mode,
            file,
            text: String::new(),
            scenario: None,
            sets: Vec::new(),
            changes: changes.into_iter().map(|c| format!("{c} [{mode:?}]")).collect(),
            other: Some(other),
        }
    }

    /// One line: seed, mode, file, changes.
    pub fn describe(&self) -> String {
        let scen = self.scenario.as_ref().map_or(String::new(), |(f, _)| format!(" --scenario {f}"));
        let changes =
            if self.changes.is_empty() { "unmutated [identity]".to_string() } else { self.changes.join("; ") };
        let study = match &self.other {
            Some(Other::Study(args)) => format!(" (plantwide {})", args.join(" ")),
            _ => String::new(),
        };
        format!("seed={:#018x} {:?} {}{scen}{study}: {changes}", self.seed, self.mode, self.file)
    }
}
