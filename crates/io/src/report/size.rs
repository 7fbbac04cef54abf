//! The report of a sizing ([`Sizing`]): the designs' table or the candidates' ranking in the
//! display units of a [`UnitSystem`], the figure of the designs' runs or of the candidates' band
//! volumes, and the report folder (`report.md`, `size.json`, `size.svg`). `plantwide size` prints
//! [`text`] (or [`super::json`] with `--json`) and writes [`plot`]; `Plant.size` returns the same.

use std::path::Path;

use plantwide_flowsheet::Plant;
use plantwide_studies::size::{
    CandidateRanking, Design, RankedCandidate, Shape, Sizing, VERIFY_TOLERANCE, VesselSizing,
};
use plantwide_units::{Dimension, Display, UnitSystem};

use crate::IoError;
use crate::plot::{Overlay, write_bars, write_responses};

/// The sizing as a markdown table in `system`'s units: one vessel's designs, then the file's
/// vessel; or the candidates, best first, then the parts that failed.
///
/// # Errors
/// [`IoError::Draw`] if `system` has no display unit for a dimension shown.
pub fn text(s: &Sizing, plant: &Plant, system: UnitSystem) -> Result<String, IoError> {
    let u = SizeUnits::new(system)?;
    Ok(match s {
        Sizing::Vessel(v) => table(v, plant, &u),
        Sizing::Ranking(r) => ranking_table(r, &u),
    })
}

/// The figure at `out` (`.png` or `.svg`): the designs' level deviation and outflow after the
/// disturbance, or the candidates' optimal band volumes.
///
/// # Errors
/// [`IoError::NothingToPlot`] when no design has a verified run (each is marked failed in the
/// report); [`IoError::PlotKind`] or [`IoError::Draw`] when the file cannot be written.
pub fn plot(out: &Path, s: &Sizing, system: UnitSystem) -> Result<(), IoError> {
    let u = SizeUnits::new(system)?;
    match s {
        Sizing::Vessel(v) => plot_designs(out, v, &u),
        Sizing::Ranking(r) => plot_candidates(out, r, &u),
    }
}

/// The report folder `dir` (made if missing): `size.md` and `size.html` (the table and the
/// figure), `size.json` (the `--json` text) and `size.svg`. A figure with nothing to draw is left
/// out and the report says why (its parts are listed as failed in the result). Returns the files
/// written.
///
/// # Errors
/// [`IoError::Draw`] when the folder or a file cannot be written.
pub fn write_report(dir: &Path, s: &Sizing, plant: &Plant, system: UnitSystem) -> Result<Vec<String>, IoError> {
    std::fs::create_dir_all(dir).map_err(|e| IoError::Draw(format!("{}: {e}", dir.display())))?;
    let mut written = vec![super::write(dir, "size.json", &super::json(s)?)?];
    let figure = match plot(&dir.join("size.svg"), s, system) {
        Ok(()) => {
            written.push("size.svg".to_string());
            "![the designs' runs, or the candidates' volumes](size.svg)\n".to_string()
        }
        Err(IoError::NothingToPlot { why, .. }) => format!("no figure: {why}\n"),
        Err(e) => return Err(e),
    };
    let md = format!("{}\n{figure}", text(s, plant, system)?);
    written.push(super::write(dir, "size.html", &crate::html::markdown_to_html("Surge sizing", &md))?);
    written.push(super::write(dir, "size.md", &md)?);
    Ok(written)
}

fn opt(v: Option<f64>, scale: f64) -> String {
    v.map_or("–".into(), |v| format!("{:.4}", v * scale))
}

/// The display units of `size`: flows, levels, areas, volumes, amounts and times in the `--units`
/// system (a rate of change of a flow per minute).
struct SizeUnits {
    system: UnitSystem,
    flow: Display,
    length: Display,
    area: Display,
    volume: Display,
    amount: Display,
    time: Display,
}

