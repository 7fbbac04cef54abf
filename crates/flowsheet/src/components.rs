//! Resolving the flowsheet's components and thermodynamic model into a [`ThermoPackage`].

use plantwide_thermo::{Component, Library, ThermoPackage, VleModel};
use plantwide_units::{Dimension, QuantityValue};

use plantwide_model::limits::{Limits, clip};

use crate::error::{Diagnostic, did_you_mean};
use crate::spec::{ComponentSpec, HypotheticalSpec, ThermoSpec, VleChoice};

/// Component names and the thermodynamic package, or diagnostics.
pub fn thermo_package(
    components: &[ComponentSpec],
    thermo: &ThermoSpec,
    diags: &mut Vec<Diagnostic>,
) -> Option<(Vec<String>, ThermoPackage, Vec<Option<f64>>)> {
    let library = match Library::builtin() {
        Ok(l) => l,
        Err(e) => {
            diags.push(Diagnostic::new("components", e.to_string()));
            return None;
        }
    };
    let n0 = diags.len();
    if let Some(msg) = Limits::get().components().check(components.len(), "the number of components") {
        diags.push(Diagnostic::new("components", msg));
        return None;
    }
    let (comps, alphas) = resolve_components(components, &library, diags);
    let names: Vec<String> = comps.iter().map(|c| c.name.clone()).collect();
    for (i, n) in names.iter().enumerate() {
        if names[..i].contains(n) {
            diags.push(Diagnostic::new(format!("components[{i}]"), format!("component `{n}` is listed twice")));
        }
    }
    if names.is_empty() && diags.len() == n0 {
        diags.push(Diagnostic::new("components", "a flowsheet needs at least one component"));
    }
    if diags.len() > n0 {
        return None;
    }
    let vle = vle_model(thermo, &names, &alphas, &library, diags);
    if diags.len() > n0 {
        return None;
    }
    Some((names, ThermoPackage { components: comps, vle }, alphas))
}

/// Every listed component (from the library, hypothetical or inline) and its relative volatility
/// where it is hypothetical.
fn resolve_components(
    components: &[ComponentSpec],
    library: &Library,
    diags: &mut Vec<Diagnostic>,
) -> (Vec<Component>, Vec<Option<f64>>) {
    let mut comps = Vec::new();
    let mut alphas = Vec::new();
    let limits = Limits::get();
    for (i, spec) in components.iter().enumerate() {
        let path = format!("components[{i}]");
        let name = spec.name();
        if let Some(msg) = limits.name_len().check(name.chars().count(), "the length of this component name") {
            diags.push(Diagnostic::new(path, format!("`{}`: {msg}", clip(name))));
            continue;
        }
        match spec {
            ComponentSpec::Library(name) => match library.component(name) {
                Ok(c) => {
                    comps.push(c.clone());
                    alphas.push(None);
                }
                Err(_) => diags.push(Diagnostic::new(
                    path,
                    format!(
                        "unknown component `{}`{}; `plantwide components` lists the library, or define it inline with \"hypothetical\"",
                        clip(name),
                        did_you_mean(name, library.components.iter().map(|c| c.name.as_str()))
                    ),
                )),
            },
            ComponentSpec::Hypothetical { name, hypothetical: h } => {
                comps.push(hypothetical(&path, name, h, diags));
                alphas.push(Some(h.alpha));
            }
            ComponentSpec::Inline(c) => {
                check_inline(&path, c, diags);
                comps.push((**c).clone());
                alphas.push(None);
            }
        }
    }
    (comps, alphas)
}

