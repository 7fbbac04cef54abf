//! Resource limits and the physical range of input values: the one place that bounds what a
//! flowsheet file, a `--set` override or a scenario event can ask for.
//!
//! **Resource limits** stop a file from asking for an allocation or a run time without bound (a
//! column of 10⁹ stages, a mixer of 10⁹ inlets, a 10 MB name, a run recording 10¹¹ rows). Each has a default chosen far above
//! any real plant and can be raised for one process by an environment variable
//! (`PLANTWIDE_MAX_STAGES=5000 plantwide steady big.json`); the error message names the variable.
//!
//! **Physical ranges** are the ranges in which the models are valid: absolute temperatures in
//! 1 … 5000 K and pressures in 1 Pa … 1 GPa (the bounds of every stream's `T` and `P`), flows up
//! to 10⁶ mol/s,
//! holdups, levels, volumes and times ≥ 0, mole fractions in [0, 1]. A value outside them can have
//! no steady state, so it is rejected where it enters rather than blamed on the solver later.

use std::sync::OnceLock;

use plantwide_units::Dimension;

/// Resource limits (see the module documentation); read once per process from the environment.
#[derive(Debug, Clone, PartialEq)]
pub struct Limits {
    /// Most stages of one column (`PLANTWIDE_MAX_STAGES`, default 1000).
    pub max_stages: usize,
    /// Most inlets of one mixer (`PLANTWIDE_MAX_INLETS`, default 1000).
    pub max_inlets: usize,
    /// Most components of a flowsheet (`PLANTWIDE_MAX_COMPONENTS`, default 200).
    pub max_components: usize,
    /// Most units plus controllers of a flowsheet (`PLANTWIDE_MAX_UNITS`, default 20000).
    pub max_units: usize,
    /// Most characters of a name (`PLANTWIDE_MAX_NAME_LEN`, default 256).
    pub max_name_len: usize,
    /// Most characters of any string or key of a file: paths, descriptions
    /// (`PLANTWIDE_MAX_STRING_LEN`, default 4096).
    pub max_string_len: usize,
    /// Most reactions of one reactor (`PLANTWIDE_MAX_REACTIONS`, default 100).
    pub max_reactions: usize,
    /// Largest flowsheet or scenario file in bytes (`PLANTWIDE_MAX_FILE_BYTES`, default 64 MiB).
    pub max_file_bytes: usize,
    /// Most variables of an assembled plant (`PLANTWIDE_MAX_VARIABLES`, default 2 000 000).
    pub max_variables: usize,
    /// Most entries (equations × local variables) of one unit's Jacobian block
    /// (`PLANTWIDE_MAX_BLOCK_ENTRIES`, default 40 000 000, i.e. 320 MB of f64).
    pub max_block_entries: usize,
    /// Most recorded rows of a run, `⌊duration / record.interval⌋ + 1` plus two per event
    /// (`PLANTWIDE_MAX_RECORD_ROWS`, default 1 000 000).
    pub max_record_rows: usize,
    /// Most recorded values, rows × columns (recorded paths plus one column per component of every
    /// `record.totals` stream), 8 bytes each (`PLANTWIDE_MAX_RECORD_VALUES`, default 20 000 000).
    pub max_record_values: usize,
    /// Most scenario events after expansion: a ramp, a pulse and a sinusoid with a `duration` count
    /// two (start and end) (`PLANTWIDE_MAX_EVENTS`, default 10 000).
    pub max_events: usize,
    /// Most discrete times of one sampled controller (`duration / scan interval`) or one analyzer
    /// (`duration / sample_time`); each one stops the integrator (`PLANTWIDE_MAX_SAMPLES`, default
    /// 100 000).
    pub max_samples: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_stages: 1000,
            max_inlets: 1000,
            max_components: 200,
            max_units: 20_000,
            max_name_len: 256,
            max_string_len: 4096,
            max_reactions: 100,
            max_file_bytes: 64 << 20,
            max_variables: 2_000_000,
            max_block_entries: 40_000_000,
            max_record_rows: 1_000_000,
            max_record_values: 20_000_000,
            max_events: 10_000,
            max_samples: 100_000,
        }
    }
}

/// One limit: its value and the environment variable that raises it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limit {
    /// The largest allowed value.
    pub max: usize,
    /// The environment variable that sets it.
    pub var: &'static str,
}

