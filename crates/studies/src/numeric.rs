//! Scalar root finding and maximisation on a bracket; Nelder–Mead minimisation of a few
//! parameters (the shape parameters of a step-response fit: two to three of them, where a
//! dependency would bring a linear-algebra stack for forty lines).

/// A root of `f` in `[a, b]` where `f(a)` and `f(b)` differ in sign: regula falsi with the
/// Illinois modification (Dowell & Jarratt 1971), bisecting when it stalls, until the bracket is
/// narrower than `x_tol · max(|a|, |b|)`.
pub(crate) fn root_bracketed(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64, x_tol: f64) -> f64 {
    let (mut fa, mut fb) = (f(a), f(b));
    if fa == 0.0 {
        return a;
    }
    if fb == 0.0 {
        return b;
    }
    debug_assert!(fa.signum() != fb.signum(), "root_bracketed: no sign change on [{a}, {b}]");
    let mut side = 0i32;
    for _ in 0..200 {
        if (b - a).abs() <= x_tol * a.abs().max(b.abs()) {
            break;
        }
        let mut c = (a * fb - b * fa) / (fb - fa);
        if !(c > a.min(b) && c < a.max(b)) || side.abs() > 3 {
            c = 0.5 * (a + b);
            side = 0;
        }
        let fc = f(c);
        if fc == 0.0 {
            return c;
        }
        if fc.signum() == fb.signum() {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = if side < 0 { side - 1 } else { -1 };
        } else {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = if side > 0 { side + 1 } else { 1 };
        }
    }
    0.5 * (a + b)
}

/// The maximum of a unimodal `f` on `[a, b]` by golden-section search, to a bracket narrower
/// than `x_tol` (absolute): returns `(x, f(x))`. Near a smooth maximum `f` is flat to second
/// order, so `x` is only good to about √ε relative while `f(x)` is good to ε.
pub(crate) fn golden_max(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64, x_tol: f64) -> (f64, f64) {
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let mut c = b - r * (b - a);
    let mut d = a + r * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..200 {
        if (b - a).abs() <= x_tol {
            break;
        }
        if fc > fd {
            b = d;
            d = c;
            fd = fc;
            c = b - r * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + r * (b - a);
            fd = f(d);
        }
    }
    if fc > fd { (c, fc) } else { (d, fd) }
}

/// The minimum of `f` over `R^n` by the Nelder–Mead simplex (Lagarias et al. 1998, standard
/// coefficients: reflection 1, expansion 2, contraction ½, shrink ½) from `x0` with initial
/// steps `step`, until the simplex's values differ by less than `f_tol` (absolute) and its
/// vertices by less than `x_tol` in every coordinate, or after `max_evals` evaluations.
/// Returns `(x, f(x), evaluations)`.
pub(crate) fn nelder_mead(
    f: impl Fn(&[f64]) -> f64,
    x0: &[f64],
    step: &[f64],
    tol: (f64, f64),
    max_evals: usize,
) -> (Vec<f64>, f64, usize) {
    let n = x0.len();
    let mut simplex: Vec<(Vec<f64>, f64)> = Vec::with_capacity(n + 1);
    simplex.push((x0.to_vec(), f(x0)));
    for i in 0..n {
        let mut x = x0.to_vec();
        x[i] += step[i];
        let fx = f(&x);
        simplex.push((x, fx));
    }
    let mut evals = n + 1;
    let along = |c: &[f64], w: &[f64], t: f64| -> Vec<f64> { c.iter().zip(w).map(|(c, w)| c + t * (w - c)).collect() };
    while evals < max_evals {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let spread =
            simplex.iter().map(|(x, _)| x.iter().zip(&simplex[0].0).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max));
        if simplex[n].1 - simplex[0].1 <= tol.0 && spread.fold(0.0, f64::max) <= tol.1 {
            break;
        }
        let centroid: Vec<f64> =
            (0..n).map(|j| simplex[..n].iter().map(|(x, _)| x[j]).sum::<f64>() / n as f64).collect();
        let worst = simplex[n].clone();
        let reflected = along(&centroid, &worst.0, -1.0);
        let fr = f(&reflected);
        evals += 1;
        if fr < simplex[0].1 {
            let expanded = along(&centroid, &worst.0, -2.0);
            let fe = f(&expanded);
            evals += 1;
            simplex[n] = if fe < fr { (expanded, fe) } else { (reflected, fr) };
        } else if fr < simplex[n - 1].1 {
            simplex[n] = (reflected, fr);
        } else {
            let (t, bound) = if fr < worst.1 { (-0.5, fr) } else { (0.5, worst.1) };
            let contracted = along(&centroid, &worst.0, t);
            let fc = f(&contracted);
            evals += 1;
            if fc < bound {
                simplex[n] = (contracted, fc);
            } else {
                let best = simplex[0].0.clone();
                for v in simplex.iter_mut().skip(1) {
                    v.0 = along(&best, &v.0, 0.5);
                    v.1 = f(&v.0);
                }
                evals += n;
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (x, fx) = simplex.swap_remove(0);
    (x, fx, evals)
}

/// One classical Runge–Kutta (RK4) step of `dx/dt = f(x)` from `x` over `dt` (the tests' reference
/// integrator of small closed loops).
#[cfg(test)]
pub(crate) fn rk4<const N: usize>(f: impl Fn([f64; N]) -> [f64; N], x: [f64; N], dt: f64) -> [f64; N] {
    let k1 = f(x);
    let k2 = f(std::array::from_fn(|i| x[i] + 0.5 * dt * k1[i]));
    let k3 = f(std::array::from_fn(|i| x[i] + 0.5 * dt * k2[i]));
    let k4 = f(std::array::from_fn(|i| x[i] + dt * k3[i]));
    std::array::from_fn(|i| x[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn root_and_maximum_of_closed_forms() {
        let x = root_bracketed(|x| x * x - 2.0, 0.0, 3.0, 1e-14);
        assert!((x - 2f64.sqrt()).abs() < 1e-13, "{x}");
        let x = root_bracketed(|x| (x - 1.0).powi(3) + 1e-3 * (x - 1.0), 0.0, 10.0, 1e-14);
        assert!((x - 1.0).abs() < 1e-12, "{x}");
        let (x, fx) = golden_max(|x| -(x - 0.3).powi(2) + 1.0, -2.0, 5.0, 1e-12);
        assert!((x - 0.3).abs() < 1e-7 && (fx - 1.0).abs() < 1e-15, "{x} {fx}");
    }

    #[test]
    fn nelder_mead_finds_the_rosenbrock_minimum() {
        // Rosenbrock's valley: minimum 0 at (1, 1), the classic hard case for simplex methods.
        let f = |x: &[f64]| 100.0 * (x[1] - x[0] * x[0]).powi(2) + (1.0 - x[0]).powi(2);
        let (x, fx, evals) = nelder_mead(f, &[-1.2, 1.0], &[0.1, 0.1], (1e-20, 1e-10), 5000);
        assert!((x[0] - 1.0).abs() < 1e-8 && (x[1] - 1.0).abs() < 1e-8, "{x:?} after {evals}");
        assert!(fx < 1e-16, "{fx}");
    }
}
