//! A sizing as a user asks for it: [`SizeRequest`], read from the same unit-bearing JSON as a
//! flowsheet file (`"level_band": "0.3 m"`, a bare number is SI), and [`size`], the one call every
//! face makes. Messages name the request's fields (`level_band`, `disturbance`); a face that
//! calls them something else maps [`SizeError::field`] to its own names.
//!
//! ```json
//! {"vessel": "tank", "disturbance": "feed.F=+10%", "level_band": "0.3 m",
//!  "max_outflow_rate": "5 kmol/h/min"}
//! ```

use plantwide_flowsheet::Plant;
use plantwide_flowsheet::scenario::ScenarioSpec;
use plantwide_units::{Dimension, QuantityValue};
use serde::{Deserialize, Serialize};

use super::{
    Attenuation, CandidateRanking, Disturbance, PARTS_PER_VESSEL, Progress, Shape, SizeCriteria, SizeError,
    VesselSizing, rank_candidates_observed, size_vessel_observed,
};

/// What `plantwide size` and `Plant.size` ask: one vessel to size, or candidates to rank, for one
/// disturbance and its limits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SizeRequest {
    /// The vessel: a tank, CSTR or flash; a column's `COL.drum` or `COL.sump`; or a stream, for a
    /// new surge tank on it. Give this or `candidates`.
    #[serde(default)]
    pub vessel: Option<String>,
    /// Vessels (same forms) to rank by the surge volume they need.
    #[serde(default)]
    pub candidates: Vec<String>,
    /// A step of an input: `PATH=+x%`, `PATH=-x%` or an amount with its unit (`PATH=+5 kmol/h`).
    #[serde(default)]
    pub disturbance: Option<String>,
    /// Instead of `disturbance`: a scenario whose one step, ramp or sinusoid of an input is the
    /// disturbance (started at once from the steady state).
    #[serde(default)]
    pub scenario: Option<ScenarioSpec>,
    /// The disturbance as a ramp to the same change over this time, instead of a step.
    #[serde(default)]
    pub ramp: Option<QuantityValue>,
    /// The disturbance as a sinusoid of amplitude Δ and this period, instead of a step.
    #[serde(default)]
    pub sine: Option<QuantityValue>,
    /// The largest allowed deviation of the level from its setpoint, either way (a length).
    pub level_band: QuantityValue,
    /// The largest allowed rate of change of the vessel's outflow (`"5 kmol/h/min"`).
    #[serde(default)]
    pub max_outflow_rate: Option<QuantityValue>,
    /// Instead of a rate limit: the outflow of the disturbance, a sinusoid of amplitude Δ at
    /// `period`, may swing at most this fraction of the inflow's, in (0, 1).
    #[serde(default)]
    pub attenuation: Option<f64>,
    /// The period of `attenuation`.
    #[serde(default)]
    pub period: Option<QuantityValue>,
    /// Length of each verification run (default: long enough for the design and the plant to
    /// settle); a run of a step or a ramp not settled by then is marked failed.
    #[serde(default)]
    pub duration: Option<QuantityValue>,
}

/// The answer of a [`SizeRequest`]: one vessel's designs or the candidates' ranking. Serializes
/// as the one it is (the JSON `plantwide size --json` prints).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Sizing {
    /// `vessel`'s designs.
    Vessel(Box<VesselSizing>),
    /// `candidates` ranked.
    Ranking(CandidateRanking),
}

impl Sizing {
    /// The parts that have no answer (a design, a run, a candidate), each with its reason.
    pub fn failed(&self) -> &[String] {
        match self {
            Sizing::Vessel(s) => &s.failed,
            Sizing::Ranking(r) => &r.failed,
        }
    }
}

impl SizeRequest {
    /// How many parts [`size`] tells its progress of.
    pub fn parts(&self) -> usize {
        PARTS_PER_VESSEL * if self.vessel.is_some() { 1 } else { self.candidates.len() }
    }

