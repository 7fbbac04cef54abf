//! Liquid residence times of a plant's drums, sumps and vessels against the ~5 min rule of
//! *Practical Distillation Control* ch. 1 (R5.3: about 5 min of holdup, "based on the total
//! material entering and leaving" the base or drum; more for large columns, many or large
//! disturbances, units in series).
//!
//! `τ = M / Σ F_out` \[s\]: `M` the liquid holdup \[mol\], `Σ F_out` every flow leaving it \[mol/s\] — a
//! column's drum `L_N + D` (reflux and distillate), its base `V_1 + B` (boilup and bottoms), a
//! vessel the sum of its outlet streams.

use plantwide_flowsheet::{Plant, VarPath};
use serde::Serialize;

/// The rule's holdup time \[s\].
pub const RULE_OF_THUMB: f64 = 300.0;

/// One vessel's residence time.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Residence {
    /// `tank`, `column1.drum`, `column1.sump`.
    pub vessel: String,
    /// Liquid holdup \[mol\].
    pub holdup: f64,
    /// Total flow leaving \[mol/s\].
    pub throughput: f64,
    /// `holdup / throughput` \[s\].
    pub time: f64,
    /// Below [`RULE_OF_THUMB`].
    pub short: bool,
}

/// The residence time of every drum, sump and vessel with a liquid holdup, at the state `x`.
pub fn residence_times(plant: &Plant, x: &[f64]) -> Vec<Residence> {
    let at = |p: &VarPath| plant.var(p).map(|i| x[i]);
    let mut out = Vec::new();
    for (name, u) in &plant.spec().units {
        // What leaves an inventory: each a variable of the unit, or an input (its value, or the
        // output of the controller that drives it).
        let leaving = |p: &String| {
            let path = VarPath::new(name, p);
            at(&path).or_else(|| input_value(plant, x, &path))
        };
        let mut ends: Vec<(String, Option<f64>, Option<f64>)> = u
            .config()
            .inventories()
            .iter()
            .map(|i| {
                let throughput = i.leaving.iter().map(leaving).sum::<Option<f64>>();
                (format!("{name}.{}", i.name), at(&VarPath::new(name, "M").index(i.stage)), throughput)
            })
            .collect();
        if u.config().vessel().is_some() {
            let out_flow: f64 = outlet_streams(plant, name).iter().filter_map(|s| at(&VarPath::new(s, "F"))).sum();
            ends.push((name.clone(), at(&VarPath::new(name, "M")), Some(out_flow)));
        }
        for (vessel, m, f) in ends {
            let (Some(holdup), Some(throughput)) = (m, f) else { continue };
            let time = if throughput > 0.0 { holdup / throughput } else { f64::INFINITY };
            out.push(Residence { vessel, holdup, throughput, time, short: time < RULE_OF_THUMB });
        }
    }
    out
}

/// The value input `path` has at `x`: the driving controller's output, else its own.
fn input_value(plant: &Plant, x: &[f64], path: &VarPath) -> Option<f64> {
    let i = plant.input(path)?;
    let info = &plant.inputs()[i];
    Some(info.driven_by.map_or(info.value, |v| x[v]))
}

/// Names of the streams leaving unit `name`.
fn outlet_streams(plant: &Plant, name: &str) -> Vec<String> {
    let Some(b) = plant.block_index(name) else { return Vec::new() };
    plant.streams_out_of(b).iter().map(|&k| plant.streams()[k].name.clone()).collect()
}
