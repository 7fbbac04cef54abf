//! Design specifications: a plant variable held at a target by moving a free input, in the steady
//! state (the "design spec" of Aspen Plus, the "adjust" of DWSIM).
//!
//! A spec replaces its input's value by one equation, `x[var] − target = 0`, solved together with
//! the plant in the whole-plant Newton ([`plantwide_solve`]'s steady state): the input becomes an
//! unknown, so the degrees of freedom stay even (the `k`-th spec pairs with the `k`-th varied
//! input for the count; all are solved together, not one per loop). At steady state a PI
//! controller on the same input reaches the same point: its integral forces its error to zero.
//!
//! Specs define a design point, not a control structure: dynamics, linearization and the studies
//! see the plant with each varied input fixed at the value its spec found ([`Plant::fix_specs`]).

use std::sync::Arc;

use plantwide_units::QuantityValue;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::error::{Diagnostic, did_you_mean};
use crate::overrides::resolve_input;
use crate::path::VarPath;
use crate::plant::Plant;

/// A design specification as written in a flowsheet file's `specs` or by `--spec PATH=VALUE
/// --vary INPUT`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpecEntry {
    /// Variable held at `value`, by path (`"distillate.x[light]"`, `"column.T[5]"`).
    pub path: String,
    /// Its target: a number in the variable's SI unit or a string with units (`"0.995"`, `"350 K"`).
    pub value: QuantityValue,
    /// Free input moved to meet it: `unit.input`, an alias or `stream.X` (`"column.reflux"`).
    pub vary: String,
}

/// A design specification resolved against an assembled plant.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignSpec {
    /// Path of the held variable, as written.
    pub path: String,
    /// Its global index.
    pub var: usize,
    /// Its target (SI).
    pub target: f64,
    /// Path of the varied input (resolved: `unit.input`).
    pub vary: String,
    /// Its input index.
    pub input: usize,
    /// Where it was given: `specs[k]` in the file or `--spec` on the command line.
    pub origin: String,
}

impl DesignSpec {
    /// `path = target (SI) by vary`, for messages.
    pub fn label(&self) -> String {
        format!("`{} = {}` by `{}`", self.path, plantwide_model::limits::number(self.target), self.vary)
    }
}

/// Why a design specification cannot be set up.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{origin}: {why}")]
pub struct SpecError {
    /// `specs[k].path` (file) or `--spec PATH=VALUE` (command line).
    pub origin: String,
    /// What is wrong and what would fix it.
    pub why: String,
}

impl Plant {
    /// The design specifications the steady state must meet (empty once fixed).
    pub fn specs(&self) -> &[DesignSpec] {
        &self.specs
    }

    /// Add design specifications (from the command line): each is resolved and checked as a file's
    /// are, and kept in the description so that variants carry it.
    ///
    /// # Errors
    /// [`SpecError`] naming the first entry that does not resolve.
    pub fn add_specs(&mut self, entries: &[SpecEntry]) -> Result<(), SpecError> {
        for e in entries {
            let origin = format!("{}={} varying {}", e.path, quantity_text(&e.value), e.vary);
            let spec = resolve(self, e, &origin).map_err(|(_, why)| SpecError { origin: origin.clone(), why })?;
            self.specs.push(spec);
            Arc::make_mut(&mut self.spec).specs.push(e.clone());
        }
        Ok(())
    }

    /// The specs met: every varied input takes its value in `u` (SI, input order: a converged
    /// steady state's inputs) and the specs are dropped, from the plant and from its description,
    /// so that dynamics, analyses and variants see the plant at its design point.
    pub fn fix_specs(&mut self, u: &[f64]) {
        for s in std::mem::take(&mut self.specs) {
            self.inputs[s.input].value = u[s.input];
        }
        Arc::make_mut(&mut self.spec).specs.clear();
    }
}

