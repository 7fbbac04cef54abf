//! Cold-start guess of the rigorous column: its steady state at the current `reflux` and
//! `reboiler_duty`, with D and B from the balances.
//!
//! 1. **Distillate estimate** from constant molar overflow: `V ≈ (Q_R + Σ F (h_F − h_L,F)) / Δh_vap`
//!    at the feed's bubble point, `D₀ = V − reflux`, kept within 1 … 99 % of the net feed.
//! 2. **Bubble-point method** (Wang & Henke 1966), from every stage at the overall feed composition
//!    and its bubble point, at most [`MAX_SWEEPS`] sweeps of
//!    - vapour flows from the stage energy balances, up from the reboiler duty,
//!      `V_i (h_V,i − h_L,i+1) = G_i (h_L,i+1 − h_L,i) + V_{i−1} (h_V,i−1 − h_L,i) + Σ F (h_F − h_L,i) + Q_i`,
//!      with the liquid from above eliminated by the balance of the section above stage i,
//!      `L_{i+1} = V_i + G_i`, `G_i = Σ_{k>i} (F_k − S_k) − D`; the distillate follows from the drum,
//!      `D = V_{N−1} + F_N − reflux` (a fixed point: `G` depends on `D` only through sensible-heat
//!      differences);
//!    - for each component the tridiagonal component balances `L_{i+1} x_{i+1} + V_{i−1} K'_{i−1}
//!      x_{i−1} − (L_i + S_i + D δ_iN + V_i K'_i) x_i = −Σ F z` with effective K-values `K' = y/x` of
//!      the last sweep (they carry the Murphree efficiency), by the Thomas algorithm;
//!    - normalised `x`, bubble-point temperatures, K-values, Murphree vapours; a duty-specified
//!      drum takes the temperature at which `h_L(T_N, x_N) = h_V,N−1 − Q_C / V_{N−1}`, a
//!      water-cooled one the same with `Q_C = Qc(T_N)` of the coolant (by bisection).
//!
//!    Vapour side draws enter the energy balance of their tray as `− S^V_i (h_V,i − h_L,i)` and
//!    the component balances with `K'`; a partial condenser's vapour distillate is `V_N = D`.
//!
//!    Tray holdups invert the weir; the drum and sump sit at their nominal holdups.
//! 3. **Newton** on the column's own equations, with a pseudo-transient fallback, finishes the
//!    profile ([`super::polish`]). The bubble-point method converges linearly and, when a
//!    composition front sits next to a product-purity cliff, very slowly (the front drifts a
//!    little each sweep); it only has to bring Newton near a solution.
//!
//! The flowsheet guesses in several sweeps; a later call finds its earlier guess in `own` and only
//! refines it by Newton when that still converges.

use plantwide_thermo::ThermoPackage;

use super::{Condenser, IN_CONDENSER_DUTY, IN_REFLUX, RigorousColumn, coolant_duty};
use crate::UnitIo;
use crate::stream::{F, H, P, T, Z0};
use crate::units::Phase;
use crate::units::column::StageIdx;
use crate::units::outflow::normalized;

/// Most sweeps of the bubble-point method.
pub const MAX_SWEEPS: usize = 100;
/// Largest temperature change [K] of a converged sweep.
pub const TOL_T: f64 = 1e-10;

/// A feed as the profile sees it.
#[derive(Debug, Clone)]
pub(super) struct FeedIn {
    /// Stage (0-based).
    pub stage: usize,
    /// Flow [mol/s].
    pub f: f64,
    /// Composition.
    pub z: Vec<f64>,
    /// Molar enthalpy [J/mol].
    pub h: f64,
}

/// What fixes the steady column.
#[derive(Debug, Clone)]
pub(super) struct Specs {
    /// Stage pressures [Pa].
    pub p: Vec<f64>,
    /// Feeds.
    pub feeds: Vec<FeedIn>,
    /// Side draws (stage, flow [mol/s], drawn from the vapour).
    pub draws: Vec<(usize, f64, bool)>,
    /// Partial condenser (vapour distillate, `V_N = D`).
    pub partial: bool,
    /// Reflux [mol/s].
    pub reflux: f64,
    /// Reboiler duty [W].
    pub q_r: f64,
    /// Condenser duty [W] of a duty-specified drum.
    pub q_c: Option<f64>,
    /// Coolant of a water-cooled drum: flow [kg/s], inlet temperature [K], UA [W/K], c_p [J/(kg K)].
    pub coolant: Option<(f64, f64, f64, f64)>,
    /// Murphree efficiency of the trays.
    pub efficiency: f64,
}

