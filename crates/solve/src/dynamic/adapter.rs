//! The plant as a [`DaeSystem`] at time-varying inputs, with the quadratures of stream component
//! flows appended: `dq_{s,c}/dt = F_s z_{s,c}` for every integrated stream `s` and component `c`.
//!
//! The state vector is `[plant variables | q_{s₀,·} | q_{s₁,·} | …]`. The integrated streams are the
//! scenario's `totals` (recorded) and then the boundary streams (outlets of `feed` units, inlets of
//! `product` units) not among them, which the conservation check needs whether recorded or not.

use std::ops::Range;

use plantwide_flowsheet::{ExplicitPlan, Plant, VarPath};

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
            p.extend(plant.components().iter().map(|c| String::from(VarPath::new(name, kind).index(c))));
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
/// (the plant's, then one per quadrature), the flow and composition variables of each
/// integrated stream, and the explicit variables the integrator eliminates.
#[derive(Debug, Clone)]
pub(super) struct DaeShape {
    mass: Vec<(usize, usize)>,
    /// Whether each plant variable is differential (carries a mass entry).
    differential: Vec<bool>,
    /// Per integrated stream: its flow variable and its composition variables.
    flows: Vec<(usize, Range<usize>)>,
    n_plant: usize,
    nc: usize,
    explicit: ExplicitPlan,
}