/// A hypothetical component from its data, each positive and below a plausibility bound (SI):
/// molar mass ≤ 10 kg/mol, heat of vaporization ≤ 10 MJ/mol, heat capacity ≤ 100 kJ/(mol·K),
/// liquid volume ≤ 1 m³/mol; a value out of range is reported and replaced by its default.
fn hypothetical(path: &str, name: &str, h: &HypotheticalSpec, diags: &mut Vec<Diagnostic>) -> Component {
    let mut q = |field: &str, v: Option<&QuantityValue>, dim: Dimension, default: f64, max: f64| -> f64 {
        let Some(v) = v else { return default };
        match v.to_si(dim) {
            Ok(x) if x.is_finite() && x > 0.0 && x <= max => x,
            Ok(x) if x > max => {
                diags.push(Diagnostic::new(
                    format!("{path}.hypothetical.{field}"),
                    format!("{x:e} {dim} is beyond the plausible {max:e} {dim}"),
                ));
                default
            }
            Ok(x) => {
                diags.push(Diagnostic::new(
                    format!("{path}.hypothetical.{field}"),
                    format!("must be positive (got {x})"),
                ));
                default
            }
            Err(e) => {
                diags.push(Diagnostic::new(format!("{path}.hypothetical.{field}"), e.to_string()));
                default
            }
        }
    };
    let mw = q("mw", Some(&h.mw), Dimension::MOLAR_MASS, 0.05, 10.0);
    let hvap = q("hvap", Some(&h.hvap), Dimension::MOLAR_ENERGY, 3e4, 1e7);
    let t_ref = q("t_ref", h.t_ref.as_ref(), Dimension::TEMPERATURE, 350.0, 5000.0);
    let cp = q("cp", h.cp.as_ref(), Dimension::HEAT_CAPACITY_MOLAR, 150.0, 1e5);
    let v = q("v_liq", h.v_liq.as_ref(), Dimension::MOLAR_VOLUME, 1e-4, 1.0);
    if !(h.alpha.is_finite() && h.alpha > 0.0 && h.alpha <= 1e6) {
        diags.push(Diagnostic::new(
            format!("{path}.hypothetical.alpha"),
            format!("relative volatility must be positive (got {})", h.alpha),
        ));
    }
    Component::hypothetical(name, h.alpha, mw, hvap, t_ref, cp, v)
}

/// The scalar data of an inline component within physical ranges (SI); the correlations are
/// checked where they are evaluated.
fn check_inline(path: &str, c: &Component, diags: &mut Vec<Diagnostic>) {
    for (field, v, lo, hi) in [
        ("mw", Some(c.mw), 1e-3, 10.0),
        ("tb", Some(c.tb), 1.0, 5000.0),
        ("tc", c.tc, 1.0, 1e4),
        ("pc", c.pc, 1.0, 1e10),
        ("omega", c.omega, -1.0, 5.0),
    ] {
        if let Some(v) = v.filter(|v| !(v.is_finite() && *v >= lo && *v <= hi)) {
            diags.push(Diagnostic::new(
                format!("{path}.{field}"),
                format!("{v:e} is outside the physical range {lo:e} … {hi:e} (SI)"),
            ));
        }
    }
}

/// The vapour-liquid equilibrium model of `thermo` for components `names` (`alphas`: the
/// hypothetical components' relative volatilities).
fn vle_model(
    thermo: &ThermoSpec,
    names: &[String],
    alphas: &[Option<f64>],
    library: &Library,
    diags: &mut Vec<Diagnostic>,
) -> VleModel {
    match thermo.vle {
        VleChoice::Ideal => VleModel::Ideal,
        VleChoice::ConstantAlpha => VleModel::ConstantAlpha { alpha: constant_alpha(thermo, names, alphas, diags) },
        VleChoice::Nrtl | VleChoice::Wilson => {
            let kind = if thermo.vle == VleChoice::Nrtl { "nrtl" } else { "wilson" };
            let refs: Vec<&str> = names.iter().map(String::as_str).collect();
            match library.activity_model(kind, &refs, &thermo.binary_parameters) {
                Ok(m) => VleModel::Activity(m),
                Err(e) => {
                    diags.push(Diagnostic::new("thermo.vle", e.to_string()));
                    VleModel::Ideal
                }
            }
        }
    }
}

/// The relative volatility of every component, from `thermo.alpha` or a hypothetical component's
/// own; every `thermo.alpha` entry must name a component.
fn constant_alpha(
    thermo: &ThermoSpec,
    names: &[String],
    alphas: &[Option<f64>],
    diags: &mut Vec<Diagnostic>,
) -> Vec<f64> {
    let mut alpha = Vec::new();
    for (i, name) in names.iter().enumerate() {
        let a = thermo.alpha.as_ref().and_then(|m| m.get(name).copied()).or(alphas[i]);
        match a {
            Some(a) if a.is_finite() && a > 0.0 => alpha.push(a),
            _ => diags.push(Diagnostic::new(
                format!("thermo.alpha.{name}"),
                "constant_alpha needs a positive relative volatility for every component (in thermo.alpha or as a hypothetical component's alpha)",
            )),
        }
    }
    if let Some(m) = &thermo.alpha {
        for k in m.keys().filter(|k| !names.contains(k)) {
            diags.push(Diagnostic::new(
                format!("thermo.alpha.{k}"),
                format!("`{k}` is not a component of this flowsheet"),
            ));
        }
    }
    alpha
}
