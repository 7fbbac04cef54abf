//! A distillation column as an engineer designs it before typing it in: stages, the split they
//! reach at a multiple of the minimum reflux (Fenske, Underwood, Gilliland), Kirkbride's feed
//! stage, the flows of the material balance, drums and trays sized by residence time, the LV
//! configuration's level loops; and, once the open plant has been converged, its quality loops
//! with setpoints read off that steady state (`quality_loops`).

use plantwide::thermo::ThermoPackage;

use super::doc::{J, obj, q, round_sig};
use super::rng::Rng;
use super::shortcut::{PUREST, Split, gilliland, kirkbride, reachable_split, underwood};
use super::thermo;

/// Uniform in `[lo, hi)`.
pub fn uniform(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * rng.unit()
}

/// Log-uniform in `[lo, hi)`.
pub fn log_uniform(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
    (lo.ln() + (hi.ln() - lo.ln()) * rng.unit()).exp()
}

/// Units a flow, amount, time, pressure, temperature or duty may be written in.
pub const FLOW: &[&str] = &["kmol/h", "kmol/min", "mol/s", "lbmol/h"];
pub const AMOUNT: &[&str] = &["kmol", "mol", "lbmol"];
pub const TIME: &[&str] = &["min", "s", "h"];
pub const PRESSURE: &[&str] = &["atm", "kPa", "bar", "psia"];
pub const TEMPERATURE: &[&str] = &["K", "degC", "degF"];
pub const DUTY: &[&str] = &["MW", "kW", "Btu/h"];

/// One of `units`, drawn.
pub fn unit_of(rng: &mut Rng, units: &[&'static str]) -> &'static str {
    units[rng.below(units.len())]
}

/// A level loop's gain written as a flow per amount (`"0.5 kmol/min/kmol"`) for `per_s` [1/s].
pub fn per_time(rng: &mut Rng, per_s: f64) -> J {
    let (f, a) = (*rng.pick(FLOW), unit_of(rng, AMOUNT));
    let factor =
        plantwide::units::convert_from_si(1.0, f).unwrap() / plantwide::units::convert_from_si(1.0, a).unwrap();
    J::S(format!("{} {f}/{a}", round_sig(per_s * factor, 4)))
}

/// Which column model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Model {
    /// Constant molar overflow (`"model": "simple"`).
    Simple,
    /// Energy balances and tray hydraulics (`"model": "rigorous"`).
    Rigorous,
}

/// What the plant around a column gives it.
pub struct Request<'a> {
    /// Unit name.
    pub name: &'a str,
    /// Model.
    pub model: Model,
    /// The package, to estimate volatilities and latent heats (`None`: constant α `alpha`).
    pub pkg: Option<&'a ThermoPackage>,
    /// Constant relative volatility of a hypothetical pair.
    pub alpha: f64,
    /// Feed [mol/s], its light fraction and quality.
    pub f: f64,
    /// Light fraction of the feed.
    pub zf: f64,
    /// Feed quality (simple model).
    pub q: f64,
    /// Top pressure [Pa].
    pub p_top: f64,
    /// Stages range.
    pub stages: (usize, usize),
    /// Reflux over its minimum range.
    pub m: (f64, f64),
    /// A split the plant needs (a recycle's design), instead of the purest the stages reach.
    pub split: Option<Split>,
}

/// The designed column.
pub struct Column {
    /// Unit name.
    pub name: String,
    /// Model.
    pub model: Model,
    /// Stages (1 = reboiler, N = condenser) and the feed stage.
    pub stages: usize,
    /// Feed stage.
    pub feed_stage: usize,
    /// Design relative volatility, reflux over minimum, the design split.
    pub alpha: f64,
    /// R / R_min.
    pub m: f64,
    /// Design split.
    pub split: Split,
    /// Design flows [mol/s]: reflux, boilup, distillate, bottoms.
    pub l: f64,
    /// Boilup.
    pub v: f64,
    /// Distillate.
    pub d: f64,
    /// Bottoms.
    pub b: f64,
    /// Reboiler duty [W] (rigorous).
    pub duty: f64,
    /// The unit's description.
    pub unit: J,
    /// The condenser and reboiler level loops.
    pub levels: Vec<(String, J)>,
}

impl Column {
    /// The input the bottom quality loop moves: `boilup` or `reboiler_duty`.
    pub fn heat_input(&self) -> String {
        let which = if self.model == Model::Simple { "boilup" } else { "reboiler_duty" };
        format!("{}.{which}", self.name)
    }

