//! Plantwide pairings: which of the manipulated variables (MVs) controls which controlled variable
//! (CV), and which MV is left as the throughput manipulator.
//!
//! 1. The loops are opened: every controller that measures a CV or drives an MV is removed, the MVs
//!    held at their values in the plant's steady state (an inventory that then nothing holds is an
//!    error naming it). The open plant is converged from the plant's steady state and checked to keep
//!    its CVs, and its exact steady-state gains `G` (CVs × MVs, SI) computed once.
//! 2. For each throughput choice (an MV held as the throughput manipulator, or none), the square
//!    `G_s` of the remaining MVs and its RGA `Λ`: the pairings are enumerated by branch and bound,
//!    a partial pairing cut as soon as a pair's relative gain is not positive (below
//!    [`MIN_RELATIVE_GAIN`]: a necessary condition
//!    of integral controllability, Grosdidier, Morari & Holt 1985). At each complete pairing: the
//!    Niederlinski index (NI > 0 necessary for integral stability, Niederlinski 1971), the necessary
//!    conditions of decentralized integral controllability (DIC: NI > 0 of every principal
//!    submatrix of the paired gains, Skogestad & Morari 1992) and the RGA number `Σ|Λ − P|`.
//! 3. With watched variables, the sensitivity-plot test ([`sensitivity`]): each must stay in its
//!    band over ± each disturbance with the CVs held.
//! 4. The best survivors by RGA number go to a dynamic test ([`dynamic`]): PI loops added, tuned
//!    together by BLT on the exact linearization, then each disturbance stepped on the nonlinear
//!    plant; ranked by their IAE relative to the best candidate's, per CV and disturbance.

pub mod dynamic;
pub mod mpc;
pub mod sensitivity;

use faer::Mat;
use plantwide_analysis::linear::Linearization;
use plantwide_analysis::measures::{niederlinski, rga};
use plantwide_analysis::shard::Share;
use plantwide_flowsheet::{Override, Plant, StructureEdit};
use plantwide_solve::{NewtonSettings, StrategySettings, steady_state};
use serde::Serialize;

pub use dynamic::{
    CandidateFailure, CandidateTask, CvFigures, DisturbanceRun, DynamicResult, DynamicSettings, STEP_AT, Tuning,
};
pub use sensitivity::{Watch, WatchResult};

use super::ScreenError;
use super::column::is_singular;

pub use crate::disturbance::Disturbance;

/// What to screen.
#[derive(Debug, Clone, PartialEq)]
pub struct PairingRequest {
    /// Controlled variables (variable paths).
    pub cvs: Vec<String>,
    /// Manipulated variables (input paths).
    pub mvs: Vec<String>,
    /// Throughput-manipulator candidates, each one of `mvs` (empty: as many MVs as CVs).
    pub throughput: Vec<String>,
    /// Disturbances of the sensitivity and dynamic tests (empty: neither); a `±` one is two steps
    /// of the dynamic test ([`PairingRequest::steps`]).
    pub disturbances: Vec<Disturbance>,
    /// Uncontrolled variables that must stay in a band over ± each disturbance (sensitivity test).
    pub watch: Vec<Watch>,
    /// The dynamic test's settings.
    pub dynamic: DynamicSettings,
    /// Further variables recorded in every run, with figures like the CVs' after them (paths).
    pub record: Vec<String>,
    /// A model predictive controller to judge beside the PI candidates: a `"type": "mpc"`
    /// controller description on the CVs and (some of) the MVs ([`mpc::screen_mpc`]).
    pub mpc: Option<mpc::ScreenMpc>,
    /// Which candidates' dynamic tests this process runs (task `t`: the `t`-th candidate tested):
    /// all, a shard's (then nothing is scored or ranked, and no MPC is run), or none, their
    /// results given by the shards' parts.
    pub share: Share<DynamicResult>,
}

impl PairingRequest {
    /// The steps of the dynamic test, one run each: every disturbance, a `±` one up then down.
    pub fn steps(&self) -> Vec<Disturbance> {
        self.disturbances.iter().flat_map(Disturbance::steps).collect()
    }