impl SizeUnits {
    fn new(system: UnitSystem) -> Result<SizeUnits, IoError> {
        let d = |dim: Dimension| Display::new(&system.unit_for(dim)).map_err(|e| IoError::Draw(e.to_string()));
        Ok(SizeUnits {
            system,
            flow: d(Dimension::MOLAR_FLOW)?,
            length: d(Dimension::LENGTH)?,
            area: d(Dimension::AREA)?,
            volume: d(Dimension::VOLUME)?,
            amount: d(Dimension::AMOUNT)?,
            time: Display::new("min").map_err(|e| IoError::Draw(e.to_string()))?,
        })
    }
    /// A flow's rate of change \[mol/s²\] per minute, and its unit.
    fn rate(&self, si: f64) -> f64 {
        self.flow.difference(si) * 60.0
    }
    fn rate_unit(&self) -> String {
        format!("{}/min", self.flow.unit())
    }
    /// A level controller's gain \[mol/s per m\] in flow per length.
    fn kc(&self, si: f64) -> f64 {
        self.flow.difference(si) / self.length.difference(1.0)
    }
    /// A holdup controller's gain \[mol/s per mol\] in flow per amount.
    fn kc_holdup(&self, si: f64) -> f64 {
        self.flow.difference(si) / self.amount.difference(1.0)
    }
    /// A time \[s\] in minutes.
    fn minutes(&self, si: f64) -> String {
        format!("{} {}", sig(self.time.difference(si)), self.time.unit())
    }
}

/// Four decimals, or four significant digits in exponent form below 10⁻³ (a holdup loop's gain).
fn fixed(v: f64) -> String {
    if v != 0.0 && v.abs() < 1e-3 { format!("{v:.3e}") } else { format!("{v:.4}") }
}

/// Four significant digits, plain or in exponent form.
fn sig(v: f64) -> String {
    if v != 0.0 && v.is_finite() && (v.abs() < 1e-3 || v.abs() >= 1e6) {
        return format!("{v:.3e}");
    }
    let digits = if v == 0.0 || !v.is_finite() { 0 } else { (3 - v.abs().log10().floor() as i32).max(0) as usize };
    format!("{v:.digits$}")
}

/// `PATH +Δ unit, shape` in display units (the disturbed input's dimension in the `--units`
/// system, the shape's time in minutes).
fn disturbance_text(s: &VesselSizing, plant: &Plant, u: &SizeUnits) -> String {
    let dim = plant.input(&s.disturbance_path).map(|i| plant.inputs()[i].dim);
    let shown = dim.and_then(|d| Display::new(&u.system.unit_for(d)).ok());
    let change = match &shown {
        Some(d) => format!("{:+.6e} {}", d.difference(s.disturbance_change), d.unit()),
        None => format!("{:+.6e} (SI)", s.disturbance_change),
    };
    let shape = match s.shape {
        Shape::Step => "step".to_string(),
        Shape::Ramp { duration } => format!("ramp over {}", u.minutes(duration)),
        Shape::Sine { period } => format!("sinusoid of period {}", u.minutes(period)),
    };
    format!("{} {change}, {shape}", s.disturbance_path)
}

/// The designs as a markdown table, then the file's vessel.
fn table(s: &VesselSizing, plant: &Plant, u: &SizeUnits) -> String {
    let (f, l) = (u.flow.unit(), u.length.unit());
    let holdup = s.kind == "column_drum" || s.kind == "column_sump";
    let mut t = format!(
        "surge sizing of `{}` ({}; level controller `{}` on `{}`) for {}: outflow change {:.4e} {f}, \
         level band ±{:.4} {l}, rate limit {:.4e} {}, liquid {:.4e} {}/{}\n\n",
        s.vessel,
        s.kind,
        s.level_controller,
        s.outflow,
        disturbance_text(s, plant, u),
        u.flow.difference(s.flow_change),
        u.length.difference(s.level_band),
        u.rate(s.max_outflow_rate),
        u.rate_unit(),
        u.volume.difference(s.liquid_molar_volume) / u.amount.difference(1.0),
        u.volume.unit(),
        u.amount.unit()
    );
    if holdup {
        t.push_str(&format!(
            "The column model gives its {} a holdup, not a level: each design is a vertical drum of the area shown \
             holding the band volume over the level band, its controller measuring the holdup (kc per {} held; \
             levels below are the drum's). The area is the least that holds the limits: where the normal holdup \
             stands too deep in it, a wider drum of the same band holds them too, its outflow slower.\n\n",
            if s.kind == "column_drum" { "drum" } else { "base" },
            u.amount.unit()
        ));
    }
    let kc_unit = if holdup { format!("{f}/{}", u.amount.unit()) } else { format!("{f}/{l}") };
    let normal = if holdup { format!(" normal holdup [{}] (its depth) |", u.amount.unit()) } else { String::new() };
    t.push_str(&format!(
        "| controller | area [{}] | band volume [{}] |{normal} kc [{kc_unit}] | τI [{}] | max level deviation [{l}] | \
         max outflow rate [{}] | meets (to {} % of the limits) |\n",
        u.area.unit(),
        u.volume.unit(),
        u.time.unit(),
        u.rate_unit(),
        VERIFY_TOLERANCE * 100.0
    ));
    t.push_str(if holdup { "|---|---|---|---|---|---|---|---|---|\n" } else { "|---|---|---|---|---|---|---|---|\n" });
    for d in &s.designs {
        t.push_str(&design_row(d, holdup.then_some(s.liquid_molar_volume), u));
    }
    if let Some(a) = &s.attenuation {
        t.push_str(&format!(
            "\nperiodic swing at {} (asked: outflow ≤ {} of the inflow; `meets` is judged on it, the peaks above \
             include the start from rest):\n",
            u.minutes(a.period),
            a.ratio
        ));
        for d in &s.designs {
            t.push_str(&format!(
                "  {:<8} attenuation {}, level amplitude {} {l}\n",
                d.controller.name(),
                opt(d.verified.attenuation, 1.0),
                opt(d.verified.level_amplitude.map(|a| u.length.difference(a)), 1.0)
            ));
        }
    }
    let kept: Vec<String> = s
        .designs
        .iter()
        .filter_map(|d| {
            d.normal_level
                .map(|h| format!("{} {} {}", d.controller.name(), sig(u.length.difference(h)), u.length.unit()))
        })
        .collect();
    if !kept.is_empty() {
        t.push_str(&format!(
            "a reactor: each design's level setpoint keeps its liquid volume, and so its conversion, at the file's: {}\n",
            kept.join(", ")
        ));
    }
    t.push_str(&current_line(s, u));
    t
}