    /// One line of the design.
    pub fn about(&self) -> String {
        format!(
            "{:?} column: {} stages, feed on {}, alpha {:.3}, R = {:.2} R_min, design xD {:.5} xB {:.5}",
            self.model, self.stages, self.feed_stage, self.alpha, self.m, self.split.xd, self.split.xb
        )
    }
}

/// The reboiler duty \[W\] that gives the design's flows `(l, d, b)` on a rigorous column: the
/// energy balance around the column with a total condenser returning saturated reflux,
/// `Q_R = Q_C + D h_L(x_D) + B h_L(x_B) − F h_F`, `Q_C = (L + D)(h_V − h_L)(x_D)` at the top,
/// the feed a liquid at its bubble point at the mean pressure. Constant molar overflow (`V` times
/// the bottoms' latent heat) is off by the ratio of the latent heats: 15 % for methanol–water,
/// which boiled more than reached the reboiler on plant 0x65d44e50b4502fc9 (no steady state).
fn reboiler_duty(pkg: &ThermoPackage, r: &Request<'_>, split: Split, (l, d, b): (f64, f64, f64), p_bottom: f64) -> f64 {
    let liquid = |p: f64, x: f64| pkg.h_liq(thermo::bubble_t(pkg, p, &[x, 1.0 - x]), &[x, 1.0 - x]);
    let condenser = (l + d) * thermo::latent_heat(pkg, r.p_top, &[split.xd, 1.0 - split.xd]);
    let feed = liquid(0.5 * (r.p_top + p_bottom), r.zf);
    condenser + d * liquid(r.p_top, split.xd) + b * liquid(p_bottom, split.xb) - r.f * feed
}

/// Design the column of `r`, its level loops named `names`. A column whose stages would reach
/// beyond [`PUREST`] at its reflux gets the stages that purity needs (at least 10): an engineer
/// does not build 50 trays for what 20 do, and a column run at its design flows with twice the
/// stages it needs makes parts per billion.
pub fn design(rng: &mut Rng, r: &Request<'_>, names: [&str; 2]) -> Column {
    let m = log_uniform(rng, r.m.0, r.m.1);
    let mut n = r.stages.0 + rng.below(r.stages.1 - r.stages.0 + 1);
    let skew = log_uniform(rng, 0.3, 3.0);
    let dp = if r.model == Model::Rigorous { uniform(rng, 400.0, 900.0) } else { 0.0 };
    let (mut alpha, mut split) = volatility_and_split(r, m, n, skew, dp);
    if r.split.is_none() && 1.0 - split.xd <= PUREST * (1.0 + 1e-9) {
        let needed = ((stages_for(alpha, r.zf, r.q, m, split) - 1.0) / 0.8).ceil() as usize + 1;
        n = needed.clamp(10, n);
        (alpha, split) = volatility_and_split(r, m, n, skew, dp);
    }
    let p_bottom = r.p_top + (n - 1) as f64 * dp;
    let d = r.f * (r.zf - split.xb) / (split.xd - split.xb);
    let b = r.f - d;
    let l = m * underwood(alpha, r.zf, r.q, split.xd) * d;
    let v = l + d - (1.0 - r.q) * r.f;
    let ratio = kirkbride(r.zf, split, d / b);
    let kirk = ((n - 2) as f64 / (1.0 + ratio)).round() as i64 + 1;
    let feed_stage = (kirk + rng.below(5) as i64 - 2).clamp(3, n as i64 - 2) as usize;
    let duty = r.pkg.map_or(0.0, |p| reboiler_duty(p, r, split, (l, d, b), p_bottom)) * uniform(rng, 1.0, 1.05);
    let mut c = Column {
        name: r.name.to_string(),
        model: r.model,
        stages: n,
        feed_stage,
        alpha,
        m,
        split,
        l,
        v,
        d,
        b,
        duty,
        unit: J::B(false),
        levels: Vec::new(),
    };
    let (drum, sump) = (uniform(rng, 3.0, 8.0) * 60.0 * (l + d), uniform(rng, 3.0, 8.0) * 60.0 * (v + b));
    c.unit = unit_description(rng, r, &c, drum, sump, dp);
    c.levels = level_loops(rng, &c, drum, sump, names);
    c
}

