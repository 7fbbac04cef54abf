//! Condenser–reboiler of a heat-integrated column pair: the vapour of a high-pressure column
//! condenses against the boiling bottoms of a low-pressure column (pressure-staged, "double-effect"
//! distillation; Luyben, *Distillation Design and Control Using Aspen Simulation*, 2nd ed. 2013,
//! ch. 8).
//!
//! The exchanged duty is `Q = UA (T_cond − T_boil)` [W], with `T_cond` the condensing temperature
//! of the high-pressure column (signal `condensing`, its drum temperature `hp.T[N]`) and `T_boil`
//! the boiling temperature of the low-pressure column (signal `boiling`, its reboiler temperature
//! `lp.T[1]`), UA [W/K] the exchanger's conductance (input `ua`). The same `Q` is the
//! high-pressure column's condenser duty (output `op2`, driving its `condenser_duty`) and the
//! low-pressure column's reboiler duty (output `op`, driving its `reboiler_duty`), so
//! `Q_C,HP = Q_R,LP = UA ΔT` holds at every state: at every steady state and along every run. The
//! exchanger holds no heat (its duty follows the two temperatures instantly, as in Luyben's Aspen
//! Dynamics models). The imbalance of the two columns goes to the columns' own auxiliary
//! exchangers: `rigorous.auxiliary_reboiler_duty` on the low-pressure column (steam) and
//! `rigorous.auxiliary_condenser_duty` on the high-pressure one (cooling water), inputs a
//! controller may move.
//!
//! The high-pressure column needs a condenser whose duty is an input (`rigorous.condenser_duty`)
//! and, for `T_cond` to be a condensing temperature, a drum at its bubble point: a pressure state
//! (`rigorous.vapour_volume`), so that its pressure floats to where `UA ΔT + Q_aux,C` condenses the
//! vapour it makes — the physics of a column whose condenser is another column's reboiler. The
//! duty is bounded below by 0: a pair whose high-pressure condenser would sit below the
//! low-pressure reboiler has no steady state of this design, and the certificate names the duty
//! pinned at its bound.
//!
//! Declared under `controllers` because, like them, it reads variables of other units and drives
//! their inputs (the flowsheet's signal wiring); it has no setpoint and no tuning.
//!
//! Variables: `op` (Q_R,LP = Q [W]) and `op2` (Q_C,HP = Q [W]), algebraic. Input: `ua`.
//! Signals: `condensing`, `boiling`.

use crate::capability::{Booking, Duty, DutySource};
use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::ControllerLinks;
use crate::{BuildCx, FieldError, InputSpec, Scalar, SignalSpec, UnitIo, UnitModel, VarSpec};

/// Flowsheet description of a condenser–reboiler.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CondenserReboilerConfig {
    /// Conductance UA [W/K] of the condenser–reboiler (e.g. `"300 kW/K"`), > 0 (input `ua`).
    pub ua: QuantityValue,
    /// The high-pressure column's condensing temperature: its drum temperature, e.g. `"hp.T[32]"`.
    pub condensing: String,
    /// The low-pressure column's boiling temperature: its reboiler temperature, e.g. `"lp.T[1]"`.
    pub boiling: String,
    /// The low-pressure column's reboiler-duty input, e.g. `"lp.reboiler_duty"`: driven with `Q`.
    pub reboiler_duty: String,
    /// The high-pressure column's condenser-duty input, e.g. `"hp.condenser_duty"`: driven with `Q`.
    pub condenser_duty: String,
}

impl super::ControllerConfig for CondenserReboilerConfig {
    fn paths(&self) -> super::ControllerPaths {
        super::ControllerPaths {
            measured: vec![
                ("condensing".to_string(), self.condensing.clone()),
                ("boiling".to_string(), self.boiling.clone()),
            ],
            driven: vec![
                ("reboiler_duty".to_string(), self.reboiler_duty.clone()),
                ("condenser_duty".to_string(), self.condenser_duty.clone()),
            ],
        }
    }
}

