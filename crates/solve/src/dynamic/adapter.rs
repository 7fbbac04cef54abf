//! The plant as a [`DaeSystem`] at time-varying inputs, with the quadratures of stream component
//! flows appended: `dq_{s,c}/dt = F_s z_{s,c}` for every integrated stream `s` and component `c`.
//!
//! The state vector is `[plant variables | q_{s₀,·} | q_{s₁,·} | …]`. The integrated streams are the
//! scenario's `totals` (recorded) and then the boundary streams (outlets of `feed` units, inlets of
//! `product` units) not among them, which the conservation check needs whether recorded or not.

use std::ops::Range;

use plantwide_flowsheet::Plant;

use super::conservation;
use super::waveform::{Waveform, values_at};
use crate::dae::DaeSystem;
use crate::{PlantSystem, System};

/// The streams integrated as quadratures.
#[derive(Debug, Clone)]
pub(super) struct Quadratures {
    /// The scenario's totals, then the boundary streams not among them.
    pub(super) streams: Vec<usize>,
    /// Boundary streams: (index into `streams`, +1 feed outlet / −1 product inlet).
    pub(super) boundary: Vec<(usize, f64)>,
    /// How many of `streams` are the scenario's (recorded) totals.
    n_recorded: usize,
}

impl Quadratures {
    /// The scenario's `totals` (stream indices), then the boundary streams of `plant` not among
    /// them.
    pub(super) fn new(plant: &Plant, totals: &[usize]) -> Quadratures {
        let mut streams = totals.to_vec();
        let mut boundary = Vec::new();
        for (s, sign) in conservation::boundary_streams(plant) {
            let k = streams.iter().position(|&q| q == s).unwrap_or_else(|| {
                streams.push(s);
                streams.len() - 1
            });
            boundary.push((k, sign));
        }
        Quadratures { streams, boundary, n_recorded: totals.len() }
    }

    /// Length of the state vector: plant variables, then one quadrature per stream and component.
    pub(super) fn n_state(&self, plant: &Plant) -> usize {
        plant.n_vars() + self.streams.len() * plant.components().len()
    }

    /// Paths of the state vector: plant variables, then `<stream>.total[<component>]` for the
    /// recorded totals and `<stream>.boundary_total[<component>]` for the rest.
    pub(super) fn state_paths(&self, plant: &Plant) -> Vec<String> {
        let mut p: Vec<String> = plant.vars().iter().map(|v| v.path.clone()).collect();
        for (k, &s) in self.streams.iter().enumerate() {
            let kind = if k < self.n_recorded { "total" } else { "boundary_total" };
            let name = &plant.streams()[s].name;
            p.extend(plant.components().iter().map(|c| format!("{name}.{kind}[{c}]")));
        }
        p
    }

    /// The component amounts [mol] the boundary streams brought in (`fed`) and took out
    /// (`removed`) between the states `x0` and `x1` (differences of their quadratures); `n_plant`
    /// plant variables, `nc` components.
    pub(super) fn fed_and_removed(&self, n_plant: usize, nc: usize, x0: &[f64], x1: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let (mut fed, mut removed) = (vec![0.0; nc], vec![0.0; nc]);
        for &(k, sign) in &self.boundary {
            let side = if sign > 0.0 { &mut fed } else { &mut removed };
            let q = n_plant + k * nc..n_plant + (k + 1) * nc;
            side.iter_mut().zip(x1[q.clone()].iter().zip(&x0[q])).for_each(|(v, (q1, q0))| *v += q1 - q0);
        }
        (fed, removed)
    }
}

/// The shape of a run's DAE, fixed for the run: the equations that carry a time derivative
/// (the plant's, then one per quadrature) and the flow and composition variables of each
/// integrated stream.
#[derive(Debug, Clone)]
pub(super) struct DaeShape {
    mass: Vec<(usize, usize)>,
    /// Whether each plant variable is differential (carries a mass entry).
    differential: Vec<bool>,
    /// Per integrated stream: its flow variable and its composition variables.
    flows: Vec<(usize, Range<usize>)>,
    n_plant: usize,
    nc: usize,
}