/// One design's row: its figures and verdict, or `failed` with the reason (never figures of a run
/// that has none).
fn design_row(d: &Design, v_l: Option<f64>, u: &SizeUnits) -> String {
    let holdup = v_l.is_some();
    let normal = match (v_l, d.normal_holdup) {
        (Some(v_l), Some(n)) => {
            format!(
                " {} ({} {}) |",
                fixed(u.amount.difference(n)),
                sig(u.length.difference(n * v_l / d.area)),
                u.length.unit()
            )
        }
        (Some(_), None) => " – |".to_string(),
        (None, _) => String::new(),
    };
    let kc = d.kc.map_or("–".into(), |k| fixed(if holdup { u.kc_holdup(k) } else { u.kc(k) }));
    let tau_i = d.tau_i.map_or("–".into(), |t| fixed(u.time.difference(t)));
    let v = &d.verified;
    let figures = match (v.max_level_deviation, v.max_outflow_rate, &v.failure) {
        (Some(dev), Some(rate), None) => {
            format!("{:.6} | {:.4e} | {}", u.length.difference(dev), u.rate(rate), if v.meets { "yes" } else { "NO" })
        }
        (_, _, why) => format!("– | – | failed: {}", why.as_deref().unwrap_or("no figures")),
    };
    format!(
        "| {} | {} | {} |{normal} {kc} | {tau_i} | {figures} |\n",
        d.controller.name(),
        fixed(u.area.difference(d.area)),
        fixed(u.volume.difference(d.band_volume)),
    )
}

/// The file's vessel (a new tank: the bare stream) through the disturbance, judged as the designs
/// are; a column's holdup, which has no level, shown in its amount and the band not judged.
fn current_line(s: &VesselSizing, u: &SizeUnits) -> String {
    let c = &s.current;
    let l = u.length.unit();
    let who = match s.kind {
        "new_surge_tank" => format!("without a tank on `{}`", s.vessel),
        _ => "as the file has it".to_string(),
    };
    let area = c.area.map_or(String::new(), |a| format!(" (area {:.4} {})", u.area.difference(a), u.area.unit()));
    if let Some(why) = &c.failure {
        return format!("\n{who}{area}: failed: {why}\n");
    }
    let mut figures = Vec::new();
    if let Some(d) = c.max_deviation {
        figures.push(format!("max deviation {:.4} {l}", u.length.difference(d)));
    }
    if let Some(d) = c.max_holdup_deviation {
        figures.push(format!(
            "max holdup deviation {:.4} {} (the column model has no drum geometry: the level band is not judged on the \
             file's {})",
            u.amount.difference(d),
            u.amount.unit(),
            if s.kind == "column_drum" { "drum" } else { "base" }
        ));
    }
    if let Some(r) = c.max_outflow_rate {
        figures.push(format!("max outflow rate {:.4e} {}", u.rate(r), u.rate_unit()));
    }
    let outside =
        c.outside.as_ref().map_or(String::new(), |o| format!(" ({o}: the vessel cannot take this disturbance)"));
    format!(
        "\n{who}{area}: {} — {}{outside}\n",
        figures.join(", "),
        current_words(c.meets, c.max_holdup_deviation.is_some())
    )
}

