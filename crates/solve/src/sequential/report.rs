//! What the sequential-modular pass reports: passes, residual history and loop gain per recycle.

use serde::Serialize;

use super::Accelerator;

/// One pass over a recycle, for progress display.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PassRecord {
    /// Recycle number (1-based, precedence order).
    pub recycle: usize,
    /// Pass number within the recycle (1-based).
    pub pass: usize,
    /// Scaled tear residual after the pass.
    pub residual: f64,
}

/// How one recycle SCC converged.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SccReport {
    /// Its solve groups in calculation order.
    pub groups: Vec<String>,
    /// Torn connections (stream names, `signal <path>`).
    pub tears: Vec<String>,
    /// Number of torn variables.
    pub n_tear_vars: usize,
    /// Accelerator used.
    pub accelerator: Accelerator,
    /// Passes (evaluations of the tear map).
    pub passes: usize,
    /// Final scaled tear residual.
    pub residual: f64,
    /// Scaled tear residual after every pass.
    pub history: Vec<f64>,
    /// Estimated loop gain: spectral radius of the secant model of the tear map.
    pub loop_gain: Option<f64>,
    /// Residual at or below the tolerance.
    pub converged: bool,
}

/// Report of a sequential-modular solve.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct SmReport {
    /// Number of solve groups.
    pub n_groups: usize,
    /// Recycles in precedence order.
    pub sccs: Vec<SccReport>,
    /// Local Newton solves.
    pub local_solves: usize,
    /// Local Newton iterations, all groups and passes.
    pub local_iterations: usize,
}

/// What a loop gain means for the user.
pub(crate) fn gain_remark(gain: f64) -> String {
    if gain < 1.0 {
        let near = if gain > 0.9 { " — near the snowball limit" } else { "" };
        format!(
            "; loop gain {gain:.3}: a disturbance entering the loop is amplified {:.1} times{near}",
            1.0 / (1.0 - gain)
        )
    } else {
        format!(
            "; loop gain {gain:.3} ≥ 1: direct substitution diverges — the recycle has no stable steady state under this control structure, or needs Wegstein/Broyden"
        )
    }
}

impl SmReport {
    /// Total passes over all recycles.
    pub fn passes(&self) -> usize {
        self.sccs.iter().map(|s| s.passes).sum()
    }

    /// One line per recycle, for the command line.
    pub fn log(&self) -> Vec<String> {
        let mut lines = vec![format!(
            "sequential-modular pass: {} solve blocks, {} recycle{}, {} local Newton solves ({} iterations)",
            self.n_groups,
            self.sccs.len(),
            if self.sccs.len() == 1 { "" } else { "s" },
            self.local_solves,
            self.local_iterations
        )];
        for (k, s) in self.sccs.iter().enumerate() {
            let state = if s.converged { "converged" } else { "NOT converged" };
            lines.push(format!(
                "  recycle {}: {}; tear {} ({} variables); {} {state} in {} passes, tear residual {:.2e}{}",
                k + 1,
                s.groups.join(" -> "),
                s.tears.join(", "),
                s.n_tear_vars,
                s.accelerator.name(),
                s.passes,
                s.residual,
                s.loop_gain.map_or_else(String::new, gain_remark)
            ));
        }
        lines
    }
}

impl super::SequentialPlan {
    /// The plan for the command line: solve blocks in calculation order, each recycle with its
    /// tears and calculation order, and why blocks are solved together.
    pub fn describe(&self, plant: &plantwide_flowsheet::Plant) -> Vec<String> {
        let mut lines =
            vec![format!("sequential-modular plan ({} solve blocks, in calculation order):", self.groups.len())];
        let mut k = 0;
        for scc in &self.sccs {
            let names: Vec<String> = scc.order.iter().map(|&v| self.node_name(plant, v)).collect();
            if !scc.is_recycle() {
                lines.push(format!("  {}", names.join(", ")));
                continue;
            }
            k += 1;
            let tears: Vec<String> = scc
                .tears
                .iter()
                .map(|&e| {
                    let c = &self.graph[e];
                    format!(
                        "{} ({} variables{})",
                        c.name(plant),
                        c.vars.len(),
                        if c.marked { ", marked in the file" } else { "" }
                    )
                })
                .collect();
            let quality = match (scc.exact, scc.redundancy) {
                (true, Some(0)) => "minimum, non-redundant".to_string(),
                (true, Some(r)) => format!("minimum; {r} extra tears on cycles torn more than once"),
                _ => "greedy (SCC beyond the exact search's limits)".to_string(),
            };
            let cycles = scc
                .n_cycles
                .map_or_else(|| "many cycles".to_string(), |n| format!("{n} cycle{}", if n == 1 { "" } else { "s" }));
            lines.push(format!(
                "  recycle {k}: {}; tear {}; {quality} ({cycles})",
                names.join(" -> "),
                tears.join(", ")
            ));
        }
        let merged: Vec<&super::SolveGroup> = self.groups.iter().filter(|g| !g.reasons.is_empty()).collect();
        if !merged.is_empty() {
            lines.push("solved together:".to_string());
            for g in merged {
                lines.push(format!("  {}: {}", g.name(plant), g.reasons.join("; ")));
            }
        }
        lines
    }
}
