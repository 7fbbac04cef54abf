//! Physical dimensions as integer exponents of the SI base dimensions.

use std::borrow::Cow;
use std::fmt;
use std::ops::{Div, Mul};

use crate::named;

/// The dimension of a quantity: integer exponents of the SI base dimensions mass (kg), length (m),
/// time (s), thermodynamic temperature (K) and amount of substance (mol), and one non-SI base,
/// currency (`$`: the plant's money unit, one currency without exchange rates), so that prices
/// (`$/kmol`), costs (`$/h`) and economic objectives are checked like any other quantity. Electric
/// current and luminous intensity are not needed by the simulator and are not represented.
///
/// `Dimension::PRESSURE` is kg·m⁻¹·s⁻², so its fields are `mass: 1, length: -1, time: -2`.
/// Displays as the SI symbol of a named dimension (`"mol/s"`, `"Pa"`, `"J/(mol*K)"`), otherwise as a
/// product of base units (`"kg*m/s3"`); every display string is itself a valid unit expression.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Dimension {
    /// Exponent of mass (kg).
    pub mass: i8,
    /// Exponent of length (m).
    pub length: i8,
    /// Exponent of time (s).
    pub time: i8,
    /// Exponent of thermodynamic temperature (K).
    pub temperature: i8,
    /// Exponent of amount of substance (mol).
    pub amount: i8,
    /// Exponent of currency (`$`).
    pub currency: i8,
}

impl Dimension {
    /// A dimension from its exponents of mass (kg), length (m), time (s), temperature (K) and
    /// amount (mol).
    pub const fn new(mass: i8, length: i8, time: i8, temperature: i8, amount: i8) -> Self {
        Dimension { mass, length, time, temperature, amount, currency: 0 }
    }

    /// The number of base dimensions: the five SI ones and currency.
    pub const BASES: usize = 6;

    /// Dimensionless (1): fractions, ratios, percentages.
    pub const DIMENSIONLESS: Dimension = Dimension::new(0, 0, 0, 0, 0);
    /// Mass (kg).
    pub const MASS: Dimension = Dimension::new(1, 0, 0, 0, 0);
    /// Length (m).
    pub const LENGTH: Dimension = Dimension::new(0, 1, 0, 0, 0);
    /// Time (s).
    pub const TIME: Dimension = Dimension::new(0, 0, 1, 0, 0);
    /// Thermodynamic temperature, and temperature difference (K).
    pub const TEMPERATURE: Dimension = Dimension::new(0, 0, 0, 1, 0);
    /// Amount of substance (mol).
    pub const AMOUNT: Dimension = Dimension::new(0, 0, 0, 0, 1);
    /// Area (m²).
    pub const AREA: Dimension = Dimension::new(0, 2, 0, 0, 0);
    /// Volume (m³).
    pub const VOLUME: Dimension = Dimension::new(0, 3, 0, 0, 0);
    /// Velocity (m/s).
    pub const VELOCITY: Dimension = Dimension::new(0, 1, -1, 0, 0);
    /// Force (N = kg·m/s²).
    pub const FORCE: Dimension = Dimension::new(1, 1, -2, 0, 0);
    /// Pressure (Pa = kg/(m·s²)).
    pub const PRESSURE: Dimension = Dimension::new(1, -1, -2, 0, 0);
    /// Energy (J = kg·m²/s²).
    pub const ENERGY: Dimension = Dimension::new(1, 2, -2, 0, 0);
    /// Power, heat duty (W = J/s).
    pub const POWER: Dimension = Dimension::new(1, 2, -3, 0, 0);
    /// Heat duty (W); the same dimension as [`Dimension::POWER`].
    pub const HEAT_DUTY: Dimension = Dimension::POWER;
    /// Inverse time (1/s): rate constants, frequencies, specific rates such as kmol/min per kmol.
    pub const INVERSE_TIME: Dimension = Dimension::new(0, 0, -1, 0, 0);
    /// Molar flow (mol/s).
    pub const MOLAR_FLOW: Dimension = Dimension::new(0, 0, -1, 0, 1);
    /// Mass flow (kg/s).
    pub const MASS_FLOW: Dimension = Dimension::new(1, 0, -1, 0, 0);
    /// Volumetric flow (m³/s).
    pub const VOLUMETRIC_FLOW: Dimension = Dimension::new(0, 3, -1, 0, 0);
    /// Molar energy, molar enthalpy, heat of reaction or vaporization, activation energy (J/mol).
    pub const MOLAR_ENERGY: Dimension = Dimension::new(1, 2, -2, 0, -1);
    /// Molar enthalpy (J/mol); the same dimension as [`Dimension::MOLAR_ENERGY`].
    pub const MOLAR_ENTHALPY: Dimension = Dimension::MOLAR_ENERGY;
    /// Specific (per-mass) energy or enthalpy (J/kg).
    pub const SPECIFIC_ENERGY: Dimension = Dimension::new(0, 2, -2, 0, 0);
    /// Heat capacity of a body or holdup (J/K).
    pub const HEAT_CAPACITY: Dimension = Dimension::new(1, 2, -2, -1, 0);
    /// Molar heat capacity, molar entropy, gas constant (J/(mol·K)).
    pub const HEAT_CAPACITY_MOLAR: Dimension = Dimension::new(1, 2, -2, -1, -1);
    /// Specific (per-mass) heat capacity (J/(kg·K)).
    pub const HEAT_CAPACITY_MASS: Dimension = Dimension::new(0, 2, -2, -1, 0);
    /// Heat-transfer conductance UA (W/K).
    pub const UA: Dimension = Dimension::new(1, 2, -3, -1, 0);
    /// Heat-transfer coefficient U (W/(m²·K)).
    pub const HEAT_TRANSFER_COEFFICIENT: Dimension = Dimension::new(1, 0, -3, -1, 0);
    /// Molar volume (m³/mol).
    pub const MOLAR_VOLUME: Dimension = Dimension::new(0, 3, 0, 0, -1);
    /// Molar mass (kg/mol).
    pub const MOLAR_MASS: Dimension = Dimension::new(1, 0, 0, 0, -1);
    /// Molar density, concentration (mol/m³).
    pub const DENSITY_MOLAR: Dimension = Dimension::new(0, -3, 0, 0, 1);
    /// Concentration (mol/m³); the same dimension as [`Dimension::DENSITY_MOLAR`].
    pub const CONCENTRATION: Dimension = Dimension::DENSITY_MOLAR;
    /// Mass density (kg/m³).
    pub const DENSITY_MASS: Dimension = Dimension::new(1, -3, 0, 0, 0);
    /// Volumetric reaction rate (mol/(m³·s)).
    pub const REACTION_RATE: Dimension = Dimension::new(0, -3, -1, 0, 1);
    /// Money (`$`).
    pub const CURRENCY: Dimension = Dimension::from_exponents([0, 0, 0, 0, 0, 1]);
    /// A cost or revenue rate, an economic objective (`$/s`; shown as `$/h` in plant units).
    pub const COST_RATE: Dimension = Dimension::from_exponents([0, 0, -1, 0, 0, 1]);

