//! `steady`: the plant converges, its answer passes a certificate written here from the stream
//! values alone, and the same question asked another way gets the same answer — `--set` against
//! the same edit in the file, a quantity in other units, other display units.

use serde_json::{Map, Value};

use super::cx::Cx;
use super::doc::{J, quantity};
use super::families::Edit;
use super::relations::{first_difference, same_values};

/// Relative and absolute agreement of two steady states that must be the same.
const REL: f64 = 1e-9;
const ABS: f64 = 1e-12;

/// Converge the plant as written; keep its values for the other studies. False if it did not.
pub fn converges(cx: &mut Cx<'_>) -> bool {
    let out = cx.pw(&["steady", "plant.json", "--json"]);
    let Some(v) = cx.succeeded(&out, "steady", true, &["values/*", "iterations"]) else { return false };
    cx.values = v["values"].as_object().cloned().unwrap_or_default();
    let warnings = v["warnings"].as_array().map_or(0, Vec::len);
    cx.check(warnings == 0, "steady: a loop saturates at the generated design point", &[&out], || {
        v["warnings"].to_string()
    });
    let cert = certificate(cx);
    cx.agree(cert, "steady: the converged state fails the certificate (balances, fractions, holdups)", &[&out]);
    true
}

/// Flows of `stream` by component [mol/s].
fn flows(values: &Map<String, Value>, stream: &str, comps: &[(String, f64)]) -> Option<Vec<f64>> {
    let f = values.get(&format!("{stream}.F"))?.as_f64()?;
    comps.iter().map(|(c, _)| Some(f * values.get(&format!("{stream}.x[{c}]"))?.as_f64()?)).collect()
}

/// Balances of every unit over its streams (mass for a reacting unit), of the plant (feeds
/// against products), mole fractions summing to 1, and no holdup or level at zero.
pub fn certificate(cx: &Cx<'_>) -> Result<(), String> {
    let (case, values) = (cx.case, &cx.values);
    let comps = &case.roles.mw;
    let kind = |u: &str| {
        case.closed.at(&["units", u, "type"]).and_then(|t| if let J::S(s) = t { Some(s.clone()) } else { None })
    };
    let mut boundary = (vec![0.0; comps.len()], vec![0.0; comps.len()]);
    let mut units: Vec<&str> = Vec::new();
    for (s, from, to) in &case.roles.streams {
        let fl = flows(values, s, comps).ok_or_else(|| format!("stream {s} is missing from the answer"))?;
        let sum: f64 = comps.iter().map(|(c, _)| values[&format!("{s}.x[{c}]")].as_f64().unwrap_or(f64::NAN)).sum();
        if sum.is_nan() || (sum - 1.0).abs() > 1e-9 {
            return Err(format!("stream {s}: mole fractions sum to {sum:.15}"));
        }
        if kind(from).as_deref() == Some("feed") {
            boundary.0.iter_mut().zip(&fl).for_each(|(a, b)| *a += b);
        }
        if kind(to).as_deref() == Some("product") {
            boundary.1.iter_mut().zip(&fl).for_each(|(a, b)| *a += b);
        }
        units.extend(
            [from.as_str(), to.as_str()]
                .into_iter()
                .filter(|u| !matches!(kind(u).as_deref(), Some("feed" | "product"))),
        );
    }
    units.sort_unstable();
    units.dedup();
    let reacting = !case.roles.reacting.is_empty();
    balance("the plant", &boundary.0, &boundary.1, comps, reacting)?;
    for u in units {
        let (mut inn, mut out) = (vec![0.0; comps.len()], vec![0.0; comps.len()]);
        for (s, from, to) in &case.roles.streams {
            let fl = flows(values, s, comps).unwrap_or_default();
            if to == u {
                inn.iter_mut().zip(&fl).for_each(|(a, b)| *a += b);
            }
            if from == u {
                out.iter_mut().zip(&fl).for_each(|(a, b)| *a += b);
            }
        }
        balance(&format!("unit {u}"), &inn, &out, comps, case.roles.reacting.iter().any(|r| r == u))?;
    }
    holdups(values)
}

fn balance(what: &str, inn: &[f64], out: &[f64], comps: &[(String, f64)], mass: bool) -> Result<(), String> {
    let total: f64 = inn.iter().sum::<f64>().max(out.iter().sum());
    if mass {
        let m = |f: &[f64]| f.iter().zip(comps).map(|(x, (_, mw))| x * mw).sum::<f64>();
        let scale = inn.iter().zip(comps).map(|(x, (_, mw))| x * mw).sum::<f64>().max(1e-300);
        let off = (m(inn) - m(out)).abs() / scale;
        return if off <= 1e-9 {
            Ok(())
        } else {
            Err(format!("{what}: mass balance off by {off:.2e} of its throughput"))
        };
    }
    for (k, (a, b)) in inn.iter().zip(out).enumerate() {
        let off = (a - b).abs() / total.max(1e-300);
        if off.is_nan() || off > 1e-9 {
            return Err(format!(
                "{what}: balance of {} off by {off:.2e} of its throughput (in {a:e}, out {b:e} mol/s)",
                comps[k].0
            ));
        }
    }
    Ok(())
}