impl DaeShape {
    /// The shape of `plant` with the component flows of `streams` integrated.
    pub(super) fn new(plant: &Plant, streams: &[usize]) -> DaeShape {
        let n_plant = plant.n_vars();
        let nc = plant.components().len();
        let mut mass = PlantSystem::new(plant, &[]).mass();
        let flows: Vec<(usize, Range<usize>)> =
            streams.iter().map(|&s| (plant.stream_flow_var(s), plant.stream_composition_vars(s))).collect();
        let mut differential = vec![false; n_plant];
        mass.iter().for_each(|&(_, j)| differential[j] = true);
        mass.extend((n_plant..n_plant + flows.len() * nc).map(|k| (k, k)));
        DaeShape { mass, differential, flows, n_plant, nc }
    }
}

thread_local! {
    /// The inputs `u(t)` of [`PlantDae::residual`], one buffer per thread (a residual per Newton
    /// iteration; its allocation was a measurable share of a run).
    static INPUTS: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// The plant at time-varying inputs, with quadratures of stream component flows appended.
pub(super) struct PlantDae<'a> {
    plant: &'a Plant,
    waves: &'a [Waveform],
    shape: &'a DaeShape,
}

impl<'a> PlantDae<'a> {
    /// The plant of shape `shape` at inputs `waves(t)`.
    pub(super) fn new(plant: &'a Plant, waves: &'a [Waveform], shape: &'a DaeShape) -> PlantDae<'a> {
        PlantDae { plant, waves, shape }
    }
}

impl DaeSystem for PlantDae<'_> {
    fn n(&self) -> usize {
        self.shape.n_plant + self.shape.flows.len() * self.shape.nc
    }
    fn residual(&self, t: f64, x: &[f64], r: &mut [f64]) {
        let np = self.shape.n_plant;
        INPUTS.with_borrow_mut(|u| {
            u.clear();
            u.extend(self.waves.iter().map(|w| w.at(t)));
            self.plant.residual(&x[..np], u, t, &mut r[..np]);
        });
        for (k, (f, z)) in self.shape.flows.iter().enumerate() {
            for (c, zc) in z.clone().enumerate() {
                r[np + k * self.shape.nc + c] = x[*f] * x[zc];
            }
        }
    }
    fn jacobian(&self, t: f64, x: &[f64], r: &mut [f64], jac: &mut Vec<(usize, usize, f64)>) {
        let np = self.shape.n_plant;
        let mut ju = Vec::new();
        self.plant.jacobian(&x[..np], &values_at(self.waves, t), t, &mut r[..np], jac, &mut ju);
        for (k, (f, z)) in self.shape.flows.iter().enumerate() {
            for (c, zc) in z.clone().enumerate() {
                let row = np + k * self.shape.nc + c;
                r[row] = x[*f] * x[zc];
                jac.push((row, *f, x[zc]));
                jac.push((row, zc, x[*f]));
            }
        }
    }
    fn mass(&self) -> &[(usize, usize)] {
        &self.shape.mass
    }
    fn nominal(&self, i: usize) -> f64 {
        if i < self.shape.n_plant { self.plant.vars()[i].spec.nominal } else { 1.0 }
    }
    fn bounds(&self, i: usize) -> (f64, f64) {
        if i < self.shape.n_plant {
            let s = &self.plant.vars()[i].spec;
            (s.lower, s.upper)
        } else {
            (f64::NEG_INFINITY, f64::INFINITY)
        }
    }
    fn error_controlled(&self, i: usize) -> bool {
        self.shape.differential.get(i).copied().unwrap_or(false)
    }
    fn quadrature(&self, i: usize) -> bool {
        i >= self.shape.n_plant
    }
}
