//! The report of a tuning: a flowsheet's tuned loops ([`FlowsheetTuning`], with the test behind
//! each setting and its margins) or a transfer-function model's ([`Tuning`]), times in a chosen
//! unit; each loop's Bode diagram; the report folder (`tune.md`, `tune.html`, `tune.json`,
//! `tune.svg`). `plantwide tune` prints [`text`] (or [`json`] with `--json`); `Plant.tune`
//! returns the same.

use std::path::Path;

use plantwide_analysis::tf::TfModel;
use plantwide_flowsheet::Plant;
use plantwide_studies::identify::number as significant;
use plantwide_studies::tune::flowsheet::{FlowsheetLoop, FlowsheetTuning, MIN_PHASE_MARGIN, kc_text};
use plantwide_studies::tune::margins::Bode;
use plantwide_studies::tune::plant_tests::{Linearity, StepTry};
use plantwide_studies::tune::request::TunedLoops;
use plantwide_studies::tune::{TuneMethod, Tuning};

use crate::IoError;
use crate::plot::{BodeLoop, write_bode};

/// `writeln!` into a `String` (which cannot fail).
macro_rules! w {
    ($out:expr, $($arg:tt)*) => {{
        use std::fmt::Write as _;
        let _ = writeln!($out, $($arg)*);
    }};
}

/// A unit of time the report shows periods and reset times in.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeUnit {
    /// As written (`min`).
    pub name: String,
    /// Seconds per unit.
    pub seconds: f64,
}

/// The tuned loops of `plant` as the table `plantwide tune FILE` prints, times in `tu`.
pub fn text(t: &TunedLoops, plant: &Plant, tu: &TimeUnit) -> String {
    let mut out = String::new();
    loops_table(&mut out, &t.tuning.clone().in_time_unit(tu.seconds), plant, tu);
    out
}

/// The `--json` text of the tuned loops, times in `tu` (gains SI).
///
/// # Errors
/// [`IoError::Draw`] if serde cannot write it.
pub fn json(t: &TunedLoops, tu: &TimeUnit) -> Result<String, IoError> {
    super::json(&t.tuning.clone().in_time_unit(tu.seconds))
}

/// Each tuned loop's Bode diagram, alone on the plant's linear model, to `out`.
///
/// # Errors
/// As [`bode`].
pub fn plot(out: &Path, t: &TunedLoops, plant: &Plant, tu: &TimeUnit) -> Result<(), IoError> {
    let labels = t.tuning.loops.iter().map(|l| format!("{} ({})", l.controller, l.output));
    let title = format!("Bode diagrams of the tuned loops of `{}`, each alone", plant.name());
    bode(out, &title, tu, labels.zip(t.bode.iter().cloned()).collect())
}

/// The report folder `dir` (made if missing): `tune.md` and `tune.html` (the table and the
/// diagrams), `tune.json` (the `--json` text) and `tune.svg`. Returns the files written.
///
/// # Errors
/// [`IoError::Draw`] when the folder or a file cannot be written.
pub fn write_report(dir: &Path, t: &TunedLoops, plant: &Plant, tu: &TimeUnit) -> Result<Vec<String>, IoError> {
    std::fs::create_dir_all(dir).map_err(|e| IoError::Draw(format!("{}: {e}", dir.display())))?;
    let mut written = vec![super::write(dir, "tune.json", &json(t, tu)?)?];
    plot(&dir.join("tune.svg"), t, plant, tu)?;
    written.push("tune.svg".to_string());
    let md = format!("```text\n{}```\n\n![each loop's Bode diagram](tune.svg)\n", text(t, plant, tu));
    written.push(super::write(dir, "tune.html", &crate::html::markdown_to_html("Tuning", &md))?);
    written.push(super::write(dir, "tune.md", &md)?);
    Ok(written)
}

/// A transfer-function model's tuning (SI) as the table `plantwide tune --tf` prints, times in
/// `tu`; `file` names the model.
pub fn model_text(t: &Tuning, model: &TfModel, file: &str, tu: &TimeUnit) -> String {
    let mut out = String::new();
    model_table(&mut out, &t.clone().in_time_unit(tu.seconds), model, file, tu);
    out
}

/// Draw the Bode diagrams of `loops` (label, diagram with SI frequencies) to `out`, ω in rad per
/// `tu`.
///
/// # Errors
/// [`IoError::PlotKind`] or [`IoError::Draw`] when the file cannot be written.
pub fn bode(out: &Path, title: &str, tu: &TimeUnit, loops: Vec<(String, Bode)>) -> Result<(), IoError> {
    let drawn: Vec<BodeLoop> = loops
        .into_iter()
        .map(|(label, b)| {
            let b = b.in_time_unit(tu.seconds);
            let m = b.margins;
            BodeLoop {
                label,
                gain_crossover: m.gain_crossover.zip(m.phase_margin),
                phase_crossover: m.phase_crossover.zip(m.gain_margin),
                omega: b.omega,
                magnitude_db: b.magnitude_db,
                phase_deg: b.phase_deg,
            }
        })
        .collect();
    write_bode(out, title, &format!("ω [rad/{}]", tu.name), &drawn)
}

