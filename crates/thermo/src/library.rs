//! The built-in component library and binary interaction parameters, embedded from `data/*.json`.

use serde::{Deserialize, Serialize};

use crate::{ActivityModel, Component, ThermoError};

/// Binary interaction parameters for one pair, in the Aspen Plus form used by [`ActivityModel`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BinaryPair {
    /// `"nrtl"` or `"wilson"`.
    pub model: String,
    /// First component name.
    pub i: String,
    /// Second component name.
    pub j: String,
    /// `a_ij` [-].
    #[serde(default)]
    pub a_ij: f64,
    /// `a_ji` [-].
    #[serde(default)]
    pub a_ji: f64,
    /// `b_ij` [K].
    #[serde(default)]
    pub b_ij: f64,
    /// `b_ji` [K].
    #[serde(default)]
    pub b_ji: f64,
    /// NRTL non-randomness `α_ij = α_ji` [-] (ignored for Wilson).
    #[serde(default)]
    pub alpha: f64,
    /// Where the numbers come from.
    #[serde(default)]
    pub source: String,
}

/// The built-in library: pure components and binary pairs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Library {
    /// Free-text description of the data sources.
    #[serde(default)]
    pub sources: Vec<String>,
    /// Pure components.
    pub components: Vec<Component>,
    /// Binary interaction parameters.
    pub binary_pairs: Vec<BinaryPair>,
}

/// The library file, embedded at compile time.
const LIBRARY_JSON: &str = include_str!("../data/library.json");

impl Library {
    /// The library shipped in `data/library.json` (embedded at compile time).
    pub fn builtin() -> Result<Library, ThermoError> {
        Library::from_json(LIBRARY_JSON)
    }

    /// Parse a library from JSON text of the [`Library`] shape.
    pub fn from_json(text: &str) -> Result<Library, ThermoError> {
        serde_json::from_str(text).map_err(|e| ThermoError::Data(e.to_string()))
    }

    /// A component by name (case-insensitive).
    pub fn component(&self, name: &str) -> Result<&Component, ThermoError> {
        let key = name.trim();
        self.components
            .iter()
            .find(|c| c.name.eq_ignore_ascii_case(key))
            .ok_or_else(|| ThermoError::UnknownComponent { name: name.to_string() })
    }

    /// Build the activity model for `names` (in that order) from the library's pairs plus `extra`
    /// pairs (which take precedence). `kind` is `"nrtl"` or `"wilson"`. Missing pairs are an error.
    ///
    /// A pair matches when its `model` equals `kind` and its names are the two components in either
    /// order (case-insensitive); a pair stored as `(j, i)` is transposed (`a_ij ↔ a_ji`,
    /// `b_ij ↔ b_ji`). Among several matching `extra` pairs the last one wins; among library pairs
    /// the first one. For NRTL, `α_ij = α_ji = pair.alpha`. Diagonals are zero.
    pub fn activity_model(
        &self,
        kind: &str,
        names: &[&str],
        extra: &[BinaryPair],
    ) -> Result<ActivityModel, ThermoError> {
        let kind_lc = kind.trim().to_ascii_lowercase();
        if kind_lc != "nrtl" && kind_lc != "wilson" {
            return Err(ThermoError::BadInput {
                routine: "activity_model",
                reason: format!("unknown activity model `{kind}` (expected `nrtl` or `wilson`)"),
            });
        }
        let n = names.len();
        for i in 0..n {
            for j in i + 1..n {
                if names[i].trim().eq_ignore_ascii_case(names[j].trim()) {
                    return Err(ThermoError::BadInput {
                        routine: "activity_model",
                        reason: format!("component `{}` is listed twice", names[i]),
                    });
                }
            }
        }
        let mut a = vec![vec![0.0; n]; n];
        let mut b = vec![vec![0.0; n]; n];
        let mut alpha = vec![vec![0.0; n]; n];
        for i in 0..n {
            for j in i + 1..n {
                let found = extra
                    .iter()
                    .rev()
                    .find_map(|p| orient(p, &kind_lc, names[i], names[j]))
                    .or_else(|| self.binary_pairs.iter().find_map(|p| orient(p, &kind_lc, names[i], names[j])));
                let Some((p, swapped)) = found else {
                    return Err(ThermoError::MissingBinaryPair {
                        model: kind_lc,
                        i: names[i].to_string(),
                        j: names[j].to_string(),
                    });
                };
                let (aij, aji, bij, bji) =
                    if swapped { (p.a_ji, p.a_ij, p.b_ji, p.b_ij) } else { (p.a_ij, p.a_ji, p.b_ij, p.b_ji) };
                a[i][j] = aij;
                a[j][i] = aji;
                b[i][j] = bij;
                b[j][i] = bji;
                alpha[i][j] = p.alpha;
                alpha[j][i] = p.alpha;
            }
        }
        Ok(if kind_lc == "nrtl" { ActivityModel::Nrtl { a, b, alpha } } else { ActivityModel::Wilson { a, b } })
    }
}

/// `Some((pair, swapped))` when `p` is a `kind` pair for `(i, j)` (`swapped` if stored as `(j, i)`).
fn orient<'a>(p: &'a BinaryPair, kind: &str, i: &str, j: &str) -> Option<(&'a BinaryPair, bool)> {
    if !p.model.trim().eq_ignore_ascii_case(kind) {
        return None;
    }
    let (pi, pj) = (p.i.trim(), p.j.trim());
    let (i, j) = (i.trim(), j.trim());
    if pi.eq_ignore_ascii_case(i) && pj.eq_ignore_ascii_case(j) {
        Some((p, false))
    } else if pi.eq_ignore_ascii_case(j) && pj.eq_ignore_ascii_case(i) {
        Some((p, true))
    } else {
        None
    }
}
