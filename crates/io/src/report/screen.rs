//! The report of a screening: a column's inventory configurations ([`ColumnScreen`]) or the
//! pairings of CVs to MVs ([`PairingScreen`]) as markdown, the report folders (`screen.md`,
//! `screen.html`, `screen.json` and figures), a column's tuned flowsheets for `plantwide run`.
//! `plantwide screen` prints [`column_text`] or [`pairing_text`] (or [`super::json`] with
//! `--json`); `Plant.screen` returns the same.

use std::path::Path;

use plantwide_flowsheet::Plant;
use plantwide_studies::screen::column::file_stem;
use plantwide_studies::screen::pairings::mpc::MpcAlternative;
use plantwide_studies::screen::pairings::{DynamicResult, STEP_AT};
use plantwide_studies::screen::{ColumnScreen, ColumnStructure, PairingScreen, ScreenRequest};
use plantwide_units::UnitSystem;

use super::shown::Shown;
use crate::IoError;
use crate::plot::{LabelledMatrix, Overlay, write_bars, write_matrices};

/// The display units of a pairing screen: each CV in the unit it names (`PATH@unit`) or in
/// `system`'s, each watched variable in `system`'s.
///
/// # Errors
/// [`IoError::DisplayUnit`] for a CV's unit that is no unit of its path.
pub fn shown(plant: &Plant, request: &ScreenRequest, system: UnitSystem) -> Result<Shown, IoError> {
    let cvs = request.cvs.iter().map(|c| {
        let (p, u) = plantwide_analysis::select::split_unit(c);
        (p.to_string(), u.map(String::from))
    });
    let watched = request.watch.iter().filter_map(|w| w.split_once('=').map(|(p, _)| (p.trim().to_string(), None)));
    Shown::new(std::slice::from_ref(plant), cvs.chain(watched), system)
}

/// A pairing screen's report folder `dir` (made if missing): `screen.json`, one figure of the
/// best candidates' responses per disturbance, the ranking's bars, `screen.md` and `screen.html`.
/// Returns the files written.
///
/// # Errors
/// [`IoError::Draw`] when the folder or a file cannot be written.
pub fn write_pairing_report(dir: &Path, s: &PairingScreen, shown: &Shown) -> Result<Vec<String>, IoError> {
    std::fs::create_dir_all(dir).map_err(|e| IoError::Draw(format!("{}: {e}", dir.display())))?;
    let mut written = vec![super::write(dir, "screen.json", &super::json(s)?)?];
    let responses = write_responses(dir, s, shown)?;
    let mut figures: String = responses.iter().map(|n| format!("\n![responses]({n})\n")).collect();
    written.extend(responses);
    if write_ranking(dir, s)? {
        figures.push_str("\n![ranking](ranking.png)\n");
        written.push("ranking.png".to_string());
    }
    let md = format!("# Pairings\n\n{}{figures}", pairing_text(s, shown));
    written.push(super::write(dir, "screen.html", &crate::html::markdown_to_html("Pairings", &md))?);
    written.push(super::write(dir, "screen.md", &md)?);
    Ok(written)
}

/// The configurations as a markdown table, in the library's order, with the scaling and the
/// verdict.
pub fn column_text(s: &ColumnScreen, file: &str) -> String {
    let mut t = format!(
        "inventory configurations of column `{}` in {} (qualities {} and {}), ranked by the {}\n\n",
        s.column, file, s.outputs[0], s.outputs[1], s.ranked_by
    );
    let allowed: Vec<String> = s
        .outputs
        .iter()
        .zip(&s.scaling.allowed_deviation)
        .zip(&s.scaling.basis)
        .map(|((o, d), b)| format!("{o} by {d:.4e} ({b})"))
        .collect();
    t.push_str(&format!("scaling of γ and of the IAEs: {}; {}\n", allowed.join(", "), s.scaling.inputs));
    if let Some(d) = s.duration {
        t.push_str(&format!(
            "dynamic check: PI loops tuned by BLT ({} s measurement dead time), {} runs of {:.4e} s: {}\n",
            s.measurement_dead_time.unwrap_or(0.0),
            s.disturbances.len(),
            d,
            s.disturbances.join(", ")
        ));
    }
    t.push_str(
        "\n| rank | structure | pairing (top, bottom) | λ | Niederlinski | γ scaled | γ* | scaled IAE [s] | steady rank | verdict |\n",
    );
    t.push_str("|---|---|---|---|---|---|---|---|---|---|\n");
    for c in &s.structures {
        t.push_str(&row(c));
    }
    t.push_str(&format!("\nverdict: {}\n", s.verdict));
    t.push('\n');
    t.push_str(&super::inventory::text(&s.inventory));
    t
}