impl DaeShape {
    /// The shape of `plant` with the component flows of `streams` integrated. With `reads`, the
    /// plant variables the caller reads during the run besides the integrated flows, every
    /// other variable nothing integrated depends on is output-only
    /// ([`plantwide_flowsheet::ExplicitPlan::outputs`]); `None`: the caller may read anything,
    /// nothing is output-only.
    pub(super) fn new(plant: &Plant, streams: &[usize], reads: Option<&[usize]>) -> DaeShape {
        let n_plant = plant.n_vars();
        let nc = plant.components().len();
        let mut mass = PlantSystem::new(plant, &[]).mass();
        let flows: Vec<(usize, Range<usize>)> =
            streams.iter().map(|&s| (plant.stream_flow_var(s), plant.stream_composition_vars(s))).collect();
        let mut differential = vec![false; n_plant];
        mass.iter().for_each(|&(_, j)| differential[j] = true);
        mass.extend((n_plant..n_plant + flows.len() * nc).map(|k| (k, k)));
        let explicit = match reads {
            Some(reads) => {
                let mut roots = reads.to_vec();
                flows.iter().for_each(|(f, z)| roots.extend(std::iter::once(*f).chain(z.clone())));
                plant.explicit_plan_for(&roots)
            }
            None => plant.explicit_plan(),
        };
        DaeShape { mass, differential, flows, n_plant, nc, explicit }
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

impl PlantDae<'_> {
    /// `f(t, x)` into `r`, at a point the explicit variables were just completed at if
    /// `completed` ([`Plant::residual_completed`]).
    fn residual_with(&self, t: f64, x: &[f64], r: &mut [f64], completed: bool) {
        let np = self.shape.n_plant;
        INPUTS.with_borrow_mut(|u| {
            u.clear();
            u.extend(self.waves.iter().map(|w| w.at(t)));
            if completed {
                self.plant.residual_completed(&self.shape.explicit, &x[..np], u, t, &mut r[..np]);
            } else {
                self.plant.residual(&x[..np], u, t, &mut r[..np]);
            }
        });
        for (k, (f, z)) in self.shape.flows.iter().enumerate() {
            for (c, zc) in z.clone().enumerate() {
                r[np + k * self.shape.nc + c] = x[*f] * x[zc];
            }
        }
    }
}

impl DaeSystem for PlantDae<'_> {
    fn n(&self) -> usize {
        self.shape.n_plant + self.shape.flows.len() * self.shape.nc
    }
    fn residual(&self, t: f64, x: &[f64], r: &mut [f64]) {
        self.residual_with(t, x, r, false);
    }
    fn residual_completed(&self, t: f64, x: &[f64], r: &mut [f64]) {
        self.residual_with(t, x, r, true);
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
    fn explicit(&self) -> &[(usize, usize)] {
        self.shape.explicit.pairs()
    }
    fn outputs(&self) -> &[(usize, usize)] {
        self.shape.explicit.outputs()
    }
    fn equation_name(&self, i: usize) -> Option<String> {
        if i >= self.shape.n_plant {
            return None;
        }
        let var = self.plant.equation_variable(i).map_or("-", |v| self.plant.vars()[v].path.as_str());
        Some(format!("{}, variable {var}", self.plant.equation_name(i)))
    }
    fn variable_name(&self, i: usize) -> Option<String> {
        self.plant.vars().get(i).map(|v| v.path.clone())
    }
    fn equation_hint(&self, i: usize) -> Option<&'static str> {
        let block = self.plant.blocks().iter().find(|b| (b.eq_offset..b.eq_offset + b.n_eq).contains(&i))?;
        Some(match block.kind {
            plantwide_flowsheet::BlockKind::Controller => {
                "; a controller whose output the plant cannot take there (moved past the range of the input it \
                 drives, or by a model of the wrong sign or size) ends a run this way"
            }
            plantwide_flowsheet::BlockKind::Unit => {
                "; a vessel running dry or overflowing, or a flow reversing, ends a run this way"
            }
            plantwide_flowsheet::BlockKind::Tag => {
                "; a tag's expression leaving its domain (a logarithm or square root of a negative number, a \
                 division by zero) ends a run this way"
            }
        })
    }
    fn complete(&self, t: f64, x: &mut [f64]) {
        let np = self.shape.n_plant;
        INPUTS.with_borrow_mut(|u| {
            u.clear();
            u.extend(self.waves.iter().map(|w| w.at(t)));
            self.plant.complete(&self.shape.explicit, &mut x[..np], u, t);
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NewtonSettings;
    use crate::dae::reduce::Reduction;

    /// Column A at its steady state. The plan eliminates every column variable but the 82
    /// holdups and 41 temperatures — M, x, y, L and V of each stage and both outlet streams, 299
    /// of the 436 — leaving 137 to Newton; completion reproduces the converged steady state; and
    /// the reduced Jacobian of the chain rule equals central differences of the reduced residual
    /// `F_k(x_k, x_e(x_k))`, evaluated by completing each perturbed point.
    #[test]
    fn column_a_reduced_jacobian_matches_differences_of_the_completed_residual() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../flowsheets/column_a.json");
        let plant = plantwide_flowsheet::load_file(std::path::Path::new(path)).unwrap();
        let u = plant.input_values();
        let x0 = crate::steady_state(&plant, &u, None, &NewtonSettings::default()).unwrap().x;
        let waves: Vec<Waveform> = u.iter().map(|&v| Waveform::Constant(v)).collect();
        let quad = Quadratures::new(&plant, &[]);
        let shape = DaeShape::new(&plant, &quad.streams, None);
        let sys = PlantDae::new(&plant, &waves, &shape);
        let n = sys.n();
        assert_eq!((n, sys.explicit().len()), (436, 299));
        let mut x = x0.clone();
        x.resize(n, 0.0);
        let mut done = x.clone();
        sys.complete(0.0, &mut done);
        for (i, (a, b)) in x.iter().zip(&done).enumerate() {
            assert!((a - b).abs() <= 1e-9 * (1.0 + a.abs()), "{}: {a} completed to {b}", plant.vars()[i].path);
        }
        let (mut r, mut jac) = (vec![0.0; n], Vec::new());
        sys.jacobian(0.0, &done, &mut r, &mut jac);
        let red = Reduction::new(n, sys.explicit(), &[]);
        let m = red.n();
        assert_eq!(m, 137);
        let mut triplets = Vec::new();
        red.jacobian(&jac, &mut triplets).unwrap();
        let mut dense = vec![0.0; m * m];
        triplets.iter().for_each(|&(i, j, v)| dense[i * m + j] += v);
        let reduced_residual = |j: usize, h: f64| {
            let mut xp = done.clone();
            xp[j] += h;
            sys.complete(0.0, &mut xp);
            let mut rp = vec![0.0; n];
            sys.residual(0.0, &xp, &mut rp);
            rp
        };
        let mut worst = 0.0f64;
        for (c, &j) in red.kept_vars.iter().enumerate() {
            let h = 1e-6 * sys.nominal(j).abs().max(x[j].abs());
            let (rp, rm) = (reduced_residual(j, h), reduced_residual(j, -h));
            for (row, &i) in red.kept_eqs.iter().enumerate() {
                let scale = (0..m).map(|k| dense[row * m + k].abs()).fold(1e-12, f64::max);
                let fd = (rp[i] - rm[i]) / (2.0 * h);
                worst = worst.max((fd - dense[row * m + c]).abs() / scale);
            }
        }
        eprintln!("reduced Jacobian against central differences: worst {worst:.2e}");
        assert!(worst < 1e-6, "reduced Jacobian against central differences: worst {worst:.2e} of its row's scale");
    }
}