    /// The disturbances of the steady-state sweeps (to both sides of the base case), each input
    /// and size once.
    pub fn sweeps(&self) -> Vec<&Disturbance> {
        crate::disturbance::sweeps(&self.disturbances)
    }
}

/// One CV–MV pair and its relative gain.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Pair {
    /// Controlled variable.
    pub cv: String,
    /// Manipulated variable.
    pub mv: String,
    /// Its relative gain.
    pub relative_gain: f64,
}

/// A candidate structure: a throughput manipulator and a pairing.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PairingStructure {
    /// The MV held as throughput manipulator, if any.
    pub throughput: Option<String>,
    /// The pairs, in CV order.
    pub pairs: Vec<Pair>,
    /// Niederlinski index.
    pub niederlinski: f64,
    /// `Σ|Λ − P|` over all elements (0 for a decoupled plant).
    pub rga_number: f64,
    /// NI > 0 of every principal submatrix of the paired gains (necessary for DIC).
    pub dic: bool,
    /// Passed the steady-state filters.
    pub passed: bool,
    /// Why it failed them.
    pub rejected: Option<String>,
    /// The watched variables over the disturbance sweeps (the sensitivity test).
    pub sensitivity: Vec<WatchResult>,
    /// The dynamic test, for the candidates that had one.
    pub dynamic: Option<DynamicResult>,
    /// Place in the ranking (1 best) among those that passed.
    pub rank: Option<usize>,
}

/// The result of a pairing screen.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PairingScreen {
    /// Controlled variables.
    pub cvs: Vec<String>,
    /// Manipulated variables.
    pub mvs: Vec<String>,
    /// Controllers removed to open the loops.
    pub opened: Vec<String>,
    /// Steady-state gains of the open plant, CVs × MVs (SI).
    pub gain: Vec<Vec<f64>>,
    /// Complete pairings examined (leaves of the branch and bound).
    pub enumerated: usize,
    /// Partial pairings cut for a non-positive relative gain.
    pub pruned: usize,
    /// Throughput choices (`null` for none) whose square gain matrix is singular: no pairing of
    /// them can hold the CVs independently, so none is listed.
    pub singular: Vec<Option<String>>,
    /// The structures that reached a leaf, best first.
    pub structures: Vec<PairingStructure>,
    /// The model predictive controller asked for, judged on the same runs (its `score` relative
    /// to the best of all tested).
    pub mpc: Option<mpc::MpcAlternative>,
    /// The structures tested dynamically, in task order (indices into `structures`).
    #[serde(skip)]
    pub tested: Vec<usize>,
    /// The parts asked for that failed, each with its reason (a candidate's tuning, a run, the
    /// model predictive controller's runs), also marked where they stand; empty when all went
    /// through.
    pub failed: Vec<String>,
    /// The recommendation (the candidate ranked first) and what it rests on; when the steady-state
    /// measure (RGA number) orders the dynamically tested candidates otherwise than their dynamic
    /// scores do, it says so.
    pub verdict: String,
    /// The plant's inventory control as the file has it: throughput manipulator candidates and
    /// each inventory's consistency ([`plantwide_flowsheet::inventory`]).
    pub inventory: plantwide_flowsheet::inventory::InventoryCheck,
}

/// The open plant: the loops on the CVs and MVs removed, its steady state and gains.
pub struct OpenPlant {
    /// The plant.
    pub plant: Plant,
    /// Its steady state.
    pub x: Vec<f64>,
    /// The MVs' steady values.
    pub mv_values: Vec<f64>,
    /// The CVs' steady values.
    pub cv_values: Vec<f64>,
    /// Gains CVs × MVs.
    pub gain: Mat<f64>,
    /// The controllers removed.
    pub opened: Vec<String>,
}

