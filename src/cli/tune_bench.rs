//! The plant tests of `plantwide tune FILE --loop CTRL`: a relay test (`relay`, `zn`, `tl`) or a
//! step test with a model fit (`simc`, `imc`) on the dynamic model.

use plantwide::flowsheet::Plant;
use plantwide::studies::tune::PiRule;
use plantwide::studies::tune::fit::ModelOrder;
use plantwide::studies::tune::flowsheet::{FlowsheetTuning, from_relay, from_step};
use plantwide::studies::tune::loops::PlantLoop;
use plantwide::studies::tune::plant_tests::{RelayOptions, StepOptions, relay_loop, step_loop};
use plantwide::studies::tune::rules::ModelRule;
use plantwide::units::Dimension;

use super::CliError;
use super::tune::{MethodArg, ModelArg, TuneArgs, tune_error};
use super::tune_plant::quantity;

/// Run the test `method` asks for on loop `l` at the steady state `x`.
pub fn run(
    a: &TuneArgs,
    plant: &Plant,
    x: &[f64],
    l: &PlantLoop,
    method: MethodArg,
) -> Result<FlowsheetTuning, CliError> {
    let (out_dim, pv_dim) = (plant.vars()[l.op].spec.dim, plant.vars()[l.pv].spec.dim);
    let scan = quantity(&a.scan, "scan", Dimension::TIME)?;
    match method {
        MethodArg::Relay | MethodArg::Zn | MethodArg::Tl => {
            let o = RelayOptions {
                amplitude: quantity(&a.relay_amplitude, "relay-amplitude", out_dim)?,
                hysteresis: quantity(&a.hysteresis, "hysteresis", pv_dim)?,
                scan,
                measurement: super::tune_plant::measurement(a)?,
            };
            let cycle = relay_loop(plant, x, l, o).map_err(tune_error)?;
            let (name, rule) = match method {
                MethodArg::Zn => ("zn", PiRule::ZieglerNichols),
                MethodArg::Tl => ("tl", PiRule::TyreusLuyben),
                _ => ("relay", PiRule::TyreusLuyben),
            };
            Ok(from_relay(l, &cycle, rule, name))
        }
        _ => {
            let order = a.model.map(|m| match m {
                ModelArg::Foptd => ModelOrder::Foptd,
                ModelArg::Soptd => ModelOrder::Soptd,
                ModelArg::Integrating => ModelOrder::Integrating,
            });
            let measurement = super::tune_plant::measurement(a)?;
            let o = StepOptions { step: quantity(&a.step, "step", out_dim)?, scan, order, measurement };
            let test = step_loop(plant, x, l, o).map_err(tune_error)?;
            let tau_c = quantity(&a.tau_c, "tau-c", Dimension::TIME)?;
            let rule = if method == MethodArg::Imc { ModelRule::Imc } else { ModelRule::Simc };
            from_step(l, test, rule, (tau_c, a.pid), measurement).map_err(tune_error)
        }
    }
}