    /// The criteria in SI, each field named when it does not parse or does not fit `plant`.
    ///
    /// # Errors
    /// [`SizeError::Field`] naming the field; [`SizeError::Disturbance`] for a disturbance that is
    /// no free input of `plant`.
    pub fn criteria(&self, plant: &Plant) -> Result<SizeCriteria, SizeError> {
        let level_band = quantity("level_band", &self.level_band, Dimension::LENGTH)?;
        let max_outflow_rate = match &self.max_outflow_rate {
            Some(r) => quantity("max_outflow_rate", r, Dimension::MOLAR_FLOW / Dimension::TIME)?,
            None if self.attenuation.is_none() => {
                return Err(field(
                    "max_outflow_rate",
                    "is missing: give the largest rate of change of the outflow, or an attenuation",
                ));
            }
            None => f64::NAN,
        };
        let attenuation = match (self.attenuation, &self.period) {
            (Some(ratio), Some(p)) => Some(Attenuation { ratio, period: quantity("period", p, Dimension::TIME)? }),
            (Some(_), None) => return Err(field("period", "is missing: an attenuation is asked at a period")),
            (None, Some(_)) => return Err(field("period", "is the attenuation's: give the attenuation too")),
            (None, None) => None,
        };
        let duration = self.duration.as_ref().map(|d| quantity("duration", d, Dimension::TIME)).transpose()?;
        if duration.is_some_and(|d| d.is_nan() || d <= 0.0) {
            return Err(field("duration", "must be a positive time"));
        }
        let disturbance = self.disturbance(plant)?;
        Ok(SizeCriteria { disturbance, level_band, max_outflow_rate, attenuation, duration })
    }

    /// The disturbance: the step of `disturbance` in the shape of `ramp` or `sine`, or the one
    /// event of `scenario`.
    fn disturbance(&self, plant: &Plant) -> Result<Disturbance, SizeError> {
        let time = |name: &'static str, t: &Option<QuantityValue>| {
            t.as_ref().map(|t| quantity(name, t, Dimension::TIME)).transpose()
        };
        let shape = match (time("ramp", &self.ramp)?, time("sine", &self.sine)?) {
            (Some(_), Some(_)) => return Err(field("sine", "is given with a ramp: a ramp or a sinusoid, not both")),
            (Some(duration), None) => Shape::Ramp { duration },
            (None, Some(period)) => Shape::Sine { period },
            (None, None) => Shape::Step,
        };
        match (&self.disturbance, &self.scenario) {
            (Some(d), None) => step(d, plant, shape),
            (None, Some(spec)) if shape == Shape::Step && self.attenuation.is_none() => from_scenario(spec, plant),
            (None, Some(_)) => Err(field(
                "scenario",
                "is given with a ramp, sine or attenuation: the scenario's event has its own shape",
            )),
            (Some(_), Some(_)) => Err(field("scenario", "is given with a disturbance: give one of them")),
            (None, None) => Err(field("disturbance", "is missing: give the disturbance (PATH=±Δ) or a scenario")),
        }
    }
}

