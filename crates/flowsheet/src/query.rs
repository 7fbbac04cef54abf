//! Read-only questions about an assembled plant that the solvers ask without knowing the stream
//! layout: which global variables hold a stream's molar flow and its composition.

use std::ops::Range;

use plantwide_model::stream::{F, Z0};

use crate::plant::Plant;

impl Plant {
    /// Global index of the molar flow `F` [mol/s] of stream `s`.
    pub fn stream_flow_var(&self, s: usize) -> usize {
        self.streams()[s].offset + F
    }

    /// Global indices of the mole fractions `z_c` of stream `s`, one per component in component
    /// order.
    pub fn stream_composition_vars(&self, s: usize) -> Range<usize> {
        let z0 = self.streams()[s].offset + Z0;
        z0..z0 + self.components().len()
    }
}
