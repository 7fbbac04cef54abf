//! The flowsheet description of the rigorous column and its build.

use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{Condenser, RigorousColumn, Weir};
use crate::units::column::{ColumnConfig, side_draws};
use crate::{BuildCx, FieldError};

/// An example of the `rigorous` block, for error messages.
pub const EXAMPLE: &str =
    r#"{"reboiler_duty": "1.2 MW", "weir_length": "0.8 m", "weir_height": "50 mm", "tray_area": "0.6 m2"}"#;

/// A steam-heated reboiler: `Q_R = m_s λ_s` [W] with the steam flow m_s [kg/s] an input
/// (`steam_flow`) and λ_s [J/kg] the latent heat the condensing steam gives up.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SteamReboiler {
    /// Steam flow m_s [kg/s] (input `steam_flow`; e.g. `"1800 kg/h"`).
    pub steam_flow: QuantityValue,
    /// Latent heat of the steam λ_s [J/kg] (e.g. `"2100 kJ/kg"`), > 0.
    pub steam_latent_heat: QuantityValue,
}

/// A water-cooled condenser: the coolant (input `coolant_flow` m_c [kg/s]) enters at `T_in` and
/// takes `Qc = m_c c_p (T_N − T_in) (1 − exp(−UA / (m_c c_p)))` [W] from the drum at `T_N`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CoolantCondenser {
    /// Coolant flow m_c [kg/s] (input `coolant_flow`; e.g. `"20 kg/s"`).
    pub coolant_flow: QuantityValue,
    /// Coolant inlet temperature T_in [K] (e.g. `"30 degC"`).
    #[serde(rename = "coolant_T_in")]
    pub coolant_t_in: QuantityValue,
    /// Overall heat-transfer coefficient times area UA [W/K] (e.g. `"60 kW/K"`).
    pub ua: QuantityValue,
    /// Coolant heat capacity c_p [J/(kg K)] (default 4184, water).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cp: Option<QuantityValue>,
}

/// Condenser type.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum CondenserType {
    /// All the vapour condenses; the distillate is liquid of the drum's composition.
    #[default]
    Total,
    /// The distillate is the drum's vapour, in equilibrium with the reflux (`y_D = K x_N`).
    Partial,
}

/// Rigorous-model data of a column (`"rigorous": {...}` with `"model": "rigorous"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RigorousConfig {
    /// Reboiler duty Q_R [W] (input `reboiler_duty`; e.g. `"1.2 MW"`); give either this or
    /// `reboiler`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reboiler_duty: Option<QuantityValue>,
    /// Steam-heated reboiler, `Q_R = m_s λ_s` (input `steam_flow` [kg/s]; e.g.
    /// `{"steam_flow": "1800 kg/h", "steam_latent_heat": "2100 kJ/kg"}`), instead of `reboiler_duty`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reboiler: Option<SteamReboiler>,
    /// Condenser duty Q_C [W] (input `condenser_duty`; e.g. `"1.1 MW"`); omit for a drum at its
    /// bubble point, whose duty is computed (variable `Qc`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub condenser_duty: Option<QuantityValue>,
    /// Water-cooled condenser (input `coolant_flow` [kg/s]; e.g. `{"coolant_flow": "20 kg/s",
    /// "coolant_T_in": "30 degC", "ua": "60 kW/K"}`), instead of `condenser_duty`; the drum energy
    /// balance gives its temperature, as with `condenser_duty`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub condenser: Option<CoolantCondenser>,
    /// Auxiliary reboiler duty Q_aux,R [W] (input `auxiliary_reboiler_duty`; e.g. `"50 kW"`): heat
    /// added to the reboiler beside `reboiler_duty`, for a reboiler another unit heats (a
    /// condenser–reboiler drives `reboiler_duty`). Default: no auxiliary reboiler.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub auxiliary_reboiler_duty: Option<QuantityValue>,
    /// Auxiliary condenser duty Q_aux,C [W] (input `auxiliary_condenser_duty`; e.g. `"20 kW"`):
    /// heat removed beside `condenser_duty` or the coolant's, `Qc = Q_C + Q_aux,C`. Needs a
    /// condenser whose duty is an input. Default: no auxiliary condenser.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub auxiliary_condenser_duty: Option<QuantityValue>,
    /// `total` (default) or `partial` (vapour distillate in equilibrium with the reflux; the drum at
    /// its bubble point, so neither `condenser_duty` nor `condenser`).
    #[serde(default, skip_serializing_if = "is_total")]
    pub condenser_type: CondenserType,
    /// Murphree vapour efficiency E of every tray [-], 0 < E ≤ 1 (default 1: equilibrium trays).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub murphree_efficiency: Option<f64>,
    /// Pressure drop per tray ΔP [Pa] (e.g. `"0.7 kPa"`; default 0): `P_i = P + (N − i) ΔP`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tray_pressure_drop: Option<QuantityValue>,
    /// Vapour space of the condenser and reflux drum V_vap [m³] (e.g. `"2 m3"`): its component
    /// holdups `nV[c]` [mol] become states, `dnV_c/dt = V_{N−1} y_{N−1,c} − W yv_c` (`W` the vapour
    /// the condenser condenses, its duty over the latent heat; `yv` the space's composition), and
    /// the top pressure `P` [Pa] their ideal-gas pressure, `P V_vap = Σ nV R T_N`, the drum at its
    /// bubble point at `P`; needs `condenser_duty` or a coolant `condenser`, whose input then holds
    /// the pressure (a pressure controller on it) or lets it float. Default: the pressure is fixed
    /// at `P`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vapour_volume: Option<QuantityValue>,
    /// Outlet weir length l_w [m] (e.g. `"0.8 m"`).
    pub weir_length: QuantityValue,
    /// Outlet weir height h_w [m] (e.g. `"50 mm"`).
    pub weir_height: QuantityValue,
    /// Tray active area A [m²] (e.g. `"0.6 m2"`): liquid height on the tray is `M v_L / A`.
    pub tray_area: QuantityValue,
}