/// A configuration's row of the table.
fn row(c: &ColumnStructure) -> String {
    let num = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{v:.4}"));
    let place = |r: Option<usize>| r.map_or("–".to_string(), |r| r.to_string());
    let iae = match (&c.dynamic, c.iae_scaled) {
        (_, Some(v)) => format!("{v:.4e}"),
        (Some(_), None) if c.lost.is_some() => "lost".into(),
        (Some(_), None) => "failed".into(),
        (None, None) => "–".into(),
    };
    let note = match (&c.failure, &c.lost) {
        (Some(why), _) => format!("failed: {why}"),
        (None, Some(how)) => format!("{}; cannot ride through: {how}", c.verdict),
        (None, None) => c.verdict.clone(),
    };
    format!(
        "| {} | {} | {} | {} | {} | {} | {} | {iae} | {} | {} |\n",
        place(c.rank),
        c.name,
        c.pairing.as_ref().map_or_else(|| c.inputs.join(", "), |p| p.join(", ")),
        num(c.relative_gain),
        num(c.niederlinski),
        num(c.condition_number),
        num(c.minimized_condition_number),
        place(c.steady_rank),
        note
    )
}

/// A column screening's report folder `dir` (made if missing): `screen.json`, the relative gains
/// (`rga.png`, `rga.svg`), the ranking's bars, `screen.md` and `screen.html`; `file` names the
/// flowsheet. Returns the files written.
///
/// # Errors
/// [`IoError::Draw`] when the folder or a file cannot be written.
pub fn write_column_report(dir: &Path, file: &str, s: &ColumnScreen) -> Result<Vec<String>, IoError> {
    std::fs::create_dir_all(dir).map_err(|e| IoError::Draw(format!("{}: {e}", dir.display())))?;
    let mut written = vec![super::write(dir, "screen.json", &super::json(s)?)?];
    let matrices: Vec<LabelledMatrix> = s
        .structures
        .iter()
        .map(|c| LabelledMatrix {
            label: format!("{} ({})", c.name, c.rank.map_or("not ranked".to_string(), |r| format!("rank {r}"))),
            values: c.rga.clone(),
            ..LabelledMatrix::default()
        })
        .collect();
    let title = format!("relative gains of column `{}`: {} (row 1), {} (row 2)", s.column, s.outputs[0], s.outputs[1]);
    for ext in ["png", "svg"] {
        write_matrices(&dir.join(format!("rga.{ext}")), &title, &matrices)?;
        written.push(format!("rga.{ext}"));
    }
    let mut ranked: Vec<_> = s.structures.iter().collect();
    ranked.sort_by_key(|c| (c.rank.is_none(), c.rank));
    let dynamic = s.duration.is_some();
    let bars: Vec<(String, f64)> = ranked
        .iter()
        .map(|c| {
            let value = match dynamic {
                true => c.iae_scaled.unwrap_or(f64::NAN),
                false => c.relative_gain.filter(|_| c.rank.is_some()).map_or(f64::NAN, |l| l.ln().abs()),
            };
            (c.name.clone(), value)
        })
        .collect();
    let (title, axis) = match dynamic {
        true => (
            format!("ranking of column `{}`'s configurations by the dynamic check (– not run)", s.column),
            "scaled IAE [s]",
        ),
        false => (format!("ranking of column `{}`'s configurations (0 = decoupled; – singular)", s.column), "|ln λ|"),
    };
    write_bars(&dir.join("ranking.png"), &title, axis, &bars)?;
    written.push("ranking.png".to_string());
    let md = format!(
        "# Column configurations: `{}`\n\n{}\n![relative gains](rga.png)\n\n![ranking](ranking.png)\n",
        s.column,
        column_text(s, file)
    );
    written.push(super::write(dir, "screen.html", &crate::html::markdown_to_html("Column configurations", &md))?);
    written.push(super::write(dir, "screen.md", &md)?);
    Ok(written)
}

