//! Periodic instants of a run: controller scans, analyzer samples, MPC executions.
//!
//! The `k`-th instant of a period `T` is `k · T`, computed from the count `k` (never by adding
//! `T` to the last instant, which accumulates rounding), and every reader computes it the same
//! way, `k as f64 * T`, so the integrator stops on exactly the time the instant is applied at.

/// The count of the first instant strictly after `t`: the smallest `k` with `k · T > t`, both
/// sides as the driver computes them.
///
/// `floor(t / T) + 1` alone is not enough: at `t = 3 · 0.7 = 2.0999999999999996`,
/// `t / 0.7 = 2.9999999999999996` floors to 2, so the third scan would fall due again at the time
/// it was just applied, a zero step that stops the integrator; rounded the other way it would skip
/// one. The estimate is corrected by comparing instants as computed. The count is bounded: a
/// scenario's resource limits keep `duration / T` far below 2⁵³, where consecutive instants are
/// distinct numbers.
pub(super) fn after(t: f64, period: f64) -> u64 {
    let at = |k: u64| k as f64 * period;
    let mut k = (t / period).floor().max(0.0) as u64 + 1;
    while k > 1 && at(k - 1) > t {
        k -= 1;
    }
    while at(k) <= t {
        k += 1;
    }
    k
}

#[cfg(test)]
mod tests {
    use super::after;

    /// At every instant of awkward periods, the next one is strictly later and none is skipped.
    #[test]
    fn the_instant_after_each_instant_is_the_next_one() {
        for period in [0.7, 33.3, 0.1, 1.0 / 3.0, 1e-3, 299.99999999999994, 7.0] {
            for k in 0..20_000u64 {
                let t = k as f64 * period;
                assert_eq!(after(t, period), k + 1, "period {period}, instant {k} at t = {t:e}");
            }
        }
    }

    /// The case a user's 0.7 s scan met: `3 · 0.7 / 0.7` floors to 2.
    #[test]
    fn a_scan_at_three_periods_of_seven_tenths_is_not_due_again() {
        let t = 3.0_f64 * 0.7;
        assert_eq!((t / 0.7).floor(), 2.0, "the rounding this guards against");
        assert_eq!(after(t, 0.7), 4);
    }

    /// Between instants, the next one is the first after `t`; before the first, it is 1.
    #[test]
    fn between_instants_the_next_is_the_first_later_one() {
        assert_eq!(after(0.0, 0.7), 1);
        assert_eq!(after(0.35, 0.7), 1);
        assert_eq!(after(2.1000000001, 0.7), 4);
        assert_eq!(after(2.09, 0.7), 3);
    }
}
