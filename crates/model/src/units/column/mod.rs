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
//! `bottoms`, each side draw's flow, and `boilup` (simple) or `reboiler_duty` / `steam_flow`
//! (rigorous, plus `condenser_duty` or `coolant_flow` when the condenser is duty-specified or
//! water-cooled).
//!
//! Fields only one model uses are optional here; building with the other model reports each of
//! them by name (simple: `tray_holdup`, `tau_l`, `boilup`, `lambda`, `feeds[k].q`,
//! `feeds[k].nominal_flow`; rigorous: `rigorous`, `side_draws[k].phase` = `vapour`).

pub mod rigorous;
pub mod simple;

use crate::capability::{
    Booking, Duty, DutySource, FlowDecl, FlowLaw, FlowVia, InventoryFlows, InventoryPhase, MaterialFlows, Shape,
    UtilityFlow,
};
use plantwide_units::QuantityValue;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::{BuildCx, FieldError, InputSpec, LocalLayout, Scalar, UnitIo, UnitModel, VarSpec};

pub use rigorous::{RigorousColumn, RigorousConfig};
pub use simple::SimpleColumn;

/// A validated side draw.
#[derive(Debug, Clone)]
pub(crate) struct Draw {
    /// 0-based stage it is drawn from.
    pub(crate) stage: usize,
    /// Flow [mol/s] (the value of its input).
    pub(crate) flow: f64,
    /// Drawn from the vapour leaving the tray (else from its liquid).
    pub(crate) vapour: bool,
}

/// Validate the side draws of `c` (a column of `n` stages whose feeds use `feed_ports`): trays
/// 2 … N−1 only, port names unique among products, feeds and draws, flows non-negative. Returns the
/// draws and their port names; errors are recorded on `cx` with their field paths.
pub(crate) fn side_draws(
    c: &ColumnConfig,
    n: usize,
    feed_ports: &[String],
    cx: &mut BuildCx<'_>,
) -> (Vec<Draw>, Vec<String>) {
    let mut draws = Vec::new();
    let mut draw_ports: Vec<String> = Vec::new();
    for (k, d) in c.side_draws.iter().enumerate() {
        if d.stage < 2 || d.stage + 1 > n {
            cx.error(
                &format!("side_draws[{k}].stage"),
                format!("side draws come from trays 2 … {}; got {}", n.saturating_sub(1), d.stage),
            );
        }
        if ["distillate", "bottoms"].contains(&d.port.as_str())
            || feed_ports.contains(&d.port)
            || draw_ports.contains(&d.port)
        {
            cx.error(&format!("side_draws[{k}].port"), format!("port name `{}` is already used", d.port));
        }
        let flow = cx.non_negative(&format!("side_draws[{k}].flow"), &d.flow, plantwide_units::Dimension::MOLAR_FLOW);
        draws.push(Draw { stage: d.stage.saturating_sub(1), flow, vapour: d.phase == DrawPhase::Vapour });
        draw_ports.push(d.port.clone());
    }
    (draws, draw_ports)
}

/// Offsets of the variables within one stage's block, shared by both fidelities:
/// `[n_1 … n_c, x_1 … x_c, y_1 … y_c, T, M, L, V]`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StageIdx {
    pub(crate) nc: usize,
}

impl StageIdx {
    pub(crate) fn n(&self, j: usize) -> usize {
        j
    }
    pub(crate) fn x(&self, j: usize) -> usize {
        self.nc + j
    }
    pub(crate) fn y(&self, j: usize) -> usize {
        2 * self.nc + j
    }
    pub(crate) fn t(&self) -> usize {
        3 * self.nc
    }
    pub(crate) fn m(&self) -> usize {
        3 * self.nc + 1
    }
    pub(crate) fn l(&self) -> usize {
        3 * self.nc + 2
    }
    pub(crate) fn v(&self) -> usize {
        3 * self.nc + 3
    }
}

