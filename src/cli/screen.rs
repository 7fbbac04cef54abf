//! `plantwide screen FILE --column COL --outputs TOP,BOTTOM [--disturbances …] [--steady-only]
//! [--write-dir DIR] [--json] [--report DIR]`: the inventory configurations of a column, built
//! through the library, judged by their scaled steady-state gains and ranked by a dynamic check
//! (each tuned by BLT and stepped by the disturbances), or by the steady state alone;
//! `plantwide screen FILE --cvs … --mvs … [--disturbances …] [--throughput …]`: the pairings of CVs
//! to MVs, filtered at steady state and the best tested dynamically; `--shard I/N` runs a share of
//! the dynamic tests (task `t`: the `t`-th candidate tested), `plantwide merge` scores them all.

use std::path::{Path, PathBuf};

use plantwide::io::html::markdown_to_html;
use plantwide::io::plot::{LabelledMatrix, Overlay, write_bars, write_matrices};
use plantwide::studies::screen::column::file_stem;
use plantwide::studies::screen::pairings::STEP_AT;
use plantwide::studies::screen::pairings::mpc::MpcAlternative;
use plantwide::studies::screen::pairings::{
    CandidateTask, Disturbance, DynamicResult, DynamicSettings, PairingRequest, PairingScreen, Watch,
};
use plantwide::studies::screen::{
    ColumnDynamic, ColumnRequest, ColumnScreen, ColumnStructure, ScreenError, screen_column_with, screen_pairings,
};
use plantwide::units::Dimension;

use plantwide::units::UnitSystem;

use super::CliError;
use super::shard::ShardArgs;
use super::steady::load_with_overrides;
use plantwide::io::report::shown::Shown;

/// Arguments of `plantwide screen`.
#[derive(Debug, clap::Args)]
pub struct ScreenArgs {
    /// Flowsheet file (JSON).
    #[arg(value_name = "FILE")]
    file: PathBuf,
    /// The column whose inventory configurations to screen (LV, DV, LB, DB, (L/D)V, L(V/B), (L/D)(V/B)).
    #[arg(long, value_name = "COL", required_unless_present = "cvs", conflicts_with = "cvs")]
    column: Option<String>,
    /// The two qualities, top then bottom (variable paths), e.g. distillate.x[light],bottoms.x[light].
    #[arg(long, value_name = "TOP,BOTTOM", value_delimiter = ',', requires = "column")]
    outputs: Vec<String>,
    /// Rank a column's configurations by their steady-state measures alone (fast): no dynamic check.
    #[arg(long, requires = "column", conflicts_with_all = ["write_dir", "disturbances", "duration"])]
    steady_only: bool,
    /// Write each configuration's flowsheet, its quality loops as tuned by the dynamic check
    /// (`<config>.json`: LV, DV, LB, LD-V, L-VB, LD-VB), and each run's scenario
    /// (`step<N>.scenario.json`) here, for `plantwide run`.
    #[arg(long, value_name = "DIR", requires = "column")]
    write_dir: Option<PathBuf>,
    /// The largest deviation allowed of each quality, top then bottom (in its unit, SI when bare):
    /// the scale of the gains and IAEs (default: a mole fraction's distance to 0 or 1).
    #[arg(long, value_name = "TOP,BOTTOM", value_delimiter = ',', requires = "column")]
    allowed_deviation: Vec<String>,
    /// Controlled variables to pair (variable paths), comma separated.
    #[arg(long, value_name = "CV1,CV2,…", value_delimiter = ',', requires = "mvs")]
    cvs: Vec<String>,
    /// Manipulated variables (input paths), comma separated.
    #[arg(long, value_name = "MV1,MV2,…", value_delimiter = ',')]
    mvs: Vec<String>,
    /// Throughput-manipulator candidates (each one of the MVs, held while the others are paired).
    #[arg(long, value_name = "MV,…", value_delimiter = ',')]
    throughput: Vec<String>,
    /// Disturbances of the dynamic and sensitivity tests: input paths, each stepped by +10 %, or
    /// PATH=+x%, -x%, ±x% (one run each way) or an amount with its unit (PATH=+5 K,
    /// PATH=-10 kmol/h); the sweeps go to both sides by the step's size. With --column the
    /// default is the rate ±10 % and composition ± a tenth of its room of each feed upstream.
    #[arg(long, value_name = "PATH[=±x%|±AMOUNT],…", value_delimiter = ',')]
    disturbances: Vec<String>,
    /// Uncontrolled variables that must stay in a band over ± each disturbance with the CVs held
    /// (sensitivity test), e.g. "column1.x[1][B]=0:0.02" or "reactor.T=340 K:360 K".
    #[arg(long, value_name = "PATH=LOW:HIGH")]
    watch: Vec<String>,
    /// How many steady-state survivors to test dynamically.
    #[arg(long, default_value_t = 4)]
    candidates: usize,
    /// Measurement dead time of every loop in the dynamic test's tuning.
    #[arg(long, value_name = "TIME", default_value = "1 min")]
    measurement_dead_time: String,
    /// Length of each dynamic run (default: 20 × the longest reset time of the tuned loops).
    #[arg(long, value_name = "TIME")]
    duration: Option<String>,
    /// A model predictive controller to judge beside the PI candidates on the same runs: a JSON
    /// file with one `"type": "mpc"` controller description (as in a flowsheet's `controllers`)
    /// on the --cvs and some of the --mvs; a CV's `sp` defaults to its steady value.
    #[arg(long, value_name = "FILE", requires = "cvs")]
    mpc: Option<PathBuf>,
    /// Override an input or unit field before converging (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Write a report here: screen.md and screen.json.
    #[arg(long, value_name = "DIR")]
    report: Option<PathBuf>,
    /// Sharding of the pairings' dynamic tests over processes.
    #[command(flatten)]
    pub shard: ShardArgs,
}