fn loops_table(out: &mut String, t: &FlowsheetTuning, plant: &Plant, tu: &TimeUnit) {
    match t.detuning_factor {
        Some(f) => w!(
            out,
            "tuning of `{}`: {} (Luyben 1986), detuning factor F = {f:.4}{}\n",
            plant.name(),
            t.method,
            raised(t.unstable_at)
        ),
        None => w!(out, "tuning of `{}`: {}\n", plant.name(), t.method),
    }
    if let Some(f) = t.detuning_raised_from {
        w!(
            out,
            "detuning raised from F = {f:.4}: the plant's exact linear model showed a loop alone unstable at it; \
             doubled until each such loop keeps a {MIN_PHASE_MARGIN:.0}° phase margin\n"
        );
    }
    let u = &tu.name;
    w!(
        out,
        "{:<18} {:<18} {:>22} {:>11} {:>22} {:>11} {:>11}  action",
        "controller",
        "measurement",
        "Ku",
        format!("Pu [{u}]"),
        "Kc",
        format!("τI [{u}]"),
        format!("τD [{u}]")
    );
    let opt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.5}"));
    // Ku is written like Kc: in the unit of the file's `kc`.
    for l in &t.loops {
        let warn = l.file_action.map_or(String::new(), |f| format!("  (the file has {f}: the loop would run away)"));
        w!(
            out,
            "{:<18} {:<18} {:>22} {:>11} {:>22} {:>11} {:>11}  {}{warn}",
            l.controller,
            l.output,
            l.ku.map_or("-".to_string(), |ku| kc_text(plant, &l.controller, ku)),
            opt(l.pu),
            kc_text(plant, &l.controller, l.kc),
            opt(l.tau_i),
            opt(l.tau_d),
            l.action
        );
        let pv_unit = plant.var(&l.output).map_or(String::new(), |v| plant.vars()[v].spec.dim.to_string());
        details(out, l, u, &pv_unit);
    }
}

/// The test behind a loop's settings: the relay cycle, the fitted model, the averaging design.
fn details(out: &mut String, l: &FlowsheetLoop, u: &str, pv_unit: &str) {
    if let Some(r) = &l.relay {
        w!(
            out,
            "  relay: {} cycles after {} switches, amplitude {:.5e}, period spread {:.2} %, amplitude spread {:.2} %, \
             time above the steady value {:.1} % of the period",
            r.cycles,
            r.switches,
            r.amplitude,
            100.0 * r.period_spread,
            100.0 * r.amplitude_spread,
            100.0 * r.duty
        );
        if let Some(path) = &r.limited_by {
            w!(
                out,
                "  relay amplitude {:.5e} (the output's SI unit), half the move that would take `{path}` past its \
                 bound at steady state: less than the default 5 % of the output",
                r.relay_amplitude
            );
        }
    }
    if let Some(f) = &l.fit {
        let model = serde_json::to_string(&f.model).unwrap_or_default();
        let settled =
            if l.settled == Some(false) { "; the response had not settled: the fit extrapolates" } else { "" };
        w!(out, "  fit ({u}): {model}, R² = {:.4}, RMSE/max = {:.2e}{settled}", f.r2, f.nrmse);
        if let Some(i) = &l.initial_fit {
            w!(
                out,
                "  lag-dominant: dead time {:.5e} {u} from the integrating model fitted to the response's first {} points \
                 (R² = {:.4}), the slow approach fitted over the whole test",
                i.model.dead_time(),
                i.points,
                i.r2
            );
        }
    }
    if let (Some(from), Some(tc)) = (l.tau_c_raised_from, l.tau_c) {
        w!(
            out,
            "  τc raised from the fitted dead time {} {u} to {} {u} for a {:.0}° phase margin: the plant's exact linear \
             model showed the default's loop unstable (the fit does not describe the response at that time scale)",
            significant(from),
            significant(tc),
            plantwide_studies::tune::flowsheet::MIN_PHASE_MARGIN
        );
    }
    if let Some(c) = &l.linearity {
        w!(out, "{}", linearity_line(c));
    }
    if let Some(av) = &l.averaging {
        w!(out, "  averaging {:?}: largest level deviation {} {pv_unit} at {:.4} {u}", av.form, av.band, av.time);
        if let Some(from) = av.band_narrowed_from {
            w!(
                out,
                "  band narrowed from the default {} {pv_unit} (a quarter of the holdup): at that band's time scale other \
                 loops move the level as well; this one keeps it a single integrator (a band given explicitly is kept)",
                significant(from)
            );
        }
    }
    if let Some(m) = &l.margins {
        w!(out, "  {}", margins_line(m, u, "on the plant's linear model, the tuned loops open"));
    }
}

