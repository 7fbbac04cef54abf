//! The trend plot of `plantwide run`: the recorded paths grouped into panels (`"panel"` in the
//! scenario's record), each with its setpoint dashed, its controller's output limits (a PID's
//! `op_min`/`op_max`, a model predictive controller's own MV and CV limits) dotted and
//! the same paths of earlier runs (`--compare OTHER.csv`) dashed, and the events as markers.

use std::path::Path;

use plantwide_flowsheet::Plant;
use plantwide_flowsheet::scenario::{EventSpec, RecordPathSpec, ScenarioSpec};
use plantwide_model::registry::ControllerSpec;
use plantwide_solve::dynamic::SimulationResult;
use plantwide_units::{Display, convert_from_si};

use crate::IoError;
use crate::error::MixedPanel;
use crate::plot::{Overlay, write_overlays};

/// An earlier run's trends (`--compare OTHER.csv`, read by the caller): its name, its times \[s\]
/// and each column by its CSV header (`path [unit]`).
pub struct OtherRun {
    /// The run's name in the legend (its file's stem).
    pub name: String,
    /// Recorded times \[s\].
    pub times: Vec<f64>,
    /// Each column's header and values, in the unit its header names.
    pub columns: Vec<(String, Vec<f64>)>,
}

/// What the plot is drawn from besides the result: the plant (controller limits), the scenario
/// (panels, event labels), the title, the time axis's unit, and the earlier runs to overlay.
pub struct PlotContext<'a> {
    /// The plant run.
    pub plant: &'a Plant,
    /// Its scenario.
    pub spec: &'a ScenarioSpec,
    /// The figure's title.
    pub title: &'a str,
    /// The time axis's unit.
    pub time_unit: &'a str,
    /// Time units per second.
    pub time_factor: f64,
    /// Earlier runs whose same paths are drawn dashed.
    pub others: &'a [OtherRun],
}

/// The trend plot of `res` into `file` (`.png` or `.svg`): one panel per scenario panel or
/// recorded path, the events as markers.
///
/// # Errors
/// [`IoError::PanelUnits`] when one panel holds paths of two units; [`IoError::PlotKind`] or
/// [`IoError::Draw`] when the file cannot be written.
pub fn plot(file: &Path, res: &SimulationResult, cx: &PlotContext<'_>) -> Result<(), IoError> {
    let times: Vec<f64> = res.times.iter().map(|t| t * cx.time_factor).collect();
    let panels = panels(res, cx.plant, cx.spec, cx.others)?;
    let events = labelled(&res.events, cx.spec, cx.time_factor);
    write_overlays(file, cx.title, &format!("time [{}]", cx.time_unit), &times, &panels, &events)
}

/// A unit as an axis label shows it: a dimensionless one as `-`.
fn axis_unit(unit: &str) -> &str {
    if unit == "1" { "-" } else { unit }
}

/// The panel each recorded column belongs to: its `"panel"` in the scenario, else its own.
fn panel_names(spec: &ScenarioSpec, n: usize) -> Vec<String> {
    (0..n)
        .map(|k| match spec.record.paths.get(k) {
            Some(RecordPathSpec::WithUnit { panel: Some(p), .. }) => p.clone(),
            _ => format!("\u{0}{k}"),
        })
        .collect()
}

/// `values` at `times` (s) linearly interpolated to `at` (s); NaN outside.
fn resample(times: &[f64], values: &[f64], at: &[f64]) -> Vec<f64> {
    at.iter()
        .map(|&t| match times.partition_point(|&x| x < t) {
            0 if times.first() == Some(&t) => values[0],
            i if i == 0 || i >= times.len() => f64::NAN,
            i => {
                let w = (t - times[i - 1]) / (times[i] - times[i - 1]);
                values[i - 1] + w * (values[i] - values[i - 1])
            }
        })
        .collect()
}

/// The output limits of the controller whose output `path` is (or drives, for an input path).
fn limits(plant: &Plant, path: &str) -> Option<(f64, f64)> {
    let var = plant.var(path).or_else(|| plant.input(path).and_then(|i| plant.inputs()[i].driven_by))?;
    plant.blocks()[plant.vars()[var].block].unit.output_limits()
}

