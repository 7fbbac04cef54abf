//! The plant families, each drawn from a seed: a column alone (constant-α or rigorous), a flash →
//! surge tank → column train, and a reactor–column recycle. A family builds the *open* plant
//! first (level loops only, the flows of its design), converges it through the library as a user
//! runs `steady` on a first draft, and closes the quality loops at the purities (or tray
//! temperature) that steady state shows. Every plant carries the roles the studies need: the
//! throughput input, the column and its qualities and handles, the vessels to size, and the
//! `--set` edits with the same edits written into the file.

use plantwide::flowsheet::{Override, Plant, load_str_with};
use plantwide::solve::{Solution, StrategySettings, converge};

use super::column::{self, BottomLoop, Column, Model, Request, log_uniform, uniform, unit_of};
use super::doc::{J, obj, q, quantity, round_sig};
use super::rng::Rng;
use super::shortcut::Split;
use super::thermo::{self, PAIRS};

/// A plant family.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Family {
    /// A constant-α column with level and quality loops.
    SimpleColumn,
    /// A rigorous column of a library binary.
    RigorousColumn,
    /// Feed heater, flash drum, surge tank, column.
    Train,
    /// CSTR A → B whose unreacted A a column recycles.
    Recycle,
}

/// A `--set PATH=VALUE` and the same edit written into the file.
#[derive(Debug, Clone)]
pub struct Edit {
    /// `PATH=VALUE`.
    pub set: String,
    /// The members of the file it changes (path in the document, new value).
    pub file: Vec<(Vec<String>, J)>,
}

/// What the studies need to know of a plant.
#[derive(Debug, Clone, Default)]
pub struct Roles {
    /// The input that sets the throughput (disturbances step it).
    pub throughput: String,
    /// Its value [SI].
    pub throughput_si: f64,
    /// The column.
    pub column: String,
    /// Distillate and bottoms stream names.
    pub products: [String; 2],
    /// The light component.
    pub light: String,
    /// The quality CVs of the closed plant (top purity; bottom impurity or tray temperature).
    pub cvs: [String; 2],
    /// The handles of the quality loops (reflux; boilup or reboiler duty).
    pub mvs: [String; 2],
    /// The quality controllers (top, bottom).
    pub quality: [String; 2],
    /// The level controllers of the column (condenser, reboiler).
    pub levels: [String; 2],
    /// Vessels `size` may size (a tank, flash, CSTR, `COL.sump`, or a stream).
    pub vessels: Vec<String>,
    /// `--set` edits.
    pub edits: Vec<Edit>,
    /// Streams: name, from unit, to unit (for the certificate).
    pub streams: Vec<(String, String, String)>,
    /// Units that react (mass balance) and every component's molar mass [kg/mol].
    pub reacting: Vec<String>,
    /// Molar masses [kg/mol] by component.
    pub mw: Vec<(String, f64)>,
}

/// A generated plant.
#[derive(Debug, Clone)]
pub struct Case {
    /// Its seed.
    pub seed: u64,
    /// Family.
    pub family: Family,
    /// Its parameters in one line.
    pub about: String,
    /// The plant with its quality loops (what a user runs).
    pub closed: J,
    /// The plant without them (its design run; `gains`, `identify` and `screen --column` use it).
    pub open: J,
    /// Roles.
    pub roles: Roles,
}

/// A plant the generator could not finish: its open draft did not converge.
pub struct Unfinished {
    /// The family.
    pub family: Family,
    /// The open draft's text.
    pub open: String,
    /// The solver's message.
    pub message: String,
}

/// The plant of `seed`.
pub fn generate(seed: u64) -> Result<Case, Box<Unfinished>> {
    let mut rng = Rng::new(seed);
    let (family, draft) = draft_with(&mut rng);
    close(&mut rng, seed, family, draft)
}

/// The open draft of plant `seed` (its design, before the engine sees it).
pub fn draft(seed: u64) -> (Family, Draft) {
    draft_with(&mut Rng::new(seed))
}

fn draft_with(rng: &mut Rng) -> (Family, Draft) {
    let family = match rng.below(10) {
        0..=2 => Family::SimpleColumn,
        3..=5 => Family::RigorousColumn,
        6..=7 => Family::Train,
        _ => Family::Recycle,
    };
    let draft = match family {
        Family::SimpleColumn => simple_column(rng),
        Family::RigorousColumn => rigorous_column(rng),
        Family::Train => train(rng),
        Family::Recycle => recycle(rng),
    };
    (family, draft)
}

