//! `plantwide size FILE --vessel V --disturbance PATH=±Δ --level-band Δh --max-outflow-rate r
//! [--json] [--plot OUT]`: the cross-section and level controller (P, critically damped PI,
//! optimal averaging) that keep a vessel's level within `±Δh` and its outflow's rate under `r`,
//! each verified by a nonlinear run; `--candidates V1,V2,…` ranks where surge capacity does it
//! with the least volume.

use std::path::{Path, PathBuf};

use plantwide::flowsheet::Plant;
use plantwide::io::plot::{Overlay, write_bars, write_responses};
use plantwide::studies::size::{
    Attenuation, CandidateRanking, Design, Disturbance, PARTS_PER_VESSEL, Progress, RankedCandidate, Shape, SizeError,
    SizeRequest, VesselSizing, rank_candidates_observed, size_vessel_observed,
};
use plantwide::units::{Dimension, Display, UnitSystem, parse_quantity_as};

use super::CliError;
use super::steady::{converge, load_with_overrides};

/// Arguments of `plantwide size`.
#[derive(Debug, clap::Args)]
pub struct SizeArgs {
    /// Flowsheet file (JSON).
    #[arg(value_name = "FILE")]
    file: PathBuf,
    /// The vessel: a tank, CSTR or flash; a column's `COL.drum` or `COL.sump`; or a stream, for a
    /// new surge tank on it.
    #[arg(long, value_name = "V", required_unless_present = "candidates", conflicts_with = "candidates")]
    vessel: Option<String>,
    /// Rank these vessels (same forms as --vessel) by the surge volume they need.
    #[arg(long, value_name = "V1,V2,…", value_delimiter = ',')]
    candidates: Vec<String>,
    /// The disturbance, a step of an input: PATH=+x% or -x% (of its value), or an amount with its
    /// unit (PATH=+5 kmol/h, PATH=-2 K).
    #[arg(long, value_name = "PATH=±Δ", required_unless_present = "scenario")]
    disturbance: Option<String>,
    /// The disturbance as the one step, ramp or sinusoid of a scenario file (started at once from
    /// the steady state), instead of --disturbance.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["disturbance", "ramp", "sine", "attenuation"])]
    scenario: Option<PathBuf>,
    /// The disturbance as a ramp to the same change over this time, instead of a step.
    #[arg(long, value_name = "TIME", conflicts_with = "sine")]
    ramp: Option<String>,
    /// The disturbance as a sinusoid of amplitude Δ and this period, instead of a step.
    #[arg(long, value_name = "PERIOD")]
    sine: Option<String>,
    /// The largest allowed deviation of the level from its setpoint, either way (a length).
    #[arg(long, value_name = "Δh", allow_hyphen_values = true)]
    level_band: String,
    /// The largest allowed rate of change of the vessel's outflow (e.g. "5 kmol/h/min").
    #[arg(long, value_name = "r", allow_hyphen_values = true, required_unless_present = "attenuation")]
    max_outflow_rate: Option<String>,
    /// Instead of a rate limit: the outflow of the disturbance, a sinusoid of amplitude Δ at
    /// --period, may swing at most this fraction of the inflow's (in (0, 1)).
    #[arg(long, value_name = "RATIO", requires = "period", conflicts_with_all = ["max_outflow_rate", "ramp", "sine"], allow_hyphen_values = true)]
    attenuation: Option<f64>,
    /// The period of --attenuation.
    #[arg(long, value_name = "PERIOD", requires = "attenuation")]
    period: Option<String>,
    /// Length of each verification run (default: long enough for the design and the plant to settle).
    #[arg(long, value_name = "TIME")]
    duration: Option<String>,
    /// Override an input or unit field before converging (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
    /// Print JSON (SI units) instead of a table.
    #[arg(long)]
    json: bool,
    /// Write a plot here (.png or .svg): the designs' level and outflow, or the candidates' volumes.
    #[arg(long, value_name = "OUT")]
    plot: Option<PathBuf>,
    /// Report each design and run as it is done on stderr even when stderr is not a terminal (a
    /// terminal gets a progress bar without it).
    #[arg(long)]
    progress: bool,
}

fn size_error(e: SizeError) -> CliError {
    if e.is_user_error() { CliError::user(e.to_string()) } else { CliError::numerical(e.to_string()) }
}

