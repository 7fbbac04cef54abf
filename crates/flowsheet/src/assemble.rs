//! From a parsed [`FlowsheetSpec`] to an assembled [`Plant`], checking everything that needs more
//! than the file's structure: components, ports and connections, controller paths, quantities.
//!
//! Assembly runs in phases, each of which adds to one `Assembler` and records what it finds wrong;
//! a phase whose successors need its results whole stops the assembly when anything was found:
//! 1. the components and the thermodynamic package;
//! 2. names (lengths, characters, one name space for units and controllers, no stream named alike);
//! 3. unit models, built from their descriptions;
//! 4. streams: each end resolved to a port, every port connected exactly once;
//! 5. unit blocks, in file order: each owns its outlet streams' variables, then its internal ones;
//! 6. controllers: measured variables and driven inputs resolved, then built (after the units, in
//!    file order) with the dimensions found, and their outputs wired to the inputs they drive;
//! 7. input aliases, input values within range, the size of the plant;
//! 8. every block's reads (inlet streams, inputs or the controller outputs driving them, signals)
//!    and equation offsets, then the design specifications and each unit's check of its input
//!    values.
//!
//! The variable order is therefore: per unit, its outlet streams then its internal variables; then
//! per controller its internal variables. Blocks are units then controllers, in file order.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use plantwide_model::controllers::ControllerLinks;
use plantwide_model::limits::Limits;
use plantwide_model::stream::StreamLayout;
use plantwide_model::{BuildCx, Coloring, ControllerSpec, LocalLayout, Unit};
use plantwide_thermo::ThermoPackage;
use plantwide_units::Dimension;

use crate::components::thermo_package;
use crate::error::{Diagnostic, LoadError, did_you_mean};
use crate::parse::parse_spec;
use crate::path::VarPath;
use crate::plant::{Block, BlockKind, InputInfo, Plant, Read, StreamInfo, TagRef, VarInfo};
use crate::spec::FlowsheetSpec;

/// Read, validate and assemble the flowsheet file at `path`.
pub fn load_file(path: &Path) -> Result<Plant, LoadError> {
    let text = crate::parse::read_text(path)?;
    load_str(&text, &path.display().to_string())
}

/// Validate and assemble flowsheet text; `file` names it in messages.
pub fn load_str(text: &str, file: &str) -> Result<Plant, LoadError> {
    let spec = parse_spec(text, file)?;
    assemble(&spec, file)
}

/// Assemble a parsed flowsheet.
pub fn assemble(spec: &FlowsheetSpec, file: &str) -> Result<Plant, LoadError> {
    let mut a = Assembler::new(spec, file)?;
    a.check_names()?;
    let units = a.build_units()?;
    let outlet_of = a.connect_streams(&units)?;
    a.push_units(units, &outlet_of);
    let pending = a.resolve_controllers()?;
    a.push_controllers(&pending)?;
    a.wire_outputs(&pending);
    a.push_tags()?;
    a.resolve_aliases();
    a.check_plant();
    a.reads_and_offsets()?;
    a.finish()
}

/// `unit.port` → (`unit`, `port`); `unit` alone → (`unit`, `None`).
fn split_port(s: &str) -> (&str, Option<&str>) {
    match s.split_once('.') {
        Some((u, p)) => (u, Some(p)),
        None => (s, None),
    }
}

/// The state of one assembly: what the phases have built so far and the problems found.
struct Assembler<'s> {
    spec: &'s FlowsheetSpec,
    file: &'s str,
    components: Vec<String>,
    thermo: ThermoPackage,
    stream_layout: StreamLayout,
    diags: Vec<Diagnostic>,
    /// Bare numbers read in SI, noted by the units' and controllers' builds.
    notes: plantwide_model::build::Notes,
    blocks: Vec<Block>,
    vars: Vec<VarInfo>,
    inputs: Vec<InputInfo>,
    streams: Vec<StreamInfo>,
    aliases: HashMap<String, usize>,
    tags: HashMap<String, TagRef>,
    var_index: HashMap<String, usize>,
    input_index: HashMap<String, usize>,
}

/// The unit models built from the file, with their names, in file order.
type Units = Vec<(String, Box<dyn Unit>)>;

/// A controller whose paths resolved: its measured paths and the input indices it drives.
struct Pending<'s> {
    name: &'s str,
    config: &'s ControllerSpec,
    measured: Vec<VarPath>,
    driven: Vec<usize>,
}