impl Limit {
    /// `None` if `n` is within the limit, else the message "`what` is `n`; at most `max` …".
    pub fn check(&self, n: usize, what: &str) -> Option<String> {
        (n > self.max).then(|| {
            format!(
                "{what} is {n}, above the limit of {} (set the environment variable {} to raise it)",
                self.max, self.var
            )
        })
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

/// The limits in force ([`Limits::get`]).
static LIMITS: OnceLock<Limits> = OnceLock::new();

impl Limits {
    /// Environment variable of [`Limits::max_record_rows`].
    pub const MAX_RECORD_ROWS: &'static str = "PLANTWIDE_MAX_RECORD_ROWS";
    /// Environment variable of [`Limits::max_record_values`].
    pub const MAX_RECORD_VALUES: &'static str = "PLANTWIDE_MAX_RECORD_VALUES";
    /// Environment variable of [`Limits::max_events`].
    pub const MAX_EVENTS: &'static str = "PLANTWIDE_MAX_EVENTS";
    /// Environment variable of [`Limits::max_samples`].
    pub const MAX_SAMPLES: &'static str = "PLANTWIDE_MAX_SAMPLES";

    /// The limits in force: those a face put in force with [`Limits::install`] (the CLI and the
    /// Python package read them from the environment once, at their start), else the defaults.
    /// The library reads no environment.
    pub fn get() -> &'static Limits {
        LIMITS.get_or_init(Limits::default)
    }

    /// Put `limits` in force for the process, before any work; false (and nothing changes) when
    /// limits are already in force — installed, or the defaults taken by a first [`Limits::get`].
    pub fn install(limits: Limits) -> bool {
        LIMITS.set(limits).is_ok()
    }

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
            ("PLANTWIDE_MAX_STAGES", &mut l.max_stages),
            ("PLANTWIDE_MAX_INLETS", &mut l.max_inlets),
            ("PLANTWIDE_MAX_COMPONENTS", &mut l.max_components),
            ("PLANTWIDE_MAX_UNITS", &mut l.max_units),
            ("PLANTWIDE_MAX_NAME_LEN", &mut l.max_name_len),
            ("PLANTWIDE_MAX_STRING_LEN", &mut l.max_string_len),
            ("PLANTWIDE_MAX_REACTIONS", &mut l.max_reactions),
            ("PLANTWIDE_MAX_FILE_BYTES", &mut l.max_file_bytes),
            ("PLANTWIDE_MAX_VARIABLES", &mut l.max_variables),
            ("PLANTWIDE_MAX_BLOCK_ENTRIES", &mut l.max_block_entries),
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

    /// Stages of one column.
    pub fn stages(&self) -> Limit {
        Limit { max: self.max_stages, var: "PLANTWIDE_MAX_STAGES" }
    }
    /// Inlets of one mixer.
    pub fn inlets(&self) -> Limit {
        Limit { max: self.max_inlets, var: "PLANTWIDE_MAX_INLETS" }
    }
    /// Components of a flowsheet.
    pub fn components(&self) -> Limit {
        Limit { max: self.max_components, var: "PLANTWIDE_MAX_COMPONENTS" }
    }
    /// Units plus controllers.
    pub fn units(&self) -> Limit {
        Limit { max: self.max_units, var: "PLANTWIDE_MAX_UNITS" }
    }
    /// Characters of a name.
    pub fn name_len(&self) -> Limit {
        Limit { max: self.max_name_len, var: "PLANTWIDE_MAX_NAME_LEN" }
    }
    /// Characters of any string of a file.
    pub fn string_len(&self) -> Limit {
        Limit { max: self.max_string_len, var: "PLANTWIDE_MAX_STRING_LEN" }
    }
    /// Reactions of one reactor.
    pub fn reactions(&self) -> Limit {
        Limit { max: self.max_reactions, var: "PLANTWIDE_MAX_REACTIONS" }
    }
    /// Bytes of a file.
    pub fn file_bytes(&self) -> Limit {
        Limit { max: self.max_file_bytes, var: "PLANTWIDE_MAX_FILE_BYTES" }
    }
    /// Variables of a plant.
    pub fn variables(&self) -> Limit {
        Limit { max: self.max_variables, var: "PLANTWIDE_MAX_VARIABLES" }
    }
    /// Entries of one unit's Jacobian block.
    pub fn block_entries(&self) -> Limit {
        Limit { max: self.max_block_entries, var: "PLANTWIDE_MAX_BLOCK_ENTRIES" }
    }
}

/// A positive whole number, written as an integer or in exponent form (`1e7`).
fn parse_count(s: &str) -> Option<usize> {
    let s = s.trim();
    if let Ok(n) = s.parse::<usize>() {
        return (n > 0).then_some(n);
    }
    let v: f64 = s.parse().ok()?;
    (v.is_finite() && v >= 1.0 && v.fract() == 0.0 && v < usize::MAX as f64).then_some(v as usize)
}

/// `s` for a message: at most 60 characters, elided in the middle (a 10 MB name is not echoed).
pub fn clip(s: &str) -> String {
    const KEEP: usize = 28;
    if s.chars().count() <= 2 * KEEP + 4 {
        return s.to_string();
    }
    let head: String = s.chars().take(KEEP).collect();
    let tail: String = s.chars().rev().take(KEEP).collect::<Vec<_>>().into_iter().rev().collect();
    format!("{head}…{tail} ({} characters)", s.chars().count())
}

/// Largest magnitude a quantity of dimension `dim` may have anywhere in a flowsheet (SI): the range
/// of the models (temperatures up to 5000 K, pressures up to 1 GPa, flows up to 10⁶ mol/s — 3.6·10⁶
/// kmol/h, a hundred times the largest process streams —, holdups
/// up to 10¹⁵ mol), and 10³⁰ for everything else so that products of values stay finite.
pub fn max_magnitude(dim: Dimension) -> f64 {
    if dim == Dimension::TEMPERATURE {
        5000.0
    } else if dim == Dimension::PRESSURE {
        1e9
    } else if dim == Dimension::MOLAR_FLOW {
        1e6
    } else if dim == Dimension::AMOUNT {
        1e15
    } else {
        1e30
    }
}

/// The physical range `[lo, hi]` of an input value of dimension `dim` named `name` (SI), within
/// which the models are valid (see the module documentation).
pub fn input_range(name: &str, dim: Dimension) -> (f64, f64) {
    let hi = max_magnitude(dim);
    if name.starts_with("z[") || name.starts_with("split[") || name == "auto" || name == "opening" {
        (0.0, 1.0)
    } else if name == "reboiler_duty" {
        (0.0, hi)
    } else if name == "bias" || name == "ratio" || name.starts_with("dp") {
        (-hi, hi)
    } else if dim == Dimension::TEMPERATURE || dim == Dimension::PRESSURE {
        (1.0, hi)
    } else if [
        Dimension::MOLAR_FLOW,
        Dimension::MASS_FLOW,
        Dimension::VOLUMETRIC_FLOW,
        Dimension::AMOUNT,
        Dimension::MASS,
        Dimension::LENGTH,
        Dimension::AREA,
        Dimension::VOLUME,
        Dimension::TIME,
        Dimension::UA,
    ]
    .contains(&dim)
    {
        (0.0, hi)
    } else {
        (-hi, hi)
    }
}

/// An input value outside its physical range ([`check_input`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RangeError {
    /// The value is NaN or infinite.
    #[error("{value} is not a finite number")]
    NotFinite {
        /// The input's name within its unit (`F`, `z[light]`).
        name: String,
        /// The value (SI).
        value: f64,
    },
    /// The value is finite but outside [`input_range`].
    #[error(
        "{}{} is outside the range {} … {}{} in which the models hold{}",
        number(*.value), unit_suffix(*.dim), number(*.lo), number(*.hi), unit_suffix(*.dim), negative_hint(*.value, *.lo)
    )]
    Outside {
        /// The input's name within its unit.
        name: String,
        /// Its dimension.
        dim: Dimension,
        /// The value (SI).
        value: f64,
        /// Lower end of the range (SI).
        lo: f64,
        /// Upper end of the range (SI).
        hi: f64,
    },
}

