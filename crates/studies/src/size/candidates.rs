//! Where surge capacity attenuates a disturbance with the least volume: each candidate vessel
//! (a vessel, a column's drum or base, or a stream to put a new surge tank on) sized for the same
//! disturbance, band and rate limit, ranked by the band volume its optimal design needs — the
//! least volume with which any level controller there meets the rate limit. Candidates whose
//! optimal design holds the limits in its run rank first, then those whose design does not (or
//! has no run), each by volume. A candidate whose current vessel and controller already meet the
//! limits needs no more surge; every verdict is [`super::verdict`]'s, so two identical candidates
//! get identical rows.

use plantwide_flowsheet::Plant;
use rayon::prelude::*;
use serde::Serialize;

use super::{LevelDesign, Progress, SizeCriteria, SizeError, VesselSizing, size_vessel_observed};

/// One ranked candidate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RankedCandidate {
    /// 1 = the least band volume among those whose optimal design holds (none when it could not be
    /// sized).
    pub rank: Option<usize>,
    /// Its sizing (none when it could not be sized).
    #[serde(flatten)]
    pub sizing: Option<VesselSizing>,
    /// The candidate as asked (when it could not be sized).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub candidate: Option<String>,
    /// The file's vessel and controller (or the bare stream) exceed the band or the rate limit:
    /// the negation of the file's vessel's verdict; none when the rate holds but the band cannot
    /// be judged (a column's holdup has no level), when the file's vessel's run failed, or when
    /// the candidate could not be sized.
    pub needs_surge: Option<bool>,
    /// The optimal design's run holds the band and the rate limit (none when it could not be
    /// sized).
    pub optimal_meets: Option<bool>,
    /// Why it could not be sized.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
}

/// Most candidates of one ranking (each is sized by three verified designs).
pub const MAX_CANDIDATES: usize = 64;

/// The ranking; serializes to `{"candidates": [...], "failed": [...]}`, best first.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CandidateRanking {
    /// Ranked candidates, then those that could not be sized.
    pub candidates: Vec<RankedCandidate>,
    /// The parts that have no answer: a candidate that could not be sized, a design or run of one
    /// that could; empty when all went through.
    pub failed: Vec<String>,
}

/// Size every candidate (in parallel) and rank them.
///
/// # Errors
/// [`SizeError`] when the request itself is bad (band, rate, disturbance, or a candidate that is
/// no vessel); a candidate that cannot be solved or that the disturbance does not reach is
/// recorded as its `failure`.
pub fn rank_candidates(
    plant: &Plant,
    x: &[f64],
    names: &[String],
    r: &SizeCriteria,
) -> Result<CandidateRanking, SizeError> {
    rank_candidates_observed(plant, x, names, r, &|_| {})
}

/// [`rank_candidates`], telling `progress` as each part of each candidate is done.
///
/// # Errors
/// See [`rank_candidates`].
pub fn rank_candidates_observed(
    plant: &Plant,
    x: &[f64],
    names: &[String],
    r: &SizeCriteria,
    progress: &(dyn Fn(Progress<'_>) + Sync),
) -> Result<CandidateRanking, SizeError> {
    crate::request::unique("candidates", names, |a, b| a == b)?;
    if names.len() > MAX_CANDIDATES {
        return Err(SizeError::Candidates { n: names.len(), max: MAX_CANDIDATES });
    }
    let sized: Vec<Result<VesselSizing, SizeError>> =
        names.par_iter().map(|n| size_vessel_observed(plant, x, n, r, progress)).collect();
    let mut out = Vec::new();
    let mut failed = Vec::new();
    for (name, s) in names.iter().zip(sized) {
        match s {
            Ok(s) => {
                failed.extend(s.failed.iter().cloned());
                out.push(ranked(s));
            }
            Err(e @ (SizeError::Vessel { .. } | SizeError::Band { .. } | SizeError::Rate { .. })) => return Err(e),
            Err(e @ SizeError::Disturbance { .. }) => return Err(e),
            Err(e) => {
                failed.push(format!("candidate `{name}`: {e}"));
                out.push(RankedCandidate {
                    rank: None,
                    sizing: None,
                    candidate: Some(name.clone()),
                    needs_surge: None,
                    optimal_meets: None,
                    failure: Some(e.to_string()),
                });
            }
        }
    }
    // Sized before not sized; a holding optimal design before one that does not hold; least volume.
    let key = |c: &RankedCandidate| {
        let volume = c.sizing.as_ref().and_then(optimal).map_or(f64::INFINITY, |d| d.band_volume);
        (c.sizing.is_none(), c.optimal_meets != Some(true), volume)
    };
    out.sort_by(|a, b| {
        let (x, y) = (key(a), key(b));
        x.0.cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.total_cmp(&y.2))
    });
    for (k, c) in out.iter_mut().enumerate() {
        if c.sizing.is_some() {
            c.rank = Some(k + 1);
        }
    }
    Ok(CandidateRanking { candidates: out, failed })
}

/// A sized candidate with its verdicts, from [`super::verdict`] alone (through the file's
/// vessel's `meets` and the optimal design's).
fn ranked(s: VesselSizing) -> RankedCandidate {
    RankedCandidate {
        rank: None,
        needs_surge: if s.current.failure.is_some() { None } else { s.current.meets.map(|meets| !meets) },
        optimal_meets: optimal(&s).map(|d| d.verified.meets),
        sizing: Some(s),
        candidate: None,
        failure: None,
    }
}

/// The optimal design of a sizing.
fn optimal(s: &VesselSizing) -> Option<&super::Design> {
    s.designs.iter().find(|d| d.controller == LevelDesign::Optimal)
}