/// The wording of the file's vessel's verdict ([`plantwide_studies::size::verdict`]); a column's
/// holdup (`no_level`) is judged on the rate alone.
fn current_words(meets: Option<bool>, no_level: bool) -> &'static str {
    match (meets, no_level) {
        (Some(true), _) => "meets the limits",
        (Some(false), false) => "exceeds them",
        (Some(false), true) => "exceeds the rate limit (the band not judged)",
        (None, _) => "within the rate limit; the band not judged",
    }
}

/// A candidate's verdicts in words: whether it needs surge, and whether its optimal design holds
/// (the ranking's table and its plot say the same).
fn candidate_words(c: &RankedCandidate) -> (&'static str, &'static str) {
    let Some(s) = &c.sizing else { return ("–", "not sized") };
    let need = match (s.current.failure.is_some(), c.needs_surge) {
        (true, _) => "unknown (run failed)",
        (false, Some(true)) => "yes",
        (false, Some(false)) => "no",
        (false, None) => "not judged",
    };
    let optimal = s.designs.iter().find(|d| d.controller.name() == "optimal");
    let holds = match (optimal.map(|d| d.verified.failure.is_some()), c.optimal_meets) {
        (Some(true), _) => "failed",
        (_, Some(true)) => "holds",
        (_, Some(false)) => "does not hold",
        (_, None) => "–",
    };
    (need, holds)
}

/// The candidates, best first, then the parts that failed.
fn ranking_table(r: &CandidateRanking, u: &SizeUnits) -> String {
    let mut t = format!(
        "| rank | candidate | kind | outflow change [{}] | now: max level deviation [{}] | now: max rate [{}] | \
         needs surge | optimal band volume [{v}] | optimal design | P band volume [{v}] |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
        u.flow.unit(),
        u.length.unit(),
        u.rate_unit(),
        v = u.volume.unit()
    );
    for c in &r.candidates {
        let Some(s) = &c.sizing else {
            t.push_str(&format!(
                "| – | {} | – | – | – | – | – | – | failed: {} | – |\n",
                c.candidate.as_deref().unwrap_or("?"),
                c.failure.as_deref().unwrap_or("")
            ));
            continue;
        };
        let vol = |name: &str| {
            s.designs
                .iter()
                .find(|d| d.controller.name() == name)
                .map_or("–".into(), |d| fixed(u.volume.difference(d.band_volume)))
        };
        let (need, holds) = candidate_words(c);
        t.push_str(&format!(
            "| {} | {} | {} | {:.4e} | {} | {} | {need} | {} | {holds} | {} |\n",
            c.rank.map_or("–".into(), |k| k.to_string()),
            s.vessel,
            s.kind,
            u.flow.difference(s.flow_change),
            now_level(s, u),
            s.current.max_outflow_rate.map_or("–".into(), |r| format!("{:.4e}", u.rate(r))),
            vol("optimal"),
            vol("p")
        ));
    }
    t.push_str(
        "\nneeds surge: the vessel as the file has it (a stream: as it is) exceeds the band or the rate limit; not \
         judged: a column's holdup has no level, and its rate is within. optimal: the optimal design's run holds \
         both.\n",
    );
    for f in &r.failed {
        t.push_str(&format!("\nfailed: {f}\n"));
    }
    t
}

/// The file's vessel's largest level deviation as the ranking shows it beside its verdict: a
/// column's holdup in its amount (no level, the band not judged), nothing for a bare stream.
fn now_level(s: &VesselSizing, u: &SizeUnits) -> String {
    let c = &s.current;
    match (c.max_deviation, c.max_holdup_deviation) {
        (Some(d), _) => format!("{:.4}", u.length.difference(d)),
        (None, Some(h)) => format!("– (holdup ±{} {}, no level)", sig(u.amount.difference(h)), u.amount.unit()),
        (None, None) if s.kind == "new_surge_tank" => "– (no vessel)".to_string(),
        (None, None) => "–".to_string(),
    }
}