/// `" (it must not be negative)"` for a negative value of a quantity whose range starts at zero.
fn negative_hint(value: f64, lo: f64) -> &'static str {
    if lo == 0.0 && value < 0.0 { " (it must not be negative)" } else { "" }
}

/// ` <SI unit>` after a number, nothing for a dimensionless one.
fn unit_suffix(dim: Dimension) -> String {
    if dim.is_dimensionless() { String::new() } else { format!(" {dim}") }
}

/// Check an input value against [`input_range`].
///
/// # Errors
/// [`RangeError`] naming the input, its value and the range.
pub fn check_input(name: &str, dim: Dimension, value: f64) -> Result<(), RangeError> {
    check_input_within(name, dim, value, input_range(name, dim))
}

/// Check an input value against the range `(lo, hi)` (SI) its unit declares
/// ([`crate::UnitModel::input_range`]), or [`input_range`]'s.
///
/// # Errors
/// [`RangeError`] naming the input, its value and the range.
pub fn check_input_within(name: &str, dim: Dimension, value: f64, (lo, hi): (f64, f64)) -> Result<(), RangeError> {
    if !value.is_finite() {
        return Err(RangeError::NotFinite { name: name.to_string(), value });
    }
    if value < lo || value > hi {
        return Err(RangeError::Outside { name: name.to_string(), dim, value, lo, hi });
    }
    Ok(())
}