/// A condenser–reboiler coupling two columns.
#[derive(Debug, Clone)]
pub struct CondenserReboiler {
    condensing: String,
    boiling: String,
    ua: f64,
    /// The file's value of the low-pressure reboiler duty [W]: the duty guessed before the
    /// columns' temperatures are.
    start: f64,
}

const VAR_REBOILER: usize = 0;
const VAR_CONDENSER: usize = 1;

impl CondenserReboiler {
    /// Build from the flowsheet description and the resolved links (`pv_dim` is the condensing
    /// temperature's dimension, `op_dim` the reboiler-duty input's, `op_value` its file value).
    pub fn build(
        c: &CondenserReboilerConfig,
        mut cx: BuildCx<'_>,
        links: &ControllerLinks,
    ) -> Result<CondenserReboiler, Vec<FieldError>> {
        if links.pv_dim != Dimension::TEMPERATURE {
            cx.error(
                "condensing",
                format!(
                    "`{}` is {}, not a temperature: name the high-pressure column's drum temperature, e.g. \"hp.T[32]\"",
                    c.condensing,
                    links.pv_dim.describe()
                ),
            );
        }
        if links.op_dim != Dimension::POWER {
            cx.error(
                "reboiler_duty",
                format!(
                    "`{}` is {}, not a duty: name the low-pressure column's `reboiler_duty`",
                    c.reboiler_duty,
                    links.op_dim.describe()
                ),
            );
        }
        let ua = cx.positive("ua", &c.ua, Dimension::UA);
        let (condensing, boiling) = (c.condensing.clone(), c.boiling.clone());
        cx.finish(CondenserReboiler { condensing, boiling, ua, start: links.op_value })
    }

    /// The coupling duty `Q = UA (T_cond − T_boil)` [W] at the signals of `io`.
    fn duty<S: Scalar>(io: &UnitIo<'_, S>) -> S {
        io.input(0) * (io.signal(0) - io.signal(1))
    }
}

impl UnitModel for CondenserReboiler {
    fn type_name(&self) -> &'static str {
        "condenser_reboiler"
    }
    /// Its output `op` \[W\], the heat one column's condenser gives the other's reboiler.
    fn duties(&self) -> Vec<Duty> {
        vec![Duty { source: DutySource::Var("op".into()), booking: Booking::Recovered }]
    }
    fn moves_process_heat(&self) -> bool {
        true
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        let nominal = self.start.max(self.ua).max(1.0);
        let duty = |name: &str| VarSpec::algebraic(name, Dimension::POWER, nominal).bounded(0.0, f64::INFINITY);
        vec![duty("op"), duty("op2")]
    }
    fn inputs(&self) -> Vec<InputSpec> {
        vec![InputSpec { name: "ua".into(), dim: Dimension::UA, value: self.ua }]
    }
    fn signals(&self) -> Vec<SignalSpec> {
        vec![
            SignalSpec { role: "condensing".into(), path: self.condensing.clone() },
            SignalSpec { role: "boiling".into(), path: self.boiling.clone() },
        ]
    }
    fn equation_name(&self, k: usize, _own_names: &[String]) -> String {
        match k {
            VAR_REBOILER => "coupling duty Q = UA (T_condensing − T_boiling)".into(),
            _ => "high-pressure condenser duty = low-pressure reboiler duty".into(),
        }
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        r[VAR_REBOILER] = io.var(VAR_REBOILER) - Self::duty(io);
        r[VAR_CONDENSER] = io.var(VAR_CONDENSER) - io.var(VAR_REBOILER);
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        // Before the columns are guessed their temperatures are defaults (no temperature
        // difference): start from the file's low-pressure reboiler duty.
        let q = Self::duty(io);
        let q = if q.is_finite() && q > 0.0 { q } else { self.start };
        own[VAR_REBOILER] = q;
        own[VAR_CONDENSER] = q;
    }
}

