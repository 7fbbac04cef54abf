//! The simple column model: constant molar overflow (Skogestad's column A).
//!
//! **Stage numbering** (as Skogestad's column A): stage 1 is the reboiler, stages 2 … N−1 are the
//! trays counted from the bottom, stage N is the total condenser. Paths use these numbers:
//! `column.x[21][light]`, `column.T[1]`, `column.M[41]`.
//!
//! Ports: one inlet per feed (`feeds[k].port`, default `feed`), outlets `distillate`, `bottoms` and
//! one per side draw. Inputs: `reflux` L [mol/s], `boilup` V [mol/s], `distillate` D [mol/s],
//! `bottoms` B [mol/s], and each side draw's flow — so LV, DV, LB, (L/D)V … are controller wiring.
//!
//! # Simple model (constant molar overflow; Skogestad's column A)
//! Variables per stage i: component holdups `n_ij` [mol] (differential), `x_ij`, `y_ij`, `T_i`,
//! `M_i`, `L_i`, `V_i`. Equations:
//! - component balances `dn_ij/dt = L_{i+1} x_{i+1,j} + V_{i−1} y_{i−1,j} − L_i x_ij − V_i y_ij + Σ_feeds F z_j − draws`,
//!   where the condenser also loses `D x_Nj` and the reboiler's liquid
//!   outflow is the bottoms;
//! - `M_i = Σ_j n_ij`, `x_ij = n_ij / M_i`;
//! - equilibrium `y_ij = K_ij(T_i, P, x_i) x_ij` (constant α: `y = α x / Σ α x`);
//! - bubble point: `Σ_j K_ij x_ij = 1` (constant α: `Σ_j x_ij P_sat,j(T_i) = P`, the temperature
//!   scale of the hypothetical components);
//! - liquid flow: trays `L_i = max(0, L0_i + (M_i − M0_i)/τ_L + λ (V_{i−1} − V0))` (linearized
//!   Francis weir; no flow once a tray has drained below its weir, as when the boilup is lost and
//!   the trays run down), condenser `L_N = reflux`, reboiler `L_1 = B`;
//! - vapour flow: `V_1 = max(0, boilup + Σ_feeds (1 − q) F)`, `V_i = max(0, V_{i−1} + Σ_feeds (1 − q) F)`
//!   (CMO; a subcooled feed condenses at most the vapour there is, as when the boilup is lost),
//!   condenser `V_N = 0`.
//!
//! `L0_i` is the nominal liquid flow leaving stage i: the nominal reflux above the feeds, plus
//! `q·F_nominal` below each feed (`F_nominal` defaults to the nominal `D + B` for one feed).
//! The feed quality `q` is given or, by default, computed from enthalpies at the feed stage:
//! `q = (h_V − h_F)/(h_V − h_L)`.
//!
//! # References
//! - S. Skogestad, I. Postlethwaite, *Multivariable Feedback Control*, Wiley 2005, §12.4 (column A).
//! - W. L. Luyben (ed.), *Practical Distillation Control*, Van Nostrand Reinhold 1992, ch. 3–4.

use plantwide_units::Dimension;

mod kernels;

use super::{ColumnConfig, Draw, StageIdx, side_draws};

use crate::stream::{F, H, P, T, Z0};
use crate::{BuildCx, FieldError, InputSpec, LocalLayout, Scalar, UnitIo, UnitModel, VarSpec};

#[derive(Debug, Clone)]
struct Feed {
    stage: usize,
    q: Option<f64>,
}

/// A distillation column, simple model.
#[derive(Debug, Clone)]
pub struct SimpleColumn {
    n_stages: usize,
    feeds: Vec<Feed>,
    feed_ports: Vec<String>,
    draws: Vec<Draw>,
    draw_ports: Vec<String>,
    pressure: f64,
    m0: Vec<f64>,
    l0: Vec<f64>,
    tau_l: f64,
    lambda: f64,
    /// Whether the K-values depend on temperature (all but constant α): `y` then reads `T`.
    k_reads_t: bool,
    v0: f64,
    reflux: f64,
    boilup: f64,
    distillate: f64,
    bottoms: f64,
    comp_names: Vec<String>,
    /// Per stage: a tray with no feed and no draw (the fast path of the hot loops, `kernels.rs`).
    plain: Vec<bool>,
}

// Inputs, in declaration order.
const IN_REFLUX: usize = 0;
const IN_BOILUP: usize = 1;
const IN_DISTILLATE: usize = 2;
const IN_BOTTOMS: usize = 3;