/// No holdup (`M`, `M[k]`) or level at or below zero.
fn holdups(values: &Map<String, Value>) -> Result<(), String> {
    let holdup = |k: &str| {
        let field = k.rsplit('.').next().unwrap_or("");
        field == "M" || field == "level" || (field.starts_with("M[") && !field.contains("]["))
    };
    match values.iter().find(|(k, v)| holdup(k) && v.as_f64().is_none_or(|x| x.is_nan() || x <= 1e-9)) {
        Some((k, v)) => Err(format!("{k} = {v}: a holdup at its floor")),
        None => Ok(()),
    }
}

/// `steady --json` under `--units metric` is the SI answer, bit for bit.
pub fn display_units(cx: &mut Cx<'_>) {
    let si = cx.pw(&["steady", "plant.json", "--json"]);
    let metric = cx.pw(&["steady", "plant.json", "--json", "--units", "metric"]);
    let (Some(a), Some(b)) = (si.json(), metric.json()) else {
        cx.check(false, "steady: --units metric changes whether it converges", &[&si, &metric], || metric.brief());
        return;
    };
    let d = first_difference(&a, &b, 0.0, &[], "");
    cx.check(d.is_none(), "steady: --json differs under --units metric", &[&si, &metric], || d.unwrap_or_default());
}

/// The document with `edit` written into it.
pub fn edited(doc: &J, edit: &Edit) -> J {
    let mut d = doc.clone();
    for (path, value) in &edit.file {
        let p: Vec<&str> = path.iter().map(String::as_str).collect();
        d.set(&p, value.clone());
    }
    d
}

/// `steady --set E` against `steady` of the file with E written in: the same values and
/// iterations.
pub fn set_equals_file(cx: &mut Cx<'_>, k: usize) {
    let edit = cx.case.roles.edits[k].clone();
    let name = cx.doc(&format!("edited-{k}.json"), &edited(&cx.case.closed, &edit));
    let set = cx.pw(&["steady", "plant.json", "--json", "--set", &edit.set]);
    let file = cx.pw(&["steady", &name, "--json"]);
    let class = "steady: --set X=v differs from the same edit in the file";
    match (set.json(), file.json()) {
        (Some(a), Some(b)) => {
            same_answer(cx, &a, &b, class, &[&set, &file]);
        }
        (None, None) => {
            cx.check(false, "steady: a generated edit does not converge (either way)", &[&set, &file], || file.brief());
        }
        _ => {
            cx.check(false, class, &[&set, &file], || format!("--set: {}; file: {}", set.brief(), file.brief()));
        }
    }
}

fn same_answer(cx: &mut Cx<'_>, a: &Value, b: &Value, class: &str, outs: &[&super::exec::Output]) -> bool {
    let (va, vb) =
        (a["values"].as_object().cloned().unwrap_or_default(), b["values"].as_object().cloned().unwrap_or_default());
    let same = same_values(&va, &vb, REL, ABS);
    let ok = cx.agree(same, class, outs);
    let (ia, ib) = (&a["iterations"], &b["iterations"]);
    cx.check(ia == ib, &format!("{class} (iterations)"), outs, || format!("{ia} against {ib} iterations")) && ok
}

/// The throughput set to the same value in two units (a rounded display unit, and SI written
/// out to every digit): the same steady state.
pub fn quantity_units(cx: &mut Cx<'_>, unit: &str) {
    let roles = &cx.case.roles;
    let (text, si) = quantity(roles.throughput_si * 1.07, unit, 6);
    let exact = format!("{} mol/s", si);
    let a = format!("{}={text}", roles.throughput);
    let b = format!("{}={exact}", roles.throughput);
    let one = cx.pw(&["steady", "plant.json", "--json", "--set", &a]);
    let two = cx.pw(&["steady", "plant.json", "--json", "--set", &b]);
    let class = "steady: equal quantities in different units give different steady states";
    match (one.json(), two.json()) {
        (Some(x), Some(y)) => {
            same_answer(cx, &x, &y, class, &[&one, &two]);
        }
        (None, None) => {
            cx.check(false, "steady: the throughput +7 % does not converge", &[&one, &two], || one.brief());
        }
        _ => {
            cx.check(false, class, &[&one, &two], || format!("{}; {}", one.brief(), two.brief()));
        }
    }
}
