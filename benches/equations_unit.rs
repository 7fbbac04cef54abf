//! Issue 57: a unit written as equations against the built-in unit it reproduces, in the time of
//! one residual + Jacobian evaluation (median of repeated runs, at the converged steady state).
//!
//! - **unit**: the unit's own evaluation as the plant calls it for one block,
//!   `Unit::residual` then `Unit::jacobian_colored` with the block's colouring (`f64` for the
//!   residual, forward-mode duals for the Jacobian, one pass per colour), on the gathered local
//!   vector;
//! - **plant**: the whole plant's `Plant::residual` + `Plant::jacobian` (feed, product and the
//!   level controller included, so the ratio is diluted by the shared work).
//!
//! Pairs: the CSTR of `flowsheets/cstr_multiplicity.json` against `tests/data/cstr_equations.json`,
//! the surge tank of `flowsheets/surge_tank_pi.json` against `tests/data/surge_tank_equations.json`.
//! The target is the equations version within 3× of the built-in. Run with
//! `cargo bench --bench equations_unit`.

use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

use plantwide::flowsheet::{Plant, load_file, with_dense_jacobian};
use plantwide::model::UnitIo;
use plantwide::solve::{NewtonSettings, steady_state};

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

/// Median time per call of `f`, each sample a batch of `batch` calls, within about `budget`.
fn time<F: FnMut()>(mut f: F, batch: usize, budget: Duration) -> Duration {
    f();
    let mut samples = Vec::new();
    let start = Instant::now();
    while samples.len() < 5 || (start.elapsed() < budget && samples.len() < 10_000) {
        let t = Instant::now();
        for _ in 0..batch {
            f();
        }
        samples.push(t.elapsed() / batch as u32);
    }
    median(samples)
}

fn load(rel: &str) -> (Plant, Vec<f64>) {
    let plant = load_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
    let x = steady_state(&plant, &plant.input_values(), None, &NewtonSettings::default())
        .unwrap_or_else(|e| panic!("{rel}: {e}"))
        .x;
    (plant, x)
}

/// Time of one residual + Jacobian of block `unit` of `plant` at `x`, and of the whole plant's.
fn measure(plant: &Plant, x: &[f64], unit: &str, budget: Duration) -> (Duration, Duration) {
    let u = plant.input_values();
    let b = &plant.blocks()[plant.block_index(unit).unwrap_or_else(|| panic!("no unit `{unit}`"))];
    let mut local = Vec::new();
    plant.gather(b, x, &u, &mut local);
    let io = UnitIo { local: &local, layout: &b.layout, thermo: plant.thermo(), time: 0.0 };
    let mut r = vec![0.0; b.n_eq];
    let t_unit = with_dense_jacobian(b.n_eq * local.len(), |jac| {
        time(
            || {
                b.unit.residual(&io, &mut r);
                b.unit.jacobian_colored(&io, &mut r, jac, b.coloring.as_ref());
                black_box(&jac[0]);
            },
            100,
            budget,
        )
    });
    let mut rp = vec![0.0; plant.n_eqs()];
    let (mut jx, mut ju) = (Vec::new(), Vec::new());
    let t_plant = time(
        || {
            plant.residual(x, &u, 0.0, &mut rp);
            plant.jacobian(x, &u, 0.0, &mut rp, &mut jx, &mut ju);
            black_box(&jx);
        },
        20,
        budget,
    );
    (t_unit, t_plant)
}

fn main() {
    // Rounds alternate the built-in and the equations version, so that a change of the machine's
    // load (a shared 2-core machine) weighs on both; the median over the rounds is reported.
    let (rounds, budget) = (7, Duration::from_millis(300));
    println!(
        "{:<12} {:<6} {:>14} {:>14} {:>7}   (residual + Jacobian, median per call over {rounds} rounds)",
        "unit", "scope", "built-in", "equations", "ratio"
    );
    let mut worst: f64 = 0.0;
    for (label, unit, builtin, eqs) in [
        ("cstr", "reactor", "flowsheets/cstr_multiplicity.json", "tests/data/cstr_equations.json"),
        ("surge tank", "tank", "flowsheets/surge_tank_pi.json", "tests/data/surge_tank_equations.json"),
    ] {
        let (pb, xb) = load(builtin);
        let (pe, xe) = load(eqs);
        let (mut ub, mut plb, mut ue, mut ple) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for _ in 0..rounds {
            let (u, p) = measure(&pb, &xb, unit, budget);
            ub.push(u);
            plb.push(p);
            let (u, p) = measure(&pe, &xe, unit, budget);
            ue.push(u);
            ple.push(p);
        }
        for (scope, tb, te) in [("unit", median(ub), median(ue)), ("plant", median(plb), median(ple))] {
            let ratio = te.as_secs_f64() / tb.as_secs_f64();
            worst = worst.max(ratio);
            println!(
                "{label:<12} {scope:<6} {:>11.2} µs {:>11.2} µs {ratio:>7.2}",
                tb.as_secs_f64() * 1e6,
                te.as_secs_f64() * 1e6
            );
        }
    }
    println!("worst ratio {worst:.2} (target: within 3x)");
}
