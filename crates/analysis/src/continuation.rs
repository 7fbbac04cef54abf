//! Natural-parameter continuation with step control: a parameter moved from one value to another
//! in steps, each solved from the last solution; a step that fails is halved (down to a floor)
//! and, after a success, doubled back toward the first step. The sensitivity sweeps walk each
//! disturbance with it, and `select FILE` holds a combination of measurements along one.

/// Where a continuation stopped: the last solution, the parameter value it belongs to, the value
/// that could not be reached from there with the smallest step, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Stalled<S, E> {
    /// The last solution.
    pub state: S,
    /// Its parameter value.
    pub reached: f64,
    /// The value the smallest step aimed at.
    pub tried: f64,
    /// Why that step failed.
    pub error: E,
}

/// The step sizes of a continuation (magnitudes, in the parameter's units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Steps {
    /// The first step.
    pub first: f64,
    /// The largest a step may grow to by doubling.
    pub largest: f64,
    /// The smallest step tried: its failure ends the continuation.
    pub smallest: f64,
}

impl Steps {
    /// Steps of `first`, never growing beyond it, halved `halvings` times at most.
    pub fn halving(first: f64, halvings: u32) -> Steps {
        let first = first.abs();
        Steps { first, largest: first, smallest: first / f64::from(2_u32.pow(halvings)) }
    }
}

/// Move the parameter from `from` to `to` starting at the solution `state` of `from`, in `steps`
/// (their sign taken from the direction), each solved by `advance(solution, at, next)`. A failed
/// step is halved; a step that succeeds doubles the next, up to `steps.largest`.
///
/// # Errors
/// [`Stalled`] when a step of `steps.smallest` (or less) fails.
pub fn reach<S, E>(
    state: S,
    (from, to): (f64, f64),
    steps: Steps,
    mut advance: impl FnMut(&S, f64, f64) -> Result<S, E>,
) -> Result<S, Stalled<S, E>> {
    let direction = if to < from { -1.0 } else { 1.0 };
    let (mut state, mut at, mut step) = (state, from, steps.first);
    while at != to {
        let next = if (to - at).abs() <= step { to } else { at + direction * step };
        match advance(&state, at, next) {
            Ok(s) => {
                (state, at) = (s, next);
                step = (2.0 * step).min(steps.largest);
            }
            Err(error) if step <= steps.smallest * (1.0 + 1e-12) => {
                return Err(Stalled { state, reached: at, tried: next, error });
            }
            Err(_) => step /= 2.0,
        }
    }
    Ok(state)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halves_at_a_hard_stretch_and_doubles_back() {
        // Steps longer than 0.1 fail inside [0.3, 0.5]: the walk halves there and still arrives.
        let mut steps = Vec::new();
        let got = reach(0.0, (0.0, 1.0), Steps::halving(0.25, 6), |_, at: f64, next: f64| {
            steps.push(next - at);
            if (0.3..=0.5).contains(&next) && next - at > 0.1 { Err("too long") } else { Ok(next) }
        });
        assert_eq!(got, Ok(1.0));
        assert!(steps.iter().any(|&s| s < 0.1) && steps.last().is_some_and(|&s| s > 0.1), "{steps:?}");
    }

    #[test]
    fn stops_with_the_last_solution_when_even_the_smallest_step_fails() {
        let got = reach(
            0.0,
            (0.0, -1.0),
            Steps::halving(0.25, 3),
            |_, _, next: f64| if next < -0.4 { Err(next) } else { Ok(next) },
        );
        let stalled = got.unwrap_err();
        assert_eq!((stalled.state, stalled.reached), (-0.375, -0.375));
        assert!((stalled.tried - (-0.375 - 0.25 / 8.0)).abs() < 1e-15, "{stalled:?}");
    }
}
