//! The steady-state system with the plant's design specifications ([`plantwide_flowsheet::design`]).
//!
//! Unknowns `z = [x; v]`: the plant's variables, then the value `v_k` of the input varied by
//! spec `k`. Equations: the plant's `f(x, u(v)) = 0`, where `u(v)` is the plant's input vector
//! with each varied input replaced by its `v_k`, then one row per spec, `x[var_k] − target_k = 0`.
//! The Jacobian is `[∂f/∂x  ∂f/∂u·E; e_var^T  0]` (`E` selects the varied inputs' columns of
//! `∂f/∂u`, which the plant's assembly already gives exactly). Without specs this is the plant's
//! own system: every steady-state routine goes through it.

use plantwide_flowsheet::Plant;
use plantwide_model::VarKind;

use crate::System;

pub(crate) mod standing;

/// The plant at inputs `u` with its design specifications, as one square nonlinear system.
pub struct SteadySystem<'a> {
    plant: &'a Plant,
    u: Vec<f64>,
    mass: Vec<(usize, usize)>,
    /// Jacobians without the controllers' output limits (the degrees-of-freedom probe).
    relaxed: bool,
}

impl<'a> SteadySystem<'a> {
    /// The system at inputs `u` (the varied inputs' entries are the start of their unknowns).
    pub fn new(plant: &'a Plant, u: &[f64]) -> SteadySystem<'a> {
        let mut mass = Vec::new();
        for b in plant.blocks() {
            for k in 0..b.layout.n_own().min(b.n_eq) {
                if plant.vars()[b.own_offset + k].spec.kind == VarKind::Differential {
                    mass.push((b.eq_offset + k, b.own_offset + k));
                }
            }
        }
        SteadySystem { plant, u: u.to_vec(), mass, relaxed: false }
    }

    /// The same system with the controllers' output limits removed.
    pub(crate) fn relaxed(mut self) -> SteadySystem<'a> {
        self.relaxed = true;
        self
    }

    /// The specification of unknown `j` when it is one of the plant's variables (not a varied
    /// input).
    pub(crate) fn plant_var(&self, j: usize) -> Option<&plantwide_model::VarSpec> {
        self.plant.vars().get(j).map(|v| &v.spec)
    }

    /// The unknowns at plant state `x` and this system's inputs.
    pub fn unknowns(&self, x: &[f64]) -> Vec<f64> {
        let mut z = x.to_vec();
        z.extend(self.plant.specs().iter().map(|s| self.u[s.input]));
        z
    }

    /// The plant state and the full input vector at unknowns `z`.
    pub fn split(&self, z: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let n = self.plant.n_vars();
        (z[..n].to_vec(), self.inputs_at(z))
    }

    fn inputs_at(&self, z: &[f64]) -> Vec<f64> {
        let n = self.plant.n_vars();
        let mut u = self.u.clone();
        for (k, s) in self.plant.specs().iter().enumerate() {
            u[s.input] = z[n + k];
        }
        u
    }

    /// Spec `k`'s residual `x[var] − target` at `z`.
    pub fn spec_residual(&self, z: &[f64], k: usize) -> f64 {
        let s = &self.plant.specs()[k];
        z[s.var] - s.target
    }
}

impl System for SteadySystem<'_> {
    fn n(&self) -> usize {
        self.plant.n_vars() + self.plant.specs().len()
    }
    fn residual(&self, z: &[f64], r: &mut [f64]) {
        let n = self.plant.n_vars();
        self.plant.residual(&z[..n], &self.inputs_at(z), 0.0, &mut r[..n]);
        for k in 0..self.plant.specs().len() {
            r[n + k] = self.spec_residual(z, k);
        }
    }
    fn jacobian(&self, z: &[f64], r: &mut [f64], jac: &mut Vec<(usize, usize, f64)>) {
        let n = self.plant.n_vars();
        let u = self.inputs_at(z);
        let mut ju = Vec::new();
        if self.relaxed {
            self.plant.jacobian_without_limits(&z[..n], &u, &mut r[..n], jac, &mut ju);
        } else {
            self.plant.jacobian(&z[..n], &u, 0.0, &mut r[..n], jac, &mut ju);
        }
        let specs = self.plant.specs();
        if specs.is_empty() {
            return;
        }
        let mut column = vec![None; u.len()];
        specs.iter().enumerate().for_each(|(k, s)| column[s.input] = Some(n + k));
        jac.extend(ju.iter().filter_map(|&(i, j, v)| column[j].map(|c| (i, c, v))));
        for (k, s) in specs.iter().enumerate() {
            r[n + k] = self.spec_residual(z, k);
            jac.push((n + k, s.var, 1.0));
        }
    }
    fn nominal(&self, i: usize) -> f64 {
        let n = self.plant.n_vars();
        if i < n {
            return self.plant.vars()[i].spec.nominal;
        }
        let v = self.u[self.plant.specs()[i - n].input].abs();
        if v > 0.0 && v.is_finite() { v } else { 1.0 }
    }
    fn size(&self, z: &[f64], i: usize) -> f64 {
        crate::steady::own_size(self, z, i, crate::steady::STOP_FLOOR)
    }
    fn bounds(&self, i: usize) -> (f64, f64) {
        let n = self.plant.n_vars();
        if i < n {
            let s = &self.plant.vars()[i].spec;
            return (s.lower, s.upper);
        }
        input_bounds(self.plant, self.plant.specs()[i - n].input)
    }
    fn mass(&self) -> Vec<(usize, usize)> {
        self.mass.clone()
    }
}

/// The physical range of input `i` ([`plantwide_model::limits::input_range`]): where a varied
/// input may go.
fn input_bounds(plant: &Plant, i: usize) -> (f64, f64) {
    let info = &plant.inputs()[i];
    let block = &plant.blocks()[info.block].name;
    let name = info.path.strip_prefix(&format!("{block}.")).unwrap_or(&info.path);
    plantwide_model::limits::input_range(name, info.dim)
}

/// Path of unknown `j` of [`SteadySystem`]: a variable's path, or the varied input's.
pub(crate) fn unknown_path(plant: &Plant, j: usize) -> String {
    let n = plant.n_vars();
    match plant.specs().get(j.wrapping_sub(n)) {
        Some(s) if j >= n => format!("{} (varied by the spec on `{}`)", s.vary, s.path),
        _ => plant.vars()[j].path.clone(),
    }
}

/// Name of equation `eq` of [`SteadySystem`]: the plant's name, or the spec's.
pub fn equation_name(plant: &Plant, eq: usize) -> String {
    let n = plant.n_eqs();
    match plant.specs().get(eq.wrapping_sub(n)) {
        Some(s) if eq >= n => format!("design spec {} ({})", s.label(), s.origin),
        _ => plant.equation_name(eq),
    }
}