impl SimpleColumn {
    /// Number of stages, condenser and reboiler included.
    pub(crate) fn n_stages(&self) -> usize {
        self.n_stages
    }
    /// Build from the flowsheet description.
    pub fn build(c: &ColumnConfig, mut cx: BuildCx<'_>) -> Result<SimpleColumn, Vec<FieldError>> {
        let n = c.stages;
        if n < 3 {
            cx.error("stages", format!("a column needs at least 3 stages (reboiler, one tray, condenser); got {n}"));
        }
        let amount = Dimension::AMOUNT;
        let flow = Dimension::MOLAR_FLOW;
        let pressure = c.pressure.as_ref().map_or(101_325.0, |p| cx.positive("P", p, Dimension::PRESSURE));
        let tray = c.tray_holdup.as_ref().map_or(f64::NAN, |v| cx.positive("tray_holdup", v, amount));
        let cond = cx.positive("condenser_holdup", &c.condenser_holdup, amount);
        let reb = cx.positive("reboiler_holdup", &c.reboiler_holdup, amount);
        let tau_l = c.tau_l.as_ref().map_or(f64::NAN, |v| cx.positive("tau_l", v, Dimension::TIME));
        let reflux = cx.non_negative("reflux", &c.reflux, flow);
        let boilup = c.boilup.as_ref().map_or(f64::NAN, |v| cx.non_negative("boilup", v, flow));
        let distillate = cx.non_negative("distillate", &c.distillate, flow);
        let bottoms = cx.non_negative("bottoms", &c.bottoms, flow);
        if c.feeds.is_empty() {
            cx.error("feeds", "give at least one feed, e.g. [{\"port\": \"feed\", \"stage\": 21}]");
        }
        let mut feeds = Vec::new();
        let mut feed_ports: Vec<String> = Vec::new();
        let mut nominal_feed = Vec::new();
        for (k, f) in c.feeds.iter().enumerate() {
            if f.stage < 1 || f.stage > n {
                cx.error(
                    &format!("feeds[{k}].stage"),
                    format!("must be between 1 (reboiler) and {n} (condenser); got {}", f.stage),
                );
            }
            if f.q.is_some_and(|q| !q.is_finite()) {
                cx.error(
                    &format!("feeds[{k}].q"),
                    "must be a finite number (1 = saturated liquid, 0 = saturated vapour)",
                );
            }
            if feed_ports.contains(&f.port) {
                cx.error(&format!("feeds[{k}].port"), format!("port `{}` is used twice", f.port));
            }
            feed_ports.push(f.port.clone());
            let nom = match &f.nominal_flow {
                Some(v) => cx.non_negative(&format!("feeds[{k}].nominal_flow"), v, flow),
                None if c.feeds.len() == 1 => distillate + bottoms,
                None => {
                    cx.error(
                        &format!("feeds[{k}].nominal_flow"),
                        "with several feeds give each feed's nominal flow for the tray hydraulics",
                    );
                    0.0
                }
            };
            nominal_feed.push(nom);
            feeds.push(Feed { stage: f.stage.saturating_sub(1), q: f.q });
        }
        let (draws, draw_ports) = side_draws(c, n, &feed_ports, &mut cx);
        let mut m0 = vec![tray; n];
        if n >= 1 {
            m0[0] = reb;
            m0[n - 1] = cond;
        }
        // Nominal liquid leaving each tray: reflux, plus q·F below each feed, minus side draws above.
        let mut l0 = vec![0.0; n];
        for i in (1..n.saturating_sub(1)).rev() {
            let mut l = if i + 2 == n { reflux } else { l0[i + 1] };
            for (f, nom) in feeds.iter().zip(&nominal_feed) {
                if f.stage == i {
                    l += f.q.unwrap_or(1.0) * nom;
                }
            }
            for d in draws.iter().filter(|d| d.stage == i) {
                l -= d.flow;
            }
            l0[i] = l;
        }
        let plain = (0..n)
            .map(|s| s > 0 && s + 1 < n && feeds.iter().all(|f| f.stage != s) && draws.iter().all(|d| d.stage != s))
            .collect();
        let column = SimpleColumn {
            plain,
            n_stages: n,
            feeds,
            feed_ports,
            draws,
            draw_ports,
            pressure,
            m0,
            l0,
            tau_l,
            lambda: c.lambda.unwrap_or(0.0),
            k_reads_t: cx.thermo.constant_alpha().is_none(),
            v0: boilup,
            reflux,
            boilup,
            distillate,
            bottoms,
            comp_names: cx.components.to_vec(),
        };
        cx.finish(column)
    }

    fn nc(&self) -> usize {
        self.comp_names.len()
    }
    /// Variables per stage: n (nc), x (nc), y (nc), T, M, L, V.
    fn per_stage(&self) -> usize {
        3 * self.nc() + 4
    }
    fn n_outlets(&self) -> usize {
        2 + self.draws.len()
    }
    /// Offset of stage `s` (0-based) in the internal variables.
    fn stage(&self, s: usize) -> usize {
        s * self.per_stage()
    }

    /// Per stage: the feeds' component flows `Σ F z_j` (stage `s`, component `j` at `s·nc + j`)
    /// and their vapour `Σ (1 − q) F`, with `q = (h_V − h_F)/(h_V − h_L)` at the feed stage where
    /// it is not given; `st(s)` is stage `s`'s variables.
    fn feed_terms<'v, S: Scalar + 'v>(&self, io: &UnitIo<'_, S>, st: impl Fn(usize) -> &'v [S]) -> (Vec<S>, Vec<S>) {
        let (nc, n) = (self.nc(), self.n_stages);
        let mut feed_comp = vec![S::from(0.0); n * nc];
        let mut feed_vap = vec![S::from(0.0); n];
        for (k, f) in self.feeds.iter().enumerate() {
            let s = io.inlet(k);
            for (acc, z) in feed_comp[f.stage * nc..(f.stage + 1) * nc].iter_mut().zip(s.z()) {
                *acc += s.f() * *z;
            }
            feed_vap[f.stage] += self.feed_vapour(io, k, st(f.stage));
        }
        (feed_comp, feed_vap)
    }

    /// The vapour `(1 − q) F` feed `k` brings to its stage, whose variables are `v` (module
    /// documentation).
    fn feed_vapour<S: Scalar>(&self, io: &UnitIo<'_, S>, k: usize, v: &[S]) -> S {
        let (nc, ix) = (self.nc(), StageIdx { nc: self.nc() });
        let s = io.inlet(k);
        let q = match self.feeds[k].q {
            Some(q) => S::from(q),
            None => {
                let hv = io.thermo.h_vap(v[ix.t()], &v[ix.y(0)..ix.y(0) + nc]);
                let hl = io.thermo.h_liq(v[ix.t()], &v[ix.x(0)..ix.x(0) + nc]);
                (hv - s.h()) / (hv - hl)
            }
        };
        (S::from(1.0) - q) * s.f()
    }

