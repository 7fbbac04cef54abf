//! `plantwide tune --tf MODEL.tf.json --method blt|zn|tl [--time-unit min] [--json] [--plot OUT.png]`: PI settings
//! of the diagonal loops of a transfer-function model from the ultimate gains and periods of its
//! diagonal elements (Ziegler–Nichols, Tyreus–Luyben), or Luyben's BLT detuning of the ZN settings;
//! `--plot` draws each loop's Bode diagram with its margins.
//!
//! `plantwide tune FILE --loop CTRL --method relay|zn|tl|simc|imc|averaging` and
//! `plantwide tune FILE --loops C1,C2,… --method blt` tune the PID loops of a flowsheet
//! ([`super::tune_plant`]).

use std::path::{Path, PathBuf};

use plantwide::analysis::tf::TfModel;
use plantwide::io::report::tune as report;
use plantwide::io::tf;
use plantwide::studies::tune::{BltSettings, PiRule, blt, bode_diagrams, single_loop};

use super::CliError;
use super::linearize::TimeUnit;
use super::tune_plant::tune_error;

/// Tuning method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// Luyben's biggest-log-modulus tuning: ZN settings detuned by one F, max L_cm = 2n dB.
    Blt,
    /// Ziegler–Nichols PI (from the ultimate gain; on a flowsheet, from a relay test): Kc = Ku/2.2, τI = Pu/1.2.
    Zn,
    /// Tyreus–Luyben PI (from the ultimate gain; on a flowsheet, from a relay test): Kc = Ku/3.2, τI = 2.2 Pu.
    Tl,
    /// Relay-feedback test on the dynamic model: Ku, Pu and Tyreus–Luyben settings.
    Relay,
    /// Step test, FOPTD/SOPTD/IPDT fit, Skogestad's SIMC settings.
    Simc,
    /// Step test, fit, internal-model-control settings.
    Imc,
    /// Averaging level control of a level loop (P only, or critically damped PI with --form pi).
    Averaging,
}

/// Arguments of `plantwide tune`.
#[derive(Debug, clap::Args)]
pub struct TuneArgs {
    /// Flowsheet whose PID loops to tune (with --loop or --loops).
    #[arg(value_name = "FILE", required_unless_present = "tf", conflicts_with = "tf")]
    pub(super) file: Option<PathBuf>,
    /// Transfer-function model (`*.tf.json`); output i is paired with input i.
    #[arg(long, value_name = "MODEL")]
    pub(super) tf: Option<PathBuf>,
    /// Tuning method.
    #[arg(long, value_enum)]
    pub(super) method: MethodArg,
    /// The PID controller to tune.
    #[arg(long = "loop", value_name = "CTRL")]
    pub(super) loop_name: Option<String>,
    /// The PID controllers to tune, comma separated: together (blt) or one after another, cascade
    /// slaves before their masters, each tested with those before it tuned (the other methods).
    #[arg(long, value_name = "C1,C2,…", value_delimiter = ',')]
    pub(super) loops: Vec<String>,
    /// Override an input or unit field before converging (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub(super) set: Vec<String>,
    /// Write the flowsheet with the tuned settings (only those fields change) to this file.
    #[arg(long, value_name = "OUT.json")]
    pub(super) write: Option<PathBuf>,
    /// Measurement dead time of every loop that the model leaves out (blt, relay, zn, tl; simc and
    /// imc add it to the fitted model's dead time), e.g. "1 min".
    #[arg(long, value_name = "TIME")]
    pub(super) measurement_dead_time: Option<String>,
    /// Measurement first-order lag of every loop (blt, relay, zn, tl; simc and imc by Skogestad's
    /// half rule), e.g. "30 s".
    #[arg(long, value_name = "TIME")]
    pub(super) measurement_lag: Option<String>,
    /// Relay amplitude in the controller's output unit (default: 5 % of the output's steady value).
    #[arg(long, value_name = "VALUE")]
    pub(super) relay_amplitude: Option<String>,
    /// Relay hysteresis in the measurement's unit (default 0).
    #[arg(long, value_name = "VALUE")]
    pub(super) hysteresis: Option<String>,
    /// Scan (sampling) interval of the relay and step tests (default: from the loop's linear model).
    #[arg(long, value_name = "TIME")]
    pub(super) scan: Option<String>,
    /// Step of the output in a step test, in its unit (default: 5 % of its steady value).
    #[arg(long, value_name = "VALUE")]
    pub(super) step: Option<String>,
    /// Model fitted to the step test (default foptd; integrating for a level).
    #[arg(long, value_enum)]
    pub(super) model: Option<ModelArg>,
    /// Closed-loop time constant τc (SIMC) or filter time λ (IMC) (default: the fitted dead time).
    #[arg(long, value_name = "TIME")]
    pub(super) tau_c: Option<String>,
    /// PID instead of PI (SIMC on a SOPTD fit, IMC).
    #[arg(long)]
    pub(super) pid: bool,
    /// Averaging: the largest allowed level deviation (default: a quarter of the level, narrowed, with a
    /// note, where other loops move the level at that band's time scale).
    #[arg(long, value_name = "LEVEL")]
    pub(super) level_band: Option<String>,
    /// Averaging: the output change that balances the design disturbance (default: 10 % of the output).
    #[arg(long, value_name = "VALUE")]
    pub(super) flow_change: Option<String>,
    /// Averaging: P only (default) or critically damped PI.
    #[arg(long, value_enum, default_value = "p")]
    pub(super) form: FormArg,
    /// Time unit of the periods and reset times printed (s, min, h).
    #[arg(long, default_value = "s")]
    pub(super) time_unit: String,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub(super) json: bool,
    /// Draw each tuned loop's Bode diagram here (`.png` or `.svg`): |L| and ∠L of L = g·c against
    /// ω, the crossovers marked and the gain and phase margins read off them.
    #[arg(long, value_name = "OUT.png", value_parser = super::output_file)]
    pub(super) plot: Option<PathBuf>,
    /// Write the report of a flowsheet's tuning to this folder: tune.md and tune.html (the table
    /// and the Bode diagrams), tune.json, tune.svg.
    #[arg(long, value_name = "DIR", conflicts_with = "tf")]
    pub(super) report: Option<PathBuf>,
}

