//! Throughput manipulator and consistency of inventory control, from the flowsheet graph and the
//! loops that measure inventories.
//!
//! Every unit declares the inventories it holds and what sets the flows that fill and drain them
//! ([`plantwide_model::MaterialFlows`]); a controller whose measurement is one of an inventory's
//! variables (a level, a holdup, a pressure) is that inventory's loop, and the process inputs its
//! output moves (through cascade slaves and ratio stations) are what it manipulates. The rules:
//!
//! - **Consistency** (Aske & Skogestad 2009, Definition 1 and the consistency rule): an inventory
//!   control system is consistent if the steady-state mass balances are satisfied for any part of
//!   the process — every inventory is controlled by a loop or regulates itself.
//! - **Self-consistency** (Aske & Skogestad 2009, the self-consistency rule): each inventory's own
//!   loop manipulates a flow *into or out of that inventory* (through units that hold nothing, such
//!   as a mixer, a heater or a splitter), or one of its flows depends on its holdup (a valve under
//!   the liquid's head). An inventory whose loop moves a flow that neither fills nor drains it is
//!   not self-consistent; one with no loop and no flow depending on it is not consistent.
//! - **Radiation rule** (Price & Georgakis 1993; Aske & Skogestad 2009): with one throughput
//!   manipulator (TPM), inventory loops act in the direction of flow downstream of it (each
//!   manipulates an outflow) and against it upstream (each manipulates an inflow). An inventory
//!   both upstream and downstream (in a recycle with the TPM) is judged by the recycle rule alone.
//!   A unit's inventories take the unit's place in the graph (a column's drum and sump both stand
//!   where the column stands).
//! - **Recycle rule** (Aske & Skogestad 2009, the consistency rule applied to the recycle loop as a
//!   part of the process): the total inventory of a recycle loop is controlled only by a flow into
//!   or out of the loop that an inventory inside it sets (its loop, or its own head); flows inside
//!   the loop only move material around it. A loop with every internal flow on level control and
//!   its boundary flows fixed or set by quality loops is not (self-)consistent: its total inventory
//!   is held, if at all, only indirectly by those quality loops.
//!
//! The TPM candidates are the streams whose rate a free input sets (a feed's `F`, a pumped
//! outflow, a column's product flow) or a flow controller's free setpoint; the feasible TPM
//! locations are those the inventory loops radiate from. Pressure inventories enter where a unit
//! declares a gas holdup (a rigorous column's vapour space); a flash drum's vapour leaves at once.
//!
//! # References
//! - Price, R. M. & Georgakis, C. (1993), "Plantwide regulatory control design procedure using a
//!   tiered framework", *Ind. Eng. Chem. Res.* 32, 2693–2705.
//! - Aske, E. M. B. & Skogestad, S. (2009), "Consistent inventory control", *Ind. Eng. Chem. Res.*
//!   48, 10892–10902.

mod network;
mod recycle;

use std::collections::{BTreeMap, HashMap, HashSet};

use petgraph::graph::{DiGraph, NodeIndex};
use petgraph::visit::{Dfs, Reversed};
use serde::Serialize;

use crate::plant::Plant;
use network::{Flow, Network, Origin, Setter};

/// The inventory check of a plant.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InventoryCheck {
    /// Whether the inventory control is consistent: every inventory self-consistent, radiating
    /// from the throughput manipulators as built, every recycle's total inventory controlled;
    /// `None` when the plant has no inventory loop (nothing to judge).
    pub consistent: Option<bool>,
    /// The feasible TPM locations: inputs (`fresh_A.F`, `fc.sp`) setting a stream's rate that the
    /// inventory control radiates from (none while some inventory is not held by its own loop or
    /// its own head, or when nothing is judged).
    pub tpm: Vec<String>,
    /// The inputs that set a stream's rate from outside the inventory control as built: the
    /// throughput manipulators of the plant as it is.
    pub set_from_outside: Vec<String>,
    /// Each inventory's verdict.
    pub inventories: Vec<InventoryVerdict>,
    /// Each recycle loop's verdict.
    pub recycles: Vec<RecycleVerdict>,
    /// Why nothing was judged, where nothing was.
    pub note: Option<String>,
}