fn screen_error(e: ScreenError) -> CliError {
    if e.is_user_error() { CliError::user(e.to_string()) } else { CliError::numerical(e.to_string()) }
}

/// Run `plantwide screen`.
pub fn run(a: &ScreenArgs, system: UnitSystem) -> Result<(), CliError> {
    let (plant, _) = load_with_overrides(&a.file, &a.set)?;
    let Some(column) = &a.column else { return pairings(a, &plant, system) };
    if a.shard.is_shard() {
        return Err(CliError::user(
            "--shard splits the pairings' dynamic tests (--cvs … --mvs … --disturbances …); a column's seven \
             configurations run in one process, in parallel: drop --shard",
        ));
    }
    let request = column_request(a, &plant, column)?;
    let screen = screen_column_with(&plant, &request).map_err(screen_error)?;
    let json = serde_json::to_string_pretty(&screen).map_err(|e| CliError::user(e.to_string()))?;
    if let Some(dir) = &a.report {
        write_report(dir, &a.file, &screen, &json)?;
    }
    let written = a.write_dir.as_deref().map(|dir| write_flowsheets(dir, &screen)).transpose()?;
    if a.json {
        outln!("{json}");
    } else {
        outln!("{}", table(&screen, &a.file));
        if let (Some(dir), Some(n)) = (&a.write_dir, written) {
            outln!("wrote {n} tuned flowsheets and {} scenarios to {}", screen.scenarios.len(), dir.display());
        }
    }
    failed_parts("screen", &screen.failed)
}

/// The column screening `a` asks for.
fn column_request(
    a: &ScreenArgs,
    plant: &plantwide::flowsheet::Plant,
    column: &str,
) -> Result<ColumnRequest, CliError> {
    let allowed = match a.allowed_deviation.as_slice() {
        [] => None,
        [top, bottom] => Some([allowed(plant, &a.outputs, 0, top)?, allowed(plant, &a.outputs, 1, bottom)?]),
        more => {
            return Err(CliError::user(format!(
                "--allowed-deviation: give two deviations, top then bottom quality; got {}",
                more.len()
            )));
        }
    };
    let dynamic = match a.steady_only {
        true => None,
        false => Some(ColumnDynamic {
            disturbances: a.disturbances.iter().map(|d| disturbance(d)).collect::<Result<_, _>>()?,
            duration: a.duration.as_deref().map(|d| time(d, "duration")).transpose()?,
            measurement: plantwide::studies::tune::loops::Measurement {
                dead_time: time(&a.measurement_dead_time, "measurement-dead-time")?,
                lag: 0.0,
            },
            keep_flowsheets: a.write_dir.is_some(),
        }),
    };
    Ok(ColumnRequest { column: column.to_string(), outputs: a.outputs.clone(), allowed, dynamic })
}

