//! The report of a dynamic run ([`SimulationResult`]): the recorded trends as CSV, the summary
//! (figures of merit per path, the conservation check, the MPC controllers' statistics) as text
//! or JSON (SI), each recorded path in its display unit. `plantwide run` writes [`csv`] and
//! [`super::run_plot::plot`], and prints [`text`] (or [`json`] with `--json`).

use std::collections::BTreeMap;

use plantwide_analysis::figures::summary;
use plantwide_flowsheet::scenario::{RecordPathSpec, ScenarioSpec};
use plantwide_solve::dynamic::{CONSERVATION_TOL, Conservation, SimulationResult};
use plantwide_units::{Display, UnitSystem, convert_from_si, unit_dimension};
use serde::Serialize;

use crate::IoError;

/// Every column whose scenario entry names no unit shown in `units`' unit of its dimension; a unit
/// the scenario names (SI ones too), and a tag's own unit, are kept.
pub fn display_units(res: &mut SimulationResult, units: UnitSystem, spec: &ScenarioSpec) {
    let asked = |k: usize| matches!(spec.record.paths.get(k), Some(RecordPathSpec::WithUnit { unit: Some(_), .. }));
    // A column already in a unit other than SI without being asked for one is a tag in its own unit.
    let own = |c: &plantwide_solve::dynamic::Column| c.unit != c.si_unit;
    for (_, c) in res.columns.iter_mut().enumerate().filter(|(k, c)| !asked(*k) && !own(c)) {
        if let Ok(dim) = unit_dimension(&c.si_unit) {
            c.unit = units.unit_for(dim);
        }
    }
}

/// `v` (SI) in `unit`, or as it is if `unit` is none.
fn to_unit(v: f64, unit: &str) -> f64 {
    convert_from_si(v, unit).unwrap_or(v)
}

/// The recorded trends as CSV: a header `time [time_unit]`, `path [unit]`…, then one row per
/// recorded time, times multiplied by `time_factor` and each column in its display unit.
pub fn csv(res: &SimulationResult, time_unit: &str, time_factor: f64) -> String {
    let mut header = vec![format!("time [{time_unit}]")];
    header.extend(res.columns.iter().map(|c| format!("{} [{}]", c.path, c.unit)));
    let mut t = header.iter().map(|h| csv_field(h)).collect::<Vec<_>>().join(",");
    t.push('\n');
    for (time, row) in res.times.iter().zip(&res.rows) {
        let mut fields = vec![format!("{}", time * time_factor)];
        fields.extend(row.iter().zip(&res.columns).map(|(v, c)| format!("{}", to_unit(*v, &c.unit))));
        t.push_str(&fields.join(","));
        t.push('\n');
    }
    t
}

/// Quote a CSV field that holds a comma or a quote.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_string() }
}

/// The run as text: the integrator's statistics (`wall` seconds of wall time), the conditions
/// that acted, a trip, one row of figures of merit per recorded path in its display unit (times
/// in `time_unit`, `time_factor` per second), the conservation check and each MPC controller's
/// statistics.
///
/// # Errors
/// [`IoError::Draw`] if a path's unit is no display unit.
pub fn text(res: &SimulationResult, wall: f64, time_factor: f64, time_unit: &str) -> Result<String, IoError> {
    let s = &res.stats;
    let mut t = format!(
        "simulated {:.4} {time_unit} in {wall:.2} s: {} steps ({} error-test failures, {} Newton failures), {} residual and {} Jacobian evaluations, {} LU factorizations, {} restarts\n",
        res.t * time_factor,
        s.n_steps,
        s.n_error_test_failures,
        s.n_newton_failures,
        s.n_residual_evals,
        s.n_jacobian_evals,
        s.n_lu,
        s.n_restarts
    );
    for (at, origin) in res.events.iter().filter(|(_, o)| o.starts_with("when[")) {
        t.push_str(&format!("{origin} at t = {:.4} {time_unit}\n", at * time_factor));
    }
    if let Some(why) = &res.tripped {
        t.push_str(&format!("stopped by the scenario: {why}; the run ends there\n"));
    }
    t.push_str(&figures(res, time_factor, time_unit)?);
    t.push_str(&conservation(&res.conservation));
    for m in &res.mpc {
        let statuses: Vec<String> = m.statuses.iter().map(|(k, v)| format!("{k} {v}")).collect();
        t.push_str(&format!(
            "mpc {}: {} samples (QP {}), solve time mean {:.3} ms, max {:.3} ms, {:.1} iterations, an input at a limit in {} samples, largest soft-limit slack {:.3e}; model: {}\n",
            m.controller,
            m.samples,
            statuses.join(", "),
            1e3 * m.mean_solve_time,
            1e3 * m.max_solve_time,
            m.mean_iterations,
            m.samples_at_limit,
            m.max_slack,
            m.model
        ));
    }
    Ok(t)
}

