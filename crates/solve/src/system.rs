//! What a solver needs to know about a nonlinear system `f(x) = 0` that comes from a DAE
//! `M dx/dt = f(x)`.

/// A square nonlinear system with a fixed sparsity pattern.
pub trait System: Sync {
    /// Number of unknowns (= equations).
    fn n(&self) -> usize;
    /// Residuals `f(x)` into `r`.
    fn residual(&self, x: &[f64], r: &mut [f64]);
    /// Residuals into `r` and the Jacobian `∂f/∂x` as triplets into `jac` (duplicates are summed;
    /// the same entries, in the same order, at every `x`).
    fn jacobian(&self, x: &[f64], r: &mut [f64], jac: &mut Vec<(usize, usize, f64)>);
    /// Typical magnitude of unknown `i` (> 0), for scaling.
    fn nominal(&self, i: usize) -> f64;
    /// Size of unknown `i` at `x` (> 0) that the stopping test scales its Jacobian column by
    /// (default: its nominal value; [`crate::SteadySystem`] gives an amount of one component its own
    /// size, so that a trace is judged relatively).
    fn size(&self, _x: &[f64], i: usize) -> f64 {
        self.nominal(i)
    }
    /// Bounds `[lo, hi]` of unknown `i`.
    fn bounds(&self, i: usize) -> (f64, f64);
    /// Entries `(row, col)` of the mass matrix `M` (each 1): the equation that is the time
    /// derivative of a differential unknown.
    fn mass(&self) -> Vec<(usize, usize)>;
}
