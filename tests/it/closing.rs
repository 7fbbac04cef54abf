//! Closing the loops from the open plant (`crates/solve/src/sequential/closing.rs`): a plant whose
//! tight quality loops stall the whole-plant Newton from the cold start converges open, then closed
//! along its setpoints. Checked against a second method: with the setpoints put exactly at the
//! open plant's measurements, the closed plant's steady state is the open plant's, each loop's
//! output at the input the open plant holds.

use crate::harness::{fixture, plantwide, value};
use plantwide::flowsheet::{Plant, load_file};
use plantwide::solve::{StrategySettings, converge};

const TRAIN: &str = "data/generated/train_d9e66480.json";

fn train() -> Plant {
    load_file(std::path::Path::new(&fixture(TRAIN))).unwrap_or_else(|e| panic!("{e}"))
}

fn input(plant: &Plant, path: &str) -> usize {
    plant.input(path).unwrap_or_else(|| panic!("no input {path}"))
}

#[test]
fn the_closed_train_reaches_the_open_trains_steady_state() {
    let mut plant = train();
    let loops = [("AC101", "D.x[n-hexane]", "column.reflux"), ("AC102", "B.x[n-hexane]", "column.boilup")];
    let mut open = plant.clone();
    for (c, _, _) in loops {
        open.set_input_value(input(&open, &format!("{c}.auto")), 0.0);
    }
    let settings = StrategySettings::default();
    let open_ss = converge(&open, &settings).unwrap_or_else(|e| panic!("the open train: {e}"));
    for (c, pv, _) in loops {
        plant.set_input_value(input(&plant, &format!("{c}.sp")), value(&open, &open_ss.x, pv));
    }
    let closed = converge(&plant, &settings).unwrap_or_else(|e| panic!("the closed train: {e}"));
    // The cold start of this plant stalls (scaled residual 0.16 on column.L[1]): the path ran.
    let note = closed.closed_loops.as_deref().expect("the loops were closed from the open plant");
    assert!(note.contains("AC101, AC102"), "{note}");
    for (c, pv, mv) in loops {
        let held = open.inputs()[input(&open, mv)].value;
        let op = value(&plant, &closed.x, &format!("{c}.op"));
        assert!((op - held).abs() <= 1e-7 * held, "{c}.op {op} against the open plant's {mv} {held}");
        let (a, b) = (value(&plant, &closed.x, pv), value(&open, &open_ss.x, pv));
        assert!((a - b).abs() <= 1e-9 * b.abs().max(1e-12), "{pv}: {a} against {b}");
    }
}

#[test]
fn steady_says_the_loops_were_closed_from_the_open_plant() {
    let out = plantwide(&["steady", &fixture(TRAIN)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}{stdout}", String::from_utf8_lossy(&out.stderr));
    assert!(
        stdout.contains("the cold start failed: converged open (loops AC101, AC102 in manual), then closed"),
        "{stdout}"
    );
}
