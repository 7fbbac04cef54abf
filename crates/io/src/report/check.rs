//! The report of `plantwide check`: what a flowsheet holds (components, units, streams,
//! controllers, design specs, counts, free inputs, recycles), its degrees of freedom, and the
//! residence times of its vessels, in the display units of a [`UnitSystem`].

use std::path::Path;

use plantwide_flowsheet::{BlockKind, Plant};
use plantwide_solve::DofError;
use plantwide_studies::size::residence::{RULE_OF_THUMB, residence_times};
use plantwide_units::{Dimension, UnitSystem};

use super::steady::shown;

/// What the flowsheet read from `file` holds: its components, units, streams, controllers and
/// design specs, its counts of variables, equations and inputs, its free inputs with the file's
/// values (in `system`'s units) and its recycles.
pub fn summary(plant: &Plant, file: &Path, system: UnitSystem) -> String {
    let mut t = format!("flowsheet `{}` ({})\n", plant.name(), file.display());
    t.push_str(&format!("components ({}): {}\n", plant.components().len(), plant.components().join(", ")));
    let units: Vec<_> = plant.blocks().iter().filter(|b| b.kind == BlockKind::Unit).collect();
    t.push_str(&format!("units ({}):\n", units.len()));
    for b in &units {
        t.push_str(&format!("  {:<16} {}\n", b.name, b.unit.type_name()));
    }
    t.push_str(&format!("streams ({}):\n", plant.streams().len()));
    for s in plant.streams() {
        let (fb, fp) = s.from;
        let (tb, tp) = s.to;
        let from = &plant.blocks()[fb];
        let to = &plant.blocks()[tb];
        t.push_str(&format!(
            "  {:<16} {}.{} -> {}.{}\n",
            s.name,
            from.name,
            from.unit.outlet_ports()[fp],
            to.name,
            to.unit.inlet_ports()[tp]
        ));
    }
    t.push_str(&controllers_and_specs(plant));
    t.push_str(&counts(plant, system));
    let recycles = plant.recycles();
    if recycles.is_empty() {
        t.push_str("recycles: none\n");
    } else {
        for (k, r) in recycles.iter().enumerate() {
            t.push_str(&format!("recycle {}: {}\n", k + 1, r.join(" -> ")));
        }
    }
    t
}

/// The controllers (what each reads and drives) and the design specs.
fn controllers_and_specs(plant: &Plant) -> String {
    // The inputs each block drives, in one pass (per controller, a scan of every input and of
    // every block was cubic in the plant's size: 15 % of `check` on 512 columns).
    let mut driven_by_block: Vec<Vec<&str>> = vec![Vec::new(); plant.blocks().len()];
    for i in plant.inputs() {
        if let Some(v) = i.driven_by {
            driven_by_block[plant.vars()[v].block].push(i.path.as_str());
        }
    }
    let ctrls: Vec<_> = plant.blocks().iter().enumerate().filter(|(_, b)| b.kind == BlockKind::Controller).collect();
    let mut t = format!("controllers ({}):\n", ctrls.len());
    for &(k, b) in &ctrls {
        let measured: Vec<String> = b.unit.signals().iter().map(|s| format!("{}={}", s.role, s.path)).collect();
        let driven = &driven_by_block[k];
        // A controller with no input of its own (a PID whose output a ratio station or a
        // cascade slave reads as its setpoint) is read by other blocks instead.
        let drives = if driven.is_empty() {
            format!("no input (its output `{}.op` is read by other controllers)", b.name)
        } else {
            driven.join(", ")
        };
        t.push_str(&format!(
            "  {:<16} {:<12} reads {} drives {drives}\n",
            b.name,
            b.unit.type_name(),
            measured.join(", ")
        ));
    }
    let tags: Vec<_> = plant.blocks().iter().filter(|b| b.kind == BlockKind::Tag).collect();
    if !tags.is_empty() {
        t.push_str(&format!("tags ({}), each the variable `<tag>.value`:\n", tags.len()));
        for b in &tags {
            let v = &plant.vars()[b.own_offset];
            t.push_str(&format!(
                "  {:<16} [{}] = {}\n",
                b.name,
                v.spec.dim,
                b.unit.equation_name(0, &[]).trim_start_matches("value = ")
            ));
        }
    }
    if !plant.specs().is_empty() {
        t.push_str(&format!(
            "design specs ({}), each with its varied input as one more unknown:\n",
            plant.specs().len()
        ));
        for sp in plant.specs() {
            t.push_str(&format!("  {:<16} {}\n", sp.origin, sp.label()));
        }
    }
    t
}

