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
    /// Bounds `[lo, hi]` of unknown `i`.
    fn bounds(&self, i: usize) -> (f64, f64);
    /// Entries `(row, col)` of the mass matrix `M` (each 1): the equation that is the time
    /// derivative of a differential unknown.
    fn mass(&self) -> Vec<(usize, usize)>;
}
