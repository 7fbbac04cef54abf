//! Tables of `y(x)` with linear or natural cubic-spline interpolation.

use crate::Scalar;
use plantwide_units::Dimension;

/// How a [`Table`] interpolates between its points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    /// Straight lines between points: continuous, with kinks at the points.
    Linear,
    /// The natural cubic spline (second derivative zero at both ends): continuous first and
    /// second derivatives, so Newton sees no kinks. Burden & Faires, *Numerical Analysis*
    /// (9th ed.), §3.5, Algorithm 3.4.
    CubicSpline,
}

/// A bad set of table points.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TableError {
    /// Fewer than two points.
    #[error("a table needs at least 2 points, found {n}")]
    TooFewPoints {
        /// Points given.
        n: usize,
    },
    /// `x` and `y` of different lengths.
    #[error("{n_x} x values but {n_y} y values")]
    LengthMismatch {
        /// Number of x values.
        n_x: usize,
        /// Number of y values.
        n_y: usize,
    },
    /// `x` not strictly increasing.
    #[error("x must be strictly increasing, but x[{index}] = {value} does not exceed the point before it")]
    NotIncreasing {
        /// Index of the offending x.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A NaN or infinite value.
    #[error("point {index} is not finite")]
    NonFinite {
        /// Index of the point.
        index: usize,
    },
}

/// A table `y(x)` through points `(x_k, y_k)`, x strictly increasing, with the dimensions of its
/// input and output.
///
/// Outside `[x_0, x_last]` it extrapolates along the straight line of the end slope (the end
/// segment for [`Interpolation::Linear`], the spline's end tangent for
/// [`Interpolation::CubicSpline`], which keeps the natural spline twice differentiable there).
/// Evaluation finds the interval by bisection, `O(log n)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    xs: Vec<f64>,
    ys: Vec<f64>,
    /// Second derivatives at the points (all zero for linear tables).
    m: Vec<f64>,
    interpolation: Interpolation,
    input: Dimension,
    output: Dimension,
}

impl Table {
    /// A table through `(xs[k], ys[k])`, its input in dimension `input`, its output in `output`.
    ///
    /// # Errors
    /// Fewer than two points, unequal lengths, x not strictly increasing, or a value not finite.
    pub fn new(
        xs: Vec<f64>,
        ys: Vec<f64>,
        interpolation: Interpolation,
        input: Dimension,
        output: Dimension,
    ) -> Result<Table, TableError> {
        validate(&xs, &ys)?;
        let m = match interpolation {
            Interpolation::Linear => vec![0.0; xs.len()],
            Interpolation::CubicSpline => natural_spline_second_derivatives(&xs, &ys),
        };
        Ok(Table { xs, ys, m, interpolation, input, output })
    }

    /// The dimension of the argument.
    pub fn input(&self) -> Dimension {
        self.input
    }

    /// The dimension of the value.
    pub fn output(&self) -> Dimension {
        self.output
    }

    /// The interpolation.
    pub fn interpolation(&self) -> Interpolation {
        self.interpolation
    }

    /// The interpolated value at `x`, differentiable through `S` (the interval is chosen by the
    /// real part of `x`).
    pub fn eval<S: Scalar>(&self, x: S) -> S {
        let n = self.xs.len();
        let xr = x.re();
        if xr < self.xs[0] {
            return (x - self.xs[0]) * self.end_slope(false) + self.ys[0];
        }
        if xr > self.xs[n - 1] {
            return (x - self.xs[n - 1]) * self.end_slope(true) + self.ys[n - 1];
        }
        let k = self.xs.partition_point(|&v| v <= xr).clamp(1, n - 1) - 1;
        self.on_interval(k, x)
    }

    /// The spline on `[x_k, x_{k+1}]` (Burden & Faires eq. 3.21 in second-derivative form):
    /// `S = (M_k a³ + M_{k+1} b³)/(6h) + (y_k/h − M_k h/6)·a + (y_{k+1}/h − M_{k+1} h/6)·b`
    /// with `a = x_{k+1} − x`, `b = x − x_k`, `h = x_{k+1} − x_k`; with all `M = 0` this is the
    /// straight line.
    fn on_interval<S: Scalar>(&self, k: usize, x: S) -> S {
        let (x0, x1, y0, y1) = (self.xs[k], self.xs[k + 1], self.ys[k], self.ys[k + 1]);
        let h = x1 - x0;
        let (a, b) = ((-x) + x1, x - x0);
        let line = a * (y0 / h) + b * (y1 / h);
        if self.interpolation == Interpolation::Linear {
            return line;
        }
        let (m0, m1) = (self.m[k], self.m[k + 1]);
        line + (a * a * a * m0 + b * b * b * m1) / (6.0 * h) - a * (m0 * h / 6.0) - b * (m1 * h / 6.0)
    }

    /// dy/dx at the first (`last = false`) or last point.
    fn end_slope(&self, last: bool) -> f64 {
        let n = self.xs.len();
        let k = if last { n - 2 } else { 0 };
        let h = self.xs[k + 1] - self.xs[k];
        let secant = (self.ys[k + 1] - self.ys[k]) / h;
        // S'(x_k) = secant − h(2M_k + M_{k+1})/6; S'(x_{k+1}) = secant + h(M_k + 2M_{k+1})/6.
        if last {
            secant + h * (self.m[k] + 2.0 * self.m[k + 1]) / 6.0
        } else {
            secant - h * (2.0 * self.m[k] + self.m[k + 1]) / 6.0
        }
    }
}

