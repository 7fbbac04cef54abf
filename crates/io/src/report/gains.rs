//! The report of steady-state gains ([`GainReport`]) of a flowsheet or a transfer-function model:
//! the gain and relative gain matrices, singular values and directions, the pairing's measures,
//! block relative gains, the scaled gains, the frequency-dependent measures, as text, JSON and the
//! RGA heat map. `plantwide gains` prints [`plant_text`] or [`tf_text`] (or [`json`] with
//! `--json`) and draws [`plot_rga`].

use std::path::Path;

use plantwide_analysis::faer::Mat;
use plantwide_analysis::frequency::FrequencyResults;
use plantwide_analysis::measures::rows;
use plantwide_analysis::perturb::{PerturbCheck, PerturbGains};
use plantwide_analysis::report::{GainJson, GainReport};
use plantwide_analysis::select::SignalLabel;
use plantwide_analysis::tf::TfModel;

use super::{sig6 as sig, truncate};
use crate::IoError;
use crate::plot::{LabelledMatrix, write_matrices};

/// The gains of the plant `name` as text: how they were found (linearization, or the
/// `perturbation` and how it was verified), the report, and the frequency table if asked.
pub fn plant_text(
    name: &str,
    r: &GainReport,
    perturbation: Option<&PerturbGains>,
    frequency: Option<&FrequencyResults>,
) -> String {
    let note = perturbation.map_or("linearization at the steady state, G(0) = −C J⁻¹ B".to_string(), perturb_note);
    let mut t = format!("steady-state gains of `{name}` ({note})\n\n");
    t.push_str(&report_text(r));
    if let Some(f) = frequency {
        t.push_str(&frequency_table(r, f));
    }
    t
}

/// The gains of the transfer-function model read from `file` as text: the report, the
/// disturbance gains Gd(0) if the model has disturbances, and the frequency table if asked.
pub fn tf_text(model: &TfModel, file: &str, r: &GainReport, frequency: Option<&FrequencyResults>) -> String {
    let mut t = format!("steady-state gains of `{}` (transfer-function model {file})\n\n", model.name);
    t.push_str(&report_text(r));
    if !model.disturbances.is_empty() {
        let gd = model.disturbance_gain();
        t.push_str("\ndisturbance gains Gd(0):\n");
        for (i, o) in model.outputs.iter().enumerate() {
            let cells: Vec<String> =
                (0..gd.ncols()).map(|j| format!("{}: {}", model.disturbances[j].name, sig(gd[(i, j)]))).collect();
            t.push_str(&format!("  {:<24} {}\n", o.name, cells.join("  ")));
        }
    }
    if let Some(f) = frequency {
        t.push_str(&frequency_table(r, f));
    }
    t
}

/// The report as JSON (`plantwide gains --json`), with the perturbation's check and the
/// frequency results when there are.
///
/// # Errors
/// [`IoError::Draw`] if serde cannot write it.
pub fn json(
    r: &GainReport,
    perturbation: Option<&PerturbCheck>,
    frequency: Option<&FrequencyResults>,
) -> Result<String, IoError> {
    super::json(&GainJson { perturbation, frequency, ..r.json() })
}

/// The RGA heat map of `r` into `file` (`.png` or `.svg`), titled by the plant or model `name`.
///
/// # Errors
/// [`IoError::PlotKind`] or [`IoError::Draw`] when the file cannot be written.
pub fn plot_rga(file: &Path, name: &str, r: &GainReport) -> Result<(), IoError> {
    let matrix = LabelledMatrix {
        label: "Λ(0)".into(),
        values: r.rga.as_ref().map(|l| rows(l.as_ref())),
        rows: r.outputs.iter().map(|s| s.path.clone()).collect(),
        cols: r.inputs.iter().map(|s| s.path.clone()).collect(),
    };
    write_matrices(file, &format!("relative gains of `{name}`"), &[matrix])
}

/// How perturbation gains were found and verified, in words.
fn perturb_note(p: &PerturbGains) -> String {
    let c = &p.check;
    format!(
        "perturbation: each input ± h and ± h/2 (relative h ≤ {:.1e}), re-converged, central differences extrapolated (Richardson); h vs h/2 differ by ≤ {:.1e}{} ({} attempt(s), {} Newton iterations; convergence error ≤ {:.1e} of the effect)",
        c.step,
        c.max_relative_difference,
        c.linear_relative_difference.map_or(String::new(), |d| format!(", linearization by {d:.1e}")),
        c.attempts,
        p.newton_iterations,
        p.error_ratio
    )
}

/// A signal as a table heading, `path [unit]`.
fn heading(s: &SignalLabel) -> String {
    format!("{} [{}]", s.path, s.unit)
}

/// The matrix `m` as a table, `title` over the row headings, one row per `rows_`, one column per
/// `cols`.
fn matrix(title: &str, rows_: &[SignalLabel], cols: &[SignalLabel], m: &Mat<f64>) -> String {
    let w = rows_.iter().map(|s| heading(s).chars().count()).max().unwrap_or(0).max(title.chars().count());
    let cw = cols.iter().map(|s| heading(s).chars().count()).max().unwrap_or(0).max(14);
    let mut t = format!("{title:<w$}");
    for c in cols {
        t.push_str(&format!("  {:>cw$}", heading(c)));
    }
    t.push('\n');
    for (i, r) in rows_.iter().enumerate() {
        t.push_str(&format!("{:<w$}", heading(r)));
        for j in 0..cols.len() {
            t.push_str(&format!("  {:>cw$}", sig(m[(i, j)])));
        }
        t.push('\n');
    }
    t
}

