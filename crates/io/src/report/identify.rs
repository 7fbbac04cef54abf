//! The report of an identification ([`Identified`]): the test, the verdict with each criterion
//! and where its threshold comes from, the gains against the exact linearization, the models on
//! validation data; the report folder (`identify.md`, `identify.html`, `identify.json`, the
//! validation plot, `step_model.json` when the model is usable or forced). `plantwide identify`
//! prints [`markdown`] (or [`super::json`] with `--json`); `Plant.identify` returns the same.

use std::path::Path;

use plantwide_studies::identify::{Identification, Identified, number};

use crate::IoError;
use crate::plot::{Overlay, write_overlays};

/// What became of step_model.json.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepModel {
    /// No --report.
    NoReport,
    /// Written: the model is usable.
    Written,
    /// Written although the model is not usable (--force).
    Forced,
    /// Not written: the model is not usable.
    Withheld,
}

impl StepModel {
    /// What became of it, in a sentence (empty without a report).
    pub fn sentence(self) -> &'static str {
        match self {
            StepModel::NoReport => "",
            StepModel::Written => "step_model.json written (the model for an `mpc` controller).",
            StepModel::Forced => {
                "step_model.json written although the model is not usable, because it was forced: an MPC on it may \
                 move the plant the wrong way or too far."
            }
            StepModel::Withheld => {
                "step_model.json not written: the model is not usable for an `mpc` controller (forcing writes it \
                 anyway)."
            }
        }
    }
}

/// The message of a model the verdict finds not usable (the faces' exit 2, after the report that
/// says why); none when it is usable. `report` is the report folder, if one was written.
pub fn not_usable(id: &Identification, step_model: StepModel, report: Option<&Path>) -> Option<String> {
    if id.verdict.reliable {
        return None;
    }
    let failed: Vec<String> = id.verdict.failed().map(|c| c.line()).collect();
    let mut file = match step_model {
        StepModel::NoReport => String::new(),
        s => format!("; {}", s.sentence().trim_end_matches('.')),
    };
    if let (StepModel::Withheld, Some(dir)) = (step_model, report)
        && dir.join("step_model.json").exists()
    {
        file.push_str(&format!(
            "; the step_model.json already in {} is an earlier run's, not this one's",
            dir.display()
        ));
    }
    Some(format!(
        "identify: the identified {} model is not usable ({} of its criteria failed, marked in the report): {}{file}",
        id.verdict.model,
        failed.len(),
        failed.join("; ")
    ))
}

fn matrix(rows: &[Vec<f64>]) -> String {
    rows.iter()
        .map(|r| format!("[{}]", r.iter().map(|v| sig(*v)).collect::<Vec<_>>().join(", ")))
        .collect::<Vec<_>>()
        .join("; ")
}

/// A number with five significant digits, fixed or in exponent form by its size.
fn sig(v: f64) -> String {
    if v == 0.0 || (1e-3..1e5).contains(&v.abs()) { format!("{v:.5}") } else { format!("{v:.4e}") }
}

/// The verdict as markdown: the overall answer, one row per criterion, and where each threshold
/// comes from.
fn verdict_markdown(id: &Identification, step_model: StepModel) -> String {
    let v = &id.verdict;
    let answer = if v.reliable { "usable" } else { "**not usable**" };
    let mut md = format!("## Verdict: the {} model is {answer}\n\n", v.model);
    let line = step_model.sentence();
    if !line.is_empty() {
        md.push_str(&format!("{line}\n\n"));
    }
    md.push_str("| criterion | at | value | must be | threshold | result |\n|---|---|---|---|---|---|\n");
    for c in &v.criteria {
        let result = match (c.pass, c.decides) {
            (true, _) => "pass",
            (false, true) => "**fail**",
            (false, false) => "warning",
        };
        let detail = c.detail.as_ref().map_or(String::new(), |d| format!(" ({d})"));
        md.push_str(&format!(
            "| {} | {}{detail} | {} | {} | {} | {result} |\n",
            c.criterion,
            c.at,
            number(c.value),
            c.must_be,
            number(c.threshold)
        ));
    }
    md.push_str("\nThresholds (a warning does not decide):\n\n");
    let mut seen = Vec::new();
    for c in &v.criteria {
        if !seen.contains(&c.criterion) {
            seen.push(c.criterion);
            md.push_str(&format!("- {}: {}\n", c.criterion, c.source));
        }
    }
    md
}