/// A column profile, stages 0-based from the reboiler.
#[derive(Debug, Clone)]
pub(super) struct Profile {
    /// Temperatures [K].
    pub t: Vec<f64>,
    /// Liquid compositions.
    pub x: Vec<Vec<f64>>,
    /// Vapour compositions.
    pub y: Vec<Vec<f64>>,
    /// Liquid flows leaving the stages [mol/s] (`l[0]` the bottoms, `l[N−1]` the reflux).
    pub l: Vec<f64>,
    /// Vapour flows leaving the stages [mol/s].
    pub v: Vec<f64>,
    /// Distillate [mol/s].
    pub d: f64,
}

/// Fill the column's own variables with the cold-start profile (steps 1–3 of the module docs). An
/// earlier guess in `own` (the flowsheet guesses in several sweeps) is only refined by Newton when
/// it is still close.
pub(super) fn guess(col: &RigorousColumn, io: &UnitIo<'_, f64>, own: &mut [f64]) {
    if plausible(col, io, own) && super::polish::polish(col, io, own, false) {
        return;
    }
    let th = io.thermo;
    let feeds: Vec<FeedIn> = col
        .feeds
        .iter()
        .enumerate()
        .map(|(k, &stage)| {
            let s = io.inlet(k);
            FeedIn { stage, f: s.f().max(0.0), z: normalized(s.z()), h: s.h() }
        })
        .collect();
    let specs = Specs {
        p: col.pressure.clone(),
        feeds,
        draws: col
            .draws
            .iter()
            .enumerate()
            .map(|(k, d)| (d.stage, io.input(col.draw_input(k)).max(0.0), d.vapour))
            .collect(),
        partial: col.partial,
        reflux: io.input(IN_REFLUX).max(0.0),
        q_r: col.q_r(io).max(0.0),
        // With a pressure state the profile is that of the drum at its bubble point at the file's
        // pressure: a duty that condenses more or less than the column boils up moves the pressure
        // (Newton's task), where at fixed pressure it would subcool the reflux without bound.
        q_c: match col.condenser {
            Condenser::Duty(_) if col.vapour_volume.is_none() => Some(io.input(IN_CONDENSER_DUTY) + col.q_aux_c(io)),
            _ => None,
        },
        coolant: match col.condenser {
            Condenser::Coolant { t_in, ua, cp, .. } if col.vapour_volume.is_none() => {
                Some((io.input(IN_CONDENSER_DUTY).max(0.0), t_in, ua, cp))
            }
            _ => None,
        },
        efficiency: col.efficiency,
    };
    let prof = bubble_point_profile(th, &specs, cmo_distillate(th, &specs));
    write_own(col, io, &specs, &prof, own);
    super::polish::polish(col, io, own, true);
}

/// Whether `own` looks like a column state: finite, positive holdups and flows, temperatures
/// inside their bounds.
fn plausible(col: &RigorousColumn, io: &UnitIo<'_, f64>, own: &[f64]) -> bool {
    let internal0 = col.n_outlets() * io.layout.stream.len();
    let ix = StageIdx { nc: col.nc() };
    own.iter().all(|v| v.is_finite())
        && (0..col.n_stages).all(|s| {
            let o = internal0 + col.stage(s);
            own[o + ix.m()] > 0.0 && own[o + ix.t()] > 10.0 && own[o + ix.l()] > 0.0
        })
}

