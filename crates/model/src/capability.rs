//! What a unit declares of itself to the layers above the equations, so that none of them
//! recognises a unit by its type name: the duties it books ([`Duty`]), its place at the plant's
//! boundary ([`Boundary`]) and how it is drawn ([`Shape`]). Each is a [`crate::UnitModel`] method
//! with a default; `ARCHITECTURE.md` lists them with what the default means.

use std::borrow::Cow;

use serde::Serialize;

/// Where a unit stands at the plant's boundary. The steady-state certificate balances the
/// plant's sources against its sinks and every interior unit on its own; the dynamic
/// conservation check integrates `Σ sources − Σ sinks` against the holdups.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Boundary {
    /// Inside the plant: what flows in flows out or is held (the default).
    Interior,
    /// Material enters the plant here (a feed).
    Source,
    /// Material leaves the plant here (a product).
    Sink,
}

/// Where a duty's value is read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DutySource {
    /// An own variable of the unit, by local name (`"Q"`; a name from the file for an `equations`
    /// unit).
    Var(Cow<'static, str>),
    /// An input of the unit, by local name (`"reboiler_duty"`): its value where it is free, the
    /// output of the controller that drives it otherwise.
    Input(Cow<'static, str>),
}

/// How a duty \[W\] is booked in an energy balance of utilities.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Booking {
    /// A utility: heating when positive, cooling when negative. An input driven by a unit that
    /// moves heat between process streams ([`crate::UnitModel::moves_process_heat`]) is not one
    /// and is left out.
    Utility,
    /// Heat removed when positive (a condenser's `Qc`), booked as `coupled − Qc`: cooling, less
    /// the part of it the input `coupled` takes to another process stream when a unit that moves
    /// process heat drives that input.
    Removed {
        /// The input that carries the heat to a process stream when coupled.
        coupled: &'static str,
    },
    /// Heat moved between two process streams (an exchanger), either sign.
    Recovered,
}

/// A duty the unit books in `compare`'s energy use.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Duty {
    /// Where its value is read.
    pub source: DutySource,
    /// How it is booked.
    pub booking: Booking,
}

/// A utility the unit uses that is a flow, not a duty (steam in kg/s, a boilup in mol/s): the
/// input's local name and the unit its value is reported in (SI).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UtilityFlow {
    /// The input's local name.
    pub input: &'static str,
    /// Its SI unit, as reported.
    pub unit: &'static str,
}

/// How the browser simulator draws a unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// A box (the default).
    Block,
    /// A column: two cells tall, with its stages (whose temperatures `T[1]`, `T[2]`, … sensor
    /// selection reads).
    Column,
    /// A vessel holding a liquid level (a tank, a drum, a reactor).
    Vessel,
    /// An arrow into the plant (a feed).
    Source,
    /// An arrow out of the plant (a product).
    Sink,
}
