//! `run` and `sensitivity` on the plant as written: a throughput step and a very short ramp to
//! the same value end at the same state, every run conserves, and a sweep's points are the
//! steady states `steady --set` finds at the same inputs.

use approx::relative_eq;
use serde_json::{Map, Value};

use super::cx::Cx;
use super::doc::{J, obj};
use super::relations::{conserved, end_slopes, same_end, same_values};

/// The recorded paths of a run: the qualities, the column's holdups, the bottoms flow.
fn recorded(cx: &Cx<'_>) -> Vec<String> {
    let r = &cx.case.roles;
    let n = cx
        .case
        .closed
        .at(&["units", &r.column, "stages"])
        .and_then(|s| if let J::I(n) = s { Some(*n) } else { None })
        .unwrap_or(2);
    vec![
        r.cvs[0].clone(),
        r.cvs[1].clone(),
        format!("{}.M[{n}]", r.column),
        format!("{}.M[1]", r.column),
        format!("{}.F", r.products[1]),
    ]
}

/// A run long enough for the column to answer: eight liquid residence times, 2 to 30 hours.
fn duration_min(cx: &Cx<'_>) -> f64 {
    let r = &cx.case.roles;
    let holdup: f64 = cx
        .values
        .iter()
        .filter(|(k, _)| k.starts_with(&format!("{}.M[", r.column)))
        .filter_map(|(_, v)| v.as_f64())
        .sum();
    let flow = cx.value(&format!("{}.F", r.products[1])).unwrap_or(1.0)
        + cx.value(&format!("{}.F", r.products[0])).unwrap_or(1.0);
    (8.0 * holdup / flow / 60.0).clamp(120.0, 1800.0).round()
}

fn scenario(cx: &Cx<'_>, ramp: Option<&str>, to_si: f64) -> J {
    let r = &cx.case.roles;
    let mut event = obj([
        ("type", if ramp.is_some() { "ramp" } else { "step" }.into()),
        ("at", "1 min".into()),
        ("path", r.throughput.clone().into()),
        ("to", format!("{to_si} mol/s").into()),
    ]);
    if let Some(d) = ramp {
        event.set(&["duration"], d.into());
    }
    let paths: Vec<J> = recorded(cx).into_iter().map(J::S).collect();
    obj([
        ("format_version", J::I(1)),
        ("name", format!("throughput {}", if ramp.is_some() { "ramp" } else { "step" }).into()),
        ("duration", format!("{} min", duration_min(cx)).into()),
        ("integrator", obj([("rtol", J::N(1e-8)), ("atol", J::N(1e-10))])),
        ("events", J::A(vec![event])),
        ("record", obj([("interval", "1 min".into()), ("time_unit", "min".into()), ("paths", J::A(paths))])),
    ])
}

/// A +5 % throughput step and the same change as a one-second ramp.
pub fn step_and_ramp(cx: &mut Cx<'_>) {
    let to = cx.case.roles.throughput_si * 1.05;
    let step = cx.doc("step.scenario.json", &scenario(cx, None, to));
    let ramp = cx.doc("ramp.scenario.json", &scenario(cx, Some("1 s"), to));
    let promised = ["paths/*/last", "conservation/max_relative_error"];
    let a = cx.pw(&["run", "plant.json", "--scenario", &step, "--csv", "step.csv", "--json"]);
    let va = cx.succeeded(&a, "run", true, &promised);
    let b = cx.pw(&["run", "plant.json", "--scenario", &ramp, "--csv", "ramp.csv", "--json"]);
    let vb = cx.succeeded(&b, "run", true, &promised);
    for (v, out) in [(&va, &a), (&vb, &b)] {
        if let Some(v) = v {
            cx.agree(conserved(v), "run: conservation over its tolerance", &[out]);
        }
    }
    if let (Some(x), Some(y)) = (va, vb) {
        let slopes = end_slopes(&std::fs::read_to_string(cx.dir.join("step.csv")).unwrap_or_default());
        cx.agree(
            same_end(&x, &y, &slopes, 1.0, 1e-4),
            "run: a step and a one-second ramp end at different states",
            &[&a, &b],
        );
    }
}

/// Rows of a sensitivity CSV: change in percent → output path → value.
fn sweep_rows(text: &str) -> Vec<(f64, Map<String, Value>)> {
    let mut lines = text.lines();
    let header: Vec<String> =
        lines.next().unwrap_or("").split(',').map(|h| h.split(" [").next().unwrap_or(h).to_string()).collect();
    lines
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            let change = cells.get(3).and_then(|c| c.parse().ok()).unwrap_or(f64::NAN);
            let outputs = header
                .iter()
                .zip(&cells)
                .skip(4)
                .map(|(h, c)| (h.clone(), Value::from(c.parse::<f64>().unwrap_or(f64::NAN))))
                .collect();
            (change, outputs)
        })
        .collect()
}

/// `sensitivity` over ±5 % of the throughput: its base point is the steady state, its +5 % end
/// is `steady --set` at +5 %.
pub fn sensitivity(cx: &mut Cx<'_>) {
    let r = cx.case.roles.clone();
    let outputs = [r.cvs[0].clone(), r.cvs[1].clone(), format!("{}.F", r.products[1])];
    let disturb = format!("{}=-5%:+5%", r.throughput);
    let out = cx.pw(&[
        "sensitivity",
        "plant.json",
        "--disturb",
        &disturb,
        "--outputs",
        &outputs.join(","),
        "--points",
        "3",
        "--csv",
        "sweep.csv",
    ]);
    if cx.succeeded(&out, "sensitivity", false, &[]).is_none() {
        return;
    }
    let rows = sweep_rows(&std::fs::read_to_string(cx.dir.join("sweep.csv")).unwrap_or_default());
    let pick = |c: f64| {
        rows.iter().find(|(p, _)| relative_eq!(*p, c, epsilon = 1e-6, max_relative = 1e-6)).map(|(_, m)| m.clone())
    };
    let (Some(base), Some(high)) = (pick(0.0), pick(5.0)) else {
        cx.check(false, "sensitivity: the CSV lacks its base or +5 % row", &[&out], || format!("{} rows", rows.len()));
        return;
    };
    let steady: Map<String, Value> =
        outputs.iter().map(|p| (p.clone(), cx.values.get(p).cloned().unwrap_or(Value::Null))).collect();
    cx.agree(same_values(&steady, &base, 1e-8, 1e-12), "sensitivity: the base point is not the steady state", &[&out]);
    let set = format!("{}={} mol/s", r.throughput, r.throughput_si * 1.05);
    let direct = cx.pw(&["steady", "plant.json", "--json", "--set", &set]);
    let Some(v) = cx.succeeded(&direct, "steady", true, &["values/*"]) else { return };
    let at: Map<String, Value> =
        outputs.iter().map(|p| (p.clone(), v["values"].get(p).cloned().unwrap_or(Value::Null))).collect();
    cx.agree(
        same_values(&at, &high, 1e-7, 1e-12),
        "sensitivity: the +5 % point is not steady --set at +5 %",
        &[&out, &direct],
    );
}