/// The design volatility and the split `n` stages reach at `m` R_min (a library pair's volatility
/// at the top and bottom of the split, estimated at the feed first).
fn volatility_and_split(r: &Request<'_>, m: f64, n: usize, skew: f64, dp: f64) -> (f64, Split) {
    let p_bottom = r.p_top + (n - 1) as f64 * dp;
    let volatility = |s: Option<Split>| match (r.pkg, s) {
        (None, _) => r.alpha,
        (Some(p), None) => thermo::alpha(p, 0.5 * (r.p_top + p_bottom), &[r.zf, 1.0 - r.zf]),
        (Some(p), Some(s)) => {
            (thermo::alpha(p, r.p_top, &[s.xd, 1.0 - s.xd]) * thermo::alpha(p, p_bottom, &[s.xb, 1.0 - s.xb])).sqrt()
        }
    };
    let reach = |alpha: f64| r.split.unwrap_or_else(|| reachable_split(alpha, r.zf, r.q, m, (n - 1) as f64, skew, 0.8));
    let alpha = volatility(None);
    match r.pkg {
        Some(_) => {
            let alpha = volatility(Some(reach(alpha)));
            (alpha, reach(alpha))
        }
        None => (alpha, reach(alpha)),
    }
}

/// `"units": {"<name>": …}` of the column.
fn unit_description(rng: &mut Rng, r: &Request<'_>, c: &Column, drum: f64, sump: f64, dp: f64) -> J {
    let (flow, amount) = (*rng.pick(FLOW), unit_of(rng, AMOUNT));
    let mut feed = obj([("port", "feed".into()), ("stage", c.feed_stage.into())]);
    if r.model == Model::Simple && r.pkg.is_none() {
        feed.set(&["q"], J::N(r.q));
    }
    let mut u = obj([
        ("type", "column".into()),
        ("model", if r.model == Model::Simple { "simple" } else { "rigorous" }.into()),
        ("stages", c.stages.into()),
        ("feeds", J::A(vec![feed])),
        ("P", q(r.p_top, unit_of(rng, PRESSURE), 5)),
    ]);
    if r.model == Model::Simple {
        let tray = uniform(rng, 0.3, 1.0) * 60.0 * r.f;
        u.set(&["tray_holdup"], q(tray, amount, 3));
    }
    u.set(&["condenser_holdup"], q(drum, amount, 3));
    u.set(&["reboiler_holdup"], q(sump, amount, 3));
    if r.model == Model::Simple {
        u.set(&["tau_l"], q(uniform(rng, 0.04, 0.15) * 60.0, unit_of(rng, &["min", "s"]), 3));
    }
    u.set(&["reflux"], q(c.l, flow, 6));
    if r.model == Model::Simple {
        u.set(&["boilup"], q(c.v, flow, 6));
    }
    u.set(&["distillate"], q(c.d, flow, 6));
    u.set(&["bottoms"], q(c.b, flow, 6));
    if r.model == Model::Rigorous {
        let p_scale = (101_325.0 / r.p_top).sqrt();
        let area = c.v * 0.022 * p_scale * uniform(rng, 0.8, 1.3);
        let mut rig = obj([
            ("reboiler_duty", q(c.duty, unit_of(rng, DUTY), 6)),
            ("tray_pressure_drop", q(dp, "kPa", 2)),
            ("weir_length", q(0.75 * area.sqrt() * uniform(rng, 0.9, 1.1), "m", 2)),
            ("weir_height", q(uniform(rng, 0.04, 0.06), "mm", 2)),
            ("tray_area", q(area, "m2", 3)),
        ]);
        if rng.chance(0.3) {
            rig.set(&["murphree_efficiency"], J::N(round_sig(uniform(rng, 0.7, 1.0), 2)));
        }
        u.set(&["rigorous"], rig);
    }
    u
}

/// The LV configuration's inventory loops: the condenser's holdup by the distillate, the
/// reboiler's by the bottoms; P only, sometimes PI.
fn level_loops(rng: &mut Rng, c: &Column, drum: f64, sump: f64, names: [&str; 2]) -> Vec<(String, J)> {
    let amount = *rng.pick(AMOUNT);
    let mut lp = |stage: usize, output: &str, holdup: f64| {
        let tau = uniform(rng, 0.5, 5.0) * 60.0;
        let mut ctrl = obj([
            ("type", "pid".into()),
            ("pv", format!("{}.M[{stage}]", c.name).into()),
            ("output", format!("{}.{output}", c.name).into()),
            ("sp", q(holdup, amount, 3)),
            ("kc", per_time(rng, 1.0 / tau)),
        ]);
        if rng.chance(0.25) {
            ctrl.set(&["tau_i"], q(uniform(rng, 10.0, 60.0) * 60.0, unit_of(rng, TIME), 3));
        }
        ctrl.set(&["action"], "direct".into());
        ctrl
    };
    let top = lp(c.stages, "distillate", drum);
    let bottom = lp(1, "bottoms", sump);
    vec![(names[0].to_string(), top), (names[1].to_string(), bottom)]
}

/// How the bottom of a column is controlled.
#[derive(Debug, Clone, PartialEq)]
pub enum BottomLoop {
    /// The bottoms' light fraction.
    Composition,
    /// A stripping-section tray's temperature, on this stage.
    Temperature(usize),
}