/// Which way an inventory loop acts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Direction {
    /// It manipulates an outflow of its inventory.
    #[serde(rename = "with flow")]
    WithFlow,
    /// It manipulates an inflow.
    #[serde(rename = "against flow")]
    AgainstFlow,
}

impl Direction {
    /// `with flow` or `against flow`.
    pub fn label(self) -> &'static str {
        match self {
            Direction::WithFlow => "with flow",
            Direction::AgainstFlow => "against flow",
        }
    }
}

/// One inventory's verdict.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InventoryVerdict {
    /// The inventory (`tank.level`, `column1.drum`).
    pub inventory: String,
    /// The controller that measures it.
    pub controller: Option<String>,
    /// The input its controller moves (the first, if several).
    pub manipulates: Option<String>,
    /// Which way the loop acts (or the flow that regulates it, for an inventory without a loop).
    pub direction: Option<Direction>,
    /// Whether it is self-consistent and its loop radiates from the TPM.
    pub consistent: bool,
    /// How it is held (the flow its loop moves, or the flow that depends on its holdup).
    pub how: Option<String>,
    /// Why it is not consistent.
    pub why: Option<String>,
}

/// One recycle loop's verdict.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecycleVerdict {
    /// The loop as a cycle of unit names (`mix→reactor→column1→mix`).
    pub recycle: String,
    /// Whether an inventory inside it sets a flow into or out of it.
    pub consistent: bool,
    /// Why not.
    pub why: Option<String>,
}

/// An inventory's own loop, judged locally.
struct Local {
    controller: Option<usize>,
    moved: Vec<usize>,
    direction: Option<Direction>,
    how: Option<String>,
    problem: Option<String>,
}

/// The inventory check of `plant`.
pub fn check(plant: &Plant) -> InventoryCheck {
    let net = Network::new(plant);
    let origins = net.origins();
    let locals: Vec<Local> = (0..net.inventories.len()).map(|k| local(&net, k)).collect();
    let graph = Reach::new(plant);
    let candidates = candidates(&net);
    // The inventory control radiates from a TPM only if it holds every inventory.
    let all_held = locals.iter().all(|l| l.problem.is_none());
    let name = |i: usize| plant.inputs()[i].path.clone();
    let tpm = candidates
        .iter()
        .filter(|&(&i, streams)| all_held && radiation(&net, &graph, i, streams, &locals).is_empty())
        .map(|(&i, _)| name(i))
        .collect();
    let given = given_flows(&net, &graph);
    let single = (candidates.len() == 1).then(|| candidates.keys().next().map(|&i| name(i))).flatten();
    let inventories: Vec<InventoryVerdict> = locals
        .iter()
        .enumerate()
        .map(|(k, l)| verdict(&net, k, l, objection(&net, k, l, &given, single.as_deref())))
        .collect();
    let recycles = recycle::recycles(&net, &graph, &origins);
    let any_loop = locals.iter().any(|l| l.controller.is_some());
    let (note, judged) = note(&net, any_loop);
    let all_ok = inventories.iter().all(|v| v.consistent) && recycles.iter().all(|r| r.consistent);
    InventoryCheck {
        consistent: judged.then_some(all_ok),
        tpm: if judged { tpm } else { Vec::new() },
        set_from_outside: candidates.keys().map(|&i| name(i)).collect(),
        inventories,
        recycles,
        note,
    }
}

