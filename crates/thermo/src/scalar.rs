//! The scalar type of everything that may be differentiated: `f64` or a dual number.

use num_dual::DualNum;

/// A real scalar for residual code: `f64` for plain evaluation, `num_dual::Dual64` for exact
/// forward-mode derivatives. All arithmetic with `f64` constants and the elementary functions
/// (`exp`, `ln`, `powf`, `sqrt`, `recip`, …) of `num_dual::DualNum` are available.
pub trait Scalar: DualNum<Primitive = f64> + Copy + Send + Sync + 'static {}

impl<T: DualNum<Primitive = f64> + Copy + Send + Sync + 'static> Scalar for T {}