/// Screen the pairings of `request` on `plant`.
///
/// # Errors
/// [`ScreenError`] naming the CV, MV or throughput choice that is wrong, or the inventory that
/// opening the loops leaves uncontrolled.
pub fn screen_pairings(plant: &Plant, request: &PairingRequest) -> Result<PairingScreen, ScreenError> {
    super::without_mpc(plant, "screen")?;
    check_request(plant, request)?;
    let open = open_plant(plant, &request.cvs, &request.mvs)?;
    let choices: Vec<Option<&String>> =
        if request.throughput.is_empty() { vec![None] } else { request.throughput.iter().map(Some).collect() };
    let (mut structures, mut enumerated, mut pruned, mut singular) = (Vec::new(), 0, 0, Vec::new());
    for tpm in choices {
        let cols: Vec<usize> = (0..request.mvs.len()).filter(|&j| Some(&request.mvs[j]) != tpm).collect();
        let g = Mat::from_fn(request.cvs.len(), cols.len(), |i, k| open.gain[(i, cols[k])]);
        let mut found = Vec::new();
        if is_singular(&g) {
            singular.push(tpm.cloned());
        } else {
            let lambda = rga(g.as_ref()).map_err(|e| analysis(e, tpm))?;
            branch(&lambda, &mut Vec::new(), &mut found, &mut pruned);
        }
        enumerated += found.len();
        for p in found {
            structures.push(judge(request, &g, &cols, &p, tpm).map_err(|e| analysis(e, tpm))?);
        }
    }
    structures.sort_by(|a, b| {
        (!a.passed, a.rga_number).partial_cmp(&(!b.passed, b.rga_number)).unwrap_or(std::cmp::Ordering::Equal)
    });
    if !request.disturbances.is_empty() && !request.watch.is_empty() {
        sensitivity::test(&open, request, &mut structures)?;
        structures.sort_by(|a, b| {
            (!a.passed, a.rga_number).partial_cmp(&(!b.passed, b.rga_number)).unwrap_or(std::cmp::Ordering::Equal)
        });
    }
    let (duration, tested) = match request.disturbances.is_empty() {
        true => (None, Vec::new()),
        false => dynamic::test(&open, request, &mut structures).map(|(d, t)| (Some(d), t))?,
    };
    let mpc_here = request.mpc.as_ref().filter(|_| !request.share.is_shard());
    let mut mpc = mpc_here.map(|m| mpc::screen_mpc(&open, request, m, duration)).transpose()?;
    if let Some(d) = mpc.as_mut().and_then(|m| m.dynamic.as_mut()) {
        let mut all: Vec<&mut DynamicResult> = structures.iter_mut().filter_map(|s| s.dynamic.as_mut()).collect();
        all.push(d);
        dynamic::score(&mut all, request.steps().len(), request.cvs.len());
    }
    rank(&mut structures);
    let failed = failed_tests(&structures, mpc.as_ref());
    let verdict = verdict(&structures);
    Ok(PairingScreen {
        cvs: request.cvs.clone(),
        mvs: request.mvs.clone(),
        opened: open.opened.clone(),
        gain: plantwide_analysis::measures::rows(open.gain.as_ref()),
        enumerated,
        pruned,
        singular,
        structures,
        mpc,
        tested,
        failed,
        verdict,
        inventory: plantwide_flowsheet::inventory::check(plant),
    })
}

/// A candidate in words: its pairs, and its throughput manipulator.
fn describe(s: &PairingStructure) -> String {
    let pairs: Vec<String> = s.pairs.iter().map(|p| format!("{} ← {}", p.cv, p.mv)).collect();
    let tpm = s.throughput.as_ref().map_or(String::new(), |t| format!(" ({t} held)"));
    format!("{}{tpm}", pairs.join(", "))
}

