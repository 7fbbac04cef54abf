//! The report of a self-optimizing-control selection ([`Ranking`]): the best subsets of the
//! candidate measurements with their worst-case and average losses, the combination `H` of each
//! (exact local method), and the nodes the branch and bound evaluated. `plantwide select` prints
//! [`text`] (or [`json`] with `--json`). Losses are in the cost's own unit.

use plantwide_analysis::measures::rows;
use plantwide_soc::{Criterion, LocalModel, Ranking, SocError, null_space};
use plantwide_studies::optimize::select::PlantSelection;
use serde::Serialize;

use super::sig6 as sig;
use crate::IoError;

/// The ranking as text: the table of subsets, then `H` of the best.
pub fn text(model: &LocalModel, size: usize, criterion: Criterion, asked: usize, ranking: &Ranking) -> String {
    let p = model.parts();
    let by = match criterion {
        Criterion::Worst => "worst-case loss ½σ̄(M)²",
        Criterion::Average => "average loss ½‖M‖²_F",
    };
    let mut t = format!(
        "self-optimizing control: the best subsets of {size} of the {} candidate measurements for {} input(s) and {} disturbance(s), ranked by {by}\n\n",
        model.ny(),
        model.nu(),
        model.nd()
    );
    t.push_str(&format!("{:>4}  {:>13}  {:>13}  measurements\n", "rank", "worst case", "average"));
    for (k, c) in ranking.subsets.iter().enumerate() {
        let names: Vec<&str> = c.measurements.iter().map(|&i| p.measurements[i].as_str()).collect();
        t.push_str(&format!(
            "{:>4}  {:>13}  {:>13}  {}\n",
            k + 1,
            sig(c.losses.worst_case),
            sig(c.losses.average),
            names.join(", ")
        ));
    }
    if ranking.subsets.len() < asked && ranking.rank_deficient > 0 {
        t.push_str(&format!(
            "\nonly {} subset(s) of {size} can hold the inputs: {} others evaluated are rank-deficient to working precision\n",
            ranking.subsets.len(),
            ranking.rank_deficient
        ));
    } else if ranking.subsets.len() < asked {
        t.push_str(&format!("\nthese are all {} subsets of {size}\n", ranking.subsets.len()));
    }
    if let Some(best) = ranking.subsets.first() {
        t.push_str("\nc = H y for the best subset (exact local method; H Gy = Juu^{1/2}):\n");
        // Whole names, each column as wide as its name: a cut name could read as another.
        let label = p.inputs.iter().map(|i| i.chars().count() + 3).max().unwrap_or(0);
        let widths: Vec<usize> = best.measurements.iter().map(|&i| p.measurements[i].chars().count().max(12)).collect();
        t.push_str(&format!("{:>label$}", ""));
        for (&i, w) in best.measurements.iter().zip(&widths) {
            t.push_str(&format!(" {:>w$}", p.measurements[i]));
        }
        t.push('\n');
        for (r, input) in p.inputs.iter().enumerate() {
            t.push_str(&format!("{:>label$}", format!("c[{input}]")));
            for (j, w) in widths.iter().enumerate() {
                t.push_str(&format!(" {:>w$}", sig(best.h[(r, j)])));
            }
            t.push('\n');
        }
    }
    t.push_str(&format!("\nbranch and bound: {} nodes evaluated\n", ranking.nodes));
    t
}

#[derive(Serialize)]
struct SelectJson<'a> {
    criterion: Criterion,
    size: usize,
    subsets: Vec<SubsetJson<'a>>,
    nodes: u64,
    inputs: &'a [String],
}

#[derive(Serialize)]
struct SubsetJson<'a> {
    measurements: Vec<&'a str>,
    worst_case_loss: f64,
    average_loss: f64,
    #[serde(rename = "H")]
    h: Vec<Vec<f64>>,
    /// The extended null-space combination, where the subset has at least nu + nd measurements
    /// (`null` when it cannot hold the inputs).
    #[serde(skip_serializing_if = "Option::is_none")]
    null_space: Option<Option<NullSpaceJson>>,
}

#[derive(Serialize)]
struct NullSpaceJson {
    #[serde(rename = "H")]
    h: Vec<Vec<f64>>,
    worst_case_loss: f64,
    average_loss: f64,
}