/// Size `request`'s vessel, or rank its candidates, in `plant` at its steady state `x`, telling
/// `progress` as each part is done ([`SizeRequest::parts`] of them).
///
/// # Errors
/// [`SizeError`]: a bad request (exit 1 at the faces, [`SizeError::is_user_error`]) or a plant
/// that cannot be solved before or after the disturbance. A design or a run that has no answer is
/// not an error: it is marked where it stands and listed in [`Sizing::failed`].
pub fn size(
    plant: &Plant,
    x: &[f64],
    request: &SizeRequest,
    progress: &(dyn Fn(Progress<'_>) + Sync),
) -> Result<Sizing, SizeError> {
    let criteria = request.criteria(plant)?;
    match (&request.vessel, request.candidates.is_empty()) {
        (Some(v), true) => size_vessel_observed(plant, x, v, &criteria, progress).map(|s| Sizing::Vessel(Box::new(s))),
        (None, false) => {
            rank_candidates_observed(plant, x, &request.candidates, &criteria, progress).map(Sizing::Ranking)
        }
        (Some(_), false) => Err(field("candidates", "is given with a vessel: size one vessel or rank candidates")),
        (None, true) => Err(field("vessel", "is missing: give the vessel to size, or candidates to rank")),
    }
}

fn field(name: &'static str, why: &str) -> SizeError {
    SizeError::Field { field: name, why: why.to_string() }
}

/// `value` in SI, of dimension `dim`.
fn quantity(name: &'static str, value: &QuantityValue, dim: Dimension) -> Result<f64, SizeError> {
    value.to_si(dim).map_err(|e| SizeError::Field { field: name, why: format!("{value}: {e}") })
}

/// `PATH=+x%`, `PATH=-x%` or an amount with its unit (`PATH=+5 kmol/h`), read by the studies' one
/// parser and judged by its range rule ([`crate::disturbance`]); sizing verifies one step, so `±`
/// is refused.
fn step(text: &str, plant: &Plant, shape: Shape) -> Result<Disturbance, SizeError> {
    use crate::disturbance::{Direction, Disturbance as Step};
    let bad = |why: String| SizeError::Field { field: "disturbance", why };
    let d: Step = text.parse().map_err(|e| bad(format!("{e}")))?;
    if d.direction == Direction::Both {
        return Err(bad(format!(
            "{}: sizing verifies one step (the closed forms hold for either sign); give its direction, {} +{} or {} -{}",
            d.label(),
            d.path,
            d.shown,
            d.path,
            d.shown
        )));
    }
    d.check(plant).map_err(|e| bad(e.to_string()))?;
    let i = plantwide_flowsheet::overrides::resolve_input(plant, &d.path)
        .ok_or_else(|| bad(format!("`{}` is no input of the flowsheet", d.path)))?;
    Ok(Disturbance { path: d.path.clone(), change: d.change(plant.inputs()[i].value), shape })
}

/// The disturbance of scenario `spec`, checked against `plant` (its limits the defaults).
fn from_scenario(spec: &ScenarioSpec, plant: &Plant) -> Result<Disturbance, SizeError> {
    let name = if spec.name.is_empty() { "(unnamed)" } else { spec.name.as_str() };
    let bad = |why: String| SizeError::Field { field: "scenario", why: format!("`{name}`: {why}") };
    let scenario = plantwide_flowsheet::scenario::resolve(spec, plant, name).map_err(|e| bad(e.to_string()))?;
    Disturbance::from_scenario(&scenario, plant).map_err(|e| match e {
        SizeError::Disturbance { why, .. } => bad(why),
        e => bad(e.to_string()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_request_reads_quantities_with_their_units_and_refuses_unknown_fields() {
        let r: SizeRequest = serde_json::from_str(
            r#"{"vessel": "tank", "disturbance": "feed.F=+10%", "level_band": "30 cm", "max_outflow_rate": 0.01}"#,
        )
        .unwrap();
        assert_eq!(quantity("level_band", &r.level_band, Dimension::LENGTH).unwrap(), 0.3);
        assert_eq!(r.max_outflow_rate, Some(QuantityValue::Number(0.01)));
        let e = serde_json::from_str::<SizeRequest>(r#"{"vessel": "t", "level_band": 1, "band": 2}"#).unwrap_err();
        assert!(e.to_string().contains("unknown field `band`"), "{e}");
    }

    #[test]
    fn a_quantity_of_the_wrong_dimension_names_its_field() {
        let e = quantity("level_band", &"5 kmol/h".into(), Dimension::LENGTH).unwrap_err();
        assert_eq!(e.field(), Some("level_band"));
        assert!(e.to_string().starts_with("level_band 5 kmol/h: "), "{e}");
    }
}