/// The recommendation and its evidence: the candidate ranked first and why; when the RGA number
/// (the steady-state filters' order) and the dynamic scores order the tested candidates
/// differently, both orders and which one the ranking follows.
fn verdict(structures: &[PairingStructure]) -> String {
    let Some(best) = structures.iter().find(|s| s.rank == Some(1)) else {
        return "no pairing recommended: no candidate passed the steady-state filters, or every tested candidate's \
                dynamic test failed or lost the plant"
            .into();
    };
    let scored: Vec<&PairingStructure> = structures
        .iter()
        .filter(|s| s.rank.is_some() && s.dynamic.as_ref().is_some_and(|d| d.rides_through()))
        .collect();
    let mut by_rga = scored.clone();
    by_rga.sort_by(|a, b| a.rga_number.total_cmp(&b.rga_number));
    let mut by_score = scored.clone();
    by_score.sort_by_key(|s| s.rank);
    let why = match best.dynamic.as_ref().filter(|d| d.rides_through()) {
        Some(d) => format!("best dynamic score ({:.3}) of {} tested on the nonlinear plant", d.score, scored.len()),
        None => format!("smallest RGA number ({:.3}); no dynamic test", best.rga_number),
    };
    let mut text = format!("recommended: {} — {why}", describe(best));
    let lost: Vec<String> = structures
        .iter()
        .filter_map(|s| Some((s, s.dynamic.as_ref()?.losses("run").into_iter().next()?)))
        .map(|(s, first)| format!("{} ({first})", describe(s)))
        .collect();
    if !lost.is_empty() {
        text.push_str(&format!("; cannot ride through the disturbances, so not ranked: {}", lost.join("; ")));
    }
    let same = by_rga.iter().zip(&by_score).all(|(a, b)| std::ptr::eq(*a, *b));
    if !same {
        let ranks: Vec<String> = by_rga.iter().map(|s| s.rank.map_or("–".into(), |r| r.to_string())).collect();
        let first = if std::ptr::eq(by_rga[0], by_score[0]) {
            "they agree on the best only".to_string()
        } else {
            format!(
                "the steady-state measure alone would recommend rank {}, {} (RGA number {:.3} against {:.3})",
                by_rga[0].rank.unwrap_or(0),
                describe(by_rga[0]),
                by_rga[0].rga_number,
                best.rga_number
            )
        };
        text.push_str(&format!(
            "; the evidence disagrees: by RGA number the tested candidates go in the order of ranks {}, not by \
             their dynamic scores ({first}); the ranking follows the dynamic test",
            ranks.join(", ")
        ));
    }
    text
}

/// The dynamic tests of `structures` and `mpc` that failed or had a run fail, each with its
/// reason.
fn failed_tests(structures: &[PairingStructure], mpc: Option<&mpc::MpcAlternative>) -> Vec<String> {
    let pi = structures.iter().filter_map(|c| Some((format!("candidate {}", describe(c)), c.dynamic.as_ref()?)));
    let mpc = mpc.into_iter().filter_map(|m| Some((format!("MPC `{}`", m.controller), m.dynamic.as_ref()?)));
    pi.chain(mpc).flat_map(|(label, d)| d.failures(&label)).collect()
}

/// One given pairing (CV `i` with MV `pairing[i]`) of `request` on `plant`: the open plant, the
/// pairing's steady-state measures and, with disturbances, its dynamic test whatever its filters
/// say, its loops tuned as `tuning` says (a scheme compared as it is built, [`crate::compare`]).
///
/// # Errors
/// As [`screen_pairings`].
pub fn assess_pairing(
    plant: &Plant,
    request: &PairingRequest,
    pairing: &[usize],
    tuning: &Tuning,
) -> Result<(OpenPlant, PairingStructure), ScreenError> {
    check_request(plant, request)?;
    let open = open_plant(plant, &request.cvs, &request.mvs)?;
    let cols: Vec<usize> = (0..request.mvs.len()).collect();
    let mut s = judge(request, &open.gain, &cols, pairing, None).map_err(|e| analysis(e, None))?;
    if !request.disturbances.is_empty() {
        dynamic::test_picked(&open, request, std::slice::from_mut(&mut s), vec![0], tuning)?;
    }
    Ok((open, s))
}

fn analysis(e: plantwide_analysis::AnalysisError, tpm: Option<&String>) -> ScreenError {
    let structure = tpm.map_or("pairings".to_string(), |t| format!("throughput {t}"));
    ScreenError::Analysis { structure, source: Box::new(e) }
}