/// Write a profile into the own variables.
fn write_own(col: &RigorousColumn, io: &UnitIo<'_, f64>, specs: &Specs, prof: &Profile, own: &mut [f64]) {
    let th = io.thermo;
    let (nc, n) = (col.nc(), col.n_stages);
    let slen = io.layout.stream.len();
    let internal0 = col.n_outlets() * slen;
    let ix = StageIdx { nc };
    let h_l: Vec<f64> = (0..n).map(|s| th.h_liq(prof.t[s], &prof.x[s])).collect();
    for s in 0..n {
        let o = internal0 + col.stage(s);
        let m = match s {
            0 => col.m_reboiler,
            _ if s + 1 == n => col.m_condenser,
            _ => col.weir.holdup(prof.l[s], th.v_liq(prof.t[s], &prof.x[s])),
        };
        for j in 0..nc {
            own[o + ix.n(j)] = m * prof.x[s][j];
            own[o + ix.x(j)] = prof.x[s][j];
            own[o + ix.y(j)] = prof.y[s][j];
        }
        own[o + ix.t()] = prof.t[s];
        own[o + ix.m()] = m;
        own[o + ix.l()] = prof.l[s];
        own[o + ix.v()] = prof.v[s];
    }
    let h_v_drum = th.h_vap(prof.t[n - 1], &prof.y[n - 1]);
    let coolant = specs.coolant.map(|(m, t_in, ua, cp)| coolant_duty(m, prof.t[n - 1], t_in, ua, cp));
    own[internal0 + col.qc()] = specs.q_c.or(coolant).unwrap_or_else(|| {
        let top = n - 2;
        let feed_heat: f64 = specs.feeds.iter().filter(|f| f.stage == n - 1).map(|f| f.f * (f.h - h_l[n - 1])).sum();
        prof.v[top] * (th.h_vap(prof.t[top], &prof.y[top]) - h_l[n - 1]) + feed_heat
            - prof.v[n - 1] * (h_v_drum - h_l[n - 1])
    });
    for k in 0..col.n_outlets() {
        let s = col.outlet_stage(k);
        let flow = match k {
            0 => prof.d,
            1 => prof.l[0],
            _ => specs.draws[k - 2].1,
        };
        let (h, z) =
            if col.outlet_is_vapour(k) { (th.h_vap(prof.t[s], &prof.y[s]), &prof.y[s]) } else { (h_l[s], &prof.x[s]) };
        let rr = &mut own[k * slen..(k + 1) * slen];
        rr[F] = flow;
        rr[T] = prof.t[s];
        rr[P] = col.pressure[s];
        rr[H] = h;
        rr[Z0..Z0 + nc].copy_from_slice(z);
    }
    if let Some(volume) = col.vapour_volume {
        // The vapour space at the top pressure and the drum temperature, of the top tray's vapour.
        let p_top = col.pressure[n - 1];
        let moles = p_top * volume / (plantwide_thermo::R_GAS * prof.t[n - 1]);
        for j in 0..nc {
            own[internal0 + col.nv_var() + j] = moles * prof.y[n - 2][j];
        }
        own[internal0 + col.p_var()] = p_top;
    }
}

/// Net feed minus side draws [mol/s].
fn net_feed(sp: &Specs) -> f64 {
    sp.feeds.iter().map(|f| f.f).sum::<f64>() - sp.draws.iter().map(|d| d.1).sum::<f64>()
}

/// Overall feed composition.
fn mean_feed(th: &ThermoPackage, sp: &Specs) -> Vec<f64> {
    let mut zsum = vec![0.0; th.n()];
    for f in &sp.feeds {
        zsum.iter_mut().zip(&f.z).for_each(|(a, z)| *a += f.f * z);
    }
    normalized(&zsum)
}

/// Distillate [mol/s] by constant molar overflow (step 1 of the module docs).
fn cmo_distillate(th: &ThermoPackage, sp: &Specs) -> f64 {
    let n = sp.p.len();
    let z = mean_feed(th, sp);
    let t = bubble(th, sp.p[n / 2], &z, 350.0);
    let mut k = vec![0.0; z.len()];
    th.k_values(t, sp.p[n / 2], &z, &mut k);
    let y = normalized(&k.iter().zip(&z).map(|(k, z)| k * z).collect::<Vec<_>>());
    let h_l = th.h_liq(t, &z);
    let latent = th.h_vap(t, &y) - h_l;
    let feed_heat: f64 = sp.feeds.iter().map(|f| f.f * (f.h - h_l)).sum();
    let v = (sp.q_r + feed_heat) / latent;
    let out = net_feed(sp);
    let d = v - sp.reflux;
    if d.is_finite() { d.clamp(0.01 * out, 0.99 * out) } else { 0.5 * out }
}

/// Bubble temperature [K] of `x` at `p`, or `fallback` when it cannot be found.
fn bubble(th: &ThermoPackage, p: f64, x: &[f64], fallback: f64) -> f64 {
    th.bubble_t(p, x).map(|b| b.t).ok().filter(|t| t.is_finite()).unwrap_or(fallback)
}

/// Vapours: equilibrium on the reboiler and in the drum, Murphree on the trays.
fn vapours(th: &ThermoPackage, sp: &Specs, t: &[f64], x: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = t.len();
    let mut k = vec![0.0; th.n()];
    let mut y: Vec<Vec<f64>> = Vec::with_capacity(n);
    for s in 0..n {
        th.k_values(t[s], sp.p[s], &x[s], &mut k);
        let eq: Vec<f64> = k.iter().zip(&x[s]).map(|(k, x)| k * x).collect();
        let ys = if s > 0 && s + 1 < n {
            y[s - 1].iter().zip(&eq).map(|(b, e)| b + sp.efficiency * (e - b)).collect()
        } else {
            eq
        };
        y.push(ys);
    }
    y
}