/// Allowed deviation `text` of quality `k` of `outputs`, in the quality's unit (SI when bare).
fn allowed(plant: &plantwide::flowsheet::Plant, outputs: &[String], k: usize, text: &str) -> Result<f64, CliError> {
    let dim = outputs.get(k).and_then(|o| plant.var(o)).map_or(Dimension::DIMENSIONLESS, |v| plant.vars()[v].spec.dim);
    plantwide::units::parse_quantity_as(text.trim(), dim)
        .map_err(|e| CliError::user(format!("--allowed-deviation {text}: {e}")))
}

/// Write each configuration's tuned flowsheet and the runs' scenarios into `dir`; how many
/// flowsheets.
fn write_flowsheets(dir: &Path, s: &ColumnScreen) -> Result<usize, CliError> {
    let fail = |e: std::io::Error| CliError::user(format!("--write-dir {}: {e}", dir.display()));
    std::fs::create_dir_all(dir).map_err(fail)?;
    let pretty = |v: &serde_json::Value| serde_json::to_string_pretty(v).map_err(|e| CliError::user(e.to_string()));
    let mut n = 0;
    for c in &s.structures {
        if let Some(f) = &c.flowsheet {
            std::fs::write(dir.join(format!("{}.json", file_stem(&c.name))), f).map_err(fail)?;
            n += 1;
        }
    }
    for (name, text) in &s.scenarios {
        std::fs::write(dir.join(name), pretty(text)? + "\n").map_err(fail)?;
    }
    Ok(n)
}

/// Exit 2 when parts of a study failed (the report, already printed, marks them): the message
/// counts them and gives each one's reason.
pub(super) fn failed_parts(study: &str, failed: &[String]) -> Result<(), CliError> {
    plantwide::studies::request::failed_parts(study, failed).map_or(Ok(()), |m| Err(CliError::numerical(m)))
}

/// The configurations as a markdown table, in the library's order, with the scaling and the
/// verdict.
fn table(s: &ColumnScreen, file: &Path) -> String {
    let mut t = format!(
        "inventory configurations of column `{}` in {} (qualities {} and {}), ranked by the {}\n\n",
        s.column,
        file.display(),
        s.outputs[0],
        s.outputs[1],
        s.ranked_by
    );
    let allowed: Vec<String> = s
        .outputs
        .iter()
        .zip(&s.scaling.allowed_deviation)
        .zip(&s.scaling.basis)
        .map(|((o, d), b)| format!("{o} by {d:.4e} ({b})"))
        .collect();
    t.push_str(&format!("scaling of γ and of the IAEs: {}; {}\n", allowed.join(", "), s.scaling.inputs));
    if let Some(d) = s.duration {
        t.push_str(&format!(
            "dynamic check: PI loops tuned by BLT ({} s measurement dead time), {} runs of {:.4e} s: {}\n",
            s.measurement_dead_time.unwrap_or(0.0),
            s.disturbances.len(),
            d,
            s.disturbances.join(", ")
        ));
    }
    t.push_str(
        "\n| rank | structure | pairing (top, bottom) | λ | Niederlinski | γ scaled | γ* | scaled IAE [s] | steady rank | verdict |\n",
    );
    t.push_str("|---|---|---|---|---|---|---|---|---|---|\n");
    for c in &s.structures {
        t.push_str(&row(c));
    }
    t.push_str(&format!("\nverdict: {}\n", s.verdict));
    t
}

