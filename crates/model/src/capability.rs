//! What a unit declares of itself to the layers above the equations, so that none of them
//! recognises a unit by its type name: the duties it books ([`Duty`]), its place at the plant's
//! boundary ([`Boundary`]), how it is drawn ([`Shape`]) and the material it holds with the flows
//! that change it ([`MaterialFlows`]). Each is a [`crate::UnitModel`] method
//! with a default; `ARCHITECTURE.md` lists them with what the default means.

use std::borrow::Cow;

use serde::Serialize;

/// Where a unit stands at the plant's boundary. The steady-state certificate balances the
/// plant's sources against its sinks and every interior unit on its own; the dynamic
/// conservation check integrates `Σ sources − Σ sinks` against the holdups.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Boundary {
    /// Inside the plant: what flows in flows out or is held (the default).
    Interior,
    /// Material enters the plant here (a feed).
    Source,
    /// Material leaves the plant here (a product).
    Sink,
}

/// Where a duty's value is read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DutySource {
    /// An own variable of the unit, by local name (`"Q"`; a name from the file for an `equations`
    /// unit).
    Var(Cow<'static, str>),
    /// An input of the unit, by local name (`"reboiler_duty"`): its value where it is free, the
    /// output of the controller that drives it otherwise.
    Input(Cow<'static, str>),
}

/// How a duty \[W\] is booked in an energy balance of utilities.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Booking {
    /// A utility: heating when positive, cooling when negative. An input driven by a unit that
    /// moves heat between process streams ([`crate::UnitModel::moves_process_heat`]) is not one
    /// and is left out.
    Utility,
    /// Heat removed when positive (a condenser's `Qc`), booked as `coupled − Qc`: cooling, less
    /// the part of it the input `coupled` takes to another process stream when a unit that moves
    /// process heat drives that input.
    Removed {
        /// The input that carries the heat to a process stream when coupled.
        coupled: &'static str,
    },
    /// Heat moved between two process streams (an exchanger), either sign.
    Recovered,
}

/// A duty the unit books in `compare`'s energy use.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Duty {
    /// Where its value is read.
    pub source: DutySource,
    /// How it is booked.
    pub booking: Booking,
}

/// A utility the unit uses that is a flow, not a duty (steam in kg/s, a boilup in mol/s): the
/// input's local name and the unit its value is reported in (SI).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UtilityFlow {
    /// The input's local name.
    pub input: &'static str,
    /// Its SI unit, as reported.
    pub unit: &'static str,
}

/// How the browser simulator draws a unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// A box (the default).
    Block,
    /// A column: two cells tall, with its stages (whose temperatures `T[1]`, `T[2]`, … sensor
    /// selection reads).
    Column,
    /// A vessel holding a liquid level (a tank, a drum, a reactor).
    Vessel,
    /// An arrow into the plant (a feed).
    Source,
    /// An arrow out of the plant (a product).
    Sink,
}

/// Where a flow into or out of an inventory passes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FlowVia {
    /// The stream at the unit's inlet port of this name.
    Inlet(Cow<'static, str>),
    /// The stream at the unit's outlet port of this name.
    Outlet(Cow<'static, str>),
    /// A flow inside the unit (a column's reflux and boilup, the condensation in its condenser),
    /// named by the input that sets it (`condensation` where none does).
    Internal(Cow<'static, str>),
}

/// What sets the rate of a flow ([`FlowVia`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FlowLaw {
    /// An input of the unit, by local name: a feed's `F`, a pumped outflow's `outflow`, a
    /// column's `distillate`. A controller that drives the input moves the flow; a free input
    /// fixes it.
    Input(Cow<'static, str>),
    /// The holdup the flow leaves: a valve under the liquid's head, a condenser at the vapour's
    /// pressure. The inventory regulates itself; `input` (a valve's `opening`) moves the flow
    /// further where there is one.
    Holdup {
        /// The input that moves the flow besides the holdup, if any.
        input: Option<Cow<'static, str>>,
    },
    /// The holdup of the unit upstream of this (inlet) port: a valve that sets its inlet flow from
    /// the pressure of the vessel it drains. That vessel regulates itself; `input` moves the flow.
    UpstreamHoldup {
        /// The input that moves the flow besides the holdup, if any.
        input: Option<Cow<'static, str>>,
    },
    /// The unit's other balances: a flash drum's vapour, which its energy balance makes. Neither
    /// an input nor the holdup sets it directly.
    Balance,
}

/// A flow of a unit with the law that sets it. A port a unit declares nothing for passes what
/// enters the unit (a mixer's outlet, a splitter's shares of its inlet) or is set at its other end
/// (a vessel's outflow a downstream valve sets).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FlowDecl {
    /// The flow.
    pub via: FlowVia,
    /// What sets it.
    pub law: FlowLaw,
}

/// The phase an inventory holds: a liquid's level or holdup, a gas's pressure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InventoryPhase {
    /// A liquid holdup (measured by a level or an amount).
    Liquid,
    /// A gas holdup (measured by a pressure).
    Gas,
}

/// A material inventory a unit holds, with the flows that fill and drain it: the data of the
/// consistency check of inventory control (Aske & Skogestad 2009).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InventoryFlows {
    /// Its name after the unit's (`drum` is `COL.drum`); `None` for the unit's single inventory.
    pub name: Option<&'static str>,
    /// Its phase.
    pub phase: InventoryPhase,
    /// The unit's variables (local names) that measure it: a controller reading one of them
    /// controls it (`level`, `M`, `V` of a vessel; `M[32]` of a column's drum; `P` of a gas).
    pub measured: Vec<String>,
    /// The flows that fill it.
    pub inflows: Vec<FlowVia>,
    /// The flows that drain it.
    pub outflows: Vec<FlowVia>,
}

/// The inventories a unit holds and the laws of its flows (default: no holdup, no law: every
/// outlet passes what enters).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct MaterialFlows {
    /// The laws of the flows the unit sets or shares.
    pub flows: Vec<FlowDecl>,
    /// The inventories it holds.
    pub inventories: Vec<InventoryFlows>,
}

impl MaterialFlows {
    /// A unit that holds nothing and sets the flow at `via` by `law`.
    pub fn one(via: FlowVia, law: FlowLaw) -> MaterialFlows {
        MaterialFlows { flows: vec![FlowDecl { via, law }], inventories: Vec::new() }
    }

    /// A vessel's: one liquid inventory measured by `level`, `M` and `V`, filled by `inlets` and
    /// drained by `outlets`, each outlet with its law where the vessel sets it (`None`: the unit
    /// downstream does).
    pub fn vessel(inlets: &[&'static str], outlets: Vec<(&'static str, Option<FlowLaw>)>) -> MaterialFlows {
        let inventory = InventoryFlows {
            name: None,
            phase: InventoryPhase::Liquid,
            measured: ["level", "M", "V"].map(String::from).to_vec(),
            inflows: inlets.iter().map(|p| FlowVia::Inlet(Cow::Borrowed(*p))).collect(),
            outflows: outlets.iter().map(|(p, _)| FlowVia::Outlet(Cow::Borrowed(*p))).collect(),
        };
        let flows = outlets
            .into_iter()
            .filter_map(|(p, law)| Some(FlowDecl { via: FlowVia::Outlet(Cow::Borrowed(p)), law: law? }))
            .collect();
        MaterialFlows { flows, inventories: vec![inventory] }
    }
}
