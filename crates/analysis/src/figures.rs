//! Figures of merit of a dynamic run: for every recorded path its deviation `e(t)` from a
//! reference (the controller's setpoint for a controlled variable, else the first recorded
//! value), the integrals `IAE = ∫|e| dt` and `ISE = ∫e² dt` by the trapezoid rule over the
//! recorded points, the largest deviation and the 2 % settling time.

use serde::Serialize;

use plantwide_solve::dynamic::SimulationResult;

/// Figures of merit of one recorded path (SI units, times in seconds).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathSummary {
    /// Path.
    pub path: String,
    /// SI unit.
    pub unit: String,
    /// First recorded value.
    pub initial: f64,
    /// Last recorded value.
    pub last: f64,
    /// What deviations are measured from: `setpoint` or `initial`.
    pub reference: &'static str,
    /// `∫|e| dt` (trapezoid over the recorded points), `e` the deviation from the reference.
    pub iae: f64,
    /// `∫e² dt`.
    pub ise: f64,
    /// The deviation of largest magnitude (signed).
    pub max_deviation: f64,
    /// Time [s] after the first event until the path stays within 2 % of its largest excursion
    /// from its final value; `None` if it never moved.
    pub settling_time: Option<f64>,
}

/// Figures of merit of every recorded column of `res`; settling times count from the first
/// scenario event (from the first recorded time if there is none).
pub fn summary(res: &SimulationResult) -> Vec<PathSummary> {
    let t_first = res.events.first().map_or(res.times.first().copied().unwrap_or(0.0), |e| e.0);
    (0..res.columns.len()).map(|k| path_summary(res, k, t_first)).collect()
}

/// Figures of merit of column `k`, settling measured from `t_first` [s].
fn path_summary(res: &SimulationResult, k: usize, t_first: f64) -> PathSummary {
    let y: Vec<f64> = res.rows.iter().map(|r| r[k]).collect();
    let (initial, last) = (y.first().copied().unwrap_or(f64::NAN), y.last().copied().unwrap_or(f64::NAN));
    let reference = res.references[k].as_ref();
    let e: Vec<f64> = y.iter().enumerate().map(|(i, v)| v - reference.map_or(initial, |r| r[i])).collect();
    let (mut iae, mut ise) = (0.0, 0.0);
    for i in 1..y.len() {
        let dt = res.times[i] - res.times[i - 1];
        iae += 0.5 * dt * (e[i].abs() + e[i - 1].abs());
        ise += 0.5 * dt * (e[i] * e[i] + e[i - 1] * e[i - 1]);
    }
    let max_deviation = e.iter().copied().fold(0.0, |m: f64, v| if v.abs() > m.abs() { v } else { m });
    let excursion = y.iter().map(|v| (v - last).abs()).fold(0.0, f64::max);
    let settling_time = (excursion > 1e-12 * last.abs().max(1e-300)).then(|| {
        let band = 0.02 * excursion;
        let outside = (0..y.len()).rev().find(|&i| (y[i] - last).abs() > band);
        outside.map_or(0.0, |i| (res.times[(i + 1).min(y.len() - 1)] - t_first).max(0.0))
    });
    PathSummary {
        path: res.columns[k].path.clone(),
        unit: res.columns[k].si_unit.clone(),
        initial,
        last,
        reference: if reference.is_some() { "setpoint" } else { "initial" },
        iae,
        ise,
        max_deviation,
        settling_time,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plantwide_solve::dae::BdfStats;
    use plantwide_solve::dynamic::{Column, Conservation, Table};

    /// A unit step recorded at t = 0, 1, 2 s: `y = [0, 1, 1]`, once against its initial value and
    /// once against a setpoint of 1.
    fn step(reference: Option<Vec<f64>>) -> SimulationResult {
        let mut rows = Table::with_capacity(1, 3);
        [0.0, 1.0, 1.0].into_iter().for_each(|y| rows.push([y]));
        SimulationResult {
            columns: vec![Column { path: "y".into(), unit: "m".into(), si_unit: "m".into() }],
            times: vec![0.0, 1.0, 2.0],
            rows,
            references: vec![reference],
            events: Vec::new(),
            x: Vec::new(),
            t: 2.0,
            stats: BdfStats::default(),
            conservation: Conservation::new(&[], None, [&[], &[]], &[], &[]),
            mpc: Vec::new(),
            tripped: None,
        }
    }

    #[test]
    fn trapezoid_integrals_deviation_and_settling_of_a_step() {
        // e = [0, 1, 1]: IAE = ISE = ½·(0 + 1) + ½·(1 + 1) = 1.5; settled (2 % band) from t = 1 s.
        let s = &summary(&step(None))[0];
        assert_eq!(s.reference, "initial");
        assert!((s.iae - 1.5).abs() < 1e-15 && (s.ise - 1.5).abs() < 1e-15, "{s:?}");
        assert!((s.max_deviation - 1.0).abs() < 1e-15 && s.settling_time == Some(1.0), "{s:?}");
        // Against a setpoint of 1: e = [−1, 0, 0], IAE = ISE = ½, the largest deviation −1.
        let s = &summary(&step(Some(vec![1.0; 3])))[0];
        assert_eq!(s.reference, "setpoint");
        assert!((s.iae - 0.5).abs() < 1e-15 && (s.ise - 0.5).abs() < 1e-15, "{s:?}");
        assert!((s.max_deviation + 1.0).abs() < 1e-15, "{s:?}");
    }
}
