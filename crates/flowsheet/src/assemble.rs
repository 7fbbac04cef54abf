//! From a parsed [`FlowsheetSpec`] to an assembled [`Plant`], checking everything that needs more
//! than the file's structure: components, ports and connections, controller paths, quantities.

use std::collections::HashMap;
use std::path::Path;

use plantwide_model::controllers::ControllerLinks;
use plantwide_model::stream::StreamLayout;
use plantwide_model::{BuildCx, Coloring, LocalLayout, Unit};

use plantwide_model::limits::Limits;

use crate::components::thermo_package;
use crate::error::{Diagnostic, LoadError, did_you_mean};
use crate::parse::parse_spec;
use crate::plant::{Block, BlockKind, InputInfo, Plant, Read, StreamInfo, VarInfo};
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

fn split_port(s: &str) -> (&str, Option<&str>) {
    match s.split_once('.') {
        Some((u, p)) => (u, Some(p)),
        None => (s, None),
    }
}

/// Assemble a parsed flowsheet.
pub fn assemble(spec: &FlowsheetSpec, file: &str) -> Result<Plant, LoadError> {
    let invalid = |diagnostics: Vec<Diagnostic>| LoadError::Invalid { file: file.to_string(), diagnostics };
    let mut diags = Vec::new();
    let Some((components, thermo, _)) = thermo_package(&spec.components, &spec.thermo, &mut diags) else {
        return Err(invalid(diags));
    };
    let stream_layout = StreamLayout { n_comp: components.len() };

    // Names: units and controllers share one name space; names must be usable in paths.
    let name_len = plantwide_model::limits::Limits::get().name_len();
    for name in spec.units.keys().chain(spec.controllers.keys()).chain(spec.streams.keys()) {
        if let Some(msg) = name_len.check(name.chars().count(), "the length of this name") {
            diags.push(Diagnostic::new(plantwide_model::limits::clip(name), msg));
        }
    }
    if !diags.is_empty() {
        return Err(invalid(diags));
    }
    for name in spec.units.keys().chain(spec.controllers.keys()) {
        if name.is_empty() || name.contains(['.', '[', ']', '@', ',', '=', ' ']) {
            diags.push(Diagnostic::new(name.clone(), "names may not be empty or contain '.', '[', ']', '@', ',', '=' or spaces (they appear in variable paths)"));
        }
    }
    for name in spec.controllers.keys().filter(|n| spec.units.contains_key(*n)) {
        diags.push(Diagnostic::new(
            format!("controllers.{name}"),
            format!("`{name}` is also a unit name; units and controllers share one name space"),
        ));
    }
    for name in spec.streams.keys().filter(|n| spec.units.contains_key(*n) || spec.controllers.contains_key(*n)) {
        diags.push(Diagnostic::new(
            format!("streams.{name}"),
            format!("`{name}` is also a unit or controller name; stream paths would be ambiguous"),
        ));
    }

    // Units.
    let mut units: Vec<(String, Box<dyn Unit>)> = Vec::new();
    for (name, u) in &spec.units {
        let cx = BuildCx::new(&components, &thermo, format!("units.{name}"));
        match u.build(cx, ()) {
            Ok(unit) => units.push((name.clone(), unit)),
            Err(errs) => diags.extend(errs.into_iter().map(|e| Diagnostic::new(e.path, e.message))),
        }
    }
    if !diags.is_empty() {
        return Err(invalid(diags));
    }
    let unit_index: HashMap<&str, usize> = units.iter().enumerate().map(|(i, (n, _))| (n.as_str(), i)).collect();

    // Streams: resolve ports, each port connected exactly once.
    let mut outlet_of: HashMap<(usize, usize), String> = HashMap::new();
    let mut inlet_of: HashMap<(usize, usize), String> = HashMap::new();
    let mut links = Vec::new();
    for (sname, s) in &spec.streams {
        let mut resolve = |end: &str, text: &str, outlet: bool| -> Option<(usize, usize)> {
            let path = format!("streams.{sname}.{end}");
            let (uname, port) = split_port(text);
            let Some(&ui) = unit_index.get(uname) else {
                diags.push(Diagnostic::new(
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
                    diags.push(Diagnostic::new(
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
            match ports.iter().position(|p| *p == port) {
                Some(k) => Some((ui, k)),
                None => {
                    let hint = if ports.is_empty() {
                        format!("it has no {dir} ports")
                    } else {
                        format!("{dir} ports: {}", ports.join(", "))
                    };
                    diags.push(Diagnostic::new(
                        path,
                        format!(
                            "`{uname}` ({}) has no {dir} port `{port}`{}; {hint}",
                            unit.type_name(),
                            did_you_mean(&port, ports.iter().map(String::as_str))
                        ),
                    ));
                    None
                }
            }
        };
        let from = resolve("from", &s.from, true);
        let to = resolve("to", &s.to, false);
        if let Some(prev) = from.and_then(|f| outlet_of.insert(f, sname.clone())) {
            diags.push(Diagnostic::new(
                format!("streams.{sname}.from"),
                format!(
                    "outlet `{}` is already the source of stream `{prev}`: a port takes one stream (use a splitter)",
                    s.from
                ),
            ));
        }
        if let Some(prev) = to.and_then(|t| inlet_of.insert(t, sname.clone())) {
            diags.push(Diagnostic::new(
                format!("streams.{sname}.to"),
                format!("inlet `{}` is already fed by stream `{prev}`: a port takes one stream (use a mixer)", s.to),
            ));
        }
        if let (Some(f), Some(t)) = (from, to) {
            links.push((sname.clone(), f, t, s.tear));
        }
    }
    for (ui, (name, unit)) in units.iter().enumerate() {
        for (k, p) in unit.outlet_ports().iter().enumerate() {
            if !outlet_of.contains_key(&(ui, k)) {
                diags.push(Diagnostic::new(format!("units.{name}"), format!("outlet port `{name}.{p}` is not connected: add a stream from it (to a `product` unit if it leaves the plant)")));
            }
        }
        for (k, p) in unit.inlet_ports().iter().enumerate() {
            if !inlet_of.contains_key(&(ui, k)) {
                diags.push(Diagnostic::new(
                    format!("units.{name}"),
                    format!("inlet port `{name}.{p}` is not connected: add a stream to it"),
                ));
            }
        }
    }
    if !diags.is_empty() {
        return Err(invalid(diags));
    }

    // Layout of the unit blocks.
    let slen = stream_layout.len();
    let mut vars = Vec::new();
    let mut inputs = Vec::new();
    let mut blocks = Vec::new();
    let mut stream_offset: HashMap<(usize, usize), usize> = HashMap::new();
    for (ui, (name, unit)) in units.into_iter().enumerate() {
        let own_offset = vars.len();
        let outlets = unit.outlet_ports();
        for k in 0..outlets.len() {
            stream_offset.insert((ui, k), vars.len());
            let sname = &outlet_of[&(ui, k)];
            for v in stream_layout.var_specs(&components, 1.0) {
                vars.push(VarInfo { path: format!("{sname}.{}", v.name), spec: v, block: ui });
            }
        }
        for v in unit.internal_vars() {
            vars.push(VarInfo { path: format!("{name}.{}", v.name), spec: v, block: ui });
        }
        let input_ids = unit
            .inputs()
            .into_iter()
            .map(|i| {
                inputs.push(InputInfo {
                    path: format!("{name}.{}", i.name),
                    dim: i.dim,
                    value: i.value,
                    driven_by: None,
                    block: ui,
                });
                inputs.len() - 1
            })
            .collect();
        let layout = LocalLayout {
            stream: stream_layout,
            n_outlets: outlets.len(),
            n_internal: unit.internal_vars().len(),
            n_inlets: unit.inlet_ports().len(),
            n_inputs: unit.inputs().len(),
            n_signals: 0,
        };
        let n_eq = (layout.n_own() as isize + unit.extra_equations()).max(0) as usize;
        blocks.push(Block {
            name,
            kind: BlockKind::Unit,
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
    let streams: Vec<StreamInfo> = links
        .iter()
        .map(|(name, f, t, tear)| StreamInfo {
            name: name.clone(),
            from: *f,
            to: *t,
            offset: stream_offset[f],
            tear: *tear,
        })
        .collect();
    let mut var_index: HashMap<String, usize> = vars.iter().enumerate().map(|(i, v)| (v.path.clone(), i)).collect();
    let mut input_index: HashMap<String, usize> = inputs.iter().enumerate().map(|(i, v)| (v.path.clone(), i)).collect();

    // Controllers: resolve paths, then build with the resolved dimensions.
    let mut driven_by_ctrl: HashMap<usize, String> = HashMap::new();
    let mut pending = Vec::new();
    for (cname, c) in &spec.controllers {
        let paths = c.config().paths();
        let mut measured = Vec::new();
        let mut ok = true;
        for (field, p) in &paths.measured {
            // A measurement may name another controller's output, laid out below: accept `<ctrl>.op`.
            let (head, _) = split_port(p);
            if spec.controllers.contains_key(head) {
                measured.push(p.clone());
                continue;
            }
            match var_index.get(p).or_else(|| var_index.get(&p.replace(".z[", ".x["))) {
                Some(_) => measured.push(p.clone()),
                None => {
                    ok = false;
                    diags.push(Diagnostic::new(
                        format!("controllers.{cname}.{field}"),
                        format!("no variable `{p}`{}", did_you_mean(p, var_index.keys().map(String::as_str))),
                    ));
                }
            }
        }
        let mut driven = Vec::new();
        for (field, p) in &paths.driven {
            match input_index.get(p) {
                Some(&i) => {
                    if let Some(prev) = driven_by_ctrl.insert(i, cname.clone()) {
                        ok = false;
                        diags.push(Diagnostic::new(format!("controllers.{cname}.{field}"), format!("input `{p}` is already driven by controller `{prev}`: an input takes one controller (use a selector or split range)")));
                    }
                    driven.push(i);
                }
                None => {
                    ok = false;
                    diags.push(Diagnostic::new(
                        format!("controllers.{cname}.{field}"),
                        format!("no manipulable input `{p}`{}; inputs are declared by units (e.g. `valve.opening`, `heater.duty`)", did_you_mean(p, input_index.keys().map(String::as_str))),
                    ));
                }
            }
        }
        if ok {
            pending.push((cname.clone(), c, measured, driven));
        }
    }
    if !diags.is_empty() {
        return Err(invalid(diags));
    }
    for (cname, c, measured, driven) in &pending {
        let pv_dim = measured.first().and_then(|p| var_index.get(p).map(|&i| vars[i].spec.dim)).or_else(|| {
            measured.first().and_then(|p| {
                let (head, _) = split_port(p);
                pending.iter().find(|(n, ..)| n == head).and_then(|(_, _, _, d)| d.first().map(|&i| inputs[i].dim))
            })
        });
        let first = driven.first().copied();
        let pv_dim = pv_dim.unwrap_or(plantwide_units::Dimension::DIMENSIONLESS);
        let op_dim = match first {
            Some(i) => inputs[i].dim,
            None => c.config().op_dimension(pv_dim).unwrap_or(plantwide_units::Dimension::DIMENSIONLESS),
        };
        let links =
            ControllerLinks { pv_dim, op_dim, op_value: first.map_or(0.0, |i| inputs[i].value), pv_nominal: 1.0 };
        let cx = BuildCx::new(&components, &thermo, format!("controllers.{cname}"));
        match c.build(cx, &links) {
            Ok(unit) => {
                let own_offset = vars.len();
                for v in unit.internal_vars() {
                    vars.push(VarInfo { path: format!("{cname}.{}", v.name), spec: v, block: blocks.len() });
                    var_index.insert(vars[vars.len() - 1].path.clone(), vars.len() - 1);
                }
                let input_ids = unit
                    .inputs()
                    .into_iter()
                    .map(|i| {
                        inputs.push(InputInfo {
                            path: format!("{cname}.{}", i.name),
                            dim: i.dim,
                            value: i.value,
                            driven_by: None,
                            block: blocks.len(),
                        });
                        input_index.insert(inputs[inputs.len() - 1].path.clone(), inputs.len() - 1);
                        inputs.len() - 1
                    })
                    .collect();
                let layout = LocalLayout {
                    stream: stream_layout,
                    n_outlets: 0,
                    n_internal: unit.internal_vars().len(),
                    n_inlets: 0,
                    n_inputs: unit.inputs().len(),
                    n_signals: unit.signals().len(),
                };
                let n_eq = (layout.n_own() as isize + unit.extra_equations()).max(0) as usize;
                blocks.push(Block {
                    name: cname.clone(),
                    kind: BlockKind::Controller,
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
            Err(errs) => diags.extend(errs.into_iter().map(|e| Diagnostic::new(e.path, e.message))),
        }
    }
    if !diags.is_empty() {
        return Err(invalid(diags));
    }
    // Controller outputs drive inputs: driven input k takes `<ctrl>.op` (k = 0) or `<ctrl>.op<k+1>`
    // (split range: `op`, `op2`).
    for (cname, _, _, driven) in &pending {
        for (k, &i) in driven.iter().enumerate() {
            let op = if k == 0 { format!("{cname}.op") } else { format!("{cname}.op{}", k + 1) };
            inputs[i].driven_by = var_index.get(&op).copied();
        }
    }

    // Aliases.
    let mut aliases = HashMap::new();
    for (alias, p) in &spec.inputs {
        match input_index.get(p) {
            Some(&i) => {
                aliases.insert(alias.clone(), i);
            }
            None => diags.push(Diagnostic::new(
                format!("inputs.{alias}"),
                format!("no manipulable input `{p}`{}", did_you_mean(p, input_index.keys().map(String::as_str))),
            )),
        }
    }

    check_inputs(&blocks, &inputs, &mut diags);
    if let Some(msg) = Limits::get().variables().check(vars.len(), "the number of variables of the plant") {
        diags.push(Diagnostic::new("units", msg));
    }

    // Reads of every block, and equation offsets.
    let mut eq_offset = 0;
    for (bi, b) in blocks.iter_mut().enumerate() {
        if let Some(msg) = block_size(b) {
            diags.push(Diagnostic::new(section_path(b), msg));
            continue;
        }
        let mut reads = Vec::new();
        if b.kind == BlockKind::Unit {
            for k in 0..b.layout.n_inlets {
                let off = streams.iter().find(|s| s.to == (bi, k)).map(|s| s.offset).unwrap_or(0);
                reads.extend((off..off + slen).map(Read::Var));
            }
        }
        for &i in &b.input_ids {
            reads.push(match inputs[i].driven_by {
                Some(v) => Read::Var(v),
                None => Read::Input(i),
            });
        }
        for s in b.unit.signals() {
            match var_index.get(&s.path).or_else(|| var_index.get(&s.path.replace(".z[", ".x["))) {
                Some(&v) => reads.push(Read::Var(v)),
                None => diags.push(Diagnostic::new(
                    format!("controllers.{}.{}", b.name, s.role),
                    format!("no variable `{}`", s.path),
                )),
            }
        }
        b.reads = reads;
        b.pattern = b.unit.pattern(&b.layout);
        b.coloring = b.pattern.as_ref().map(|p| Coloring::new(p, b.n_eq, b.layout.len()));
        b.eq_offset = eq_offset;
        eq_offset += b.n_eq;
    }
    if !diags.is_empty() {
        return Err(invalid(diags));
    }
    let plant = Plant {
        file: file.to_string(),
        name: spec.name.clone(),
        components,
        thermo,
        stream_layout,
        blocks,
        vars,
        inputs,
        streams,
        aliases,
        var_index,
        input_index,
        spec: spec.clone(),
    };
    crate::overrides::check_unit_inputs(&plant, &plant.input_values())
        .map_err(|(path, why)| invalid(vec![Diagnostic::new(path, why)]))?;
    Ok(plant)
}

/// `units.<name>` or `controllers.<name>`: where block `b` is described in the file.
fn section_path(b: &Block) -> String {
    match b.kind {
        BlockKind::Unit => format!("units.{}", b.name),
        BlockKind::Controller => format!("controllers.{}", b.name),
    }
}

/// Every input value of the file within its physical range ([`plantwide_model::limits::check_input`],
/// the check `--set` and scenario events go through too).
fn check_inputs(blocks: &[Block], inputs: &[InputInfo], diags: &mut Vec<Diagnostic>) {
    for info in inputs {
        let b = &blocks[info.block];
        let name = info.path.strip_prefix(&format!("{}.", b.name)).unwrap_or(&info.path);
        if let Err(why) = plantwide_model::limits::check_input(name, info.dim, info.value) {
            diags.push(Diagnostic::new(format!("{}.{name}", section_path(b)), why.to_string()));
        }
    }
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