    /// Whether all exponents are zero.
    pub const fn is_dimensionless(&self) -> bool {
        self.mass == 0
            && self.length == 0
            && self.time == 0
            && self.temperature == 0
            && self.amount == 0
            && self.currency == 0
    }

    /// The exponents in the order mass, length, time, temperature, amount, currency.
    pub const fn exponents(&self) -> [i8; Dimension::BASES] {
        [self.mass, self.length, self.time, self.temperature, self.amount, self.currency]
    }

    /// The dimension with exponents `e`, in the order of [`Dimension::exponents`].
    pub const fn from_exponents(e: [i8; Dimension::BASES]) -> Self {
        Dimension { mass: e[0], length: e[1], time: e[2], temperature: e[3], amount: e[4], currency: e[5] }
    }

    fn zip(self, other: Dimension, f: impl Fn(i8, i8) -> Option<i8>) -> Option<Dimension> {
        let (a, b) = (self.exponents(), other.exponents());
        let mut out = [0i8; Dimension::BASES];
        for i in 0..Dimension::BASES {
            out[i] = f(a[i], b[i])?;
        }
        Some(Dimension::from_exponents(out))
    }

    /// The dimension of a product, or `None` if an exponent leaves the `i8` range.
    pub fn checked_mul(self, other: Dimension) -> Option<Dimension> {
        self.zip(other, i8::checked_add)
    }

    /// The dimension of a quotient, or `None` if an exponent leaves the `i8` range.
    pub fn checked_div(self, other: Dimension) -> Option<Dimension> {
        self.zip(other, i8::checked_sub)
    }

    /// The dimension raised to an integer power, or `None` if an exponent leaves the `i8` range.
    pub fn checked_pow(self, n: i32) -> Option<Dimension> {
        let mut out = [0i8; Dimension::BASES];
        for (o, e) in out.iter_mut().zip(self.exponents()) {
            *o = i8::try_from(i32::from(e).checked_mul(n)?).ok()?;
        }
        Some(Dimension::from_exponents(out))
    }

    /// The dimension raised to an integer power.
    ///
    /// # Panics
    /// If an exponent leaves the `i8` range.
    pub fn pow(self, n: i32) -> Dimension {
        self.checked_pow(n).expect("dimension exponent overflow")
    }

