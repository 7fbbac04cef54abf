//! `plantwide check FILE`: validate and summarize; values in the `--units` system (default SI).

use std::path::Path;

use plantwide::flowsheet::BlockKind;
use plantwide::solve::{DofProbe, dof_check};
use plantwide::units::{Dimension, UnitSystem};

use super::CliError;

pub fn run(file: &Path, system: UnitSystem) -> Result<(), CliError> {
    let plant = super::steady::load_plant(file, &[])?;
    outln!("flowsheet `{}` ({})", plant.name(), file.display());
    outln!("components ({}): {}", plant.components().len(), plant.components().join(", "));
    let units: Vec<_> = plant.blocks().iter().filter(|b| b.kind == BlockKind::Unit).collect();
    outln!("units ({}):", units.len());
    for b in &units {
        outln!("  {:<16} {}", b.name, b.unit.type_name());
    }
    outln!("streams ({}):", plant.streams().len());
    for s in plant.streams() {
        let (fb, fp) = s.from;
        let (tb, tp) = s.to;
        let from = &plant.blocks()[fb];
        let to = &plant.blocks()[tb];
        outln!(
            "  {:<16} {}.{} -> {}.{}",
            s.name,
            from.name,
            from.unit.outlet_ports()[fp],
            to.name,
            to.unit.inlet_ports()[tp]
        );
    }
    print_controllers_and_specs(&plant);
    let n_diff = plant.differential().iter().filter(|d| **d).count();
    let free: Vec<String> = plant
        .inputs()
        .iter()
        .enumerate()
        .filter(|(k, i)| i.driven_by.is_none() && !plant.specs().iter().any(|s| s.input == *k))
        .map(|(_, i)| format!("{} = {}", i.path, super::steady::shown(i.value, i.dim, system)))
        .collect();
    outln!(
        "variables: {} ({} differential, {} algebraic){}; equations: {}{}; inputs: {} ({} driven by controllers{})",
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
    outln!("free inputs (manipulated variables and disturbances), with the file's values:");
    for f in &free {
        outln!("  {f}");
    }
    let recycles = plant.recycles();
    if recycles.is_empty() {
        outln!("recycles: none");
    } else {
        for (k, r) in recycles.iter().enumerate() {
            outln!("recycle {}: {}", k + 1, r.join(" -> "));
        }
    }
    let u = plant.input_values();
    let x = plant.initial_guess();
    // The numerical probe judges one point: a singular Jacobian at the cold-start guess (a dry tray,
    // a closed valve) proves nothing until the plant also fails to converge from there.
    let numerical = match dof_check(&plant, &u, &x, DofProbe::Numerical) {
        Ok(()) => true,
        Err(e @ plantwide::solve::DofError::Count { .. }) => return Err(CliError::user(e.to_string())),
        Err(e) => match super::steady::converge(&plant, &u) {
            Ok(_) => {
                outln!(
                    "note: the Jacobian is singular at the cold-start guess ({}), but the plant converges from there: a property of the guess, not of the plant",
                    e.to_string().rsplit_once("the steady state is not determined: ").map_or("", |(_, why)| why)
                );
                false
            }
            Err(_) => return Err(CliError::user(e.to_string())),
        },
    };
    outln!(
        "degrees of freedom: 0 — square, structurally nonsingular{}",
        if numerical { ", numerically nonsingular at the initial guess" } else { "" }
    );
    plantwide::solve::sequential::plan(&plant, &u, &x).describe(&plant).iter().for_each(|l| outln!("{l}"));
    residence(&plant, &u, &x, system);
    Ok(())
}

/// The controllers (what each reads and drives) and the design specs.
fn print_controllers_and_specs(plant: &plantwide::flowsheet::Plant) {
    let ctrls: Vec<_> = plant.blocks().iter().filter(|b| b.kind == BlockKind::Controller).collect();
    outln!("controllers ({}):", ctrls.len());
    for b in &ctrls {
        let measured: Vec<String> = b.unit.signals().iter().map(|s| format!("{}={}", s.role, s.path)).collect();
        let driven: Vec<&str> = plant
            .inputs()
            .iter()
            .filter(|i| {
                i.driven_by.is_some_and(|v| {
                    plant.vars()[v].block
                        == plant.blocks().iter().position(|x| std::ptr::eq(x, *b)).unwrap_or(usize::MAX)
                })
            })
            .map(|i| i.path.as_str())
            .collect();
        // A controller with no input of its own (a PID whose output a ratio station or a
        // cascade slave reads as its setpoint) is read by other blocks instead.
        let drives = if driven.is_empty() {
            format!("no input (its output `{}.op` is read by other controllers)", b.name)
        } else {
            driven.join(", ")
        };
        outln!("  {:<16} {:<12} reads {} drives {drives}", b.name, b.unit.type_name(), measured.join(", "));
    }
    if !plant.specs().is_empty() {
        outln!("design specs ({}), each with its varied input as one more unknown:", plant.specs().len());
        for sp in plant.specs() {
            outln!("  {:<16} {}", sp.origin, sp.label());
        }
    }
}

fn specs_note(k: usize, what: &str) -> String {
    if k == 0 { String::new() } else { format!(" + {k} {what}") }
}

/// Residence times of the drums, sumps and vessels against the ~5 min rule, at the steady state
/// (or, when the plant does not converge, at the initial guess, said so).
fn residence(plant: &plantwide::flowsheet::Plant, u: &[f64], guess: &[f64], units: UnitSystem) {
    use plantwide::studies::size::residence::{RULE_OF_THUMB, residence_times};
    let (x, basis) = match super::steady::converge(plant, u) {
        Ok(s) => (s.x, "at the steady state"),
        Err(_) => (guess.to_vec(), "at the initial guess (the plant did not converge)"),
    };
    let times = residence_times(plant, &x);
    if times.is_empty() {
        return;
    }
    outln!(
        "liquid residence times {basis} (holdup / total flow leaving; rule of thumb ~{:.0} min):",
        RULE_OF_THUMB / 60.0
    );
    for r in times {
        outln!(
            "  {:<16} {:>9.2} min  (holdup {}, leaving {}){}",
            r.vessel,
            r.time / 60.0,
            super::steady::shown(r.holdup, Dimension::AMOUNT, units),
            super::steady::shown(r.throughput, Dimension::MOLAR_FLOW, units),
            if r.short { "  — short: little surge capacity (Practical Distillation Control ch. 1)" } else { "" }
        );
    }
}