/// The limits a model predictive controller keeps on `path`, named by the controller (SI): the
/// hard `min`/`max` of an MV it drives, the soft ones of a CV it controls; a controller that does
/// not state one has none drawn.
fn mpc_limits(plant: &Plant, path: &str) -> Vec<(String, f64)> {
    let dim =
        plant.var(path).map(|v| plant.vars()[v].spec.dim).or_else(|| plant.input(path).map(|i| plant.inputs()[i].dim));
    let Some(dim) = dim else { return Vec::new() };
    let mut out = Vec::new();
    for (name, c) in &plant.spec().controllers {
        let ControllerSpec::Mpc(cfg) = c else { continue };
        let mvs = cfg.mvs.iter().filter(|m| m.output == path).map(|m| (&m.min, &m.max, ""));
        let cvs = cfg.cvs.iter().filter(|c| c.pv == path).map(|c| (&c.min, &c.max, " (soft)"));
        for (min, max, kind) in mvs.chain(cvs) {
            for (what, q) in [("min", min), ("max", max)] {
                if let Some(v) = q.as_ref().and_then(|q| q.to_si(dim).ok()) {
                    out.push((format!("{name} {what}{kind}"), v));
                }
            }
        }
    }
    out
}

/// The panels of the run's plot, with the same paths of the `others` runs.
fn panels(
    res: &SimulationResult,
    plant: &Plant,
    spec: &ScenarioSpec,
    others: &[OtherRun],
) -> Result<Vec<Overlay>, IoError> {
    let names = panel_names(spec, res.columns.len());
    let mut order: Vec<&String> = Vec::new();
    names.iter().for_each(|n| {
        if !order.contains(&n) {
            order.push(n)
        }
    });
    let mut out = Vec::new();
    for name in order {
        let members: Vec<usize> = (0..names.len()).filter(|&k| &names[k] == name).collect();
        let unit = &res.columns[members[0]].unit;
        if let Some(&k) = members.iter().find(|&&k| &res.columns[k].unit != unit) {
            return Err(IoError::PanelUnits(Box::new(MixedPanel {
                index: k,
                panel: name.clone(),
                first: (res.columns[members[0]].path.clone(), unit.clone()),
                other: (res.columns[k].path.clone(), res.columns[k].unit.clone()),
            })));
        }
        let d = Display::new(unit).map_err(|e| IoError::Draw(e.to_string()))?;
        let single = members.len() == 1;
        let mut o = Overlay {
            label: match single {
                true => format!("{} [{}]", res.columns[members[0]].path, axis_unit(unit)),
                false => format!("{name} [{}]", axis_unit(unit)),
            },
            ..Overlay::default()
        };
        for (m, &k) in members.iter().enumerate() {
            let c = &res.columns[k];
            let label = |what: &str| if single { what.to_string() } else { format!("{} {what}", c.path) };
            o.curves.push((
                if single { String::new() } else { c.path.clone() },
                res.rows.iter().map(|r| d.value(r[k])).collect(),
            ));
            if let Some(r) = &res.references[k] {
                o.dashed.push((label("setpoint"), Some(m), r.iter().map(|v| d.value(*v)).collect()));
            }
            for other in others {
                let header = format!("{} [{}]", c.path, c.unit);
                if let Some((_, v)) = other.columns.iter().find(|(h, _)| *h == header) {
                    o.dashed.push((label(&other.name), Some(m), resample(&other.times, v, &res.times)));
                }
            }
            let pid = limits(plant, &c.path)
                .map_or(Vec::new(), |(lo, hi)| vec![("op_min".to_string(), lo), ("op_max".to_string(), hi)]);
            for (what, v) in pid.into_iter().chain(mpc_limits(plant, &c.path)).filter(|(_, v)| v.is_finite()) {
                o.limits.push((label(&what), convert_from_si(v, unit).unwrap_or(v)));
            }
        }
        if single && !o.dashed.is_empty() {
            o.curves[0].0 = "this run".into();
        }
        out.push(o);
    }
    Ok(out)
}

/// The scenario's applied events `(time [s], origin)` as `(time in the plot's unit, label)`, the
/// labels of events at one time joined (an interlock's crossing and the events it starts at once
/// are one marker).
fn labelled(events: &[(f64, String)], spec: &ScenarioSpec, time_factor: f64) -> Vec<(f64, String)> {
    let mut out: Vec<(f64, String)> = Vec::new();
    for (t, origin) in events {
        let (t, text) = (t * time_factor, event_label(origin, spec));
        match out.last_mut() {
            Some((last, joined)) if *last == t => {
                joined.push_str(", ");
                joined.push_str(&text);
            }
            _ => out.push((t, text)),
        }
    }
    out
}