    /// A human word for a named dimension (`"molar flow"`, `"pressure"`), otherwise
    /// `"quantity in kg*m/s3"`.
    pub fn name(&self) -> Cow<'static, str> {
        match named::lookup(*self) {
            Some(n) => Cow::Borrowed(n.name),
            None => Cow::Owned(format!("quantity in {self}")),
        }
    }

    /// The name with an indefinite article, for messages: `"a molar flow"`, `"an energy"`,
    /// `"a dimensionless number"`, `"a quantity in kg*m/s3"`.
    pub fn describe(&self) -> Cow<'static, str> {
        match named::lookup(*self) {
            Some(n) => Cow::Borrowed(n.phrase),
            None => Cow::Owned(format!("a quantity in {self}")),
        }
    }

    /// Example inputs for a field of this dimension (`["1 kmol/min", "100 lbmol/h"]`); empty for
    /// dimensions without a name.
    pub fn examples(&self) -> &'static [&'static str] {
        named::lookup(*self).map_or(&[], |n| n.examples)
    }

    /// A hint listing valid inputs, used in error messages:
    /// `"1 kmol/min", "100 lbmol/h" or a bare number in mol/s` (with the quotes).
    pub fn example_hint(&self) -> String {
        let mut parts: Vec<String> = self.examples().iter().map(|e| format!("\"{e}\"")).collect();
        parts.push(if self.is_dimensionless() {
            "a bare number".to_owned()
        } else {
            format!("a bare number in {self}")
        });
        let last = parts.pop().unwrap_or_default();
        if parts.is_empty() { last } else { format!("{} or {last}", parts.join(", ")) }
    }
}

impl Mul for Dimension {
    type Output = Dimension;
    /// # Panics
    /// If an exponent leaves the `i8` range.
    fn mul(self, rhs: Dimension) -> Dimension {
        self.checked_mul(rhs).expect("dimension exponent overflow")
    }
}

impl Div for Dimension {
    type Output = Dimension;
    /// # Panics
    /// If an exponent leaves the `i8` range.
    fn div(self, rhs: Dimension) -> Dimension {
        self.checked_div(rhs).expect("dimension exponent overflow")
    }
}

impl fmt::Display for Dimension {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(n) = named::lookup(*self) {
            return f.write_str(n.symbol);
        }
        const SYMBOLS: [&str; Dimension::BASES] = ["kg", "m", "s", "K", "mol", "$"];
        let term = |s: &str, e: i8| {
            if e == 1 { s.to_owned() } else { format!("{s}{e}") }
        };
        let (mut num, mut den) = (Vec::new(), Vec::new());
        for (s, e) in SYMBOLS.iter().zip(self.exponents()) {
            if e > 0 {
                num.push(term(s, e));
            } else if e < 0 {
                den.push(term(s, -e));
            }
        }
        let num = if num.is_empty() { "1".to_owned() } else { num.join("*") };
        match den.len() {
            0 => write!(f, "{num}"),
            1 => write!(f, "{num}/{}", den[0]),
            _ => write!(f, "{num}/({})", den.join("*")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn algebra() {
        assert_eq!(Dimension::AMOUNT / Dimension::TIME, Dimension::MOLAR_FLOW);
        assert_eq!(Dimension::ENERGY / Dimension::TIME, Dimension::POWER);
        assert_eq!(Dimension::FORCE / Dimension::AREA, Dimension::PRESSURE);
        assert_eq!(Dimension::LENGTH.pow(3), Dimension::VOLUME);
        assert_eq!(Dimension::POWER / Dimension::TEMPERATURE, Dimension::UA);
        assert_eq!(Dimension::MOLAR_FLOW / Dimension::AMOUNT, Dimension::INVERSE_TIME);
        assert_eq!(Dimension::TIME.pow(-1), Dimension::INVERSE_TIME);
        assert!(Dimension::LENGTH.checked_pow(200).is_none());
        assert!(Dimension::new(127, 0, 0, 0, 0).checked_mul(Dimension::MASS).is_none());
    }

    #[test]
    fn display_named_and_generic() {
        assert_eq!(Dimension::MOLAR_FLOW.to_string(), "mol/s");
        assert_eq!(Dimension::TEMPERATURE.to_string(), "K");
        assert_eq!(Dimension::PRESSURE.to_string(), "Pa");
        assert_eq!(Dimension::HEAT_CAPACITY_MOLAR.to_string(), "J/(mol*K)");
        assert_eq!(Dimension::DIMENSIONLESS.to_string(), "1");
        assert_eq!(Dimension::new(0, 1, -2, 0, 0).to_string(), "m/s2");
        assert_eq!(Dimension::new(0, 0, -2, 0, 0).to_string(), "1/s2");
        assert_eq!(Dimension::new(1, 1, 0, -1, -1).to_string(), "kg*m/(K*mol)");
    }

    #[test]
    fn names_and_hints() {
        assert_eq!(Dimension::MOLAR_FLOW.name(), "molar flow");
        assert_eq!(Dimension::PRESSURE.name(), "pressure");
        assert_eq!(Dimension::ENERGY.describe(), "an energy");
        assert_eq!(Dimension::new(0, 1, -2, 0, 0).name(), "quantity in m/s2");
        assert_eq!(Dimension::MOLAR_FLOW.example_hint(), "\"1 kmol/min\", \"100 lbmol/h\" or a bare number in mol/s");
        assert_eq!(Dimension::new(0, 1, -2, 0, 0).example_hint(), "a bare number in m/s2");
        assert_eq!(Dimension::DIMENSIONLESS.example_hint(), "\"0.5\", \"50 %\" or a bare number");
    }
}
