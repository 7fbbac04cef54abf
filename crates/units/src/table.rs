//! The table of unit symbols with their SI factors, and SI prefixes.
//!
//! Conversion factors are exact definitions where one exists, otherwise NIST SP 811 (2008),
//! Appendix B.

use crate::Dimension;

/// How a unit maps onto its SI unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnitKind {
    /// `si = value * factor`.
    Linear,
    /// A temperature scale with an offset zero (degC, degF): `si = value * factor + offset` when it
    /// is the whole unit of an absolute temperature; inside a compound unit (only allowed in a
    /// denominator, "per degree") or for a temperature difference it acts as its
    /// `linear` equivalent (degC as K, degF as degR).
    OffsetTemperature {
        /// The linear unit with the same degree size.
        linear: &'static str,
    },
    /// A gauge pressure (psig, barg): `si = value * factor + 101325 Pa`. Only allowed as the whole
    /// unit; for a pressure difference it acts as its `linear` equivalent.
    GaugePressure {
        /// The linear unit with the same size.
        linear: &'static str,
    },
}

/// One row of the unit table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitDef {
    /// The symbol as written in unit expressions: `"lbmol"`.
    pub symbol: &'static str,
    /// What it is: `"pound-mole"`.
    pub name: &'static str,
    /// The size of one unit in coherent SI units: 453.59237 for lbmol (mol).
    pub factor: f64,
    /// The SI value of the scale's zero (273.15 K for degC, 101325 Pa for psig); 0 for linear units.
    pub offset: f64,
    /// The dimension.
    pub dim: Dimension,
    /// Whether SI prefixes may be attached (`kmol`, `kPa`, `mL`).
    pub prefixable: bool,
    /// Linear, offset temperature or gauge pressure.
    pub kind: UnitKind,
}

/// An SI prefix accepted on prefixable units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prefix {
    /// The symbol: `"k"`.
    pub symbol: &'static str,
    /// The multiplier: 1e3.
    pub factor: f64,
}

/// Pound (avoirdupois) in kg: 0.45359237 kg, exact.
pub const POUND: f64 = 0.45359237;
/// Standard acceleration of gravity in m/s²: 9.80665 m/s², exact.
pub const STANDARD_GRAVITY: f64 = 9.80665;
/// Foot in m: 0.3048 m, exact.
pub const FOOT: f64 = 0.3048;
/// Inch in m: 0.0254 m, exact.
pub const INCH: f64 = 0.0254;
/// Pound-force in N: lb × g₀ = 4.4482216152605 N, exact.
pub const POUND_FORCE: f64 = POUND * STANDARD_GRAVITY;
/// Pound-force per square inch in Pa: ≈ 6894.757293168 Pa.
pub const PSI: f64 = POUND_FORCE / (INCH * INCH);
/// Standard atmosphere in Pa: 101325 Pa, exact.
pub const ATM: f64 = 101325.0;
/// US liquid gallon in m³: 231 in³ = 3.785411784e-3 m³, exact.
pub const US_GALLON: f64 = 231.0 * INCH * INCH * INCH;
/// British thermal unit (International Table) in J: 1055.05585262 J, exact.
pub const BTU: f64 = 1055.05585262;
/// Thermochemical calorie in J: 4.184 J, exact.
pub const CALORIE: f64 = 4.184;
/// Mechanical horsepower in W: 550 ft·lbf/s ≈ 745.69987158 W.
pub const HORSEPOWER: f64 = 550.0 * FOOT * POUND_FORCE;
/// Pound-mole in mol: 453.59237 mol, exact.
pub const POUND_MOLE: f64 = 1000.0 * POUND;
/// Conventional millimetre of mercury in Pa: 13.5951 g/cm³ × g₀ × 1 mm = 133.322387415 Pa.
pub const MM_HG: f64 = 13595.1 * STANDARD_GRAVITY * 1e-3;
/// Size of the Rankine and Fahrenheit degree in K: 5/9 K.
pub const RANKINE: f64 = 5.0 / 9.0;
/// Molar gas constant in J/(mol·K): N_A·k = 8.31446261815324, exact since the 2019 SI.
pub const GAS_CONSTANT: f64 = 8.314_462_618_153_24;
/// Normal cubic metre in mol: the ideal gas in 1 m³ at 0 °C and 1 atm (DIN 1343), `ATM / (R · 273.15 K)`
/// ≈ 44.6150 mol. The volume of `kscmh` (10³ m³/h at 0 °C and 1 atm).
pub const NORMAL_CUBIC_METRE: f64 = ATM / (GAS_CONSTANT * 273.15);
/// Standard cubic foot in mol: the ideal gas in 1 ft³ at 60 °F and 14.696 psia (the US gas-industry
/// standard conditions of GPA 2172 / API MPMS 14.5), ≈ 1.19530 mol. The volume of `MMSCFD`.
pub const STANDARD_CUBIC_FOOT: f64 = 14.696 * PSI * FOOT * FOOT * FOOT / (GAS_CONSTANT * 519.67 * RANKINE);

