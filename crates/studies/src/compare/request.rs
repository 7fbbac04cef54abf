//! A comparison as a user asks for it: [`CompareRequest`], read from the same unit-bearing JSON as
//! a flowsheet file, and [`study`], the one call every face makes. Messages name the request's
//! fields (`disturbances`, `heating_price`); a face that calls them otherwise maps them.
//!
//! ```json
//! {"disturbances": ["feed.F=±10%"], "outputs": ["column.reboiler_duty@MW", "distillate.x[A]"]}
//! ```

use plantwide_flowsheet::Plant;
use plantwide_units::{Dimension, QuantityValue};
use serde::{Deserialize, Serialize};

use super::{CompareError, CompareSettings, Comparison, Prices, compare};
use crate::screen::pairings::{Disturbance, DynamicSettings};
use crate::tune::loops::Measurement;

/// How the quality loops are tuned for the closed-loop runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LoopTuning {
    /// BLT where the open loop is stable, the file's settings where it is not.
    #[default]
    Blt,
    /// Every file's own settings (like for like when the files share them).
    File,
}

/// What `plantwide compare` and `plantwide.compare` ask of two or more schemes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompareRequest {
    /// Disturbances: `PATH` (+10 % of its steady value), `PATH=+x%`, `-x%`, `±x%` (one run each
    /// way) or an amount with its unit (`PATH=+5 K`); the sweeps go both ways by the step's size.
    pub disturbances: Vec<String>,
    /// Outputs watched in every scheme: variable paths, or inputs a controller drives, each with
    /// an optional display unit (`column.reboiler_duty@MW`).
    pub outputs: Vec<String>,
    /// Quality loops by controller name (default: every PI loop whose measurement is not a level,
    /// holdup or pressure).
    #[serde(default)]
    pub loops: Vec<String>,
    /// Measurement dead time the BLT tuning of the quality loops allows for (default 1 min).
    #[serde(default = "one_minute")]
    pub measurement_dead_time: QuantityValue,
    /// Tuning of the quality loops in the closed-loop runs.
    #[serde(default)]
    pub tuning: LoopTuning,
    /// Length of each closed-loop run (default: 20 reset times of the slowest tuned loop).
    #[serde(default)]
    pub duration: Option<QuantityValue>,
    /// Price of the heating utility \[$/GJ\] (default: low-pressure steam, 7.78, Luyben 2013).
    #[serde(default = "heating")]
    pub heating_price: f64,
    /// Price of the cooling utility \[$/GJ\] (default: cooling water, 0.354, Turton et al. 2012).
    #[serde(default = "cooling")]
    pub cooling_price: f64,
    /// Operating hours a year for the yearly utility cost (default 8760).
    #[serde(default = "hours")]
    pub hours: f64,
}

fn one_minute() -> QuantityValue {
    QuantityValue::Text("1 min".into())
}
fn heating() -> f64 {
    Prices::default().heating
}
fn cooling() -> f64 {
    Prices::default().cooling
}
fn hours() -> f64 {
    Prices::default().hours
}

impl CompareRequest {
    /// The fields a message names in backticks (`` give a `duration` ``), for a face to map to its
    /// own names; a field a message only starts with is [`CompareError::field`]'s.
    pub const FIELDS: &'static [&'static str] = &["duration", "loops"];

    /// `outputs` without their display units.
    pub fn output_paths(&self) -> Vec<String> {
        let path = |o: &String| plantwide_analysis::select::split_unit(o).0.to_string();
        self.outputs.iter().map(path).collect()
    }

    /// The request in SI, each field named when it does not parse.
    ///
    /// # Errors
    /// [`CompareError::Field`] or [`CompareError::Disturbance`] naming the field.
    pub fn settings(&self) -> Result<CompareSettings, CompareError> {
        let disturbances = self.disturbances.iter().map(|d| d.parse::<Disturbance>()).collect::<Result<_, _>>()?;
        let dead_time = time("measurement_dead_time", &self.measurement_dead_time)?;
        let duration = self.duration.as_ref().map(|d| time("duration", d)).transpose()?;
        Ok(CompareSettings {
            disturbances,
            outputs: self.output_paths(),
            loops: self.loops.clone(),
            file_tuning: self.tuning == LoopTuning::File,
            prices: self.prices()?,
            dynamic: DynamicSettings { candidates: 1, duration, measurement: Measurement { dead_time, lag: 0.0 } },
        })
    }

    /// The utility prices: each finite and not negative, the hours within a year.
    fn prices(&self) -> Result<Prices, CompareError> {
        for (field, v) in [("heating_price", self.heating_price), ("cooling_price", self.cooling_price)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(CompareError::Field { field, why: format!("{v}: give a price in $/GJ, zero or more") });
            }
        }
        if !(self.hours > 0.0 && self.hours <= 8784.0) {
            return Err(CompareError::Field {
                field: "hours",
                why: format!("{}: give the operating hours in a year, more than 0 and at most 8784", self.hours),
            });
        }
        Ok(Prices { heating: self.heating_price, cooling: self.cooling_price, hours: self.hours })
    }
}

/// A time field in SI.
fn time(field: &'static str, value: &QuantityValue) -> Result<f64, CompareError> {
    value.to_si(Dimension::TIME).map_err(|e| CompareError::Field { field, why: format!("{value}: {e}") })
}

/// Compare the schemes `plants` (each at its design point) as `request` asks.
///
/// # Errors
/// As [`compare`]; a bad field of the request first.
pub fn study(plants: &[Plant], request: &CompareRequest) -> Result<Comparison, CompareError> {
    compare(plants, &request.settings()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_request_takes_the_clis_defaults_and_names_a_bad_field() {
        let r: CompareRequest = serde_json::from_str(r#"{"disturbances": ["feed.F"], "outputs": ["x@MW"]}"#).unwrap();
        let s = r.settings().unwrap();
        assert_eq!((s.dynamic.measurement.dead_time, s.prices, s.file_tuning), (60.0, Prices::default(), false));
        assert_eq!(s.outputs, ["x"]);
        let bad = CompareRequest { hours: 9000.0, ..r.clone() };
        assert!(bad.settings().unwrap_err().to_string().starts_with("hours 9000: "));
        let bad = CompareRequest { duration: Some("2 kg".into()), ..r };
        let e = bad.settings().unwrap_err();
        assert_eq!(e.field(), Some("duration"));
        let e = serde_json::from_str::<CompareRequest>(r#"{"disturbances": [], "outputs": [], "tunning": "file"}"#);
        assert!(e.unwrap_err().to_string().contains("unknown field `tunning`"));
    }
}
