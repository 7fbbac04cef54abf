//! The integration tests of plantwide, one binary: the shipped flowsheets end to end against
//! published numbers and independent closed forms, the command line, hostile and fuzzed input.
//!
//! One module per subject; [`harness`] holds what they share (the binary as a command, fixture
//! paths, converge-and-read helpers, conservation checks). Data live beside the modules:
//! `tests/broken/`, `tests/hostile/`, `tests/data/`. Run one module with
//! `cargo test --test it columns::` (a name filter); slow tests are `#[ignore]`d with their reason
//! (`-- --include-ignored` runs them), larger campaigns are sized by environment variables
//! (`PLANTWIDE_FUZZ_MUTANTS=…`, `PLANTWIDE_PLANTS=…`).

mod harness;

mod analysis;
mod capabilities;
mod cli;
mod cli_errors;
mod closing;
mod columns;
mod columns_rigorous;
mod compare;
mod conditions;
mod core;
mod display_units;
mod dynamics;
mod equation_units_in_studies;
mod equations_bad_input;
mod evaporator;
mod faults;
mod fehe;
mod flowsheets;
mod fuzz;
mod gas_vessel;
mod generator;
mod heat_integration;
mod hostile;
mod hostile_commands;
mod identify;
mod inventory;
mod layers;
mod mpc;
mod optimize;
mod plots;
mod pressure;
mod recycle;
mod screen;
mod screen_column;
mod select;
mod serve;
mod shard;
mod size;
mod size_newcomer;
mod snowball;
mod specs;
mod tags;
mod thermo_functions;
mod threads;
mod tune;
mod tutorial;
mod two_column_study;