/// The identification as markdown.
/// The identification as the markdown `plantwide identify` prints; `file` names the plant.
pub fn markdown(file: &str, id: &Identification, step_model: StepModel) -> String {
    let d = &id.design;
    let label = |s: &plantwide_analysis::select::SignalLabel| format!("`{}` [{}]", s.path, s.unit);
    let mut md = format!("# Identification of `{file}`\n\n");
    md.push_str(&format!(
        "Inputs {}; outputs {}.\n\n## Test\n\n- design `{}`, τ_dom = {:.1} min, α = {}, β = {}\n- sample time {:.2} min, PRBS clock {:.1} min, {} registers (N = {}), period {:.0} min, band {:.2e}…{:.2e} rad/min\n- estimation test {:.0} min, validation test {:.0} min (fresh signals and noise)\n- amplitudes {}\n",
        id.inputs.iter().map(label).collect::<Vec<_>>().join(", "),
        id.outputs.iter().map(label).collect::<Vec<_>>().join(", "),
        serde_json::to_value(d.design).ok().and_then(|v| v.as_str().map(String::from)).unwrap_or_default(),
        d.tau_dom / 60.0, d.alpha, d.beta, d.sample_time / 60.0, d.clock_period / 60.0, d.registers, d.period_clocks,
        d.period / 60.0, d.band[0] * 60.0, d.band[1] * 60.0, d.duration / 60.0, d.validation_duration / 60.0,
        d.amplitude.iter().zip(&id.inputs).map(|(v, s)| format!("{v:.4e} {}", s.unit)).collect::<Vec<_>>().join(", "),
    ));
    if let Some(dir) = &d.directions {
        md.push_str(&format!(
            "- directions: singular values {:?} (κ = {:.1}), relative amplitudes {:?}\n",
            dir.singular_values, dir.condition_number, dir.scales
        ));
    }
    md.push('\n');
    md.push_str(&verdict_markdown(id, step_model));
    md.push_str(&format!("\n## Gains ({} model)\n\n", id.validation.model));
    md.push_str(&format!("- identified G(0) = {}\n- exact G(0) = {}\n", matrix(&id.gain), matrix(&id.exact.gain)));
    md.push_str(&format!("- relative errors {}\n", matrix(&id.exact.gain_relative_error)));
    match &id.rga {
        Some(r) => md.push_str(&format!("- identified RGA = {}\n", matrix(r))),
        None => md.push_str("- identified RGA: none (the identified gain is singular)\n"),
    }
    if let Some(r) = &id.exact.rga {
        md.push_str(&format!("- exact RGA = {}\n", matrix(r)));
    }
    if let Some(e) = id.exact.rga11_relative_error {
        md.push_str(&format!("- λ11 relative error {:.2} %\n", 100.0 * e));
    }
    md.push_str(
        "\n## Models (validation data)\n\nfit %: against the measured output; noise-free fit %: against the plant's own \
         response (what the verdict judges); reliable: the criteria of one output (denominator, gain signs, gain error, \
         fit).\n\n| output | model | orders | gains | fit % | noise-free fit % | white | independent | reliable |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for m in &id.models {
        md.push_str(&format!(
            "| `{}` | {} | {} | {} | {:.2} | {:.2} | {} | {} | {} |\n",
            m.output,
            m.model,
            m.orders,
            m.gain.iter().map(|v| sig(*v)).collect::<Vec<_>>().join(", "),
            m.fit_percent,
            m.fit_noise_free,
            m.white,
            m.independent,
            m.reliable
        ));
    }
    md
}

/// The report folder `dir` (made if missing): `identify.json` (the `--json` text),
/// `step_model.json` (unless withheld), `validation.png`, `identify.md` and `identify.html`;
/// `file` names the plant. Returns the files written.
///
/// # Errors
/// [`IoError::Draw`] when the folder or a file cannot be written.
pub fn write_report(dir: &Path, file: &str, r: &Identified, step_model: StepModel) -> Result<Vec<String>, IoError> {
    let id = &r.identification;
    std::fs::create_dir_all(dir).map_err(|e| IoError::Draw(format!("{}: {e}", dir.display())))?;
    let mut written = vec![super::write(dir, "identify.json", &super::json(id)?)?];
    if step_model != StepModel::Withheld {
        written.push(super::write(dir, "step_model.json", &super::json(&id.step_model)?)?);
    }
    let ts = id.design.sample_time;
    let n = id.measured.first().map_or(0, Vec::len);
    let times: Vec<f64> = (0..n).map(|k| k as f64 * ts / 60.0).collect();
    let panels: Vec<Overlay> = r
        .outputs
        .iter()
        .zip(&id.measured)
        .zip(&id.validation.outputs)
        .map(|((o, y), v)| Overlay {
            label: format!("Δ{} [{}]", o.path, o.unit),
            curves: vec![
                ("measured".into(), y.iter().map(|v| v / o.factor).collect()),
                (
                    format!("{} model ({:.1} %)", id.validation.model, v.fit_percent),
                    v.predicted.iter().map(|v| v / o.factor).collect(),
                ),
            ],
            ..Overlay::default()
        })
        .collect();
    let title = "validation: fresh test, model simulated";
    write_overlays(&dir.join("validation.png"), title, "time [min]", &times, &panels, &[])?;
    written.push("validation.png".to_string());
    let md = format!("{}\n![validation](validation.png)\n", markdown(file, id, step_model));
    written.push(super::write(dir, "identify.html", &crate::html::markdown_to_html("Identification", &md))?);
    written.push(super::write(dir, "identify.md", &md)?);
    Ok(written)
}