/// Run `plantwide size`: the report is printed whole (a failed part marked where it stands), then
/// the command exits 2 when a part failed or the plot had nothing to show.
pub fn run(a: &SizeArgs, system: UnitSystem) -> Result<(), CliError> {
    let units = SizeUnits::new(system)?;
    let (plant, u) = load_with_overrides(&a.file, &a.set)?;
    let request = request(a, &plant)?;
    if let Some(out) = &a.plot {
        check_plot_path(out)?;
    }
    let x = converge(&plant, &u)?.x;
    let parts = PARTS_PER_VESSEL * a.vessel.as_ref().map_or(a.candidates.len(), |_| 1);
    let bar = progress_bar(parts as u64);
    let lines = a.progress && !std::io::IsTerminal::is_terminal(&std::io::stderr());
    let tell = |p: Progress<'_>| {
        bar.inc(1);
        let how = if p.failed { "failed" } else { "done" };
        let message = format!("`{}`: {} {how}", p.vessel, p.part);
        if lines {
            eprintln!("size: {}/{parts} {message}", bar.position());
        }
        bar.set_message(message);
    };
    let (failed, plotted) = if let Some(v) = &a.vessel {
        let s = size_vessel_observed(&plant, &x, v, &request, &tell);
        bar.finish_and_clear();
        let s = s.map_err(size_error)?;
        let plotted = a.plot.as_deref().map(|out| plot_designs(out, &s, &units)).transpose();
        print(a.json, &s, |s| table(s, &plant, &units))?;
        (s.failed, plotted)
    } else {
        let ranking = rank_candidates_observed(&plant, &x, &a.candidates, &request, &tell);
        bar.finish_and_clear();
        let ranking = ranking.map_err(size_error)?;
        let plotted = a.plot.as_deref().map(|out| plot_candidates(out, &ranking, &units)).transpose();
        print(a.json, &ranking, |r| ranking_table(r, &units))?;
        (ranking.failed, plotted)
    };
    let plot_error = plotted.err();
    match (super::screen::failed_parts("size", &failed), plot_error) {
        (Ok(()), None) => Ok(()),
        (Ok(()), Some(e)) => Err(e),
        (Err(e), None) => Err(e),
        (Err(e), Some(p)) => Err(CliError { message: format!("{}; {}", e.message, p.message), code: e.code }),
    }
}

/// Refuse a plot that could not be written before the runs, not after them: a name ending in
/// neither `.png` nor `.svg`, or a folder that does not exist.
fn check_plot_path(out: &Path) -> Result<(), CliError> {
    let ext = out.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("png" | "svg")) {
        return Err(CliError::user(format!("--plot {}: the plot file must end in .png or .svg", out.display())));
    }
    match out.parent().filter(|p| !p.as_os_str().is_empty()) {
        Some(dir) if !dir.is_dir() => Err(CliError::user(format!(
            "--plot {}: the folder {} does not exist (create it first)",
            out.display(),
            dir.display()
        ))),
        _ => Ok(()),
    }
}

