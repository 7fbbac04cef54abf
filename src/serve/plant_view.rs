//! What the page draws, from the plant's unit graph: units placed in columns by their distance
//! from the feeds, streams between them, controllers with their measurement, setpoint, output,
//! mode and tuning inputs (a faceplate each), the free inputs, the tags (each a name for a value
//! path, with its unit and the input it names), and every path's SI unit.

use std::collections::VecDeque;

use plantwide::flowsheet::{BlockKind, Plant, VarPath};
use serde_json::{Value, json};

/// The page's description of `plant`; `paths` are the value paths in order.
pub fn describe(plant: &Plant, paths: &[String]) -> Value {
    let units: Vec<usize> = (0..plant.blocks().len()).filter(|&b| plant.blocks()[b].kind == BlockKind::Unit).collect();
    let depth = depths(plant);
    let row = rows(plant, &units, &depth);
    let units_json: Vec<Value> = units
        .iter()
        .map(|&b| {
            let (name, unit) = (&plant.blocks()[b].name, &plant.blocks()[b].unit);
            json!({ "name": name, "type": unit.type_name(), "shape": unit.shape(), "col": depth[b], "row": row[b] })
        })
        .collect();
    let streams: Vec<Value> = plant
        .streams()
        .iter()
        .map(|s| {
            let (from, to) = (&plant.blocks()[s.from.0], &plant.blocks()[s.to.0]);
            json!({ "name": s.name, "from": from.name, "from_port": s.from.1, "from_ports": from.layout.n_outlets,
                    "to": to.name, "to_port": s.to.1, "to_ports": to.layout.n_inlets })
        })
        .collect();
    let controllers: Vec<Value> = (0..plant.blocks().len())
        .filter(|&b| plant.blocks()[b].kind == BlockKind::Controller)
        .map(|b| controller(plant, b))
        .collect();
    let inputs: Vec<Value> = plant
        .inputs()
        .iter()
        .filter(|i| i.driven_by.is_none())
        .map(|i| json!({ "path": i.path, "unit": i.dim.to_string(), "value": i.value }))
        .collect();
    let mut tags: Vec<Value> = plant
        .tags()
        .iter()
        .map(|(name, t)| {
            let (var, input) = (&plant.vars()[t.var], t.input.map(|i| &plant.inputs()[i].path));
            json!({ "name": name, "path": var.path, "unit": t.unit, "si_unit": var.spec.dim.to_string(), "input": input })
        })
        .collect();
    tags.sort_by(|a, b| a["name"].as_str().cmp(&b["name"].as_str()));
    let mut si: Vec<String> = plant.vars().iter().map(|v| v.spec.dim.to_string()).collect();
    si.extend(plant.inputs().iter().filter(|i| i.driven_by.is_none()).map(|i| i.dim.to_string()));
    json!({
        "name": plant.name(),
        "units": units_json,
        "streams": streams,
        "controllers": controllers,
        "inputs": inputs,
        "tags": tags,
        "paths": paths,
        "si_units": si,
        "trend": default_trend(plant),
    })
}

/// Each unit's row within its column: ordered by where its stream leaves the column before
/// (that unit's row, then its outlet port), so that a column's distillate (port 0) goes to the
/// unit drawn above the one its bottoms go to and no two streams from one unit cross; units fed
/// from no earlier column keep the file's order.
fn rows(plant: &Plant, units: &[usize], depth: &[usize]) -> Vec<usize> {
    let mut row = vec![0usize; plant.blocks().len()];
    let deepest = units.iter().map(|&b| depth[b]).max().unwrap_or(0);
    for d in 0..=deepest {
        let mut here: Vec<usize> = units.iter().copied().filter(|&b| depth[b] == d).collect();
        let key = |b: usize| {
            let upstream = plant.streams_into(b).iter().map(|&k| &plant.streams()[k]).filter(|s| depth[s.from.0] < d);
            upstream.map(|s| (row[s.from.0], s.from.1)).min().unwrap_or((0, 0))
        };
        here.sort_by_key(|&b| key(b));
        for (r, &b) in here.iter().enumerate() {
            row[b] = r;
        }
    }
    row
}

