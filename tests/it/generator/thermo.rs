//! Property look-ups the generator's designs need, from the engine's own component library through
//! the library API (a one-feed plant loaded from text hands back its thermodynamic package): bubble
//! temperatures, relative volatilities, latent heats, liquid molar volumes.

use plantwide::flowsheet::{Override, load_str_with};
use plantwide::thermo::ThermoPackage;

use super::doc::{J, obj};

/// A binary from the component library, the VLE model that suits it and a pressure range
/// [atm] at which its condenser runs on cooling water.
pub struct Pair {
    /// The lighter component.
    pub light: &'static str,
    /// The heavier component.
    pub heavy: &'static str,
    /// `ideal` (Raoult) or `nrtl`.
    pub vle: &'static str,
    /// Top pressure range [atm].
    pub p_atm: (f64, f64),
}

/// The binaries a rigorous column is drawn from.
pub const PAIRS: &[Pair] = &[
    Pair { light: "benzene", heavy: "toluene", vle: "ideal", p_atm: (1.0, 1.6) },
    Pair { light: "methanol", heavy: "water", vle: "nrtl", p_atm: (1.0, 1.3) },
    Pair { light: "propane", heavy: "n-butane", vle: "ideal", p_atm: (12.0, 16.0) },
    Pair { light: "n-hexane", heavy: "n-heptane", vle: "ideal", p_atm: (1.0, 1.3) },
    Pair { light: "toluene", heavy: "o-xylene", vle: "ideal", p_atm: (1.0, 1.3) },
    Pair { light: "isobutane", heavy: "n-butane", vle: "ideal", p_atm: (6.0, 8.0) },
    Pair { light: "cyclohexane", heavy: "n-heptane", vle: "ideal", p_atm: (1.0, 1.3) },
];

/// The thermodynamic package of `components` (the file's `components` array) under `vle`.
pub fn package(components: &J, vle: &str) -> ThermoPackage {
    let J::A(list) = components else { panic!("generator: components must be an array") };
    let name = |c: &J| match c {
        J::S(s) => s.clone(),
        c => match c.get("name") {
            Some(J::S(s)) => s.clone(),
            _ => panic!("generator: a component without a name"),
        },
    };
    let z = J::O(list.iter().enumerate().map(|(i, c)| (name(c), J::N(if i == 0 { 1.0 } else { 0.0 }))).collect());
    let doc = obj([
        ("format_version", J::I(1)),
        ("name", "thermo probe".into()),
        ("components", components.clone()),
        ("thermo", obj([("vle", vle.into())])),
        (
            "units",
            obj([
                (
                    "src",
                    obj([
                        ("type", "feed".into()),
                        ("F", J::N(1.0)),
                        ("T", J::N(300.0)),
                        ("P", J::N(101325.0)),
                        ("z", z),
                    ]),
                ),
                ("sink", obj([("type", "product".into())])),
            ]),
        ),
        ("streams", obj([("s", obj([("from", "src".into()), ("to", "sink".into())]))])),
    ]);
    let plant = load_str_with(&doc.render(), "generator-thermo-probe", &[] as &[Override])
        .unwrap_or_else(|e| panic!("generator: the component section does not load: {e}"));
    plant.thermo().clone()
}

/// Bubble temperature [K] of liquid `x` at `p` [Pa].
pub fn bubble_t(pkg: &ThermoPackage, p: f64, x: &[f64]) -> f64 {
    pkg.bubble_t(p, x).unwrap_or_else(|e| panic!("generator: bubble point of {x:?} at {p} Pa: {e}")).t
}

/// Dew temperature [K] of vapour `y` at `p` [Pa].
pub fn dew_t(pkg: &ThermoPackage, p: f64, y: &[f64]) -> f64 {
    pkg.dew_t(p, y).unwrap_or_else(|e| panic!("generator: dew point of {y:?} at {p} Pa: {e}")).t
}

/// Relative volatility `K_0 / K_1` of a binary liquid `x` at its bubble point at `p`.
pub fn alpha(pkg: &ThermoPackage, p: f64, x: &[f64]) -> f64 {
    let t = bubble_t(pkg, p, x);
    let mut k = vec![0.0; x.len()];
    pkg.k_values(t, p, x, &mut k);
    k[0] / k[1]
}

/// Latent heat [J/mol] of liquid `x` at its bubble point at `p` (vapour of the same composition).
pub fn latent_heat(pkg: &ThermoPackage, p: f64, x: &[f64]) -> f64 {
    let t = bubble_t(pkg, p, x);
    pkg.h_vap(t, x) - pkg.h_liq(t, x)
}

/// Liquid molar volume [m³/mol] of `x` at its bubble point at `p`.
pub fn molar_volume(pkg: &ThermoPackage, p: f64, x: &[f64]) -> f64 {
    pkg.v_liq(bubble_t(pkg, p, x), x)
}

/// Vapour fraction of feed `z` flashed at `t` [K], `p` [Pa], and the liquid's composition.
pub fn flash(pkg: &ThermoPackage, t: f64, p: f64, z: &[f64]) -> (f64, Vec<f64>) {
    let r = pkg.flash_tp(t, p, z).unwrap_or_else(|e| panic!("generator: flash of {z:?} at {t} K, {p} Pa: {e}"));
    (r.beta, r.x)
}