/// `None` if `value` lies in `range`, else the sentence [`RangeError::Outside`] says of it
/// ("-5 mol/s is outside the range 0 … 1e6 mol/s in which the models hold (it must not be
/// negative)"), for a field whose range another quantity gives (a setpoint, a controller limit).
pub fn outside(value: f64, range: (f64, f64), dim: Dimension) -> Option<String> {
    check_input_within("", dim, value, range).err().map(|e| e.to_string())
}

/// A number for a message: plain between 1e-3 and 1e6 (at most 6 significant digits), else in
/// exponent form.
pub fn number(v: f64) -> String {
    if v == 0.0 || (v.abs() >= 1e-3 && v.abs() < 1e6) {
        let s = format!("{v:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if v.fract() == 0.0 { format!("{v}") } else { s.to_string() }
    } else {
        format!("{v:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inputs_outside_their_physical_range_are_named() {
        assert!(
            check_input("F", Dimension::MOLAR_FLOW, -1.0).unwrap_err().to_string().contains("must not be negative")
        );
        assert!(check_input("T", Dimension::TEMPERATURE, 1e-300).is_err());
        assert!(check_input("sp", Dimension::TEMPERATURE, -1e308).is_err());
        assert!(check_input("z[light]", Dimension::DIMENSIONLESS, 1.5).is_err());
        assert!(check_input("reflux", Dimension::MOLAR_FLOW, 1e308).is_err());
        assert!(check_input("duty", Dimension::POWER, f64::NAN).is_err());
        assert!(check_input("duty", Dimension::POWER, -1e6).is_ok());
        assert!(check_input("P", Dimension::PRESSURE, 101_325.0).is_ok());
        // The typed errors print the messages the loader and `--set` always printed.
        let e = check_input("F", Dimension::MOLAR_FLOW, -1.0).unwrap_err();
        assert_eq!(
            e.to_string(),
            "-1 mol/s is outside the range 0 … 1e6 mol/s in which the models hold (it must not be negative)"
        );
        let e = check_input("z[light]", Dimension::DIMENSIONLESS, 1.5).unwrap_err();
        assert_eq!(e.to_string(), "1.5 is outside the range 0 … 1 in which the models hold");
        assert_eq!(
            check_input("T", Dimension::TEMPERATURE, f64::NAN).unwrap_err().to_string(),
            "NaN is not a finite number"
        );
    }

    #[test]
    fn a_huge_name_is_clipped_in_messages() {
        let long = "A".repeat(10_000_000);
        let c = clip(&long);
        assert!(c.len() < 100 && c.contains("10000000 characters"), "{c}");
        assert_eq!(clip("benzene"), "benzene");
    }

    #[test]
    fn environment_overrides_defaults_and_rejects_nonsense() {
        let l = Limits::from_lookup(|v| (v == Limits::MAX_RECORD_ROWS).then(|| "2e7".to_string())).unwrap();
        assert_eq!(l, Limits { max_record_rows: 20_000_000, ..Limits::default() });
        let l = Limits::from_lookup(|v| (v == "PLANTWIDE_MAX_STAGES").then(|| "5000".to_string())).unwrap();
        assert_eq!(l.max_stages, 5000);
        for bad in ["0", "-5", "1.5", "lots", "1e400", ""] {
            let e = Limits::from_lookup(|v| (v == Limits::MAX_SAMPLES).then(|| bad.to_string())).unwrap_err();
            assert_eq!(e.var, Limits::MAX_SAMPLES, "{bad}");
            assert!(e.to_string().contains("PLANTWIDE_MAX_SAMPLES"), "{e}");
        }
    }

    #[test]
    fn a_limit_names_its_environment_variable() {
        let msg = Limits::default().stages().check(5000, "`stages`").expect("over the limit");
        assert!(msg.contains("PLANTWIDE_MAX_STAGES") && msg.contains("1000"), "{msg}");
        assert_eq!(Limits::default().stages().check(1000, "`stages`"), None);
    }
}