/// The note on a BLT factor raised for a stable closed loop (empty if it was not).
fn raised(unstable_at: Option<f64>) -> String {
    unstable_at.map_or(String::new(), |f| {
        format!(
            " (raised from F = {f:.4}, which met the log-modulus target but left the loops unstable by the \
             generalized Nyquist criterion)"
        )
    })
}

/// A loop's margins as one line (`GM 3.14 at ω = 0.785 rad/min, PM 61.4° at ω = 0.25 rad/min`).
fn margins_line(m: &plantwide_studies::tune::margins::Margins, u: &str, alone: &str) -> String {
    let gm = match (m.gain_margin, m.phase_crossover) {
        (Some(gm), Some(w)) => format!("GM {} at ω = {} rad/{u}", significant(gm), significant(w)),
        _ => "GM ∞ (the phase never reaches −180° where |L| < 1)".to_string(),
    };
    let pm = match (m.phase_margin, m.gain_crossover) {
        (Some(pm), Some(w)) => format!("PM {:.1}° at ω = {} rad/{u}", pm, significant(w)),
        _ => "no gain crossover (|L| never falls through 1)".to_string(),
    };
    format!("margins (this loop alone, {alone}): {gm}, {pm}")
}

/// The step tests behind a fit against the linearized gain: the step the fit comes from, and the
/// larger ones before it whose responses left the linear range.
fn linearity_line(c: &Linearity) -> String {
    let line = |t: &StepTry| {
        format!(
            "step {}: gain {}, {} % off",
            significant(t.step),
            significant(t.gain),
            significant(100.0 * t.gain_error)
        )
    };
    let mut s = format!("  linearized gain G(0) = {}", significant(c.linear_gain));
    if let Some((last, before)) = c.tests.split_last() {
        s.push_str(&format!("; fitted on the {}", line(last)));
        if !before.is_empty() {
            let tried: Vec<String> = before.iter().map(line).collect();
            s.push_str(&format!("; larger steps left the linear range ({})", tried.join("; ")));
        }
    }
    s
}
fn model_table(out: &mut String, t: &Tuning, model: &TfModel, file: &str, tu: &TimeUnit) {
    let what = match (t.detuning_factor, t.max_lcm_db, t.peak_omega) {
        (Some(f), Some(db), Some(w)) => format!(
            "BLT (Luyben 1986): detuning factor F = {f:.4}, biggest log modulus {db:.3} dB at ω = {w:.4} rad/{}{}",
            tu.name,
            raised(t.unstable_at)
        ),
        _ if t.method == TuneMethod::TyreusLuyben => "Tyreus–Luyben PI, each loop tuned alone".to_string(),
        _ => "Ziegler–Nichols PI, each loop tuned alone".to_string(),
    };
    w!(out, "tuning of `{}` (transfer-function model {})", model.name, file);
    w!(out, "{what}\n");
    let unit = |name: &str| model.inputs.iter().chain(&model.outputs).find(|s| s.name == name).map(|s| s.unit.clone());
    let w_out = t.loops.iter().map(|l| l.output.len()).chain([6]).max().unwrap_or(6);
    let w_in = t.loops.iter().map(|l| l.input.len()).chain([5]).max().unwrap_or(5);
    let u = &tu.name;
    w!(
        out,
        "{:<w_out$}  {:<w_in$}  {:>12}  {:>12}  {:>12}  {:>12}  gain unit",
        "output",
        "input",
        "Ku",
        format!("Pu [{u}]"),
        "Kc",
        format!("τI [{u}]")
    );
    for l in &t.loops {
        let gain_unit = match (unit(&l.input), unit(&l.output)) {
            (Some(i), Some(o)) if !i.is_empty() || !o.is_empty() => format!("({i})/({o})"),
            _ => String::new(),
        };
        w!(
            out,
            "{:<w_out$}  {:<w_in$}  {:>12.5}  {:>12.5}  {:>12.5}  {:>12.5}  {gain_unit}",
            l.output,
            l.input,
            l.ku,
            l.pu,
            l.kc,
            l.tau_i
        );
        if let Some(m) = &l.margins {
            w!(out, "  {}", margins_line(m, u, "its element under its PI, the other loops open"));
        }
    }
}
