//! Errors of quantity and unit parsing.

use crate::Dimension;

/// A quantity or unit expression that cannot be read, or has the wrong dimension. `text` is always
/// the whole input as the user wrote it, so messages can quote it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum UnitError {
    /// The input is empty or only whitespace.
    #[error("empty quantity: give a number with an optional unit, e.g. \"1 kmol/min\"")]
    Empty,
    /// The input does not start with a number, or the number (or its value in SI units) is not
    /// finite.
    #[error("`{text}`: {reason}")]
    BadNumber {
        /// The whole input.
        text: String,
        /// What is wrong: `"expected a number first"`, `"1e400 is not a finite number"`.
        reason: String,
    },
    /// A unit symbol that is not in the table.
    #[error("unknown unit `{unit}` in `{text}`{}", did_you_mean(.suggestion.as_deref()))]
    UnknownUnit {
        /// The unknown symbol.
        unit: String,
        /// The whole input.
        text: String,
        /// The closest known symbol, if one is close enough.
        suggestion: Option<String>,
    },
    /// The quantity has a different dimension from the one the field needs.
    #[error("`{text}` is {} but {} is expected here (e.g. {example})", .found.describe(), .expected.describe())]
    WrongDimension {
        /// The whole input.
        text: String,
        /// The dimension of the input.
        found: Dimension,
        /// The dimension the field needs.
        expected: Dimension,
        /// Valid inputs: `"1 kmol/min", "100 lbmol/h" or a bare number in mol/s`.
        example: String,
    },
    /// An offset unit (degC, degF, psig, barg) used inside a compound unit where it cannot mean an
    /// absolute value: in a numerator (`80 degC/min`), with a power, or a gauge pressure anywhere.
    #[error("`{text}`: {}", affine_hint(.unit, .linear))]
    AffineInCompound {
        /// The offset unit: `"degC"`.
        unit: String,
        /// The whole input.
        text: String,
        /// The linear unit of the same size to use instead: `"K"`.
        linear: String,
    },
    /// A malformed unit expression: unbalanced parentheses, a missing operator, a bad exponent.
    #[error("`{text}`: {message}")]
    Syntax {
        /// The whole input.
        text: String,
        /// What is wrong.
        message: String,
    },
}

fn did_you_mean(suggestion: Option<&str>) -> String {
    suggestion.map(|s| format!(" (did you mean `{s}`?)")).unwrap_or_default()
}

fn affine_hint(unit: &str, linear: &str) -> String {
    if linear == "K" || linear == "degR" {
        format!(
            "`{unit}` has an offset zero, so it may only stand alone as an absolute temperature \
             (\"80 {unit}\") or be per degree in a denominator (\"kJ/(kmol*{unit})\"); \
             for a temperature change write `{linear}` (e.g. \"{linear}/min\")"
        )
    } else {
        format!(
            "`{unit}` is a gauge pressure, so it may only stand alone (\"30 {unit}\"); \
             inside a compound unit write `{linear}`"
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_are_lowercase_without_period() {
        let errors = [
            UnitError::Empty,
            UnitError::BadNumber { text: "abc".into(), reason: "expected a number first".into() },
            UnitError::UnknownUnit { unit: "kmols".into(), text: "1 kmols".into(), suggestion: Some("kmol".into()) },
            UnitError::WrongDimension {
                text: "5 K".into(),
                found: Dimension::TEMPERATURE,
                expected: Dimension::MOLAR_FLOW,
                example: Dimension::MOLAR_FLOW.example_hint(),
            },
            UnitError::AffineInCompound { unit: "degC".into(), text: "80 degC/min".into(), linear: "K".into() },
            UnitError::AffineInCompound { unit: "psig".into(), text: "3 psig/s".into(), linear: "psi".into() },
            UnitError::Syntax { text: "1 (m".into(), message: "missing `)`".into() },
        ];
        for e in errors {
            let m = e.to_string();
            assert!(!m.ends_with('.'), "{m}");
            let first = m.chars().next().unwrap();
            assert!(!first.is_uppercase(), "{m}");
        }
    }

    #[test]
    fn wrong_dimension_message() {
        let e = UnitError::WrongDimension {
            text: "5 K".into(),
            found: Dimension::TEMPERATURE,
            expected: Dimension::MOLAR_FLOW,
            example: Dimension::MOLAR_FLOW.example_hint(),
        };
        assert_eq!(
            e.to_string(),
            "`5 K` is a temperature but a molar flow is expected here \
             (e.g. \"1 kmol/min\", \"100 lbmol/h\" or a bare number in mol/s)"
        );
    }

    #[test]
    fn unknown_unit_message() {
        let e =
            UnitError::UnknownUnit { unit: "kmols".into(), text: "1 kmols/h".into(), suggestion: Some("kmol".into()) };
        assert_eq!(e.to_string(), "unknown unit `kmols` in `1 kmols/h` (did you mean `kmol`?)");
        let e = UnitError::UnknownUnit { unit: "furlongs".into(), text: "3 furlongs".into(), suggestion: None };
        assert_eq!(e.to_string(), "unknown unit `furlongs` in `3 furlongs`");
    }
}
