//! The flowsheet file format (JSON). `flowsheets/plantwide.schema.json` is generated from these
//! types (`plantwide schema`), so editors can validate and autocomplete.
//!
//! Quantities are strings with units (`"1 kmol/min"`, `"80 degC"`) or bare SI numbers
//! (mol, s, K, Pa, J, m). The format carries `format_version: 1`.

use std::collections::BTreeMap;

use indexmap::IndexMap;
use plantwide_model::{ControllerSpec, UnitSpec};
use plantwide_thermo::{BinaryPair, Component};
use plantwide_units::QuantityValue;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The format version this build reads and writes.
pub const FORMAT_VERSION: u32 = 1;

/// A whole flowsheet file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FlowsheetSpec {
    /// Format version; must be 1.
    pub format_version: u32,
    /// Short name of the plant.
    #[serde(default)]
    pub name: String,
    /// What the plant is and where its data come from.
    #[serde(default)]
    pub description: String,
    /// Components, in the order used by every composition: library names (`"water"`),
    /// hypothetical components or full inline data.
    pub components: Vec<ComponentSpec>,
    /// Thermodynamic model.
    pub thermo: ThermoSpec,
    /// Process units by name.
    pub units: IndexMap<String, UnitSpec>,
    /// Material streams by name, each from an outlet port to an inlet port.
    pub streams: IndexMap<String, StreamSpec>,
    /// Controllers by name (they share the name space of units).
    #[serde(default)]
    pub controllers: IndexMap<String, ControllerSpec>,
    /// Named inputs and disturbances: a short name for an input path (`"feed_rate": "fresh.F"`).
    #[serde(default)]
    pub inputs: IndexMap<String, String>,
    /// Design specifications of the steady state: each holds a variable at a target by moving a
    /// free input (`{"path": "distillate.x[light]", "value": 0.995, "vary": "column.reflux"}`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub specs: Vec<crate::design::SpecEntry>,
    /// Named constants with units, for the tags' expressions (`"steam_price": "0.03 $/kWh"`); a
    /// bare number is dimensionless.
    #[serde(default, skip_serializing_if = "IndexMap::is_empty")]
    pub parameters: IndexMap<String, QuantityValue>,
    /// Tags: named quantities computed from the plant's variables and inputs by an expression
    /// (`"cost": "steam_price*reboiler.duty + feed_price*fresh.F"`), each a variable
    /// `<tag>.value` of the plant that every analysis sees ([`plantwide_model::tag`]).
    #[serde(default, skip_serializing_if = "IndexMap::is_empty")]
    pub tags: IndexMap<String, TagSpec>,
    /// The economic optimum `plantwide optimize` finds: an objective (a tag or variable), the
    /// inputs it may move and the limits it must keep ([`crate::optimization`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub optimization: Option<crate::optimization::OptimizationSpec>,
}

/// A tag: its expression, alone or with the unit its value must have and a description.
///
/// A display unit may follow the expression after `@` (`"XMEAS(7)": "reactor.P@kPag"`): the tag's
/// value is shown in it wherever the tag is named without a unit (`run` records, `gains`,
/// `steady --json`'s `tags`). A tag is named like a path: by its name alone (`XMEAS(7)`), which
/// reads its value, or, when its expression is one input's path, moves that input (`--set`,
/// scenario events, `gains` inputs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum TagSpec {
    /// The expression alone (`"steam_price*reboiler.duty"`), or with a unit (`"reactor.P@kPag"`).
    Expression(String),
    /// The expression with a declared unit and a description.
    Full {
        /// The expression, over plant paths (`column.T[5]`, `fresh.F`, `lc.op`, `other_tag.value`)
        /// and the flowsheet's `parameters`.
        expression: String,
        /// A unit whose dimension the expression must have (`"$/h"`), in which the tag's value is
        /// shown.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        unit: Option<String>,
        /// What the tag measures.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        description: Option<String>,
    },
}