/// The gain report: gains, RGA, singular values and directions, condition numbers, the
/// pairing's measures, block relative gains and the scaled gains.
fn report_text(r: &GainReport) -> String {
    let mut t = matrix("gain", &r.outputs, &r.inputs, &r.gain);
    t.push('\n');
    match &r.rga {
        Some(l) => t.push_str(&matrix("relative gain array", &r.outputs, &r.inputs, l)),
        None => t.push_str("relative gain array: undefined (the gain matrix is singular)\n"),
    }
    let sv: Vec<String> = r.svd.singular_values.iter().map(|s| sig(*s)).collect();
    t.push_str(&format!("\nsingular values: {}\n", sv.join(", ")));
    t.push_str(&format!("condition number: {}\n", sig(r.condition_number)));
    if let Some(g) = r.min_condition_number {
        t.push_str(&format!("minimized condition number (optimal input and output scaling): {}\n", sig(g)));
    }
    let dir_labels = |n: usize| {
        (1..=n).map(|k| SignalLabel { path: format!("direction {k}"), unit: "-".into() }).collect::<Vec<_>>()
    };
    let k = r.svd.singular_values.len();
    t.push('\n');
    t.push_str(&matrix("output directions U", &r.outputs, &dir_labels(k), &r.svd.u));
    t.push_str(&matrix("input directions V", &r.inputs, &dir_labels(k), &r.svd.v));
    t.push_str(&pairing_text(r));
    if let Some(s) = &r.scaled {
        t.push('\n');
        t.push_str(&matrix("scaled gain", &r.outputs, &r.inputs, &s.gain));
        let sv: Vec<String> = s.singular_values.iter().map(|v| sig(*v)).collect();
        t.push_str(&format!("scaled singular values: {}; condition number {:.4}\n", sv.join(", "), s.condition_number));
        t.push_str(&format!("Morari resiliency index (smallest scaled singular value): {:.6}\n", s.resiliency_index));
    }
    t
}

/// The pairing with its relative gains, Niederlinski index and RGA number; each block's relative
/// gain.
fn pairing_text(r: &GainReport) -> String {
    let mut t = String::new();
    if let (Some(p), Some(ni), Some(rn)) = (&r.pairing, r.niederlinski, r.rga_number) {
        let pairs: Vec<String> =
            p.iter().enumerate().map(|(i, &j)| format!("{}–{}", r.outputs[i].path, r.inputs[j].path)).collect();
        t.push_str(&format!("\npairing: {}\n", pairs.join(", ")));
        if let Some(l) = &r.rga {
            let lam: Vec<String> = p.iter().enumerate().map(|(i, &j)| format!("{:.4}", l[(i, j)])).collect();
            t.push_str(&format!("paired relative gains: {}\n", lam.join(", ")));
        }
        let verdict = if ni < 0.0 { " (negative: unstable under integral action for any tuning)" } else { "" };
        t.push_str(&format!("Niederlinski index: {ni:.6}{verdict}\n"));
        t.push_str(&format!("RGA number: {rn:.4}\n"));
    }
    for (b, m) in &r.block_relative_gains {
        let outs: Vec<&str> = b.outputs.iter().map(|&i| r.outputs[i].path.as_str()).collect();
        let ins: Vec<&str> = b.inputs.iter().map(|&j| r.inputs[j].path.as_str()).collect();
        let det = m.determinant();
        t.push_str(&format!("\nblock relative gain of {} with {} (det {det:.6}):\n", outs.join(", "), ins.join(", ")));
        for row in rows(m.as_ref()) {
            let cells: Vec<String> = row.iter().map(|v| format!("{v:>14.6}")).collect();
            t.push_str(&format!("  {}\n", cells.join(" ")));
        }
    }
    t
}

/// The frequency-dependent measures (σ_max, σ_min, the paired |λ|, the RGA number) and each
/// element's magnitude and phase, one row per frequency.
fn frequency_table(r: &GainReport, f: &FrequencyResults) -> String {
    let mut t = format!("\nfrequency response (ω in rad/{}):\n", f.time_unit);
    let pairing = r.pairing.clone().unwrap_or_default();
    t.push_str(&format!("{:>12} {:>14} {:>14}", "ω", "σ_max", "σ_min"));
    for (i, &j) in pairing.iter().enumerate() {
        t.push_str(&format!(" {:>12}", format!("|λ{}{}|", i + 1, j + 1)));
    }
    t.push_str(&format!(" {:>12}\n", if pairing.is_empty() { "" } else { "RGA number" }));
    for p in &f.points {
        let sv = &p.singular_values;
        let (smax, smin) = (sv.first().copied().unwrap_or(f64::NAN), sv.last().copied().unwrap_or(f64::NAN));
        t.push_str(&format!("{:>12} {:>14} {:>14}", sig(p.omega), sig(smax), sig(smin)));
        match (&p.rga, p.rga_number) {
            (Some(l), Some(number)) => {
                for (i, &j) in pairing.iter().enumerate() {
                    t.push_str(&format!(" {:>12}", sig(l[i][j].magnitude)));
                }
                t.push_str(&format!(" {:>12}\n", sig(number)));
            }
            _ => t.push('\n'),
        }
    }
    t.push_str("\nG(jω) elements, |g| and phase [deg]:\n");
    t.push_str(&format!("{:>12}", "ω"));
    for o in &r.outputs {
        for i in &r.inputs {
            t.push_str(&format!(" {:>26}", format!("{} ← {}", truncate(&o.path, 11), truncate(&i.path, 11))));
        }
    }
    t.push('\n');
    for p in &f.points {
        t.push_str(&format!("{:>12}", sig(p.omega)));
        for row in &p.g {
            for z in row {
                t.push_str(&format!(" {:>26}", format!("{} ∠{:.2}", sig(z.magnitude), z.phase_deg)));
            }
        }
        t.push('\n');
    }
    t
}
