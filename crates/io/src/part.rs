//! Part files of a sharded job (`--shard I/N` on a sweeping command) and their merge
//! (`plantwide merge`).
//!
//! A part file is JSON: the command line the job was started with (less its `--shard` and
//! `--part`), a fingerprint of the flowsheet file, the shard, the job's task count and the results
//! of this shard's tasks by task number. [`merge`] checks that the parts belong to one job (same
//! command line, flowsheet, plantwide version and shard count), that every shard is there exactly
//! once and every task has exactly one result from the shard that owns it, then hands the results
//! back for the command to finish as if it had computed them itself. Numbers are written with
//! shortest round-trip formatting, so a merged result is the one-process result bit for bit.

use std::collections::BTreeMap;

use plantwide_analysis::shard::{MAX_SHARDS, Shard};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// The `format` tag of a part file.
pub const FORMAT: &str = "plantwide-part";
/// The layout version of a part file.
pub const VERSION: u32 = 1;
/// Most tasks a job may have (a bound on what a part file can make `merge` do).
pub const MAX_TASKS: usize = 1_000_000;

/// What a part file holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Part {
    /// Always [`FORMAT`].
    pub format: String,
    /// [`VERSION`].
    pub version: u32,
    /// The plantwide version that computed it (parts of one job come from one version).
    pub plantwide: String,
    /// The subcommand (`sensitivity`, `screen`).
    pub command: String,
    /// The command line after the program name, without `--shard` and `--part`.
    pub args: Vec<String>,
    /// The flowsheet file as named on the command line.
    pub flowsheet: String,
    /// [`fingerprint`] of the flowsheet file's bytes.
    pub fingerprint: String,
    /// This shard.
    pub shard: Shard,
    /// Tasks of the whole job.
    pub tasks: usize,
    /// This shard's results by task number.
    pub results: BTreeMap<usize, Value>,
}

/// The job the parts put together: its command line and every task's result.
#[derive(Debug, Clone, PartialEq)]
pub struct Job {
    /// The subcommand.
    pub command: String,
    /// Its command line after the program name.
    pub args: Vec<String>,
    /// The flowsheet file as named on the command line.
    pub flowsheet: String,
    /// Fingerprint of the flowsheet the shards read.
    pub fingerprint: String,
    /// Every task's result.
    pub results: BTreeMap<usize, Value>,
}

/// Why parts do not merge.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PartError {
    /// Not a part file, or not one this version reads.
    #[error("{file}: not a plantwide part file ({why}); give the files that a `shard` I/N run wrote")]
    NotAPart {
        /// The file.
        file: String,
        /// What is wrong.
        why: String,
    },
    /// A part of another job.
    #[error("{file}: a part of another job ({field} differs from {first}'s: `{theirs}` vs `{ours}`)")]
    OtherJob {
        /// The file.
        file: String,
        /// The first part given.
        first: String,
        /// What differs.
        field: &'static str,
        /// Its value in the first part.
        ours: String,
        /// Its value in this part.
        theirs: String,
    },
    /// A shard given twice.
    #[error("{file}: shard {index}/{count} is also in {other}; give each part once")]
    Duplicate {
        /// The file.
        file: String,
        /// The shard.
        index: usize,
        /// Shards of the job.
        count: usize,
        /// The other file.
        other: String,
    },
    /// Shards missing.
    #[error("shards {missing} of {count} are missing; run them (`shard` I/{count}) and merge all {count} parts")]
    Missing {
        /// The missing indices, comma-separated.
        missing: String,
        /// Shards of the job.
        count: usize,
    },
    /// A part whose results are not its shard's tasks.
    #[error(
        "{file}: shard {index}/{count} holds task {task}, which is not its own (or beyond the job's {tasks} tasks)"
    )]
    Foreign {
        /// The file.
        file: String,
        /// The shard.
        index: usize,
        /// Shards of the job.
        count: usize,
        /// The task.
        task: usize,
        /// Tasks of the job.
        tasks: usize,
    },
    /// A task without a result.
    #[error("{file}: task {task} of shard {index}/{count} has no result; run that shard again")]
    Incomplete {
        /// The file.
        file: String,
        /// The task.
        task: usize,
        /// The shard.
        index: usize,
        /// Shards of the job.
        count: usize,
    },
    /// No part given.
    #[error("no part files given: `plantwide merge PART.json …`")]
    Empty,
}

