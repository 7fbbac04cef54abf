//! `plantwide tune FILE --loop CTRL --method relay|zn|tl|simc|imc|averaging` and
//! `plantwide tune FILE --loops C1,C2,… --method blt`: tune the PID loops of a flowsheet at its
//! steady state and optionally write the settings into a copy of the file (`--write`).

use std::path::Path;

use plantwide::flowsheet::Plant;
use plantwide::model::limits::number;
use plantwide::studies::identify::number as significant;
use plantwide::studies::tune::averaging::AveragingForm;
use plantwide::studies::tune::flowsheet::{
    FlowsheetLoop, FlowsheetTuning, averaging_loop, blt_loops, edits, flowsheet_margins, kc_text,
};
use plantwide::studies::tune::loops::{Measurement, PlantLoop, inner_first, plant_loop, plant_loops};
use plantwide::studies::tune::plant_tests::{Linearity, StepTry};
use plantwide::units::{Dimension, parse_quantity_as};

use super::CliError;
use super::linearize::TimeUnit;
use super::steady::{converge, load_with_overrides};
use super::tune::{FormArg, MethodArg, TuneArgs, tune_error};

/// Tune the loops of `a.file`.
pub fn run(a: &TuneArgs, tu: &TimeUnit) -> Result<(), CliError> {
    let Some(file) = &a.file else { return Err(CliError::user("give a flowsheet FILE or --tf MODEL")) };
    let (plant, u) = load_with_overrides(file, &a.set)?;
    let names = loop_names(a)?;
    let loops: Vec<PlantLoop> = plant_loops(&plant, &names).map_err(tune_error)?;
    let x = converge(&plant, &u)?.x;
    let mut tuning = match a.method {
        MethodArg::Blt => blt_loops(&plant, &x, &loops, measurement(a)?).map_err(tune_error)?,
        _ => in_sequence(a, file, &plant, &loops, tu)?,
    };
    let diagrams = flowsheet_margins(&plant, &x, &mut tuning, measurement(a)?).map_err(tune_error)?;
    if let Some(out) = &a.plot {
        let labels = tuning.loops.iter().map(|l| format!("{} ({})", l.controller, l.output));
        let title = format!("Bode diagrams of the tuned loops of `{}`, each alone", plant.name());
        super::tune::plot_bode(out, &title, tu, labels.zip(diagrams).collect())?;
    }
    let refuted = tuning.loops.iter().any(|l| l.failure.is_some());
    if let Some(out) = a.write.as_ref().filter(|_| !refuted) {
        write(file, out, &plant, &tuning, tu)?;
    }
    let shown = tuning.clone().in_time_unit(tu.seconds);
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&shown).map_err(|e| CliError::user(e.to_string()))?);
    } else {
        print_table(&shown, &plant, tu);
    }
    let failed: Vec<String> =
        shown.loops.iter().filter_map(|l| l.failure.as_ref().map(|f| format!("`{}`: {f}", l.controller))).collect();
    match failed.is_empty() {
        true => Ok(()),
        false => Err(CliError::numerical(format!(
            "{}{}",
            failed.join("\n"),
            if a.write.is_some() { "\nnothing written" } else { "" }
        ))),
    }
}

/// The loops asked for: `--loop CTRL` or `--loops C1,C2,…` (BLT tunes them together, the other
/// methods one after another).
fn loop_names(a: &TuneArgs) -> Result<Vec<String>, CliError> {
    match (&a.loop_name, a.loops.is_empty()) {
        (None, false) => Ok(a.loops.clone()),
        (Some(l), true) => Ok(vec![l.clone()]),
        (Some(_), false) => Err(CliError::user("give either --loop CTRL or --loops C1,C2,…, not both")),
        (None, true) => Err(CliError::user("give the loop to tune: --loop CTRL (or --loops C1,C2,…)")),
    }
}

/// A single-loop method on each of `loops` in turn, cascade slaves before their masters
/// ([`inner_first`]): each loop's test runs on the plant with the loops tuned before it at their
/// new settings (the file's text edited as `--write` would, loaded and converged again — a P-only
/// loop given reset action moves the steady state).
fn in_sequence(
    a: &TuneArgs,
    file: &Path,
    plant: &Plant,
    loops: &[PlantLoop],
    tu: &TimeUnit,
) -> Result<FlowsheetTuning, CliError> {
    let text = plantwide::flowsheet::read_text(file).map_err(|e| CliError::user(e.to_string()))?;
    let user = |e: plantwide::flowsheet::OverrideError| CliError::user(e.to_string());
    let overrides = a.set.iter().map(|s| s.parse()).collect::<Result<Vec<_>, _>>().map_err(user)?;
    let name = file.display().to_string();
    let mut tuned: Option<FlowsheetTuning> = None;
    let mut current = plant.clone();
    for l in inner_first(plant, loops) {
        if let Some(t) = &tuned {
            let edited =
                plantwide::flowsheet::edit::edit_fields(&text, &name, &edits(plant, t, &tu.name).map_err(tune_error)?)
                    .map_err(|e| CliError::user(e.to_string()))?;
            current = plantwide::flowsheet::load_str_with(&edited, &name, &overrides).map_err(user)?;
        }
        let x = converge(&current, &current.input_values())?.x;
        let l = plant_loop(&current, &l.name).map_err(tune_error)?;
        let one = match a.method {
            MethodArg::Averaging => averaging(a, &current, &x, &l)?,
            m => super::tune_bench::run(a, &current, &x, &l, m)?,
        };
        match &mut tuned {
            Some(t) => t.loops.extend(one.loops),
            None => tuned = Some(one),
        }
    }
    tuned.ok_or_else(|| CliError::user("give the loop to tune: --loop CTRL (or --loops C1,C2,…)"))
}