/// Model fitted to a step test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ModelArg {
    /// First order plus dead time.
    Foptd,
    /// Second order plus dead time.
    Soptd,
    /// Integrating plus dead time.
    Integrating,
}

/// Averaging-level form.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FormArg {
    /// Proportional only.
    P,
    /// Critically damped PI.
    Pi,
}

pub fn run(a: &TuneArgs) -> Result<(), CliError> {
    let tu = TimeUnit::parse(&a.time_unit)?;
    let (Some(tf_file), None) = (&a.tf, &a.file) else {
        return super::tune_plant::run(a, &tu);
    };
    let model = load(tf_file)?;
    let tuning = match a.method {
        MethodArg::Blt => blt(&model, &BltSettings::default()),
        MethodArg::Zn => single_loop(&model, PiRule::ZieglerNichols),
        MethodArg::Tl => single_loop(&model, PiRule::TyreusLuyben),
        m => {
            return Err(CliError::user(format!(
                "--method {}: a transfer-function model is tuned by blt, zn or tl; relay, simc, imc and averaging \
                 test a flowsheet's loops (plantwide tune FILE --loop CTRL)",
                format!("{m:?}").to_lowercase()
            )));
        }
    }
    .map_err(tune_error)?;
    let tu = report::TimeUnit { name: tu.name.clone(), seconds: tu.seconds };
    if let Some(out) = &a.plot {
        let diagrams = bode_diagrams(&model, &tuning).into_iter().zip(&tuning.loops);
        let loops = diagrams.filter_map(|(b, l)| Some((format!("{} ← {}", l.output, l.input), b?))).collect();
        let title = format!("Bode diagrams of the loops of `{}`, each alone", model.name);
        report::bode(out, &title, &tu, loops).map_err(|e| CliError::user(format!("--plot {e}")))?;
    }
    if a.json {
        let shown = tuning.in_time_unit(tu.seconds);
        outln!("{}", plantwide::io::report::json(&shown).map_err(|e| CliError::user(e.to_string()))?);
        return Ok(());
    }
    out!("{}", report::model_text(&tuning, &model, &tf_file.display().to_string(), &tu));
    Ok(())
}

fn load(file: &Path) -> Result<TfModel, CliError> {
    let text = plantwide::flowsheet::read_text(file).map_err(|e| CliError::user(e.to_string()))?;
    tf::parse(&text, &file.display().to_string()).map_err(|e| CliError::user(e.to_string()))
}
