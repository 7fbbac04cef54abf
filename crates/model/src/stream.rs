//! Material streams. A stream is a block of variables owned by the unit that produces it:
//! `[F, T, P, h, z_1 … z_n]` — molar flow [mol/s], temperature [K], pressure [Pa], molar enthalpy
//! [J/mol] and overall mole fractions [-]. The enthalpy is carried so that two-phase streams close
//! their energy balance exactly; consumers use `F·h` in energy balances and `T` only where the
//! physics needs it.

use plantwide_units::Dimension;

use crate::{Scalar, VarSpec};

/// Index of the molar flow in a stream block.
pub const F: usize = 0;
/// Index of the temperature in a stream block.
pub const T: usize = 1;
/// Index of the pressure in a stream block.
pub const P: usize = 2;
/// Index of the molar enthalpy in a stream block.
pub const H: usize = 3;
/// Index of the first mole fraction in a stream block.
pub const Z0: usize = 4;

/// Layout of a stream block for `n_comp` components.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StreamLayout {
    /// Number of components.
    pub n_comp: usize,
}

impl StreamLayout {
    /// Number of variables in one stream block.
    pub fn len(&self) -> usize {
        Z0 + self.n_comp
    }
    /// Always false: a stream has at least F, T, P, h.
    pub fn is_empty(&self) -> bool {
        false
    }
    /// Variable descriptions of a stream block, local names `F`, `T`, `P`, `h`, `x[<comp>]`.
    pub fn var_specs(&self, comp_names: &[String], nominal_flow: f64) -> Vec<VarSpec> {
        let mut v = vec![
            VarSpec::algebraic("F", Dimension::MOLAR_FLOW, nominal_flow).bounded(0.0, f64::INFINITY),
            VarSpec::algebraic("T", Dimension::TEMPERATURE, 350.0).bounded(1.0, 5000.0),
            VarSpec::algebraic("P", Dimension::PRESSURE, 1e5).bounded(1.0, 1e9),
            VarSpec::algebraic("h", Dimension::MOLAR_ENERGY, 3e4),
        ];
        for name in comp_names {
            v.push(VarSpec::algebraic(format!("x[{name}]"), Dimension::DIMENSIONLESS, 1.0).bounded(0.0, 1.0));
        }
        v
    }
}

/// A read-only view of one stream's variables.
#[derive(Debug, Clone, Copy)]
pub struct Stream<'a, S> {
    /// The `nc + 4` values `[F, T, P, h, z…]`.
    pub v: &'a [S],
}

impl<'a, S: Scalar> Stream<'a, S> {
    /// Molar flow [mol/s].
    pub fn f(&self) -> S {
        self.v[F]
    }
    /// Temperature [K].
    pub fn t(&self) -> S {
        self.v[T]
    }
    /// Pressure [Pa].
    pub fn p(&self) -> S {
        self.v[P]
    }
    /// Molar enthalpy [J/mol].
    pub fn h(&self) -> S {
        self.v[H]
    }
    /// Mole fractions.
    pub fn z(&self) -> &'a [S] {
        &self.v[Z0..]
    }
}

/// Residuals that make outlet stream `out` a copy of `inlet` with flow `flow`
/// (`nc + 4` equations written into `r`).
pub fn copy_stream<S: Scalar>(out: Stream<'_, S>, inlet: Stream<'_, S>, flow: S, r: &mut [S]) {
    r[F] = out.f() - flow;
    r[T] = out.t() - inlet.t();
    r[P] = out.p() - inlet.p();
    r[H] = out.h() - inlet.h();
    for (k, (zo, zi)) in out.z().iter().zip(inlet.z()).enumerate() {
        r[Z0 + k] = *zo - *zi;
    }
}