/// An optional quantity option in SI.
/// A flag's quantity in SI, checked against the largest magnitude a quantity of its dimension may
/// have anywhere in a flowsheet ([`plantwide::model::limits::max_magnitude`]: 10⁶ mol/s for a
/// flow), the rule every value of a file and of `--set` passes.
pub(super) fn quantity(text: &Option<String>, flag: &str, dim: Dimension) -> Result<Option<f64>, CliError> {
    let check = |t: &String| {
        let v = parse_quantity_as(t, dim).map_err(|e| CliError::user(format!("--{flag} {t}: {e}")))?;
        let max = plantwide::model::limits::max_magnitude(dim);
        if v.is_nan() || v.abs() > max {
            let n = number;
            return Err(CliError::user(format!(
                "--{flag} {t}: {} {dim} is beyond ±{} {dim}, the range in which the models hold",
                n(v),
                n(max)
            )));
        }
        Ok(v)
    };
    text.as_ref().map(check).transpose()
}

pub(super) fn measurement(a: &TuneArgs) -> Result<Measurement, CliError> {
    let dead_time = quantity(&a.measurement_dead_time, "measurement-dead-time", Dimension::TIME)?.unwrap_or(0.0);
    let lag = quantity(&a.measurement_lag, "measurement-lag", Dimension::TIME)?.unwrap_or(0.0);
    if dead_time < 0.0 || lag < 0.0 {
        return Err(CliError::user("--measurement-dead-time and --measurement-lag must not be negative"));
    }
    Ok(Measurement { dead_time, lag })
}

fn averaging(a: &TuneArgs, plant: &Plant, x: &[f64], l: &PlantLoop) -> Result<FlowsheetTuning, CliError> {
    let dim = |v: usize| plant.vars()[v].spec.dim;
    let du = quantity(&a.flow_change, "flow-change", dim(l.op))?;
    let band = quantity(&a.level_band, "level-band", dim(l.pv))?;
    let form = match a.form {
        FormArg::P => AveragingForm::P,
        FormArg::Pi => AveragingForm::Pi,
    };
    averaging_loop(plant, x, l, du, band, form).map_err(tune_error)
}

/// Write `file` with the tuned settings to `out`.
fn write(file: &Path, out: &Path, plant: &Plant, t: &FlowsheetTuning, tu: &TimeUnit) -> Result<(), CliError> {
    let text = plantwide::flowsheet::read_text(file).map_err(|e| CliError::user(e.to_string()))?;
    let edits = edits(plant, t, &tu.name).map_err(tune_error)?;
    let name = file.display().to_string();
    let new =
        plantwide::flowsheet::edit::edit_fields(&text, &name, &edits).map_err(|e| CliError::user(e.to_string()))?;
    std::fs::write(out, new).map_err(|e| CliError::user(format!("{}: cannot write: {e}", out.display())))
}

fn print_table(t: &FlowsheetTuning, plant: &Plant, tu: &TimeUnit) {
    match t.detuning_factor {
        Some(f) => outln!(
            "tuning of `{}`: {} (Luyben 1986), detuning factor F = {f:.4}{}\n",
            plant.name(),
            t.method,
            raised(t.unstable_at)
        ),
        None => outln!("tuning of `{}`: {}\n", plant.name(), t.method),
    }
    let u = &tu.name;
    outln!(
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
        outln!(
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
        print_details(l, u, &pv_unit);
    }
}

/// The test behind a loop's settings: the relay cycle, the fitted model, the averaging design.
fn print_details(l: &FlowsheetLoop, u: &str, pv_unit: &str) {
    if let Some(r) = &l.relay {
        outln!(
            "  relay: {} cycles after {} switches, amplitude {:.5e}, period spread {:.2} %, amplitude spread {:.2} %, \
             time above the steady value {:.1} % of the period",
            r.cycles,
            r.switches,
            r.amplitude,
            100.0 * r.period_spread,
            100.0 * r.amplitude_spread,
            100.0 * r.duty
        );
    }
    if let Some(f) = &l.fit {
        let model = serde_json::to_string(&f.model).unwrap_or_default();
        let settled =
            if l.settled == Some(false) { "; the response had not settled: the fit extrapolates" } else { "" };
        outln!("  fit ({u}): {model}, R² = {:.4}, RMSE/max = {:.2e}{settled}", f.r2, f.nrmse);
        if let Some(i) = &l.initial_fit {
            outln!(
                "  lag-dominant: dead time {:.5e} {u} from the integrating model fitted to the response's first {} points \
                 (R² = {:.4}), the slow approach fitted over the whole test",
                i.model.dead_time(),
                i.points,
                i.r2
            );
        }
    }
    if let Some(c) = &l.linearity {
        outln!("{}", linearity_line(c));
    }
    if let Some(av) = &l.averaging {
        outln!("  averaging {:?}: largest level deviation {} {pv_unit} at {:.4} {u}", av.form, av.band, av.time);
    }
    if let Some(m) = &l.margins {
        outln!("  {}", margins_line(m, u, "on the plant's linear model, the tuned loops open"));
    }
}

/// The note on a BLT factor raised for a stable closed loop (empty if it was not).
pub(super) fn raised(unstable_at: Option<f64>) -> String {
    unstable_at.map_or(String::new(), |f| {
        format!(
            " (raised from F = {f:.4}, which met the log-modulus target but left the loops unstable by the \
             generalized Nyquist criterion)"
        )
    })
}

/// A loop's margins as one line (`GM 3.14 at ω = 0.785 rad/min, PM 61.4° at ω = 0.25 rad/min`).
pub(super) fn margins_line(m: &plantwide::studies::tune::margins::Margins, u: &str, alone: &str) -> String {
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