/// The counts of variables, equations and inputs (design specs add a varied input to the unknowns
/// and an equation each), then the free inputs with the file's values.
fn counts(plant: &Plant, system: UnitSystem) -> String {
    let n_diff = plant.differential().iter().filter(|d| **d).count();
    let free: Vec<String> = plant
        .inputs()
        .iter()
        .enumerate()
        .filter(|(k, i)| i.driven_by.is_none() && !plant.specs().iter().any(|s| s.input == *k))
        .map(|(_, i)| format!("{} = {}", i.path, shown(i.value, i.dim, system)))
        .collect();
    let mut t = format!(
        "variables: {} ({} differential, {} algebraic){}; equations: {}{}; inputs: {} ({} driven by controllers{})\n",
        plant.n_vars(),
        n_diff,
        plant.n_vars() - n_diff,
        specs_note(plant.specs().len(), "varied inputs"),
        plant.n_eqs(),
        specs_note(plant.specs().len(), "design specs"),
        plant.inputs().len(),
        plant.inputs().iter().filter(|i| i.driven_by.is_some()).count(),
        specs_note(plant.specs().len(), "varied by specs").replace(" + ", ", ")
    );
    t.push_str("free inputs (manipulated variables and disturbances), with the file's values:\n");
    for f in &free {
        t.push_str(&format!("  {f}\n"));
    }
    t
}

/// ` + k what`, or nothing without specs.
fn specs_note(k: usize, what: &str) -> String {
    if k == 0 { String::new() } else { format!(" + {k} {what}") }
}

/// The note that the Jacobian is singular at the cold-start guess (`e`), though the plant
/// converges from there.
pub fn singular_at_guess(e: &DofError) -> String {
    format!(
        "note: the Jacobian is singular at the cold-start guess ({}), but the plant converges from there: a property of the guess, not of the plant\n",
        e.to_string().rsplit_once("the steady state is not determined: ").map_or("", |(_, why)| why)
    )
}

/// The degrees of freedom found: none, the system square and structurally nonsingular, and
/// `numerically` nonsingular at the initial guess.
pub fn degrees_of_freedom(numerically: bool) -> String {
    format!(
        "degrees of freedom: 0 — square, structurally nonsingular{}\n",
        if numerically { ", numerically nonsingular at the initial guess" } else { "" }
    )
}

/// Residence times of the drums, sumps and vessels against the ~5 min rule at `x`, the steady
/// state (`converged`) or else the initial guess, said so; holdups and flows in `units`. Empty
/// when the plant has no vessel.
pub fn residence(plant: &Plant, x: &[f64], converged: bool, units: UnitSystem) -> String {
    let basis = if converged { "at the steady state" } else { "at the initial guess (the plant did not converge)" };
    let times = residence_times(plant, x);
    if times.is_empty() {
        return String::new();
    }
    let mut t = format!(
        "liquid residence times {basis} (holdup / total flow leaving; rule of thumb ~{:.0} min):\n",
        RULE_OF_THUMB / 60.0
    );
    for r in times {
        t.push_str(&format!(
            "  {:<16} {:>9.2} min  (holdup {}, leaving {}){}\n",
            r.vessel,
            r.time / 60.0,
            shown(r.holdup, Dimension::AMOUNT, units),
            shown(r.throughput, Dimension::MOLAR_FLOW, units),
            if r.short { "  — short: little surge capacity (Practical Distillation Control ch. 1)" } else { "" }
        ));
    }
    t
}
