//! A screening as a user asks for it: [`ScreenRequest`], read from the same unit-bearing JSON as
//! a flowsheet file, and [`study`], the one call every face makes: a column's inventory
//! configurations (`column`) or the pairings of CVs to MVs (`cvs`, `mvs`). Messages name the
//! request's fields (`outputs`, `` `mvs` ``); a face maps them to its own names
//! ([`ScreenRequest::FIELDS`]).
//!
//! ```json
//! {"column": "column", "outputs": ["distillate.x[light]", "bottoms.x[light]"], "steady_only": true}
//! {"cvs": ["column.T[8]@degC", "bottoms.x[light]"], "mvs": ["column.reflux", "column.boilup"],
//!  "disturbances": ["feed_source.F=±10%"]}
//! ```

use plantwide_analysis::shard::Share;
use plantwide_flowsheet::Plant;
use plantwide_units::{Dimension, QuantityValue};
use serde::{Deserialize, Serialize};

use super::ScreenError;
use super::column::{ColumnDynamic, ColumnRequest, ColumnScreen, screen_column_with};
use super::pairings::{DynamicResult, DynamicSettings, PairingRequest, PairingScreen, Watch, screen_pairings};
use crate::disturbance::Disturbance;
use crate::tune::loops::Measurement;

/// What `plantwide screen` and `Plant.screen` ask: `column`'s configurations, or the pairings of
/// `cvs` to `mvs`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScreenRequest {
    /// The column whose inventory configurations to screen (LV, DV, LB, DB, (L/D)V, L(V/B),
    /// (L/D)(V/B)); give this or `cvs` and `mvs`.
    #[serde(default)]
    pub column: Option<String>,
    /// The column's two qualities, top then bottom (variable paths).
    #[serde(default)]
    pub outputs: Vec<String>,
    /// The column's configurations ranked by their steady-state measures alone: no dynamic check.
    #[serde(default)]
    pub steady_only: bool,
    /// Keep each configuration's flowsheet with its quality loops as tuned by the dynamic check,
    /// and each run's scenario, in the result (for `plantwide run`).
    #[serde(default)]
    pub keep_flowsheets: bool,
    /// The largest deviation allowed of each quality, top then bottom, in its unit: the scale of
    /// the gains and IAEs (default: a mole fraction's distance to 0 or 1).
    #[serde(default)]
    pub allowed_deviation: Vec<QuantityValue>,
    /// Controlled variables to pair (variable paths, each with an optional display unit).
    #[serde(default)]
    pub cvs: Vec<String>,
    /// Manipulated variables (input paths).
    #[serde(default)]
    pub mvs: Vec<String>,
    /// Throughput-manipulator candidates, each one of the MVs.
    #[serde(default)]
    pub throughput: Vec<String>,
    /// Disturbances: `PATH` (+10 %), `PATH=±x%` or an amount with its unit; a column's default is
    /// each upstream feed's rate ±10 % and its composition ± a tenth of its room.
    #[serde(default)]
    pub disturbances: Vec<String>,
    /// Uncontrolled variables that must stay in a band over ± each disturbance with the CVs held:
    /// `PATH=LOW:HIGH`, the ends in the variable's unit.
    #[serde(default)]
    pub watch: Vec<String>,
    /// How many steady-state survivors of the pairings to test dynamically (default 4).
    #[serde(default = "four")]
    pub candidates: usize,
    /// Measurement dead time of every loop in the dynamic test's tuning (default 1 min).
    #[serde(default = "one_minute")]
    pub measurement_dead_time: QuantityValue,
    /// Length of each dynamic run (default: 20 × the longest reset time of the tuned loops).
    #[serde(default)]
    pub duration: Option<QuantityValue>,
    /// A model predictive controller to judge beside the PI candidates on the same runs: one
    /// `"type": "mpc"` controller description on the CVs and some of the MVs.
    #[serde(default)]
    pub mpc: Option<crate::screen::pairings::mpc::ScreenMpc>,
}

fn four() -> usize {
    4
}

fn one_minute() -> QuantityValue {
    QuantityValue::Text("1 min".into())
}

/// The answer of a [`ScreenRequest`].
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Screened {
    /// A column's configurations.
    Column(Box<ColumnScreen>),
    /// The pairings.
    Pairings(Box<PairingScreen>),
}

impl Screened {
    /// The parts that have no answer, each with its reason.
    pub fn failed(&self) -> &[String] {
        match self {
            Screened::Column(s) => &s.failed,
            Screened::Pairings(s) => &s.failed,
        }
    }
}