/// CVs are variables, MVs inputs, throughput candidates MVs, and the count square.
fn check_request(plant: &Plant, r: &PairingRequest) -> Result<(), ScreenError> {
    let hint = |p: &str, names: Vec<&str>| plantwide_flowsheet::error::did_you_mean(p, names);
    if let Some(cv) = r.cvs.iter().find(|c| plant.var(c).is_none()) {
        let hint = hint(cv, plant.vars().iter().map(|v| v.path.as_str()).collect());
        return Err(ScreenError::NoCv { path: cv.clone(), hint });
    }
    if let Some(mv) = r.mvs.iter().find(|m| plant.input(m).is_none()) {
        let hint = hint(mv, plant.inputs().iter().map(|v| v.path.as_str()).collect());
        return Err(ScreenError::NoMv { path: mv.clone(), hint });
    }
    if let Some(w) = r.watch.iter().find(|w| plant.var(&w.path).is_none()) {
        let hint = hint(&w.path, plant.vars().iter().map(|v| v.path.as_str()).collect());
        return Err(ScreenError::NoWatch { path: w.path.clone(), hint });
    }
    for d in &r.disturbances {
        d.check(plant)?;
    }
    if !r.watch.is_empty() && r.disturbances.is_empty() {
        return Err(ScreenError::WatchWithoutDisturbances);
    }
    crate::request::unique("cvs", &r.cvs, |a, b| plant.var(a) == plant.var(b))?;
    crate::request::unique("mvs", &r.mvs, |a, b| plant.input(a) == plant.input(b))?;
    if let Some(t) = r.throughput.iter().find(|t| !r.mvs.contains(t)) {
        return Err(ScreenError::ThroughputNotMv { path: t.clone() });
    }
    disturbances_unpaired(plant, r)?;
    let free = r.mvs.len().saturating_sub(usize::from(!r.throughput.is_empty()));
    if r.cvs.is_empty() || free != r.cvs.len() || r.cvs.len() > 8 {
        return Err(ScreenError::NotSquare {
            cvs: r.cvs.len(),
            mvs: r.mvs.len(),
            throughput: !r.throughput.is_empty(),
        });
    }
    Ok(())
}

/// No disturbance steps an input a candidate pairs: an MV is stepped only as the one throughput
/// candidate, which every candidate holds.
fn disturbances_unpaired(plant: &Plant, r: &PairingRequest) -> Result<(), ScreenError> {
    let same = |a: &str, b: &str| plant.input(a).is_some() && plant.input(a) == plant.input(b);
    for d in &r.disturbances {
        if !r.mvs.iter().any(|m| same(m, &d.path)) {
            continue;
        }
        let others: Vec<&String> = r.throughput.iter().filter(|t| !same(t, &d.path)).collect();
        if r.throughput.len() == 1 && others.is_empty() {
            continue;
        }
        let held = match others.as_slice() {
            [] => String::new(),
            list => {
                let names: Vec<&str> = list.iter().map(|s| s.as_str()).collect();
                format!(
                    " (the candidates holding {} pair it; a throughput change there is a step of the input they hold)",
                    names.join(" or ")
                )
            }
        };
        return Err(ScreenError::DisturbedMv { path: d.path.clone(), held });
    }
    Ok(())
}