/// The ranked pairings' dynamic scores as bars (`false` when none was tested).
fn write_ranking(dir: &Path, s: &PairingScreen) -> Result<bool, IoError> {
    let mut ranked: Vec<_> = s.structures.iter().filter(|c| c.rank.is_some() && c.dynamic.is_some()).collect();
    if ranked.is_empty() {
        return Ok(false);
    }
    ranked.sort_by_key(|c| c.rank);
    let bars: Vec<(String, f64)> = ranked
        .iter()
        .map(|c| {
            let mvs: Vec<&str> = c.pairs.iter().map(|p| p.mv.as_str()).collect();
            let tpm = c.throughput.as_deref().map_or(String::new(), |t| format!("TPM {t}: "));
            (
                format!("{} {tpm}{}", c.rank.unwrap_or(0), mvs.join(", ")),
                c.dynamic.as_ref().map_or(f64::NAN, |d| d.score),
            )
        })
        .collect();
    let file = dir.join("ranking.png");
    write_bars(&file, "dynamic score (1 = best on every CV and disturbance)", "score", &bars)?;
    Ok(true)
}

/// One figure per disturbance: each CV's response under the (up to three) best tested candidates.
fn write_responses(dir: &Path, s: &PairingScreen, shown: &Shown) -> Result<Vec<String>, IoError> {
    let mut best: Vec<_> = s
        .structures
        .iter()
        .filter(|c| c.rank.is_some() && c.dynamic.as_ref().is_some_and(DynamicResult::completed))
        .collect();
    best.sort_by_key(|c| c.rank);
    best.truncate(3);
    let Some(first) = best.first().and_then(|c| c.dynamic.as_ref()) else { return Ok(Vec::new()) };
    let mut names = Vec::new();
    for (d, run) in first.runs.iter().enumerate() {
        let panels: Vec<Overlay> = s
            .cvs
            .iter()
            .enumerate()
            .map(|(k, cv)| Overlay {
                label: shown.label(cv),
                curves: best
                    .iter()
                    .filter_map(|c| {
                        c.dynamic.as_ref().map(|t| {
                            let series = t.runs[d].series[k].iter().map(|v| shown.value(cv, *v)).collect();
                            (format!("rank {}", c.rank.unwrap_or(0)), series)
                        })
                    })
                    .collect(),
                ..Overlay::default()
            })
            .collect();
        let times: Vec<f64> = run.times.iter().map(|t| t / 3600.0).collect();
        let name = format!("responses_{}.png", d + 1);
        let title = format!("{}: the best structures' responses", run.disturbance);
        let step = [(STEP_AT * times.last().copied().unwrap_or(0.0), run.disturbance.clone())];
        crate::plot::write_responses(&dir.join(&name), &title, "time [h]", &times, &panels, &step)?;
        names.push(name);
    }
    Ok(names)
}

/// Write each configuration's tuned flowsheet (`<config>.json`) and the runs' scenarios into
/// `dir` (made if missing), for `plantwide run`; how many flowsheets.
///
/// # Errors
/// [`IoError::Draw`] when the folder or a file cannot be written.
pub fn write_flowsheets(dir: &Path, s: &ColumnScreen) -> Result<usize, IoError> {
    std::fs::create_dir_all(dir).map_err(|e| IoError::Draw(format!("{}: {e}", dir.display())))?;
    let mut n = 0;
    for c in &s.structures {
        if let Some(f) = &c.flowsheet {
            super::write(dir, &format!("{}.json", file_stem(&c.name)), f)?;
            n += 1;
        }
    }
    for (name, text) in &s.scenarios {
        super::write(dir, name, &(super::json(text)? + "\n"))?;
    }
    Ok(n)
}

/// A dynamic test's score as the tables show it: `failed`, `lost` (the plant left its operating
/// range in a run) or the number.
fn score_text(d: &DynamicResult) -> String {
    match (d.completed(), d.rides_through()) {
        (false, _) => "failed".into(),
        (true, false) => "lost".into(),
        (true, true) => format!("{:.3}", d.score),
    }
}

