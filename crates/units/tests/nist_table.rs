//! Every unit in the table against an independently written conversion factor.
//!
//! Sources: exact definitions (lb = 0.45359237 kg, ft = 0.3048 m, in = 0.0254 m, US gal = 231 in³,
//! atm = 101325 Pa, bar = 1e5 Pa, cal(th) = 4.184 J, Btu(IT) = 1055.05585262 J, °R = 5/9 K) and
//! NIST SP 811 (2008) Appendix B.8/B.9 for derived ones (psi = 6.894 757 293 168 E+03 Pa,
//! hp = 7.456 998 716 E+02 W, torr = 1.333 224 E+02 Pa, mmHg = 1.333 224 E+02 Pa,
//! inHg (conventional) = 3.386 389 E+03 Pa, inH2O (conventional) = 2.490 889 E+02 Pa,
//! lbf = 4.448 222 E+00 N, bbl (42 gal) = 1.589 873 E-01 m³). Standard gas volumes: the ideal-gas
//! molar volume at 0 °C and 101.325 kPa, 22.413 969 54 L/mol (CODATA 2018), and 379.482 scf per
//! lb-mol at 60 °F and 14.696 psia (GPA 2172).

use approx::abs_diff_eq;
use plantwide_units::{Dimension as D, UnitKind, parse_quantity, units};