fn is_total(t: &CondenserType) -> bool {
    *t == CondenserType::Total
}

impl RigorousColumn {
    /// Build from the flowsheet description (the model-specific fields were checked by the caller).
    pub fn build(c: &ColumnConfig, mut cx: BuildCx<'_>) -> Result<RigorousColumn, Vec<FieldError>> {
        let n = c.stages;
        if n < 3 {
            cx.error("stages", format!("a column needs at least 3 stages (reboiler, one tray, condenser); got {n}"));
        }
        let flow = Dimension::MOLAR_FLOW;
        let p_top = c.pressure.as_ref().map_or(101_325.0, |p| cx.positive("P", p, Dimension::PRESSURE));
        let m_condenser = cx.positive("condenser_holdup", &c.condenser_holdup, Dimension::AMOUNT);
        let m_reboiler = cx.positive("reboiler_holdup", &c.reboiler_holdup, Dimension::AMOUNT);
        let reflux = cx.non_negative("reflux", &c.reflux, flow);
        let distillate = cx.non_negative("distillate", &c.distillate, flow);
        let bottoms = cx.non_negative("bottoms", &c.bottoms, flow);
        let RigorousData {
            reboiler_duty,
            steam_latent_heat,
            condenser,
            partial,
            efficiency,
            dp,
            weir,
            vapour_volume,
            aux_reboiler,
            aux_condenser,
        } = c.rigorous.as_ref().map_or_else(RigorousData::default, |r| rigorous_data(r, &mut cx));
        let (feeds, feed_ports) = feed_stages(c, n, &mut cx);
        let (draws, draw_ports) = side_draws(c, n, &feed_ports, &mut cx);
        check_ranges(&mut cx, &weir, (p_top, dp), n);
        let pressure = (0..n).map(|s| p_top + (n - 1 - s) as f64 * dp).collect();
        let n_comp = cx.thermo.n().max(1) as f64;
        let v_mean = cx.thermo.components.iter().map(|c| c.v_liq(298.15)).sum::<f64>() / n_comp;
        let v_mean = if v_mean.is_finite() && v_mean > 0.0 { v_mean } else { 1e-4 };
        let m_tray = weir.holdup(reflux, v_mean);
        let column = RigorousColumn {
            n_stages: n,
            feeds,
            feed_ports,
            draws,
            draw_ports,
            pressure,
            efficiency,
            weir,
            m_condenser,
            m_reboiler,
            m_tray: if m_tray.is_finite() && m_tray > 0.0 { m_tray } else { 1.0 },
            reflux,
            reboiler_duty,
            steam_latent_heat,
            distillate,
            bottoms,
            condenser,
            partial,
            aux_reboiler,
            aux_condenser,
            vapour_volume,
            comp_names: cx.components.to_vec(),
        };
        cx.finish(column)
    }
}

