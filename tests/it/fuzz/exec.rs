//! Running one mutant in process through the library, as `plantwide check`, `steady` and `run`
//! would, and classifying what came back.

use plantwide::flowsheet::Plant;
use plantwide::flowsheet::scenario::{parse_scenario, resolve};
use plantwide::flowsheet::{Override, load_str_with};
use plantwide::solve::dynamic::{SimError, Start, simulate};
use plantwide::solve::{DofProbe, dof_check};
use plantwide::solve::{Solution, StrategySettings, converge};

use super::certificate;
use super::corpus::{Corpus, Mode, Mutant, Other};
use super::kinds;

/// What an honest engine may answer.
#[derive(Debug)]
pub enum Outcome {
    /// Loaded, converged (and certified), or ran (with finite values).
    Ok,
    /// Rejected as a user error (exit 1).
    User(String),
    /// A numerical failure (exit 2).
    Numerical(String),
}

/// A dishonest answer: `Ok` with a failed certificate.
#[derive(Debug)]
pub struct Dishonest(pub String);

/// Run `m`.
pub fn execute(m: &Mutant, corpus: &Corpus) -> Result<Outcome, Dishonest> {
    if let Some(other) = &m.other {
        return match other {
            Other::Tf(file, text) => kinds::tf(file, text),
            Other::StepModel(text) => kinds::step_model(&corpus.seeds.mpc_flowsheet, text),
            Other::Snapshot(text) => kinds::snapshot(text, &corpus.seeds.snapshot.1),
            Other::Study(args) => kinds::study(args),
            Other::Serve(raw) => kinds::serve(raw),
        };
    }
    let (mut plant, u) = match load(m) {
        Ok(p) => p,
        Err(e) => return Ok(Outcome::User(e)),
    };
    match m.mode {
        Mode::Load => {
            let _ = plant.recycles();
            let x = plant.initial_guess_at(&u);
            Ok(match dof_check(&plant, &u, &x, DofProbe::Structural) {
                Ok(()) => Outcome::Ok,
                Err(e) => Outcome::User(e.to_string()),
            })
        }
        Mode::Steady => match steady(&plant, &u) {
            Ok(sol) => certificate::steady(&plant, &sol.x).map(|()| Outcome::Ok).map_err(Dishonest),
            Err(o) => Ok(o),
        },
        Mode::Run => {
            plant.set_input_values(&u);
            run(m, &plant, &u)
        }
        _ => unreachable!("a mutant of another kind carries its input"),
    }
}

/// Parse, assemble and apply the `--set` assignments as `plantwide steady` does.
fn load(m: &Mutant) -> Result<(Plant, Vec<f64>), String> {
    let overrides =
        m.sets.iter().map(|s| s.parse()).collect::<Result<Vec<Override>, _>>().map_err(|e| e.to_string())?;
    let plant = load_str_with(&m.text, &m.file, &overrides).map_err(|e| e.to_string())?;
    let u = plant.input_values();
    Ok((plant, u))
}

/// The steady state as `plantwide steady` finds it ([`converge`]: DOF probe, strategy, certificate).
fn steady(plant: &Plant, u: &[f64]) -> Result<Solution, Outcome> {
    debug_assert_eq!(plant.input_values(), u);
    converge(plant, &StrategySettings::default())
        .map_err(|e| if e.is_user_error() { Outcome::User(e.to_string()) } else { Outcome::Numerical(e.to_string()) })
}

/// The scenario from the certified steady state, as `plantwide run` does.
fn run(m: &Mutant, plant: &Plant, u: &[f64]) -> Result<Outcome, Dishonest> {
    let (file, text) = m.scenario.as_ref().expect("a run mutant has a scenario");
    let sc = match parse_scenario(text, file).and_then(|s| resolve(&s, plant, file)) {
        Ok(sc) => sc,
        Err(e) => return Ok(Outcome::User(e.to_string())),
    };
    let sol = match steady(plant, u) {
        Ok(sol) => sol,
        Err(o) => return Ok(o),
    };
    certificate::steady(plant, &sol.x).map_err(Dishonest)?;
    match simulate(plant, &sc, Start::Steady(&sol.x), "fuzz", &mut |_| {}) {
        Ok(res) => certificate::run(&res).map(|()| Outcome::Ok).map_err(|e| Dishonest(format!("run: {e}"))),
        Err(e @ (SimError::Snapshot { .. } | SimError::Wiring(_))) => Ok(Outcome::User(e.to_string())),
        Err(e) => Ok(Outcome::Numerical(e.to_string())),
    }
}
