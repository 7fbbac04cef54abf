//! The energy a scheme uses at its steady state: every duty of its units, read from the units'
//! own variables and inputs, classed as heating (a utility in), cooling (a utility out) or
//! recovered (heat moved between process streams by an exchanger). Each unit declares its duties
//! ([`plantwide_model::UnitModel::duties`]); those of the library's units:
//!
//! - `heater` (heater or cooler): its duty `Q` [W], heating when positive, cooling when negative;
//! - `cstr`: `Q` [W], the heat into the reactor (a jacket's is negative: cooling);
//! - `heat_exchanger`: `Q` [W], recovered;
//! - `column` (rigorous): the reboiler duty (input `reboiler_duty`, or the controller output
//!   driving it) and an auxiliary reboiler's (`auxiliary_reboiler_duty`) heating, the condenser
//!   duty `Qc` [W] cooling; a steam reboiler's `steam_flow` [kg/s] and a simple column's `boilup`
//!   [mol/s] have no duty in the model and are listed as other utilities;
//! - `condenser_reboiler`: its duty `op` [W] recovered — and not counted again as the driven
//!   reboiler's heating or the driven condenser's cooling (that condenser's `Qc` less the coupling
//!   duty is its auxiliary condenser's, cooling).

use plantwide_flowsheet::{Plant, VarPath};
use serde::Serialize;

/// One duty.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Duty {
    /// Unit and variable (`trim.Q`, `column.Qc`, `column.reboiler_duty`).
    pub path: String,
    /// `heating`, `cooling` or `recovered`.
    pub kind: &'static str,
    /// Magnitude \[W\].
    pub duty: f64,
}

/// A utility the model carries without a duty.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OtherUtility {
    /// Input path (`column.boilup`, `column.steam_flow`).
    pub path: String,
    /// Its value (SI).
    pub value: f64,
    /// Its SI unit.
    pub unit: String,
}

/// The energy use of a scheme.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Energy {
    /// Σ heating duties \[W\].
    pub heating: f64,
    /// Σ cooling duties \[W\].
    pub cooling: f64,
    /// Σ heat recovered between process streams \[W\].
    pub recovered: f64,
    /// Every duty.
    pub duties: Vec<Duty>,
    /// Utilities without a duty in the model.
    pub other: Vec<OtherUtility>,
}

/// The value of input `path` at the steady state: a free input's value, or the controller output
/// driving it.
fn input_value(plant: &Plant, x: &[f64], u: &[f64], path: &VarPath) -> Option<f64> {
    let i = plant.input(path)?;
    Some(plant.inputs()[i].driven_by.map_or(u[i], |v| x[v]))
}

/// Whether input `path` is driven by a unit that moves heat between process streams (a
/// condenser–reboiler): heat recovered, not a utility.
fn driven_by_coupling(plant: &Plant, path: &VarPath) -> bool {
    let driver = plant.input(path).and_then(|i| plant.inputs()[i].driven_by);
    driver.is_some_and(|v| plant.blocks()[plant.vars()[v].block].unit.moves_process_heat())
}

/// The energy use of `plant` at steady state `(x, u)`: each unit's declared duties
/// ([`plantwide_model::UnitModel::duties`]) and utility flows, in the order of its blocks.
pub fn energy(plant: &Plant, x: &[f64], u: &[f64]) -> Energy {
    let mut duties = Vec::new();
    let mut other = Vec::new();
    for b in plant.blocks() {
        for d in &b.unit.duties() {
            if let Some(duty) = booked(plant, x, u, &b.name, d) {
                duties.push(duty);
            }
        }
        for f in b.unit.utility_flows() {
            let path = VarPath::new(&b.name, f.input);
            if let Some(value) = input_value(plant, x, u, &path) {
                other.push(OtherUtility { path: path.into(), value, unit: f.unit.into() });
            }
        }
    }
    let total = |kind: &str| duties.iter().filter(|d| d.kind == kind).map(|d| d.duty).sum::<f64>() + 0.0;
    Energy { heating: total("heating"), cooling: total("cooling"), recovered: total("recovered"), duties, other }
}