/// (symbol, SI value of 1 unit, SI value of 0 units (offset), dimension, relative tolerance)
const EXPECTED: &[(&str, f64, f64, D, f64)] = &[
    ("-", 1.0, 0.0, D::DIMENSIONLESS, 0.0),
    ("%", 0.01, 0.0, D::DIMENSIONLESS, 1e-15),
    ("ppm", 1e-6, 0.0, D::DIMENSIONLESS, 1e-15),
    ("ppb", 1e-9, 0.0, D::DIMENSIONLESS, 1e-15),
    ("$", 1.0, 0.0, D::CURRENCY, 0.0),
    ("g", 1e-3, 0.0, D::MASS, 1e-15),
    ("lb", 0.45359237, 0.0, D::MASS, 1e-15),
    ("lbm", 0.45359237, 0.0, D::MASS, 1e-15),
    ("ton", 907.18474, 0.0, D::MASS, 1e-15),
    ("t", 1000.0, 0.0, D::MASS, 0.0),
    ("tonne", 1000.0, 0.0, D::MASS, 0.0),
    ("m", 1.0, 0.0, D::LENGTH, 0.0),
    ("ft", 0.3048, 0.0, D::LENGTH, 1e-15),
    ("in", 0.0254, 0.0, D::LENGTH, 1e-15),
    ("s", 1.0, 0.0, D::TIME, 0.0),
    ("min", 60.0, 0.0, D::TIME, 0.0),
    ("h", 3600.0, 0.0, D::TIME, 0.0),
    ("hr", 3600.0, 0.0, D::TIME, 0.0),
    ("d", 86400.0, 0.0, D::TIME, 0.0),
    ("day", 86400.0, 0.0, D::TIME, 0.0),
    ("K", 1.0, 0.0, D::TEMPERATURE, 0.0),
    ("degC", 274.15, 273.15, D::TEMPERATURE, 1e-15),
    ("°C", 274.15, 273.15, D::TEMPERATURE, 1e-15),
    ("℃", 274.15, 273.15, D::TEMPERATURE, 1e-15),
    // 0 °F = 459.67 °R = 255.372 222… K; 1 °F = 460.67 × 5/9 K.
    ("degF", 255.927_777_777_777_8, 255.372_222_222_222_2, D::TEMPERATURE, 1e-14),
    ("°F", 255.927_777_777_777_8, 255.372_222_222_222_2, D::TEMPERATURE, 1e-14),
    ("℉", 255.927_777_777_777_8, 255.372_222_222_222_2, D::TEMPERATURE, 1e-14),
    ("degR", 0.555_555_555_555_555_6, 0.0, D::TEMPERATURE, 1e-15),
    ("°R", 0.555_555_555_555_555_6, 0.0, D::TEMPERATURE, 1e-15),
    ("R", 0.555_555_555_555_555_6, 0.0, D::TEMPERATURE, 1e-15),
    ("mol", 1.0, 0.0, D::AMOUNT, 0.0),
    ("gmol", 1.0, 0.0, D::AMOUNT, 0.0),
    ("kgmol", 1000.0, 0.0, D::AMOUNT, 0.0),
    ("lbmol", 453.59237, 0.0, D::AMOUNT, 1e-15),
    ("L", 1e-3, 0.0, D::VOLUME, 1e-15),
    ("l", 1e-3, 0.0, D::VOLUME, 1e-15),
    ("gal", 3.785411784e-3, 0.0, D::VOLUME, 1e-15),
    ("bbl", 0.158987294928, 0.0, D::VOLUME, 1e-15),
    ("gpm", 3.785411784e-3 / 60.0, 0.0, D::VOLUMETRIC_FLOW, 1e-15),
    ("Nm3", 1.0 / 22.413_969_54e-3, 0.0, D::AMOUNT, 1e-9),
    ("scmh", 1.0 / 22.413_969_54e-3 / 3600.0, 0.0, D::MOLAR_FLOW, 1e-9),
    ("kscmh", 1e3 / 22.413_969_54e-3 / 3600.0, 0.0, D::MOLAR_FLOW, 1e-9),
    ("scf", 453.59237 / 379.482, 0.0, D::AMOUNT, 1e-5),
    ("MSCFD", 1e3 * 453.59237 / 379.482 / 86400.0, 0.0, D::MOLAR_FLOW, 1e-5),
    ("MMSCFD", 1e6 * 453.59237 / 379.482 / 86400.0, 0.0, D::MOLAR_FLOW, 1e-5),
    ("Pa", 1.0, 0.0, D::PRESSURE, 0.0),
    ("bar", 1e5, 0.0, D::PRESSURE, 0.0),
    ("bara", 1e5, 0.0, D::PRESSURE, 0.0),
    ("barg", 1e5 + 101325.0, 101325.0, D::PRESSURE, 1e-15),
    ("atm", 101325.0, 0.0, D::PRESSURE, 0.0),
    ("psi", 6894.757293168, 0.0, D::PRESSURE, 1e-13),
    ("psia", 6894.757293168, 0.0, D::PRESSURE, 1e-13),
    ("psig", 6894.757293168 + 101325.0, 101325.0, D::PRESSURE, 1e-13),
    ("kPag", 1e3 + 101325.0, 101325.0, D::PRESSURE, 1e-15),
    ("MPag", 1e6 + 101325.0, 101325.0, D::PRESSURE, 1e-15),
    ("torr", 133.3224, 0.0, D::PRESSURE, 1e-6),
    ("Torr", 133.3224, 0.0, D::PRESSURE, 1e-6),
    ("mmHg", 133.3224, 0.0, D::PRESSURE, 1e-6),
    ("inHg", 3386.389, 0.0, D::PRESSURE, 1e-6),
    ("inH2O", 249.0889, 0.0, D::PRESSURE, 1e-6),
    ("J", 1.0, 0.0, D::ENERGY, 0.0),
    ("cal", 4.184, 0.0, D::ENERGY, 1e-15),
    ("Btu", 1055.05585262, 0.0, D::ENERGY, 1e-15),
    ("MMBtu", 1.05505585262e9, 0.0, D::ENERGY, 1e-15),
    ("Wh", 3600.0, 0.0, D::ENERGY, 1e-15),
    ("W", 1.0, 0.0, D::POWER, 0.0),
    ("hp", 745.69987158, 0.0, D::POWER, 1e-11),
    ("N", 1.0, 0.0, D::FORCE, 0.0),
    ("lbf", 4.4482216152605, 0.0, D::FORCE, 1e-15),
];

#[test]
fn every_table_unit_has_a_hand_written_factor() {
    for u in units() {
        assert!(EXPECTED.iter().any(|e| e.0 == u.symbol), "no expected factor for `{}`", u.symbol);
    }
    for e in EXPECTED {
        assert!(units().iter().any(|u| u.symbol == e.0), "`{}` is not in the table", e.0);
    }
}