/// The quality loops of column `c` (named `names`), their setpoints read off the open plant's
/// steady state `value`: the distillate's purity by reflux (reverse acting), and the bottoms'
/// impurity (direct) or a tray temperature (reverse) by the boilup or reboiler duty.
pub fn quality_loops(
    rng: &mut Rng,
    c: &Column,
    streams: [&str; 2],
    light: &str,
    bottom: &BottomLoop,
    names: [&str; 2],
    value: &dyn Fn(&str) -> f64,
) -> Vec<(String, J)> {
    let (top_pv, bottom_pv) = (format!("{}.x[{light}]", streams[0]), format!("{}.x[{light}]", streams[1]));
    let holdup: f64 = (1..=c.stages).map(|k| value(&format!("{}.M[{k}]", c.name))).sum();
    let feed = c.d + c.b;
    let tau_i = uniform(rng, 1.0, 3.0) * (holdup / feed).max(600.0);
    let (xd, flow) = (value(&top_pv), unit_of(rng, FLOW));
    let delta_d = round_sig(1.0 - xd, 3).max(1e-9);
    // The gains move the input 1–4 % for an error the size of the impurity, but no faster than
    // for an impurity of 0.1 %: a user does not type 2e7 mol/s per mole fraction (the engine
    // refuses a `kc` beyond 1e6 mol/s).
    let span = |x: f64| x.max(1e-3);
    let l = value(&format!("{}.reflux", c.name));
    let top = obj([
        ("type", "pid".into()),
        ("pv", top_pv.into()),
        ("output", format!("{}.reflux", c.name).into()),
        ("sp", J::N(round_sig(1.0 - delta_d, 12))),
        ("kc", q(uniform(rng, 0.01, 0.04) * l / span(delta_d), flow, 3)),
        ("tau_i", q(tau_i, unit_of(rng, TIME), 3)),
        ("action", "reverse".into()),
        ("op_min", q(0.0, flow, 3)),
        ("op_max", q(3.0 * l, flow, 3)),
    ]);
    let heat = c.heat_input();
    let (u0, unit) = match c.model {
        Model::Simple => (value(&heat), flow),
        Model::Rigorous => (value(&heat), unit_of(rng, DUTY)),
    };
    let (pv, sp, kc, action) = match bottom {
        BottomLoop::Composition => {
            let xb = round_sig(value(&bottom_pv), 3).max(1e-9);
            (bottom_pv, J::N(xb), q(uniform(rng, 0.01, 0.04) * u0 / span(xb), unit, 3), "direct")
        }
        BottomLoop::Temperature(k) => {
            let span = value(&format!("{}.T[1]", c.name)) - value(&format!("{}.T[{}]", c.name, c.stages));
            let t = value(&format!("{}.T[{k}]", c.name));
            let per_k = uniform(rng, 0.5, 2.0) * u0 / span.max(1.0);
            let kc =
                J::S(format!("{} {unit}/K", round_sig(plantwide::units::convert_from_si(per_k, unit).unwrap(), 3)));
            (format!("{}.T[{k}]", c.name), q(t, unit_of(rng, TEMPERATURE), 7), kc, "reverse")
        }
    };
    let bottom = obj([
        ("type", "pid".into()),
        ("pv", pv.into()),
        ("output", heat.into()),
        ("sp", sp),
        ("kc", kc),
        ("tau_i", q(tau_i, unit_of(rng, TIME), 3)),
        ("action", action.into()),
        ("op_min", q(0.0, unit, 3)),
        ("op_max", q(3.0 * u0, unit, 3)),
    ]);
    vec![(names[0].to_string(), top), (names[1].to_string(), bottom)]
}

/// The stripping-section tray whose temperature moves most from tray to tray in `value`'s
/// profile (where a temperature loop belongs), if the column reports temperatures.
pub fn sensitive_tray(c: &Column, value: &dyn Fn(&str) -> Option<f64>) -> Option<usize> {
    let t = |k: usize| value(&format!("{}.T[{k}]", c.name));
    (2..c.feed_stage.max(3))
        .filter_map(|k| Some((k, (t(k - 1)? - t(k + 1)?).abs())))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(k, _)| k)
}

/// The stages Gilliland asks for `split` at `m` R_min (recycle designs size the column from it).
pub fn stages_for(alpha: f64, zf: f64, q: f64, m: f64, split: Split) -> f64 {
    let r_min = underwood(alpha, zf, q, split.xd);
    gilliland(super::shortcut::fenske(alpha, split), r_min, m * r_min) + 1.0
}