    /// `dn_sj/dt` of the component balance of stage `s`, component `j` (module documentation),
    /// with the feeds' flow `feed` of it, the distillate `d_in` and the side draws' flows.
    fn component_balance<S: Scalar>(
        &self,
        io: &UnitIo<'_, S>,
        s: usize,
        j: usize,
        feed: S,
        d_in: S,
        draw_flow: &[S],
    ) -> S {
        let (n, ix) = (self.n_stages, StageIdx { nc: self.nc() });
        let st = |s: usize| io.vars(self.stage(s), self.per_stage());
        let v = st(s);
        let mut acc = feed - v[ix.l()] * v[ix.x(j)] - v[ix.v()] * v[ix.y(j)];
        if s + 1 < n {
            let up = st(s + 1);
            acc += up[ix.l()] * up[ix.x(j)];
        }
        if s > 0 {
            let dn = st(s - 1);
            acc += dn[ix.v()] * dn[ix.y(j)];
        }
        if s + 1 == n {
            acc -= d_in * v[ix.x(j)];
        }
        for (d, fl) in self.draws.iter().zip(draw_flow) {
            if d.stage == s {
                acc -= *fl * v[ix.x(j)];
            }
        }
        acc
    }

    /// The rows of stage `s` of [`UnitModel::pattern`] (see there) into `p`.
    fn stage_pattern(&self, s: usize, layout: &LocalLayout, p: &mut Vec<(usize, usize)>) {
        let (nc, n, ix) = (self.nc(), self.n_stages, StageIdx { nc: self.nc() });
        let slen = layout.stream.len();
        let internal0 = self.n_outlets() * slen;
        let col = |s: usize, k: usize| internal0 + self.stage(s) + k;
        let input = |k: usize| layout.inputs_offset() + k;
        let inlet = |f: usize, field: usize| layout.inlets_offset() + f * slen + field;
        let feeds: Vec<usize> = (0..self.feeds.len()).filter(|&f| self.feeds[f].stage == s).collect();
        let xs = (0..nc).map(|j| col(s, ix.x(j)));
        for j in 0..nc {
            let row = col(s, ix.n(j));
            p.extend([ix.n(j), ix.l(), ix.x(j), ix.v(), ix.y(j)].map(|k| (row, col(s, k))));
            if s + 1 < n {
                p.extend([(row, col(s + 1, ix.l())), (row, col(s + 1, ix.x(j)))]);
            } else {
                p.push((row, input(IN_DISTILLATE)));
            }
            if s > 0 {
                p.extend([(row, col(s - 1, ix.v())), (row, col(s - 1, ix.y(j)))]);
            }
            let draws = self.draws.iter().enumerate().filter(|(_, d)| d.stage == s);
            p.extend(draws.map(|(k, _)| (row, input(4 + k))));
            p.extend(feeds.iter().flat_map(|&f| [(row, inlet(f, F)), (row, inlet(f, Z0 + j))]));
            let row = col(s, ix.x(j));
            p.extend([ix.x(j), ix.n(j), ix.m()].map(|k| (row, col(s, k))));
            let row = col(s, ix.y(j));
            p.push((row, col(s, ix.y(j))));
            p.extend(xs.clone().map(|c| (row, c)));
            if self.k_reads_t {
                p.push((row, col(s, ix.t())));
            }
        }
        let row = col(s, ix.t());
        p.push((row, row));
        p.extend(xs.clone().map(|c| (row, c)));
        let row = col(s, ix.m());
        p.push((row, row));
        p.extend((0..nc).map(|j| (row, col(s, ix.n(j)))));
        let row = col(s, ix.l());
        p.push((row, row));
        match s {
            _ if s + 1 == n => p.push((row, input(IN_REFLUX))),
            0 => p.push((row, input(IN_BOTTOMS))),
            _ => p.extend([(row, col(s, ix.m())), (row, col(s - 1, ix.v()))]),
        }
        let row = col(s, ix.v());
        p.push((row, row));
        match s {
            0 => p.push((row, input(IN_BOILUP))),
            _ if s + 1 == n => {}
            _ => p.push((row, col(s - 1, ix.v()))),
        }
        for &f in &feeds {
            p.extend([(row, inlet(f, F)), (row, inlet(f, H))]);
            if self.feeds[f].q.is_none() {
                p.push((row, col(s, ix.t())));
                p.extend((0..nc).flat_map(|j| [(row, col(s, ix.x(j))), (row, col(s, ix.y(j)))]));
            }
        }
    }

    /// Outlet residuals: distillate from the condenser (flow `D`), bottoms from the reboiler (its
    /// liquid `L_1`), each side draw from its stage; every outlet leaves as the stage's liquid.
    fn outlet_residuals<S: Scalar>(&self, io: &UnitIo<'_, S>, d_in: S, draw_flow: &[S], r: &mut [S]) {
        let (nc, n, ix) = (self.nc(), self.n_stages, StageIdx { nc: self.nc() });
        let slen = io.layout.stream.len();
        let p = S::from(self.pressure);
        let st = |s: usize| io.vars(self.stage(s), self.per_stage());
        let outlet = |k: usize, s: usize, flow: S, r: &mut [S]| {
            let out = io.outlet(k);
            let v = st(s);
            let rr = &mut r[k * slen..(k + 1) * slen];
            rr[F] = out.f() - flow;
            rr[T] = out.t() - v[ix.t()];
            rr[P] = out.p() - p;
            rr[H] = out.h() - io.thermo.h_liq(v[ix.t()], &v[ix.x(0)..ix.x(0) + nc]);
            for j in 0..nc {
                rr[Z0 + j] = out.z()[j] - v[ix.x(j)];
            }
        };
        outlet(0, n - 1, d_in, r);
        outlet(1, 0, st(0)[ix.l()], r);
        for (k, d) in self.draws.iter().enumerate() {
            outlet(2 + k, d.stage, draw_flow[k], r);
        }
    }
}