/// Why the plant's inventory control is not judged, if it is not, and whether it is: not when no
/// unit declares an inventory, when no loop measures one (a steady-state flowsheet), or when a
/// unit holds a level whose flows it does not declare (an equation-written vessel).
fn note(net: &Network<'_>, any_loop: bool) -> (Option<String>, bool) {
    let undeclared: Vec<&str> = net
        .plant
        .spec()
        .units
        .iter()
        .filter(|(name, u)| {
            u.config().vessel().is_some() && !net.inventories.iter().any(|i| net.plant.blocks()[i.block].name == **name)
        })
        .map(|(name, _)| name.as_str())
        .collect();
    if !undeclared.is_empty() {
        let why = format!(
            "{} holds a level without declaring the flows that change it, so the inventory control is not judged",
            undeclared.join(", ")
        );
        return (Some(why), false);
    }
    match (net.inventories.is_empty(), any_loop) {
        (true, _) => (Some("no unit holds an inventory: nothing to judge".into()), false),
        (false, false) => (
            Some(
                "no level or pressure loop measures an inventory: the file does not say how its inventories are \
                 controlled (a steady-state flowsheet), so the inventory control is not judged"
                    .into(),
            ),
            false,
        ),
        _ => (None, true),
    }
}

/// Inventory `k`'s own loop: which flow it moves and which way, or the flow that depends on its
/// holdup; the self-consistency problem if there is one.
fn local(net: &Network<'_>, k: usize) -> Local {
    let inv = &net.inventories[k];
    let Some(c) = inv.controller else { return unlooped(net, k) };
    let moved = net.moved_inputs(c);
    let ctrl = &net.plant.blocks()[c].name;
    if moved.is_empty() {
        let problem = format!("its controller {ctrl} moves no process input");
        return Local { controller: Some(c), moved, direction: None, how: None, problem: Some(problem) };
    }
    let affected = net.affected(&moved);
    let hit = |flows: &[Flow]| flows.iter().find(|f| affected.contains(f)).cloned();
    let (direction, flow) = match (hit(&inv.outflows), hit(&inv.inflows)) {
        (Some(f), _) => (Some(Direction::WithFlow), Some(f)),
        (None, Some(f)) => (Some(Direction::AgainstFlow), Some(f)),
        (None, None) => (None, None),
    };
    let paths = moved.iter().map(|&i| net.plant.inputs()[i].path.as_str()).collect::<Vec<_>>().join(", ");
    let (how, problem) = match (flow, direction) {
        (Some(f), Some(d)) => {
            let side = if d == Direction::WithFlow { "outflow" } else { "inflow" };
            (Some(format!("{ctrl} moves {paths}: its {side} {}", flow_name(net, &f))), None)
        }
        _ => (
            None,
            Some(format!(
                "{ctrl} moves {paths}, a flow that neither fills nor drains {}: self-consistency needs a loop on \
                 its own inflow or outflow",
                inv.path
            )),
        ),
    };
    Local { controller: Some(c), moved, direction, how, problem }
}

/// Inventory `k` without a loop: held if one of its flows depends on its holdup.
fn unlooped(net: &Network<'_>, k: usize) -> Local {
    let inv = &net.inventories[k];
    let regulates = |f: &&Flow| match net.setters.get(*f) {
        Some(Setter::Holdup { inventory, .. }) => *inventory == k,
        // A unit that moves heat between process streams (a condenser–reboiler) sets the duty from
        // both sides' temperatures: the condensation rises with the pressure it condenses at.
        Some(Setter::Input(i)) => net.driver(*i).is_some_and(|c| net.plant.blocks()[c].unit.moves_process_heat()),
        _ => false,
    };
    let by_out = inv.outflows.iter().find(regulates);
    let by_in = inv.inflows.iter().find(regulates);
    let base = Local { controller: None, moved: Vec::new(), direction: None, how: None, problem: None };
    match (by_out, by_in) {
        (Some(f), _) | (None, Some(f)) => Local {
            direction: Some(if by_out.is_some() { Direction::WithFlow } else { Direction::AgainstFlow }),
            how: Some(match net.setters.get(f) {
                Some(Setter::Input(_)) => {
                    format!("regulates itself: {} ({}) depends on its holdup", flow_name(net, f), set_by(net, f))
                }
                _ => format!("regulates itself: {} depends on its holdup", flow_name(net, f)),
            }),
            ..base
        },
        (None, None) => {
            let list = |flows: &[Flow]| {
                let v: Vec<String> =
                    flows.iter().map(|f| format!("{} ({})", flow_name(net, f), set_by(net, f))).collect();
                if v.is_empty() { "nothing".to_string() } else { v.join(", ") }
            };
            let problem = format!(
                "no loop measures it and no flow in or out depends on it: {} fill it, {} drain it",
                list(&inv.inflows),
                list(&inv.outflows)
            );
            Local { problem: Some(problem), ..base }
        }
    }
}

