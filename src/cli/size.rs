//! `plantwide size FILE --vessel V --disturbance PATH=±Δ --level-band Δh --max-outflow-rate r
//! [--json] [--plot OUT]`: the cross-section and level controller (P, critically damped PI,
//! optimal averaging) that keep a vessel's level within `±Δh` and its outflow's rate under `r`,
//! each verified by a nonlinear run; `--candidates V1,V2,…` ranks where surge capacity does it
//! with the least volume.

use std::path::{Path, PathBuf};

use plantwide::flowsheet::Plant;
use plantwide::io::plot::{Overlay, write_bars, write_overlays};
use plantwide::studies::size::{
    Attenuation, CandidateRanking, Disturbance, Shape, SizeError, SizeRequest, VesselSizing, rank_candidates,
    size_vessel,
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
}

fn size_error(e: SizeError) -> CliError {
    if e.is_user_error() { CliError::user(e.to_string()) } else { CliError::numerical(e.to_string()) }
}

/// Run `plantwide size`.
pub fn run(a: &SizeArgs, system: UnitSystem) -> Result<(), CliError> {
    let units = SizeUnits::new(system)?;
    plantwide::analysis::faer::set_global_parallelism(plantwide::analysis::faer::Par::Seq);
    let (plant, u) = load_with_overrides(&a.file, &a.set)?;
    let request = request(a, &plant)?;
    let x = converge(&plant, &u)?.x;
    if let Some(v) = &a.vessel {
        let s = size_vessel(&plant, &x, v, &request).map_err(size_error)?;
        if let Some(out) = &a.plot {
            plot_designs(out, &s, &units)?;
        }
        return print(a.json, &s, |s| table(s, &units));
    }
    let ranking = rank_candidates(&plant, &x, &a.candidates, &request).map_err(size_error)?;
    if let Some(out) = &a.plot {
        plot_candidates(out, &ranking)?;
    }
    print(a.json, &ranking, |r| ranking_table(r, &units))
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

/// The display units of `size`: flows, levels, areas, volumes and amounts in the `--units`
/// system (a rate of change of a flow per minute).
struct SizeUnits {
    flow: Display,
    length: Display,
    area: Display,
    volume: Display,
    amount: Display,
}

impl SizeUnits {
    fn new(system: UnitSystem) -> Result<SizeUnits, CliError> {
        let d = |dim: Dimension| Display::new(&system.unit_for(dim)).map_err(|e| CliError::user(e.to_string()));
        Ok(SizeUnits {
            flow: d(Dimension::MOLAR_FLOW)?,
            length: d(Dimension::LENGTH)?,
            area: d(Dimension::AREA)?,
            volume: d(Dimension::VOLUME)?,
            amount: d(Dimension::AMOUNT)?,
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
}

/// The designs as a markdown table.
fn table(s: &VesselSizing, u: &SizeUnits) -> String {
    let (f, l) = (u.flow.unit(), u.length.unit());
    let mut t = format!(
        "surge sizing of `{}` ({}; level controller `{}` on `{}`) for {}: outflow change {:.4e} {f}, \
         level band ±{:.4} {l}, rate limit {:.4e} {}, liquid {:.4e} {}/{}\n\n",
        s.vessel,
        s.kind,
        s.level_controller,
        s.outflow,
        s.disturbance,
        u.flow.difference(s.flow_change),
        u.length.difference(s.level_band),
        u.rate(s.max_outflow_rate),
        u.rate_unit(),
        u.volume.difference(s.liquid_molar_volume) / u.amount.difference(1.0),
        u.volume.unit(),
        u.amount.unit()
    );
    t.push_str(&format!(
        "| controller | area [{}] | band volume [{}] | kc [{f}/{l}] | τI [min] | max level deviation [{l}] | max outflow rate [{}] | meets |\n",
        u.area.unit(),
        u.volume.unit(),
        u.rate_unit()
    ));
    t.push_str("|---|---|---|---|---|---|---|---|\n");
    for d in &s.designs {
        t.push_str(&format!(
            "| {} | {:.4} | {:.4} | {} | {} | {:.6} | {:.4e} | {} |\n",
            d.controller.name(),
            u.area.difference(d.area),
            u.volume.difference(d.band_volume),
            d.kc.map_or("–".into(), |k| format!("{:.4}", u.kc(k))),
            opt(d.tau_i, 1.0 / 60.0),
            u.length.difference(d.verified.max_level_deviation),
            u.rate(d.verified.max_outflow_rate),
            if d.verified.meets { "yes" } else { "NO" }
        ));
    }
    if let Some(a) = &s.attenuation {
        t.push_str(&format!(
            "\nperiodic swing at {} s (asked: outflow ≤ {} of the inflow; `meets` is judged on it, the peaks above \
             include the start from rest):\n",
            a.period, a.ratio
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
    for d in s.designs.iter().filter(|d| d.verified.failure.is_some()) {
        t.push_str(&format!("\n{}: {}\n", d.controller.name(), d.verified.failure.as_deref().unwrap_or("")));
    }
    let c = &s.current;
    t.push_str(&format!(
        "\nas the file has it{}: max deviation {} {l}, max outflow rate {:.4e} {} — {}\n",
        c.area.map_or(String::new(), |a| format!(" (area {:.4} {})", u.area.difference(a), u.area.unit())),
        opt(c.max_deviation.map(|d| u.length.difference(d)), 1.0),
        u.rate(c.max_outflow_rate),
        u.rate_unit(),
        if c.meets { "meets the limits" } else { "exceeds them" }
    ));
    if let Some(why) = &c.failure {
        t.push_str(&format!("its run stopped: {why}\n"));
    }
    t
}

/// The candidates, best first.
fn ranking_table(r: &CandidateRanking, u: &SizeUnits) -> String {
    let mut t = format!(
        "| rank | candidate | kind | outflow change [{}] | now: max rate [{}] | needs surge | optimal band volume [{v}] | P band volume [{v}] |\n|---|---|---|---|---|---|---|---|\n",
        u.flow.unit(),
        u.rate_unit(),
        v = u.volume.unit()
    );
    for c in &r.candidates {
        let Some(s) = &c.sizing else {
            t.push_str(&format!(
                "| – | {} | – | – | – | – | – | {} |\n",
                c.candidate.as_deref().unwrap_or("?"),
                c.failure.as_deref().unwrap_or("")
            ));
            continue;
        };
        let vol = |k: usize| s.designs.get(k).map_or(f64::NAN, |d| u.volume.difference(d.band_volume));
        t.push_str(&format!(
            "| {} | {} | {} | {:.4e} | {:.4e} | {} | {:.4} | {:.4} |\n",
            c.rank.unwrap_or(0),
            s.vessel,
            s.kind,
            u.flow.difference(s.flow_change),
            u.rate(s.current.max_outflow_rate),
            if c.needs_surge == Some(true) { "yes" } else { "no" },
            vol(2),
            vol(0)
        ));
    }
    t
}

/// Level deviation and outflow of the designs and the file's vessel, on one time grid (each
/// record held at its last value after it ends).
fn plot_designs(out: &Path, s: &VesselSizing, u: &SizeUnits) -> Result<(), CliError> {
    let end = s.designs.iter().map(|d| d.verified.duration).fold(0.0, f64::max);
    let grid: Vec<f64> = (0..=1000).map(|k| end * k as f64 / 1000.0).collect();
    let at = |times: &[f64], ys: &[f64]| -> Vec<f64> { grid.iter().map(|&t| interpolate(times, ys, t)).collect() };
    let mut level = Vec::new();
    let mut flow = Vec::new();
    for d in &s.designs {
        let tr = &d.verified.trace;
        let name = format!("{} (A = {:.3} {})", d.controller.name(), u.area.difference(d.area), u.area.unit());
        let deviation: Vec<f64> = tr.deviation.iter().map(|v| u.length.difference(*v)).collect();
        let outflow: Vec<f64> = tr.outflow.iter().map(|v| u.flow.value(*v)).collect();
        level.push((name.clone(), at(&tr.times, &deviation)));
        flow.push((name, at(&tr.times, &outflow)));
    }
    let tr = &s.current.trace;
    let outflow: Vec<f64> = tr.outflow.iter().map(|v| u.flow.value(*v)).collect();
    flow.push(("as in the file".to_string(), at(&tr.times, &outflow)));
    let panels = [
        Overlay { label: format!("level deviation [{}]", u.length.unit()), curves: level, ..Overlay::default() },
        Overlay { label: format!("{} [{}]", s.outflow, u.flow.unit()), curves: flow, ..Overlay::default() },
    ];
    let hours: Vec<f64> = grid.iter().map(|t| t / 3600.0).collect();
    let band = u.length.difference(s.level_band);
    let title = format!("surge designs of `{}` for {} (band ±{band:.4} {})", s.vessel, s.disturbance, u.length.unit());
    write_overlays(out, &title, "time after the step [h]", &hours, &panels, &[])
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

/// The candidates' optimal band volumes as bars.
fn plot_candidates(out: &Path, r: &CandidateRanking) -> Result<(), CliError> {
    let bars: Vec<(String, f64)> = r
        .candidates
        .iter()
        .map(|c| match &c.sizing {
            Some(s) => {
                let need = if c.needs_surge == Some(true) { "needs surge" } else { "meets the limit now" };
                let fails = s.designs.get(2).is_some_and(|d| !d.verified.meets);
                let need = if fails { format!("{need}; the design fails its run") } else { need.to_string() };
                (
                    format!("{} {} ({need})", c.rank.unwrap_or(0), s.vessel),
                    s.designs.get(2).map_or(f64::NAN, |d| d.band_volume),
                )
            }
            None => (format!("– {}", c.candidate.as_deref().unwrap_or("?")), f64::NAN),
        })
        .collect();
    write_bars(out, "band volume the optimal averaging controller needs", "m³", &bars)
        .map_err(|e| CliError::user(e.to_string()))
}
