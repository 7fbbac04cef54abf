//! A vessel as the sizing sees it: its level measurement, the PID that holds it by a flow, the
//! liquid's molar volume, how its size is written, and the flow change a disturbance asks of it.

use plantwide_flowsheet::{Plant, StructureEdit, VarPath};
use plantwide_model::controllers::Setpoint;
use plantwide_model::{ControllerSpec, UnitSpec};
use plantwide_units::{Dimension, QuantityValue};

use super::{SizeCriteria, SizeError, steady_from};

/// How the vessel's size enters the flowsheet.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Kind {
    /// A `tank`, `cstr` or `flash` (a new surge tank when `new_on` names the stream it was put on):
    /// level in m, cross-section `area` \[m²\] written as `area` or as `diameter`.
    Area { unit: String, diameter: bool, area: f64, height: Option<f64>, new_on: Option<String> },
    /// A column's drum or base: holdup in mol.
    Holdup { drum: bool },
}

/// A vessel with its level loop, at a steady state.
#[derive(Debug, Clone)]
pub(super) struct Vessel {
    /// The plant holding it (with the new tank, for a stream).
    pub plant: Plant,
    /// Its steady state.
    pub x: Vec<f64>,
    /// The plant as the file has it and its steady state (for the `current` run).
    pub original: (Plant, Vec<f64>),
    pub kind: Kind,
    /// The level PID's name and its description.
    pub controller: String,
    pub config: plantwide_model::controllers::pid::PidConfig,
    /// Path and index of the level measurement; index of the controller's output.
    pub measurement: String,
    pub pv: usize,
    pub op: usize,
    /// The flow input the controller drives.
    pub outflow: String,
    /// The controller's setpoint (SI of the measurement).
    pub sp: f64,
    /// Liquid molar volume \[m³/mol\].
    pub v_l: f64,
}

impl Vessel {
    /// The vessel `name` of `plant` at `x`: a unit with a level, `COL.drum`/`COL.sump`, or a
    /// stream (a new surge tank on it).
    pub fn resolve(plant: &Plant, x: &[f64], name: &str, r: &SizeCriteria) -> Result<Vessel, SizeError> {
        let original = (plant.clone(), x.to_vec());
        let spec = plant.spec();
        if let Some(u) = spec.units.get(name) {
            let (diameter, area, height) = geometry(u).ok_or_else(|| not_a_vessel(plant, name, "it holds no level"))?;
            let kind = Kind::Area { unit: name.to_string(), diameter, area, height, new_on: None };
            return Vessel::with_loop(original, plant.clone(), x.to_vec(), kind, &VarPath::new(name, "level"), r);
        }
        if let Some((unit, end)) = name.rsplit_once('.')
            && let Some(inv) =
                spec.units.get(unit).and_then(|u| u.config().inventories().into_iter().find(|i| i.name == end))
        {
            let kind = Kind::Holdup { drum: inv.name == "drum" };
            return Vessel::with_loop(
                original,
                plant.clone(),
                x.to_vec(),
                kind,
                &VarPath::new(unit, "M").index(inv.stage),
                r,
            );
        }
        if spec.streams.contains_key(name) {
            let (p, xs, unit) = new_tank(plant, x, name, r)?;
            let kind =
                Kind::Area { unit: unit.clone(), diameter: false, area: 1.0, height: None, new_on: Some(name.into()) };
            return Vessel::with_loop(original, p, xs, kind, &VarPath::new(&unit, "level"), r);
        }
        Err(not_a_vessel(plant, name, "no unit, column end or stream has this name"))
    }

    fn with_loop(
        original: (Plant, Vec<f64>),
        plant: Plant,
        x: Vec<f64>,
        kind: Kind,
        measurement: &VarPath,
        r: &SizeCriteria,
    ) -> Result<Vessel, SizeError> {
        let fail = |why: String| SizeError::LevelLoop { vessel: measurement.to_string(), why };
        let pv =
            plant.var(measurement).ok_or_else(|| fail(format!("the flowsheet has no variable `{measurement}`")))?;
        let (controller, cfg) = level_pid(&plant, pv).ok_or_else(|| {
            fail(format!(
                "no PID controller measures `{measurement}`: sizing designs the level controller of a vessel whose level a \
                 PID holds by moving a flow"
            ))
        })?;
        let outflow = cfg.output.clone().ok_or_else(|| {
            fail(format!("`{controller}` sets another controller's setpoint; size a level loop that moves a flow"))
        })?;
        match plant.input(&outflow).map(|i| plant.inputs()[i].dim) {
            Some(d) if d == Dimension::MOLAR_FLOW => {}
            d => {
                return Err(fail(format!(
                    "`{controller}` moves `{outflow}` ({}), not a molar flow: put the outflow on flow control (a pump with \
                     `\"outflow\": {{\"type\": \"flow\"}}`, a column's distillate or bottoms)",
                    d.map_or("no input".to_string(), |d| d.describe().into_owned())
                )));
            }
        }
        // The local setpoint is an input: its value in the plant (the file's, or a `--set`).
        let sp = match (&cfg.sp, plant.input(VarPath::setpoint(&controller))) {
            (Setpoint::Value(_), Some(i)) => plant.inputs()[i].value,
            _ => return Err(fail(format!("`{controller}` takes its setpoint from a master"))),
        };
        let op = plant
            .var(VarPath::controller_output(&controller, 0))
            .ok_or_else(|| fail(format!("`{controller}` has no output")))?;
        let config = cfg.clone();
        let v_l = liquid_volume(&plant, &x, &kind, measurement.as_str())
            .ok_or_else(|| fail("no liquid molar volume".into()))?;
        let v = Vessel {
            plant,
            x,
            original,
            kind,
            controller,
            config,
            measurement: measurement.to_string(),
            pv,
            op,
            outflow,
            sp,
            v_l,
        };
        v.check_band(r.level_band)?;
        Ok(v)
    }

