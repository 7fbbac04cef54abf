//! The unit library of plantwide: every unit and controller is written once, as equations, and that
//! one model serves the whole-plant Newton steady state, dynamic integration and linearization.
//!
//! The plant is the semi-explicit DAE `M · dx/dt = f(x, u, t)`. A unit owns a block of variables
//! (its outlet streams, then its internal variables) and writes a block of residuals: for a
//! differential variable the residual *is* its time derivative; for an algebraic variable it is an
//! equation that is zero at a solution.
//!
//! **Architecture Invariant:** a unit sees only its local read vector ([`UnitIo`]); global indices,
//! other units and solvers never leak in. This crate knows nothing about files or solvers.

#![warn(missing_docs)]

pub mod build;
pub mod capability;
pub mod controllers;
pub mod error;
pub mod limits;
pub mod registry;
pub mod stream;
pub mod tag;
pub mod testing;
pub mod unit;
pub mod units;
pub mod var;

pub use build::{BuildCx, FieldError};
pub use capability::{
    Booking, Boundary, Duty, DutySource, FlowDecl, FlowLaw, FlowVia, InventoryFlows, InventoryPhase, MaterialFlows,
    Shape, UtilityFlow,
};
pub use error::{Error, InputError, SpecError};
pub use registry::{ControllerSpec, Inventory, UnitSpec};
pub use stream::{Stream, StreamLayout};
pub use unit::{Coloring, InputSpec, LocalLayout, Saturation, SignalSpec, Unit, UnitIo, UnitModel};
pub use var::{VarKind, VarSpec};

pub use plantwide_thermo::Scalar;
