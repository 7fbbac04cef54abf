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
use plantwide::io::plot::{BodeLoop, write_bode};
use plantwide::io::tf;
use plantwide::studies::TuneError;
use plantwide::studies::tune::margins::Bode;
use plantwide::studies::tune::{BltSettings, PiRule, TuneMethod, Tuning, blt, bode_diagrams, single_loop};

use super::CliError;
use super::linearize::TimeUnit;

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
    /// Averaging: the largest allowed level deviation (default: a quarter of the level).
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

pub(super) fn tune_error(e: TuneError) -> CliError {
    if e.is_user_error() { CliError::user(e.to_string()) } else { CliError::numerical(e.to_string()) }
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
    if let Some(out) = &a.plot {
        let diagrams = bode_diagrams(&model, &tuning).into_iter().zip(&tuning.loops);
        let loops = diagrams.filter_map(|(b, l)| Some((format!("{} ← {}", l.output, l.input), b?))).collect();
        plot_bode(out, &format!("Bode diagrams of the loops of `{}`, each alone", model.name), &tu, loops)?;
    }
    let tuning = tuning.in_time_unit(tu.seconds);
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&tuning).map_err(|e| CliError::user(e.to_string()))?);
        return Ok(());
    }
    print_table(&tuning, &model, tf_file, &tu);
    Ok(())
}

/// Draw the Bode diagrams of `loops` (label, diagram with SI frequencies) to `out`, ω in rad per
/// `tu`.
pub(super) fn plot_bode(out: &Path, title: &str, tu: &TimeUnit, loops: Vec<(String, Bode)>) -> Result<(), CliError> {
    let drawn: Vec<BodeLoop> = loops
        .into_iter()
        .map(|(label, b)| {
            let b = b.in_time_unit(tu.seconds);
            let m = b.margins;
            BodeLoop {
                label,
                gain_crossover: m.gain_crossover.zip(m.phase_margin),
                phase_crossover: m.phase_crossover.zip(m.gain_margin),
                omega: b.omega,
                magnitude_db: b.magnitude_db,
                phase_deg: b.phase_deg,
            }
        })
        .collect();
    write_bode(out, title, &format!("ω [rad/{}]", tu.name), &drawn).map_err(|e| CliError::user(e.to_string()))
}

fn load(file: &Path) -> Result<TfModel, CliError> {
    let text = plantwide::flowsheet::read_text(file).map_err(|e| CliError::user(e.to_string()))?;
    tf::parse(&text, &file.display().to_string()).map_err(|e| CliError::user(e.to_string()))
}

fn print_table(t: &Tuning, model: &TfModel, file: &Path, tu: &TimeUnit) {
    let what = match (t.detuning_factor, t.max_lcm_db, t.peak_omega) {
        (Some(f), Some(db), Some(w)) => format!(
            "BLT (Luyben 1986): detuning factor F = {f:.4}, biggest log modulus {db:.3} dB at ω = {w:.4} rad/{}{}",
            tu.name,
            super::tune_plant::raised(t.unstable_at)
        ),
        _ if t.method == TuneMethod::TyreusLuyben => "Tyreus–Luyben PI, each loop tuned alone".to_string(),
        _ => "Ziegler–Nichols PI, each loop tuned alone".to_string(),
    };
    outln!("tuning of `{}` (transfer-function model {})", model.name, file.display());
    outln!("{what}\n");
    let unit = |name: &str| model.inputs.iter().chain(&model.outputs).find(|s| s.name == name).map(|s| s.unit.clone());
    let w_out = t.loops.iter().map(|l| l.output.len()).chain([6]).max().unwrap_or(6);
    let w_in = t.loops.iter().map(|l| l.input.len()).chain([5]).max().unwrap_or(5);
    let u = &tu.name;
    outln!(
        "{:<w_out$}  {:<w_in$}  {:>12}  {:>12}  {:>12}  {:>12}  gain unit",
        "output",
        "input",
        "Ku",
        format!("Pu [{u}]"),
        "Kc",
        format!("τI [{u}]")
    );
    for l in &t.loops {
        let gain_unit = match (unit(&l.input), unit(&l.output)) {
            (Some(i), Some(o)) if !i.is_empty() || !o.is_empty() => format!("({i})/({o})"),
            _ => String::new(),
        };
        outln!(
            "{:<w_out$}  {:<w_in$}  {:>12.5}  {:>12.5}  {:>12.5}  {:>12.5}  {gain_unit}",
            l.output,
            l.input,
            l.ku,
            l.pu,
            l.kc,
            l.tau_i
        );
        if let Some(m) = &l.margins {
            outln!("  {}", super::tune_plant::margins_line(m, u, "its element under its PI, the other loops open"));
        }
    }
}