/// Vapour and liquid flows and the distillate from the energy balances (step 2 of the module
/// docs), starting the distillate's fixed point at `d0`.
fn flows(sp: &Specs, h_l: &[f64], h_v: &[f64], d0: f64, eps: f64) -> (Vec<f64>, Vec<f64>, f64) {
    let n = h_l.len();
    let feed_at = |s: usize| sp.feeds.iter().filter(move |f| f.stage == s);
    let draw_at = |s: usize| sp.draws.iter().filter(move |d| d.0 == s).map(|d| d.1).sum::<f64>();
    let vapour_draw_at = |s: usize| sp.draws.iter().filter(move |d| d.0 == s && d.2).map(|d| d.1).sum::<f64>();
    // Σ_{k>s} (F_k − S_k): what enters the section above stage s besides V_s, net of side draws.
    let mut above = vec![0.0; n];
    for s in (0..n - 1).rev() {
        above[s] = above[s + 1] + feed_at(s + 1).map(|f| f.f).sum::<f64>() - draw_at(s + 1);
    }
    let mut v = vec![0.0; n];
    let mut d = d0.max(eps);
    for _ in 0..100 {
        for s in 0..n - 1 {
            let g = above[s] - d;
            let mut num = g * (h_l[s + 1] - h_l[s]) + feed_at(s).map(|f| f.f * (f.h - h_l[s])).sum::<f64>();
            num += if s > 0 { v[s - 1] * (h_v[s - 1] - h_l[s]) } else { sp.q_r };
            num -= vapour_draw_at(s) * (h_v[s] - h_l[s]);
            v[s] = (num / (h_v[s] - h_l[s + 1])).max(eps);
        }
        let d_new = (v[n - 2] + above[n - 2] - sp.reflux).max(eps);
        let done = (d_new - d).abs() <= 1e-13 * (d + sp.reflux);
        d = d_new;
        if done {
            break;
        }
    }
    let mut l = vec![0.0; n];
    l[0] = (net_feed(sp) - d).max(eps);
    for s in 0..n - 2 {
        l[s + 1] = (v[s] + above[s] - d).max(eps);
    }
    l[n - 1] = sp.reflux;
    if sp.partial {
        v[n - 1] = d;
    }
    (v, l, d)
}

/// The column state the sweeps carry.
#[derive(Debug, Clone)]
struct State {
    t: Vec<f64>,
    x: Vec<Vec<f64>>,
    y: Vec<Vec<f64>>,
    v: Vec<f64>,
    l: Vec<f64>,
}

/// Bubble-point sweeps until the temperatures settle; returns the distillate.
fn sweeps(th: &ThermoPackage, sp: &Specs, mut d: f64, eps: f64, st: &mut State) -> f64 {
    let (n, nc) = (sp.p.len(), th.n());
    let draw_at =
        |s: usize, vapour: bool| sp.draws.iter().filter(|d| d.0 == s && d.2 == vapour).map(|d| d.1).sum::<f64>();
    let (mut a, mut b, mut c, mut rhs) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for _ in 0..MAX_SWEEPS {
        let h_l: Vec<f64> = (0..n).map(|s| th.h_liq(st.t[s], &st.x[s])).collect();
        let h_v: Vec<f64> = (0..n).map(|s| th.h_vap(st.t[s], &st.y[s])).collect();
        (st.v, st.l, d) = flows(sp, &h_l, &h_v, d, eps);
        let (v, l) = (&st.v, &st.l);
        let k_eff: Vec<Vec<f64>> = (0..n)
            .map(|s| (0..nc).map(|j| if st.x[s][j] > 1e-300 { st.y[s][j] / st.x[s][j] } else { 0.0 }).collect())
            .collect();
        let mut x_new = vec![vec![0.0; nc]; n];
        for j in 0..nc {
            for s in 0..n {
                a[s] = if s > 0 { v[s - 1] * k_eff[s - 1][j] } else { 0.0 };
                let total_d = if s + 1 == n && !sp.partial { d } else { 0.0 };
                b[s] = -(l[s] + draw_at(s, false) + (v[s] + draw_at(s, true)) * k_eff[s][j] + total_d);
                c[s] = if s + 1 < n { l[s + 1] } else { 0.0 };
                rhs[s] = -sp.feeds.iter().filter(|f| f.stage == s).map(|f| f.f * f.z[j]).sum::<f64>();
            }
            for (s, xs) in thomas(&a, &b, &c, &rhs).into_iter().enumerate() {
                x_new[s][j] = if xs.is_finite() { xs.max(0.0) } else { st.x[s][j] };
            }
        }
        let x_new: Vec<Vec<f64>> = x_new.iter().map(|xs| normalized(xs)).collect();
        let mut t_new: Vec<f64> = (0..n).map(|s| bubble(th, sp.p[s], &x_new[s], st.t[s])).collect();
        if let Some(q_c) = sp.q_c {
            let h_target = h_v[n - 2] - q_c / v[n - 2];
            t_new[n - 1] = Phase::Liquid.temperature(th, h_target, sp.p[n - 1], &x_new[n - 1], t_new[n - 1]);
        }
        if let Some(c) = sp.coolant {
            t_new[n - 1] = coolant_drum_temperature(th, c, h_v[n - 2], v[n - 2], &x_new[n - 1], t_new[n - 1]);
        }
        let change = st.t.iter().zip(&t_new).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        st.x = x_new;
        st.t = t_new;
        st.y = vapours(th, sp, &st.t, &st.x);
        if change <= TOL_T {
            break;
        }
    }
    d
}