/// How reports name a flow: the stream's name, or `unit.flow` inside a unit.
fn flow_name(net: &Network<'_>, f: &Flow) -> String {
    match f {
        Flow::Stream(s) => net.plant.streams()[*s].name.clone(),
        Flow::Internal(b, n) => format!("{}.{n}", net.plant.blocks()[*b].name),
    }
}

/// What sets flow `f`, in words.
fn set_by(net: &Network<'_>, f: &Flow) -> String {
    match net.setters.get(f) {
        Some(Setter::Input(i)) => origin_name(net, &net.input_origin(*i)),
        Some(Setter::Holdup { inventory, .. }) => format!("the holdup of {}", net.inventories[*inventory].path),
        Some(Setter::Balance(b)) => format!("the balances of {}", net.plant.blocks()[*b].name),
        Some(Setter::Through(b)) => format!("what enters {}", net.plant.blocks()[*b].name),
        None => "nothing declared".to_string(),
    }
}

/// An origin in words.
fn origin_name(net: &Network<'_>, o: &Origin) -> String {
    let block = |b: usize| net.plant.blocks()[b].name.clone();
    match *o {
        Origin::Free(i) => format!("{} (free)", net.plant.inputs()[i].path),
        Origin::Inventory(k) => format!("the inventory {}", net.inventories[k].path),
        Origin::Controller(c) => format!("controller {}", block(c)),
        Origin::Balance(b) => format!("the balances of {}", block(b)),
    }
}

/// The throughput manipulator candidates: each free input (or free flow-controller setpoint) that
/// sets a stream's rate, with the streams it sets.
fn candidates(net: &Network<'_>) -> BTreeMap<usize, Vec<usize>> {
    let mut out: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (f, s) in &net.setters {
        if let (Flow::Stream(st), Setter::Input(i)) = (f, s)
            && let Origin::Free(j) = net.input_origin(*i)
        {
            out.entry(j).or_default().push(*st);
        }
    }
    out.values_mut().for_each(|v| v.sort_unstable());
    out
}

/// Reachability between units over the streams.
struct Reach {
    graph: DiGraph<usize, usize>,
    node: HashMap<usize, NodeIndex>,
}

impl Reach {
    fn new(plant: &Plant) -> Reach {
        let graph = plant.unit_graph();
        let node = graph.node_indices().map(|n| (graph[n], n)).collect();
        Reach { graph, node }
    }

    /// The units (block indices) reachable from unit `b` along the streams (`forward`) or against
    /// them, `b` included.
    fn reached(&self, b: usize, forward: bool) -> HashSet<usize> {
        let mut out = HashSet::new();
        let Some(&start) = self.node.get(&b) else { return out };
        if forward {
            let mut dfs = Dfs::new(&self.graph, start);
            while let Some(n) = dfs.next(&self.graph) {
                out.insert(self.graph[n]);
            }
        } else {
            let rev = Reversed(&self.graph);
            let mut dfs = Dfs::new(rev, start);
            while let Some(n) = dfs.next(rev) {
                out.insert(self.graph[n]);
            }
        }
        out
    }
}

