//! `plantwide tune FILE --loop CTRL --method relay|zn|tl|simc|imc|averaging` and
//! `plantwide tune FILE --loops C1,C2,… --method blt`: the flags as the library's
//! [`TuneRequest`], its answer printed, drawn, reported and optionally written into a copy of the
//! file (`--write`).

use plantwide::io::IoError;
use plantwide::io::report::tune::{self as report, TimeUnit};
use plantwide::studies::TuneError;
use plantwide::studies::tune::request::{Method, TuneRequest, tune, tuned_text};
use plantwide::units::QuantityValue;

use super::CliError;
use super::steady::{converge, load_with_overrides};
use super::tune::{FormArg, MethodArg, ModelArg, TuneArgs};

/// A library refusal or failure with the request's fields named as this command's flags.
pub(super) fn tune_error(e: TuneError) -> CliError {
    let message = super::with_flags(e.to_string(), e.field(), TuneRequest::FIELDS);
    if e.is_user_error() { CliError::user(message) } else { CliError::numerical(message) }
}

/// Tune the loops of `a.file`.
pub fn run(a: &TuneArgs, tu: &super::linearize::TimeUnit) -> Result<(), CliError> {
    let Some(file) = &a.file else { return Err(CliError::user("give a flowsheet FILE or --tf MODEL")) };
    let (plant, u) = load_with_overrides(file, &a.set)?;
    let request = request(a)?;
    plantwide::studies::tune::loops::plant_loops(&plant, &request.loops).map_err(tune_error)?;
    let x = converge(&plant, &u)?.x;
    let tuned = tune(&plant, &x, &request).map_err(tune_error)?;
    let tu = TimeUnit { name: tu.name.clone(), seconds: tu.seconds };
    let io = |flag: &str, e: IoError| CliError::user(format!("{flag} {e}"));
    if let Some(out) = &a.plot {
        report::plot(out, &tuned, &plant, &tu).map_err(|e| io("--plot", e))?;
    }
    let failed = tuned.failed();
    if let Some(out) = a.write.as_ref().filter(|_| failed.is_empty()) {
        let text = plantwide::flowsheet::read_text(file).map_err(|e| CliError::user(e.to_string()))?;
        let new = tuned_text(&text, &file.display().to_string(), &plant, &tuned.tuning, &tu.name);
        std::fs::write(out, new.map_err(tune_error)?)
            .map_err(|e| CliError::user(format!("{}: cannot write: {e}", out.display())))?;
    }
    if a.json {
        outln!("{}", report::json(&tuned, &tu).map_err(|e| io("--json", e))?);
    } else {
        out!("{}", report::text(&tuned, &plant, &tu));
    }
    if let Some(dir) = &a.report {
        report::write_report(dir, &tuned, &plant, &tu).map_err(|e| io("--report", e))?;
    }
    match failed.is_empty() {
        true => Ok(()),
        false => Err(CliError::numerical(format!(
            "{}{}",
            failed.join("\n"),
            if a.write.is_some() { "\nnothing written" } else { "" }
        ))),
    }
}

/// The flags as the library's request (quantities as written; the library reads their units).
fn request(a: &TuneArgs) -> Result<TuneRequest, CliError> {
    let loops = match (&a.loop_name, a.loops.is_empty()) {
        (None, false) => a.loops.clone(),
        (Some(l), true) => vec![l.clone()],
        (Some(_), false) => return Err(CliError::user("give either --loop CTRL or --loops C1,C2,…, not both")),
        (None, true) => return Err(CliError::user("give the loop to tune: --loop CTRL (or --loops C1,C2,…)")),
    };
    let method = match a.method {
        MethodArg::Blt => Method::Blt,
        MethodArg::Zn => Method::Zn,
        MethodArg::Tl => Method::Tl,
        MethodArg::Relay => Method::Relay,
        MethodArg::Simc => Method::Simc,
        MethodArg::Imc => Method::Imc,
        MethodArg::Averaging => Method::Averaging,
    };
    let model = a.model.map(|m| match m {
        ModelArg::Foptd => plantwide::studies::tune::fit::ModelOrder::Foptd,
        ModelArg::Soptd => plantwide::studies::tune::fit::ModelOrder::Soptd,
        ModelArg::Integrating => plantwide::studies::tune::fit::ModelOrder::Integrating,
    });
    let form = match a.form {
        FormArg::P => plantwide::studies::tune::averaging::AveragingForm::P,
        FormArg::Pi => plantwide::studies::tune::averaging::AveragingForm::Pi,
    };
    let q = |t: &Option<String>| t.as_deref().map(QuantityValue::from);
    Ok(TuneRequest {
        loops,
        method,
        measurement_dead_time: q(&a.measurement_dead_time),
        measurement_lag: q(&a.measurement_lag),
        relay_amplitude: q(&a.relay_amplitude),
        hysteresis: q(&a.hysteresis),
        scan: q(&a.scan),
        step: q(&a.step),
        model,
        tau_c: q(&a.tau_c),
        pid: a.pid,
        level_band: q(&a.level_band),
        flow_change: q(&a.flow_change),
        form,
        time_unit: a.time_unit.clone(),
    })
}
