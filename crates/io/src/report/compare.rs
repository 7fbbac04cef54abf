//! The report of a comparison ([`Comparison`]): markdown with one table per question (energy,
//! control structure, stability, recycles, sensitivity, closed-loop responses), and the report
//! folder (`compare.md`, `compare.html`, `compare.json`, the energy bars, the relative gains, one
//! figure of responses per disturbance). `plantwide compare` prints [`text`] (or
//! [`super::json`] with `--json`); `plantwide.compare` returns the same.

use std::path::Path;

use faer::Mat;
use plantwide_analysis::measures::{rga, rows};
use plantwide_flowsheet::Plant;
use plantwide_studies::compare::{Comparison, Scheme};
use plantwide_studies::screen::pairings::mpc::MpcAlternative;
use plantwide_studies::screen::pairings::{DisturbanceRun, STEP_AT};
use plantwide_units::UnitSystem;

use super::shown::Shown;
use crate::IoError;
use crate::plot::{LabelledMatrix, Overlay, write_bars, write_matrices};

/// The display units of `c`: each output in the unit it names (`PATH@unit`) or in `system`'s, and
/// each loop's and MPC's CVs and MVs in `system`'s, looked up in the first of `plants` that has
/// the path.
///
/// # Errors
/// [`IoError::DisplayUnit`] for an output's unit that is no unit of its path.
pub fn shown(plants: &[Plant], outputs: &[String], c: &Comparison, system: UnitSystem) -> Result<Shown, IoError> {
    let outputs = outputs.iter().map(|o| {
        let (p, u) = plantwide_analysis::select::split_unit(o);
        (p.to_string(), u.map(String::from))
    });
    let loops = c.schemes.iter().flat_map(|s| {
        let pi = s.loops.iter().flat_map(|l| [l.cv.clone(), l.mv.clone()]);
        let mpc = s.mpc.iter().flat_map(|m| m.cvs.iter().chain(&m.mvs).cloned());
        pi.chain(mpc).map(|p| (p, None)).collect::<Vec<_>>()
    });
    Shown::new(plants, outputs.chain(loops), system)
}

/// The comparison as the markdown `plantwide compare` prints.
pub fn text(c: &Comparison, shown: &Shown) -> String {
    markdown(c, shown)
}

/// The report folder `dir` (made if missing): `compare.json` (the `--json` text), `energy.png`,
/// `rga.png` (when a scheme has loops), `responses_<k>.png` per disturbance, `compare.md` and
/// `compare.html`. Returns the files written.
///
/// # Errors
/// [`IoError::Draw`] when the folder or a file cannot be written.
pub fn write_report(dir: &Path, c: &Comparison, shown: &Shown) -> Result<Vec<String>, IoError> {
    std::fs::create_dir_all(dir).map_err(|e| IoError::Draw(format!("{}: {e}", dir.display())))?;
    let mut written = vec![super::write(dir, "compare.json", &super::json(c)?)?];
    let bars: Vec<(String, f64)> = c.schemes.iter().map(|s| (s.name.clone(), s.energy.heating / 1e3)).collect();
    write_bars(&dir.join("energy.png"), "heating duty", "kW", &bars)?;
    written.push("energy.png".to_string());
    let mut figures = String::from("\n![heating duty](energy.png)\n");
    if write_rga(&dir.join("rga.png"), c)? {
        figures.push_str("\n![relative gains](rga.png)\n");
        written.push("rga.png".to_string());
    }
    for name in write_responses(dir, c, shown)? {
        figures.push_str(&format!("\n![responses]({name})\n"));
        written.push(name);
    }
    let md = format!("{}{figures}", markdown(c, shown));
    written.push(super::write(dir, "compare.html", &crate::html::markdown_to_html("Schemes compared", &md))?);
    written.push(super::write(dir, "compare.md", &md)?);
    Ok(written)
}

