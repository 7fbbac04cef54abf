//! Scalar root finders used by the iterative routines (private).

/// Lowest temperature [K] any search will try.
pub(crate) const T_MIN: f64 = 1.0;
/// Highest temperature [K] any search will try.
pub(crate) const T_MAX: f64 = 1.0e5;

const MAX_ITER: usize = 300;

/// Root of an increasing function `f` (value, derivative) on `[lo_limit, hi_limit]`, starting at
/// `x0 > 0`: geometric bracket expansion, then safeguarded Newton (rtsafe), converged until the
/// Newton step is below `1e-14 |x|` or the bracket is a few ulps wide.
///
/// Returns `(root, evaluations)`, or `Err(evaluations)` when no sign change is found or the
/// function is not finite where it must be.
pub(crate) fn solve_increasing<F>(mut f: F, x0: f64, lo_limit: f64, hi_limit: f64) -> Result<(f64, usize), usize>
where
    F: FnMut(f64) -> (f64, f64),
{
    let mut evals = 1;
    let x0 = x0.clamp(lo_limit, hi_limit);
    let (f0, d0) = f(x0);
    if f0 == 0.0 {
        return Ok((x0, evals));
    }
    if f0.is_nan() {
        return Err(evals);
    }
    // Bracket [lo, hi] with f(lo) < 0 < f(hi): march from x0 towards the root (upwards when
    // f(x0) < 0), first with a slightly overshooting Newton probe, then geometrically.
    let up = f0 < 0.0;
    let (mut known, mut f_known, mut d_known) = (x0, f0, d0);
    let mut factor: f64 = 1.02;
    let mut newton_tried = false;
    // The search limit in the marching direction; pulled in where `f` is not a number.
    let mut limit = if up { hi_limit } else { lo_limit };
    let mut limit_is_nan = false;
    let (mut lo, mut hi, mut x, mut fx, mut dx_f);
    loop {
        if evals > MAX_ITER {
            return Err(evals);
        }
        let newton = known - 1.05 * f_known / d_known;
        if !newton_tried && (newton - known).abs() <= 1e-15 * known.abs() {
            return Ok((known, evals)); // already a root to rounding
        }
        let inside = |v: f64| if up { v > known && v < limit } else { v < known && v > limit };
        let next = if !newton_tried && d_known.is_finite() && d_known > 0.0 && newton.is_finite() && inside(newton) {
            newton_tried = true;
            newton
        } else {
            newton_tried = true;
            factor = (factor * factor).min(2.0);
            let geometric = if up { known * factor } else { known / factor };
            if inside(geometric) {
                geometric
            } else if limit_is_nan {
                0.5 * (known + limit)
            } else {
                limit
            }
        };
        if next == known || (limit_is_nan && (limit - known).abs() <= 1e-12 * known.abs()) {
            return Err(evals); // at a search limit without a sign change
        }
        evals += 1;
        let (fv, dv) = f(next);
        if fv.is_nan() {
            limit = next;
            limit_is_nan = true;
            continue;
        }
        if fv == 0.0 {
            return Ok((next, evals));
        }
        if (fv < 0.0) == up {
            (known, f_known, d_known) = (next, fv, dv);
            continue;
        }
        (lo, hi) = if up { (known, next) } else { (next, known) };
        (x, fx, dx_f) =
            if fv.abs() < f_known.abs() || !f_known.is_finite() { (next, fv, dv) } else { (known, f_known, d_known) };
        break;
    }
    // Safeguarded Newton inside the bracket.
    let mut step_old = hi - lo;
    for _ in 0..MAX_ITER {
        let newton_ok = dx_f.is_finite() && dx_f > 0.0 && fx.is_finite();
        let mut x_new = if newton_ok { x - fx / dx_f } else { f64::NAN };
        let fast_enough = newton_ok && (2.0 * fx).abs() <= (step_old * dx_f).abs();
        if !(x_new > lo && x_new < hi && fast_enough) {
            x_new = 0.5 * (lo + hi);
        }
        step_old = (x_new - x).abs();
        let small_step = step_old <= 1e-14 * x.abs().max(1e-300);
        evals += 1;
        let (fv, dv) = f(x_new);
        if fv.is_nan() {
            return Err(evals);
        }
        if fv == 0.0 {
            return Ok((x_new, evals));
        }
        if fv < 0.0 {
            lo = x_new;
        } else {
            hi = x_new;
        }
        (x, fx, dx_f) = (x_new, fv, dv);
        if small_step || hi - lo <= 4.0 * f64::EPSILON * x.abs() {
            return Ok((x, evals));
        }
    }
    Err(evals)
}

/// Brent's method (zeroin) for a sign change of `f` on `[a, b]` with `f(a) = fa`, `f(b) = fb` of
/// opposite signs; converged until the bracket is `4 ε |x|` wide or `|f| ≤ ftol`.
/// Returns `(root, f(root), evaluations)` or `Err(evaluations)` (no convergence or error from `f`).
pub(crate) fn brent<F, E>(
    mut f: F,
    mut a: f64,
    mut b: f64,
    mut fa: f64,
    mut fb: f64,
    ftol: f64,
) -> Result<(f64, f64, usize), (usize, Option<E>)>
where
    F: FnMut(f64) -> Result<f64, E>,
{
    if fa == 0.0 {
        return Ok((a, fa, 0));
    }
    if fb == 0.0 {
        return Ok((b, fb, 0));
    }
    if fa.signum() == fb.signum() || !fa.is_finite() || !fb.is_finite() {
        return Err((0, None));
    }
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    for it in 1..=MAX_ITER {
        if fb.signum() == fc.signum() {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + 1e-300;
        let m = 0.5 * (c - b);
        if m.abs() <= tol || fb.abs() <= ftol {
            return Ok((b, fb, it));
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * m * s;
                q = 1.0 - s;
            } else {
                let qq = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * m * qq * (qq - r) - (b - a) * (r - 1.0));
                q = (qq - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * m * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        } else {
            d = m;
            e = m;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol { d } else { tol.copysign(m) };
        fb = f(b).map_err(|err| (it, Some(err)))?;
        if fb.is_nan() {
            return Err((it, None));
        }
    }
    Err((MAX_ITER, None))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn newton_finds_cube_root() {
        let (x, _) = solve_increasing(|x| (x * x * x - 2.0, 3.0 * x * x), 10.0, 1e-3, 1e3).unwrap();
        assert!((x - 2f64.cbrt()).abs() <= 4.0 * f64::EPSILON);
        let (x, _) = solve_increasing(|x| (x.ln() - 50f64.ln(), 1.0 / x), 0.5, 1e-3, 1e3).unwrap();
        assert!((x - 50.0).abs() <= 1e-13);
    }

    #[test]
    fn newton_reports_missing_root() {
        assert!(solve_increasing(|x| (x + 5.0, 1.0), 1.0, 1.0, 10.0).is_err());
    }

    #[test]
    fn brent_finds_root() {
        let (x, _, _) = brent::<_, ()>(|x| Ok(x.cos() - x), 0.0, 1.0, 1.0, 1f64.cos() - 1.0, 0.0).unwrap();
        assert!((x - 0.739_085_133_215_160_6).abs() < 1e-15);
    }
}