type D = Dimension;

const fn lin(symbol: &'static str, name: &'static str, factor: f64, dim: D) -> UnitDef {
    UnitDef { symbol, name, factor, offset: 0.0, dim, prefixable: false, kind: UnitKind::Linear }
}

const fn pre(symbol: &'static str, name: &'static str, factor: f64, dim: D) -> UnitDef {
    UnitDef { symbol, name, factor, offset: 0.0, dim, prefixable: true, kind: UnitKind::Linear }
}

const fn temp(symbol: &'static str, name: &'static str, factor: f64, offset: f64, linear: &'static str) -> UnitDef {
    let kind = UnitKind::OffsetTemperature { linear };
    UnitDef { symbol, name, factor, offset, dim: D::TEMPERATURE, prefixable: false, kind }
}

const fn gauge(symbol: &'static str, name: &'static str, factor: f64, linear: &'static str) -> UnitDef {
    let kind = UnitKind::GaugePressure { linear };
    UnitDef { symbol, name, factor, offset: ATM, dim: D::PRESSURE, prefixable: false, kind }
}

const DEG_F_OFFSET: f64 = 459.67 * RANKINE;

static UNITS: &[UnitDef] = &[
    // Dimensionless. "-" is only recognised as a whole unit expression.
    lin("-", "dimensionless", 1.0, D::DIMENSIONLESS),
    lin("%", "percent", 1e-2, D::DIMENSIONLESS),
    lin("ppm", "parts per million", 1e-6, D::DIMENSIONLESS),
    lin("ppb", "parts per billion", 1e-9, D::DIMENSIONLESS),
    // Currency: one money unit, the plant's (no exchange rates); k$ and M$ by prefix.
    pre("$", "currency unit", 1.0, D::CURRENCY),
    // Mass.
    pre("g", "gram", 1e-3, D::MASS),
    lin("lb", "pound (avoirdupois)", POUND, D::MASS),
    lin("lbm", "pound-mass", POUND, D::MASS),
    lin("ton", "short ton (2000 lb)", 2000.0 * POUND, D::MASS),
    lin("t", "tonne (metric ton)", 1000.0, D::MASS),
    lin("tonne", "tonne (metric ton)", 1000.0, D::MASS),
    // Length.
    pre("m", "metre", 1.0, D::LENGTH),
    lin("ft", "foot", FOOT, D::LENGTH),
    lin("in", "inch", INCH, D::LENGTH),
    // Time.
    pre("s", "second", 1.0, D::TIME),
    lin("min", "minute", 60.0, D::TIME),
    lin("h", "hour", 3600.0, D::TIME),
    lin("hr", "hour", 3600.0, D::TIME),
    lin("d", "day", 86400.0, D::TIME),
    lin("day", "day", 86400.0, D::TIME),
    // Temperature.
    lin("K", "kelvin", 1.0, D::TEMPERATURE),
    temp("degC", "degree Celsius", 1.0, 273.15, "K"),
    temp("°C", "degree Celsius", 1.0, 273.15, "K"),
    temp("℃", "degree Celsius", 1.0, 273.15, "K"),
    temp("degF", "degree Fahrenheit", RANKINE, DEG_F_OFFSET, "degR"),
    temp("°F", "degree Fahrenheit", RANKINE, DEG_F_OFFSET, "degR"),
    temp("℉", "degree Fahrenheit", RANKINE, DEG_F_OFFSET, "degR"),
    lin("degR", "degree Rankine", RANKINE, D::TEMPERATURE),
    lin("°R", "degree Rankine", RANKINE, D::TEMPERATURE),
    lin("R", "degree Rankine", RANKINE, D::TEMPERATURE),
    // Amount of substance.
    pre("mol", "mole", 1.0, D::AMOUNT),
    lin("gmol", "gram-mole", 1.0, D::AMOUNT),
    lin("kgmol", "kilogram-mole", 1000.0, D::AMOUNT),
    lin("lbmol", "pound-mole", POUND_MOLE, D::AMOUNT),
    // Volume and volumetric flow.
    pre("L", "litre", 1e-3, D::VOLUME),
    pre("l", "litre", 1e-3, D::VOLUME),
    lin("gal", "US gallon", US_GALLON, D::VOLUME),
    lin("bbl", "barrel (petroleum, 42 US gal)", 42.0 * US_GALLON, D::VOLUME),
    lin("gpm", "US gallon per minute", US_GALLON / 60.0, D::VOLUMETRIC_FLOW),
    // Gas quantities as ideal-gas volumes at standard conditions: amounts and molar flows.
    lin("Nm3", "normal cubic metre (0 degC, 1 atm)", NORMAL_CUBIC_METRE, D::AMOUNT),
    lin("scmh", "standard cubic metre per hour (0 degC, 1 atm)", NORMAL_CUBIC_METRE / 3600.0, D::MOLAR_FLOW),
    lin(
        "kscmh",
        "10^3 standard cubic metres per hour (0 degC, 1 atm)",
        1e3 * NORMAL_CUBIC_METRE / 3600.0,
        D::MOLAR_FLOW,
    ),
    lin("scf", "standard cubic foot (60 degF, 14.696 psia)", STANDARD_CUBIC_FOOT, D::AMOUNT),
    lin(
        "MSCFD",
        "10^3 standard cubic feet per day (60 degF, 14.696 psia)",
        1e3 * STANDARD_CUBIC_FOOT / 86400.0,
        D::MOLAR_FLOW,
    ),
    lin(
        "MMSCFD",
        "10^6 standard cubic feet per day (60 degF, 14.696 psia)",
        1e6 * STANDARD_CUBIC_FOOT / 86400.0,
        D::MOLAR_FLOW,
    ),
    // Pressure.
    pre("Pa", "pascal", 1.0, D::PRESSURE),
    pre("bar", "bar", 1e5, D::PRESSURE),
    lin("bara", "bar absolute", 1e5, D::PRESSURE),
    gauge("barg", "bar gauge", 1e5, "bar"),
    gauge("kPag", "kilopascal gauge", 1e3, "kPa"),
    gauge("MPag", "megapascal gauge", 1e6, "MPa"),
    lin("atm", "standard atmosphere", ATM, D::PRESSURE),
    lin("psi", "pound-force per square inch", PSI, D::PRESSURE),
    lin("psia", "pound-force per square inch absolute", PSI, D::PRESSURE),
    gauge("psig", "pound-force per square inch gauge", PSI, "psi"),
    lin("torr", "torr (1/760 atm)", ATM / 760.0, D::PRESSURE),
    lin("Torr", "torr (1/760 atm)", ATM / 760.0, D::PRESSURE),
    lin("mmHg", "millimetre of mercury (conventional)", MM_HG, D::PRESSURE),
    lin("inHg", "inch of mercury (conventional)", 13595.1 * STANDARD_GRAVITY * INCH, D::PRESSURE),
    lin("inH2O", "inch of water (conventional)", 1000.0 * STANDARD_GRAVITY * INCH, D::PRESSURE),
    // Energy.
    pre("J", "joule", 1.0, D::ENERGY),
    pre("cal", "calorie (thermochemical)", CALORIE, D::ENERGY),
    lin("Btu", "British thermal unit (IT)", BTU, D::ENERGY),
    lin("MMBtu", "million Btu (IT)", 1e6 * BTU, D::ENERGY),
    pre("Wh", "watt-hour", 3600.0, D::ENERGY),
    // Power.
    pre("W", "watt", 1.0, D::POWER),
    lin("hp", "horsepower (mechanical, 550 ft·lbf/s)", HORSEPOWER, D::POWER),
    // Force.
    pre("N", "newton", 1.0, D::FORCE),
    lin("lbf", "pound-force", POUND_FORCE, D::FORCE),
];

