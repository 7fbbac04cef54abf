//! Variable descriptions: name, kind, SI dimension, typical magnitude and bounds.

use plantwide_units::Dimension;

/// Whether a variable carries a time derivative in the plant DAE.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VarKind {
    /// Appears as `dx/dt` (holdups, energies, controller integrals): `M_ii = 1`.
    Differential,
    /// Defined by an algebraic equation (temperatures, stream variables): `M_ii = 0`.
    Algebraic,
}

/// One variable a unit owns.
#[derive(Debug, Clone, PartialEq)]
pub struct VarSpec {
    /// Local name, e.g. `"M"`, `"T"`, `"x[light]"`, `"M[41]"`; the global path is `unit.name`.
    pub name: String,
    /// Differential or algebraic.
    pub kind: VarKind,
    /// SI dimension of the value.
    pub dim: Dimension,
    /// Typical magnitude used for scaling and finite-difference steps (SI, > 0).
    pub nominal: f64,
    /// Lower bound honoured by Newton (SI).
    pub lower: f64,
    /// Upper bound honoured by Newton (SI).
    pub upper: f64,
    /// A total holdup (moles of a stage, a drum, a vessel): at a steady state it must not rest on
    /// its lower bound, where the equations that divide by it degenerate.
    pub inventory: bool,
}

impl VarSpec {
    /// An unbounded variable.
    pub fn new(name: impl Into<String>, kind: VarKind, dim: Dimension, nominal: f64) -> VarSpec {
        VarSpec {
            name: name.into(),
            kind,
            dim,
            nominal,
            lower: f64::NEG_INFINITY,
            upper: f64::INFINITY,
            inventory: false,
        }
    }
    /// A differential variable.
    pub fn differential(name: impl Into<String>, dim: Dimension, nominal: f64) -> VarSpec {
        VarSpec::new(name, VarKind::Differential, dim, nominal)
    }
    /// An algebraic variable.
    pub fn algebraic(name: impl Into<String>, dim: Dimension, nominal: f64) -> VarSpec {
        VarSpec::new(name, VarKind::Algebraic, dim, nominal)
    }
    /// The same variable marked as a total holdup (see [`VarSpec::inventory`]).
    pub fn inventory(mut self) -> VarSpec {
        self.inventory = true;
        self
    }
    /// The same variable with bounds `[lower, upper]`.
    pub fn bounded(mut self, lower: f64, upper: f64) -> VarSpec {
        self.lower = lower;
        self.upper = upper;
        self
    }
}