    /// Whether the vessel is a unit with reactions (its volume sets its conversion).
    pub fn reacts(&self) -> bool {
        let Kind::Area { unit, new_on: None, .. } = &self.kind else { return false };
        self.plant.block_index(unit).is_some_and(|b| self.plant.blocks()[b].unit.reacts())
    }

    /// The band must fit between the vessel's bottom and top around the setpoint.
    fn check_band(&self, band: f64) -> Result<(), SizeError> {
        let Kind::Area { height, new_on: None, .. } = &self.kind else { return Ok(()) };
        let fail = |why: String| SizeError::Band { vessel: self.measurement.clone(), band, why };
        if self.sp - band <= 0.0 {
            return Err(fail(format!(
                "the band reaches below the vessel's bottom (setpoint {} m): give a band under {} m or raise the setpoint",
                self.sp, self.sp
            )));
        }
        match height {
            Some(h) if self.sp + band >= *h => Err(fail(format!(
                "the band reaches above the vessel's top (setpoint {} m, height {h} m): give a band under {} m",
                self.sp,
                h - self.sp
            ))),
            _ => Ok(()),
        }
    }

    /// `vessel`, `column_drum`, `column_sump` or `new_surge_tank`.
    pub fn kind_name(&self) -> &'static str {
        match &self.kind {
            Kind::Area { new_on: Some(_), .. } => "new_surge_tank",
            Kind::Area { .. } => "vessel",
            Kind::Holdup { drum: true } => "column_drum",
            Kind::Holdup { drum: false } => "column_sump",
        }
    }

    /// For a cross-section `area` and a level band `band` \[m\]: the band in the measurement's
    /// units and the measurement's integrating gain per unit of outflow (`v_L/A` for a level,
    /// 1 for a holdup), a magnitude.
    pub fn measurement_scale(&self, area: f64, band: f64) -> (f64, f64) {
        match self.kind {
            Kind::Area { .. } => (band, self.v_l / area),
            Kind::Holdup { .. } => (area * band / self.v_l, 1.0),
        }
    }

    /// The edit that writes `area` into the flowsheet (none for a column's holdup).
    pub fn size_edit(&self, area: f64) -> Option<StructureEdit> {
        let Kind::Area { unit, diameter, .. } = &self.kind else { return None };
        let o = if *diameter {
            plantwide_flowsheet::Override::new(
                VarPath::new(unit, "diameter"),
                (4.0 * area / std::f64::consts::PI).sqrt().to_string(),
            )
        } else {
            plantwide_flowsheet::Override::new(VarPath::new(unit, "area"), area.to_string())
        };
        Some(StructureEdit::Set(o))
    }

    /// The steady change of the outflow after the disturbance (signed, SI).
    pub fn flow_change(&self, r: &SizeCriteria) -> Result<f64, SizeError> {
        let x1 = super::steady::after(&self.plant, &self.x, r, "the plant after the disturbance")?;
        let du = x1[self.op] - self.x[self.op];
        if du.abs() <= 1e-9 * self.x[self.op].abs().max(1e-12) {
            return Err(SizeError::Unreached {
                vessel: self.measurement.clone(),
                outflow: self.outflow.clone(),
                path: r.disturbance.path.clone(),
                change: du,
            });
        }
        Ok(du)
    }
}