static PREFIXES: &[Prefix] = &[
    Prefix { symbol: "T", factor: 1e12 },
    Prefix { symbol: "G", factor: 1e9 },
    Prefix { symbol: "M", factor: 1e6 },
    Prefix { symbol: "k", factor: 1e3 },
    Prefix { symbol: "h", factor: 1e2 },
    Prefix { symbol: "da", factor: 1e1 },
    Prefix { symbol: "d", factor: 1e-1 },
    Prefix { symbol: "c", factor: 1e-2 },
    Prefix { symbol: "m", factor: 1e-3 },
    Prefix { symbol: "µ", factor: 1e-6 },
    Prefix { symbol: "μ", factor: 1e-6 },
    Prefix { symbol: "u", factor: 1e-6 },
    Prefix { symbol: "n", factor: 1e-9 },
    Prefix { symbol: "p", factor: 1e-12 },
];

/// The unit table (without prefixed forms).
pub fn units() -> &'static [UnitDef] {
    UNITS
}

/// The SI prefixes accepted on units with [`UnitDef::prefixable`] set.
pub fn prefixes() -> &'static [Prefix] {
    PREFIXES
}

/// A symbol resolved against the table: the definition and the prefix multiplier (1 without one).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Resolved {
    pub def: &'static UnitDef,
    pub prefix: f64,
}

