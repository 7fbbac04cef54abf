//! Display unit systems: the unit a person reads a quantity in when no path asked for one
//! (`--units si|metric|field`). Values are computed and exported in SI; only text is converted.

use crate::{Dimension, Unit};

/// A set of display units (`"si"`, `"metric"`, `"field"` in a study's request).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum UnitSystem {
    /// Coherent SI (mol/s, K, Pa, W): what JSON and CSV carry.
    #[default]
    Si,
    /// Plant units of metric practice: kmol/h, °C, kPa, kW, kmol, m³, min.
    Metric,
    /// US field units: lbmol/h, °F, psia, Btu/h, lbmol, ft³, gpm.
    Field,
}

/// (dimension, metric unit, field unit); dimensions not listed are shown in SI.
const TABLE: &[(Dimension, &str, &str)] = &[
    (Dimension::TEMPERATURE, "degC", "degF"),
    (Dimension::PRESSURE, "kPa", "psia"),
    (Dimension::MOLAR_FLOW, "kmol/h", "lbmol/h"),
    (Dimension::MASS_FLOW, "kg/h", "lb/h"),
    (Dimension::VOLUMETRIC_FLOW, "m3/h", "gpm"),
    (Dimension::POWER, "kW", "Btu/h"),
    (Dimension::ENERGY, "kJ", "Btu"),
    (Dimension::AMOUNT, "kmol", "lbmol"),
    (Dimension::MASS, "kg", "lb"),
    (Dimension::LENGTH, "m", "ft"),
    (Dimension::AREA, "m2", "ft2"),
    (Dimension::VOLUME, "m3", "ft3"),
    (Dimension::TIME, "min", "min"),
    (Dimension::MOLAR_ENERGY, "kJ/mol", "Btu/lbmol"),
    (Dimension::UA, "kW/K", "Btu/(h*degF)"),
    (Dimension::COST_RATE, "$/h", "$/h"),
];

impl UnitSystem {
    /// Parse `si`, `metric` or `field` (case-insensitive).
    pub fn parse(text: &str) -> Option<UnitSystem> {
        match text.trim().to_ascii_lowercase().as_str() {
            "si" => Some(UnitSystem::Si),
            "metric" => Some(UnitSystem::Metric),
            "field" => Some(UnitSystem::Field),
            _ => None,
        }
    }

    /// The display unit of `dim` in this system: its entry in the table, else the SI unit.
    pub fn unit_for(&self, dim: Dimension) -> String {
        let entry = TABLE.iter().find(|(d, _, _)| *d == dim);
        match (self, entry) {
            (UnitSystem::Metric, Some((_, m, _))) => m.to_string(),
            (UnitSystem::Field, Some((_, _, f))) => f.to_string(),
            (UnitSystem::Si, _) => dim.to_string(),
            (_, None) => self.integral_unit(dim).unwrap_or_else(|| dim.to_string()),
        }
    }

    /// The unit of a quantity integrated over time (a controller's integral of its error, `K·s`,
    /// `Pa·s`): the listed unit of the integrand (a temperature as a difference, K or degR) times
    /// the system's time unit, so that a plant's integrals read in one time unit.
    fn integral_unit(&self, dim: Dimension) -> Option<String> {
        let time = self.unit_for(Dimension::TIME);
        let (d, _, _) = TABLE.iter().find(|(d, _, _)| *d != Dimension::TIME && *d * Dimension::TIME == dim)?;
        let integrand = match *d {
            Dimension::TEMPERATURE if *self == UnitSystem::Field => "degR".to_string(),
            Dimension::TEMPERATURE => "K".to_string(),
            _ => self.unit_for(*d),
        };
        Some(format!("{integrand}*{time}"))
    }
}

/// How a value and a difference of one quantity are shown: its unit, parsed once.
#[derive(Debug, Clone)]
pub struct Display {
    absolute: Unit,
    difference: Unit,
}

impl Display {
    /// The display of a quantity in `unit` (e.g. `"degC"`, `"kmol/h"`, or an SI unit string).
    pub fn new(unit: &str) -> Result<Display, crate::UnitError> {
        Ok(Display { absolute: Unit::parse(unit)?, difference: Unit::parse_difference(unit)? })
    }
    /// The unit as written.
    pub fn unit(&self) -> &str {
        self.absolute.expression()
    }
    /// A value (SI) in the display unit (an offset scale's zero applied: 373.15 K is 100 degC).
    pub fn value(&self, si: f64) -> f64 {
        self.absolute.from_si(si)
    }
    /// A difference or deviation (SI) in the display unit (no offset: 1 K is 1 degC).
    pub fn difference(&self, si: f64) -> f64 {
        si / self.difference.factor()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_unit_has_its_dimension() {
        for (dim, metric, field) in TABLE {
            for u in [metric, field] {
                assert_eq!(Unit::parse(u).unwrap().dimension(), *dim, "{u}");
            }
        }
        assert_eq!(UnitSystem::Metric.unit_for(Dimension::DIMENSIONLESS), Dimension::DIMENSIONLESS.to_string());
        assert_eq!(UnitSystem::parse("Field"), Some(UnitSystem::Field));
        assert_eq!(UnitSystem::parse("imperial"), None);
    }

    /// A controller's integral of a temperature error, 60 K·s, reads 1 K·min in metric units and
    /// 1.8 degR·min in field units; of a flow error, 3600 mol, 3.6 kmol (the table's own entry).
    #[test]
    fn integrals_read_in_the_systems_time_unit() {
        let ks = Dimension::TEMPERATURE * Dimension::TIME;
        assert_eq!(UnitSystem::Metric.unit_for(ks), "K*min");
        assert_eq!(UnitSystem::Field.unit_for(ks), "degR*min");
        assert_eq!(UnitSystem::Si.unit_for(ks), ks.to_string());
        assert!((Display::new("K*min").unwrap().value(60.0) - 1.0).abs() < 1e-12);
        assert!((Display::new("degR*min").unwrap().value(60.0) - 1.8).abs() < 1e-12);
        let pa_s = UnitSystem::Metric.unit_for(Dimension::PRESSURE * Dimension::TIME);
        assert_eq!(pa_s, "kPa*min");
        assert!((Display::new(&pa_s).unwrap().value(60_000.0) - 1.0).abs() < 1e-12);
        assert_eq!(UnitSystem::Metric.unit_for(Dimension::MOLAR_FLOW * Dimension::TIME), "kmol");
    }

    #[test]
    fn values_take_the_offset_and_differences_do_not() {
        let c = Display::new("degC").unwrap();
        assert!((c.value(373.15) - 100.0).abs() < 1e-12);
        assert!((c.difference(2.5) - 2.5).abs() < 1e-12);
        let f = Display::new("degF").unwrap();
        assert!((f.value(373.15) - 212.0).abs() < 1e-9);
        assert!((f.difference(1.0) - 1.8).abs() < 1e-12);
        let kw = Display::new("kmol/h").unwrap();
        assert!((kw.value(1.0) - 3.6).abs() < 1e-12 && (kw.difference(1.0) - 3.6).abs() < 1e-12);
    }
}