/// `(written as diameter, area [m²], height [m])` of a unit with a level.
fn geometry(u: &UnitSpec) -> Option<(bool, f64, Option<f64>)> {
    let g = u.config().vessel()?;
    let (d, a, h) = (g.diameter, g.area, g.height);
    let si = |q: &QuantityValue, dim| q.to_si(dim).ok();
    let height = h.and_then(|h| si(h, Dimension::LENGTH));
    match (d, a) {
        (Some(d), _) => si(d, Dimension::LENGTH).map(|d| (true, std::f64::consts::PI * d * d / 4.0, height)),
        (None, Some(a)) => si(a, Dimension::AREA).map(|a| (false, a, height)),
        (None, None) => None,
    }
}

/// The PID whose measurement is variable `pv`.
fn level_pid(plant: &Plant, pv: usize) -> Option<(String, plantwide_model::controllers::pid::PidConfig)> {
    plant.spec().controllers.iter().find_map(|(name, c)| match c {
        ControllerSpec::Pid(cfg) => {
            let b = plant.controller(name).ok()?;
            (plant.measured_var(b) == Some(pv)).then(|| (name.clone(), cfg.clone()))
        }
        _ => None,
    })
}

/// Molar volume of the liquid: `V/M` of a vessel, `v_L(T, x)` of a column's stage.
fn liquid_volume(plant: &Plant, x: &[f64], kind: &Kind, measurement: &str) -> Option<f64> {
    let at = |p: VarPath| plant.var(p).map(|i| x[i]);
    match kind {
        Kind::Area { unit, .. } => Some(at(VarPath::new(unit, "V"))? / at(VarPath::new(unit, "M"))?),
        Kind::Holdup { .. } => {
            let (col, stage) = measurement.strip_suffix(']')?.split_once(".M[")?;
            let t = at(VarPath::new(col, "T").index(stage))?;
            let comps: Option<Vec<f64>> =
                plant.components().iter().map(|c| at(VarPath::new(col, "x").index(stage).index(c))).collect();
            Some(plant.thermo().v_liq(t, &comps?))
        }
    }
}

fn not_a_vessel(plant: &Plant, name: &str, why: &str) -> SizeError {
    let mut known: Vec<String> = Vec::new();
    for (n, u) in &plant.spec().units {
        if geometry(u).is_some() {
            known.push(n.clone());
        }
        known.extend(u.config().inventories().iter().map(|i| format!("{n}.{}", i.name)));
    }
    let streams: Vec<&str> = plant.spec().streams.keys().map(String::as_str).collect();
    SizeError::Vessel {
        name: name.to_string(),
        why: why.to_string(),
        known: format!("{}; or a stream to put a new surge tank on ({})", known.join(", "), streams.join(", ")),
    }
}

/// `plant` with a surge tank on `stream` (cross-section 1 m², P-only level loop on its pumped
/// outflow, setpoint at twice the band in a tank four bands tall), its steady state and its name.
fn new_tank(plant: &Plant, x: &[f64], stream: &str, r: &SizeCriteria) -> Result<(Plant, Vec<f64>, String), SizeError> {
    let at = |f: &str| plant.var(VarPath::new(stream, f)).map(|i| x[i]);
    let (Some(flow), Some(p)) = (at("F"), at("P")) else {
        return Err(not_a_vessel(plant, stream, "the stream has no flow and pressure"));
    };
    let unit = format!("surge_{stream}");
    let band = r.level_band;
    let n = QuantityValue::Number;
    let tank = UnitSpec::Tank(plantwide_model::units::tank::TankConfig {
        diameter: None,
        area: Some(n(1.0)),
        height: Some(n(4.0 * band)),
        pressure: Some(n(p)),
        duty: None,
        outflow: plantwide_model::units::outflow::Outflow::Flow { flow: n(flow) },
        level: None,
    });
    let level = ControllerSpec::Pid(plantwide_model::controllers::pid::PidConfig {
        pv: VarPath::new(&unit, "level").into(),
        output: Some(VarPath::new(&unit, "outflow").into()),
        sp: Setpoint::Value(n(2.0 * band)),
        kc: n((0.1 * flow / band).max(1e-9)),
        tau_i: None,
        tau_d: None,
        filter_ratio: None,
        action: plantwide_model::controllers::Action::Direct,
        bias: Some(n(flow)),
        op_min: None,
        op_max: None,
        mode: Default::default(),
        op_manual: None,
    });
    let edits = [
        StructureEdit::InsertOnStream {
            stream: stream.into(),
            unit: unit.clone(),
            spec: Box::new(tank),
            outlet: format!("{stream}_surged"),
        },
        StructureEdit::AddController { name: format!("{unit}_level"), spec: Box::new(level) },
    ];
    let v = plant
        .restructure(&edits)
        .map_err(|source| SizeError::Structure { what: format!("surge tank on `{stream}`"), source })?;
    let xs = steady_from(plant, x, &v, &format!("the plant with a surge tank on `{stream}`"))?;
    Ok((v, xs, unit))
}