/// Duty `d` of unit `unit` as booked at `(x, u)`; `None` where it is absent (a variable or input
/// this unit's configuration does not have, an input driven by a coupling) or zero.
fn booked(plant: &Plant, x: &[f64], u: &[f64], unit: &str, d: &plantwide_model::Duty) -> Option<Duty> {
    use plantwide_model::{Booking, DutySource};
    let (path, value) = match &d.source {
        DutySource::Var(name) => {
            let path = VarPath::new(unit, name);
            let value = plant.var(&path).map(|v| x[v]);
            (path, value)
        }
        DutySource::Input(name) => {
            let path = VarPath::new(unit, name);
            let value = input_value(plant, x, u, &path).filter(|_| !driven_by_coupling(plant, &path));
            (path, value)
        }
    };
    let value = value?;
    let (value, positive, negative) = match d.booking {
        Booking::Utility => (value, "heating", "cooling"),
        Booking::Recovered => (value, "recovered", "recovered"),
        Booking::Removed { coupled } => {
            let input = VarPath::new(unit, coupled);
            let coupled = match driven_by_coupling(plant, &input) {
                true => input_value(plant, x, u, &input).unwrap_or(0.0),
                false => 0.0,
            };
            (coupled - value, "heating", "cooling")
        }
    };
    (value != 0.0).then(|| Duty {
        path: path.into(),
        kind: if value > 0.0 { positive } else { negative },
        duty: value.abs(),
    })
}

/// Utility prices and the hours a year the plant runs, to cost the duties of [`Energy`].
///
/// The defaults are the prices of the textbook design studies the comparisons follow: low-pressure
/// steam at 7.78 $/GJ (Luyben, *Distillation Design and Control Using Aspen Simulation*, 2nd ed.,
/// 2013, and his plantwide design papers) for every heating duty, cooling water at 0.354 $/GJ
/// (Turton et al., *Analysis, Synthesis and Design of Chemical Processes*, 4th ed., 2012) for
/// every cooling duty, and continuous operation (8760 h/yr). Heat recovered between process
/// streams costs nothing here: the exchanger's capital is not in the comparison.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
pub struct Prices {
    /// Heating utility \[$/GJ\].
    pub heating: f64,
    /// Cooling utility \[$/GJ\].
    pub cooling: f64,
    /// Operating hours a year \[h/yr\].
    pub hours: f64,
}

impl Default for Prices {
    fn default() -> Self {
        Prices { heating: 7.78, cooling: 0.354, hours: 8760.0 }
    }
}

/// The yearly cost of a scheme's utilities.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UtilityCost {
    /// Heating \[$/yr\]: Σ heating duties × the heating price × the hours.
    pub heating: f64,
    /// Cooling \[$/yr\].
    pub cooling: f64,
    /// Heating and cooling \[$/yr\].
    pub total: f64,
    /// Utilities the model carries without a duty (a simple column's boilup, a steam flow), not
    /// costed: a comparison between schemes that have them is of the costed part only.
    pub uncosted: Vec<String>,
}

/// Seconds in an hour times joules in a gigajoule: `W · h → GJ`.
const GJ_PER_W_HOUR: f64 = 3600.0 / 1e9;

/// The yearly utility cost of `e` at `prices`.
pub fn cost(e: &Energy, prices: &Prices) -> UtilityCost {
    let per_year = |duty: f64, price: f64| duty * GJ_PER_W_HOUR * prices.hours * price;
    let (heating, cooling) = (per_year(e.heating, prices.heating), per_year(e.cooling, prices.cooling));
    UtilityCost {
        heating,
        cooling,
        total: heating + cooling,
        uncosted: e.other.iter().map(|o| o.path.clone()).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 1 MW of steam for a year at 7.78 $/GJ: 1e6 W × 3.1536e7 s = 31 536 GJ, 245 350.08 $;
    /// 1 MW of cooling water at 0.354 $/GJ: 11 163.744 $.
    #[test]
    fn a_megawatt_for_a_year_costs_its_gigajoules_at_the_price() {
        let e = Energy { heating: 1e6, cooling: 1e6, recovered: 5e5, duties: Vec::new(), other: Vec::new() };
        let c = cost(&e, &Prices::default());
        assert!((c.heating - 245_350.08).abs() < 1e-6, "{}", c.heating);
        assert!((c.cooling - 11_163.744).abs() < 1e-6, "{}", c.cooling);
        assert_eq!(c.total, c.heating + c.cooling);
    }
}