/// Temperature of a water-cooled drum of liquid `x` fed the vapour flow `v` [mol/s] of molar enthalpy
/// `h_v` (coolant `(m, T_in, UA, c_p)`): the root of `h_L(T, x) − h_v + Qc(T) / v = 0` between the
/// coolant inlet and the bubble point `t_bubble` (both sides increase with `T`), by bisection; the
/// bubble point when the coolant cannot condense all the vapour there.
fn coolant_drum_temperature(
    th: &ThermoPackage,
    (m, t_in, ua, cp): (f64, f64, f64, f64),
    h_v: f64,
    v: f64,
    x: &[f64],
    t_bubble: f64,
) -> f64 {
    let f = |t: f64| th.h_liq(t, x) - h_v + coolant_duty(m, t, t_in, ua, cp) / v.max(1e-300);
    let (mut lo, mut hi) = (t_in.min(t_bubble), t_bubble);
    let (f_lo, f_hi) = (f(lo), f(hi));
    if f_lo.is_nan() || f_hi.is_nan() || f_lo >= 0.0 || f_hi <= 0.0 {
        return t_bubble;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            hi = mid
        } else {
            lo = mid
        }
        if hi - lo <= 1e-12 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// The column at the reflux and reboiler duty of `sp` by the bubble-point method (step 2 of the
/// module docs), the distillate's fixed point started at `d0`.
pub(super) fn bubble_point_profile(th: &ThermoPackage, sp: &Specs, d0: f64) -> Profile {
    let n = sp.p.len();
    let z = mean_feed(th, sp);
    let eps = 1e-9 * net_feed(sp).max(sp.reflux).max(1e-9);
    let t0 = bubble(th, sp.p[n - 1], &z, 350.0);
    let t: Vec<f64> = sp.p.iter().map(|&p| bubble(th, p, &z, t0)).collect();
    let x = vec![z; n];
    let y = vapours(th, sp, &t, &x);
    let mut st = State { t, x, y, v: vec![0.0; n], l: vec![0.0; n] };
    let d = sweeps(th, sp, d0, eps, &mut st);
    Profile { t: st.t, x: st.x, y: st.y, l: st.l, v: st.v, d }
}

/// Solve the tridiagonal system `a_i u_{i−1} + b_i u_i + c_i u_{i+1} = r_i` (Thomas algorithm,
/// stable for the column-diagonally-dominant component balances).
fn thomas(a: &[f64], b: &[f64], c: &[f64], r: &[f64]) -> Vec<f64> {
    let n = b.len();
    let mut cp = vec![0.0; n];
    let mut rp = vec![0.0; n];
    for i in 0..n {
        let prev_c = if i > 0 { cp[i - 1] } else { 0.0 };
        let prev_r = if i > 0 { rp[i - 1] } else { 0.0 };
        let m = b[i] - a[i] * prev_c;
        cp[i] = c[i] / m;
        rp[i] = (r[i] - a[i] * prev_r) / m;
    }
    let mut u = vec![0.0; n];
    for i in (0..n).rev() {
        u[i] = rp[i] - if i + 1 < n { cp[i] * u[i + 1] } else { 0.0 };
    }
    u
}