/// An open plant and what closing it needs.
pub struct Draft {
    /// The document.
    pub doc: J,
    /// The column.
    pub column: Column,
    /// Its bottom quality loop: composition, or temperature (stage chosen once converged).
    pub temperature_loop: bool,
    /// Names of the quality loops.
    pub quality: [&'static str; 2],
    /// Roles so far.
    pub roles: Roles,
    /// Parameters in words.
    pub about: String,
}

/// The open draft with its column's reflux and heat input at the values that meet the design split,
/// written into the document in the units it has, and that plant converged. The values are found
/// as a user of a dynamic simulator finds them: two PI loops hold `x_D` by the reflux and `x_B` by
/// the heat input at the design split and the plant is converged (from the open plant's state,
/// the loops closed along their setpoints where the cold start fails: `converge`'s homotopy). The
/// shortcut design (Underwood, Fenske, a mean α, a flash taken isothermal where the plant's is
/// adiabatic) can miss the split by orders of magnitude on a nonideal pair (a 1e-15 bottoms
/// impurity for a designed 1.2e-4), and a user designs to the split, not to the shortcut's flows.
/// `None` (the draft kept) where that plant does not converge.
fn meet_design(d: &mut Draft, plant: &Plant, sol: &Solution) -> Option<(Plant, Solution)> {
    let c = &d.column;
    let (light, products) = (&d.roles.light, &d.roles.products);
    let value = |path: &str| plant.input(path).map(|i| sol.u[i]);
    let (reflux, heat) = (format!("{}.reflux", c.name), c.heat_input());
    let unit = if c.model == Model::Simple { "mol/s" } else { "W" };
    let pi = |stream: &str, sp: f64, output: &str, kc: f64, unit: &str, action: &str| {
        obj([
            ("type", "pid".into()),
            ("pv", format!("{stream}.x[{light}]").into()),
            ("output", output.into()),
            ("sp", J::N(sp)),
            ("kc", J::S(format!("{kc:e} {unit}"))),
            ("tau_i", "1 h".into()),
            ("action", action.into()),
        ])
    };
    let mut held = d.doc.clone();
    let top = pi(
        &products[0],
        c.split.xd,
        &reflux,
        0.02 * value(&reflux)? / (1.0 - c.split.xd).max(1e-3),
        "mol/s",
        "reverse",
    );
    let bottom = pi(&products[1], c.split.xb, &heat, 0.02 * value(&heat)? / c.split.xb.max(1e-3), unit, "direct");
    held.set(&["controllers", "design_top"], top);
    held.set(&["controllers", "design_bottom"], bottom);
    let held_plant = load_str_with(&held.render(), "generated", &[] as &[Override]).ok()?;
    let met = converge(&held_plant, &StrategySettings::default()).ok()?;
    let mut designed = d.doc.clone();
    for (path, ctrl) in [(&reflux, "design_top"), (&heat, "design_bottom")] {
        let op = met.x[held_plant.var(format!("{ctrl}.op"))?];
        let field = path.rsplit('.').next().unwrap_or_default();
        let at: Vec<&str> = match field {
            "reboiler_duty" => vec!["units", &c.name, "rigorous", field],
            _ => vec!["units", &c.name, field],
        };
        let Some(J::S(text)) = designed.at(&at) else { return None };
        let unit = text.split_once(' ')?.1.to_string();
        designed.set(&at, q(op, &unit, 6));
    }
    let plant = load_str_with(&designed.render(), "generated", &[] as &[Override]).ok()?;
    let sol = converge(&plant, &StrategySettings::default()).ok()?;
    d.doc = designed;
    Some((plant, sol))
}

/// Converge the draft, add the quality loops at its steady state, finish the roles and edits.
fn close(rng: &mut Rng, seed: u64, family: Family, mut d: Draft) -> Result<Case, Box<Unfinished>> {
    let text = d.doc.render();
    let unfinished = |message: String| Box::new(Unfinished { family, open: text.clone(), message });
    let plant = load_str_with(&text, "generated", &[] as &[Override]).map_err(|e| unfinished(e.to_string()))?;
    let sol = converge(&plant, &StrategySettings::default()).map_err(|e| unfinished(e.to_string()))?;
    let (plant, sol) = match meet_design(&mut d, &plant, &sol) {
        Some(met) => met,
        None => (plant, sol),
    };
    let values: std::collections::HashMap<String, f64> = sol.values(&plant).into_iter().collect();
    let get = |p: &str| values.get(p).copied();
    let value = |p: &str| get(p).unwrap_or_else(|| panic!("generator: the open plant has no `{p}`"));
    let c = &d.column;
    let bottom = match d.temperature_loop.then(|| column::sensitive_tray(c, &get)).flatten() {
        Some(k) => BottomLoop::Temperature(k),
        None => BottomLoop::Composition,
    };
    let products = [d.roles.products[0].as_str(), d.roles.products[1].as_str()];
    let loops = column::quality_loops(rng, c, products, &d.roles.light, &bottom, d.quality, &value);
    let mut closed = d.doc.clone();
    for (name, ctrl) in loops {
        closed.set(&["controllers", &name], ctrl);
    }
    let light = d.roles.light.clone();
    d.roles.cvs = [
        format!("{}.x[{light}]", products[0]),
        match bottom {
            BottomLoop::Composition => format!("{}.x[{light}]", products[1]),
            BottomLoop::Temperature(k) => format!("{}.T[{k}]", c.name),
        },
    ];
    d.roles.mvs = [format!("{}.reflux", c.name), c.heat_input()];
    d.roles.quality = d.quality.map(String::from);
    d.roles.edits.extend(quality_edits(rng, &closed, &d.roles, &value));
    let about = format!("{}; {}; bottom loop {bottom:?}", d.about, c.about());
    Ok(Case { seed, family, about, closed, open: d.doc, roles: d.roles })
}

/// `--set` edits of the quality and level loops: the top setpoint a little less pure, a level
/// gain in other units.
fn quality_edits(rng: &mut Rng, closed: &J, roles: &Roles, value: &dyn Fn(&str) -> f64) -> Vec<Edit> {
    let top = &roles.quality[0];
    let xd = value(&roles.cvs[0]);
    let sp = round_sig(1.0 - round_sig((1.0 - xd) * uniform(rng, 1.1, 1.5), 3), 12);
    let mut edits = Vec::new();
    // A purity, not a column that barely separates (a rigorous design whose duty estimate fell
    // short: xD 0.45 would become a setpoint of 0.28, no question a user asks).
    if xd > 0.9 {
        let file = vec![(vec!["controllers".into(), top.clone(), "sp".into()], J::N(sp))];
        edits.push(Edit { set: format!("{top}.sp={sp}"), file });
    }
    let level = &roles.levels[rng.below(2)];
    if let Some(J::S(kc)) = closed.at(&["controllers", level, "kc"]) {
        let per_s = plantwide::units::parse_quantity(kc).map(|q| q.value_si).unwrap_or(1e-3);
        let factor = uniform(rng, 0.5, 2.0);
        let new = column::per_time(rng, per_s * factor);
        if let J::S(text) = &new {
            edits.push(Edit {
                set: format!("{level}.kc={text}"),
                file: vec![(vec!["controllers".into(), level.clone(), "kc".into()], new.clone())],
            });
        }
    }
    edits
}

/// An edit of a unit's field given as a quantity.
fn unit_edit(unit: &str, field: &str, text: String) -> Edit {
    Edit {
        set: format!("{unit}.{field}={text}"),
        file: vec![(vec!["units".into(), unit.into(), field.into()], J::S(text))],
    }
}

/// The throughput edits of a binary feed: its flow in another unit, its light fraction moved.
fn feed_edits(rng: &mut Rng, feed: &str, f: f64, z: Option<(&str, &str, f64)>) -> Vec<Edit> {
    let (text, _) = quantity(f * uniform(rng, 0.9, 1.1), unit_of(rng, column::FLOW), 5);
    let mut edits = vec![unit_edit(feed, "F", text)];
    if let Some((light, heavy, z0)) = z {
        let z1 = round_sig(z0 + uniform(rng, -0.03, 0.03), 3);
        edits.push(Edit {
            set: format!("{feed}.z[{light}]={z1}"),
            file: vec![(
                vec!["units".into(), feed.into(), "z".into()],
                obj([(light, J::N(z1)), (heavy, J::N(round_sig(1.0 - z1, 12)))]),
            )],
        });
    }
    edits
}

/// Streams, units and controllers of a column between a feed stream and two products.
struct Layout<'a> {
    feed_stream: &'a str,
    feed_from: &'a str,
    column: &'a Column,
    products: [&'a str; 2],
    sinks: [&'a str; 2],
}

fn add_column(doc: &mut J, roles: &mut Roles, l: &Layout<'_>) {
    let c = l.column;
    doc.set(&["units", &c.name], c.unit.clone());
    // A sink written as `unit.port` is a unit already there (a recycle's mixer).
    for sink in l.sinks.iter().filter(|s| !s.contains('.')) {
        doc.set(&["units", sink], obj([("type", "product".into())]));
    }
    let streams = [
        (l.feed_stream, l.feed_from.to_string(), format!("{}.feed", c.name)),
        (l.products[0], format!("{}.distillate", c.name), l.sinks[0].to_string()),
        (l.products[1], format!("{}.bottoms", c.name), l.sinks[1].to_string()),
    ];
    for (name, from, to) in streams {
        doc.set(&["streams", name], obj([("from", from.clone().into()), ("to", to.clone().into())]));
        let unit = |p: &str| p.split('.').next().unwrap_or(p).to_string();
        roles.streams.push((name.to_string(), unit(&from), unit(&to)));
    }
    for (name, ctrl) in &c.levels {
        doc.set(&["controllers", name], ctrl.clone());
    }
    roles.column = c.name.clone();
    roles.products = l.products.map(String::from);
    roles.levels = [c.levels[0].0.clone(), c.levels[1].0.clone()];
}

fn skeleton(name: String, description: String, components: J, vle: &str) -> J {
    obj([
        ("format_version", J::I(1)),
        ("name", name.into()),
        ("description", description.into()),
        ("components", components),
        ("thermo", obj([("vle", vle.into())])),
        ("units", J::O(Vec::new())),
        ("streams", J::O(Vec::new())),
        ("controllers", J::O(Vec::new())),
    ])
}

/// Hypothetical components `light` (α) and `heavy` (1) as the shipped constant-α plants write them.
fn hypothetical(rng: &mut Rng, names: [&str; 2], alpha: f64) -> (J, f64) {
    let mw = round_sig(uniform(rng, 30.0, 120.0), 3);
    let hvap = round_sig(uniform(rng, 20.0, 40.0), 3);
    let t_ref = round_sig(uniform(rng, 300.0, 400.0), 4);
    let comp = |name: &str, a: f64| {
        let data = obj([
            ("alpha", J::N(a)),
            ("mw", format!("{mw} kg/kmol").into()),
            ("hvap", format!("{hvap} kJ/mol").into()),
            ("t_ref", format!("{t_ref} K").into()),
        ]);
        obj([("name", name.into()), ("hypothetical", data)])
    };
    (J::A(vec![comp(names[0], alpha), comp(names[1], 1.0)]), mw / 1000.0)
}

fn names(rng: &mut Rng) -> ([&'static str; 2], [&'static str; 2], [&'static str; 2]) {
    match rng.below(3) {
        0 => (
            ["condenser_level", "reboiler_level"],
            ["top_composition", "bottom_composition"],
            ["distillate", "bottoms"],
        ),
        1 => (["drum_level", "sump_level"], ["xd_control", "xb_control"], ["top", "bottom"]),
        _ => (["LC101", "LC102"], ["AC101", "AC102"], ["D", "B"]),
    }
}

/// A constant-α column with LV level loops, quality loops to be closed.
fn simple_column(rng: &mut Rng) -> Draft {
    let n = 10 + rng.below(51);
    let alpha_min = (5.889 / (0.6 * (n - 1) as f64)).exp().max(1.3);
    let alpha = round_sig(log_uniform(rng, alpha_min, (1.6 * alpha_min).max(4.0)), 3);
    let light = *rng.pick(&["light", "A", "lk"]);
    let heavy = if light == "lk" {
        "hk"
    } else if light == "A" {
        "B"
    } else {
        "heavy"
    };
    let (components, mw) = hypothetical(rng, [light, heavy], alpha);
    let f = log_uniform(rng, 10.0, 500.0) / 3.6;
    let zf = round_sig(uniform(rng, 0.2, 0.8), 2);
    let q_feed = if rng.chance(0.75) { 1.0 } else { round_sig(uniform(rng, 0.7, 1.15), 2) };
    let p = 101_325.0 * round_sig(uniform(rng, 1.0, 2.0), 2);
    let (levels, quality, products) = names(rng);
    let col_name = *rng.pick(&["column", "C1", "splitter"]);
    let r = Request {
        name: col_name,
        model: Model::Simple,
        pkg: None,
        alpha,
        f,
        zf,
        q: q_feed,
        p_top: p,
        stages: (n, n),
        m: (1.2, 10.0),
        split: None,
    };
    let col = column::design(rng, &r, levels);
    let feed = *rng.pick(&["feed_source", "supply"]);
    let (f_text, f_si) = quantity(f, unit_of(rng, column::FLOW), 5);
    let mut doc = skeleton(format!("generated simple column {n}"), col.about(), components, "constant_alpha");
    let feed_unit = obj([
        ("type", "feed".into()),
        ("F", f_text.into()),
        ("P", q(p * 1.1, unit_of(rng, column::PRESSURE), 4)),
        ("z", obj([(light, J::N(zf)), (heavy, J::N(round_sig(1.0 - zf, 12)))])),
        ("condition", "saturated_liquid".into()),
    ]);
    doc.set(&["units", feed], feed_unit);
    let mut roles = Roles {
        throughput: format!("{feed}.F"),
        throughput_si: f_si,
        light: light.into(),
        mw: vec![(light.into(), mw), (heavy.into(), mw)],
        ..Roles::default()
    };
    let sinks = ["top_product", "bottom_product"];
    add_column(&mut doc, &mut roles, &Layout { feed_stream: "feed", feed_from: feed, column: &col, products, sinks });
    roles.vessels = vec![format!("{col_name}.sump"), products[1].to_string()];
    roles.edits = feed_edits(rng, feed, f, Some((light, heavy, zf)));
    let tray = plantwide::units::convert_from_si(60.0 * f, "kmol").unwrap() * uniform(rng, 0.3, 1.0);
    roles.edits.push(unit_edit(col_name, "tray_holdup", format!("{} kmol", round_sig(tray, 3))));
    let about = format!("simple column: F {f_si:.4} mol/s, zF {zf}, q {q_feed}");
    Draft { doc, column: col, temperature_loop: rng.chance(0.3), quality, roles, about }
}

/// The feed, pressure and stage range of a rigorous column of a library binary.
struct Binary {
    pair: &'static thermo::Pair,
    pkg: plantwide::thermo::ThermoPackage,
    components: J,
    p_top: f64,
    stages: (usize, usize),
}

fn binary(rng: &mut Rng, zf: f64) -> Binary {
    let pair = rng.pick(PAIRS);
    let components = J::A(vec![pair.light.into(), pair.heavy.into()]);
    let pkg = thermo::package(&components, pair.vle);
    let p_top = 101_325.0 * round_sig(uniform(rng, pair.p_atm.0, pair.p_atm.1), 3);
    let alpha = thermo::alpha(&pkg, p_top, &[zf, 1.0 - zf]);
    let least = ((5.889 / alpha.ln() / 0.6) as usize + 2).clamp(10, 50);
    Binary { pair, pkg, components, p_top, stages: (least, 60) }
}

/// A rigorous column of a library binary, LV, reboiler duty as the boilup handle.
fn rigorous_column(rng: &mut Rng) -> Draft {
    let zf = round_sig(uniform(rng, 0.25, 0.75), 2);
    let bin = binary(rng, zf);
    let (light, heavy) = (bin.pair.light, bin.pair.heavy);
    let f = log_uniform(rng, 20.0, 400.0) / 3.6;
    let (levels, quality, products) = names(rng);
    let r = Request {
        name: "column",
        model: Model::Rigorous,
        pkg: Some(&bin.pkg),
        alpha: 0.0,
        f,
        zf,
        q: 1.0,
        p_top: bin.p_top,
        stages: bin.stages,
        m: (1.2, 10.0),
        split: None,
    };
    let col = column::design(rng, &r, levels);
    let feed = "feed_source";
    let p_feed = bin.p_top + col.stages as f64 * 900.0 + uniform(rng, 10e3, 40e3);
    let (f_text, f_si) = quantity(f, unit_of(rng, column::FLOW), 5);
    let mut doc =
        skeleton(format!("generated {light}/{heavy} column"), col.about(), bin.components.clone(), bin.pair.vle);
    let feed_unit = obj([
        ("type", "feed".into()),
        ("F", f_text.into()),
        ("P", q(p_feed, unit_of(rng, column::PRESSURE), 4)),
        ("z", obj([(light, J::N(zf)), (heavy, J::N(round_sig(1.0 - zf, 12)))])),
        ("condition", "saturated_liquid".into()),
    ]);
    doc.set(&["units", feed], feed_unit);
    let mw = bin.pkg.components.iter().map(|c| (c.name.clone(), c.mw)).collect();
    let mut roles =
        Roles { throughput: format!("{feed}.F"), throughput_si: f_si, light: light.into(), mw, ..Roles::default() };
    let sinks = ["top_product", "bottom_product"];
    add_column(&mut doc, &mut roles, &Layout { feed_stream: "feed", feed_from: feed, column: &col, products, sinks });
    roles.vessels = vec!["column.sump".into(), products[1].to_string()];
    roles.edits = feed_edits(rng, feed, f, Some((light, heavy, zf)));
    let sump = plantwide::units::convert_from_si(60.0 * 5.0 * (col.v + col.b), "kmol").unwrap();
    roles.edits.push(unit_edit("column", "reboiler_holdup", format!("{} kmol", round_sig(sump, 3))));
    let about =
        format!("rigorous {light}/{heavy} ({}): F {f_si:.4} mol/s, zF {zf}, P {:.0} Pa", bin.pair.vle, bin.p_top);
    Draft { doc, column: col, temperature_loop: rng.chance(0.4), quality, roles, about }
}

/// A level loop on a vessel's pumped outflow.
fn vessel_level(rng: &mut Rng, vessel: &str, height: f64, flow: f64, pi: bool) -> J {
    let flow_unit = *rng.pick(column::FLOW);
    let per_m = uniform(rng, 0.5, 2.0) * flow / (0.5 * height);
    let kc = round_sig(plantwide::units::convert_from_si(per_m, flow_unit).unwrap(), 3);
    let mut c = obj([
        ("type", "pid".into()),
        ("pv", format!("{vessel}.level").into()),
        ("output", format!("{vessel}.outflow").into()),
        ("sp", q(0.5 * height, "m", 3)),
        ("kc", format!("{kc} {flow_unit}/m").into()),
    ]);
    if pi {
        c.set(&["tau_i"], q(uniform(rng, 3.0, 10.0) * 60.0, unit_of(rng, column::TIME), 3));
    }
    c.set(&["action"], "direct".into());
    c
}

/// A vertical vessel holding `flow` [mol/s] of liquid of molar volume `v_l` for `minutes` at half
/// its height: (diameter, height) [m].
fn vessel_size(rng: &mut Rng, flow: f64, v_l: f64, minutes: f64) -> (f64, f64) {
    let height = round_sig(uniform(rng, 2.0, 5.0), 2);
    let area = flow * v_l * minutes * 60.0 / (0.5 * height);
    (round_sig((4.0 * area / std::f64::consts::PI).sqrt(), 2), height)
}

/// Heater, flash drum, surge tank, column (the newcomer's job 2, drawn).
fn train(rng: &mut Rng) -> Draft {
    let zf = round_sig(uniform(rng, 0.3, 0.7), 2);
    let bin = binary(rng, zf);
    let (light, heavy) = (bin.pair.light, bin.pair.heavy);
    let p_flash = bin.p_top + 101_325.0 * round_sig(uniform(rng, 0.3, 1.0), 2);
    let p_tank = bin.p_top + 101_325.0 * round_sig(uniform(rng, 0.2, 0.8), 2);
    let z = [zf, 1.0 - zf];
    let (t_bub, t_dew) = (thermo::bubble_t(&bin.pkg, p_flash, &z), thermo::dew_t(&bin.pkg, p_flash, &z));
    let t_out = round_sig(t_bub + uniform(rng, 0.05, 0.3) * (t_dew - t_bub), 5);
    let (beta, x) = thermo::flash(&bin.pkg, t_out, p_flash, &z);
    let f = log_uniform(rng, 30.0, 400.0) / 3.6;
    let liquid = f * (1.0 - beta);
    let v_l = thermo::molar_volume(&bin.pkg, p_flash, &x);
    let model = if rng.chance(0.6) { Model::Rigorous } else { Model::Simple };
    let (levels, quality, products) = names(rng);
    let r = Request {
        name: "column",
        model,
        pkg: Some(&bin.pkg),
        alpha: 0.0,
        f: liquid,
        zf: x[0],
        q: 1.0,
        p_top: bin.p_top,
        stages: bin.stages,
        m: (1.2, 6.0),
        split: None,
    };
    let col = column::design(rng, &r, levels);
    let mut doc = skeleton(
        format!("generated {light}/{heavy} flash-tank-column train"),
        col.about(),
        bin.components.clone(),
        bin.pair.vle,
    );
    let (f_text, f_si) = quantity(f, unit_of(rng, column::FLOW), 5);
    let temp = *rng.pick(column::TEMPERATURE);
    let feed = obj([
        ("type", "feed".into()),
        ("F", f_text.into()),
        ("T", q(t_bub - uniform(rng, 10.0, 30.0), temp, 4)),
        ("P", q(p_flash + 101_325.0, unit_of(rng, column::PRESSURE), 4)),
        ("z", obj([(light, J::N(zf)), (heavy, J::N(round_sig(1.0 - zf, 12)))])),
        ("condition", "liquid".into()),
    ]);
    let (flash_min, tank_min) = (uniform(rng, 5.0, 10.0), uniform(rng, 10.0, 30.0));
    let (flash_d, flash_h) = vessel_size(rng, liquid, v_l, flash_min);
    let (tank_d, tank_h) = vessel_size(rng, liquid, v_l, tank_min);
    let flow_unit = *rng.pick(column::FLOW);
    let outflow = || obj([("type", "flow".into()), ("flow", q(liquid, flow_unit, 5))]);
    let vessel = |rng: &mut Rng, kind: &str, p: f64, d: f64, h: f64| {
        let pressure = q(p, unit_of(rng, column::PRESSURE), 4);
        let out = outflow();
        obj([
            ("type", kind.into()),
            ("P", pressure),
            ("diameter", q(d, "m", 2)),
            ("height", q(h, "m", 2)),
            ("outflow", out),
        ])
    };
    doc.set(&["units", "feed_source"], feed);
    doc.set(&["units", "preheater"], obj([("type", "heater".into()), ("T_out", q(t_out, temp, 6))]));
    let flash = vessel(rng, "flash", p_flash, flash_d, flash_h);
    doc.set(&["units", "flash"], flash);
    let tank = vessel(rng, "tank", p_tank, tank_d, tank_h);
    doc.set(&["units", "surge"], tank);
    doc.set(&["units", "vent"], obj([("type", "product".into())]));
    let mut roles = Roles {
        throughput: "feed_source.F".into(),
        throughput_si: f_si,
        light: light.into(),
        mw: bin.pkg.components.iter().map(|c| (c.name.clone(), c.mw)).collect(),
        ..Roles::default()
    };
    for (name, from, to) in [
        ("feed", "feed_source", "preheater"),
        ("hot", "preheater", "flash"),
        ("flash_vapour", "flash.vapour", "vent"),
        ("flash_liquid", "flash.liquid", "surge"),
    ] {
        doc.set(&["streams", name], obj([("from", from.into()), ("to", to.into())]));
        let unit = |p: &str| p.split('.').next().unwrap_or(p).to_string();
        roles.streams.push((name.into(), unit(from), unit(to)));
    }
    let sinks = ["top_product", "bottom_product"];
    add_column(
        &mut doc,
        &mut roles,
        &Layout { feed_stream: "column_feed", feed_from: "surge", column: &col, products, sinks },
    );
    let flash_level = vessel_level(rng, "flash", flash_h, liquid, true);
    doc.set(&["controllers", "flash_level"], flash_level);
    let pi = rng.chance(0.3);
    let surge_level = vessel_level(rng, "surge", tank_h, liquid, pi);
    doc.set(&["controllers", "surge_level"], surge_level);
    roles.vessels = vec!["surge".into(), "flash".into()];
    roles.edits = feed_edits(rng, "feed_source", f, Some((light, heavy, zf)));
    let t_new = t_bub + uniform(rng, 0.05, 0.3) * (t_dew - t_bub);
    roles.edits.push(unit_edit("preheater", "T_out", quantity(t_new, unit_of(rng, column::TEMPERATURE), 5).0));
    roles.edits.push(unit_edit(
        "flash",
        "P",
        quantity(p_flash * uniform(rng, 0.95, 1.05), unit_of(rng, column::PRESSURE), 4).0,
    ));
    let flash = Flash { pkg: &bin.pkg, t: t_out, p: p_flash, z: zf };
    roles.edits.retain(|e| flash.stays_two_phase(e));
    let about = format!(
        "train {light}/{heavy}: F {f_si:.4} mol/s, zF {zf}, flash {t_out:.2} K / {p_flash:.0} Pa, vapour {beta:.3}"
    );
    Draft { doc, column: col, temperature_loop: rng.chance(0.3), quality, roles, about }
}

/// A train's flash drum at its design point.
struct Flash<'a> {
    pkg: &'a plantwide::thermo::ThermoPackage,
    t: f64,
    p: f64,
    z: f64,
}

impl Flash<'_> {
    /// Whether the drum stays two-phase after edit `e` of its feed's light fraction, its heater's
    /// outlet temperature or its pressure: a flash drum must (its module says so; a subcooled drum
    /// has no steady state and the engine stops with `Stalled` on `flash_vapour.F`), so an edit
    /// that moves its feed below the bubble point is no question to ask of it.
    fn stays_two_phase(&self, e: &Edit) -> bool {
        let Some((path, value)) = e.set.split_once('=') else { return true };
        let si = |v: &str| plantwide::units::parse_quantity(v).map(|q| q.value_si).ok();
        let (t, p, z) = match path {
            "preheater.T_out" => (si(value), Some(self.p), Some(self.z)),
            "flash.P" => (Some(self.t), si(value), Some(self.z)),
            p if p.starts_with("feed_source.z[") => (Some(self.t), Some(self.p), value.parse().ok()),
            _ => return true,
        };
        let (Some(t), Some(p), Some(z)) = (t, p, z) else { return false };
        let z = [z, 1.0 - z];
        thermo::bubble_t(self.pkg, p, &z) < t && t < thermo::dew_t(self.pkg, p, &z)
    }
}

/// Luyben's snowball plant, drawn: fresh A → mixer → CSTR (A → B) → column, distillate recycled.
fn recycle(rng: &mut Rng) -> Draft {
    let alpha = round_sig(uniform(rng, 1.6, 3.0), 3);
    let (components, mw) = hypothetical(rng, ["A", "B"], alpha);
    let pkg = thermo::package(&components, "constant_alpha");
    let split = Split { xd: round_sig(uniform(rng, 0.9, 0.97), 3), xb: round_sig(log_uniform(rng, 0.005, 0.03), 2) };
    let z = round_sig(uniform(rng, 0.35, 0.6), 2);
    let f0 = log_uniform(rng, 100.0, 500.0) * 0.453_592_37 / 3.6;
    let d = f0 * (z - split.xb) / (split.xd - z);
    let mut m = uniform(rng, 1.2, 2.5);
    while column::stages_for(alpha, z, 1.0, m, split) > 0.8 * 60.0 {
        m *= 1.25;
    }
    let n = ((column::stages_for(alpha, z, 1.0, m, split) / 0.8).ceil() as usize).clamp(16, 60);
    let (levels, quality, _) = names(rng);
    let r = Request {
        name: "column",
        model: Model::Simple,
        pkg: None,
        alpha,
        f: f0 + d,
        zf: z,
        q: 1.0,
        p_top: 101_325.0,
        stages: (n, n),
        m: (m, m * 1.0001),
        split: Some(split),
    };
    let col = column::design(rng, &r, levels);
    let (area, height) = (round_sig(uniform(rng, 10.0, 30.0), 2), round_sig(uniform(rng, 4.0, 8.0), 2));
    let holdup = area * 0.5 * height / thermo::molar_volume(&pkg, 101_325.0, &[z, 1.0 - z]);
    let k = f0 * (1.0 - split.xb) / (z * holdup);
    let structure = if rng.chance(0.6) { 1 } else { 2 };
    let flow = *rng.pick(column::FLOW);
    let mut doc = skeleton(
        format!("generated reactor-column recycle, structure {structure}"),
        col.about(),
        components,
        "constant_alpha",
    );
    let (f0_text, f0_si) = quantity(f0, flow, 5);
    let fresh = obj([
        ("type", "feed".into()),
        ("F", f0_text.into()),
        ("P", "1 atm".into()),
        ("z", obj([("A", J::N(1.0))])),
        ("condition", "saturated_liquid".into()),
    ]);
    let (effluent_text, effluent_si) = quantity(f0 + d, flow, 5);
    let reactor = obj([
        ("type", "cstr".into()),
        ("area", format!("{area} m2").into()),
        ("height", format!("{height} m").into()),
        ("level", format!("{} m", 0.5 * height).into()),
        ("outflow", obj([("type", "flow".into()), ("flow", effluent_text.into())])),
        (
            "reactions",
            J::A(vec![obj([("stoichiometry", obj([("A", J::N(-1.0)), ("B", J::N(1.0))])), ("k0", q(k, "1/h", 7))])]),
        ),
    ]);
    doc.set(&["units", "fresh"], fresh);
    doc.set(&["units", "mixer"], obj([("type", "mixer".into()), ("inlets", J::I(2))]));
    doc.set(&["units", "reactor"], reactor);
    let mut roles = Roles { light: "A".into(), mw: vec![("A".into(), mw), ("B".into(), mw)], ..Roles::default() };
    roles.reacting = vec!["reactor".into()];
    for (name, from, to) in [("feed", "fresh", "mixer.in1"), ("reactor_feed", "mixer", "reactor")] {
        doc.set(&["streams", name], obj([("from", from.into()), ("to", to.into())]));
        roles.streams.push((name.into(), from.into(), to.split('.').next().unwrap_or(to).into()));
    }
    let products = ["recycle", "bottoms"];
    add_column(
        &mut doc,
        &mut roles,
        &Layout {
            feed_stream: "effluent",
            feed_from: "reactor",
            column: &col,
            products,
            sinks: ["mixer.in2", "product"],
        },
    );
    if rng.chance(0.7) {
        doc.set(&["streams", "recycle", "tear"], J::B(true));
    }
    let level_flow = uniform(rng, 0.5, 2.0) * (f0 + d) / (0.5 * height);
    let kc = format!("{} {flow}/m", round_sig(plantwide::units::convert_from_si(level_flow, flow).unwrap(), 3));
    let (output, action) = if structure == 1 { ("reactor.outflow", "direct") } else { ("fresh.F", "reverse") };
    let level = obj([
        ("type", "pid".into()),
        ("pv", "reactor.level".into()),
        ("output", output.into()),
        ("sp", format!("{} m", 0.5 * height).into()),
        ("kc", kc.into()),
        ("tau_i", q(uniform(rng, 20.0, 90.0) * 60.0, unit_of(rng, column::TIME), 3)),
        ("action", action.into()),
    ]);
    doc.set(&["controllers", "reactor_level"], level);
    (roles.throughput, roles.throughput_si) = match structure {
        1 => ("fresh.F".into(), f0_si),
        _ => ("reactor.outflow".into(), effluent_si),
    };
    roles.vessels =
        if structure == 1 { vec!["reactor".into(), "column.sump".into()] } else { vec!["column.sump".into()] };
    let (unit, field, base) = if structure == 1 { ("fresh", "F", f0) } else { ("reactor", "outflow", f0 + d) };
    roles.edits = vec![Edit {
        set: format!("{unit}.{field}={}", quantity(base * uniform(rng, 0.9, 1.1), unit_of(rng, column::FLOW), 5).0),
        file: vec![],
    }];
    fix_outflow_edit(&mut roles.edits[0], unit, field);
    let about = format!(
        "recycle structure {structure}: F0 {f0_si:.4} mol/s, z {z}, k {k:.4e} 1/s, reactor {area} m2 x {height} m"
    );
    Draft { doc, column: col, temperature_loop: false, quality, roles, about }
}

/// The file side of a throughput edit: a feed's `F`, or a vessel's `outflow.flow`.
fn fix_outflow_edit(e: &mut Edit, unit: &str, field: &str) {
    let value = e.set.split_once('=').map(|(_, v)| v.to_string()).unwrap_or_default();
    let path: Vec<String> = match field {
        "outflow" => vec!["units".into(), unit.into(), "outflow".into(), "flow".into()],
        f => vec!["units".into(), unit.into(), f.into()],
    };
    e.file = vec![(path, J::S(value))];
}