/// The ranking as JSON: `{"criterion", "size", "subsets": [{"measurements", "worst_case_loss",
/// "average_loss", "H"}], "nodes"}`, best first (`H`: one row per input); beside them `inputs` (the
/// rows of `H`) and, for subsets of at least nu + nd measurements, each one's `null_space`
/// combination with its losses (`null` when that combination cannot hold the inputs).
///
/// # Errors
/// [`IoError::Draw`] if a factorization of the null-space combination fails or serde cannot
/// write the result.
pub fn json(model: &LocalModel, size: usize, criterion: Criterion, ranking: &Ranking) -> Result<String, IoError> {
    let p = model.parts();
    let null = |s: &[usize]| -> Result<Option<Option<NullSpaceJson>>, SocError> {
        if s.len() < model.nu() + model.nd() {
            return Ok(None);
        }
        match null_space(model, s) {
            Ok(c) => Ok(Some(Some(NullSpaceJson {
                h: rows(c.h.as_ref()),
                worst_case_loss: c.losses.worst_case,
                average_loss: c.losses.average,
            }))),
            Err(SocError::Request(_)) => Ok(Some(None)),
            Err(e) => Err(e),
        }
    };
    let mut subsets = Vec::with_capacity(ranking.subsets.len());
    for c in &ranking.subsets {
        subsets.push(SubsetJson {
            measurements: c.measurements.iter().map(|&i| p.measurements[i].as_str()).collect(),
            worst_case_loss: c.losses.worst_case,
            average_loss: c.losses.average,
            h: rows(c.h.as_ref()),
            null_space: null(&c.measurements).map_err(|e| IoError::Draw(e.to_string()))?,
        });
    }
    super::json(&SelectJson { criterion, size, subsets, nodes: ranking.nodes, inputs: &p.inputs })
}

/// The selection on a plant as JSON: [`json`]'s contract, each subset with its `nonlinear`
/// verification points, and `optimum` (the [`Optimum`]'s JSON) and `local_model` (the names,
/// `Gy`, `Gyd`, `Juu`, `Jud`, `Wd`, `Wn` in display units).
///
/// # Errors
/// As [`json`].
pub fn plant_json(sel: &PlantSelection, size: usize, criterion: Criterion) -> Result<String, IoError> {
    let text = json(&sel.model, size, criterion, &sel.ranking)?;
    let mut v: serde_json::Value = serde_json::from_str(&text).map_err(|e| IoError::Draw(e.to_string()))?;
    let err = |e: serde_json::Error| IoError::Draw(e.to_string());
    if let Some(subsets) = v.get_mut("subsets").and_then(|s| s.as_array_mut()) {
        for (s, check) in subsets.iter_mut().zip(&sel.verification) {
            s["nonlinear"] = serde_json::to_value(&check.points).map_err(err)?;
        }
    }
    let p = sel.model.parts();
    v["optimum"] = serde_json::to_value(&sel.optimum).map_err(err)?;
    v["local_model"] = serde_json::json!({
        "inputs": p.inputs, "disturbances": p.disturbances, "measurements": p.measurements,
        "Gy": rows(p.gy.as_ref()), "Gyd": rows(p.gyd.as_ref()), "Juu": rows(p.juu.as_ref()),
        "Jud": rows(p.jud.as_ref()), "Wd": rows(p.wd.as_ref()), "Wn": rows(p.wn.as_ref()),
    });
    super::json(&v)
}

/// The selection on a plant as text: the optimum, then [`text`], then the nonlinear check of each
/// listed subset (with `every_h`, every subset's `H`, not only the best's).
pub fn plant_text(sel: &PlantSelection, size: usize, criterion: Criterion, asked: usize, every_h: bool) -> String {
    let mut t = super::optimize::text(&sel.optimum);
    t.push('\n');
    t.push_str(&text(&sel.model, size, criterion, asked, &sel.ranking));
    if every_h {
        t.push_str(&all_h(&sel.model, &sel.ranking));
    }
    t.push_str(&format!(
        "\nnonlinear check: c = H y and the active limits held at the nominal optimum, each disturbance moved by ± its magnitude, loss = held − re-optimized ({})\n",
        sel.optimum.objective_unit
    ));
    t.push_str(&format!(
        "{:>4}  {:<32} {:>5}  {:>13}  {:>13}  notes\n",
        "rank", "disturbance", "sign", "loss", "local"
    ));
    for (k, check) in sel.verification.iter().enumerate() {
        for pt in &check.points {
            let loss = pt.loss.map_or_else(|| "failed".to_string(), sig);
            let mut notes = pt.failure.clone().unwrap_or_default();
            if !pt.violated.is_empty() {
                notes = format!("violates: {}", pt.violated.join("; "));
            }
            let sign = if pt.sign > 0.0 { "+" } else { "−" };
            t.push_str(&format!(
                "{:>4}  {:<32} {:>5}  {:>13}  {:>13}  {notes}\n",
                k + 1,
                pt.disturbance,
                sign,
                loss,
                sig(pt.local_loss)
            ));
        }
    }
    t
}

fn names(p: &plantwide_soc::Parts, subset: &[usize]) -> String {
    subset.iter().map(|&i| p.measurements[i].as_str()).collect::<Vec<_>>().join(", ")
}

/// Every listed subset's `H` after the best's (`--combinations`).
pub fn all_h(model: &LocalModel, ranking: &Ranking) -> String {
    let p = model.parts();
    let mut t = String::new();
    for (k, c) in ranking.subsets.iter().enumerate().skip(1) {
        t.push_str(&format!("\nH of subset {} ({}):\n", k + 1, names(p, &c.measurements)));
        for row in rows(c.h.as_ref()) {
            let cells: Vec<String> = row.iter().map(|v| format!("{:>13}", sig(*v))).collect();
            t.push_str(&format!("  {}\n", cells.join(" ")));
        }
    }
    t
}
