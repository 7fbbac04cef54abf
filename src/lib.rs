//! plantwide: plantwide process-control studies from one model of the plant.
//!
//! This facade re-exports the layers: [`thermo`], [`units`] ← [`model`] ← [`flowsheet`] ← [`solve`] ←
//! [`analysis`] ← [`studies`] ← [`io`] (file formats and plots); [`soc`], self-optimizing control on a
//! local model, beside them. The `plantwide` binary (src/main.rs) is
//! the only code that touches the terminal.

pub use plantwide_analysis as analysis;
pub use plantwide_flowsheet as flowsheet;
pub use plantwide_io as io;
pub use plantwide_model as model;
pub use plantwide_soc as soc;
pub use plantwide_solve as solve;
pub use plantwide_studies as studies;
pub use plantwide_thermo as thermo;
pub use plantwide_units as units;