#[test]
fn one_unit_and_zero_units_in_si() {
    for &(symbol, one, zero, dim, rel) in EXPECTED {
        let q = parse_quantity(&format!("1 {symbol}")).unwrap();
        assert_eq!(q.dim, dim, "{symbol}");
        let got = q.value_si;
        assert!(abs_diff_eq!(got, one, epsilon = rel * one.abs()), "1 {symbol}: got {got:e}, expected {one:e}");
        let q = parse_quantity(&format!("0 {symbol}")).unwrap();
        let got = q.value_si;
        assert!(abs_diff_eq!(got, zero, epsilon = rel * zero.abs()), "0 {symbol}: got {got:e}, expected {zero:e}");
    }
}

#[test]
fn table_rows_agree_with_expected() {
    for u in units() {
        let &(_, one, zero, dim, rel) = EXPECTED.iter().find(|e| e.0 == u.symbol).unwrap();
        assert_eq!(u.dim, dim, "{}", u.symbol);
        assert!(abs_diff_eq!(u.offset, zero, epsilon = rel * zero.abs()), "{}: offset {:e}", u.symbol, u.offset);
        let got = u.factor + u.offset;
        assert!(
            abs_diff_eq!(got, one, epsilon = rel.max(1e-15) * one.abs()),
            "{}: got {got:e}, expected {one:e}",
            u.symbol
        );
        let affine = !matches!(u.kind, UnitKind::Linear);
        assert_eq!(affine, u.offset != 0.0, "{}", u.symbol);
        assert!(!(affine && u.prefixable), "{}", u.symbol);
    }
}

#[test]
fn si_prefixes() {
    let cases: &[(&str, f64, D)] = &[
        ("kmol", 1e3, D::AMOUNT),
        ("mmol", 1e-3, D::AMOUNT),
        ("µmol", 1e-6, D::AMOUNT),
        ("umol", 1e-6, D::AMOUNT),
        ("kg", 1.0, D::MASS),
        ("mg", 1e-6, D::MASS),
        ("Mg", 1e3, D::MASS),
        ("km", 1e3, D::LENGTH),
        ("cm", 1e-2, D::LENGTH),
        ("mm", 1e-3, D::LENGTH),
        ("µm", 1e-6, D::LENGTH),
        ("nm", 1e-9, D::LENGTH),
        ("dam", 10.0, D::LENGTH),
        ("ms", 1e-3, D::TIME),
        ("ks", 1e3, D::TIME),
        ("kPa", 1e3, D::PRESSURE),
        ("MPa", 1e6, D::PRESSURE),
        ("hPa", 1e2, D::PRESSURE),
        ("mbar", 1e2, D::PRESSURE),
        ("kJ", 1e3, D::ENERGY),
        ("MJ", 1e6, D::ENERGY),
        ("GJ", 1e9, D::ENERGY),
        ("kcal", 4184.0, D::ENERGY),
        ("kWh", 3.6e6, D::ENERGY),
        ("kW", 1e3, D::POWER),
        ("MW", 1e6, D::POWER),
        ("mW", 1e-3, D::POWER),
        ("kN", 1e3, D::FORCE),
        ("mL", 1e-6, D::VOLUME),
        ("ml", 1e-6, D::VOLUME),
        ("dL", 1e-4, D::VOLUME),
        ("kL", 1.0, D::VOLUME),
        ("pmol", 1e-12, D::AMOUNT),
        ("Tmol", 1e12, D::AMOUNT),
    ];
    for &(symbol, factor, dim) in cases {
        let q = parse_quantity(&format!("1 {symbol}")).unwrap();
        assert_eq!(q.dim, dim, "{symbol}");
        let got = q.value_si;
        assert!(abs_diff_eq!(got, factor, epsilon = 1e-15 * factor), "{symbol}: got {got:e}, expected {factor:e}");
    }
}

#[test]
fn prefixes_only_on_prefixable_units() {
    for s in ["kft", "klb", "kmin", "kK", "kdegC", "MBtu", "kpsi", "katm", "mhp", "ktonne", "kgal"] {
        assert!(parse_quantity(&format!("1 {s}")).is_err(), "{s} should not parse");
    }
}