/// A configuration's row of the table.
fn row(c: &ColumnStructure) -> String {
    let num = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{v:.4}"));
    let place = |r: Option<usize>| r.map_or("–".to_string(), |r| r.to_string());
    let iae = match (&c.dynamic, c.iae_scaled) {
        (_, Some(v)) => format!("{v:.4e}"),
        (Some(_), None) if c.lost.is_some() => "lost".into(),
        (Some(_), None) => "failed".into(),
        (None, None) => "–".into(),
    };
    let note = match (&c.failure, &c.lost) {
        (Some(why), _) => format!("failed: {why}"),
        (None, Some(how)) => format!("{}; cannot ride through: {how}", c.verdict),
        (None, None) => c.verdict.clone(),
    };
    format!(
        "| {} | {} | {} | {} | {} | {} | {} | {iae} | {} | {} |\n",
        place(c.rank),
        c.name,
        c.pairing.as_ref().map_or_else(|| c.inputs.join(", "), |p| p.join(", ")),
        num(c.relative_gain),
        num(c.niederlinski),
        num(c.condition_number),
        num(c.minimized_condition_number),
        place(c.steady_rank),
        note
    )
}

fn write_report(dir: &Path, file: &Path, s: &ColumnScreen, json: &str) -> Result<(), CliError> {
    let fail = |e: std::io::Error| CliError::user(format!("--report {}: {e}", dir.display()));
    std::fs::create_dir_all(dir).map_err(fail)?;
    std::fs::write(dir.join("screen.json"), json).map_err(fail)?;
    let matrices: Vec<LabelledMatrix> = s
        .structures
        .iter()
        .map(|c| LabelledMatrix {
            label: format!("{} ({})", c.name, c.rank.map_or("not ranked".to_string(), |r| format!("rank {r}"))),
            values: c.rga.clone(),
            ..LabelledMatrix::default()
        })
        .collect();
    let title = format!("relative gains of column `{}`: {} (row 1), {} (row 2)", s.column, s.outputs[0], s.outputs[1]);
    for ext in ["png", "svg"] {
        write_matrices(&dir.join(format!("rga.{ext}")), &title, &matrices)
            .map_err(|e| CliError::user(e.to_string()))?;
    }
    let mut ranked: Vec<_> = s.structures.iter().collect();
    ranked.sort_by_key(|c| (c.rank.is_none(), c.rank));
    let dynamic = s.duration.is_some();
    let bars: Vec<(String, f64)> = ranked
        .iter()
        .map(|c| {
            let value = match dynamic {
                true => c.iae_scaled.unwrap_or(f64::NAN),
                false => c.relative_gain.filter(|_| c.rank.is_some()).map_or(f64::NAN, |l| l.ln().abs()),
            };
            (c.name.clone(), value)
        })
        .collect();
    let (title, axis) = match dynamic {
        true => (
            format!("ranking of column `{}`'s configurations by the dynamic check (– not run)", s.column),
            "scaled IAE [s]",
        ),
        false => (format!("ranking of column `{}`'s configurations (0 = decoupled; – singular)", s.column), "|ln λ|"),
    };
    write_bars(&dir.join("ranking.png"), &title, axis, &bars).map_err(|e| CliError::user(e.to_string()))?;
    let md = format!(
        "# Column configurations: `{}`\n\n{}\n![relative gains](rga.png)\n\n![ranking](ranking.png)\n",
        s.column,
        table(s, file)
    );
    std::fs::write(dir.join("screen.html"), markdown_to_html("Column configurations", &md)).map_err(fail)?;
    std::fs::write(dir.join("screen.md"), md).map_err(fail)
}

