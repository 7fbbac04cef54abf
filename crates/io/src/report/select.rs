//! The report of a self-optimizing-control selection ([`Ranking`]): the best subsets of the
//! candidate measurements with their worst-case and average losses, the combination `H` of each
//! (exact local method), and the nodes the branch and bound evaluated. `plantwide select` prints
//! [`text`] (or [`json`] with `--json`). Losses are in the cost's own unit.

use plantwide_analysis::measures::rows;
use plantwide_soc::{Criterion, LocalModel, Ranking, SocError, null_space};
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