/// The quality loops' relative gains of every scheme that has loops, side by side; false (and no
/// file) when none has.
fn write_rga(file: &Path, c: &Comparison) -> Result<bool, IoError> {
    let matrices: Vec<LabelledMatrix> = c
        .schemes
        .iter()
        .filter(|s| !s.gain.is_empty())
        .map(|s| {
            let g = Mat::from_fn(s.gain.len(), s.gain[0].len(), |i, j| s.gain[i][j]);
            LabelledMatrix {
                label: s.name.clone(),
                values: rga(g.as_ref()).ok().map(|l| rows(l.as_ref())),
                rows: s.loops.iter().map(|l| l.cv.clone()).collect(),
                cols: s.loops.iter().map(|l| l.mv.clone()).collect(),
            }
        })
        .collect();
    if matrices.is_empty() {
        return Ok(false);
    }
    write_matrices(file, "relative gains of the quality loops", &matrices)?;
    Ok(true)
}

/// Run `d` of a scheme's closed-loop runs, if it went through.
fn ran(s: &Scheme, d: usize) -> Option<&DisturbanceRun> {
    s.runs().and_then(|t| t.runs.get(d)).filter(|r| r.failure.is_none() && r.lost.is_none())
}

/// One figure per disturbance: a panel per CV and output, a curve per scheme (schemes whose runs
/// share the time grid; all do when the run length is common).
fn write_responses(dir: &Path, c: &Comparison, shown: &Shown) -> Result<Vec<String>, IoError> {
    let Some(first) = c.schemes.iter().find_map(Scheme::runs) else { return Ok(Vec::new()) };
    let mut names = Vec::new();
    for d in 0..first.runs.len() {
        // The time grid of the first scheme whose run went through (a failed run has none).
        let ran = |s| ran(s, d);
        let Some(run) = c.schemes.iter().find_map(ran) else { continue };
        let paths: Vec<&String> = run.cvs.iter().map(|f| &f.cv).collect();
        let panels: Vec<Overlay> = paths
            .iter()
            .map(|&p| Overlay {
                label: shown.label(p),
                curves: c
                    .schemes
                    .iter()
                    .filter_map(|s| {
                        let r = ran(s)?;
                        let k = r.cvs.iter().position(|f| &f.cv == p)?;
                        let series = r.series[k].iter().map(|v| shown.value(p, *v)).collect();
                        (r.times.len() == run.times.len()).then(|| (s.name.clone(), series))
                    })
                    .collect(),
                ..Overlay::default()
            })
            .collect();
        let times: Vec<f64> = run.times.iter().map(|t| t / 3600.0).collect();
        let name = format!("responses_{}.png", d + 1);
        let step = STEP_AT * times.last().copied().unwrap_or(0.0);
        crate::plot::write_responses(
            &dir.join(&name),
            &format!("{}: closed-loop responses (tuning in compare.md)", run.disturbance),
            "time [h]",
            &times,
            &panels,
            &[(step, run.disturbance.clone())],
        )?;
        names.push(name);
    }
    Ok(names)
}

fn sig(v: f64) -> String {
    if v == 0.0 || (v.abs() >= 1e-3 && v.abs() < 1e5) { format!("{v:.4}") } else { format!("{v:.4e}") }
}

/// The comparison as markdown: one table per question.
pub fn markdown(c: &Comparison, shown: &Shown) -> String {
    let mut t = String::from("# Schemes compared\n\n");
    t.push_str(&format!("## Verdict\n\n{}\n\n", c.verdict));
    t.push_str(&energy_table(c));
    t.push_str(&structure_table(c));
    t.push_str(&stability_table(c));
    t.push_str(&recycle_table(c));
    t.push_str(&sensitivity_table(c, shown));
    t.push_str(&response_table(c, shown));
    t
}

fn energy_table(c: &Comparison) -> String {
    let mut t = String::from(
        "## Energy at steady state\n\n| scheme | heating kW | cooling kW | recovered kW | utility cost $/yr | duties |\n|---|---|---|---|---|---|\n",
    );
    for s in &c.schemes {
        let e = &s.energy;
        let mut items: Vec<String> =
            e.duties.iter().map(|d| format!("{} {} {:.3} kW", d.path, d.kind, d.duty / 1e3)).collect();
        items.extend(e.other.iter().map(|o| format!("{} {} {}", o.path, sig(o.value), o.unit)));
        t.push_str(&format!(
            "| {} | {:.3} | {:.3} | {:.3} | {:.0} | {} |\n",
            s.name,
            e.heating / 1e3,
            e.cooling / 1e3,
            e.recovered / 1e3,
            s.cost.total,
            items.join("; ")
        ));
    }
    let p = &c.prices;
    t + &format!(
        "\nUtility cost: heating at {} $/GJ, cooling at {} $/GJ, {} h/yr, as asked; heat recovered costs nothing \
         here.\n\n",
        p.heating, p.cooling, p.hours
    )
}