/// The ranked pairings' dynamic scores as bars (`false` when none was tested).
fn write_ranking(dir: &Path, s: &PairingScreen) -> Result<bool, CliError> {
    let mut ranked: Vec<_> = s.structures.iter().filter(|c| c.rank.is_some() && c.dynamic.is_some()).collect();
    if ranked.is_empty() {
        return Ok(false);
    }
    ranked.sort_by_key(|c| c.rank);
    let bars: Vec<(String, f64)> = ranked
        .iter()
        .map(|c| {
            let mvs: Vec<&str> = c.pairs.iter().map(|p| p.mv.as_str()).collect();
            let tpm = c.throughput.as_deref().map_or(String::new(), |t| format!("TPM {t}: "));
            (
                format!("{} {tpm}{}", c.rank.unwrap_or(0), mvs.join(", ")),
                c.dynamic.as_ref().map_or(f64::NAN, |d| d.score),
            )
        })
        .collect();
    let file = dir.join("ranking.png");
    write_bars(&file, "dynamic score (1 = best on every CV and disturbance)", "score", &bars)
        .map_err(|e| CliError::user(e.to_string()))?;
    Ok(true)
}

/// One figure per disturbance: each CV's response under the (up to three) best tested candidates.
fn write_responses(dir: &Path, s: &PairingScreen, shown: &Shown) -> Result<Vec<String>, CliError> {
    let mut best: Vec<_> = s
        .structures
        .iter()
        .filter(|c| c.rank.is_some() && c.dynamic.as_ref().is_some_and(DynamicResult::completed))
        .collect();
    best.sort_by_key(|c| c.rank);
    best.truncate(3);
    let Some(first) = best.first().and_then(|c| c.dynamic.as_ref()) else { return Ok(Vec::new()) };
    let mut names = Vec::new();
    for (d, run) in first.runs.iter().enumerate() {
        let panels: Vec<Overlay> = s
            .cvs
            .iter()
            .enumerate()
            .map(|(k, cv)| Overlay {
                label: shown.label(cv),
                curves: best
                    .iter()
                    .filter_map(|c| {
                        c.dynamic.as_ref().map(|t| {
                            let series = t.runs[d].series[k].iter().map(|v| shown.value(cv, *v)).collect();
                            (format!("rank {}", c.rank.unwrap_or(0)), series)
                        })
                    })
                    .collect(),
                ..Overlay::default()
            })
            .collect();
        let times: Vec<f64> = run.times.iter().map(|t| t / 3600.0).collect();
        let name = format!("responses_{}.png", d + 1);
        let title = format!("{}: the best structures' responses", run.disturbance);
        let step = [(STEP_AT * times.last().copied().unwrap_or(0.0), run.disturbance.clone())];
        plantwide::io::plot::write_responses(&dir.join(&name), &title, "time [h]", &times, &panels, &step)
            .map_err(|e| CliError::user(e.to_string()))?;
        names.push(name);
    }
    Ok(names)
}

pub(super) fn time(text: &str, flag: &str) -> Result<f64, CliError> {
    plantwide::units::parse_quantity_as(text, Dimension::TIME)
        .map_err(|e| CliError::user(format!("--{flag} {text}: {e}")))
}

/// A disturbance of `--disturbances`: `PATH` (+10 %), `PATH=±x%` or `PATH=±AMOUNT UNIT` (the
/// studies' one parser, [`plantwide::studies::disturbance`]).
pub(super) fn disturbance(text: &str) -> Result<Disturbance, CliError> {
    text.parse().map_err(|e| CliError::user(format!("--disturbances {e}")))
}

/// `PATH=LOW:HIGH`, the ends in the variable's unit (SI when bare).
fn watch(plant: &plantwide::flowsheet::Plant, text: &str) -> Result<Watch, CliError> {
    let bad = || CliError::user(format!("--watch {text}: expected PATH=LOW:HIGH, e.g. column1.x[1][B]=0:0.02"));
    let (path, band) = text.split_once('=').ok_or_else(bad)?;
    let (lo, hi) = band.split_once(':').ok_or_else(bad)?;
    let Some(v) = plant.var(path.trim()) else {
        return Err(CliError::user(format!("--watch {text}: no variable `{}`", path.trim())));
    };
    let dim = plant.vars()[v].spec.dim;
    let end = |s: &str| {
        plantwide::units::parse_quantity_as(s.trim(), dim).map_err(|e| CliError::user(format!("--watch {text}: {e}")))
    };
    let (low, high) = (end(lo)?, end(hi)?);
    if low.is_nan() || high.is_nan() || low >= high {
        return Err(CliError::user(format!("--watch {text}: the band must go from low to high")));
    }
    Ok(Watch { path: path.trim().to_string(), low, high })
}

