//! The driver's conditional events (`when`, [`plantwide_flowsheet::scenario::Condition`]): a
//! condition is checked at the end of every step; the first step at whose end it holds is cut
//! back to the crossing, located on the step's interpolating polynomial by the Illinois variant
//! of regula falsi to `100 ε · max(|t|, h)` (SUNDIALS' root-finding tolerance), and the
//! integrator restarted there (a consistent start from the interpolated state). The condition
//! then acts: its `then` events are queued, each due its delay after the crossing, or the run
//! ends (`stop`). What the conditions have done is part of the driver's state, so a snapshot
//! resumed goes on as the continuous run.

use plantwide_flowsheet::scenario::Action;

use super::Driver;
use crate::dae::{DaeError, DaeIntegrator, DenseOutput};
use crate::dynamic::adapter::PlantDae;
use crate::dynamic::snapshot::Triggered;

/// Iterations of the crossing's location: regula falsi halves its bracket at least every other
/// iteration with the Illinois rule, so 200 reach any tolerance above rounding from any step.
const LOCATE_MAXITER: usize = 200;

impl Driver<'_> {
    /// Whether condition `k` is still to act.
    fn armed(&self, k: usize) -> bool {
        let key = self.sc.conditions[k].key();
        !self.st.fired.contains(&key)
    }

    /// The armed conditions that hold in the integrator's current state.
    fn holding(&self) -> Vec<usize> {
        let x = self.bdf.x();
        (0..self.sc.conditions.len())
            .filter(|&k| {
                let c = &self.sc.conditions[k];
                c.excess(x[c.var]) > 0.0 && self.armed(k)
            })
            .collect()
    }

    /// At the start of a run (or a resumed one): the conditions that hold there act there.
    pub(super) fn conditions_at_start(&mut self) {
        let t = self.bdf.t();
        for k in self.holding() {
            self.act(k, t);
        }
    }

    /// After a step: if conditions came to hold in it, cut the step back to the earliest crossing
    /// (rows recorded up to it, the integrator restarted there from the interpolated state in
    /// `x`) and let every condition crossing there act. True if the step was cut.
    pub(super) fn conditions_after_step(&mut self, x: &mut [f64]) -> Result<bool, DaeError> {
        let crossed = self.holding();
        if crossed.is_empty() {
            return Ok(false);
        }
        let (t0, t1) = (self.bdf.t_prev(), self.bdf.t());
        let tol = 100.0 * f64::EPSILON * t1.abs().max(t1 - t0);
        let at: Vec<(usize, f64)> = crossed.iter().map(|&k| (k, self.locate(k, t0, t1, tol))).collect();
        let first = at.iter().map(|&(_, t)| t).fold(f64::INFINITY, f64::min);
        if first < t1 {
            self.record_through(first, x);
            self.interpolate(first, x);
            let sys = PlantDae::new(&self.plant, &self.st.waveforms, &self.shape);
            self.bdf.restart_after_discontinuity(&sys, first, x)?;
            x.copy_from_slice(self.bdf.x());
        }
        for (k, t) in at {
            if t <= first + tol {
                self.act(k, first);
            }
        }
        Ok(first < t1)
    }

    /// The crossing of condition `k` in the last step `[t0, t1]` (it holds at `t1`): the first
    /// time at which it holds on the interpolating polynomial, to `tol`.
    fn locate(&self, k: usize, t0: f64, t1: f64, tol: f64) -> f64 {
        let c = &self.sc.conditions[k];
        let mut dense = DenseOutput::default();
        self.bdf.dense_output_into(&[c.var], &mut dense);
        let mut buf = vec![0.0; self.bdf.x().len()];
        let mut g = |t: f64| {
            dense.at(t, &mut buf);
            c.excess(buf[c.var])
        };
        let (mut a, mut b) = (t0, t1);
        let (mut ga, mut gb) = (g(a), c.excess(self.bdf.x()[c.var]));
        if ga > 0.0 || !ga.is_finite() {
            return a;
        }
        // Illinois: the end kept twice running has its value halved, so the bracket shrinks
        // from both sides.
        let mut kept = 0i8;
        for _ in 0..LOCATE_MAXITER {
            if b - a <= tol {
                break;
            }
            let secant = b - gb * (b - a) / (gb - ga);
            let t = if secant > a && secant < b { secant } else { 0.5 * (a + b) };
            let gt = g(t);
            if gt > 0.0 {
                (b, gb) = (t, gt);
                if kept == 1 {
                    ga *= 0.5;
                }
                kept = 1;
            } else {
                (a, ga) = (t, gt);
                if kept == -1 {
                    gb *= 0.5;
                }
                kept = -1;
            }
        }
        b
    }

    /// Condition `k` acts at `t`: its events are queued, or the run ends.
    fn act(&mut self, k: usize, t: f64) {
        let c = &self.sc.conditions[k];
        let key = c.key();
        self.events.push((t, format!("{} ({})", c.origin, c.text)));
        if c.stop {
            let at = plantwide_model::limits::number(t);
            self.tripped.get_or_insert(format!("{} at t = {at} s ({}: \"stop\": true)", c.text, c.origin));
        }
        for (j, e) in c.then.iter().enumerate() {
            let due = t + e.t;
            let slot = self.st.triggered.partition_point(|q| q.due <= due);
            self.st.triggered.insert(slot, Triggered { at: t, due, when: key.clone(), event: j });
        }
        self.st.fired.push(key);
    }

    /// The earliest time a condition's queued event is due.
    pub(super) fn next_triggered(&self) -> Option<f64> {
        self.st.triggered.first().map(|q| q.due)
    }

    /// Apply the conditions' events due at `t` (after the scenario's own); true if any was. One
    /// that no longer fits the run (a fault on an input failed already, a repair of none) is
    /// skipped and listed as such among the run's events.
    pub(super) fn apply_triggered(&mut self, t: f64, x: &[f64], applied: bool) -> bool {
        let mut any = applied;
        while self.st.triggered.first().is_some_and(|q| q.due <= t) {
            let q = self.st.triggered.remove(0);
            let Some(c) = self.sc.conditions.iter().find(|c| c.key() == q.when) else { continue };
            let Some(e) = c.then.get(q.event) else { continue };
            let mut action = e.action.clone();
            if let Action::Ramp { end, .. } = &mut action {
                *end += q.at;
            }
            let origin = e.origin.clone();
            if !any && self.times.last() != Some(&t) {
                self.push_row(t, x);
            }
            any = true;
            match self.inadmissible(&action) {
                Some(why) => self.events.push((t, format!("{origin} skipped: {why}"))),
                None => {
                    self.apply(&action, t, x);
                    self.events.push((t, origin));
                }
            }
        }
        any
    }

    /// Why a condition's event cannot act now: a fault on an input in a fault already, a repair
    /// of an input in none, an analyzer frozen twice or repaired unfrozen.
    fn inadmissible(&self, action: &Action) -> Option<String> {
        let faulted = |i: usize| self.st.faults.iter().any(|f| f.path == self.plant.inputs()[i].path);
        let frozen = |b: usize| self.sc.analyzers.iter().position(|&(a, ..)| a == b).map(|k| self.st.frozen[k]);
        match *action {
            Action::Stuck { input, .. } if faulted(input) => {
                Some(format!("`{}` has failed already", self.plant.inputs()[input].path))
            }
            Action::Repair { input } if !faulted(input) => {
                Some(format!("`{}` has no fault to repair", self.plant.inputs()[input].path))
            }
            Action::Analyzer { block, frozen: f } if frozen(block) != Some(!f) => Some(format!(
                "the analyzer of `{}` is {}",
                self.plant.blocks()[block].name,
                if f { "frozen already" } else { "not frozen" }
            )),
            _ => None,
        }
    }
}