/// Fidelity of the column model.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ColumnModel {
    /// Constant molar overflow, linearized tray hydraulics, no energy balances.
    #[default]
    Simple,
    /// Energy balances, Murphree efficiency, Francis-weir hydraulics, tray pressure drop.
    Rigorous,
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
    /// Feed quality q (liquid fraction; 1 = saturated liquid); default from enthalpies (simple
    /// model only: the rigorous model takes the feed's enthalpy from the stream).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub q: Option<f64>,
    /// Nominal feed flow for the tray hydraulics (default: nominal D + B when there is one feed;
    /// simple model only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nominal_flow: Option<QuantityValue>,
}

fn default_feed_port() -> String {
    "feed".into()
}

/// The phase a side draw takes from its tray.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DrawPhase {
    /// Part of the liquid leaving the tray (composition x, enthalpy h_L).
    #[default]
    Liquid,
    /// Part of the vapour leaving the tray (composition y, enthalpy h_V; rigorous model only).
    Vapour,
}

/// A side draw.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SideDraw {
    /// Outlet port name (also the name of its flow input).
    pub port: String,
    /// Stage it is drawn from.
    pub stage: usize,
    /// Draw flow (e.g. `"0.1 kmol/min"`).
    pub flow: QuantityValue,
    /// Phase drawn: `liquid` (default) or `vapour` (rigorous model only).
    #[serde(default, skip_serializing_if = "is_liquid")]
    pub phase: DrawPhase,
}

fn is_liquid(p: &DrawPhase) -> bool {
    *p == DrawPhase::Liquid
}

/// Component holdups [mol] of a column: the `n[s][c]` variables, which start at internal variable
/// `stage_at(s)` of stage `s`, summed over its `n_stages` stages.
pub(crate) fn summed_holdups(
    io: &UnitIo<'_, f64>,
    n_stages: usize,
    nc: usize,
    stage_at: impl Fn(usize) -> usize,
) -> Vec<f64> {
    let mut n = vec![0.0; nc];
    for s in 0..n_stages {
        io.vars(stage_at(s), nc).iter().zip(&mut n).for_each(|(v, t)| *t += v);
    }
    n
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
    /// Side draws (default none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub side_draws: Vec<SideDraw>,
    /// Column pressure (default 1 atm); for the rigorous model the top (condenser) pressure.
    #[serde(rename = "P", default, skip_serializing_if = "Option::is_none")]
    pub pressure: Option<QuantityValue>,
    /// Nominal liquid holdup of a tray (e.g. `"0.5 kmol"`; simple model only, required).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tray_holdup: Option<QuantityValue>,
    /// Nominal liquid holdup of the condenser / reflux drum.
    pub condenser_holdup: QuantityValue,
    /// Nominal liquid holdup of the reboiler / sump.
    pub reboiler_holdup: QuantityValue,
    /// Liquid hydraulic time constant τ_L of a tray (e.g. `"0.063 min"`; simple model only, required).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tau_l: Option<QuantityValue>,
    /// Effect of vapour flow on liquid flow λ [-] (simple model only; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lambda: Option<f64>,
    /// Reflux flow L.
    pub reflux: QuantityValue,
    /// Boilup V (simple model only, required).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub boilup: Option<QuantityValue>,
    /// Distillate flow D.
    pub distillate: QuantityValue,
    /// Bottoms flow B.
    pub bottoms: QuantityValue,
    /// Rigorous-model data: duties, efficiency, tray geometry (rigorous model only, required).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rigorous: Option<Box<RigorousConfig>>,
}

impl crate::registry::UnitConfig for ColumnConfig {
    fn ports() -> &'static str {
        "inlets named by `feeds[k].port`; outlets `distillate`, `bottoms` and one named by each `side_draws[k].port`"
    }
    /// The reflux drum (stage N: reflux `L[N]` and distillate leave it) and the base (stage 1:
    /// bottoms `L[1]` and boilup `V[1]` leave it).
    fn inventories(&self) -> Vec<crate::registry::Inventory> {
        let n = self.stages;
        vec![
            crate::registry::Inventory {
                name: "drum",
                stage: n,
                leaving: vec![format!("L[{n}]"), "distillate".into()],
            },
            crate::registry::Inventory { name: "sump", stage: 1, leaving: vec!["L[1]".into(), "V[1]".into()] },
        ]
    }
}