fn structure_table(c: &Comparison) -> String {
    let mut t = String::from(
        "## Control structure (quality loops opened together; exact steady-state gains)\n\n| scheme | loops CV ← MV (relative gain) | NI | DIC | condition number |\n|---|---|---|---|---|\n",
    );
    for s in &c.schemes {
        for m in &s.mpc {
            t.push_str(&format!(
                "| {} | model predictive control `{}`: CVs {} by MVs {} (multivariable: no pairing) | – | – | {} |\n",
                s.name,
                m.controller,
                m.cvs.join(", "),
                m.mvs.join(", "),
                m.condition_number.map_or("–".into(), sig)
            ));
        }
        let Some(st) = &s.structure else {
            if s.mpc.is_empty() {
                t.push_str(&format!("| {} | no quality loops | – | – | – |\n", s.name));
            }
            continue;
        };
        let pairs: Vec<String> =
            st.pairs.iter().map(|p| format!("{} ← {} ({:.4})", p.cv, p.mv, p.relative_gain)).collect();
        t.push_str(&format!(
            "| {} | {} | {:.4} | {} | {} |\n",
            s.name,
            pairs.join("; "),
            st.niederlinski,
            if st.dic { "yes" } else { "no" },
            s.condition_number.map_or("–".into(), sig)
        ));
    }
    t + "\n"
}

fn modes_text(m: &plantwide_studies::compare::Modes) -> String {
    let unstable = if m.unstable.is_empty() {
        "stable".to_string()
    } else {
        let ev: Vec<String> = m.unstable.iter().map(|l| format!("{:.4e}{:+.4e}j", l[0], l[1])).collect();
        format!("**unstable or integrating: {} 1/s**", ev.join(", "))
    };
    let slow: Vec<String> = m.slowest.iter().map(|t| sig(*t)).collect();
    format!("{unstable}; slowest τ [s]: {}", slow.join(", "))
}

fn stability_table(c: &Comparison) -> String {
    let mut t = String::from(
        "## Stability (eigenvalues of the exact linearization)\n\n| scheme | as built (loops in auto) | quality loops in manual |\n|---|---|---|\n",
    );
    for s in &c.schemes {
        t.push_str(&format!(
            "| {} | {} | {} |\n",
            s.name,
            modes_text(&s.stability.as_built),
            modes_text(&s.stability.open_loop)
        ));
    }
    t + "\n"
}

fn recycle_table(c: &Comparison) -> String {
    let mut t = String::from("## Recycles\n\n| scheme | tears | loop gain |\n|---|---|---|\n");
    for s in &c.schemes {
        if s.recycles.is_empty() {
            t.push_str(&format!("| {} | none | – |\n", s.name));
        }
        for r in &s.recycles {
            let gain = r.loop_gain.map_or(format!("not estimated ({} passes)", r.passes), sig);
            t.push_str(&format!("| {} | {} | {gain} |\n", s.name, r.tears.join(", ")));
        }
    }
    t + "\n"
}

fn sensitivity_table(c: &Comparison, shown: &Shown) -> String {
    let mut t = String::from(
        "## Sensitivity (steady state at ± each disturbance, control structure active)\n\n| disturbance | output | scheme | low | base | high |\n|---|---|---|---|---|---|\n",
    );
    let value = |p: &str, v: Option<f64>| v.map_or("–".into(), |v| sig(shown.value(p, v)));
    let mut notes: Vec<String> = Vec::new();
    for s in &c.schemes {
        for r in &s.sensitivity {
            let failed = r.failures.iter().map(|f| format!("failed: {f}"));
            for f in r.no_steady_state.iter().cloned().chain(failed) {
                let note = format!("- {}: {f}", s.name);
                if !notes.contains(&note) {
                    notes.push(note);
                }
            }
            t.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} |\n",
                r.disturbance,
                shown.label(&r.output),
                s.name,
                value(&r.output, r.low),
                sig(shown.value(&r.output, r.base)),
                value(&r.output, r.high)
            ));
        }
    }
    if !notes.is_empty() {
        t.push_str(&format!("\nEnds without a steady state (–):\n{}\n", notes.join("\n")));
    }
    t + "\n"
}

