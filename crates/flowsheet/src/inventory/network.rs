//! The plant as a network of flows for the inventory check: every stream and every flow inside a
//! unit, what sets its rate ([`Setter`], from the units' declared [`MaterialFlows`]), where that
//! setting comes from ([`Origin`]: a free input, an inventory, another controller), and the
//! inventories with the loops that measure them.

use std::collections::{BTreeSet, HashMap, HashSet};

use plantwide_model::{FlowLaw, FlowVia, InventoryFlows, MaterialFlows};

use crate::plant::{BlockKind, Plant};

/// A flow of the plant.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(super) enum Flow {
    /// A stream, by index.
    Stream(usize),
    /// A flow inside a unit (block index, the flow's name: `reflux`, `boilup`).
    Internal(usize, String),
}

/// What sets a flow's rate.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) enum Setter {
    /// A plant input (its index): free, or driven by a controller.
    Input(usize),
    /// The holdup of inventory `inventory` (self-regulation), moved further by `input` if any.
    Holdup { inventory: usize, input: Option<usize> },
    /// The balances of unit `block` (a flash drum's vapour), or nothing the unit declares.
    Balance(usize),
    /// What enters unit `block`, which holds nothing (a mixer, a heater, a splitter).
    Through(usize),
}

/// Where the setting of a flow comes from.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(super) enum Origin {
    /// A free input (a feed's rate, a valve position, a flow controller's setpoint), by index:
    /// a throughput manipulator.
    Free(usize),
    /// An inventory (by index), through its own loop or by regulating itself.
    Inventory(usize),
    /// A controller (block index) that controls no inventory: a quality, temperature or ratio loop.
    Controller(usize),
    /// The balances of a unit (block index).
    Balance(usize),
}

/// An inventory of the plant.
#[derive(Debug, Clone)]
pub(super) struct Inventory {
    /// The unit (block index) that holds it.
    pub block: usize,
    /// How reports name it: `tank.level`, `column1.drum`.
    pub path: String,
    /// The flows that fill it.
    pub inflows: Vec<Flow>,
    /// The flows that drain it.
    pub outflows: Vec<Flow>,
    /// The controller (block index) that measures it, if any: the first in file order.
    pub controller: Option<usize>,
}

/// The flow network of a plant.
pub(super) struct Network<'p> {
    /// The plant.
    pub plant: &'p Plant,
    /// Each block's declared flows (empty for controllers and tags).
    decls: Vec<MaterialFlows>,
    /// Every inventory.
    pub inventories: Vec<Inventory>,
    /// What sets every stream and internal flow.
    pub setters: HashMap<Flow, Setter>,
    /// The stream at each (block, inlet port) and each (block, outlet port).
    stream_into: HashMap<(usize, usize), usize>,
    stream_out_of: HashMap<(usize, usize), usize>,
    /// The flows each block passes on from its inlets ([`Setter::Through`]), by block.
    through: HashMap<usize, Vec<Flow>>,
    /// The inputs each block's output drives (for controllers), in input order.
    drives: Vec<Vec<usize>>,
    /// The first block (in file order) that measures each measured variable.
    measurer: HashMap<usize, usize>,
    /// The first inventory each controller measures, by controller block.
    loops: HashMap<usize, usize>,
    /// The names of the streams.
    stream_names: HashSet<String>,
}