/// The `rigorous` block's data in SI: heating, condenser, tray efficiency, pressure drop, weir.
struct RigorousData {
    reboiler_duty: f64,
    steam_latent_heat: Option<f64>,
    condenser: Condenser,
    partial: bool,
    efficiency: f64,
    dp: f64,
    weir: Weir,
    vapour_volume: Option<f64>,
    aux_reboiler: Option<f64>,
    aux_condenser: Option<f64>,
}

impl Default for RigorousData {
    /// Without a `rigorous` block (an error the caller reports): no duty, equilibrium trays.
    fn default() -> RigorousData {
        RigorousData {
            reboiler_duty: f64::NAN,
            steam_latent_heat: None,
            condenser: Condenser::BubblePoint,
            partial: false,
            efficiency: 1.0,
            dp: 0.0,
            weir: Weir { length: f64::NAN, height: f64::NAN, area: f64::NAN },
            vapour_volume: None,
            aux_reboiler: None,
            aux_condenser: None,
        }
    }
}

/// Read and check the `rigorous` block `r`, recording its errors in `cx`.
fn rigorous_data(r: &RigorousConfig, cx: &mut BuildCx<'_>) -> RigorousData {
    let mut d = RigorousData::default();
    match (&r.reboiler_duty, &r.reboiler) {
            (Some(q), None) => d.reboiler_duty = cx.non_negative("rigorous.reboiler_duty", q, Dimension::POWER),
            (None, Some(s)) => {
                d.reboiler_duty = cx.non_negative("rigorous.reboiler.steam_flow", &s.steam_flow, Dimension::MASS_FLOW);
                d.steam_latent_heat = Some(cx.positive(
                    "rigorous.reboiler.steam_latent_heat",
                    &s.steam_latent_heat,
                    Dimension::SPECIFIC_ENERGY,
                ));
            }
            (Some(_), Some(_)) => cx.error(
                "rigorous.reboiler",
                "give either `reboiler_duty` or the steam `reboiler`, not both: remove one",
            ),
            (None, None) => cx.error(
                "rigorous.reboiler_duty",
                r#"the rigorous model needs `reboiler_duty` (e.g. "1.2 MW") or a steam `reboiler` (e.g. {"steam_flow": "1800 kg/h", "steam_latent_heat": "2100 kJ/kg"})"#,
            ),
        }
    if let Some(q) = &r.condenser_duty {
        d.condenser = Condenser::Duty(cx.non_negative("rigorous.condenser_duty", q, Dimension::POWER));
    }
    if let Some(c) = &r.condenser {
        if r.condenser_duty.is_some() {
            cx.error(
                "rigorous.condenser",
                "give either `condenser_duty` or the coolant `condenser`, not both: remove one",
            );
        }
        let cp =
            c.cp.as_ref().map_or(4184.0, |v| cx.positive("rigorous.condenser.cp", v, Dimension::HEAT_CAPACITY_MASS));
        d.condenser = Condenser::Coolant {
            flow: cx.positive("rigorous.condenser.coolant_flow", &c.coolant_flow, Dimension::MASS_FLOW),
            t_in: cx.positive("rigorous.condenser.coolant_T_in", &c.coolant_t_in, Dimension::TEMPERATURE),
            ua: cx.positive("rigorous.condenser.ua", &c.ua, Dimension::UA),
            cp,
        };
    }
    d.partial = r.condenser_type == CondenserType::Partial;
    if d.partial && (r.condenser_duty.is_some() || r.condenser.is_some()) {
        cx.error(
            "rigorous.condenser_type",
            "a partial condenser keeps its drum at the bubble point, so its duty is computed: remove \
                 `condenser_duty` / `condenser`, or make the condenser `total`",
        );
    }
    if let Some(e) = r.murphree_efficiency {
        if !(e.is_finite() && e > 0.0 && e <= 1.0) {
            cx.error("rigorous.murphree_efficiency", format!("must lie in (0, 1] (1 = equilibrium trays); got {e}"));
        }
        d.efficiency = e;
    }
    if let Some(v) = &r.vapour_volume {
        d.vapour_volume = Some(cx.positive("rigorous.vapour_volume", v, Dimension::VOLUME));
        if !matches!(d.condenser, Condenser::Duty(_) | Condenser::Coolant { .. }) || d.partial {
            cx.error(
                "rigorous.vapour_volume",
                "a pressure state needs a total condenser whose duty is an input: give `condenser_duty` \
                 (e.g. \"1.1 MW\") or a coolant `condenser`; it then holds the pressure or lets it float",
            );
        }
    }
    auxiliary_duties(r, cx, &mut d);
    d.dp = r
        .tray_pressure_drop
        .as_ref()
        .map_or(0.0, |v| cx.non_negative("rigorous.tray_pressure_drop", v, Dimension::PRESSURE));
    d.weir = Weir {
        length: cx.positive("rigorous.weir_length", &r.weir_length, Dimension::LENGTH),
        height: cx.non_negative("rigorous.weir_height", &r.weir_height, Dimension::LENGTH),
        area: cx.positive("rigorous.tray_area", &r.tray_area, Dimension::AREA),
    };
    d
}