fn pairings(a: &ScreenArgs, plant: &plantwide::flowsheet::Plant, system: UnitSystem) -> Result<(), CliError> {
    let dead_time = time(&a.measurement_dead_time, "measurement-dead-time")?;
    let duration = a.duration.as_deref().map(|d| time(d, "duration")).transpose()?;
    let cvs: Vec<(String, Option<String>)> = a
        .cvs
        .iter()
        .map(|c| {
            let (p, u) = plantwide::analysis::select::split_unit(c);
            (p.to_string(), u.map(String::from))
        })
        .collect();
    let request = PairingRequest {
        cvs: cvs.iter().map(|(p, _)| p.clone()).collect(),
        mvs: a.mvs.clone(),
        throughput: a.throughput.clone(),
        disturbances: a.disturbances.iter().map(|d| disturbance(d)).collect::<Result<_, _>>()?,
        watch: a.watch.iter().map(|w| watch(plant, w)).collect::<Result<_, _>>()?,
        dynamic: DynamicSettings {
            candidates: a.candidates,
            duration,
            measurement: plantwide::studies::tune::loops::Measurement { dead_time, lag: 0.0 },
        },
        record: Vec::new(),
        mpc: a.mpc.as_deref().map(mpc_description).transpose()?,
        share: a.shard.share_as::<CandidateTask, DynamicResult>()?,
    };
    let screen = screen_pairings(plant, &request).map_err(screen_error)?;
    if a.shard.is_shard() {
        let done = screen
            .tested
            .iter()
            .enumerate()
            .filter_map(|(t, &k)| screen.structures[k].dynamic.as_ref().map(|d| (t, CandidateTask::from(d))));
        return a.shard.write_part("screen", &a.file, screen.tested.len(), done);
    }
    a.shard.check_merged(screen.tested.len())?;
    let watched = request.watch.iter().map(|w| (w.path.clone(), None));
    let shown = Shown::new(std::slice::from_ref(plant), cvs.iter().cloned().chain(watched), system)
        .map_err(|e| CliError::user(super::with_flags(e.to_string(), e.field(), &[])))?;
    let json = serde_json::to_string_pretty(&screen).map_err(|e| CliError::user(e.to_string()))?;
    if let Some(dir) = &a.report {
        let fail = |e: std::io::Error| CliError::user(format!("--report {}: {e}", dir.display()));
        std::fs::create_dir_all(dir).map_err(fail)?;
        std::fs::write(dir.join("screen.json"), &json).map_err(fail)?;
        let mut figures: String =
            write_responses(dir, &screen, &shown)?.iter().map(|n| format!("\n![responses]({n})\n")).collect();
        if write_ranking(dir, &screen)? {
            figures.push_str("\n![ranking](ranking.png)\n");
        }
        let md = format!("# Pairings\n\n{}{figures}", pairing_table(&screen, &shown));
        std::fs::write(dir.join("screen.html"), markdown_to_html("Pairings", &md)).map_err(fail)?;
        std::fs::write(dir.join("screen.md"), md).map_err(fail)?;
    }
    if a.json {
        outln!("{json}");
    } else {
        outln!("{}", pairing_table(&screen, &shown));
    }
    failed_parts("screen", &screen.failed)
}

/// The `--mpc` file's controller description.
fn mpc_description(file: &Path) -> Result<serde_json::Value, CliError> {
    let text = plantwide::flowsheet::read_text(file).map_err(|e| CliError::user(e.to_string()))?;
    serde_json::from_str(&text).map_err(|e| CliError::user(format!("--mpc {}: {e}", file.display())))
}

/// A dynamic test's score as the tables show it: `failed`, `lost` (the plant left its operating
/// range in a run) or the number.
fn score_text(d: &DynamicResult) -> String {
    match (d.completed(), d.rides_through()) {
        (false, _) => "failed".into(),
        (true, false) => "lost".into(),
        (true, true) => format!("{:.3}", d.score),
    }
}