impl ScreenRequest {
    /// The fields a message names in backticks (`` one of the `mvs` ``), for a face to map to its
    /// own names; a field a message only starts with is [`ScreenError::field`]'s. (Kept to the
    /// fields messages name: a unit called `column` is no field.)
    pub const FIELDS: &'static [&'static str] = &["cvs", "mvs", "throughput", "disturbances", "steady_only", "mpc"];

    /// The column screening asked for, in SI.
    ///
    /// # Errors
    /// [`ScreenError::Field`] naming a field that does not parse; [`ScreenError::BadDisturbance`].
    pub fn column_request(&self, plant: &Plant, column: &str) -> Result<ColumnRequest, ScreenError> {
        let allowed = match self.allowed_deviation.as_slice() {
            [] => None,
            [top, bottom] => Some([self.allowed(plant, 0, top)?, self.allowed(plant, 1, bottom)?]),
            more => {
                let why = format!("give two deviations, top then bottom quality; got {}", more.len());
                return Err(ScreenError::Field { field: "allowed_deviation", why });
            }
        };
        let dynamic = match self.steady_only {
            true => None,
            false => Some(ColumnDynamic {
                disturbances: self.disturbances()?,
                duration: self.duration()?,
                measurement: self.measurement()?,
                keep_flowsheets: self.keep_flowsheets,
            }),
        };
        Ok(ColumnRequest { column: column.to_string(), outputs: self.outputs.clone(), allowed, dynamic })
    }

    /// The pairing screening asked for, in SI, running `share` of its dynamic tests.
    ///
    /// # Errors
    /// [`ScreenError::Field`] naming a field that does not parse; [`ScreenError::BadDisturbance`].
    pub fn pairing_request(&self, plant: &Plant, share: Share<DynamicResult>) -> Result<PairingRequest, ScreenError> {
        Ok(PairingRequest {
            cvs: self.cv_paths(),
            mvs: self.mvs.clone(),
            throughput: self.throughput.clone(),
            disturbances: self.disturbances()?,
            watch: self.watch.iter().map(|w| watch(plant, w)).collect::<Result<_, _>>()?,
            dynamic: DynamicSettings {
                candidates: self.candidates,
                duration: self.duration()?,
                measurement: self.measurement()?,
            },
            record: Vec::new(),
            mpc: self.mpc.clone(),
            share,
        })
    }

    /// `cvs` without their display units.
    pub fn cv_paths(&self) -> Vec<String> {
        self.cvs.iter().map(|c| plantwide_analysis::select::split_unit(c).0.to_string()).collect()
    }

    fn disturbances(&self) -> Result<Vec<Disturbance>, ScreenError> {
        let parsed = self.disturbances.iter().map(|d| d.parse::<Disturbance>());
        parsed.collect::<Result<_, _>>().map_err(|e| ScreenError::BadDisturbance(Box::new(e)))
    }

    fn duration(&self) -> Result<Option<f64>, ScreenError> {
        self.duration.as_ref().map(|d| time("duration", d)).transpose()
    }

    fn measurement(&self) -> Result<Measurement, ScreenError> {
        Ok(Measurement { dead_time: time("measurement_dead_time", &self.measurement_dead_time)?, lag: 0.0 })
    }

    /// Allowed deviation `value` of quality `k`, in the quality's unit (SI when bare).
    fn allowed(&self, plant: &Plant, k: usize, value: &QuantityValue) -> Result<f64, ScreenError> {
        let dim = self
            .outputs
            .get(k)
            .and_then(|o| plant.var(o))
            .map_or(Dimension::DIMENSIONLESS, |v| plant.vars()[v].spec.dim);
        value.to_si(dim).map_err(|e| ScreenError::Field { field: "allowed_deviation", why: format!("{value}: {e}") })
    }
}

/// Screen `plant` (at its design point) as `request` asks, running `share` of a pairing screen's
/// dynamic tests.
///
/// # Errors
/// As [`screen_column_with`] and [`screen_pairings`]; a bad field of the request first.
pub fn study(plant: &Plant, request: &ScreenRequest, share: Share<DynamicResult>) -> Result<Screened, ScreenError> {
    match (&request.column, request.cvs.is_empty()) {
        (Some(column), true) => {
            let r = request.column_request(plant, column)?;
            Ok(Screened::Column(Box::new(screen_column_with(plant, &r)?)))
        }
        (None, false) => {
            let r = request.pairing_request(plant, share)?;
            Ok(Screened::Pairings(Box::new(screen_pairings(plant, &r)?)))
        }
        (Some(_), false) => {
            Err(ScreenError::Field { field: "cvs", why: "is given with a column: screen a column or pairings".into() })
        }
        (None, true) => Err(ScreenError::Field {
            field: "column",
            why: "is missing: give the column to screen, or the cvs and mvs to pair".into(),
        }),
    }
}

/// A time field in SI.
fn time(field: &'static str, value: &QuantityValue) -> Result<f64, ScreenError> {
    value.to_si(Dimension::TIME).map_err(|e| ScreenError::Field { field, why: format!("{value}: {e}") })
}

/// `PATH=LOW:HIGH`, the ends in the variable's unit (SI when bare).
fn watch(plant: &Plant, text: &str) -> Result<Watch, ScreenError> {
    let bad = |why: String| ScreenError::Field { field: "watch", why: format!("{text}: {why}") };
    let shape = || bad("expected PATH=LOW:HIGH, e.g. column1.x[1][B]=0:0.02".into());
    let (path, band) = text.split_once('=').ok_or_else(shape)?;
    let (lo, hi) = band.split_once(':').ok_or_else(shape)?;
    let Some(v) = plant.var(path.trim()) else { return Err(bad(format!("no variable `{}`", path.trim()))) };
    let dim = plant.vars()[v].spec.dim;
    let end = |s: &str| plantwide_units::parse_quantity_as(s.trim(), dim).map_err(|e| bad(e.to_string()));
    let (low, high) = (end(lo)?, end(hi)?);
    if low.is_nan() || high.is_nan() || low >= high {
        return Err(bad("the band must go from low to high".into()));
    }
    Ok(Watch { path: path.trim().to_string(), low, high })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_request_takes_the_clis_defaults() {
        let r: ScreenRequest = serde_json::from_str(r#"{"cvs": ["a@degC"], "mvs": ["b"]}"#).unwrap();
        assert_eq!((r.candidates, r.cv_paths()), (4, vec!["a".to_string()]));
        assert_eq!(time("measurement_dead_time", &r.measurement_dead_time).unwrap(), 60.0);
        let e = time("duration", &"3 kg".into()).unwrap_err();
        assert_eq!(e.field(), Some("duration"));
        assert!(e.to_string().starts_with("duration 3 kg: "), "{e}");
        let e = serde_json::from_str::<ScreenRequest>(r#"{"cvs": [], "candidate": 2}"#).unwrap_err();
        assert!(e.to_string().contains("unknown field `candidate`"));
    }
}
