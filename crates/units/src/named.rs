//! The table of named dimensions: a word for messages, the SI symbol and example inputs.

use crate::Dimension;

/// A dimension with a name, as listed by [`named_dimensions`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NamedDimension {
    /// The dimension.
    pub dim: Dimension,
    /// A human word: `"molar flow"`.
    pub name: &'static str,
    /// The name with an indefinite article: `"a molar flow"`.
    pub phrase: &'static str,
    /// The coherent SI unit as a unit expression: `"mol/s"`.
    pub symbol: &'static str,
    /// Example inputs: `["1 kmol/min", "100 lbmol/h"]`.
    pub examples: &'static [&'static str],
}

const fn nd(
    dim: Dimension,
    name: &'static str,
    phrase: &'static str,
    symbol: &'static str,
    examples: &'static [&'static str],
) -> NamedDimension {
    NamedDimension { dim, name, phrase, symbol, examples }
}

type D = Dimension;

static NAMED: &[NamedDimension] = &[
    nd(D::DIMENSIONLESS, "dimensionless", "a dimensionless number", "1", &["0.5", "50 %"]),
    nd(D::MASS, "mass", "a mass", "kg", &["100 kg", "10 lb"]),
    nd(D::CURRENCY, "money", "an amount of money", "$", &["1000 $", "2 k$"]),
    nd(D::COST_RATE, "cost rate", "a cost rate", "$/s", &["100 $/h", "2 k$/d"]),
    nd(D::LENGTH, "length", "a length", "m", &["4.5 ft", "2 m"]),
    nd(D::TIME, "time", "a time", "s", &["2 min", "1 h"]),
    nd(D::TEMPERATURE, "temperature", "a temperature", "K", &["350 K", "80 degC"]),
    nd(D::AMOUNT, "amount of substance", "an amount of substance", "mol", &["0.5 kmol", "10 lbmol"]),
    nd(D::AREA, "area", "an area", "m2", &["10 m2", "100 ft2"]),
    nd(D::VOLUME, "volume", "a volume", "m3", &["5 m3", "100 gal"]),
    nd(D::VELOCITY, "velocity", "a velocity", "m/s", &["1.5 m/s", "3 ft/s"]),
    nd(D::FORCE, "force", "a force", "N", &["10 kN", "5 lbf"]),
    nd(D::PRESSURE, "pressure", "a pressure", "Pa", &["1 atm", "30 psia", "1.2 bar"]),
    nd(D::ENERGY, "energy", "an energy", "J", &["2500 kJ", "1 MMBtu"]),
    nd(D::POWER, "power (heat duty)", "a power (heat duty)", "W", &["3 kW", "1e6 Btu/h"]),
    nd(
        D::INVERSE_TIME,
        "inverse time (rate constant)",
        "an inverse time (rate constant)",
        "1/s",
        &["0.1 1/min", "10 kmol/min/kmol"],
    ),
    nd(D::MOLAR_FLOW, "molar flow", "a molar flow", "mol/s", &["1 kmol/min", "100 lbmol/h"]),
    nd(D::MASS_FLOW, "mass flow", "a mass flow", "kg/s", &["1e3 kg/h", "10 lb/s"]),
    nd(D::VOLUMETRIC_FLOW, "volumetric flow", "a volumetric flow", "m3/s", &["120 gpm", "2 m3/h"]),
    nd(
        D::MOLAR_ENERGY,
        "molar energy (molar enthalpy)",
        "a molar energy (molar enthalpy)",
        "J/mol",
        &["20 kJ/mol", "2500 kJ/kmol"],
    ),
    nd(
        D::SPECIFIC_ENERGY,
        "specific energy (per-mass enthalpy)",
        "a specific energy (per-mass enthalpy)",
        "J/kg",
        &["2257 kJ/kg", "970 Btu/lb"],
    ),
    nd(D::HEAT_CAPACITY, "heat capacity", "a heat capacity", "J/K", &["10 kJ/K", "50 Btu/degF"]),
    nd(
        D::HEAT_CAPACITY_MOLAR,
        "molar heat capacity",
        "a molar heat capacity",
        "J/(mol*K)",
        &["75 J/(mol*K)", "18 Btu/(lbmol*degF)"],
    ),
    nd(
        D::HEAT_CAPACITY_MASS,
        "specific heat capacity",
        "a specific heat capacity",
        "J/(kg*K)",
        &["4.18 kJ/(kg*K)", "1 Btu/(lb*degF)"],
    ),
    nd(
        D::UA,
        "heat-transfer conductance (UA)",
        "a heat-transfer conductance (UA)",
        "W/K",
        &["75 kW/K", "1e4 Btu/(h*degF)"],
    ),
    nd(
        D::HEAT_TRANSFER_COEFFICIENT,
        "heat-transfer coefficient",
        "a heat-transfer coefficient",
        "W/(m2*K)",
        &["500 W/(m2*K)", "100 Btu/(h*ft2*degF)"],
    ),
    nd(D::MOLAR_VOLUME, "molar volume", "a molar volume", "m3/mol", &["2.3e-4 m3/mol", "22.4 L/mol"]),
    nd(D::MOLAR_MASS, "molar mass", "a molar mass", "kg/mol", &["18 g/mol", "44 kg/kmol"]),
    nd(
        D::DENSITY_MOLAR,
        "molar density (concentration)",
        "a molar density (concentration)",
        "mol/m3",
        &["10 kmol/m3", "0.5 mol/L"],
    ),
    nd(D::DENSITY_MASS, "mass density", "a mass density", "kg/m3", &["1000 kg/m3", "62.4 lb/ft3"]),
    nd(D::REACTION_RATE, "volumetric reaction rate", "a volumetric reaction rate", "mol/(m3*s)", &["1 kmol/(m3*h)"]),
];

/// All named dimensions, one entry per distinct [`Dimension`].
pub fn named_dimensions() -> &'static [NamedDimension] {
    NAMED
}

pub(crate) fn lookup(dim: Dimension) -> Option<&'static NamedDimension> {
    NAMED.iter().find(|n| n.dim == dim)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_entry_per_dimension() {
        for (i, a) in NAMED.iter().enumerate() {
            for b in &NAMED[i + 1..] {
                assert_ne!(a.dim, b.dim, "{} and {} share a dimension", a.name, b.name);
            }
        }
    }

    #[test]
    fn phrases_contain_names() {
        for n in NAMED {
            assert!(n.phrase.contains(n.name), "{}", n.phrase);
            assert!(n.phrase.starts_with("a ") || n.phrase.starts_with("an "), "{}", n.phrase);
        }
    }
}