/// A bar of `parts` on stderr, drawn only when stderr is a terminal (never on stdout; `--progress`
/// prints a line per part instead where it is not).
fn progress_bar(parts: u64) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(parts);
    bar.set_style(
        indicatif::ProgressStyle::with_template("sizing {pos}/{len} parts [{elapsed_precise}] {bar:30} {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.enable_steady_tick(std::time::Duration::from_millis(250));
    bar
}

/// `value` as JSON with `--json`, otherwise as the text `table` makes of it.
fn print<T: serde::Serialize>(json: bool, value: &T, table: impl Fn(&T) -> String) -> Result<(), CliError> {
    if json {
        let text = serde_json::to_string_pretty(value).map_err(|e| CliError::user(e.to_string()))?;
        outln!("{text}");
    } else {
        outln!("{}", table(value));
    }
    Ok(())
}

/// The request in SI, each argument named when it does not parse.
fn request(a: &SizeArgs, plant: &Plant) -> Result<SizeRequest, CliError> {
    let quantity = |flag: &str, text: &str, dim: Dimension| {
        parse_quantity_as(text, dim).map_err(|e| CliError::user(format!("{flag} {text}: {e}")))
    };
    let level_band = quantity("--level-band", &a.level_band, Dimension::LENGTH)?;
    let max_outflow_rate = match &a.max_outflow_rate {
        Some(r) => quantity("--max-outflow-rate", r, Dimension::MOLAR_FLOW / Dimension::TIME)?,
        None => f64::NAN,
    };
    let attenuation = match (a.attenuation, &a.period) {
        (Some(ratio), Some(p)) => Some(Attenuation { ratio, period: quantity("--period", p, Dimension::TIME)? }),
        _ => None,
    };
    let duration = a.duration.as_deref().map(|d| quantity("--duration", d, Dimension::TIME)).transpose()?;
    if duration.is_some_and(|d| d.is_nan() || d <= 0.0) {
        return Err(CliError::user("--duration: must be a positive time"));
    }
    let time = |flag: &str, t: &Option<String>| t.as_deref().map(|t| quantity(flag, t, Dimension::TIME)).transpose();
    let shape = match (time("--ramp", &a.ramp)?, time("--sine", &a.sine)?) {
        (Some(duration), _) => Shape::Ramp { duration },
        (None, Some(period)) => Shape::Sine { period },
        (None, None) => Shape::Step,
    };
    let disturbance = match (&a.disturbance, &a.scenario) {
        (Some(d), _) => disturbance(d, plant, shape)?,
        (None, Some(file)) => from_scenario(file, plant)?,
        (None, None) => return Err(CliError::user("give --disturbance PATH=±Δ or --scenario FILE")),
    };
    Ok(SizeRequest { disturbance, level_band, max_outflow_rate, attenuation, duration })
}

/// The disturbance of scenario file `file`.
fn from_scenario(file: &Path, plant: &Plant) -> Result<Disturbance, CliError> {
    let name = file.display().to_string();
    let text = std::fs::read_to_string(file).map_err(|e| CliError::user(format!("--scenario {name}: {e}")))?;
    let spec =
        plantwide::flowsheet::scenario::parse_scenario(&text, &name).map_err(|e| CliError::user(e.to_string()))?;
    let scenario =
        plantwide::flowsheet::scenario::resolve(&spec, plant, &name).map_err(|e| CliError::user(e.to_string()))?;
    Disturbance::from_scenario(&scenario, plant).map_err(|e| CliError::user(format!("{name}: {e}")))
}

/// `PATH=+x%`, `PATH=-x%` or an amount with its unit (`PATH=+5 kmol/h`), read by the studies' one
/// parser and judged by its range rule ([`plantwide::studies::disturbance`]); sizing verifies one
/// step, so `±` is refused.
fn disturbance(text: &str, plant: &Plant, shape: Shape) -> Result<Disturbance, CliError> {
    use plantwide::studies::disturbance::{Direction, Disturbance as Step};
    let bad = |why: String| CliError::user(format!("--disturbance {why}"));
    let d: Step = text.parse().map_err(|e| bad(format!("{e}")))?;
    if d.direction == Direction::Both {
        return Err(bad(format!(
            "{}: sizing verifies one step (the closed forms hold for either sign); give its direction, {} +{} or {} -{}",
            d.label(),
            d.path,
            d.shown,
            d.path,
            d.shown
        )));
    }
    d.check(plant).map_err(|e| bad(e.to_string()))?;
    let i = plantwide::flowsheet::overrides::resolve_input(plant, &d.path)
        .ok_or_else(|| bad(format!("`{}` is no input of the flowsheet", d.path)))?;
    Ok(Disturbance { path: d.path.clone(), change: d.change(plant.inputs()[i].value), shape })
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
    fn new(system: UnitSystem) -> Result<SizeUnits, CliError> {
        let d = |dim: Dimension| Display::new(&system.unit_for(dim)).map_err(|e| CliError::user(e.to_string()));
        Ok(SizeUnits {
            system,
            flow: d(Dimension::MOLAR_FLOW)?,
            length: d(Dimension::LENGTH)?,
            area: d(Dimension::AREA)?,
            volume: d(Dimension::VOLUME)?,
            amount: d(Dimension::AMOUNT)?,
            time: Display::new("min").map_err(|e| CliError::user(e.to_string()))?,
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
        plantwide::studies::size::VERIFY_TOLERANCE * 100.0
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

/// The wording of the file's vessel's verdict ([`plantwide::studies::size::verdict`]); a column's
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
fn plot_designs(out: &Path, s: &VesselSizing, u: &SizeUnits) -> Result<(), CliError> {
    let shown: Vec<&Design> = s.designs.iter().filter(|d| d.verified.failure.is_none()).collect();
    if shown.is_empty() {
        return Err(CliError::numerical(format!(
            "--plot {}: not written: no design of `{}` has a verified run to plot (each is marked failed in the report)",
            out.display(),
            s.vessel
        )));
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
        .map_err(|e| CliError::user(e.to_string()))
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
fn plot_candidates(out: &Path, r: &CandidateRanking, u: &SizeUnits) -> Result<(), CliError> {
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
        .map_err(|e| CliError::user(e.to_string()))
}
