//! Quantities as flowsheet files write them: compounds, affine temperatures, dimensions.

use approx::{abs_diff_eq, assert_abs_diff_eq};
use plantwide_units::{
    Dimension as D, Quantity, parse_difference, parse_difference_as, parse_quantity, parse_quantity_as,
};

#[track_caller]
fn check(text: &str, expected_si: f64, dim: D) {
    let q = parse_quantity(text).unwrap_or_else(|e| panic!("{text}: {e}"));
    assert_eq!(q.dim, dim, "{text}: dimension {} instead of {}", q.dim, dim);
    // 1e-12 relative, or absolute (SI) where the expected value is 0.
    let tolerance = 1e-12 * if expected_si == 0.0 { 1.0 } else { expected_si.abs() };
    for got in [q.value_si, parse_quantity_as(text, dim).unwrap()] {
        assert!(abs_diff_eq!(got, expected_si, epsilon = tolerance), "{text}: got {got:e}, expected {expected_si:e}");
    }
}

#[test]
fn flowsheet_examples() {
    check("1 kmol/min", 1000.0 / 60.0, D::MOLAR_FLOW);
    check("100 lbmol/h", 12.599_788_055_555_556, D::MOLAR_FLOW);
    check("350 K", 350.0, D::TEMPERATURE);
    check("80 degC", 353.15, D::TEMPERATURE);
    check("176 degF", 353.15, D::TEMPERATURE);
    check("30 degC", 303.15, D::TEMPERATURE);
    check("1 atm", 101_325.0, D::PRESSURE);
    check("30 psia", 206_842.718_795_04, D::PRESSURE);
    check("2 min", 120.0, D::TIME);
    check("5 m3", 5.0, D::VOLUME);
    check("1e6 Btu/h", 293_071.070_172_222_2, D::POWER);
    check("10 kmol/min/kmol", 10.0 / 60.0, D::INVERSE_TIME);
    check("0.5 kmol", 500.0, D::AMOUNT);
    check("1.2 bar", 120_000.0, D::PRESSURE);
    check("3 kW", 3000.0, D::POWER);
    check("2500 kJ/kmol", 2500.0, D::MOLAR_ENERGY);
    check("4.5 ft", 1.3716, D::LENGTH);
    check("120 gpm", 7.570_823_568e-3, D::VOLUMETRIC_FLOW);
    check("50 %", 0.5, D::DIMENSIONLESS);
    check("1.5", 1.5, D::DIMENSIONLESS);
    check("2.3e-4 m3/mol", 2.3e-4, D::MOLAR_VOLUME);
    check("20 kJ/mol", 20_000.0, D::MOLAR_ENERGY);
    check("8000 J/(mol*K)", 8000.0, D::HEAT_CAPACITY_MOLAR);
    check("75 kW/K", 75_000.0, D::UA);
    check("1e3 kg/h", 1000.0 / 3600.0, D::MASS_FLOW);
}

#[test]
fn gauge_pressure() {
    // 30 psi = 206842.71879504 Pa, plus one standard atmosphere.
    check("30 psig", 308_167.718_795_04, D::PRESSURE);
    check("0 psig", 101_325.0, D::PRESSURE);
    check("2 barg", 301_325.0, D::PRESSURE);
    check("14.695948775513 psia", 101_325.0, D::PRESSURE);
}

#[test]
fn affine_temperatures() {
    check("-40 degF", 233.15, D::TEMPERATURE);
    check("-40 degC", 233.15, D::TEMPERATURE);
    check("32 degF", 273.15, D::TEMPERATURE);
    check("212 °F", 373.15, D::TEMPERATURE);
    check("0 degC", 273.15, D::TEMPERATURE);
    check("25 °C", 298.15, D::TEMPERATURE);
    check("25 ℃", 298.15, D::TEMPERATURE);
    check("491.67 R", 273.15, D::TEMPERATURE);
    check("671.67 degR", 373.15, D::TEMPERATURE);
    check("-459.67 degF", 0.0, D::TEMPERATURE);
}

#[test]
fn offset_units_per_degree_in_compounds() {
    // In a denominator degC acts as K and degF as degR.
    check("4.184 kJ/(kg*degC)", 4184.0, D::HEAT_CAPACITY_MASS);
    check("1 kcal/(kg*degC)", 4184.0, D::HEAT_CAPACITY_MASS);
    // 1 Btu/(lb·°F) = 4186.8 J/(kg·K) exactly (IT Btu), likewise per lbmol and J/(mol·K).
    check("1 Btu/(lb*degF)", 4186.8, D::HEAT_CAPACITY_MASS);
    check("1 Btu/(lbmol*degF)", 4.1868, D::HEAT_CAPACITY_MOLAR);
    check("1 Btu/(lbmol*R)", 4.1868, D::HEAT_CAPACITY_MOLAR);
    check("1 Btu/(h*degF)", 1055.05585262 / 3600.0 * 1.8, D::UA);
    check("2e-4 1/degC", 2e-4, D::new(0, 0, 0, -1, 0));
}

