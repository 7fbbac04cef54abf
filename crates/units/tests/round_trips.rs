//! convert_from_si(parse(x)) = x, and named dimensions display as parseable SI units.

use approx::{abs_diff_eq, assert_abs_diff_eq};
use plantwide_units::{
    Dimension as D, Quantity, Unit, convert_from_si, convert_to_si, named_dimensions, parse_quantity, prefixes,
    unit_dimension, units,
};

const VALUES: [f64; 6] = [0.0, 1.0, -40.0, 80.0, 176.0, 1.234_567e5];

#[track_caller]
fn round_trip(value: f64, unit: &str) {
    let q = parse_quantity(&format!("{value} {unit}")).unwrap_or_else(|e| panic!("{e}"));
    let back = convert_from_si(q.value_si, unit).unwrap();
    let what = format!("{value} {unit} -> {} -> {back}", q.value_si);
    // Affine units subtract a large offset, so compare against the scale of the SI value.
    let tolerance = 1e-13 * q.value_si.abs().max(value.abs()).max(1.0);
    assert!((back - value).abs() <= tolerance, "{what}");
    let si = convert_to_si(value, unit).unwrap();
    assert!(abs_diff_eq!(si, q.value_si, epsilon = 1e-15 * q.value_si.abs()), "{what}: convert_to_si gives {si:e}");
    assert_eq!(q.in_unit(unit).unwrap(), back, "{what}");
}

#[test]
fn every_table_unit() {
    for u in units() {
        for v in VALUES {
            round_trip(v, u.symbol);
        }
    }
}

#[test]
fn every_prefix_on_every_prefixable_unit() {
    for u in units().iter().filter(|u| u.prefixable) {
        for p in prefixes() {
            let symbol = format!("{}{}", p.symbol, u.symbol);
            let unit = Unit::parse(&symbol).unwrap();
            let factor = p.factor * u.factor;
            assert!(
                abs_diff_eq!(unit.factor(), factor, epsilon = 1e-15 * factor),
                "{symbol}: {} vs {factor}",
                unit.factor()
            );
            round_trip(1.234_567e5, &symbol);
        }
    }
}

#[test]
fn compound_units() {
    let compounds = [
        "kmol/min",
        "lbmol/h",
        "kmol/min/kmol",
        "Btu/h",
        "MMBtu/h",
        "J/(mol*K)",
        "kJ/(kmol*degC)",
        "Btu/(lbmol*degF)",
        "kW/K",
        "kg/h",
        "m3/mol",
        "ft^3/min",
        "W/(m2*K)",
        "1/min",
        "s⁻¹",
        "gpm",
        "lb/ft3",
        "kcal/(kg*degC)",
    ];
    for unit in compounds {
        for v in VALUES {
            round_trip(v, unit);
        }
    }
}

#[test]
fn affine_display_conversions() {
    assert_abs_diff_eq!(convert_from_si(353.15, "degC").unwrap(), 80.0, epsilon = 1e-13 * 80.0);
    assert_abs_diff_eq!(convert_from_si(353.15, "degF").unwrap(), 176.0, epsilon = 1e-13 * 176.0);
    assert_abs_diff_eq!(convert_from_si(353.15, "degR").unwrap(), 635.67, epsilon = 1e-13 * 635.67);
    assert_abs_diff_eq!(convert_from_si(308_167.718_795_04, "psig").unwrap(), 30.0, epsilon = 1e-12 * 30.0);
    // 0 barg: absolute, in bar.
    assert_abs_diff_eq!(convert_from_si(101_325.0, "barg").unwrap(), 0.0, epsilon = 1e-12);
    // 250 kPag is 351.325 kPa absolute; 2.5 MPag is 2.601325 MPa absolute.
    assert_abs_diff_eq!(convert_from_si(351_325.0, "kPag").unwrap(), 250.0, epsilon = 1e-12 * 250.0);
    assert_abs_diff_eq!(convert_from_si(2_601_325.0, "MPag").unwrap(), 2.5, epsilon = 1e-12 * 2.5);
    // Standard gas flows: 1 kscmh is 10^3 m3/h of ideal gas at 0 degC and 1 atm, 22.41396954 L/mol
    // (CODATA 2018), so 12.393 mol/s; 1 MMSCFD is 10^6 scf/d at 379.48 scf per lb-mol (GPSA), so
    // 13.834 mol/s.
    let kscmh = 1e6 / 22.413_969_54 / 3600.0;
    assert_abs_diff_eq!(convert_from_si(kscmh, "kscmh").unwrap(), 1.0, epsilon = 1e-9);
    assert_abs_diff_eq!(convert_from_si(kscmh, "Nm3/h").unwrap(), 1e3, epsilon = 1e-6);
    let mmscfd = 1e6 / 379.48 * 453.592_37 / 86_400.0;
    assert_abs_diff_eq!(convert_from_si(mmscfd, "MMSCFD").unwrap(), 1.0, epsilon = 3e-5);
    assert_abs_diff_eq!(convert_from_si(12.599_788_055_555_556, "lbmol/h").unwrap(), 100.0, epsilon = 1e-14 * 100.0);
    assert_abs_diff_eq!(convert_from_si(1000.0 / 60.0, "kmol/min").unwrap(), 1.0, epsilon = 1e-15);
    assert!(convert_from_si(f64::NAN, "K").unwrap().is_nan(), "NaN passes through");
    let u = Unit::parse_difference("degC").unwrap();
    assert!(!u.is_affine());
    assert_eq!(u.from_si(10.0), 10.0, "difference");
}

#[test]
fn named_dimensions_display_as_parseable_si_units() {
    for n in named_dimensions() {
        assert_eq!(n.dim.to_string(), n.symbol);
        let unit = Unit::parse(n.symbol).unwrap_or_else(|e| panic!("{}: {e}", n.symbol));
        assert_eq!(unit.dimension(), n.dim, "{}", n.symbol);
        assert!(abs_diff_eq!(unit.factor(), 1.0, epsilon = 1e-15), "{}: factor {}", n.symbol, unit.factor());
        assert_eq!(unit_dimension(n.symbol).unwrap(), n.dim);
        assert_eq!(n.dim.name(), n.name);
        assert!(!n.examples.is_empty(), "{}", n.name);
        for example in n.examples {
            let q = parse_quantity(example).unwrap_or_else(|e| panic!("{example}: {e}"));
            assert_eq!(q.dim, n.dim, "example {example} of {}", n.name);
        }
    }
}

#[test]
fn generic_dimensions_display_as_parseable_units() {
    for dim in [D::new(1, 1, -2, 0, -1), D::new(0, 0, -2, 0, 0), D::new(2, -1, 0, 1, -3), D::new(0, 4, 0, 0, 0)] {
        let shown = dim.to_string();
        let unit = Unit::parse(&shown).unwrap_or_else(|e| panic!("{shown}: {e}"));
        assert_eq!(unit.dimension(), dim, "{shown}");
        assert!(abs_diff_eq!(unit.factor(), 1.0, epsilon = 1e-15), "{shown}: factor {}", unit.factor());
        let q = Quantity::new(2.0, dim);
        assert_eq!(parse_quantity(&q.to_string()).unwrap(), q);
    }
}