/// Level deviation and outflow of the designs and the file's vessel, on one time grid (each
/// record held at its last value after it ends). A design or run without figures is left out (its
/// record ends where it failed, and a plot of it would read as an answer); when no design has
/// any, the plot is not written and the error says why.
fn plot_designs(out: &Path, s: &VesselSizing, u: &SizeUnits) -> Result<(), IoError> {
    let shown: Vec<&Design> = s.designs.iter().filter(|d| d.verified.failure.is_none()).collect();
    if shown.is_empty() {
        return Err(IoError::NothingToPlot {
            file: out.display().to_string(),
            why: format!(
                "no design of `{}` has a verified run to plot (each is marked failed in the report)",
                s.vessel
            ),
        });
    }
    let end = shown.iter().map(|d| d.verified.duration).fold(0.0, f64::max);
    let grid: Vec<f64> = (0..=1000).map(|k| end * k as f64 / 1000.0).collect();
    let at = |times: &[f64], ys: &[f64]| -> Vec<f64> { grid.iter().map(|&t| interpolate(times, ys, t)).collect() };
    let mut level = Vec::new();
    let mut flow = Vec::new();
    for d in &shown {
        let tr = &d.verified.trace;
        let name = format!("{} (A = {:.3} {})", d.controller.name(), u.area.difference(d.area), u.area.unit());
        let deviation: Vec<f64> = tr.deviation.iter().map(|v| u.length.difference(*v)).collect();
        let outflow: Vec<f64> = tr.outflow.iter().map(|v| u.flow.value(*v)).collect();
        level.push((name.clone(), at(&tr.times, &deviation)));
        flow.push((name, at(&tr.times, &outflow)));
    }
    if s.current.failure.is_none() {
        let tr = &s.current.trace;
        let outflow: Vec<f64> = tr.outflow.iter().map(|v| u.flow.value(*v)).collect();
        flow.push(("as in the file".to_string(), at(&tr.times, &outflow)));
    }
    let skipped: Vec<&str> =
        s.designs.iter().filter(|d| d.verified.failure.is_some()).map(|d| d.controller.name()).collect();
    let note = if skipped.is_empty() { String::new() } else { format!("; failed, not drawn: {}", skipped.join(", ")) };
    let band = u.length.difference(s.level_band);
    let level = Overlay {
        label: format!("level deviation [{}]", u.length.unit()),
        curves: level,
        band: Some((format!("band ±{band:.3} {}", u.length.unit()), -band, band)),
        ..Overlay::default()
    };
    let panels =
        [level, Overlay { label: format!("{} [{}]", s.outflow, u.flow.unit()), curves: flow, ..Overlay::default() }];
    let hours: Vec<f64> = grid.iter().map(|t| t / 3600.0).collect();
    let title = format!("surge designs of `{}` for a change of {}{note}", s.vessel, s.disturbance_path);
    write_responses(out, &title, "time after the step [h]", &hours, &panels, &[])
}

fn interpolate(times: &[f64], ys: &[f64], t: f64) -> f64 {
    let k = times.partition_point(|&s| s < t);
    match (k, times.get(k)) {
        (0, _) => ys.first().copied().unwrap_or(f64::NAN),
        (_, None) => ys.last().copied().unwrap_or(f64::NAN),
        (k, Some(&t1)) => {
            let (t0, y0, y1) = (times[k - 1], ys[k - 1], ys[k]);
            if t1 > t0 { y0 + (y1 - y0) * (t - t0) / (t1 - t0) } else { y1 }
        }
    }
}

/// The candidates' optimal band volumes as bars, labelled with the table's verdicts.
fn plot_candidates(out: &Path, r: &CandidateRanking, u: &SizeUnits) -> Result<(), IoError> {
    let bars: Vec<(String, f64)> = r
        .candidates
        .iter()
        .map(|c| match &c.sizing {
            Some(s) => {
                let (need, holds) = candidate_words(c);
                let volume = s
                    .designs
                    .iter()
                    .find(|d| d.controller.name() == "optimal")
                    .map_or(f64::NAN, |d| u.volume.difference(d.band_volume));
                let rank = c.rank.map_or("–".into(), |k| k.to_string());
                (format!("{rank} {} (needs surge: {need}; optimal: {holds})", s.vessel), volume)
            }
            None => (format!("– {} (not sized)", c.candidate.as_deref().unwrap_or("?")), f64::NAN),
        })
        .collect();
    write_bars(out, "band volume the optimal averaging controller needs", u.volume.unit(), &bars)
}