/// The auxiliary reboiler and condenser duties; the condenser's needs a condenser whose duty is an
/// input.
fn auxiliary_duties(r: &RigorousConfig, cx: &mut BuildCx<'_>, d: &mut RigorousData) {
    let power = Dimension::POWER;
    d.aux_reboiler =
        r.auxiliary_reboiler_duty.as_ref().map(|q| cx.non_negative("rigorous.auxiliary_reboiler_duty", q, power));
    d.aux_condenser =
        r.auxiliary_condenser_duty.as_ref().map(|q| cx.non_negative("rigorous.auxiliary_condenser_duty", q, power));
    if d.aux_condenser.is_some() && !d.condenser.has_input() {
        cx.error(
            "rigorous.auxiliary_condenser_duty",
            "an auxiliary condenser adds to a condenser whose duty is an input: give `condenser_duty` (e.g. \"0.5 MW\") \
             or a coolant `condenser`, or remove it (a drum at its bubble point computes its whole duty)",
        );
    }
}

/// The feeds' stages (0-based) and port names, each stage within the column and each port used once.
fn feed_stages(c: &ColumnConfig, n: usize, cx: &mut BuildCx<'_>) -> (Vec<usize>, Vec<String>) {
    if c.feeds.is_empty() {
        cx.error("feeds", "give at least one feed, e.g. [{\"port\": \"feed\", \"stage\": 10}]");
    }
    let mut feeds = Vec::new();
    let mut feed_ports: Vec<String> = Vec::new();
    for (k, f) in c.feeds.iter().enumerate() {
        if f.stage < 1 || f.stage > n {
            cx.error(
                &format!("feeds[{k}].stage"),
                format!("must be between 1 (reboiler) and {n} (condenser); got {}", f.stage),
            );
        }
        if feed_ports.contains(&f.port) {
            cx.error(&format!("feeds[{k}].port"), format!("port `{}` is used twice", f.port));
        }
        feed_ports.push(f.port.clone());
        feeds.push(f.stage.saturating_sub(1));
    }
    (feeds, feed_ports)
}

/// Tray geometry and pressures within the range of real columns: weirs of a few cm (the Francis
/// formula's range), trays of at most a few hundred m², the reboiler below 1 GPa; outside it the
/// hydraulics and the property models have no meaning.
fn check_ranges(cx: &mut BuildCx<'_>, weir: &Weir, (p_top, dp): (f64, f64), n: usize) {
    for (field, v, max, unit) in [
        ("rigorous.weir_height", weir.height, 1.0, "m"),
        ("rigorous.weir_length", weir.length, 100.0, "m"),
        ("rigorous.tray_area", weir.area, 1000.0, "m²"),
    ] {
        if v > max {
            cx.error(field, format!("{} {unit} is beyond the {max} {unit} of any real tray", crate::limits::number(v)));
        }
    }
    let p_bottom = p_top + n.saturating_sub(1) as f64 * dp;
    if p_bottom > crate::limits::max_magnitude(Dimension::PRESSURE) {
        cx.error(
            "rigorous.tray_pressure_drop",
            format!(
                "{dp:e} Pa per tray over {n} stages puts the reboiler at {p_bottom:e} Pa, beyond the 1e9 Pa in which the models hold"
            ),
        );
    }
}