fn response_table(c: &Comparison, shown: &Shown) -> String {
    let mut t = format!(
        "## Closed-loop responses (tuning below; runs of {})\n\n| scheme | disturbance | variable [unit] | IAE [unit·s] | largest deviation [unit] | settling time [s] | MVs at a limit |\n|---|---|---|---|---|---|---|\n",
        c.duration.map_or("–".into(), |d| format!("{} s", sig(d)))
    );
    for (label, d) in c.schemes.iter().flat_map(Scheme::tests) {
        if let Some(why) = &d.failure {
            t.push_str(&format!("| {label} | – | – | failed: {why} | | | |\n"));
            continue;
        }
        for run in &d.runs {
            if let Some(why) = &run.failure {
                t.push_str(&format!("| {label} | {} | – | failed: {why} | | | |\n", run.disturbance));
                continue;
            }
            if let Some(how) = &run.lost {
                t.push_str(&format!("| {label} | {} | – | cannot ride through: {how} | | | |\n", run.disturbance));
                continue;
            }
            for f in &run.cvs {
                t.push_str(&format!(
                    "| {} | {} | {} | {} | {} | {} | {} |\n",
                    label,
                    run.disturbance,
                    shown.label(&f.cv),
                    sig(shown.difference(&f.cv, f.iae)),
                    sig(shown.difference(&f.cv, f.max_deviation)),
                    f.settling_time.map_or("–".into(), sig),
                    if run.saturated.is_empty() { "none".to_string() } else { run.saturated.join(", ") }
                ));
            }
        }
    }
    let tuned: Vec<String> = c
        .schemes
        .iter()
        .filter_map(|s| {
            let d = s.structure.as_ref()?.dynamic.as_ref()?;
            let loops: Vec<String> = d
                .loops
                .iter()
                .map(|l| {
                    // u = Kc e in SI: in the display units, Kc · (one unit of the CV) / (one unit of the MV).
                    let kc = l.kc * shown.difference(&l.mv, 1.0) / shown.difference(&l.cv, 1.0);
                    let unit = format!("{}/{}", shown.unit(&l.mv), shown.unit(&l.cv));
                    format!("{} ← {}: Kc {} {unit} ({}), τI {} s", l.cv, l.mv, sig(kc), l.action, sig(l.tau_i))
                })
                .collect();
            let how = match (s.tuning, s.stability.open_loop_unstable) {
                ("blt", _) => "BLT",
                (_, true) => "the file's settings: unstable with its quality loops in manual, where BLT does not apply",
                _ => "the file's settings",
            };
            Some(format!("- {} ({how}): {}", s.name, loops.join("; ")))
        })
        .collect();
    let mpc = c.schemes.iter().flat_map(|s| s.mpc.iter().map(move |m| mpc_note(&s.name, m)));
    let tuned: Vec<String> = tuned.into_iter().chain(mpc).collect();
    if !tuned.is_empty() {
        t.push_str(&format!("\nTuning:\n{}\n", tuned.join("\n")));
    }
    t
}

/// A model predictive controller's settings and what its QP did over the runs.
pub(super) fn mpc_note(scheme: &str, m: &MpcAlternative) -> String {
    let samples: usize = m.qp.iter().map(|l| l.samples).sum();
    let solved: usize = m.qp.iter().map(|l| l.statuses.get("Solved").copied().unwrap_or(0)).sum();
    let mean = m.qp.iter().map(|l| l.mean_solve_time * l.samples as f64).sum::<f64>() / samples.max(1) as f64;
    let max = m.qp.iter().map(|l| l.max_solve_time).fold(0.0, f64::max);
    let at_limit: usize = m.qp.iter().map(|l| l.samples_at_limit).sum();
    format!(
        "- {scheme}: model predictive control `{}` every {} s, horizons P = {}, M = {}; over the runs {samples} QPs, \
         {solved} solved, mean solve time {:.3} ms (largest {:.3} ms), {at_limit} samples with an MV at a hard limit",
        m.controller,
        sig(m.sample_time),
        m.prediction_horizon,
        m.control_horizon,
        1e3 * mean,
        1e3 * max
    )
}
