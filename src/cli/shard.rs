//! `--shard I/N [--part FILE]` on the sweeping commands (`sensitivity`, `screen`) and
//! `plantwide merge PART…`: a job's independent tasks split over processes without Python or a
//! scheduler of ours (Slurm job arrays, Kubernetes indexed Jobs), put together afterwards.
//!
//! A shard computes its tasks ([`Shard::owns`]) and writes them to a part file; it prints, plots
//! and reports nothing else. `merge` checks the parts ([`plantwide::io::part::merge`]), checks the
//! flowsheet is the one the shards read, and runs the command line they were started with, its
//! tasks taken from the parts: the text, `--json`, `--csv`, `--plot` and `--report` are those of the
//! one-process run, bit for bit.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use clap::Parser;
use plantwide::analysis::shard::{Shard, Share};
use plantwide::io::part::{self, FORMAT, Part, VERSION};
use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::Value;

use super::{Cli, CliError, Command};

/// The sharding options of a sweeping command.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ShardArgs {
    /// Compute only shard I of N of the job's independent tasks (I counts from 0: `0/4` … `3/4`,
    /// as `$SLURM_ARRAY_TASK_ID` with `--array=0-3` or `$JOB_COMPLETION_INDEX`) and write them to
    /// a part file; `plantwide merge` puts the N parts together.
    #[arg(long, value_name = "I/N")]
    shard: Option<Shard>,
    /// The part file to write (default `<command>-<job>.part-<I>-of-<N>.json`, `<job>` a
    /// fingerprint of the command line and the flowsheet).
    #[arg(long, value_name = "FILE", requires = "shard")]
    part: Option<PathBuf>,
    /// The tasks' results given by `merge`.
    #[arg(skip)]
    merged: Option<BTreeMap<usize, Value>>,
}

impl ShardArgs {
    /// Which tasks this process computes: all, its shard's, or none (merged).
    pub fn share<T: DeserializeOwned>(&self) -> Result<Share<T>, CliError> {
        self.share_as::<T, T>()
    }

    /// [`ShardArgs::share`] of results written in the parts as `W`.
    pub fn share_as<W: DeserializeOwned, T: From<W>>(&self) -> Result<Share<T>, CliError> {
        if let Some(given) = &self.merged {
            let mut out = BTreeMap::new();
            for (&task, v) in given {
                let r = W::deserialize(v)
                    .map_err(|e| CliError::user(format!("merge: the result of task {task} does not read back: {e}")))?;
                out.insert(task, T::from(r));
            }
            return Ok(Share::Merge(out));
        }
        Ok(self.shard.map_or(Share::All, Share::Shard))
    }

    /// When merging, that the parts hold exactly the job's `tasks` tasks (a part file edited by
    /// hand could claim another count than the command line gives).
    pub fn check_merged(&self, tasks: usize) -> Result<(), CliError> {
        match &self.merged {
            Some(given) if given.len() != tasks || given.keys().any(|&t| t >= tasks) => Err(CliError::user(format!(
                "merge: the parts hold {} task results, but the command line makes {tasks} tasks; run the shards again",
                given.len()
            ))),
            _ => Ok(()),
        }
    }

    /// Whether this process is a shard.
    pub fn is_shard(&self) -> bool {
        self.shard.is_some()
    }

    /// Write this shard's `results` (task number, result) of a job of `tasks` tasks of `command`
    /// on the flowsheet `file`, and say so.
    pub fn write_part<T: Serialize>(
        &self,
        command: &str,
        file: &Path,
        tasks: usize,
        results: impl IntoIterator<Item = (usize, T)>,
    ) -> Result<(), CliError> {
        let Some(shard) = self.shard else { return Ok(()) };
        let user = |e: String| CliError::user(e);
        let text = plantwide::flowsheet::read_text(file).map_err(|e| user(e.to_string()))?;
        let args = job_args();
        let fingerprint = part::fingerprint(text.as_bytes());
        let results: BTreeMap<usize, Value> = results
            .into_iter()
            .map(|(t, r)| serde_json::to_value(&r).map(|v| (t, v)))
            .collect::<Result<_, _>>()
            .map_err(|e| user(format!("part file: {e}")))?;
        let done = results.len();
        let p = Part {
            format: FORMAT.into(),
            version: VERSION,
            plantwide: env!("CARGO_PKG_VERSION").into(),
            command: command.into(),
            flowsheet: file.display().to_string(),
            fingerprint: fingerprint.clone(),
            shard,
            tasks,
            results,
            args,
        };
        let job = part::fingerprint(format!("{}\u{0}{fingerprint}", p.args.join("\u{0}")).as_bytes());
        let out = self.part.clone().unwrap_or_else(|| {
            PathBuf::from(format!("{command}-{}.part-{}-of-{}.json", &job[..8], shard.index, shard.count))
        });
        let json = serde_json::to_string(&p).map_err(|e| user(format!("part file: {e}")))?;
        std::fs::write(&out, json).map_err(|e| user(format!("--part {}: cannot write: {e}", out.display())))?;
        outln!(
            "shard {}/{} of `{command}`: {done} of {tasks} tasks computed, written to {}; merge all {} parts with `plantwide merge`",
            shard.index,
            shard.count,
            out.display(),
            shard.count
        );
        Ok(())
    }
}

/// This process's command line after the program name, less `--shard` and `--part` (a part
/// file's job: the same for every shard).
fn job_args() -> Vec<String> {
    let mut out = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--shard" | "--part" => {
                args.next();
            }
            s if s.starts_with("--shard=") || s.starts_with("--part=") => {}
            _ => out.push(a),
        }
    }
    out
}

/// Arguments of `plantwide merge`.
#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// The part files of one job, one per shard (any order), e.g. `sensitivity-*.part-*.json`.
    #[arg(value_name = "PART", required = true)]
    parts: Vec<PathBuf>,
}

/// Run `plantwide merge`.
pub fn run(a: &MergeArgs) -> Result<(), CliError> {
    let mut parts = Vec::with_capacity(a.parts.len());
    for p in &a.parts {
        let name = p.display().to_string();
        let text = plantwide::flowsheet::read_text(p).map_err(|e| CliError::user(e.to_string()))?;
        parts.push((name.clone(), part::parse(&text, &name).map_err(|e| CliError::user(e.to_string()))?));
    }
    let job = part::merge(parts).map_err(|e| CliError::user(e.to_string()))?;
    let text = plantwide::flowsheet::read_text(Path::new(&job.flowsheet)).map_err(|e| {
        CliError::user(format!("merge: the shards' flowsheet cannot be read (run merge where the shards ran): {e}"))
    })?;
    let now = part::fingerprint(text.as_bytes());
    if now != job.fingerprint {
        return Err(CliError::user(format!(
            "merge: {} changed since the shards ran (fingerprint {now}, the shards read {}); run the shards again",
            job.flowsheet, job.fingerprint
        )));
    }
    let argv = std::iter::once("plantwide".to_string()).chain(job.args.iter().cloned());
    let mut cli =
        Cli::try_parse_from(argv).map_err(|e| CliError::user(format!("merge: the parts' command line: {e}")))?;
    match &mut cli.command {
        Command::Sensitivity(s) => s.shard.merged = Some(job.results),
        Command::Screen(s) => s.shard.merged = Some(job.results),
        _ => return Err(CliError::user(format!("merge: `{}` is no sharded command", job.command))),
    }
    super::run(cli)
}