/// Each block's distance (in streams) from a unit without inlets.
fn depths(plant: &Plant) -> Vec<usize> {
    let n = plant.blocks().len();
    let mut depth = vec![usize::MAX; n];
    let mut queue = VecDeque::new();
    for (b, d) in depth.iter_mut().enumerate() {
        if plant.blocks()[b].kind == BlockKind::Unit && plant.streams_into(b).is_empty() {
            *d = 0;
            queue.push_back(b);
        }
    }
    while let Some(b) = queue.pop_front() {
        for s in plant.streams_out_of(b).iter().map(|&k| &plant.streams()[k]) {
            if depth[s.to.0] == usize::MAX {
                depth[s.to.0] = depth[b] + 1;
                queue.push_back(s.to.0);
            }
        }
    }
    // A unit only on a recycle without a feed: first column.
    depth.iter().map(|&d| if d == usize::MAX { 0 } else { d.min(n) }).collect()
}

/// One controller's faceplate: measurement, setpoint, outputs, driven inputs, mode and tuning.
fn controller(plant: &Plant, b: usize) -> Value {
    let block = &plant.blocks()[b];
    let name = &block.name;
    let own = block.own_offset..block.own_offset + block.layout.n_own();
    let op: Vec<&str> = plant.vars()[own.clone()]
        .iter()
        .filter(|v| VarPath::parse(&v.path).is_controller_output())
        .map(|v| v.path.as_str())
        .collect();
    let drives: Vec<Value> = plant
        .inputs()
        .iter()
        .filter(|i| i.driven_by.is_some_and(|v| own.contains(&v)))
        .map(|i| json!({ "path": i.path, "unit": plant.blocks()[i.block].name }))
        .collect();
    let pv = plant.measured_var(b).map(|v| plant.vars()[v].path.clone());
    let pv_unit = plant.measured_var(b).map(|v| plant.blocks()[plant.vars()[v].block].name.clone());
    let special = [VarPath::setpoint(name), VarPath::auto(name), VarPath::manual_output(name)];
    let [sp, auto, op_manual] = special.each_ref().map(|p| plant.input(p));
    let cascade = sp.is_some_and(|i| plant.inputs()[i].driven_by.is_some());
    let tuning: Vec<&str> = block
        .input_ids
        .iter()
        .map(|&i| plant.inputs()[i].path.as_str())
        .filter(|p| {
            !special.iter().any(|s| s.as_str() == *p)
                && plant.input(p).is_some_and(|i| plant.inputs()[i].driven_by.is_none())
        })
        .collect();
    json!({
        "name": name,
        "type": block.unit.type_name(),
        "settings": settings(plant, name),
        "pv": pv,
        "pv_unit": pv_unit,
        "sp": sp.map(|i| plant.inputs()[i].path.clone()),
        "cascade": cascade,
        "op": op,
        "drives": drives,
        "auto": auto.map(|i| plant.inputs()[i].path.clone()),
        "op_manual": op_manual.map(|i| plant.inputs()[i].path.clone()),
        "tuning": tuning,
    })
}

/// A controller's settings as the flowsheet writes them (gain, reset, action, limits): its
/// description without what the faceplate shows live (measurement, output, setpoint).
fn settings(plant: &Plant, name: &str) -> Value {
    let Some(spec) = plant.spec().controllers.get(name) else { return json!({}) };
    let mut v = serde_json::to_value(spec).unwrap_or_else(|_| json!({}));
    if let Value::Object(m) = &mut v {
        for k in ["type", "pv", "output", "outputs", "sp"] {
            m.remove(k);
        }
    }
    v
}

/// Every controller's measurement, setpoint and first output.
pub fn default_trend(plant: &Plant) -> Vec<String> {
    let mut paths = Vec::new();
    for b in (0..plant.blocks().len()).filter(|&b| plant.blocks()[b].kind == BlockKind::Controller) {
        let name = &plant.blocks()[b].name;
        paths.extend(plant.measured_var(b).map(|v| plant.vars()[v].path.clone()));
        let sp = plant.input(VarPath::setpoint(name)).filter(|&i| plant.inputs()[i].driven_by.is_none());
        paths.extend(sp.map(|i| plant.inputs()[i].path.clone()));
    }
    paths
}