/// Open the loops on `cvs` and `mvs`, converge from the plant's steady state and linearize.
pub fn open_plant(plant: &Plant, cvs: &[String], mvs: &[String]) -> Result<OpenPlant, ScreenError> {
    let steady = |structure: &str, e: plantwide_solve::Error| ScreenError::Steady {
        structure: structure.into(),
        source: Box::new(e),
    };
    let base = plantwide_solve::converge(plant, &StrategySettings::default()).map_err(|e| steady("file", e.into()))?;
    let opened: Vec<String> = plant
        .spec()
        .controllers
        .iter()
        .filter(|(_, c)| {
            let p = c.config().paths();
            p.driven.iter().any(|(_, d)| mvs.contains(d))
                || p.measured.iter().any(|(f, m)| f == "pv" && cvs.contains(m))
        })
        .map(|(n, _)| n.clone())
        .collect();
    let mv_values: Vec<f64> = mvs.iter().map(|m| super::column::input_value(plant, &base.x, m)).collect();
    let mut edits: Vec<StructureEdit> = opened.iter().map(|n| StructureEdit::RemoveController(n.clone())).collect();
    edits.extend(
        mvs.iter().zip(&mv_values).map(|(m, v)| StructureEdit::Set(Override::new(m.clone(), format!("{v:e}")))),
    );
    let label = format!("with the loops on the CVs and MVs opened ({})", opened.join(", "));
    let wiring = |e| ScreenError::Wiring { structure: label.clone(), source: Box::new(e) };
    let v = plant.restructure(&edits).map_err(wiring)?;
    let u = v.input_values();
    let guess = super::column::mapped_guess(plant, &base.x, &v);
    let s = steady_state(&v, &u, Some(&guess), &NewtonSettings::default())
        .map_err(|e| steady(&label, plantwide_solve::SolveError::from(e).into()))?;
    let cv_ids: Vec<usize> = cvs.iter().filter_map(|c| v.var(c)).collect();
    let cv_values: Vec<f64> = cvs.iter().filter_map(|c| plant.var(c)).map(|i| base.x[i]).collect();
    for ((&i, &b), c) in cv_ids.iter().zip(&cv_values).zip(cvs) {
        if super::column::moved(s.x[i], b) {
            return Err(ScreenError::Moved { structure: label, output: c.clone(), value: s.x[i], base: b });
        }
    }
    let mv_ids: Vec<usize> = mvs.iter().filter_map(|m| v.input(m)).collect();
    let gain = match Linearization::new(&v, &s.x, &u).steady_gain(&mv_ids, &cv_ids) {
        Ok(g) => g,
        // A singular Jacobian at a point that satisfies the equations: name what is left free.
        Err(e) => match plantwide_solve::dof_check(&v, &u, &s.x, plantwide_solve::DofProbe::Numerical) {
            Err(dof) => {
                let e = plantwide_solve::SolveError::from(plantwide_solve::SteadyError::from(dof));
                return Err(steady(&label, e.into()));
            }
            Ok(()) => return Err(ScreenError::Analysis { structure: label, source: Box::new(e) }),
        },
    };
    Ok(OpenPlant { plant: v, x: s.x, mv_values, cv_values, gain, opened })
}

/// The smallest relative gain a pair may have: below it (a loop whose gain is rounding next to the
/// interactions, e.g. a downstream column's input on an upstream quality) the pair cannot be closed.
pub const MIN_RELATIVE_GAIN: f64 = 1e-6;

/// Branch and bound over the pairings of `lambda`'s rows to its columns: row `k = p.len()` next,
/// every unused column with a positive relative gain a branch; a complete pairing is a leaf.
fn branch(lambda: &Mat<f64>, p: &mut Vec<usize>, leaves: &mut Vec<Vec<usize>>, pruned: &mut usize) {
    let k = p.len();
    if k == lambda.nrows() {
        leaves.push(p.clone());
        return;
    }
    for j in 0..lambda.ncols() {
        if p.contains(&j) {
            continue;
        }
        if lambda[(k, j)].is_nan() || lambda[(k, j)] <= MIN_RELATIVE_GAIN {
            *pruned += 1;
            continue;
        }
        p.push(j);
        branch(lambda, p, leaves, pruned);
        p.pop();
    }
}

