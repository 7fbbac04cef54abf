//! Scalar root finding and maximisation on a bracket.

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
}