/// What did not finish in a dynamic test: its failed parts, else where the plant was lost.
fn unfinished(d: &DynamicResult) -> Option<String> {
    let failed = d.failures("failed");
    let parts = if failed.is_empty() { d.losses("cannot ride through") } else { failed };
    (!parts.is_empty()).then(|| parts.join("; "))
}

/// The model predictive controller's row of the pairing table.
fn mpc_row(m: &MpcAlternative) -> String {
    let dynamic = m.dynamic.as_ref();
    let score = dynamic.map_or("–".to_string(), score_text);
    let samples: usize = m.qp.iter().map(|l| l.samples).sum();
    let mean = m.qp.iter().map(|l| l.mean_solve_time * l.samples as f64).sum::<f64>() / samples.max(1) as f64;
    let note = dynamic.and_then(unfinished).unwrap_or_else(|| {
        format!(
            "every {} s, P = {}, M = {}; {samples} QPs, mean solve {:.3} ms; condition number {}",
            m.sample_time,
            m.prediction_horizon,
            m.control_horizon,
            1e3 * mean,
            m.condition_number.map_or("–".into(), |c| format!("{c:.3}"))
        )
    });
    format!(
        "| MPC | – | model predictive control: {} by {} | – | – | – | {score} | {note} |\n",
        m.cvs.join(", "),
        m.mvs.join(", ")
    )
}

/// The candidate structures as a markdown table, ranked first.
pub fn pairing_text(s: &PairingScreen, shown: &Shown) -> String {
    let mut t = format!(
        "{} complete pairings examined, {} partial ones cut for a non-positive relative gain; loops opened: {}\n\n",
        s.enumerated,
        s.pruned,
        if s.opened.is_empty() { "none".to_string() } else { s.opened.join(", ") }
    );
    for tpm in &s.singular {
        let choice = tpm.as_deref().map_or("the MVs".to_string(), |t| format!("the MVs with {t} held"));
        t.push_str(&format!(
            "singular: {choice} cannot set the CVs independently at steady state; no pairing listed\n\n"
        ));
    }
    let watched: Vec<String> = s
        .structures
        .first()
        .map(|c| {
            c.sensitivity
                .iter()
                .map(|w| {
                    format!(
                        "{} over {}: {:.6e} … {:.6e} {} ({})",
                        w.path,
                        w.disturbance,
                        shown.value(&w.path, w.min),
                        shown.value(&w.path, w.max),
                        shown.unit(&w.path),
                        if w.within { "in band" } else { "OUT of band" }
                    )
                })
                .collect()
        })
        .unwrap_or_default();
    if !watched.is_empty() {
        t.push_str(&format!("sensitivity (CVs held, first throughput choice): {}\n\n", watched.join("; ")));
    }
    t.push_str("| rank | throughput | pairs (relative gain) | NI | DIC | RGA number | dynamic score | note |\n");
    t.push_str("|---|---|---|---|---|---|---|---|\n");
    for c in &s.structures {
        let pairs: Vec<String> =
            c.pairs.iter().map(|p| format!("{} ← {} ({:.3})", p.cv, p.mv, p.relative_gain)).collect();
        let dynamic = c.dynamic.as_ref();
        let score = dynamic.map_or("–".to_string(), score_text);
        let note = c.rejected.clone().or(dynamic.and_then(unfinished)).unwrap_or_default();
        t.push_str(&format!(
            "| {} | {} | {} | {:.4} | {} | {:.3} | {score} | {note} |\n",
            c.rank.map_or("–".to_string(), |r| r.to_string()),
            c.throughput.as_deref().unwrap_or("–"),
            pairs.join("; "),
            c.niederlinski,
            if c.dic { "yes" } else { "no" },
            c.rga_number
        ));
    }
    if let Some(m) = &s.mpc {
        t.push_str(&mpc_row(m));
    }
    t.push_str(&format!("\nverdict: {}\n", s.verdict));
    t.push('\n');
    t.push_str(&super::inventory::text(&s.inventory));
    t
}