impl Plant {
    /// The plant at the steady state its model predictive controllers drive it to: each one's
    /// CVs at their setpoints (`<mpc>.sp<k>`, SI), its MVs free (design specs `cv_k = sp_k`
    /// varying `<mpc>.mv<k>`, solved together). A DMC with a constant output-disturbance estimate
    /// is offset-free: once the plant settles with no constraint active, its predicted errors are
    /// zero, so a square controller with a nonsingular gain holds every CV on its setpoint —
    /// the steady state a PI loop's integral gives. In the DAE an MPC holds its MVs instead (its
    /// moves are discrete, made by the dynamic driver), so that steady-state studies with the
    /// control structure active (sensitivity) need this plant. Whether the MVs found lie within
    /// the controller's limits is for the caller to check.
    ///
    /// # Errors
    /// [`SpecError`] for a controller with more CVs than MVs or fewer (its steady state depends on
    /// its weights, or on the path it took), or whose setpoints do not resolve.
    pub fn with_mpc_at_setpoints(&self) -> Result<Plant, SpecError> {
        let mut held = self.clone();
        let mut entries = Vec::new();
        for (name, c) in &self.spec.controllers {
            let plantwide_model::registry::ControllerSpec::Mpc(cfg) = c else { continue };
            if cfg.cvs.len() != cfg.mvs.len() {
                return Err(SpecError {
                    origin: format!("controllers.{name}"),
                    why: format!(
                        "a model predictive controller with {} CVs and {} MVs has no steady state set by its \
                         setpoints alone (it depends on its weights, or on its path); give it as many CVs as MVs \
                         for steady-state studies",
                        cfg.cvs.len(),
                        cfg.mvs.len()
                    ),
                });
            }
            for (k, cv) in cfg.cvs.iter().enumerate() {
                let sp = VarPath::cv_setpoint(name, k);
                let sp = self.input(&sp).map(|i| self.inputs[i].value).ok_or_else(|| SpecError {
                    origin: format!("controllers.{name}.cvs[{k}]"),
                    why: format!("no input `{sp}`"),
                })?;
                entries.push(SpecEntry {
                    path: cv.pv.clone(),
                    value: QuantityValue::Number(sp),
                    vary: VarPath::mv(name, k).into(),
                });
            }
        }
        held.add_specs(&entries)?;
        Ok(held)
    }
}

fn quantity_text(v: &QuantityValue) -> String {
    match v {
        QuantityValue::Number(x) => x.to_string(),
        QuantityValue::Text(s) => s.clone(),
    }
}

/// The file's `specs`, resolved against the assembled plant; one diagnostic per problem.
pub(crate) fn resolve_file_specs(plant: &Plant) -> Result<Vec<DesignSpec>, Vec<Diagnostic>> {
    let mut out = Vec::new();
    let mut diags = Vec::new();
    for (k, e) in plant.spec.specs.iter().enumerate() {
        let origin = format!("specs[{k}]");
        match resolve_among(plant, &out, e, &origin) {
            Ok(s) => out.push(s),
            Err((field, why)) => diags.push(Diagnostic::new(format!("{origin}.{field}"), why)),
        }
    }
    if diags.is_empty() { Ok(out) } else { Err(diags) }
}

fn resolve(plant: &Plant, e: &SpecEntry, origin: &str) -> Result<DesignSpec, (&'static str, String)> {
    resolve_among(plant, &plant.specs, e, origin)
}

/// Resolve `e` given the specs already resolved (`earlier`); on failure, the field at fault and why.
fn resolve_among(
    plant: &Plant,
    earlier: &[DesignSpec],
    e: &SpecEntry,
    origin: &str,
) -> Result<DesignSpec, (&'static str, String)> {
    let var = plant.var(&e.path).ok_or_else(|| {
        let hint = did_you_mean(&e.path, plant.vars.iter().map(|v| v.path.as_str()));
        ("path", format!("no variable `{}`{hint}; the steady state lists every variable's path", e.path))
    })?;
    let info = &plant.vars[var].spec;
    let target = e.value.to_si(info.dim).map_err(|err| ("value", format!("{err} (the target of `{}`)", e.path)))?;
    if target < info.lower || target > info.upper {
        return Err((
            "value",
            format!(
                "{} lies outside the range of `{}` [{}, {}] (SI): no steady state can meet it",
                plantwide_model::limits::number(target),
                e.path,
                plantwide_model::limits::number(info.lower),
                plantwide_model::limits::number(info.upper)
            ),
        ));
    }
    let input = resolve_input(plant, &e.vary).ok_or_else(|| {
        let hint = did_you_mean(&e.vary, plant.inputs.iter().map(|i| i.path.as_str()));
        (
            "vary",
            format!(
                "no input `{}`{hint}; the inputs are listed by `plantwide check`",
                plantwide_model::limits::clip(&e.vary)
            ),
        )
    })?;
    let vary = plant.inputs[input].path.clone();
    if let Some(v) = plant.inputs[input].driven_by {
        let ctrl = &plant.blocks[plant.vars[v].block].name;
        return Err((
            "vary",
            format!(
                "`{vary}` is driven by controller `{ctrl}`: the controller and the spec would both set it; vary a free input or remove `{ctrl}`"
            ),
        ));
    }
    if let Some(s) = earlier.iter().find(|s| s.input == input) {
        return Err(("vary", format!("`{vary}` is already varied by the spec on `{}` ({})", s.path, s.origin)));
    }
    if let Some(s) = earlier.iter().find(|s| s.var == var) {
        return Err(("path", format!("`{}` is already held by {} ({})", e.path, s.label(), s.origin)));
    }
    Ok(DesignSpec { path: e.path.clone(), var, target, vary, input, origin: origin.to_string() })
}