#[cfg(test)]
mod tests {
    use plantwide_units::Dimension;
    use serde_json::json;

    use super::*;
    use crate::ControllerSpec;
    use crate::testing::{binary_package, controller_eval as eval, controller_layout as layout, jacobian_error};

    fn links(pv_dim: Dimension, op_dim: Dimension) -> ControllerLinks {
        ControllerLinks {
            measured_dims: Vec::new(),
            driven: Vec::new(),
            pv_dim,
            op_dim,
            op_value: 1.0e6,
            pv_nominal: 1.0,
            measured_ranges: Vec::new(),
            driven_ranges: Vec::new(),
        }
    }

    fn config() -> serde_json::Value {
        json!({"ua": "300 kW/K", "condensing": "hp.T[32]", "boiling": "lp.T[1]",
               "reboiler_duty": "lp.reboiler_duty", "condenser_duty": "hp.condenser_duty"})
    }

    fn build(config: serde_json::Value, links: &ControllerLinks) -> Result<CondenserReboiler, Vec<FieldError>> {
        let c: CondenserReboilerConfig = serde_json::from_value(config).expect("valid description");
        let thermo = binary_package();
        let comps = vec!["light".to_string(), "heavy".to_string()];
        CondenserReboiler::build(&c, BuildCx::new(&comps, &thermo, "controllers.hx"), links)
    }

    #[test]
    fn both_sides_carry_ua_delta_t() {
        let u = build(config(), &links(Dimension::TEMPERATURE, Dimension::POWER)).unwrap();
        let names: Vec<_> = u.inputs().iter().map(|i| i.name.clone()).collect();
        assert_eq!(names, ["ua"]);
        // local = [op, op2 | UA | T_cond, T_boil]: 300 kW/K over 12 K = 3.6 MW.
        let local = [0.0, 0.0, 3.0e5, 390.0, 378.0];
        let (_, guess) = eval(&u, &local);
        assert_eq!(guess, [3.6e6, 3.6e6]);
        let mut at = local;
        at[..2].copy_from_slice(&guess);
        let (r, _) = eval(&u, &at);
        assert_eq!(r, [0.0, 0.0]);
        let (r, _) = eval(&u, &[3.5e6, 3.4e6, 3.0e5, 390.0, 378.0]);
        assert_eq!(r, [-1.0e5, -1.0e5]);
        assert!(jacobian_error(&u, &layout(&u), &binary_package(), &at, 2) < 1e-7);
        // Before the columns are guessed (no temperature difference): the file's reboiler duty.
        let (_, guess) = eval(&u, &[0.0, 0.0, 3.0e5, 350.0, 350.0]);
        assert_eq!(guess, [1.0e6, 1.0e6]);
    }

    #[test]
    fn a_signal_that_is_not_a_temperature_or_an_output_that_is_not_a_duty_is_named() {
        let errs = build(config(), &links(Dimension::PRESSURE, Dimension::MOLAR_FLOW)).unwrap_err();
        let paths: Vec<_> = errs.iter().map(|e| e.path.as_str()).collect();
        assert_eq!(paths, ["controllers.hx.condensing", "controllers.hx.reboiler_duty"]);
        assert!(errs[0].message.contains("hp.T[32]"), "{}", errs[0].message);
        let mut bad = config();
        bad["ua"] = json!("-1 kW/K");
        let errs = build(bad, &links(Dimension::TEMPERATURE, Dimension::POWER)).unwrap_err();
        assert_eq!(errs[0].path, "controllers.hx.ua");
    }

    #[test]
    fn the_registry_knows_the_type_and_its_paths() {
        let mut v = config();
        v["type"] = json!("condenser_reboiler");
        let spec: ControllerSpec = serde_json::from_value(v).unwrap();
        assert_eq!(spec.type_name(), "condenser_reboiler");
        let paths = spec.config().paths();
        assert_eq!(paths.driven[1], ("condenser_duty".to_string(), "hp.condenser_duty".to_string()));
    }
}