impl<'p> Network<'p> {
    /// The network of `plant`.
    pub fn new(plant: &'p Plant) -> Network<'p> {
        let decls: Vec<MaterialFlows> = plant
            .blocks()
            .iter()
            .map(|b| if b.kind == BlockKind::Unit { b.unit.material_flows() } else { MaterialFlows::default() })
            .collect();
        let streams = plant.streams();
        let mut drives = vec![Vec::new(); plant.blocks().len()];
        for (i, info) in plant.inputs().iter().enumerate() {
            if let Some(v) = info.driven_by {
                drives[plant.vars()[v].block].push(i);
            }
        }
        let mut net = Network {
            plant,
            decls,
            inventories: Vec::new(),
            setters: HashMap::new(),
            stream_into: streams.iter().enumerate().rev().map(|(k, s)| (s.to, k)).collect(),
            stream_out_of: streams.iter().enumerate().rev().map(|(k, s)| (s.from, k)).collect(),
            through: HashMap::new(),
            drives,
            measurer: HashMap::new(),
            loops: HashMap::new(),
            stream_names: streams.iter().map(|s| s.name.clone()).collect(),
        };
        for c in (0..plant.blocks().len()).rev() {
            net.measurer.extend(plant.measured_vars(c).into_iter().map(|(_, v)| (v, c)));
        }
        net.inventories = net.collect_inventories();
        for (k, inv) in net.inventories.iter().enumerate().rev() {
            if let Some(c) = inv.controller {
                net.loops.insert(c, k);
            }
        }
        net.setters = net.collect_setters();
        for (f, s) in &net.setters {
            if let Setter::Through(b) = *s {
                net.through.entry(b).or_default().push(f.clone());
            }
        }
        net.through.values_mut().for_each(|v| v.sort());
        net
    }

    /// The inventories every unit declares, with the controller that measures each.
    fn collect_inventories(&self) -> Vec<Inventory> {
        let mut out = Vec::new();
        for (b, decl) in self.decls.iter().enumerate() {
            for inv in &decl.inventories {
                out.push(self.inventory(b, inv));
            }
        }
        out
    }

    fn inventory(&self, b: usize, inv: &InventoryFlows) -> Inventory {
        let name = &self.plant.blocks()[b].name;
        let measured: Vec<usize> = inv.measured.iter().filter_map(|m| self.plant.var(format!("{name}.{m}"))).collect();
        let path = match (inv.name, inv.measured.first()) {
            (Some(n), _) => format!("{name}.{n}"),
            (None, Some(m)) => format!("{name}.{m}"),
            (None, None) => name.clone(),
        };
        let flows = |vias: &[FlowVia]| vias.iter().filter_map(|v| self.flow(b, v)).collect();
        let controller = measured.iter().filter_map(|v| self.measurer.get(v).copied()).min();
        Inventory { block: b, path, inflows: flows(&inv.inflows), outflows: flows(&inv.outflows), controller }
    }

    /// The flow `via` of unit `b`: the stream at one of its ports, or a flow inside it.
    fn flow(&self, b: usize, via: &FlowVia) -> Option<Flow> {
        let unit = &self.plant.blocks()[b].unit;
        match via {
            FlowVia::Inlet(p) => {
                let k = unit.inlet_ports().iter().position(|q| q == p)?;
                self.stream_into.get(&(b, k)).copied().map(Flow::Stream)
            }
            FlowVia::Outlet(p) => {
                let k = unit.outlet_ports().iter().position(|q| q == p)?;
                self.stream_out_of.get(&(b, k)).copied().map(Flow::Stream)
            }
            FlowVia::Internal(n) => Some(Flow::Internal(b, n.to_string())),
        }
    }

    /// The input `local` of unit `b`, by index.
    fn input_of(&self, b: usize, local: &str) -> Option<usize> {
        self.plant.input(format!("{}.{local}", self.plant.blocks()[b].name))
    }

    /// The inventory of unit `b` that `flow` drains, if any.
    fn drained_by(&self, b: usize, flow: &Flow) -> Option<usize> {
        self.inventories.iter().position(|i| i.block == b && i.outflows.contains(flow))
    }

    /// What sets every stream and every internal flow a unit declares.
    fn collect_setters(&self) -> HashMap<Flow, Setter> {
        let mut out = HashMap::new();
        for (s, info) in self.plant.streams().iter().enumerate() {
            out.insert(Flow::Stream(s), self.stream_setter(s, info.from, info.to));
        }
        for (b, decl) in self.decls.iter().enumerate() {
            for d in decl.flows.iter().filter(|d| matches!(d.via, FlowVia::Internal(_))) {
                if let Some(flow) = self.flow(b, &d.via) {
                    let setter = self.law_setter(b, &d.law, &flow);
                    out.insert(flow, setter);
                }
            }
        }
        out
    }

    /// A stream's setter: the law its source declares for the outlet, else the law its destination
    /// declares for the inlet, else what enters its source (a unit that holds nothing), else the
    /// source's balances.
    fn stream_setter(&self, s: usize, from: (usize, usize), to: (usize, usize)) -> Setter {
        let flow = Flow::Stream(s);
        let declared = |b: usize| {
            self.decls[b].flows.iter().find(|d| self.flow(b, &d.via).as_ref() == Some(&flow)).map(|d| d.law.clone())
        };
        if let Some(law) = declared(from.0) {
            return self.law_setter(from.0, &law, &flow);
        }
        if let Some(law) = declared(to.0) {
            return match law {
                FlowLaw::UpstreamHoldup { input } => match self.drained_by(from.0, &flow) {
                    Some(inventory) => Setter::Holdup { inventory, input: input.and_then(|i| self.input_of(to.0, &i)) },
                    None => Setter::Through(from.0),
                },
                law => self.law_setter(to.0, &law, &flow),
            };
        }
        if self.drained_by(from.0, &flow).is_some() { Setter::Balance(from.0) } else { Setter::Through(from.0) }
    }

    /// The setter of `flow`, whose law unit `b` declares.
    fn law_setter(&self, b: usize, law: &FlowLaw, flow: &Flow) -> Setter {
        match law {
            FlowLaw::Input(name) => self.input_of(b, name).map_or(Setter::Balance(b), Setter::Input),
            FlowLaw::Holdup { input } | FlowLaw::UpstreamHoldup { input } => match self.drained_by(b, flow) {
                Some(inventory) => {
                    Setter::Holdup { inventory, input: input.as_ref().and_then(|i| self.input_of(b, i)) }
                }
                None => Setter::Balance(b),
            },
            FlowLaw::Balance => Setter::Balance(b),
        }
    }

    /// The controller (block index) whose output drives input `i`, if any.
    pub fn driver(&self, i: usize) -> Option<usize> {
        self.plant.inputs()[i].driven_by.map(|v| self.plant.vars()[v].block)
    }

    /// The process-unit inputs controller `c` moves: those its output drives, and through a
    /// controller it drives (a cascade's slave, a ratio station), what that one moves.
    pub fn moved_inputs(&self, c: usize) -> Vec<usize> {
        let mut out = Vec::new();
        let mut seen = BTreeSet::new();
        let mut todo = vec![c];
        while let Some(c) = todo.pop() {
            if !seen.insert(c) {
                continue;
            }
            for &i in &self.drives[c] {
                match self.plant.blocks()[self.plant.inputs()[i].block].kind {
                    BlockKind::Unit => out.push(i),
                    _ => todo.push(self.plant.inputs()[i].block),
                }
            }
        }
        out
    }

    /// The inventory controller `c` measures, if any.
    pub fn loop_of(&self, c: usize) -> Option<usize> {
        self.loops.get(&c).copied()
    }

    /// Where the value of input `i` comes from: free, or the first controller up its chain that
    /// controls an inventory, else the controller that drives it — a flow controller passing on the
    /// origin of its setpoint.
    pub fn input_origin(&self, i: usize) -> Origin {
        let mut i = i;
        let mut seen = BTreeSet::new();
        while let Some(c) = self.driver(i) {
            if let Some(k) = self.loop_of(c) {
                return Origin::Inventory(k);
            }
            match self.flow_setpoint(c) {
                Some(sp) if seen.insert(sp) => i = sp,
                _ => return Origin::Controller(c),
            }
        }
        Origin::Free(i)
    }

    /// The setpoint input of controller `c` if it is a flow controller: its measurement (`pv`) is
    /// a stream's flow `F`.
    fn flow_setpoint(&self, c: usize) -> Option<usize> {
        let block = &self.plant.blocks()[c];
        let signals = block.unit.signals();
        let pv = self.plant.measured_vars(c).into_iter().find(|(k, _)| signals.get(*k).is_some_and(|s| s.role == "pv"));
        let path = &self.plant.vars()[pv?.1].path;
        let is_flow = path.strip_suffix(".F").is_some_and(|stream| self.stream_names.contains(stream));
        if is_flow { self.input_of(c, "sp") } else { None }
    }

    /// The input that sets a flow with `setter` directly: its own input, or the one that moves its
    /// holdup law (a valve's opening).
    fn direct_input(setter: &Setter) -> Option<usize> {
        match *setter {
            Setter::Input(i) | Setter::Holdup { input: Some(i), .. } => Some(i),
            _ => None,
        }
    }

    /// The flows moving `inputs` changes: those they set, and what passes them on through units
    /// that hold nothing (a mixer's outlet when one of its inlets changes), found by a search from
    /// the flows set directly along the streams into such units.
    pub fn affected(&self, inputs: &[usize]) -> BTreeSet<Flow> {
        let mut out: BTreeSet<Flow> = self
            .setters
            .iter()
            .filter(|(_, s)| Self::direct_input(s).is_some_and(|i| inputs.contains(&i)))
            .map(|(f, _)| f.clone())
            .collect();
        let mut todo: Vec<Flow> = out.iter().cloned().collect();
        while let Some(f) = todo.pop() {
            let Flow::Stream(k) = f else { continue };
            let into = self.plant.streams()[k].to.0;
            for g in self.through.get(&into).into_iter().flatten() {
                if out.insert(g.clone()) {
                    todo.push(g.clone());
                }
            }
        }
        out
    }

    /// The streams entering unit `b`.
    fn inlet_streams(&self, b: usize) -> impl Iterator<Item = Flow> + '_ {
        self.plant.streams_into(b).iter().map(|&k| Flow::Stream(k))
    }

    /// The origins of every flow: a flow that passes what enters a unit has the origins of that
    /// unit's inlets (found by iterating to a fixed point, recycles included).
    pub fn origins(&self) -> HashMap<Flow, BTreeSet<Origin>> {
        let mut out: HashMap<Flow, BTreeSet<Origin>> = HashMap::new();
        for (f, s) in &self.setters {
            let own = match *s {
                Setter::Input(i) => BTreeSet::from([self.input_origin(i)]),
                Setter::Holdup { inventory, .. } => BTreeSet::from([Origin::Inventory(inventory)]),
                Setter::Balance(b) => BTreeSet::from([Origin::Balance(b)]),
                Setter::Through(_) => BTreeSet::new(),
            };
            out.insert(f.clone(), own);
        }
        loop {
            let mut changed = false;
            for (f, s) in &self.setters {
                let Setter::Through(b) = *s else { continue };
                let from: BTreeSet<Origin> =
                    self.inlet_streams(b).flat_map(|t| out.get(&t).cloned().unwrap_or_default()).collect();
                let entry = out.entry(f.clone()).or_default();
                let before = entry.len();
                entry.extend(from);
                changed |= entry.len() != before;
            }
            if !changed {
                return out;
            }
        }
    }
}