fn validate(xs: &[f64], ys: &[f64]) -> Result<(), TableError> {
    if xs.len() != ys.len() {
        return Err(TableError::LengthMismatch { n_x: xs.len(), n_y: ys.len() });
    }
    if xs.len() < 2 {
        return Err(TableError::TooFewPoints { n: xs.len() });
    }
    if let Some(index) = xs.iter().zip(ys).position(|(x, y)| !x.is_finite() || !y.is_finite()) {
        return Err(TableError::NonFinite { index });
    }
    match xs.windows(2).position(|w| w[1] <= w[0]) {
        Some(k) => Err(TableError::NotIncreasing { index: k + 1, value: xs[k + 1] }),
        None => Ok(()),
    }
}

/// Second derivatives `M_k` of the natural cubic spline (`M_0 = M_last = 0`), from the
/// tridiagonal system `h_{k−1} M_{k−1} + 2(h_{k−1} + h_k) M_k + h_k M_{k+1} =
/// 6((y_{k+1} − y_k)/h_k − (y_k − y_{k−1})/h_{k−1})`, solved by the Thomas algorithm
/// (diagonally dominant, so no pivoting is needed).
fn natural_spline_second_derivatives(xs: &[f64], ys: &[f64]) -> Vec<f64> {
    let n = xs.len();
    let mut m = vec![0.0; n];
    if n < 3 {
        return m;
    }
    let h: Vec<f64> = xs.windows(2).map(|w| w[1] - w[0]).collect();
    // Forward sweep over the interior unknowns 1..n-1.
    let (mut diag, mut rhs) = (vec![0.0; n], vec![0.0; n]);
    for k in 1..n - 1 {
        let mut d = 2.0 * (h[k - 1] + h[k]);
        let mut r = 6.0 * ((ys[k + 1] - ys[k]) / h[k] - (ys[k] - ys[k - 1]) / h[k - 1]);
        if k > 1 {
            let w = h[k - 1] / diag[k - 1];
            d -= w * h[k - 1];
            r -= w * rhs[k - 1];
        }
        diag[k] = d;
        rhs[k] = r;
    }
    for k in (1..n - 1).rev() {
        m[k] = (rhs[k] - h[k] * m[k + 1]) / diag[k];
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_dual::Dual64;

    fn dimless(xs: Vec<f64>, ys: Vec<f64>, i: Interpolation) -> Table {
        Table::new(xs, ys, i, Dimension::DIMENSIONLESS, Dimension::DIMENSIONLESS).unwrap()
    }

    #[test]
    fn linear_interpolates_and_extrapolates() {
        let t = dimless(vec![0.0, 1.0, 3.0], vec![1.0, 3.0, 4.0], Interpolation::Linear);
        assert!((t.eval(0.5_f64) - 2.0).abs() < 1e-15);
        assert!((t.eval(2.0_f64) - 3.5).abs() < 1e-15);
        assert!((t.eval(-1.0_f64) - (-1.0)).abs() < 1e-15);
        assert!((t.eval(5.0_f64) - 5.0).abs() < 1e-15);
        assert!((t.eval(Dual64::new(2.0, 1.0)).eps - 0.5).abs() < 1e-15);
    }

    /// The natural spline reproduces any straight line exactly, and through the points of
    /// y = x³ on [0, 1, 2] it is the known interpolant: with h = 1 the system is 4·M₁ = 6·(7 − 1),
    /// M₁ = 9, and on [0, 1] (a = 1 − x, b = x) S = M₁·b³/6 + (y₁ − M₁/6)·b = 1.5·b³ − 0.5·b, so
    /// S(0.5) = 0.1875 − 0.25 = −0.0625 and S'(0.5) = 4.5·0.25 − 0.5 = 0.625.
    #[test]
    fn natural_spline_known_values() {
        let line = dimless(vec![0.0, 1.0, 2.5, 4.0], vec![1.0, 3.0, 6.0, 9.0], Interpolation::CubicSpline);
        for x in [0.3, 1.7, 3.9, 5.0, -2.0] {
            assert!((line.eval::<f64>(x) - (1.0 + 2.0 * x)).abs() < 1e-12, "{x}");
        }
        let cubic = dimless(vec![0.0, 1.0, 2.0], vec![0.0, 1.0, 8.0], Interpolation::CubicSpline);
        assert!((cubic.eval(0.5_f64) - (-0.0625)).abs() < 1e-14);
        assert!((cubic.eval(Dual64::new(0.5, 1.0)).eps - 0.625).abs() < 1e-14);
        // Through the points exactly.
        assert!((cubic.eval(1.0_f64) - 1.0).abs() < 1e-14 && (cubic.eval(2.0_f64) - 8.0).abs() < 1e-14);
        // Beyond x = 2 along the end tangent: S'(2) = 7 + 1·(M₁ + 2·0)/6 = 8.5.
        assert!((cubic.eval(3.0_f64) - 16.5).abs() < 1e-13);
    }

    #[test]
    fn bad_points_are_refused() {
        let t = |xs: Vec<f64>, ys: Vec<f64>| {
            Table::new(xs, ys, Interpolation::Linear, Dimension::DIMENSIONLESS, Dimension::DIMENSIONLESS)
        };
        assert_eq!(t(vec![1.0], vec![1.0]), Err(TableError::TooFewPoints { n: 1 }));
        assert_eq!(t(vec![1.0, 2.0], vec![1.0]), Err(TableError::LengthMismatch { n_x: 2, n_y: 1 }));
        assert_eq!(t(vec![1.0, 1.0], vec![1.0, 2.0]), Err(TableError::NotIncreasing { index: 1, value: 1.0 }));
        assert_eq!(t(vec![1.0, f64::NAN], vec![1.0, 2.0]), Err(TableError::NonFinite { index: 1 }));
    }
}