/// The steady-state measures and filters of pairing `p` (row i with column `p[i]` of `g`).
fn judge(
    r: &PairingRequest,
    g: &Mat<f64>,
    cols: &[usize],
    p: &[usize],
    tpm: Option<&String>,
) -> Result<PairingStructure, plantwide_analysis::AnalysisError> {
    let lambda = rga(g.as_ref())?;
    let ni = niederlinski(g.as_ref(), p)?;
    let n = p.len();
    let rga_number: f64 = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| (lambda[(i, j)] - if p[i] == j { 1.0 } else { 0.0 }).abs())
        .sum();
    let dic = dic_necessary(g, p)?;
    let rejected = if ni <= 0.0 {
        Some(format!("NI = {ni:.4} ≤ 0: the loops closed together with integral action are unstable"))
    } else if !dic {
        Some("a principal subsystem has NI ≤ 0: not decentralized integral controllable (loops taken out of service destabilize the rest)".into())
    } else {
        None
    };
    let pairs = (0..n)
        .map(|i| Pair { cv: r.cvs[i].clone(), mv: r.mvs[cols[p[i]]].clone(), relative_gain: lambda[(i, p[i])] })
        .collect();
    Ok(PairingStructure {
        throughput: tpm.cloned(),
        pairs,
        niederlinski: ni,
        rga_number,
        dic,
        passed: rejected.is_none(),
        rejected,
        sensitivity: Vec::new(),
        dynamic: None,
        rank: None,
    })
}

/// NI > 0 of every principal submatrix of the paired gains `G_p` (columns reordered so the pairs
/// sit on the diagonal): necessary for decentralized integral controllability.
fn dic_necessary(g: &Mat<f64>, p: &[usize]) -> Result<bool, plantwide_analysis::AnalysisError> {
    let n = p.len();
    let paired = Mat::from_fn(n, n, |i, k| g[(i, p[k])]);
    for mask in 1u32..(1 << n) {
        let idx: Vec<usize> = (0..n).filter(|&i| mask & (1 << i) != 0).collect();
        if idx.len() < 2 {
            continue;
        }
        let sub = Mat::from_fn(idx.len(), idx.len(), |a, b| paired[(idx[a], idx[b])]);
        let diag: Vec<usize> = (0..idx.len()).collect();
        if niederlinski(sub.as_ref(), &diag)? <= 0.0 {
            return Ok(false);
        }
    }
    Ok(true)
}