/// A short label for the event `origin` names: `events[k]`, a condition acting
/// (`` when[k] (`path` above v) ``: its crossing, `path > v`), or one of its events
/// (`when[k].then[j]`, perhaps `… skipped: why`).
fn event_label(origin: &str, spec: &ScenarioSpec) -> String {
    let index = |s: &str, prefix: &str| -> Option<(usize, usize)> {
        let rest = s.strip_prefix(prefix)?;
        let close = rest.find(']')?;
        Some((rest[..close].parse().ok()?, prefix.len() + close + 1))
    };
    if let Some((k, _)) = index(origin, "events[") {
        return spec.events.get(k).map_or_else(|| origin.to_string(), kind_label);
    }
    let Some((k, end)) = index(origin, "when[") else { return origin.to_string() };
    let rest = &origin[end..];
    if let Some((j, end)) = index(rest, ".then[") {
        let skipped = if rest[end..].contains("skipped") { " (skipped)" } else { "" };
        let then = spec.when.get(k).and_then(|w| w.then.get(j));
        return then.map_or_else(|| origin.to_string(), |e| format!("{}{skipped}", kind_label(e)));
    }
    let crossing = rest.trim_start().trim_start_matches('(').trim_end_matches(')').replace('`', "");
    crossing.replace(" above ", " > ").replace(" below ", " < ")
}

/// What an event does, in a few words.
fn kind_label(e: &EventSpec) -> String {
    match e {
        EventSpec::Step { path, .. } => format!("step {path}"),
        EventSpec::Ramp { path, .. } => format!("ramp {path}"),
        EventSpec::Pulse { path, .. } => format!("pulse {path}"),
        EventSpec::Sinusoid { path, .. } => format!("sinusoid {path}"),
        EventSpec::Mode { controller, mode, .. } => format!("{controller} {mode:?}").to_lowercase(),
        EventSpec::ValveStuck { path, .. } => format!("{path} stuck"),
        EventSpec::ValveRepaired { path, .. } => format!("{path} repaired"),
        EventSpec::FeedLost { unit, .. } => format!("{unit} lost"),
        EventSpec::FeedRestored { unit, .. } => format!("{unit} restored"),
        EventSpec::AnalyzerFrozen { controller, .. } => format!("{controller} analyzer frozen"),
        EventSpec::AnalyzerRepaired { controller, .. } => format!("{controller} analyzer repaired"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resampling_interpolates_inside_and_leaves_nan_outside() {
        let v = resample(&[0.0, 10.0, 20.0], &[1.0, 2.0, 4.0], &[0.0, 5.0, 15.0, 25.0]);
        assert_eq!(&v[..3], &[1.0, 1.5, 3.0]);
        assert!(v[3].is_nan());
        assert_eq!(axis_unit("1"), "-");
    }

    /// A condition's crossing and the events it starts at once are one marker; later ones,
    /// skipped ones and timed ones are labelled by what they do.
    #[test]
    fn conditional_events_are_labelled_by_what_they_do() {
        let spec = plantwide_flowsheet::scenario::parse_scenario(
            r#"{"format_version": 1, "duration": "1 h",
                "events": [{"type": "step", "at": "5 min", "path": "F", "to": "2 mol/s"}],
                "when": [{"path": "tank.level", "above": "3 m",
                          "then": [{"type": "feed_lost", "at": "0 s", "unit": "inflow"},
                                   {"type": "feed_restored", "at": "10 min", "unit": "inflow"}]}]}"#,
            "s.json",
        )
        .unwrap();
        let raw = [
            (300.0, "events[0]".to_string()),
            (600.0, "when[0] (`tank.level` above 3 m)".to_string()),
            (600.0, "when[0].then[0]".to_string()),
            (1200.0, "when[0].then[1] skipped: `inflow.F` has no fault to repair".to_string()),
        ];
        let got = labelled(&raw, &spec, 1.0 / 60.0);
        assert_eq!(
            got,
            vec![
                (5.0, "step F".to_string()),
                (10.0, "tank.level > 3 m, inflow lost".to_string()),
                (20.0, "inflow restored (skipped)".to_string()),
            ]
        );
    }
}