/// The inventory loops that break the radiation rule around the TPM `tpm` (an input) that sets
/// `streams`, each with why.
fn radiation(
    net: &Network<'_>,
    reach: &Reach,
    tpm: usize,
    streams: &[usize],
    locals: &[Local],
) -> Vec<(usize, String)> {
    let tpm = &net.plant.inputs()[tpm].path;
    let mut out = Vec::new();
    for &s in streams {
        let info = &net.plant.streams()[s];
        let down = reach.reached(info.to.0, true);
        let up = reach.reached(info.from.0, false);
        for (k, l) in locals.iter().enumerate() {
            let (Some(_), Some(d)) = (l.controller, l.direction) else { continue };
            let b = net.inventories[k].block;
            let path = &net.inventories[k].path;
            match (down.contains(&b), up.contains(&b), d) {
                (true, false, Direction::AgainstFlow) => out.push((
                    k,
                    format!(
                        "{path} is controlled by its inflow while downstream of the TPM {tpm}: the radiation rule \
                         needs its outflow"
                    ),
                )),
                (false, true, Direction::WithFlow) => out.push((
                    k,
                    format!(
                        "{path} is controlled by its outflow while upstream of the TPM {tpm}: the radiation rule \
                         needs its inflow"
                    ),
                )),
                _ => {}
            }
        }
    }
    out
}

/// A flow given to the inventory control: a stream a free input or a loop that controls no
/// inventory sets, with the units it reaches downstream and those that reach it upstream.
struct Given {
    down: HashSet<usize>,
    up: HashSet<usize>,
}

/// The given flows of the plant.
fn given_flows(net: &Network<'_>, reach: &Reach) -> Vec<Given> {
    let streams = net.plant.streams();
    let mut out = Vec::new();
    for (f, s) in &net.setters {
        let (Flow::Stream(st), Setter::Input(i)) = (f, s) else { continue };
        if matches!(net.input_origin(*i), Origin::Free(_) | Origin::Controller(_)) {
            out.push(Given {
                down: reach.reached(streams[*st].to.0, true),
                up: reach.reached(streams[*st].from.0, false),
            });
        }
    }
    out
}

/// The radiation rule's objection to inventory `k`'s loop, if any. With several given flows (a
/// TPM and flows fixed by other loops), each loop must radiate from one of them: a loop acting
/// with the flow needs a given flow upstream of its inventory, one acting against the flow a
/// given flow downstream. With a single TPM (`single`) this is Price & Georgakis's rule around
/// it.
fn objection(net: &Network<'_>, k: usize, l: &Local, given: &[Given], single: Option<&str>) -> Option<String> {
    let (Some(_), Some(d)) = (l.controller, l.direction) else { return None };
    let b = net.inventories[k].block;
    let path = &net.inventories[k].path;
    let radiates = match d {
        Direction::WithFlow => given.iter().any(|g| g.down.contains(&b)),
        Direction::AgainstFlow => given.iter().any(|g| g.up.contains(&b)),
    };
    if radiates {
        return None;
    }
    let (side, other, wanted) = match d {
        Direction::WithFlow => ("outflow", "upstream", "inflow"),
        Direction::AgainstFlow => ("inflow", "downstream", "outflow"),
    };
    Some(match single {
        Some(tpm) => format!(
            "{path} is controlled by its {side}, but the TPM {tpm} is not {other} of it: the radiation rule needs \
             its {wanted}"
        ),
        None => format!(
            "{path} is controlled by its {side}, but no flow {other} of it is given (a TPM or a flow another loop \
             sets): the radiation rule needs its {wanted}, or a given flow {other} of it"
        ),
    })
}

/// Inventory `k`'s verdict from its local judgment and the radiation rule's objections.
fn verdict(net: &Network<'_>, k: usize, l: &Local, radiation: Option<String>) -> InventoryVerdict {
    let plant = net.plant;
    let mut why: Vec<String> = l.problem.iter().cloned().collect();
    why.extend(radiation);
    InventoryVerdict {
        inventory: net.inventories[k].path.clone(),
        controller: l.controller.map(|c| plant.blocks()[c].name.clone()),
        manipulates: l.moved.first().map(|&i| plant.inputs()[i].path.clone()),
        direction: l.direction,
        consistent: why.is_empty(),
        how: l.how.clone(),
        why: (!why.is_empty()).then(|| why.join("; ")),
    }
}
