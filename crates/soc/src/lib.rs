//! Self-optimizing control: which variables to hold at constant setpoints so that the plant stays
//! near its economic optimum as the disturbances come (Skogestad's top-down procedure, step 3).
//!
//! * [`model`]: the local model at the optimum (`Gy`, `Gyd`, `Juu`, `Jud`, `Wd`, `Wn`), checked.
//! * [`loss`]: the loss of a measurement combination, the exact local method's best one and the
//!   null-space one.
//! * [`bnb`]: the best subsets of the candidates by bidirectional branch and bound, and by
//!   enumeration.
//! * [`matrices`]: published linear data as a JSON file.

mod dense;

pub mod bnb;
pub mod error;
pub mod loss;
pub mod matrices;
pub mod model;

pub use bnb::{Criterion, DEFAULT_MAX_NODES, Ranking, Search, branch_and_bound, enumerate};
pub use error::SocError;
pub use loss::{Combination, Losses, exact_local, losses_of, null_space};
pub use model::{LocalModel, Parts};
