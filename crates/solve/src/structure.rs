//! Structural analysis: a maximum matching of equations to unknowns, from `plantwide-structure`
//! (Hopcroft–Karp from the diagonal matching, O(√n · nnz)). An unmatched unknown is not determined
//! by any equation left over; an unmatched equation over-determines the system.

pub use plantwide_structure::{Matching, maximum_matching};
