//! One plant's checking session: its folder of files, the commands run in it, the relations
//! checked and the violations found (each with the commands that show it).

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Duration;

use serde_json::Value;

use super::doc::J;
use super::exec::{self, Output};
use super::families::Case;
use super::{known, relations};

/// A broken relation.
#[derive(Debug, Clone)]
pub struct Violation {
    /// The plant's seed.
    pub seed: u64,
    /// The class: the study and the relation, in a few words (violations are grouped by it).
    pub class: String,
    /// The commands that show it (run in the plant's folder).
    pub commands: Vec<String>,
    /// What was found.
    pub detail: String,
}

/// A plant under check.
pub struct Cx<'a> {
    /// The plant.
    pub case: &'a Case,
    /// Its folder: the plant's files and what the commands write.
    pub dir: PathBuf,
    /// Time a command may take.
    pub limit: Duration,
    /// Relations checked.
    pub checks: usize,
    /// Commands run and their total wall time.
    pub commands: usize,
    /// Wall time of the commands [s].
    pub command_secs: f64,
    /// Commands and wall time [s] by subcommand.
    pub by_command: BTreeMap<String, (usize, f64)>,
    /// Violations.
    pub violations: Vec<Violation>,
    /// Violations of known, open defects, with their notes (see `known.rs`).
    pub known: Vec<(Violation, &'static str)>,
    /// The closed plant's steady state (`values` of `steady --json`), once converged.
    pub values: serde_json::Map<String, Value>,
}

impl<'a> Cx<'a> {
    /// A session for `case` in `dir` (emptied first).
    pub fn new(case: &'a Case, dir: PathBuf, limit: Duration) -> Cx<'a> {
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create the plant's folder");
        let cx = Cx {
            case,
            dir,
            limit,
            checks: 0,
            commands: 0,
            command_secs: 0.0,
            by_command: BTreeMap::new(),
            violations: Vec::new(),
            known: Vec::new(),
            values: Default::default(),
        };
        cx.write("plant.json", &case.closed.render());
        cx.write("open.json", &case.open.render());
        cx.write("about.txt", &format!("plant {:#018x} ({:?}): {}\n", case.seed, case.family, case.about));
        cx
    }

    /// Write `text` to `name` in the plant's folder; the name back.
    pub fn write(&self, name: &str, text: &str) -> String {
        std::fs::write(self.dir.join(name), text).expect("write into the plant's folder");
        name.to_string()
    }

    /// Write a document.
    pub fn doc(&self, name: &str, doc: &J) -> String {
        self.write(name, &doc.render())
    }

    /// Run `plantwide ARGS` in the plant's folder.
    pub fn pw<S: AsRef<str>>(&mut self, args: &[S]) -> Output {
        let args: Vec<String> = args.iter().map(|a| a.as_ref().to_string()).collect();
        let out = exec::run(&self.dir, &args, self.limit);
        self.commands += 1;
        self.command_secs += out.secs;
        let entry = self.by_command.entry(args[0].clone()).or_default();
        *entry = (entry.0 + 1, entry.1 + out.secs);
        out
    }

    /// Count one relation; record a violation of `class` when it does not hold.
    pub fn check(&mut self, holds: bool, class: &str, outs: &[&Output], detail: impl FnOnce() -> String) -> bool {
        self.checks += 1;
        if !holds {
            let v = Violation {
                seed: self.case.seed,
                class: class.to_string(),
                commands: outs.iter().map(|o| o.line.clone()).collect(),
                detail: detail(),
            };
            match known::open(&v) {
                Some(note) => self.known.push((v, note)),
                None => self.violations.push(v),
            }
        }
        holds
    }

    /// [`Cx::check`] of a comparison that says what differs.
    pub fn agree(&mut self, result: Result<(), String>, class: &str, outs: &[&Output]) -> bool {
        let holds = result.is_ok();
        self.check(holds, class, outs, || result.err().unwrap_or_default())
    }

    /// The command did its job on a well-posed generated plant (exit 0 and, if `json`, a JSON
    /// answer that is honest about its parts and gives every number it promises: `promised` are
    /// patterns of members, `*` for any key or index). Returns the JSON.
    pub fn succeeded(&mut self, out: &Output, study: &str, json: bool, promised: &[&str]) -> Option<Value> {
        let parsed = out.json();
        if let Some(v) = &parsed {
            let why = relations::honest(v, out.code, promised);
            self.agree(
                why,
                &format!("{study}: exit code and JSON disagree (failed parts, null or NaN numbers)"),
                &[out],
            );
        }
        let class = match out.code {
            None => format!("{study}: over the time limit"),
            Some(1) => format!("{study}: refused (exit 1) on a generated plant"),
            Some(_) => format!("{study}: fails (exit 2) on a generated plant"),
        };
        if !self.check(out.ok(), &class, &[out], || out.brief()) {
            return None;
        }
        match parsed {
            Some(v) => Some(v),
            None if json => {
                self.check(false, &format!("{study}: --json output is not JSON"), &[out], || {
                    out.stdout.chars().take(300).collect()
                });
                None
            }
            None => Some(Value::Null),
        }
    }

    /// A value of the closed plant's steady state.
    pub fn value(&self, path: &str) -> Option<f64> {
        self.values.get(path).and_then(Value::as_f64)
    }
}
