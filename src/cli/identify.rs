//! `plantwide identify FILE --inputs … --outputs … [--design prbs|gbn|directional] [--noise σ]
//! [--seed N] [--duration T] [--closed-loop] [--json] [--report DIR]`: a plant test on the
//! nonlinear model, FIR/ARX/OE fits and their validation (the reference book's chapter 7).

use std::path::PathBuf;

use plantwide::io::report::identify::{self as report, StepModel};
use plantwide::studies::identify::{Design, IdentifyError, IdentifyRequest, study};
use plantwide::units::{QuantityValue, UnitSystem};

use super::CliError;
use super::steady::{converge, load_with_overrides};

/// Test signal family (`--design`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DesignArg {
    /// Delayed copies of one PRBS (Eq. 7-10).
    Prbs,
    /// Independent generalized binary noise.
    Gbn,
    /// Independent signals along the input singular directions of the model's gain, the low-gain
    /// direction amplified (Koung & MacGregor 1991): for ill-conditioned plants.
    Directional,
}

/// Arguments of `plantwide identify`.
#[derive(Debug, clap::Args)]
pub struct IdentifyArgs {
    /// Flowsheet file (JSON).
    file: PathBuf,
    /// Inputs moved by the test, comma-separated, each `PATH[@unit]`.
    #[arg(long, value_delimiter = ',', required = true)]
    inputs: Vec<String>,
    /// Outputs measured, comma-separated, each `PATH[@unit]`.
    #[arg(long, value_delimiter = ',', required = true)]
    outputs: Vec<String>,
    /// Test signals.
    #[arg(long, value_enum, default_value_t = DesignArg::Directional)]
    design: DesignArg,
    /// White measurement noise σ per output, in the output's display unit (one for all, or one
    /// per output, comma-separated).
    #[arg(long, value_delimiter = ',', value_name = "σ", action = clap::ArgAction::Set)]
    noise: Vec<f64>,
    /// Seed of the test signals and the noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Length of the estimation test, e.g. `8000 min` (default four PRBS periods).
    #[arg(long, value_name = "T")]
    duration: Option<String>,
    /// Sample time, e.g. `10 min` (default τ_dom/20).
    #[arg(long, value_name = "T")]
    sample_time: Option<String>,
    /// Dominant time constant, e.g. `190 min` (default: the slowest of the exact linear model).
    #[arg(long, value_name = "T")]
    tau_dom: Option<String>,
    /// Largest move per input, in the input's display unit (one for all, or one per input;
    /// default 1 % of the steady value).
    #[arg(long, value_delimiter = ',', action = clap::ArgAction::Set)]
    amplitude: Vec<f64>,
    /// Closed-loop speed factor α of the PRBS design (Eq. 7-7).
    #[arg(long, default_value_t = 2.0)]
    alpha: f64,
    /// Settling factor β of the PRBS design (3: 95 %, 4: 98 %, 5: 99 %).
    #[arg(long, default_value_t = 3.0)]
    beta: f64,
    /// Directional design: output amplitude of the high-gain directions relative to the
    /// low-gain one's (1: Koung & MacGregor's equal amplitudes).
    #[arg(long, default_value_t = 2.0)]
    high_gain_boost: f64,
    /// Test in closed loop: the inputs are the outputs of the file's controllers, whose
    /// setpoints the test moves (setpoint injection).
    #[arg(long)]
    closed_loop: bool,
    /// Print `{"gain","rga","models","validation","design",…}` as JSON.
    #[arg(long)]
    json: bool,
    /// Write identify.md, identify.html, identify.json, the validation plot and step_model.json (the
    /// chosen models' step responses, a model for an `mpc` controller's `"model": {"file": …}`) here;
    /// step_model.json only when the verdict finds the model usable (or with --force).
    #[arg(long, value_name = "DIR")]
    report: Option<PathBuf>,
    /// Write step_model.json even when the verdict finds the model not usable (the exit code stays 2).
    #[arg(long, requires = "report")]
    force: bool,
    /// Override an input or a unit parameter first, e.g. `--set feed_source.F=1.01kmol/min`.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
}

/// The flags as the library's request (quantities as written; the library reads their units).
fn request(a: &IdentifyArgs, units: UnitSystem) -> IdentifyRequest {
    let q = |t: &Option<String>| t.as_deref().map(QuantityValue::from);
    IdentifyRequest {
        inputs: a.inputs.clone(),
        outputs: a.outputs.clone(),
        design: match a.design {
            DesignArg::Prbs => Design::Prbs,
            DesignArg::Gbn => Design::Gbn,
            DesignArg::Directional => Design::Directional,
        },
        noise: a.noise.clone(),
        seed: a.seed,
        duration: q(&a.duration),
        sample_time: q(&a.sample_time),
        tau_dom: q(&a.tau_dom),
        amplitude: a.amplitude.clone(),
        alpha: a.alpha,
        beta: a.beta,
        high_gain_boost: a.high_gain_boost,
        closed_loop: a.closed_loop,
        units,
    }
}

/// A library refusal or failure with the request's fields named as this command's flags.
fn identify_error(e: IdentifyError) -> CliError {
    let message = super::with_flags(e.to_string(), None, IdentifyRequest::FIELDS);
    if e.is_user_error() { CliError::user(message) } else { CliError::numerical(message) }
}

pub fn run(a: &IdentifyArgs, units: UnitSystem) -> Result<(), CliError> {
    let (plant, u) = load_with_overrides(&a.file, &a.set)?;
    let ss = converge(&plant, &u)?;
    let identified = study(&plant, &ss.x, &ss.u, &request(a, units)).map_err(identify_error)?;
    let id = &identified.identification;
    let step_model = match (&a.report, id.verdict.reliable, a.force) {
        (None, ..) => StepModel::NoReport,
        (Some(_), true, _) => StepModel::Written,
        (Some(_), false, true) => StepModel::Forced,
        (Some(_), false, false) => StepModel::Withheld,
    };
    let file = a.file.display().to_string();
    let io = |e: plantwide::io::IoError| CliError::user(format!("--report {e}"));
    // Said before the folder is written: a step model withheld now is told from one left there.
    let not_usable = report::not_usable(id, step_model, a.report.as_deref());
    if let Some(dir) = &a.report {
        report::write_report(dir, &file, &identified, step_model).map_err(io)?;
    }
    if a.json {
        outln!("{}", plantwide::io::report::json(id).map_err(io)?);
    } else {
        outln!("{}", report::markdown(&file, id, step_model));
    }
    not_usable.map_or(Ok(()), |m| Err(CliError::numerical(super::with_flags(m, None, &[]))))
}