/// A 64-bit FNV-1a fingerprint of `bytes`, as 16 hex digits: it tells a flowsheet edited between
/// the shards and the merge from the one they read (a check against accidents, not an
/// adversary, which is why no cryptographic hash is needed).
pub fn fingerprint(bytes: &[u8]) -> String {
    let h = bytes.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3));
    format!("{h:016x}")
}

/// Parse one part file's `text` (`file` names it in messages).
///
/// # Errors
/// [`PartError::NotAPart`] for text that is not a part file of this layout version.
pub fn parse(text: &str, file: &str) -> Result<Part, PartError> {
    let not = |why: String| PartError::NotAPart { file: file.to_string(), why };
    let part: Part = serde_json::from_str(text).map_err(|e| not(e.to_string()))?;
    if part.format != FORMAT {
        return Err(not(format!("format `{}`, expected `{FORMAT}`", part.format)));
    }
    if part.version != VERSION {
        return Err(not(format!("layout version {}, this plantwide reads {VERSION}", part.version)));
    }
    let Shard { index, count } = part.shard;
    if count == 0 || index >= count || count > MAX_SHARDS {
        return Err(not(format!("shard {index}/{count} is not one of 0/N … (N−1)/N with N ≤ {MAX_SHARDS}")));
    }
    if part.tasks > MAX_TASKS {
        return Err(not(format!("{} tasks, more than the {MAX_TASKS} a job may have", part.tasks)));
    }
    Ok(part)
}

/// Put `parts` (each with its file name) together into their job.
///
/// # Errors
/// [`PartError`] naming the file that belongs to another job, the shard given twice or missing,
/// or the task without a result.
pub fn merge(parts: Vec<(String, Part)>) -> Result<Job, PartError> {
    let Some((first_file, first)) = parts.first().cloned() else { return Err(PartError::Empty) };
    let count = first.shard.count;
    let mut seen: Vec<Option<String>> = vec![None; count];
    let mut results = BTreeMap::new();
    for (file, p) in parts {
        same_job(&first_file, &first, &file, &p)?;
        let index = p.shard.index;
        if index >= count {
            return Err(PartError::NotAPart { file, why: format!("shard {index}/{count}") });
        }
        if let Some(other) = &seen[index] {
            return Err(PartError::Duplicate { file, index, count, other: other.clone() });
        }
        for &task in p.results.keys() {
            if task >= p.tasks || !p.shard.owns(task) {
                return Err(PartError::Foreign { file, index, count, task, tasks: p.tasks });
            }
        }
        if let Some(task) = (index..p.tasks).step_by(count).find(|t| !p.results.contains_key(t)) {
            return Err(PartError::Incomplete { file, task, index, count });
        }
        results.extend(p.results);
        seen[index] = Some(file);
    }
    let missing: Vec<String> =
        seen.iter().enumerate().filter(|(_, f)| f.is_none()).map(|(i, _)| i.to_string()).collect();
    if !missing.is_empty() {
        return Err(PartError::Missing { missing: missing.join(", "), count });
    }
    Ok(Job {
        command: first.command,
        args: first.args,
        flowsheet: first.flowsheet,
        fingerprint: first.fingerprint,
        results,
    })
}