impl<'s> Assembler<'s> {
    /// Phase 1: the components and the thermodynamic package.
    fn new(spec: &'s FlowsheetSpec, file: &'s str) -> Result<Assembler<'s>, LoadError> {
        let mut diags = Vec::new();
        let Some((components, thermo, _)) = thermo_package(&spec.components, &spec.thermo, &mut diags) else {
            return Err(LoadError::Invalid { file: file.to_string(), diagnostics: diags });
        };
        let stream_layout = StreamLayout { n_comp: components.len() };
        Ok(Assembler {
            spec,
            file,
            components,
            thermo,
            stream_layout,
            diags,
            notes: Default::default(),
            blocks: Vec::new(),
            vars: Vec::new(),
            inputs: Vec::new(),
            streams: Vec::new(),
            aliases: HashMap::new(),
            tags: HashMap::new(),
            var_index: HashMap::new(),
            input_index: HashMap::new(),
        })
    }

    /// Stop here if any problem was found.
    fn stop_if_invalid(&mut self) -> Result<(), LoadError> {
        if self.diags.is_empty() {
            Ok(())
        } else {
            Err(LoadError::Invalid { file: self.file.to_string(), diagnostics: std::mem::take(&mut self.diags) })
        }
    }

    /// Phase 2: names within the length limit (else stop), usable in paths, one name space for
    /// units and controllers, no stream named like either.
    fn check_names(&mut self) -> Result<(), LoadError> {
        let spec = self.spec;
        let name_len = Limits::get().name_len();
        for name in spec.units.keys().chain(spec.controllers.keys()).chain(spec.streams.keys()).chain(spec.tags.keys())
        {
            if let Some(msg) = name_len.check(name.chars().count(), "the length of this name") {
                self.diags.push(Diagnostic::new(plantwide_model::limits::clip(name), msg));
            }
        }
        self.stop_if_invalid()?;
        let named = spec.units.keys().map(|n| ("units", n)).chain(spec.controllers.keys().map(|n| ("controllers", n)));
        for (section, name) in named {
            if name.is_empty() {
                let msg = "a name may not be empty (it begins every variable path of the unit): name it";
                self.diags.push(Diagnostic::new(format!("{section}.\"\""), msg));
            } else if name.contains(['.', '[', ']', '@', ',', '=', ' ']) {
                self.diags.push(Diagnostic::new(
                    format!("{section}.{name}"),
                    "names may not contain '.', '[', ']', '@', ',', '=' or spaces (they appear in variable paths)",
                ));
            }
        }
        for name in spec.controllers.keys().filter(|n| spec.units.contains_key(*n)) {
            self.diags.push(Diagnostic::new(
                format!("controllers.{name}"),
                format!("`{name}` is also a unit name; units and controllers share one name space"),
            ));
        }
        for name in spec.tags.keys() {
            if spec.units.contains_key(name) || spec.controllers.contains_key(name) || spec.streams.contains_key(name) {
                let msg = format!("`{name}` is also a unit, controller or stream name; tags share their name space");
                self.diags.push(Diagnostic::new(format!("tags.{name}"), msg));
            } else if name.is_empty() || name.contains(['.', '[', ']', '@', ',', '=', ' ']) {
                let msg = "a tag's name is used as a path: not empty, without '.', '[', ']', '@', ',', '=' or spaces \
                           (`XMEAS(7)`, `reactor_cost`); to be read in other tags' expressions (`<tag>.value`) it \
                           must be letters, digits and '_'";
                self.diags.push(Diagnostic::new(format!("tags.{name}"), msg));
            }
        }
        for name in spec.streams.keys().filter(|n| spec.units.contains_key(*n) || spec.controllers.contains_key(*n)) {
            self.diags.push(Diagnostic::new(
                format!("streams.{name}"),
                format!("`{name}` is also a unit or controller name; stream paths would be ambiguous"),
            ));
        }
        Ok(())
    }

    /// Phase 3: every unit model built from its description, in file order (stops on any problem
    /// found so far).
    fn build_units(&mut self) -> Result<Units, LoadError> {
        let mut units = Vec::new();
        for (name, u) in &self.spec.units {
            let cx = BuildCx::new(&self.components, &self.thermo, format!("units.{name}")).noting(self.notes.clone());
            match u.build(cx, ()) {
                Ok(unit) => units.push((name.clone(), unit)),
                Err(errs) => self.diags.extend(errs.into_iter().map(|e| Diagnostic::new(e.path, e.message))),
            }
        }
        self.stop_if_invalid()?;
        Ok(units)
    }

    /// Phase 4: each stream's ends resolved to ports, each port connected exactly once. Returns the
    /// stream leaving each (unit, outlet port); stops on any problem.
    fn connect_streams(
        &mut self,
        units: &[(String, Box<dyn Unit>)],
    ) -> Result<HashMap<(usize, usize), String>, LoadError> {
        let unit_index: HashMap<&str, usize> = units.iter().enumerate().map(|(i, (n, _))| (n.as_str(), i)).collect();
        let mut outlet_of: HashMap<(usize, usize), String> = HashMap::new();
        let mut inlet_of: HashMap<(usize, usize), String> = HashMap::new();
        for (sname, s) in &self.spec.streams {
            let from = self.resolve_port(units, &unit_index, &format!("streams.{sname}.from"), &s.from, true);
            let to = self.resolve_port(units, &unit_index, &format!("streams.{sname}.to"), &s.to, false);
            if let Some(prev) = from.and_then(|f| outlet_of.insert(f, sname.clone())) {
                self.diags.push(Diagnostic::new(
                    format!("streams.{sname}.from"),
                    format!(
                        "outlet `{}` is already the source of stream `{prev}`: a port takes one stream (use a splitter)",
                        s.from
                    ),
                ));
            }
            if let Some(prev) = to.and_then(|t| inlet_of.insert(t, sname.clone())) {
                self.diags.push(Diagnostic::new(
                    format!("streams.{sname}.to"),
                    format!(
                        "inlet `{}` is already fed by stream `{prev}`: a port takes one stream (use a mixer)",
                        s.to
                    ),
                ));
            }
            if let (Some(f), Some(t)) = (from, to) {
                self.streams.push(StreamInfo { name: sname.clone(), from: f, to: t, offset: 0, tear: s.tear });
            }
        }
        for (ui, (name, unit)) in units.iter().enumerate() {
            for (k, p) in unit.outlet_ports().iter().enumerate() {
                if !outlet_of.contains_key(&(ui, k)) {
                    self.diags.push(Diagnostic::new(format!("units.{name}"), format!("outlet port `{name}.{p}` is not connected: add a stream from it (to a `product` unit if it leaves the plant)")));
                }
            }
            for (k, p) in unit.inlet_ports().iter().enumerate() {
                if !inlet_of.contains_key(&(ui, k)) {
                    self.diags.push(Diagnostic::new(
                        format!("units.{name}"),
                        format!("inlet port `{name}.{p}` is not connected: add a stream to it"),
                    ));
                }
            }
        }
        self.stop_if_invalid()?;
        Ok(outlet_of)
    }

    /// The (unit, port) that stream end `text` (`unit.port`, or `unit` with one port of that
    /// direction) names, at JSON path `path`; `outlet` tells the direction.
    fn resolve_port(
        &mut self,
        units: &[(String, Box<dyn Unit>)],
        unit_index: &HashMap<&str, usize>,
        path: &str,
        text: &str,
        outlet: bool,
    ) -> Option<(usize, usize)> {
        let (uname, port) = split_port(text);
        let Some(&ui) = unit_index.get(uname) else {
            self.diags.push(Diagnostic::new(
                path,
                format!("no unit named `{uname}`{}", did_you_mean(uname, unit_index.keys().copied())),
            ));
            return None;
        };
        let unit = &units[ui].1;
        let ports = if outlet { unit.outlet_ports() } else { unit.inlet_ports() };
        let dir = if outlet { "outlet" } else { "inlet" };
        let port = match port {
            Some(p) => p.to_string(),
            None if ports.len() == 1 => ports[0].clone(),
            None => {
                self.diags.push(Diagnostic::new(
                    path,
                    format!(
                        "`{uname}` ({}) has {} {dir} ports: name one as `{uname}.<port>` ({})",
                        unit.type_name(),
                        ports.len(),
                        ports.join(", ")
                    ),
                ));
                return None;
            }
        };
        let k = ports.iter().position(|p| *p == port);
        if k.is_none() {
            let hint = if ports.is_empty() {
                format!("it has no {dir} ports")
            } else {
                format!("{dir} ports: {}", ports.join(", "))
            };
            self.diags.push(Diagnostic::new(
                path,
                format!(
                    "`{uname}` ({}) has no {dir} port `{port}`{}; {hint}",
                    unit.type_name(),
                    did_you_mean(&port, ports.iter().map(String::as_str))
                ),
            ));
        }
        k.map(|k| (ui, k))
    }

    /// Phase 5: the unit blocks, in file order, each owning its outlet streams' variables (named
    /// by the stream) before its internal ones; then each stream's offset, at its source's variables.
    fn push_units(&mut self, units: Units, outlet_of: &HashMap<(usize, usize), String>) {
        for (ui, (name, unit)) in units.into_iter().enumerate() {
            let outlets: Vec<&str> = (0..unit.outlet_ports().len()).map(|k| outlet_of[&(ui, k)].as_str()).collect();
            self.push_block(name, BlockKind::Unit, unit, &outlets);
        }
        let slen = self.stream_layout.len();
        for st in &mut self.streams {
            st.offset = self.blocks[st.from.0].own_offset + st.from.1 * slen;
        }
    }

    /// Append block `name` (a unit or a controller) with its own variables: the variables of the
    /// streams leaving it (`outlets`, named by stream), then its internal variables; and its
    /// declared inputs. Every path is indexed as it is added.
    fn push_block(&mut self, name: String, kind: BlockKind, unit: Box<dyn Unit>, outlets: &[&str]) {
        let block = self.blocks.len();
        let own_offset = self.vars.len();
        let mut own = Vec::new();
        for s in outlets {
            own.extend(
                self.stream_layout.var_specs(&self.components, 1.0).into_iter().map(|v| (VarPath::new(s, &v.name), v)),
            );
        }
        own.extend(unit.internal_vars().into_iter().map(|v| (VarPath::new(&name, &v.name), v)));
        for (path, spec) in own {
            self.var_index.insert(path.to_string(), self.vars.len());
            self.vars.push(VarInfo { path: path.into(), spec, block });
        }
        let mut input_ids = Vec::new();
        for i in unit.inputs() {
            let path = VarPath::new(&name, &i.name).to_string();
            self.input_index.insert(path.clone(), self.inputs.len());
            input_ids.push(self.inputs.len());
            self.inputs.push(InputInfo { path, dim: i.dim, value: i.value, driven_by: None, block });
        }
        let is_unit = kind == BlockKind::Unit;
        let layout = LocalLayout {
            stream: self.stream_layout,
            n_outlets: outlets.len(),
            n_internal: unit.internal_vars().len(),
            n_inlets: if is_unit { unit.inlet_ports().len() } else { 0 },
            n_inputs: unit.inputs().len(),
            n_signals: if is_unit { 0 } else { unit.signals().len() },
        };
        let n_eq = (layout.n_own() as isize + unit.extra_equations()).max(0) as usize;
        self.blocks.push(Block {
            name,
            kind,
            unit: unit.into(),
            layout,
            own_offset,
            eq_offset: 0,
            n_eq,
            reads: Vec::new(),
            input_ids,
            pattern: None,
            coloring: None,
        });
    }

    /// Phase 6a: every controller's measured variables and driven inputs resolved against the units
    /// (a measurement may name another controller's output, laid out later: `<ctrl>.op`); an input
    /// takes one controller. Stops on any problem.
    fn resolve_controllers(&mut self) -> Result<Vec<Pending<'s>>, LoadError> {
        let spec = self.spec;
        let mut driven_by: HashMap<usize, &str> = HashMap::new();
        let mut pending = Vec::new();
        for (name, config) in &spec.controllers {
            let paths = config.config().paths();
            let mut ok = true;
            let mut measured = Vec::new();
            for (field, p) in &paths.measured {
                let path = VarPath::parse(p);
                if spec.controllers.contains_key(path.owner()) || path.find(&self.var_index).is_some() {
                    measured.push(path);
                } else {
                    ok = false;
                    let hint = did_you_mean(p, self.var_index.keys().map(String::as_str));
                    self.diags.push(Diagnostic::new(
                        format!("controllers.{name}.{field}"),
                        format!("no variable `{p}`{hint}"),
                    ));
                }
            }
            let mut driven = Vec::new();
            for (field, p) in &paths.driven {
                let at = format!("controllers.{name}.{field}");
                match self.input_index.get(p) {
                    Some(&i) => {
                        if let Some(prev) = driven_by.insert(i, name) {
                            ok = false;
                            self.diags.push(Diagnostic::new(at, format!("input `{p}` is already driven by controller `{prev}`: an input takes one controller (use a selector or split range)")));
                        }
                        driven.push(i);
                    }
                    None => {
                        ok = false;
                        let hint = did_you_mean(p, self.input_index.keys().map(String::as_str));
                        self.diags.push(Diagnostic::new(at, format!("no manipulable input `{p}`{hint}; inputs are declared by units (e.g. `valve.opening`, `heater.duty`)")));
                    }
                }
            }
            if ok {
                pending.push(Pending { name, config, measured, driven });
            }
        }
        self.stop_if_invalid()?;
        Ok(pending)
    }

    /// Phase 6b: the controller blocks, in file order, each built with the dimensions of what it
    /// measures and drives. Stops on any problem.
    fn push_controllers(&mut self, pending: &[Pending<'s>]) -> Result<(), LoadError> {
        for c in pending {
            let links = self.controller_links(pending, c);
            let cx = BuildCx::new(&self.components, &self.thermo, format!("controllers.{}", c.name))
                .noting(self.notes.clone());
            match c.config.build(cx, &links) {
                Ok(unit) => self.push_block(c.name.to_string(), BlockKind::Controller, unit, &[]),
                Err(errs) => self.diags.extend(errs.into_iter().map(|e| Diagnostic::new(e.path, e.message))),
            }
        }
        self.stop_if_invalid()
    }

    /// What controller `c` is built with: the dimension of its first measurement (a variable laid
    /// out so far, or the first input driven by the controller whose output it reads; else
    /// dimensionless), that of its first driven input (or the output dimension its kind gives),
    /// that input's value as the output's bias, and a unit measurement scale (`pv_nominal` = 1).
    fn controller_links(&self, pending: &[Pending<'s>], c: &Pending<'s>) -> ControllerLinks {
        let pv_dim = c.measured.first().and_then(|p| {
            p.find(&self.var_index).map(|i| self.vars[i].spec.dim).or_else(|| {
                let master = pending.iter().find(|m| m.name == p.owner())?;
                master.driven.first().map(|&i| self.inputs[i].dim)
            })
        });
        let pv_dim = pv_dim.unwrap_or(Dimension::DIMENSIONLESS);
        let first = c.driven.first().copied();
        let op_dim = match first {
            Some(i) => self.inputs[i].dim,
            None => c.config.config().op_dimension(pv_dim).unwrap_or(Dimension::DIMENSIONLESS),
        };
        let measured_dims = c
            .measured
            .iter()
            .map(|p| p.find(&self.var_index).map_or(Dimension::DIMENSIONLESS, |i| self.vars[i].spec.dim))
            .collect();
        let driven = c.driven.iter().map(|&i| (self.inputs[i].dim, self.inputs[i].value)).collect();
        let measured_ranges = c
            .measured
            .iter()
            .map(|p| {
                p.find(&self.var_index)
                    .map(|i| physical_range(&self.vars[i].spec))
                    .or_else(|| {
                        let master = pending.iter().find(|m| m.name == p.owner())?;
                        master.driven.first().map(|&i| input_range_of(&self.blocks, &self.inputs, i))
                    })
                    .unwrap_or((f64::NEG_INFINITY, f64::INFINITY))
            })
            .collect();
        let driven_ranges = c.driven.iter().map(|&i| input_range_of(&self.blocks, &self.inputs, i)).collect();
        ControllerLinks {
            pv_dim,
            op_dim,
            op_value: first.map_or(0.0, |i| self.inputs[i].value),
            pv_nominal: 1.0,
            measured_dims,
            driven,
            measured_ranges,
            driven_ranges,
        }
    }

    /// Phase 6c: controller outputs drive inputs: driven input k takes output k
    /// ([`VarPath::controller_output`]: `<ctrl>.op`, `<ctrl>.op2`, …).
    fn wire_outputs(&mut self, pending: &[Pending<'s>]) {
        for c in pending {
            for (k, &i) in c.driven.iter().enumerate() {
                self.inputs[i].driven_by = self.var_index.get(VarPath::controller_output(c.name, k).as_str()).copied();
            }
        }
    }

    /// Phase 6d: the tags, in file order ([`plantwide_model::tag`]): each expression's names
    /// resolved to the flowsheet's parameters or to plant variables and inputs laid out so far
    /// (units, controllers, earlier tags), compiled with their dimensions, checked against a
    /// declared unit, and pushed as a block with the one variable `<tag>.value`. Stops on any
    /// problem.
    fn push_tags(&mut self) -> Result<(), LoadError> {
        let parameters = self.tag_parameters();
        for (name, t) in &self.spec.tags {
            let at = format!("tags.{name}");
            let text = t.expression();
            let names = match plantwide_model::tag::names(text) {
                Ok(n) => n,
                Err(e) => {
                    self.diags.push(Diagnostic::new(at, e.render()));
                    continue;
                }
            };
            let (mut reads, mut guess, mut ok) = (Vec::new(), Vec::new(), true);
            for (n, span) in names.into_iter().filter(|(n, _)| !parameters.iter().any(|p| &p.0 == n)) {
                match self.tag_read(&n) {
                    Some((dim, nominal)) => {
                        reads.push((n, dim));
                        guess.push(nominal);
                    }
                    None => {
                        ok = false;
                        let known = self.var_index.keys().chain(self.input_index.keys()).map(String::as_str);
                        let hint = did_you_mean(&n, known.chain(parameters.iter().map(|p| p.0.as_str())));
                        let caret = plantwide_expr::render_caret(text, span);
                        let msg = format!("no variable, input or parameter `{n}`{hint}\n{caret}");
                        self.diags.push(Diagnostic::new(format!("{at}.expression"), msg));
                    }
                }
            }
            if !ok {
                continue;
            }
            if let Some((field, after)) = t.unit_given_twice() {
                let msg =
                    format!("the unit is given twice (`unit`: `{field}`, and `@{after}` in the expression): keep one");
                self.diags.push(Diagnostic::new(format!("{at}.unit"), msg));
                continue;
            }
            match plantwide_model::tag::Tag::build(text, &reads, &parameters, &guess) {
                Ok(tag) => match self.tag_unit_mismatch(t.unit(), tag.dimension()) {
                    Some(msg) => self.diags.push(Diagnostic::new(format!("{at}.unit"), msg)),
                    None => {
                        self.push_block(name.clone(), BlockKind::Tag, Box::new(tag), &[]);
                        self.name_tag(name, t);
                    }
                },
                Err(e) => self.diags.push(Diagnostic::new(format!("{at}.expression"), e.to_string())),
            }
        }
        self.stop_if_invalid()
    }

    /// Tag `name`, just pushed, by name: its value variable, its unit and the input its expression
    /// is, if it is one input's path.
    fn name_tag(&mut self, name: &str, t: &crate::spec::TagSpec) {
        let Some(&var) = self.var_index.get(&format!("{name}.value")) else { return };
        let input = self.input_index.get(t.expression().trim()).copied();
        self.tags.insert(name.to_string(), TagRef { var, unit: t.unit().map(str::to_string), input });
    }

    /// The flowsheet's `parameters` in SI with their dimensions (a bare number is dimensionless);
    /// a bad one is reported.
    fn tag_parameters(&mut self) -> Vec<(String, f64, Dimension)> {
        let mut out = Vec::new();
        for (name, q) in &self.spec.parameters {
            let parsed = match q {
                plantwide_units::QuantityValue::Number(x) => Ok((*x, Dimension::DIMENSIONLESS)),
                plantwide_units::QuantityValue::Text(t) => {
                    plantwide_units::parse_quantity(t).map(|q| (q.value_si, q.dim)).map_err(|e| e.to_string())
                }
            };
            match parsed {
                Ok((v, _)) if !v.is_finite() => {
                    self.diags.push(Diagnostic::new(format!("parameters.{name}"), "must be a finite number"));
                }
                Ok((v, dim)) if plantwide_expr::name::is_valid_name(name) && !name.contains('.') => {
                    out.push((name.clone(), v, dim));
                }
                Ok(_) => self.diags.push(Diagnostic::new(
                    format!("parameters.{name}"),
                    "a parameter's name is read in expressions: letters, digits and '_', not starting with a digit",
                )),
                Err(e) => self.diags.push(Diagnostic::new(format!("parameters.{name}"), e)),
            }
        }
        out
    }

    /// The dimension and nominal value of what a tag reads at `path`: a variable laid out so far,
    /// else an input (its value).
    fn tag_read(&self, path: &str) -> Option<(Dimension, f64)> {
        if let Some(i) = VarPath::parse(path).find(&self.var_index) {
            let v = &self.vars[i].spec;
            return Some((v.dim, v.nominal));
        }
        self.input_index.get(path).map(|&i| (self.inputs[i].dim, self.inputs[i].value))
    }

    /// Why a tag of dimension `dim` does not have the declared `unit`'s dimension, if it does not.
    fn tag_unit_mismatch(&self, unit: Option<&str>, dim: Dimension) -> Option<String> {
        let unit = unit?;
        match plantwide_units::parse_quantity(&format!("1 {unit}")) {
            Err(e) => Some(format!("`{unit}` is not a unit: {e}")),
            Ok(q) if q.dim != dim => Some(format!(
                "the expression is {} ({dim}) but the unit `{unit}` is {}; fix the expression or the unit",
                dim.describe(),
                q.dim.describe()
            )),
            Ok(_) => None,
        }
    }

    /// Phase 7a: input aliases, each naming a declared input.
    fn resolve_aliases(&mut self) {
        for (alias, p) in &self.spec.inputs {
            match self.input_index.get(p) {
                Some(&i) => {
                    self.aliases.insert(alias.clone(), i);
                }
                None => self.diags.push(Diagnostic::new(
                    format!("inputs.{alias}"),
                    format!(
                        "no manipulable input `{p}`{}",
                        did_you_mean(p, self.input_index.keys().map(String::as_str))
                    ),
                )),
            }
        }
    }

    /// Phase 7b: every input value of the file within its physical range
    /// ([`plantwide_model::limits::check_input`], the check `--set` and scenario events go through
    /// too), and the number of variables within its limit.
    fn check_plant(&mut self) {
        for (i, info) in self.inputs.iter().enumerate() {
            let b = &self.blocks[info.block];
            let path = VarPath::parse(&info.path);
            let name = path.field().unwrap_or(&info.path);
            let range = input_range_of(&self.blocks, &self.inputs, i);
            if let Err(why) = plantwide_model::limits::check_input_within(name, info.dim, info.value, range) {
                self.diags.push(Diagnostic::new(format!("{}.{name}", section_path(b)), why.to_string()));
            }
        }
        if let Some(msg) = Limits::get().variables().check(self.vars.len(), "the number of variables of the plant") {
            self.diags.push(Diagnostic::new("units", msg));
        }
    }

    /// Phase 8: the reads of every block (its inlet streams, its inputs or the controller outputs
    /// driving them, its signals), its sparsity pattern and colouring, and equation offsets in
    /// block order. A block too large to evaluate is reported and skipped. Stops on any problem.
    fn reads_and_offsets(&mut self) -> Result<(), LoadError> {
        let slen = self.stream_layout.len();
        let mut eq_offset = 0;
        for (bi, b) in self.blocks.iter_mut().enumerate() {
            if let Some(msg) = block_size(b) {
                self.diags.push(Diagnostic::new(section_path(b), msg));
                continue;
            }
            let mut reads = Vec::new();
            if b.kind == BlockKind::Unit {
                for k in 0..b.layout.n_inlets {
                    let off = self.streams.iter().find(|s| s.to == (bi, k)).map(|s| s.offset).unwrap_or(0);
                    reads.extend((off..off + slen).map(Read::Var));
                }
            }
            for &i in &b.input_ids {
                reads.push(match self.inputs[i].driven_by {
                    Some(v) => Read::Var(v),
                    None => Read::Input(i),
                });
            }
            for s in b.unit.signals() {
                // A tag may read an input: the controller output driving it, else its value.
                let input = || {
                    self.input_index.get(&s.path).map(|&i| self.inputs[i].driven_by.map_or(Read::Input(i), Read::Var))
                };
                match VarPath::parse(&s.path).find(&self.var_index).map(Read::Var).or_else(input) {
                    Some(read) => reads.push(read),
                    None => self.diags.push(Diagnostic::new(
                        format!("{}.{}.{}", b.kind.section(), b.name, s.role),
                        format!("no variable `{}`", s.path),
                    )),
                }
            }
            b.reads = reads;
            // One triplet is emitted per declared entry: a repeated entry would be summed twice.
            b.pattern = b.unit.pattern(&b.layout).map(|mut p| {
                p.sort_unstable();
                p.dedup();
                p
            });
            b.coloring = b.pattern.as_ref().map(|p| Coloring::new(p, b.n_eq, b.layout.len()));
            b.eq_offset = eq_offset;
            eq_offset += b.n_eq;
        }
        self.stop_if_invalid()
    }

    /// The plant, after each unit's own check of its input values.
    fn finish(self) -> Result<Plant, LoadError> {
        let stream_ends = Arc::new(crate::plant::StreamEnds::new(self.blocks.len(), &self.streams));
        let plant = Plant {
            file: self.file.to_string(),
            name: self.spec.name.clone(),
            components: self.components,
            thermo: self.thermo,
            stream_layout: self.stream_layout,
            blocks: self.blocks,
            vars: Arc::new(self.vars),
            inputs: self.inputs,
            stream_ends,
            streams: self.streams,
            aliases: Arc::new(self.aliases),
            tags: Arc::new(self.tags),
            var_index: Arc::new(self.var_index),
            input_index: self.input_index,
            spec: Arc::new(self.spec.clone()),
            assembled_inputs: Vec::new(),
            specs: Vec::new(),
            notes: std::mem::take(&mut *self.notes.lock().unwrap_or_else(std::sync::PoisonError::into_inner))
                .into_iter()
                .map(|n| n.to_string())
                .collect(),
        };
        let mut plant = plant;
        plant.assembled_inputs = plant.input_values();
        plant.specs = crate::design::resolve_file_specs(&plant)
            .map_err(|diagnostics| LoadError::Invalid { file: plant.file().to_string(), diagnostics })?;
        crate::overrides::check_unit_inputs(&plant, &plant.input_values()).map_err(|e| LoadError::Invalid {
            file: plant.file().to_string(),
            diagnostics: vec![Diagnostic::new(e.path, e.source.to_string())],
        })?;
        check_guess(&plant)?;
        Ok(plant)
    }
}

/// `units.<name>` or `controllers.<name>`: where block `b` is described in the file.
/// The physical range of input `i` (SI): the one its block declares
/// ([`plantwide_model::UnitModel::input_range`]: a setpoint takes its measurement's), else the one
/// its name and dimension give ([`plantwide_model::limits::input_range`]).
pub(crate) fn input_range_of(blocks: &[Block], inputs: &[InputInfo], i: usize) -> (f64, f64) {
    let info = &inputs[i];
    let path = VarPath::parse(&info.path);
    let name = path.field().unwrap_or(&info.path);
    let declared = blocks
        .get(info.block)
        .and_then(|b| Some((b, b.input_ids.iter().position(|&j| j == i)?)))
        .and_then(|(b, k)| b.unit.input_range(k));
    declared.unwrap_or_else(|| plantwide_model::limits::input_range(name, info.dim))
}

/// The physical range of a variable's values (SI), for the setpoints that measure it: its bounds,
/// with a holdup's numerical floor (a tiny positive amount that keeps Newton off zero) read as 0
/// and no bound beyond the largest magnitude of its dimension
/// ([`plantwide_model::limits::max_magnitude`]).
pub(crate) fn physical_range(spec: &plantwide_model::VarSpec) -> (f64, f64) {
    let max = plantwide_model::limits::max_magnitude(spec.dim);
    let lo = if spec.inventory { spec.lower.min(0.0) } else { spec.lower };
    (lo.max(-max), spec.upper.min(max))
}

/// The units' own checks at the plant's cold-start guess
/// ([`plantwide_model::UnitModel::check_guess`]: an equations unit's division by zero where
/// Newton starts), with the upstream units' guesses at their inlets; the guess is computed only
/// when some unit has such a check.
fn check_guess(plant: &Plant) -> Result<(), LoadError> {
    if !plant.blocks.iter().any(|b| b.unit.checks_guess()) {
        return Ok(());
    }
    let u = plant.input_values();
    let x = plant.initial_guess_at(&u);
    let (mut local, mut diagnostics) = (Vec::new(), Vec::new());
    for b in plant.blocks.iter().filter(|b| b.unit.checks_guess()) {
        plant.gather(b, &x, &u, &mut local);
        let io = plantwide_model::UnitIo { local: &local, layout: &b.layout, thermo: &plant.thermo, time: 0.0 };
        let found = b.unit.check_guess(&io);
        diagnostics.extend(found.into_iter().map(|(f, m)| Diagnostic::new(format!("{}.{f}", section_path(b)), m)));
    }
    if diagnostics.is_empty() {
        Ok(())
    } else {
        Err(LoadError::Invalid { file: plant.file().to_string(), diagnostics })
    }
}

fn section_path(b: &Block) -> String {
    format!("{}.{}", b.kind.section(), b.name)
}

/// Why block `b`'s Jacobian block is too large to evaluate, if it is: it is held dense, equations ×
/// local variables.
fn block_size(b: &Block) -> Option<String> {
    let entries = b.n_eq.saturating_mul(b.layout.len());
    Limits::get().block_entries().check(entries, "the size of its Jacobian block").map(|msg| {
        format!(
            "{} equations × {} local variables ({:.1} GB): {msg}; fewer stages or components make it smaller",
            b.n_eq,
            b.layout.len(),
            entries as f64 * 8e-9
        )
    })
}