impl ColumnConfig {
    /// Report every field the chosen model needs but lacks, or does not use but has.
    fn check_model_fields(&self, cx: &mut BuildCx<'_>) {
        let simple = self.model == ColumnModel::Simple;
        let (this, other) = if simple { ("simple", "rigorous") } else { ("rigorous", "simple") };
        // (field, given, belongs to the simple model, example when its model requires it)
        let mut fields: Vec<(String, bool, bool, Option<&str>)> = vec![
            ("tray_holdup".into(), self.tray_holdup.is_some(), true, Some("\"0.5 kmol\"")),
            ("tau_l".into(), self.tau_l.is_some(), true, Some("\"0.063 min\"")),
            ("boilup".into(), self.boilup.is_some(), true, Some("\"3.2 kmol/min\"")),
            ("lambda".into(), self.lambda.is_some(), true, None),
            ("rigorous".into(), self.rigorous.is_some(), false, Some(rigorous::EXAMPLE)),
        ];
        for (k, f) in self.feeds.iter().enumerate() {
            fields.push((format!("feeds[{k}].q"), f.q.is_some(), true, None));
            fields.push((format!("feeds[{k}].nominal_flow"), f.nominal_flow.is_some(), true, None));
        }
        for (k, d) in self.side_draws.iter().enumerate() {
            fields.push((format!("side_draws[{k}].phase"), d.phase == DrawPhase::Vapour, false, None));
        }
        for (field, given, of_simple, example) in fields {
            if of_simple != simple && given {
                cx.error(&field, format!("the {this} model does not use `{field}` (a {other}-model field): remove it"));
            } else if let (false, Some(e)) = (given, example.filter(|_| of_simple == simple)) {
                cx.error(&field, format!("the {this} model needs `{field}`, e.g. {e}"));
            }
        }
    }
}

/// A distillation column at the chosen fidelity.
#[derive(Debug, Clone)]
pub enum Column {
    /// Constant molar overflow.
    Simple(SimpleColumn),
    /// Energy balances, Murphree efficiency, Francis weir.
    Rigorous(RigorousColumn),
}

impl Column {
    /// Build from the flowsheet description.
    pub fn build(c: &ColumnConfig, mut cx: BuildCx<'_>, _links: ()) -> Result<Column, Vec<FieldError>> {
        if !cx.count("stages", c.stages, crate::limits::Limits::get().stages()) {
            return Err(cx.errors);
        }
        c.check_model_fields(&mut cx);
        match c.model {
            ColumnModel::Simple => SimpleColumn::build(c, cx).map(Column::Simple),
            ColumnModel::Rigorous => RigorousColumn::build(c, cx).map(Column::Rigorous),
        }
    }
}