/// What did not finish in a dynamic test: its failed parts, else where the plant was lost.
fn unfinished(d: &DynamicResult) -> Option<String> {
    let failed = d.failures("failed");
    let parts = if failed.is_empty() { d.losses("cannot ride through") } else { failed };
    (!parts.is_empty()).then(|| parts.join("; "))
}

/// The model predictive controller's row of the pairing table.
fn mpc_row(m: &MpcAlternative) -> String {
    let dynamic = m.dynamic.as_ref();
    let score = dynamic.map_or("–".to_string(), score_text);
    let samples: usize = m.qp.iter().map(|l| l.samples).sum();
    let mean = m.qp.iter().map(|l| l.mean_solve_time * l.samples as f64).sum::<f64>() / samples.max(1) as f64;
    let note = dynamic.and_then(unfinished).unwrap_or_else(|| {
        format!(
            "every {} s, P = {}, M = {}; {samples} QPs, mean solve {:.3} ms; condition number {}",
            m.sample_time,
            m.prediction_horizon,
            m.control_horizon,
            1e3 * mean,
            m.condition_number.map_or("–".into(), |c| format!("{c:.3}"))
        )
    });
    format!(
        "| MPC | – | model predictive control: {} by {} | – | – | – | {score} | {note} |\n",
        m.cvs.join(", "),
        m.mvs.join(", ")
    )
}

/// The candidate structures as a markdown table, ranked first.
fn pairing_table(s: &PairingScreen, shown: &Shown) -> String {
    let mut t = format!(
        "{} complete pairings examined, {} partial ones cut for a non-positive relative gain; loops opened: {}\n\n",
        s.enumerated,
        s.pruned,
        if s.opened.is_empty() { "none".to_string() } else { s.opened.join(", ") }
    );
    for tpm in &s.singular {
        let choice = tpm.as_deref().map_or("the MVs".to_string(), |t| format!("the MVs with {t} held"));
        t.push_str(&format!(
            "singular: {choice} cannot set the CVs independently at steady state; no pairing listed\n\n"
        ));
    }
    let watched: Vec<String> = s
        .structures
        .first()
        .map(|c| {
            c.sensitivity
                .iter()
                .map(|w| {
                    format!(
                        "{} over {}: {:.6e} … {:.6e} {} ({})",
                        w.path,
                        w.disturbance,
                        shown.value(&w.path, w.min),
                        shown.value(&w.path, w.max),
                        shown.unit(&w.path),
                        if w.within { "in band" } else { "OUT of band" }
                    )
                })
                .collect()
        })
        .unwrap_or_default();
    if !watched.is_empty() {
        t.push_str(&format!("sensitivity (CVs held, first throughput choice): {}\n\n", watched.join("; ")));
    }
    t.push_str("| rank | throughput | pairs (relative gain) | NI | DIC | RGA number | dynamic score | note |\n");
    t.push_str("|---|---|---|---|---|---|---|---|\n");
    for c in &s.structures {
        let pairs: Vec<String> =
            c.pairs.iter().map(|p| format!("{} ← {} ({:.3})", p.cv, p.mv, p.relative_gain)).collect();
        let dynamic = c.dynamic.as_ref();
        let score = dynamic.map_or("–".to_string(), score_text);
        let note = c.rejected.clone().or(dynamic.and_then(unfinished)).unwrap_or_default();
        t.push_str(&format!(
            "| {} | {} | {} | {:.4} | {} | {:.3} | {score} | {note} |\n",
            c.rank.map_or("–".to_string(), |r| r.to_string()),
            c.throughput.as_deref().unwrap_or("–"),
            pairs.join("; "),
            c.niederlinski,
            if c.dic { "yes" } else { "no" },
            c.rga_number
        ));
    }
    if let Some(m) = &s.mpc {
        t.push_str(&mpc_row(m));
    }
    t.push_str(&format!("\nverdict: {}\n", s.verdict));
    t
}