impl UnitModel for SimpleColumn {
    fn type_name(&self) -> &'static str {
        "column"
    }
    fn inlet_ports(&self) -> Vec<String> {
        self.feed_ports.clone()
    }
    fn outlet_ports(&self) -> Vec<String> {
        let mut v = vec!["distillate".to_string(), "bottoms".to_string()];
        v.extend(self.draw_ports.iter().cloned());
        v
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        let mut v = Vec::with_capacity(self.n_stages * self.per_stage());
        let flow_nom = self.reflux.max(self.boilup).max(1e-3);
        for s in 0..self.n_stages {
            let st = s + 1;
            let m0 = self.m0[s];
            for c in &self.comp_names {
                v.push(
                    VarSpec::differential(format!("n[{st}][{c}]"), Dimension::AMOUNT, m0).bounded(0.0, f64::INFINITY),
                );
            }
            for c in &self.comp_names {
                v.push(VarSpec::algebraic(format!("x[{st}][{c}]"), Dimension::DIMENSIONLESS, 1.0).bounded(0.0, 1.0));
            }
            for c in &self.comp_names {
                v.push(VarSpec::algebraic(format!("y[{st}][{c}]"), Dimension::DIMENSIONLESS, 1.0).bounded(0.0, 1.0));
            }
            v.push(VarSpec::algebraic(format!("T[{st}]"), Dimension::TEMPERATURE, 350.0).bounded(1.0, 5000.0));
            v.push(
                VarSpec::algebraic(format!("M[{st}]"), Dimension::AMOUNT, m0)
                    .bounded(1e-12 * m0, f64::INFINITY)
                    .inventory(),
            );
            v.push(VarSpec::algebraic(format!("L[{st}]"), Dimension::MOLAR_FLOW, flow_nom).bounded(0.0, f64::INFINITY));
            v.push(VarSpec::algebraic(format!("V[{st}]"), Dimension::MOLAR_FLOW, flow_nom).bounded(0.0, f64::INFINITY));
        }
        v
    }
    fn inputs(&self) -> Vec<InputSpec> {
        let flow = Dimension::MOLAR_FLOW;
        let mut v = vec![
            InputSpec { name: "reflux".into(), dim: flow, value: self.reflux },
            InputSpec { name: "boilup".into(), dim: flow, value: self.boilup },
            InputSpec { name: "distillate".into(), dim: flow, value: self.distillate },
            InputSpec { name: "bottoms".into(), dim: flow, value: self.bottoms },
        ];
        for (d, p) in self.draws.iter().zip(&self.draw_ports) {
            v.push(InputSpec { name: p.clone(), dim: flow, value: d.flow });
        }
        v
    }
    fn holdup(&self, io: &UnitIo<'_, f64>) -> Option<Vec<f64>> {
        Some(super::summed_holdups(io, self.n_stages, self.nc(), |s| self.stage(s)))
    }
    /// Structural nonzeros read off [`UnitModel::eval`], row by row. Per stage: the component
    /// balance of `j` reads its own holdup (the mass matrix's entry), `L`, `x_j`, `V`, `y_j` of
    /// the stage, `L`, `x_j` of the stage above, `V`, `y_j` of the stage below, the distillate
    /// (condenser), a side draw (its stage) and a feed's flow and `z_j` (its stage); `x_j` reads
    /// `n_j` and `M`; `y_j` reads `x` and, unless the K-values are constant-α (independent of
    /// temperature), `T`; the bubble point reads `T` and `x`; `M` reads `n`; `L` reads the reflux
    /// (condenser), the bottoms (reboiler) or `M` and the vapour below (trays); `V` reads the
    /// boilup (reboiler) or the vapour below (trays), a feed's flow and enthalpy, and where the
    /// feed quality comes from enthalpies the stage's `T`, `x` and `y`. An outlet's flow reads
    /// its flow variable, its temperature and enthalpy the stage's `T` (and `x`), its
    /// composition the stage's `x`. Exact rows keep a constant-α tray temperature out of every
    /// row but its own and the outlets' (so the integrator can leave it out, see
    /// `DaeSystem::outputs`) and let the Jacobian colour in fewer dual passes.
    fn pattern(&self, layout: &LocalLayout) -> Option<Vec<(usize, usize)>> {
        let (nc, n, ix) = (self.nc(), self.n_stages, StageIdx { nc: self.nc() });
        let slen = layout.stream.len();
        let internal0 = self.n_outlets() * slen;
        let col = |s: usize, k: usize| internal0 + self.stage(s) + k;
        let input = |k: usize| layout.inputs_offset() + k;
        let mut p = Vec::new();
        for k in 0..self.n_outlets() {
            let (s, flow) = match k {
                0 => (n - 1, input(IN_DISTILLATE)),
                1 => (0, col(0, ix.l())),
                _ => (self.draws[k - 2].stage, input(4 + k - 2)),
            };
            let row = |field: usize| k * slen + field;
            p.extend([(row(F), row(F)), (row(F), flow), (row(T), row(T)), (row(T), col(s, ix.t())), (row(P), row(P))]);
            p.extend([(row(H), row(H)), (row(H), col(s, ix.t()))]);
            p.extend((0..nc).map(|j| (row(H), col(s, ix.x(j)))));
            p.extend((0..nc).flat_map(|j| [(row(Z0 + j), row(Z0 + j)), (row(Z0 + j), col(s, ix.x(j)))]));
        }
        for s in 0..n {
            self.stage_pattern(s, layout, &mut p);
        }
        // Assembly emits one triplet per declared entry: an entry declared twice (the bottoms'
        // flow is its stage's `L`) would be summed twice.
        p.sort_unstable();
        p.dedup();
        Some(p)
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let nc = self.nc();
        let slen = io.layout.stream.len();
        let internal0 = self.n_outlets() * slen;
        let ix = StageIdx { nc };
        let p = S::from(self.pressure);
        let st = |s: usize| io.vars(self.stage(s), self.per_stage());
        let n = self.n_stages;
        let (l_in, v_in, d_in, b_in) =
            (io.input(IN_REFLUX), io.input(IN_BOILUP), io.input(IN_DISTILLATE), io.input(IN_BOTTOMS));
        let mut kbuf = vec![S::from(0.0); nc];
        let (feed_comp, feed_vap) = self.feed_terms(io, st);
        let draw_flow: Vec<S> = (0..self.draws.len()).map(|k| io.input(4 + k)).collect();

        for s in 0..n {
            let v = st(s);
            let o = internal0 + self.stage(s);
            let m = v[ix.m()];
            for j in 0..nc {
                r[o + ix.n(j)] = self.component_balance(io, s, j, feed_comp[s * nc + j], d_in, &draw_flow);
                r[o + ix.x(j)] = v[ix.x(j)] - v[ix.n(j)] / m;
            }
            let x = &v[ix.x(0)..ix.x(0) + nc];
            // Equilibrium and bubble point.
            io.thermo.k_values(v[ix.t()], p, x, &mut kbuf);
            for j in 0..nc {
                r[o + ix.y(j)] = v[ix.y(j)] - kbuf[j] * x[j];
            }
            r[o + ix.t()] = io.thermo.bubble_residual(v[ix.t()], p, x);
            r[o + ix.m()] = m - v[ix.n(0)..ix.n(0) + nc].iter().fold(S::from(0.0), |a, b| a + *b);
            // Liquid flows.
            r[o + ix.l()] = if s + 1 == n {
                v[ix.l()] - l_in
            } else if s == 0 {
                v[ix.l()] - b_in
            } else {
                let mut l = S::from(self.l0[s]) + (m - self.m0[s]) / self.tau_l;
                if self.lambda != 0.0 {
                    l += (st(s - 1)[ix.v()] - self.v0) * self.lambda;
                }
                // No flow over the weir once the tray has drained below it.
                if l.re() < 0.0 {
                    l = S::from(0.0);
                }
                v[ix.l()] - l
            };
            // Vapour flows (CMO).
            // A subcooled feed condenses at most the vapour there is: no negative vapour flow.
            let floor = |v: S| if v.re() < 0.0 { S::from(0.0) } else { v };
            r[o + ix.v()] = if s == 0 {
                v[ix.v()] - floor(v_in + feed_vap[0])
            } else if s + 1 == n {
                v[ix.v()]
            } else {
                v[ix.v()] - floor(st(s - 1)[ix.v()] + feed_vap[s])
            };
        }
        self.outlet_residuals(io, d_in, &draw_flow, r);
    }
    /// Every variable but the holdups `n` and temperatures `T`, in the order
    /// [`SimpleColumn::complete`] computes them: per stage `M`, `x`, `y`; then the vapour flows
    /// bottom up, the liquid flows; then the outlet streams.
    fn explicit(&self, layout: &LocalLayout) -> Vec<usize> {
        let (nc, n, ix) = (self.nc(), self.n_stages, StageIdx { nc: self.nc() });
        let outlets = self.n_outlets() * layout.stream.len();
        let col = |s: usize, k: usize| outlets + self.stage(s) + k;
        let mut e = Vec::with_capacity(n * (2 * nc + 3) + outlets);
        for s in 0..n {
            e.push(col(s, ix.m()));
            e.extend((0..nc).map(|j| col(s, ix.x(j))));
            e.extend((0..nc).map(|j| col(s, ix.y(j))));
        }
        e.extend((0..n).map(|s| col(s, ix.v())));
        e.extend((0..n).map(|s| col(s, ix.l())));
        e.extend(0..outlets);
        e
    }
    /// The component balances and bubble points alone (a bubble point in `skip` left out): every
    /// other equation is explicit. The
    /// terms of each balance are summed in [`SimpleColumn::component_balance`]'s order (the same
    /// values bit for bit), on slices of the stage and its neighbours and without allocation: this
    /// runs at every Newton iteration of the dynamic integrator.
    fn eval_kept(&self, io: &UnitIo<'_, f64>, own: &[f64], r: &mut [f64], skip: &[bool]) {
        match self.nc() {
            2 => self.eval_kept_nc::<2>(io, own, r, skip),
            3 => self.eval_kept_nc::<3>(io, own, r, skip),
            4 => self.eval_kept_nc::<4>(io, own, r, skip),
            _ => self.eval_kept_nc::<0>(io, own, r, skip),
        }
    }
    /// `M = Σ n`, `x = n/M`, `y = K(T, P, x) x`, the CMO vapour flows, the liquid flows and the
    /// outlets, each from its own equation of [`UnitModel::eval`] (module documentation).
    fn complete(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        match self.nc() {
            2 => self.complete_nc::<2>(io, own),
            3 => self.complete_nc::<3>(io, own),
            4 => self.complete_nc::<4>(io, own),
            _ => self.complete_nc::<0>(io, own),
        }
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let nc = self.nc();
        let n = self.n_stages;
        let slen = io.layout.stream.len();
        let internal0 = self.n_outlets() * slen;
        let ix = StageIdx { nc };
        // Overall feed composition.
        let mut zf = vec![0.0; nc];
        let mut ftot = 0.0;
        for k in 0..self.feeds.len() {
            let s = io.inlet(k);
            ftot += s.f();
            zf.iter_mut().zip(s.z()).for_each(|(a, z)| *a += s.f() * z);
        }
        if ftot > 0.0 {
            zf.iter_mut().for_each(|a| *a /= ftot);
        } else {
            zf.iter_mut().for_each(|a| *a = 1.0 / nc as f64);
        }
        // Linear profile between a heavy-rich bottom (z/K) and a light-rich top (z·K).
        let t_feed = io.thermo.bubble_t(self.pressure, &zf).map(|s| s.t).unwrap_or(350.0);
        let mut k = vec![0.0; nc];
        io.thermo.k_values(t_feed, self.pressure, &zf, &mut k);
        let norm = |v: Vec<f64>| {
            let s: f64 = v.iter().sum();
            v.into_iter().map(|a| a / s).collect::<Vec<f64>>()
        };
        let top = norm(zf.iter().zip(&k).map(|(z, k)| z * k * k).collect());
        let bot = norm(zf.iter().zip(&k).map(|(z, k)| z / (k * k)).collect());
        let (l_in, v_in) = (io.input(IN_REFLUX), io.input(IN_BOILUP));
        let mut vflow = v_in;
        for s in 0..n {
            let w = s as f64 / (n - 1) as f64;
            let x: Vec<f64> = bot.iter().zip(&top).map(|(b, t)| (1.0 - w) * b + w * t).collect();
            let t = io.thermo.bubble_t(self.pressure, &x).map(|s| s.t).unwrap_or(t_feed);
            io.thermo.k_values(t, self.pressure, &x, &mut k);
            let y: Vec<f64> = norm(x.iter().zip(&k).map(|(a, b)| a * b).collect());
            let o = internal0 + self.stage(s);
            let m = self.m0[s];
            for j in 0..nc {
                own[o + ix.n(j)] = m * x[j];
                own[o + ix.x(j)] = x[j];
                own[o + ix.y(j)] = y[j];
            }
            own[o + ix.t()] = t;
            own[o + ix.m()] = m;
            own[o + ix.l()] = if s + 1 == n {
                l_in
            } else if s == 0 {
                io.input(IN_BOTTOMS)
            } else {
                self.l0[s]
            };
            if s > 0 {
                for f in self.feeds.iter().filter(|f| f.stage == s) {
                    vflow += (1.0 - f.q.unwrap_or(1.0))
                        * io.inlet(self.feeds.iter().position(|g| std::ptr::eq(g, f)).unwrap_or(0)).f();
                }
            }
            own[o + ix.v()] = if s + 1 == n { 0.0 } else { vflow };
        }
        let mut outlet = |k: usize, s: usize, flow: f64| {
            let o = internal0 + self.stage(s);
            let x: Vec<f64> = own[o + ix.x(0)..o + ix.x(0) + nc].to_vec();
            let t = own[o + ix.t()];
            let rr = &mut own[k * slen..(k + 1) * slen];
            rr[F] = flow;
            rr[T] = t;
            rr[P] = self.pressure;
            rr[H] = io.thermo.h_liq(t, &x);
            rr[Z0..].copy_from_slice(&x);
        };
        outlet(0, n - 1, io.input(IN_DISTILLATE));
        outlet(1, 0, io.input(IN_BOTTOMS));
        for (k, d) in self.draws.iter().enumerate() {
            outlet(2 + k, d.stage, io.input(4 + k));
        }
    }
}