/// `p` (from `file`) belongs to the job of `first` (from `first_file`).
fn same_job(first_file: &str, first: &Part, file: &str, p: &Part) -> Result<(), PartError> {
    let fields: [(&'static str, String, String); 6] = [
        ("plantwide version", first.plantwide.clone(), p.plantwide.clone()),
        ("command", first.command.clone(), p.command.clone()),
        ("command line", first.args.join(" "), p.args.join(" ")),
        ("flowsheet fingerprint", first.fingerprint.clone(), p.fingerprint.clone()),
        ("shard count", first.shard.count.to_string(), p.shard.count.to_string()),
        ("task count", first.tasks.to_string(), p.tasks.to_string()),
    ];
    match fields.into_iter().find(|(_, a, b)| a != b) {
        Some((field, ours, theirs)) => {
            Err(PartError::OtherJob { file: file.into(), first: first_file.into(), field, ours, theirs })
        }
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn part(index: usize, count: usize, tasks: usize) -> (String, Part) {
        let shard = Shard { index, count };
        let results = (0..tasks).filter(|&t| shard.owns(t)).map(|t| (t, Value::from(t as f64 * 0.1))).collect();
        let p = Part {
            format: FORMAT.into(),
            version: VERSION,
            plantwide: "0.1.0".into(),
            command: "sensitivity".into(),
            args: vec!["sensitivity".into(), "f.json".into()],
            flowsheet: "f.json".into(),
            fingerprint: fingerprint(b"{}"),
            shard,
            tasks,
            results,
        };
        (format!("p{index}.json"), p)
    }

    #[test]
    fn parts_of_one_job_merge_into_every_task_once() {
        let job = merge(vec![part(2, 3, 7), part(0, 3, 7), part(1, 3, 7)]).unwrap();
        assert_eq!(job.results.keys().copied().collect::<Vec<_>>(), (0..7).collect::<Vec<_>>());
        assert_eq!(job.results[&4], Value::from(0.4));
        // Through text and back: the same part.
        let (f, p) = part(1, 3, 7);
        assert_eq!(parse(&serde_json::to_string(&p).unwrap(), &f).unwrap(), p);
    }

    #[test]
    fn parts_that_do_not_make_one_job_are_refused_by_name() {
        let missing = merge(vec![part(0, 3, 7), part(2, 3, 7)]).unwrap_err();
        assert!(matches!(&missing, PartError::Missing { missing, count: 3 } if missing == "1"), "{missing}");
        let twice = merge(vec![part(0, 2, 4), part(0, 2, 4)]).unwrap_err();
        assert!(twice.to_string().contains("shard 0/2 is also in p0.json"), "{twice}");
        let mut other = part(1, 2, 4);
        other.1.fingerprint = fingerprint(b"{ }");
        let e = merge(vec![part(0, 2, 4), other]).unwrap_err();
        assert!(e.to_string().contains("flowsheet fingerprint differs"), "{e}");
        let mut short = part(1, 2, 4);
        short.1.results.remove(&3);
        let e = merge(vec![part(0, 2, 4), short]).unwrap_err();
        assert_eq!(e, PartError::Incomplete { file: "p1.json".into(), task: 3, index: 1, count: 2 });
        let mut foreign = part(1, 2, 4);
        foreign.1.results.insert(2, Value::Null);
        assert!(matches!(merge(vec![part(0, 2, 4), foreign]), Err(PartError::Foreign { task: 2, .. })));
        assert!(parse("{\"format\": \"x\"}", "x.json").unwrap_err().to_string().starts_with("x.json: not a"));
        assert_eq!(merge(vec![]), Err(PartError::Empty));
        let mut beyond = part(1, 2, 4).1;
        beyond.shard.index = 2;
        let e = parse(&serde_json::to_string(&beyond).unwrap(), "b.json").unwrap_err();
        assert!(e.to_string().contains("shard 2/2 is not one of"), "{e}");
    }

    #[test]
    fn the_fingerprint_is_fnv1a() {
        // FNV-1a 64 reference values (Fowler, Noll & Vo test vectors): "" and "a".
        assert_eq!(fingerprint(b""), "cbf29ce484222325");
        assert_eq!(fingerprint(b"a"), "af63dc4c8601ec8c");
    }
}