/// A column's inventories and flow laws, from its stage count `n`, ports and input names:
/// - the drum (`M[n]`) is filled by the vapour the reboiler makes (its input `boilup`,
///   `reboiler_duty` or `steam_flow`) and drained by the reflux (input `reflux`) and the distillate
///   (input `distillate`);
/// - the sump (`M[1]`) is filled by the liquid the trays pass down — the reflux and the feeds, the
///   trays regulating themselves over their weirs — and drained by the boilup and the bottoms
///   (input `bottoms`);
/// - a vapour space (`gas`: the top pressure `P` is a variable) is filled by the boilup and
///   drained by condensation: the input `condenser_duty` or `coolant_flow`, else the condenser at
///   the drum's bubble point, which regulates the pressure itself.
///
/// Side draws leave trays, which regulate themselves; each is set by its input.
fn column_flows(n: usize, inlets: &[String], outlets: &[String], inputs: &[String], gas: bool) -> MaterialFlows {
    let has = |name: &str| inputs.iter().any(|i| i == name);
    let boilup = ["boilup", "reboiler_duty", "steam_flow"].into_iter().find(|b| has(b)).unwrap_or("boilup");
    let internal = |name: &'static str| FlowVia::Internal(name.into());
    let mut flows: Vec<FlowDecl> = outlets
        .iter()
        .map(|p| FlowDecl { via: FlowVia::Outlet(p.clone().into()), law: FlowLaw::Input(p.clone().into()) })
        .collect();
    flows.push(FlowDecl { via: internal("reflux"), law: FlowLaw::Input("reflux".into()) });
    flows.push(FlowDecl { via: internal(boilup), law: FlowLaw::Input(boilup.into()) });
    let mut sump_in = vec![internal("reflux")];
    sump_in.extend(inlets.iter().map(|p| FlowVia::Inlet(p.clone().into())));
    let mut inventories = vec![
        InventoryFlows {
            name: Some("drum"),
            phase: InventoryPhase::Liquid,
            measured: vec![format!("M[{n}]")],
            inflows: vec![internal(boilup)],
            outflows: vec![internal("reflux"), FlowVia::Outlet("distillate".into())],
        },
        InventoryFlows {
            name: Some("sump"),
            phase: InventoryPhase::Liquid,
            measured: vec!["M[1]".into()],
            inflows: sump_in,
            outflows: vec![internal(boilup), FlowVia::Outlet("bottoms".into())],
        },
    ];
    if gas {
        let condenser = ["condenser_duty", "coolant_flow"].into_iter().find(|c| has(c));
        let law = condenser.map_or(FlowLaw::Holdup { input: None }, |c| FlowLaw::Input(c.into()));
        flows.push(FlowDecl { via: internal("condensation"), law });
        inventories.push(InventoryFlows {
            name: Some("vapour"),
            phase: InventoryPhase::Gas,
            measured: vec!["P".into()],
            inflows: vec![internal(boilup)],
            outflows: vec![internal("condensation")],
        });
    }
    MaterialFlows { flows, inventories }
}

macro_rules! delegate {
    ($self:ident, $m:ident($($a:expr),*)) => {
        match $self {
            Column::Simple(c) => c.$m($($a),*),
            Column::Rigorous(c) => c.$m($($a),*),
        }
    };
}

impl UnitModel for Column {
    fn type_name(&self) -> &'static str {
        "column"
    }
    /// The reboilers' inputs (utilities unless a condenser–reboiler drives them) and the
    /// condenser's `Qc`, cooling less what a coupled `condenser_duty` gives another column.
    fn duties(&self) -> Vec<Duty> {
        vec![
            Duty { source: DutySource::Input("reboiler_duty".into()), booking: Booking::Utility },
            Duty { source: DutySource::Input("auxiliary_reboiler_duty".into()), booking: Booking::Utility },
            Duty { source: DutySource::Var("Qc".into()), booking: Booking::Removed { coupled: "condenser_duty" } },
        ]
    }
    /// A rigorous column's reboiler steam \[kg/s\], a simple column's boilup \[mol/s\].
    fn utility_flows(&self) -> &'static [UtilityFlow] {
        &[UtilityFlow { input: "steam_flow", unit: "kg/s" }, UtilityFlow { input: "boilup", unit: "mol/s" }]
    }
    fn shape(&self) -> Shape {
        Shape::Column
    }
    /// The reflux drum (stage N) and the sump (stage 1), and the vapour space of a rigorous column
    /// that has one (its pressure `P`): see [`column_flows`].
    fn material_flows(&self) -> MaterialFlows {
        let names: Vec<String> = self.inputs().into_iter().map(|i| i.name).collect();
        let gas = self.internal_vars().iter().any(|v| v.name == "P");
        column_flows(delegate!(self, n_stages()), &self.inlet_ports(), &self.outlet_ports(), &names, gas)
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
    fn explicit(&self, layout: &LocalLayout) -> Vec<usize> {
        delegate!(self, explicit(layout))
    }
    fn complete(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        delegate!(self, complete(io, own))
    }
    fn eval_kept(&self, io: &UnitIo<'_, f64>, own: &[f64], r: &mut [f64], skip: &[bool]) {
        delegate!(self, eval_kept(io, own, r, skip))
    }
    fn holdup(&self, io: &UnitIo<'_, f64>) -> Option<Vec<f64>> {
        delegate!(self, holdup(io))
    }
}