impl TagSpec {
    /// The text as written: expression and a unit after `@`, if any.
    fn written(&self) -> &str {
        match self {
            TagSpec::Expression(e) | TagSpec::Full { expression: e, .. } => e,
        }
    }

    /// The unit written after `@` in the expression's text, if any.
    fn unit_after_at(&self) -> Option<&str> {
        self.written().rsplit_once('@').map(|(_, u)| u.trim())
    }

    /// The expression's text, without the unit written after `@`.
    pub fn expression(&self) -> &str {
        let w = self.written();
        w.rsplit_once('@').map_or(w, |(e, _)| e.trim_end())
    }

    /// The declared unit: the `unit` field, else the one written after `@`.
    pub fn unit(&self) -> Option<&str> {
        match self {
            TagSpec::Full { unit: Some(u), .. } => Some(u),
            _ => self.unit_after_at(),
        }
    }

    /// Both spellings of the unit when the tag gives the `unit` field and a unit after `@`.
    pub fn unit_given_twice(&self) -> Option<(&str, &str)> {
        match self {
            TagSpec::Full { unit: Some(u), .. } => self.unit_after_at().map(|a| (u.as_str(), a)),
            _ => None,
        }
    }
}

/// A component of the flowsheet.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum ComponentSpec {
    /// A component of the built-in library, by name (`plantwide components` lists them).
    Library(String),
    /// A hypothetical component defined by its relative volatility.
    Hypothetical {
        /// Name used in compositions and paths.
        name: String,
        /// Its definition.
        hypothetical: HypotheticalSpec,
    },
    /// A component with full property data (same fields as the library file).
    Inline(Box<Component>),
}

impl ComponentSpec {
    /// The component's name.
    pub fn name(&self) -> &str {
        match self {
            ComponentSpec::Library(n) => n,
            ComponentSpec::Hypothetical { name, .. } => name,
            ComponentSpec::Inline(c) => &c.name,
        }
    }
}

/// A hypothetical component for constant-relative-volatility studies. Components that share `hvap`
/// and `t_ref` have exactly the relative volatility given by the ratio of their `alpha`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HypotheticalSpec {
    /// Relative volatility against the reference scale (the heaviest component usually has 1).
    pub alpha: f64,
    /// Molar mass (e.g. `"50 kg/kmol"`; bare numbers in kg/mol).
    pub mw: QuantityValue,
    /// Heat of vaporization (e.g. `"30 kJ/mol"`).
    pub hvap: QuantityValue,
    /// Temperature at which a component of `alpha = 1` boils at 1 atm (default 350 K).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t_ref: Option<QuantityValue>,
    /// Liquid (and ideal-gas) heat capacity (default 150 J/(mol K)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cp: Option<QuantityValue>,
    /// Liquid molar volume (default 1e-4 m3/mol).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub v_liq: Option<QuantityValue>,
}

/// VLE model choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum VleChoice {
    /// Constant relative volatility (from the hypothetical components' `alpha` or `thermo.alpha`).
    ConstantAlpha,
    /// Raoult's law with the components' vapour pressures.
    Ideal,
    /// NRTL activity coefficients with binary parameters.
    Nrtl,
    /// Wilson activity coefficients with binary parameters.
    Wilson,
}

/// Thermodynamic model of the flowsheet.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ThermoSpec {
    /// VLE model.
    pub vle: VleChoice,
    /// Relative volatilities by component for `constant_alpha` (default: the hypothetical
    /// components' `alpha`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alpha: Option<BTreeMap<String, f64>>,
    /// Binary parameters that add to or override the library's (`nrtl`, `wilson`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub binary_parameters: Vec<BinaryPair>,
}

/// A material stream from an outlet port to an inlet port.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StreamSpec {
    /// Source `"unit.port"` (or `"unit"` when the unit has one outlet).
    pub from: String,
    /// Destination `"unit.port"` (or `"unit"` when the unit has one inlet).
    pub to: String,
    /// Prefer this stream as a tear stream in the sequential-modular pass.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub tear: bool,
}
