//! `plantwide tune --tf MODEL.tf.json --method blt|zn|tl [--time-unit min] [--json]`: PI settings
//! of the diagonal loops of a transfer-function model from the ultimate gains and periods of its
//! diagonal elements (Ziegler–Nichols, Tyreus–Luyben), or Luyben's BLT detuning of the ZN settings.

use std::path::{Path, PathBuf};

use plantwide::analysis::tf::TfModel;
use plantwide::io::tf;
use plantwide::studies::TuneError;
use plantwide::studies::tune::{BltSettings, PiRule, TuneMethod, Tuning, blt, single_loop};

use super::CliError;
use super::linearize::TimeUnit;

/// Tuning method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// Luyben's biggest-log-modulus tuning: ZN settings detuned by one F, max L_cm = 2n dB.
    Blt,
    /// Ziegler–Nichols PI of each loop alone: Kc = Ku/2.2, τI = Pu/1.2.
    Zn,
    /// Tyreus–Luyben PI of each loop alone: Kc = Ku/3.2, τI = 2.2 Pu.
    Tl,
}

/// Arguments of `plantwide tune`.
#[derive(Debug, clap::Args)]
pub struct TuneArgs {
    /// Transfer-function model (`*.tf.json`); output i is paired with input i.
    #[arg(long, value_name = "MODEL")]
    tf: PathBuf,
    /// Tuning method.
    #[arg(long, value_enum)]
    method: MethodArg,
    /// Time unit of the periods and reset times printed (s, min, h).
    #[arg(long, default_value = "s")]
    time_unit: String,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

fn tune_error(e: TuneError) -> CliError {
    if e.is_user_error() { CliError::user(e.to_string()) } else { CliError::numerical(e.to_string()) }
}

pub fn run(a: &TuneArgs) -> Result<(), CliError> {
    let tu = TimeUnit::parse(&a.time_unit)?;
    let model = load(&a.tf)?;
    let tuning = match a.method {
        MethodArg::Blt => blt(&model, &BltSettings::default()),
        MethodArg::Zn => single_loop(&model, PiRule::ZieglerNichols),
        MethodArg::Tl => single_loop(&model, PiRule::TyreusLuyben),
    }
    .map_err(tune_error)?
    .in_time_unit(tu.seconds);
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&tuning).map_err(|e| CliError::user(e.to_string()))?);
        return Ok(());
    }
    print_table(&tuning, &model, &a.tf, &tu);
    Ok(())
}

fn load(file: &Path) -> Result<TfModel, CliError> {
    let text = plantwide::flowsheet::read_text(file).map_err(|e| CliError::user(e.to_string()))?;
    tf::parse(&text, &file.display().to_string()).map_err(|e| CliError::user(e.to_string()))
}

fn print_table(t: &Tuning, model: &TfModel, file: &Path, tu: &TimeUnit) {
    let what = match (t.detuning_factor, t.max_lcm_db, t.peak_omega) {
        (Some(f), Some(db), Some(w)) => format!(
            "BLT (Luyben 1986): detuning factor F = {f:.4}, biggest log modulus {db:.3} dB at ω = {w:.4} rad/{}",
            tu.name
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
    }
}
