//! Flowsheet files (JSON) and their assembly into one plant DAE.
//!
//! Entry point: [`load_file`] → [`Plant`]. Loading collects every problem it finds and reports them
//! together, each with the file, the JSON path and what would fix it.

#![warn(missing_docs)]

pub mod assemble;
pub mod components;
pub mod design;
pub mod edit;
pub mod error;
pub mod explicit;
pub mod graph;
pub mod guess;
pub mod inventory;
pub mod optimization;
pub mod outputs;
pub mod overrides;
pub mod parse;
pub mod path;
mod plan_cache;
pub mod plant;
pub mod query;
pub mod scenario;
pub mod schema;
pub mod spec;
pub mod tears;
pub mod wiring;
pub mod write;

pub use assemble::{assemble, load_file, load_str};
pub use design::{DesignSpec, SpecEntry, SpecError};
pub use error::{Diagnostic, Error, LoadError};
pub use explicit::ExplicitPlan;
pub use overrides::{Override, OverrideError, load_str_with, load_with};
pub use parse::{parse_spec, read_text};
pub use path::VarPath;
pub use plant::{
    Block, BlockKind, InputInfo, Parallelism, Plant, Read, StreamInfo, TagRef, VarInfo, with_dense_jacobian,
};
pub use spec::FlowsheetSpec;
pub use wiring::{StructureEdit, WiringError};