/// The table of figures of merit: per path its reference, initial and final values, IAE, ISE,
/// largest deviation and settling time, in its display unit.
fn figures(res: &SimulationResult, time_factor: f64, time_unit: &str) -> Result<String, IoError> {
    let mut t = format!(
        "{:<28} {:<10} {:>10} {:>14} {:>14} {:>14} {:>14} {:>14} {:>12}\n",
        "path",
        "unit",
        "reference",
        "initial",
        "final",
        format!("IAE [u·{time_unit}]"),
        format!("ISE [u²·{time_unit}]"),
        "max deviation",
        "settling"
    );
    for (p, c) in summary(res).iter().zip(&res.columns) {
        let d =
            Display::new(&c.unit).or_else(|_| Display::new(&c.si_unit)).map_err(|e| IoError::Draw(e.to_string()))?;
        let settling = p.settling_time.map_or("-".to_string(), |t| format!("{:.4} {time_unit}", t * time_factor));
        t.push_str(&format!(
            "{:<28} {:<10} {:>10} {:>14.7e} {:>14.7e} {:>14.4e} {:>14.4e} {:>14.4e} {:>12}\n",
            p.path,
            d.unit(),
            p.reference,
            d.value(p.initial),
            d.value(p.last),
            d.difference(p.iae) * time_factor,
            d.difference(d.difference(p.ise)) * time_factor,
            d.difference(p.max_deviation),
            settling
        ));
    }
    Ok(t)
}

/// One line per balance: `Δ held` against `∫(in − out)`, and the relative error.
fn conservation(c: &Conservation) -> String {
    let worst = c.worst();
    let verdict = if c.check(CONSERVATION_TOL).is_ok() { "ok" } else { "FAILED" };
    let mut t = format!(
        "conservation ({}): largest relative error {worst:.2e} (tolerance {CONSERVATION_TOL:.0e}): {verdict}\n",
        c.basis
    );
    for b in &c.balances {
        t.push_str(&format!(
            "  {:<20} Δheld {:>14.6e} {u}, fed {:>14.6e} {u}, removed {:>14.6e} {u}: relative error {:.2e}\n",
            b.name,
            b.held[1] - b.held[0],
            b.fed,
            b.removed,
            b.relative_error,
            u = b.unit
        ));
    }
    t
}

/// `plantwide run --json`. Its keys in alphabetical order, at every level: the order this JSON
/// has always had (serde_json's map sorts its keys, and the solver's reports are shown through
/// one).
#[derive(Serialize)]
struct RunJson<'a> {
    conservation: ConservationJson<'a>,
    events: Vec<EventJson<'a>>,
    final_values: BTreeMap<String, f64>,
    mpc: serde_json::Value,
    paths: serde_json::Value,
    stats: serde_json::Value,
    t_end: f64,
    tripped: &'a Option<String>,
    wall_time_s: f64,
}

/// The conservation check: its basis, tolerance, largest relative error and each balance.
#[derive(Serialize)]
struct ConservationJson<'a> {
    balances: serde_json::Value,
    basis: &'a str,
    max_relative_error: f64,
    tolerance: f64,
}

/// An event applied: what it was and when \[s\].
#[derive(Serialize)]
struct EventJson<'a> {
    event: &'a str,
    t: f64,
}

/// The run's summary as JSON (SI): the end time, `wall` seconds of wall time, the integrator's
/// statistics, the events, each path's final value and figures of merit, the conservation check,
/// the MPC controllers' statistics and a trip.
///
/// # Errors
/// [`IoError::Draw`] if serde cannot write it.
pub fn json(res: &SimulationResult, wall: f64) -> Result<String, IoError> {
    let value = |v: serde_json::Result<serde_json::Value>| v.map_err(|e| IoError::Draw(format!("JSON: {e}")));
    let summary = summary(res);
    super::json(&RunJson {
        conservation: ConservationJson {
            balances: value(serde_json::to_value(&res.conservation.balances))?,
            basis: res.conservation.basis,
            max_relative_error: res.conservation.worst(),
            tolerance: CONSERVATION_TOL,
        },
        events: res.events.iter().map(|(t, o)| EventJson { event: o, t: *t }).collect(),
        final_values: summary.iter().map(|p| (p.path.clone(), p.last)).collect(),
        mpc: value(serde_json::to_value(&res.mpc))?,
        paths: value(serde_json::to_value(&summary))?,
        stats: value(serde_json::to_value(res.stats))?,
        t_end: res.t,
        tripped: &res.tripped,
        wall_time_s: wall,
    })
}