#[test]
fn differences_drop_offsets() {
    let q = parse_difference("10 degC").unwrap();
    assert_eq!(q.dim, D::TEMPERATURE);
    assert_abs_diff_eq!(q.value_si, 10.0, epsilon = 1e-15 * 10.0);
    assert_abs_diff_eq!(parse_difference_as("18 degF", D::TEMPERATURE).unwrap(), 10.0, epsilon = 1e-14 * 10.0);
    let psi5 = 5.0 * 6894.757293168;
    assert_abs_diff_eq!(parse_difference_as("5 psig", D::PRESSURE).unwrap(), psi5, epsilon = 1e-13 * psi5);
    assert_abs_diff_eq!(parse_difference_as("5 kPag", D::PRESSURE).unwrap(), 5e3, epsilon = 1e-12 * 5e3);
    assert_eq!(parse_difference_as("10 K", D::TEMPERATURE).unwrap(), 10.0, "10 K");
    assert_eq!(parse_difference_as("3", D::TEMPERATURE).unwrap(), 3.0, "bare");
}

#[test]
fn more_compounds_and_spellings() {
    check("1 kWh", 3.6e6, D::ENERGY);
    check("1 hp", 745.699_871_582_270_2, D::POWER);
    check("1 ft3", 0.028_316_846_592, D::VOLUME);
    check("1 ft^3/min", 0.028_316_846_592 / 60.0, D::VOLUMETRIC_FLOW);
    check("264.172052358148 gal", 1.0, D::VOLUME);
    check("1 bbl/d", 0.158_987_294_928 / 86_400.0, D::VOLUMETRIC_FLOW);
    check("760 torr", 101_325.0, D::PRESSURE);
    check("760 mmHg", 101_325.014_435_4, D::PRESSURE);
    check("62.4 lb/ft3", 999.552_114_535_112_7, D::DENSITY_MASS);
    check("18 g/mol", 0.018, D::MOLAR_MASS);
    check("10 kmol/m3", 10_000.0, D::DENSITY_MOLAR);
    check("0.5 mol/L", 500.0, D::DENSITY_MOLAR);
    check("1 kmol/(m3*h)", 1000.0 / 3600.0, D::REACTION_RATE);
    check("500 W/(m2*K)", 500.0, D::HEAT_TRANSFER_COEFFICIENT);
    check("500 W/m2/K", 500.0, D::HEAT_TRANSFER_COEFFICIENT);
    check("500 W*m^-2*K^-1", 500.0, D::HEAT_TRANSFER_COEFFICIENT);
    check("2257 kJ/kg", 2.257e6, D::SPECIFIC_ENERGY);
    check("10 kJ/K", 10_000.0, D::HEAT_CAPACITY);
    check("3 ft/s", 0.9144, D::VELOCITY);
    check("5 lbf", 22.241_108_076_302_5, D::FORCE);
    check("0.1 1/min", 0.1 / 60.0, D::INVERSE_TIME);
    check("0.1 min^-1", 0.1 / 60.0, D::INVERSE_TIME);
    check("0.1 min⁻¹", 0.1 / 60.0, D::INVERSE_TIME);
    check("6 h·kmol/kmol", 21_600.0, D::TIME);
    check("1 J / ( mol * K )", 1.0, D::HEAT_CAPACITY_MOLAR);
    check("100 ppm", 1e-4, D::DIMENSIONLESS);
    check("0.25 -", 0.25, D::DIMENSIONLESS);
    check("2 t/h", 2000.0 / 3600.0, D::MASS_FLOW);
    check("1 ton", 907.184_74, D::MASS);
}

#[test]
fn number_spellings() {
    check("5m3", 5.0, D::VOLUME);
    check("  1 kmol/min  ", 1000.0 / 60.0, D::MOLAR_FLOW);
    check("+2.5e+2 K", 250.0, D::TEMPERATURE);
    check(".5 kmol", 500.0, D::AMOUNT);
    check("1. h", 3600.0, D::TIME);
    check("-3E-3 m", -3e-3, D::LENGTH);
    check("1e-400 m", 0.0, D::LENGTH);
}

#[test]
fn bare_numbers_are_si_in_the_expected_dimension() {
    assert_eq!(parse_quantity_as("12.6", D::MOLAR_FLOW).unwrap(), 12.6, "bare flow");
    assert_eq!(parse_quantity_as("350", D::TEMPERATURE).unwrap(), 350.0, "bare temperature");
    assert_eq!(parse_quantity("350").unwrap().dim, D::DIMENSIONLESS);
}

#[test]
fn quantity_from_str_and_display() {
    let q: Quantity = "100 lbmol/h".parse().unwrap();
    assert_eq!(q.dim, D::MOLAR_FLOW);
    assert_eq!(Quantity::new(2.5, D::MOLAR_FLOW).to_string(), "2.5 mol/s");
    assert_eq!(Quantity::new(101_325.0, D::PRESSURE).to_string(), "101325 Pa");
}
