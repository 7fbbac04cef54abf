//! Tray-by-tray distillation column with its condenser (reflux drum) and reboiler (sump) as stages
//! of the same unit, at two fidelity levels chosen in the flowsheet (`"model"`): `simple`
//! (constant molar overflow, [`simple`]) and `rigorous` (energy balances, Murphree efficiency,
//! Francis weir, [`rigorous`]).
//!
//! **Stage numbering** (as Skogestad's column A): stage 1 is the reboiler, stages 2 … N−1 are the
//! trays counted from the bottom, stage N is the condenser. Paths use these numbers:
//! `column.x[21][light]`, `column.T[1]`, `column.M[41]`.
//!
//! Ports: one inlet per feed (`feeds[k].port`, default `feed`), outlets `distillate`, `bottoms` and
//! one per side draw. Manipulated inputs declared by both models: `reflux`, `distillate`,
//! `bottoms`, each side draw's flow, and `boilup` (simple) or `reboiler_duty` (rigorous).

pub mod simple;

use plantwide_units::QuantityValue;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::{BuildCx, FieldError, InputSpec, LocalLayout, Scalar, UnitIo, UnitModel, VarSpec};

pub use simple::SimpleColumn;

/// Fidelity of the column model.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ColumnModel {
    /// Constant molar overflow, linearized tray hydraulics, no energy balances.
    #[default]
    Simple,
}

/// A feed to the column.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ColumnFeed {
    /// Inlet port name (default `feed`).
    #[serde(default = "default_feed_port")]
    pub port: String,
    /// Stage the feed enters (1 = reboiler, N = condenser).
    pub stage: usize,
    /// Feed quality q (liquid fraction; 1 = saturated liquid); default from enthalpies.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub q: Option<f64>,
    /// Nominal feed flow for the tray hydraulics (default: nominal D + B when there is one feed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nominal_flow: Option<QuantityValue>,
}

fn default_feed_port() -> String {
    "feed".into()
}

/// A liquid side draw.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SideDraw {
    /// Outlet port name (also the name of its flow input).
    pub port: String,
    /// Stage it is drawn from.
    pub stage: usize,
    /// Draw flow (e.g. `"0.1 kmol/min"`).
    pub flow: QuantityValue,
}

/// Flowsheet description of a column.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ColumnConfig {
    /// Fidelity (default `simple`).
    #[serde(default)]
    pub model: ColumnModel,
    /// Number of stages N including reboiler (stage 1) and condenser (stage N); ≥ 3.
    pub stages: usize,
    /// Feeds.
    pub feeds: Vec<ColumnFeed>,
    /// Liquid side draws (default none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub side_draws: Vec<SideDraw>,
    /// Column pressure (default 1 atm).
    #[serde(rename = "P", default, skip_serializing_if = "Option::is_none")]
    pub pressure: Option<QuantityValue>,
    /// Nominal liquid holdup of a tray (e.g. `"0.5 kmol"`).
    pub tray_holdup: QuantityValue,
    /// Nominal liquid holdup of the condenser / reflux drum.
    pub condenser_holdup: QuantityValue,
    /// Nominal liquid holdup of the reboiler / sump.
    pub reboiler_holdup: QuantityValue,
    /// Liquid hydraulic time constant τ_L of a tray (e.g. `"0.063 min"`).
    pub tau_l: QuantityValue,
    /// Effect of vapour flow on liquid flow λ [-] (default 0).
    #[serde(default)]
    pub lambda: f64,
    /// Reflux flow L.
    pub reflux: QuantityValue,
    /// Boilup V.
    pub boilup: QuantityValue,
    /// Distillate flow D.
    pub distillate: QuantityValue,
    /// Bottoms flow B.
    pub bottoms: QuantityValue,
}


/// A distillation column at the chosen fidelity.
#[derive(Debug, Clone)]
pub enum Column {
    /// Constant molar overflow.
    Simple(SimpleColumn),
}

impl Column {
    /// Build from the flowsheet description.
    pub fn build(c: &ColumnConfig, cx: BuildCx<'_>, _links: ()) -> Result<Column, Vec<FieldError>> {
        match c.model {
            ColumnModel::Simple => SimpleColumn::build(c, cx).map(Column::Simple),
        }
    }
}

macro_rules! delegate {
    ($self:ident, $m:ident($($a:expr),*)) => {
        match $self {
            Column::Simple(c) => c.$m($($a),*),
        }
    };
}

impl UnitModel for Column {
    fn type_name(&self) -> &'static str {
        "column"
    }
    fn inlet_ports(&self) -> Vec<String> {
        delegate!(self, inlet_ports())
    }
    fn outlet_ports(&self) -> Vec<String> {
        delegate!(self, outlet_ports())
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        delegate!(self, internal_vars())
    }
    fn inputs(&self) -> Vec<InputSpec> {
        delegate!(self, inputs())
    }
    fn extra_equations(&self) -> isize {
        delegate!(self, extra_equations())
    }
    fn pattern(&self, layout: &LocalLayout) -> Option<Vec<(usize, usize)>> {
        delegate!(self, pattern(layout))
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        delegate!(self, eval(io, r))
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        delegate!(self, guess(io, own))
    }
}
