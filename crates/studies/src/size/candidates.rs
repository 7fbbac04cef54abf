//! Where surge capacity attenuates a disturbance with the least volume: each candidate vessel
//! (a vessel, a column's drum or base, or a stream to put a new surge tank on) sized for the same
//! disturbance, band and rate limit, ranked by the band volume its optimal design needs — the
//! least volume with which any level controller there meets the rate limit. A candidate whose
//! current vessel and controller already meet the limit needs no more surge.

use plantwide_flowsheet::Plant;
use rayon::prelude::*;
use serde::Serialize;

use super::{LevelDesign, SizeError, SizeRequest, VesselSizing, size_vessel};

/// One ranked candidate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RankedCandidate {
    /// 1 = the least band volume (none when it could not be sized).
    pub rank: Option<usize>,
    /// Its sizing (none when it could not be sized).
    #[serde(flatten)]
    pub sizing: Option<VesselSizing>,
    /// The candidate as asked (when it could not be sized).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub candidate: Option<String>,
    /// The file's vessel and controller (or the bare stream) exceed the band or the rate limit.
    pub needs_surge: Option<bool>,
    /// Why it could not be sized.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
}

/// Most candidates of one ranking (each is sized by three verified designs).
pub const MAX_CANDIDATES: usize = 64;

/// The ranking; serializes to `{"candidates": [...]}`, best first.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CandidateRanking {
    /// Ranked candidates, then those that could not be sized.
    pub candidates: Vec<RankedCandidate>,
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
    r: &SizeRequest,
) -> Result<CandidateRanking, SizeError> {
    crate::request::unique("--candidates", names, |a, b| a == b)?;
    if names.len() > MAX_CANDIDATES {
        return Err(SizeError::Candidates { n: names.len(), max: MAX_CANDIDATES });
    }
    let sized: Vec<Result<VesselSizing, SizeError>> = names.par_iter().map(|n| size_vessel(plant, x, n, r)).collect();
    let mut out = Vec::new();
    for (name, s) in names.iter().zip(sized) {
        match s {
            Ok(s) => {
                let needs = Some(!s.current.meets);
                out.push(RankedCandidate {
                    rank: None,
                    sizing: Some(s),
                    candidate: None,
                    needs_surge: needs,
                    failure: None,
                });
            }
            Err(e @ (SizeError::Vessel { .. } | SizeError::Band { .. } | SizeError::Rate { .. })) => return Err(e),
            Err(e @ SizeError::Disturbance { .. }) => return Err(e),
            Err(e) => out.push(RankedCandidate {
                rank: None,
                sizing: None,
                candidate: Some(name.clone()),
                needs_surge: None,
                failure: Some(e.to_string()),
            }),
        }
    }
    let volume = |c: &RankedCandidate| {
        c.sizing
            .as_ref()
            .and_then(|s| s.designs.iter().find(|d| d.controller == LevelDesign::Optimal))
            .map(|d| d.band_volume)
    };
    out.sort_by(|a, b| match (volume(a), volume(b)) {
        (Some(x), Some(y)) => x.total_cmp(&y),
        (Some(_), None) => std::cmp::Ordering::Less,
        (None, Some(_)) => std::cmp::Ordering::Greater,
        (None, None) => std::cmp::Ordering::Equal,
    });
    for (k, c) in out.iter_mut().enumerate() {
        if c.sizing.is_some() {
            c.rank = Some(k + 1);
        }
    }
    Ok(CandidateRanking { candidates: out })
}