#[cfg(test)]
mod tests {
    use plantwide_thermo::{ThermoPackage, VleModel};

    use crate::testing::{binary_package, jacobian_error};
    use crate::units::column::{Column, ColumnConfig};
    use crate::units::outflow::test_support::{Lcg, at_guess};
    use crate::{BuildCx, Coloring, Unit, UnitIo};

    /// A seven-stage column fed on stage 3 with `feed` (`"q": 1.0` or none: q from enthalpies),
    /// `extra` fields (a side draw, λ).
    fn column(feed: &str, extra: &str) -> Column {
        column_in(&binary_package(), feed, extra)
    }

    /// [`column`] on the package `thermo`.
    fn column_in(thermo: &ThermoPackage, feed: &str, extra: &str) -> Column {
        let json = format!(
            r#"{{"stages": 7, "feeds": [{{"stage": 3{feed}}}], "P": "1 atm", "tray_holdup": "0.5 kmol",
            "condenser_holdup": "0.5 kmol", "reboiler_holdup": "0.5 kmol", "tau_l": "0.063 min",
            "reflux": "2.7 kmol/min", "boilup": "3.2 kmol/min", "distillate": "0.5 kmol/min",
            "bottoms": "0.5 kmol/min"{extra}}}"#
        );
        let names: Vec<String> = thermo.components.iter().map(|c| c.name.clone()).collect();
        let c: ColumnConfig = serde_json::from_str(&json).unwrap();
        Column::build(&c, BuildCx::new(&names, thermo, "units.column"), ()).unwrap()
    }

    /// The binary test package and a subcooled equimolar feed stream (F, T, P, h, z).
    fn subcooled_feed() -> (ThermoPackage, [f64; 6]) {
        let thermo = binary_package();
        let t = thermo.bubble_t(101_325.0, &[0.5, 0.5]).unwrap().t;
        let feed = [1000.0 / 60.0, t, 101_325.0, thermo.h_liq(t, &[0.5, 0.5]) - 500.0, 0.5, 0.5];
        (thermo, feed)
    }

    /// [`subcooled_feed`]'s package (temperature-dependent K-values) and its constant-α twin,
    /// and the feed.
    fn both_packages() -> ([ThermoPackage; 2], [f64; 6]) {
        let (ideal, feed) = subcooled_feed();
        let alpha = ThermoPackage { vle: VleModel::ConstantAlpha { alpha: vec![2.0, 1.0] }, ..ideal.clone() };
        ([ideal, alpha], feed)
    }

    /// The configurations that change which rows read what: feed quality given or from
    /// enthalpies, vapour dynamics (λ ≠ 0) with a side draw.
    const CONFIGS: [(&str, &str); 3] = [
        (r#", "q": 1.0"#, ""),
        ("", ""),
        ("", r#", "lambda": 0.3, "side_draws": [{"port": "side", "stage": 5, "flow": "0.1 kmol/min"}]"#),
    ];

    /// The declared pattern holds every entry of the dense dual-number Jacobian (one pass per
    /// column, no colouring) at the guess and at randomly perturbed points, for every
    /// configuration that changes which rows read what: feed quality given or from enthalpies, a
    /// side draw, vapour dynamics (λ ≠ 0). A missed entry would silently corrupt the coloured
    /// Jacobian; the coloured one also agrees with central differences.
    #[test]
    fn the_declared_pattern_holds_every_nonzero_and_colours_the_jacobian_exactly() {
        let ([ideal, alpha], feed) = both_packages();
        let mut rng = Lcg(7);
        for ((f, extra), thermo) in CONFIGS.into_iter().flat_map(|c| [(c, &ideal), (c, &alpha)]) {
            let u = column_in(thermo, f, extra);
            let (lay, guess) = at_guess(&u, thermo, &feed);
            let n = lay.len();
            let m = lay.n_own();
            let pattern = u.pattern(&lay).expect("declared");
            let mut unique = pattern.clone();
            unique.sort_unstable();
            unique.dedup();
            assert_eq!(
                unique.len(),
                pattern.len(),
                "{f}{extra}: an entry is declared twice (assembly would sum it twice)"
            );
            let mut declared = vec![false; m * n];
            pattern.iter().for_each(|&(k, j)| declared[k * n + j] = true);
            let coloring = Coloring::new(&pattern, m, n);
            for trial in 0..4 {
                let local: Vec<f64> = guess
                    .iter()
                    .map(|&v| if trial == 0 { v } else { v * rng.range(0.8, 1.2) + rng.range(0.0, 1e-3) })
                    .collect();
                let io = UnitIo { local: &local, layout: &lay, thermo, time: 0.0 };
                let (mut r, mut dense) = (vec![0.0; m], vec![0.0; m * n]);
                u.jacobian_colored(&io, &mut r, &mut dense, None);
                for (e, (&v, &d)) in dense.iter().zip(&declared).enumerate() {
                    assert!(v == 0.0 || d, "{f}{extra}: entry ({}, {}) = {v} is not declared", e / n, e % n);
                }
                let mut colored = vec![0.0; m * n];
                u.jacobian_colored(&io, &mut r, &mut colored, Some(&coloring));
                let worst = colored.iter().zip(&dense).fold(0.0f64, |w, (a, b)| w.max((a - b).abs()));
                assert_eq!(worst, 0.0, "{f}{extra}: coloured and dense Jacobians differ");
                assert!(jacobian_error(&u, &lay, thermo, &local, m) < 1e-6, "{f}{extra}");
            }
            eprintln!("{f}{extra}: {} colours for {n} local columns", coloring.n_colors);
        }
    }

    /// `eval_kept` gives `eval`'s value on every equation that is not explicit, bit for bit (it
    /// sums the same terms in the same order), reading its own variables from its `own` argument
    /// alone, for each configuration, at perturbed points.
    #[test]
    fn eval_kept_equals_eval_on_the_kept_rows() {
        let (thermo, feed) = subcooled_feed();
        let mut rng = Lcg(5);
        for (f, extra) in CONFIGS {
            let u = column(f, extra);
            let (lay, guess) = at_guess(&u, &thermo, &feed);
            let m = lay.n_own();
            let mut kept = vec![true; m];
            Unit::explicit(&u, &lay).into_iter().for_each(|k| kept[k] = false);
            for _ in 0..3 {
                let local: Vec<f64> = guess.iter().map(|&v| v * rng.range(0.8, 1.2) + rng.range(0.0, 1e-3)).collect();
                let io = UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 };
                let (mut full, mut only) = (vec![0.0; m], vec![f64::NAN; m]);
                Unit::residual(&u, &io, &mut full);
                // The own block of `io.local` is not filled for `eval_kept`: NaN here.
                let mut reads_only = local.clone();
                reads_only[..m].fill(f64::NAN);
                let rio = UnitIo { local: &reads_only, ..io };
                Unit::residual_kept(&u, &rio, &local[..m], &mut only, &[]);
                for k in (0..m).filter(|&k| kept[k]) {
                    assert_eq!(
                        only[k].to_bits(),
                        full[k].to_bits(),
                        "{f}{extra}: row {k}: {} against {}",
                        only[k],
                        full[k]
                    );
                }
            }
        }
    }

    /// The completion of `own` by the kernels for `NC` components, and the kept residuals at the
    /// completed point.
    fn kernels<const NC: usize>(c: &super::SimpleColumn, io: &UnitIo<'_, f64>, own: &[f64]) -> [Vec<u64>; 2] {
        let mut own = own.to_vec();
        c.complete_nc::<NC>(io, &mut own);
        let mut r = vec![0.0; own.len()];
        c.eval_kept_nc::<NC>(io, &own, &mut r, &[]);
        [own, r].map(|v| v.iter().map(|x| x.to_bits()).collect())
    }

    /// Two ways of running the kernels on a configuration's column, `a` and `b` (each giving
    /// [`kernels`]' bits), agree bit for bit for every configuration, with constant α and
    /// temperature-dependent K-values, at three perturbed points each.
    fn kernels_agree(
        seed: u64,
        a: impl Fn(&super::SimpleColumn, &UnitIo<'_, f64>, &[f64]) -> [Vec<u64>; 2],
        b: impl Fn(&super::SimpleColumn, &UnitIo<'_, f64>, &[f64]) -> [Vec<u64>; 2],
    ) {
        let ([ideal, alpha], feed) = both_packages();
        let mut rng = Lcg(seed);
        for ((f, extra), thermo) in CONFIGS.into_iter().flat_map(|c| [(c, &ideal), (c, &alpha)]) {
            let u = column_in(thermo, f, extra);
            let Column::Simple(c) = &u else { panic!("a simple column") };
            let (lay, guess) = at_guess(&u, thermo, &feed);
            for _ in 0..3 {
                let local: Vec<f64> = guess.iter().map(|&v| v * rng.range(0.8, 1.2) + rng.range(0.0, 1e-3)).collect();
                let io = UnitIo { local: &local, layout: &lay, thermo, time: 0.0 };
                let own = &local[..lay.n_own()];
                let ([own_a, r_a], [own_b, r_b]) = (a(c, &io, own), b(c, &io, own));
                assert_eq!(own_a, own_b, "{f}{extra}: completion");
                assert_eq!(r_a, r_b, "{f}{extra}: kept residuals");
            }
        }
    }

    /// The kernels with the component count a compile-time constant ([`super::kernels`]) give
    /// the general loop's values bit for bit: completion and kept residuals, for every
    /// configuration, constant α and temperature-dependent K-values, at perturbed points.
    #[test]
    fn the_unrolled_kernels_equal_the_general_loop_bit_for_bit() {
        kernels_agree(13, kernels::<2>, kernels::<0>);
    }

    /// The plain trays' fast path of the kernels (no feed, no draw) gives the general loop's
    /// values bit for bit: the same column with every tray taken through the general loop is the
    /// reference, for every configuration (λ ≠ 0 with a side draw among them).
    #[test]
    fn the_plain_trays_fast_path_equals_the_general_loop_bit_for_bit() {
        let general = |c: &super::SimpleColumn, io: &UnitIo<'_, f64>, own: &[f64]| {
            assert!(c.plain.iter().filter(|&&p| p).count() >= 3, "plain trays to test");
            kernels::<2>(&super::SimpleColumn { plain: vec![false; c.plain.len()], ..c.clone() }, io, own)
        };
        kernels_agree(17, kernels::<2>, general);
    }

    /// `complete` solves every explicit equation exactly and leaves the other variables alone,
    /// and no explicit equation reads an explicit variable computed after it (the dense Jacobian's
    /// entries there are zero) — the contract the integrator's elimination relies on — for the
    /// configurations that change what the flows read: q given or from enthalpies, λ ≠ 0 with a
    /// side draw.
    #[test]
    fn complete_solves_the_explicit_equations_in_declared_order() {
        let (thermo, feed) = subcooled_feed();
        let mut rng = Lcg(11);
        for (f, extra) in CONFIGS {
            let u = column(f, extra);
            let (lay, guess) = at_guess(&u, &thermo, &feed);
            let (n, m) = (lay.len(), lay.n_own());
            let explicit = Unit::explicit(&u, &lay);
            let mut position = vec![usize::MAX; m];
            explicit.iter().enumerate().for_each(|(p, &k)| position[k] = p);
            for _ in 0..3 {
                let mut local: Vec<f64> =
                    guess.iter().map(|&v| v * rng.range(0.8, 1.2) + rng.range(0.0, 1e-3)).collect();
                let mut own = local[..m].to_vec();
                // The own block of `io.local` is not filled for `complete`: NaN here.
                let mut reads_only = local.clone();
                reads_only[..m].fill(f64::NAN);
                Unit::complete(&u, &UnitIo { local: &reads_only, layout: &lay, thermo: &thermo, time: 0.0 }, &mut own);
                assert!(own.iter().all(|v| v.is_finite()), "{f}{extra}: complete read its own block from io.local");
                for k in (0..m).filter(|&k| position[k] == usize::MAX) {
                    assert_eq!(own[k], local[k], "{f}{extra}: kept variable {k} changed");
                }
                local[..m].copy_from_slice(&own);
                let io = UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 };
                let (mut r, mut jac) = (vec![0.0; m], vec![0.0; m * n]);
                u.jacobian_colored(&io, &mut r, &mut jac, None);
                for (p, &k) in explicit.iter().enumerate() {
                    let scale = 1.0 + own[k].abs();
                    assert!(r[k].abs() <= 1e-12 * scale, "{f}{extra}: explicit row {k} residual {}", r[k]);
                    for (q, &later) in explicit.iter().enumerate().skip(p + 1) {
                        assert_eq!(jac[k * n + later], 0.0, "{f}{extra}: row {k} (#{p}) reads #{q}");
                    }
                }
            }
        }
    }
}
