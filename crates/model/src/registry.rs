//! The registries: flowsheet descriptions (`"type": "..."` in JSON) mapped to unit models.
//! Adding a unit type is one line in `unit_registry!` below (plus its file and `pub mod` line).

use plantwide_units::QuantityValue;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::controllers::{self, ControllerConfig, ControllerLinks};
use crate::units;
use crate::{BuildCx, FieldError, SpecError, Unit};

/// What every unit description offers: its ports, as the schema documents them.
pub trait UnitConfig: std::fmt::Debug {
    /// The unit type's ports in words, e.g. ``"inlet `in`, outlet `out`"`` (shown in the JSON
    /// Schema of flowsheet files, where a stream's `from` and `to` name them).
    fn ports() -> &'static str
    where
        Self: Sized;
    /// The geometry of the vessel whose liquid level the unit holds, as written, for sizing
    /// (default: none; `size` then refuses the unit as a vessel).
    fn vessel(&self) -> Option<VesselGeometry<'_>> {
        None
    }
    /// The liquid inventories the unit holds without a geometry (a column's reflux drum and
    /// base), for sizing and the residence-time check (default: none).
    fn inventories(&self) -> Vec<Inventory> {
        Vec::new()
    }
}

/// A liquid inventory a unit holds as a holdup without a geometry: sized as a vertical drum of the
/// area the design needs, and checked for its residence time.
#[derive(Debug, Clone, PartialEq)]
pub struct Inventory {
    /// Its name after the unit's: `drum` is addressed `COL.drum`.
    pub name: &'static str,
    /// The stage whose holdup `M[k]`, temperature `T[k]` and composition `x[k][c]` are the
    /// inventory's.
    pub stage: usize,
    /// What leaves it, each a variable or an input of the unit (`L[12]`, `distillate`): their sum
    /// is its throughput.
    pub leaving: Vec<String>,
}

/// A vessel's cross-section (by diameter or area) and height as its description writes them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VesselGeometry<'a> {
    /// Diameter, where written.
    pub diameter: Option<&'a QuantityValue>,
    /// Cross-sectional area, where written.
    pub area: Option<&'a QuantityValue>,
    /// Height, where written.
    pub height: Option<&'a QuantityValue>,
}

macro_rules! registry {
    ($(#[$meta:meta])* $name:ident, $cx:ty, $tr:path, [$($tag:literal => $variant:ident($cfg:ty, $unit:ty)),* $(,)?]) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
        #[serde(tag = "type")]
        pub enum $name {
            $(
                #[doc = concat!("`\"type\": \"", $tag, "\"`")]
                #[serde(rename = $tag)]
                $variant($cfg),
            )*
        }

        impl $name {
            /// Every type name, as written in flowsheet files.
            pub const TYPES: &'static [&'static str] = &[$($tag),*];

            /// Type name as written in flowsheet files.
            pub fn type_name(&self) -> &'static str {
                match self { $($name::$variant(_) => $tag,)* }
            }

            /// The ports of type `tag` in words (empty for controllers, which have none), or `None`
            /// for an unknown type.
            pub fn ports_of(tag: &str) -> Option<&'static str> {
                match tag {
                    $($tag => Some(<$cfg as $tr>::ports()),)*
                    _ => None,
                }
            }

            /// The description as a trait object.
            pub fn config(&self) -> &dyn $tr {
                match self { $($name::$variant(c) => c,)* }
            }

            /// Deserialize the description of `"type": tag` from `value` (the `type` key is
            /// ignored).
            ///
            /// # Errors
            /// [`SpecError`]: the JSON path below `value` of the first problem and its message
            /// (serde's internally tagged enums lose that path).
            pub fn from_tagged(tag: &str, value: &serde_json::Value) -> Result<Self, SpecError> {
                let mut body = value.clone();
                if let Some(o) = body.as_object_mut() {
                    o.remove("type");
                }
                let path_error = |e: serde_path_to_error::Error<serde_json::Error>| {
                    let path = e.path().to_string();
                    SpecError { path: if path == "." { String::new() } else { path }, message: e.into_inner().to_string() }
                };
                match tag {
                    $($tag => serde_path_to_error::deserialize::<_, $cfg>(&body).map($name::$variant).map_err(path_error),)*
                    _ => Err(SpecError { path: "type".into(), message: format!("unknown type `{tag}`") }),
                }
            }

            /// Build the unit model, or every error found in the description.
            pub fn build(&self, cx: BuildCx<'_>, links: $cx) -> Result<Box<dyn Unit>, Vec<FieldError>> {
                match self {
                    $($name::$variant(c) => <$unit>::build(c, cx, links).map(|u| Box::new(u) as Box<dyn Unit>),)*
                }
            }
        }
    };
}

registry!(
    /// A process unit's description in a flowsheet file.
    UnitSpec, (), UnitConfig, [
    "feed" => Feed(units::feed::FeedConfig, units::feed::Feed),
    "product" => Product(units::product::ProductConfig, units::product::Product),
    "mixer" => Mixer(units::mixer::MixerConfig, units::mixer::Mixer),
    "splitter" => Splitter(units::splitter::SplitterConfig, units::splitter::Splitter),
    "heater" => Heater(units::heater::HeaterConfig, units::heater::Heater),
    "column" => Column(units::column::ColumnConfig, units::column::Column),
    "valve" => Valve(units::valve::ValveConfig, units::valve::Valve),
    "pump" => Pump(units::pump::PumpConfig, units::pump::Pump),
    "heat_exchanger" => HeatExchanger(units::hx::HeatExchangerConfig, units::hx::HeatExchanger),
    "tank" => Tank(units::tank::TankConfig, units::tank::Tank),
    "gas_vessel" => GasVessel(units::gas_vessel::GasVesselConfig, units::gas_vessel::GasVessel),
    "flash" => Flash(units::flash::FlashConfig, units::flash::Flash),
    "cstr" => Cstr(units::cstr::CstrConfig, units::cstr::Cstr),
    "equations" => Equations(units::equations::EquationsConfig, units::equations::Equations),
]);

registry!(
    /// A controller's description in a flowsheet file.
    ControllerSpec, &ControllerLinks, ControllerConfig, [
    "pid" => Pid(controllers::pid::PidConfig, controllers::pid::Pid),
    "lag" => Lag(controllers::lag::LagConfig, controllers::lag::Lag),
    "delay" => Delay(controllers::delay::DelayConfig, controllers::delay::Delay),
    "ratio" => Ratio(controllers::ratio::RatioConfig, controllers::ratio::Ratio),
    "summer" => Summer(controllers::summer::SummerConfig, controllers::summer::Summer),
    "split_range" => SplitRange(controllers::split_range::SplitRangeConfig, controllers::split_range::SplitRange),
    "selector" => Selector(controllers::selector::SelectorConfig, controllers::selector::Selector),
    "averaging_level" => AveragingLevel(controllers::averaging_level::AveragingLevelConfig, controllers::averaging_level::AveragingLevel),
    "condenser_reboiler" => CondenserReboiler(controllers::condenser_reboiler::CondenserReboilerConfig, controllers::condenser_reboiler::CondenserReboiler),
    "mpc" => Mpc(controllers::mpc::MpcConfig, controllers::mpc::Mpc),
]);