/// Rank: dynamically tested candidates by their score, then the other survivors by RGA number; a
/// candidate whose dynamic test failed (it could not be tuned, or a run stopped) or that lost the
/// plant in a run (a vessel ran dry, a flow would reverse) is not ranked.
fn rank(structures: &mut [PairingStructure]) {
    let key = |s: &PairingStructure| {
        let score = s.dynamic.as_ref().map_or(f64::INFINITY, |d| d.score);
        (score, s.rga_number)
    };
    let failed = |s: &PairingStructure| s.dynamic.as_ref().is_some_and(|d| !d.rides_through());
    let mut order: Vec<usize> =
        (0..structures.len()).filter(|&k| structures[k].passed && !failed(&structures[k])).collect();
    order.sort_by(|&a, &b| key(&structures[a]).partial_cmp(&key(&structures[b])).unwrap_or(std::cmp::Ordering::Equal));
    for (place, k) in order.into_iter().enumerate() {
        structures[k].rank = Some(place + 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every permutation of 0..n (Heap's algorithm would do; n ≤ 5 here).
    fn permutations(n: usize) -> Vec<Vec<usize>> {
        if n == 0 {
            return vec![Vec::new()];
        }
        let mut out = Vec::new();
        for p in permutations(n - 1) {
            for k in 0..n {
                let mut q = p.clone();
                q.insert(k, n - 1);
                out.push(q);
            }
        }
        out
    }

    #[test]
    fn branch_and_bound_finds_exactly_the_pairings_with_positive_relative_gains() {
        // A deterministic pseudo-random 5 × 5 (linear congruential), its RGA, and brute force.
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let g = Mat::from_fn(5, 5, |_, _| next());
        let lambda = rga(g.as_ref()).unwrap();
        let (mut leaves, mut pruned) = (Vec::new(), 0);
        branch(&lambda, &mut Vec::new(), &mut leaves, &mut pruned);
        let mut brute: Vec<Vec<usize>> =
            permutations(5).into_iter().filter(|p| (0..5).all(|i| lambda[(i, p[i])] > MIN_RELATIVE_GAIN)).collect();
        brute.sort();
        leaves.sort();
        assert_eq!(leaves, brute);
        assert!(pruned > 0 && leaves.len() < 120, "{} leaves, {pruned} cut", leaves.len());
    }

    /// A candidate pairing `cv` with `mv`, with its RGA number and, when tested, its score.
    fn candidate(mv: &str, rga_number: f64, score: Option<f64>) -> PairingStructure {
        let dynamic = score.map(|score| DynamicResult {
            detuning_factor: None,
            loops: Vec::new(),
            runs: Vec::new(),
            score,
            failure: None,
        });
        PairingStructure {
            throughput: None,
            pairs: vec![Pair { cv: "x".into(), mv: mv.into(), relative_gain: 1.0 }],
            niederlinski: 1.0,
            rga_number,
            dic: true,
            passed: true,
            rejected: None,
            sensitivity: Vec::new(),
            dynamic,
            rank: None,
        }
    }

    #[test]
    fn a_recommendation_its_own_steady_state_evidence_contradicts_says_so() {
        // The RGA number prefers `a`, the dynamic test `b`: the ranking follows the dynamic test and
        // the verdict names the candidate the steady-state measure alone would recommend.
        let mut s = vec![candidate("a", 0.5, Some(2.0)), candidate("b", 1.0, Some(1.0)), candidate("c", 3.0, None)];
        rank(&mut s);
        assert_eq!(s.iter().map(|c| c.rank).collect::<Vec<_>>(), [Some(2), Some(1), Some(3)]);
        let v = verdict(&s);
        assert!(v.starts_with("recommended: x ← b — best dynamic score (1.000) of 2 tested"), "{v}");
        assert!(
            v.contains("the evidence disagrees: by RGA number the tested candidates go in the order of ranks 2, 1")
        );
        assert!(v.contains("would recommend rank 2, x ← a (RGA number 0.500 against 1.000)"), "{v}");
        // Both measures agree: no contradiction to flag.
        let mut s = vec![candidate("a", 0.5, Some(1.0)), candidate("b", 1.0, Some(2.0))];
        rank(&mut s);
        let v = verdict(&s);
        assert!(v.starts_with("recommended: x ← a — best dynamic score") && !v.contains("disagrees"), "{v}");
        // They agree on the best only.
        let mut s =
            vec![candidate("a", 0.5, Some(1.0)), candidate("b", 1.0, Some(3.0)), candidate("c", 2.0, Some(2.0))];
        rank(&mut s);
        let v = verdict(&s);
        assert!(v.contains("order of ranks 1, 3, 2") && v.contains("they agree on the best only"), "{v}");
        // Nothing ranked.
        assert!(verdict(&[]).starts_with("no pairing recommended"));
    }

    #[test]
    fn dic_fails_when_a_principal_subsystem_has_a_negative_niederlinski_index() {
        // G = [[1, 2, 1], [1, 1, 0], [−2, 0, 1]]: det = 1·1 − 2·1 + 1·(0 + 2) = 1 and the diagonal's
        // product 1, so NI = 1 > 0; but the loops 1–2 alone, [[1, 2], [1, 1]], have NI = −1: take loop 3
        // out of service and the other two go unstable. Not DIC; the NI filter alone would pass it.
        let h = Mat::from_fn(3, 3, |i, j| [[1.0, 2.0, 1.0], [1.0, 1.0, 0.0], [-2.0, 0.0, 1.0]][i][j]);
        let ni = niederlinski(h.as_ref(), &[0, 1, 2]).unwrap();
        assert!((ni - 1.0).abs() < 1e-12, "{ni}");
        assert!(!dic_necessary(&h, &[0, 1, 2]).unwrap());
        // A diagonally dominant plant passes.
        let d = Mat::from_fn(3, 3, |i, j| if i == j { 2.0 } else { 0.3 });
        assert!(dic_necessary(&d, &[0, 1, 2]).unwrap());
    }
}
