//! Resource limits on what a scenario file may ask for, so that no file can make a run allocate
//! without bound or stop the integrator an unbounded number of times.
//!
//! Every limit has a default and an environment variable that raises (or lowers) it, read in one
//! place, [`Limits::from_env`]. The CLI reads them; library callers pass a [`Limits`] to
//! [`super::resolve_with`] ([`super::resolve`] uses the defaults).

/// Limits checked by [`super::resolve_with`]. Counts are over the whole run, `duration` [s].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Largest number of recorded rows, `⌊duration / record.interval⌋ + 1` plus two per event
    /// (default 1 000 000; [`Limits::MAX_RECORD_ROWS`]).
    pub max_record_rows: u64,
    /// Largest number of recorded values, rows × columns (recorded paths plus one column per
    /// component of every `record.totals` stream), 8 bytes each (default 20 000 000, 160 MB;
    /// [`Limits::MAX_RECORD_VALUES`]).
    pub max_record_values: u64,
    /// Largest number of events after expansion: a ramp, a pulse and a sinusoid with a `duration`
    /// count two (start and end) (default 10 000; [`Limits::MAX_EVENTS`]).
    pub max_events: u64,
    /// Largest number of discrete times of one sampled controller (`duration / scan interval`) or
    /// one analyzer (`duration / sample_time`); each one stops the integrator (default 100 000;
    /// [`Limits::MAX_SAMPLES`]).
    pub max_samples: u64,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits { max_record_rows: 1_000_000, max_record_values: 20_000_000, max_events: 10_000, max_samples: 100_000 }
    }
}

/// An environment variable that does not hold a limit.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("environment variable {var}: `{value}` is not a limit (give a positive whole number, e.g. 1000000 or 1e7)")]
pub struct LimitsError {
    /// Variable name.
    pub var: &'static str,
    /// Its value.
    pub value: String,
}

impl Limits {
    /// Environment variable of [`Limits::max_record_rows`].
    pub const MAX_RECORD_ROWS: &'static str = "PLANTWIDE_MAX_RECORD_ROWS";
    /// Environment variable of [`Limits::max_record_values`].
    pub const MAX_RECORD_VALUES: &'static str = "PLANTWIDE_MAX_RECORD_VALUES";
    /// Environment variable of [`Limits::max_events`].
    pub const MAX_EVENTS: &'static str = "PLANTWIDE_MAX_EVENTS";
    /// Environment variable of [`Limits::max_samples`].
    pub const MAX_SAMPLES: &'static str = "PLANTWIDE_MAX_SAMPLES";

    /// The defaults, each replaced by its environment variable when that is set.
    ///
    /// # Errors
    /// A variable that is set but not a positive whole number.
    pub fn from_env() -> Result<Limits, LimitsError> {
        Limits::from_lookup(|var| std::env::var(var).ok())
    }

    /// The defaults, each replaced by `lookup(variable name)` when that is `Some`.
    ///
    /// # Errors
    /// A value that is not a positive whole number.
    pub fn from_lookup(lookup: impl Fn(&str) -> Option<String>) -> Result<Limits, LimitsError> {
        let mut l = Limits::default();
        for (var, field) in [
            (Limits::MAX_RECORD_ROWS, &mut l.max_record_rows),
            (Limits::MAX_RECORD_VALUES, &mut l.max_record_values),
            (Limits::MAX_EVENTS, &mut l.max_events),
            (Limits::MAX_SAMPLES, &mut l.max_samples),
        ] {
            if let Some(value) = lookup(var) {
                *field = parse_count(&value).ok_or(LimitsError { var, value })?;
            }
        }
        Ok(l)
    }
}

/// A positive whole number, written as an integer or in exponent form (`1e7`).
fn parse_count(s: &str) -> Option<u64> {
    let s = s.trim();
    if let Ok(n) = s.parse::<u64>() {
        return (n > 0).then_some(n);
    }
    let v: f64 = s.parse().ok()?;
    (v.is_finite() && v >= 1.0 && v.fract() == 0.0 && v < u64::MAX as f64).then_some(v as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn environment_overrides_defaults_and_rejects_nonsense() {
        let l = Limits::from_lookup(|v| (v == Limits::MAX_RECORD_ROWS).then(|| "2e7".to_string())).unwrap();
        assert_eq!(l, Limits { max_record_rows: 20_000_000, ..Limits::default() });
        for bad in ["0", "-5", "1.5", "lots", "1e400", ""] {
            let e = Limits::from_lookup(|v| (v == Limits::MAX_SAMPLES).then(|| bad.to_string())).unwrap_err();
            assert_eq!(e.var, Limits::MAX_SAMPLES, "{bad}");
            assert!(e.to_string().contains("PLANTWIDE_MAX_SAMPLES"), "{e}");
        }
    }
}