impl Resolved {
    pub fn factor(&self) -> f64 {
        self.def.factor * self.prefix
    }
}

fn exact(symbol: &str) -> Option<&'static UnitDef> {
    UNITS.iter().find(|u| u.symbol == symbol)
}

/// Resolves a symbol: an exact table entry first, then an SI prefix on a prefixable unit.
pub(crate) fn lookup(symbol: &str) -> Option<Resolved> {
    if let Some(def) = exact(symbol) {
        return Some(Resolved { def, prefix: 1.0 });
    }
    PREFIXES.iter().find_map(|p| {
        let def = exact(symbol.strip_prefix(p.symbol)?)?;
        def.prefixable.then_some(Resolved { def, prefix: p.factor })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn symbols_unique() {
        for (i, a) in UNITS.iter().enumerate() {
            assert!(UNITS[i + 1..].iter().all(|b| b.symbol != a.symbol), "duplicate {}", a.symbol);
        }
    }

    /// An exact symbol must not shadow a different prefixed reading (e.g. "min" is not milli-inch).
    #[test]
    fn exact_symbols_do_not_shadow_prefixed_forms() {
        for u in UNITS {
            for p in PREFIXES {
                if let Some(def) = u.symbol.strip_prefix(p.symbol).and_then(exact)
                    && def.prefixable
                {
                    let same = def.dim == u.dim && (def.factor * p.factor - u.factor).abs() <= 1e-12 * u.factor;
                    assert!(same, "{} is also {} + {}", u.symbol, p.symbol, def.symbol);
                }
            }
        }
    }

    #[test]
    fn prefixed_lookup() {
        let r = lookup("kmol").unwrap();
        assert_eq!(r.def.symbol, "mol");
        assert_eq!(r.factor(), 1e3);
        assert_eq!(lookup("kg").unwrap().factor(), 1.0);
        assert_eq!(lookup("dam").unwrap().factor(), 10.0);
        assert_eq!(lookup("min").unwrap().factor(), 60.0);
        assert!(lookup("kft").is_none());
        assert!(lookup("kdegC").is_none());
        assert!(lookup("MBtu").is_none());
    }

    /// Standard gas volumes against independent figures: 1 Nm³ = 44.615 mol (the ideal-gas molar
    /// volume at 0 °C and 1 atm is 22.41397 L/mol, CODATA 2018); 1 scf = 1.19530 mol (379.48 scf per
    /// lb-mol at 60 °F and 14.696 psia, GPSA Engineering Data Book, section 1).
    #[test]
    fn standard_gas_volumes() {
        assert!((1.0 / NORMAL_CUBIC_METRE - 22.413_969_54e-3).abs() < 1e-11);
        let scf_per_lbmol = POUND_MOLE / STANDARD_CUBIC_FOOT;
        assert!((scf_per_lbmol - 379.48).abs() < 0.01, "{scf_per_lbmol}");
        assert_eq!(lookup("kscmh").unwrap().factor(), 1e3 * lookup("scmh").unwrap().factor());
        assert_eq!(lookup("MMSCFD").unwrap().def.dim, D::MOLAR_FLOW);
    }
}
