//! Seeded, structure-aware mutation fuzz of the shipped flowsheets and scenarios, in process.
//!
//! Each mutant is made from its own seed: a file of one kind the engine reads (flowsheet loaded,
//! converged or run; transfer-function model; MPC step model; snapshot), a study command line, or
//! a request to a live server, with one to three mutations chosen by the kind and key of the JSON
//! nodes (`tests/fuzz/`). It fails on a panic, a mutant over 10 s of both wall and CPU time (or a
//! minute of wall time) or 2 GiB (the process aborts after printing the mutant; a crash leaves it
//! in `target/fuzz-current.txt`), a steady state reported converged that fails the independent
//! certificate, a run that returns non-finite values, a study that exits 0 with a failed part, or
//! a server answer outside its documented statuses.
//!
//! * `cargo test --test it fuzz::`: the fast sample (2 000 mutants, seed fixed).
//! * `PLANTWIDE_FUZZ_MUTANTS=100000`: a large sample; `PLANTWIDE_FUZZ_SEED=<n|0x..>`: another seed.
//! * Replay one mutant: `PLANTWIDE_FUZZ_SEED=<its seed> PLANTWIDE_FUZZ_MUTANTS=1`; a stretch of a
//!   campaign: `PLANTWIDE_FUZZ_START=<k>` runs its mutants from the k-th on.
//! * `PLANTWIDE_FUZZ_SKIP=class,class`: temporary, opt-in: skip mutants whose description holds
//!   one of these words (known defect classes while their fixes land elsewhere).
//!
//! The campaign runs in a child process of the test binary (the test re-runs itself with
//! [`CHILD`] set): it installs the process's panic hook, counts the live heap against its limit
//! and aborts the process on a crash or a hang, which must not take the other tests with it.

mod certificate;
mod corpus;
mod doc;
mod exec;
mod guard;
mod kinds;
mod mutate;
pub(crate) mod rng;
mod targeted;

use std::sync::Mutex;
use std::time::{Duration, Instant};

use corpus::{Corpus, Mode, Mutant, Other};
use exec::{Dishonest, Outcome, execute};

#[global_allocator]
static ALLOC: guard::Counting = guard::Counting;

/// Seed of the committed fast sample.
const DEFAULT_SEED: u64 = 0x5eed_f022_2024_0013;
/// Size of the fast sample.
const DEFAULT_MUTANTS: usize = 2000;

/// Message and place of the last panic (the quiet hook keeps it here instead of printing).
static LAST_PANIC: Mutex<String> = Mutex::new(String::new());

use crate::harness::{env_u64, say};

/// Counts and extremes of a campaign.
#[derive(Default)]
struct Report {
    by_mode: [(usize, Duration); Mode::ALL.len()],
    ok: usize,
    user: usize,
    numerical: usize,
    skipped: usize,
    longest_message: (usize, u64),
    baseline: usize,
    warmup: usize,
    slowest: (Duration, String),
    failures: Vec<(String, String, String)>,
}

impl Report {
    fn record(
        &mut self,
        m: &Mutant,
        (took, cpu): (Duration, Duration),
        result: std::thread::Result<Result<Outcome, Dishonest>>,
    ) {
        let slot = &mut self.by_mode[m.mode as usize];
        slot.0 += 1;
        slot.1 += took;
        if took > self.slowest.0 {
            self.slowest = (took, m.describe());
        }
        if guard::over_limit(took, cpu) {
            self.failures.push(("over the time limit".into(), m.describe(), format!("{took:?} wall, {cpu:?} CPU")));
        }
        if let Ok(Ok(Outcome::User(msg) | Outcome::Numerical(msg))) = &result
            && msg.len() > MAX_MESSAGE
        {
            let head: String = msg.chars().take(300).collect();
            self.failures.push(("message too long".into(), m.describe(), format!("{} bytes: {head}…", msg.len())));
        }
        match result {
            Ok(Ok(Outcome::Ok)) => self.ok += 1,
            Ok(Ok(Outcome::User(msg))) => {
                self.user += 1;
                self.longest_message = self.longest_message.max((msg.len(), m.seed));
            }
            Ok(Ok(Outcome::Numerical(msg))) => {
                self.numerical += 1;
                self.longest_message = self.longest_message.max((msg.len(), m.seed));
            }
            Ok(Err(Dishonest(why))) => self.failures.push(("dishonest".into(), m.describe(), why)),
            Err(_) => {
                let why = std::mem::take(&mut *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()));
                self.failures.push(("panic".into(), m.describe(), why));
            }
        }
    }

    fn summary(&self, wall: Duration) -> String {
        let rate = |(n, t): (usize, Duration)| n as f64 / t.as_secs_f64().max(1e-9);
        let kinds: Vec<String> = Mode::ALL
            .iter()
            .zip(&self.by_mode)
            .map(|(m, &slot)| format!("{} {} at {:.1}/s", format!("{m:?}").to_lowercase(), slot.0, rate(slot)))
            .collect();
        format!(
            "fuzz: {} shipped runs, then {} mutants in {:.1} s ({}; {} skipped): \
             ok {}, user error {}, numerical failure {}, FAILURES {}; slowest {:.2} s ({}); peak allocation {:.1} MiB above a {:.0} MiB baseline; longest message {} chars (seed {:#x})",
            self.warmup,
            self.by_mode.iter().map(|s| s.0).sum::<usize>(),
            wall.as_secs_f64(),
            kinds.join(", "),
            self.skipped,
            self.ok,
            self.user,
            self.numerical,
            self.failures.len(),
            self.slowest.0.as_secs_f64(),
            self.slowest.1,
            guard::peak() as f64 / (1 << 20) as f64,
            self.baseline as f64 / (1 << 20) as f64,
            self.longest_message.0,
            self.longest_message.1
        )
    }
}

/// Write a replayed mutant's files under `target/` and print the equivalent command line.
fn dump(m: &Mutant) {
    let dir = guard::current_file().with_file_name("fuzz-replay");
    let _ = std::fs::create_dir_all(&dir);
    let fs = dir.join("flowsheet.json");
    let _ = std::fs::write(&fs, &m.text);
    let sets: String = m.sets.iter().map(|s| format!(" --set '{s}'")).collect();
    if let Some(other) = &m.other {
        let what = match other {
            Other::Tf(_, text) => write_as(&dir, "model.tf.json", text, "tune --tf {} --method zn"),
            Other::StepModel(text) => write_as(&dir, "sm.json", text, "(column A's MPC reading {})"),
            Other::Snapshot(text) => {
                write_as(&dir, "snapshot.json", text, "run flowsheets/surge_tank_pi.json --resume {}")
            }
            Other::Study(args) => args.join(" "),
            Other::Serve(raw) => write_as(&dir, "request.txt", raw, "(an HTTP request to serve: {})"),
        };
        say(&format!("fuzz replay files: plantwide {what}"));
        return;
    }
    let command = match &m.scenario {
        Some((_, text)) => {
            let sc = dir.join("scenario.json");
            let _ = std::fs::write(&sc, text);
            format!("run {}{sets} --scenario {} --csv /tmp/fuzz.csv", fs.display(), sc.display())
        }
        None if m.mode == Mode::Load => format!("check {}{sets}", fs.display()),
        None => format!("steady {}{sets}", fs.display()),
    };
    say(&format!("fuzz replay files: plantwide {command}"));
}

/// Write `text` to `dir/name` and fill the file's path into `command`.
fn write_as(dir: &std::path::Path, name: &str, text: &str, command: &str) -> String {
    let file = dir.join(name);
    let _ = std::fs::write(&file, text);
    command.replace("{}", &file.display().to_string())
}

/// Make and run `n` mutants from `seed` (mutant 0 has the seed itself).
fn campaign(seed: u64, n: usize, skip: &[String]) -> Report {
    let corpus = Corpus::load();
    let mut report = Report::default();
    // The shipped files must pass themselves; running them first also lets the engine's
    // per-thread scratch settle before the memory limit starts counting.
    let mut shipped: Vec<Mutant> = corpus.small.iter().map(|&fi| Mutant::shipped(&corpus, fi, None)).collect();
    for s in &corpus.scenarios {
        shipped.extend(s.flowsheets.iter().map(|&fi| Mutant::shipped(&corpus, fi, Some(s))));
    }
    for m in &shipped {
        guard::begin(&m.describe());
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| execute(m, &corpus)));
        let _ = guard::end();
        if !matches!(result, Ok(Ok(Outcome::Ok))) {
            report.failures.push(("shipped file".into(), m.describe(), format!("{result:?}")));
        }
    }
    report.baseline = guard::set_baseline();
    report.warmup = shipped.len();
    let mut seeds = rng::Rng::new(seed);
    let mut left = [0isize; Mode::ALL.len()];
    // Replay a stretch of a campaign: its mutants from `PLANTWIDE_FUZZ_START` on (a failure that
    // depends on what ran before it).
    let start = env_u64("PLANTWIDE_FUZZ_START").unwrap_or(0) as usize;
    for i in 0..n {
        let s = if i == 0 { seed } else { seeds.next_u64() };
        if i < start {
            continue;
        }
        guard::making(s);
        let made = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| Mutant::new(s, &corpus)));
        let Ok(m) = made else {
            let why = std::mem::take(&mut *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()));
            report.failures.push(("harness: mutator panicked".into(), format!("seed={s:#018x}"), why));
            continue;
        };
        let description = m.describe();
        if skip.iter().any(|w| description.contains(w.as_str())) {
            report.skipped += 1;
            continue;
        }
        if n == 1 {
            dump(&m);
        }
        left[m.mode as usize] += run_one(&m, &corpus, &mut report, n == 1);
        if (i + 1) % 5000 == 0 {
            checkpoint(i + 1, &left);
        }
    }
    if let Err(why) = kinds::stop_server() {
        report.failures.push(("serve".into(), "the live server after the campaign".into(), why));
    }
    report
}

/// Run `m` under the guards and record it in `report` (and print its outcome if `replay`).
/// Returns the live heap it left behind [bytes], measured once its outcome is recorded and
/// dropped: an error message the report keeps only the length of is not heap the engine kept.
fn run_one(m: &Mutant, corpus: &Corpus, report: &mut Report, replay: bool) -> isize {
    let description = m.describe();
    guard::begin(&description);
    let (started, cpu) = (Instant::now(), guard::cpu_time(None));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| execute(m, corpus)));
    let took = (started.elapsed(), guard::cpu_time(None).saturating_sub(cpu));
    if replay {
        say(&format!("fuzz replay: {description}\n    -> {result:?}"));
    }
    report.record(m, took, result);
    guard::end()
}

/// Print where the live heap goes after `done` mutants: what each kind left behind, and the live
/// heap above the warm-up baseline (a slow leak shows here before the limit).
fn checkpoint(done: usize, left: &[isize]) {
    let mib = |b: isize| b as f64 / 1048576.0;
    let by: Vec<String> = Mode::ALL.iter().zip(left).map(|(k, &b)| format!("{k:?} {:+.1} MiB", mib(b))).collect();
    say(&format!(
        "fuzz: after {done} mutants the live heap they left behind: {}; live heap {:+.1} MiB above the baseline",
        by.join(", "),
        mib(guard::above_baseline())
    ));
}

/// Longest error message a person can be expected to read (bytes): every problem is named, but a
/// message must not echo a huge input or list a million problems.
const MAX_MESSAGE: usize = 20_000;

/// Set in the child process that runs the campaign.
const CHILD: &str = "PLANTWIDE_FUZZ_CHILD";

/// Whether this process is the child that runs the test `name` alone (its heap counted without
/// the other tests'); if not, run that child (the test binary again, with [`CHILD`] set) and
/// assert that it passed.
fn in_child(name: &str) -> bool {
    if std::env::var_os(CHILD).is_some() {
        return true;
    }
    // The child's report goes to stderr; its stdout is the test runner's own lines.
    let status = std::process::Command::new(std::env::current_exe().expect("the test binary"))
        .args([name, "--exact", "--nocapture", "--test-threads=1"])
        .env(CHILD, "1")
        .stdout(std::process::Stdio::null())
        .status()
        .expect("the test binary runs");
    assert!(status.success(), "{name} failed in its child process ({status}; its report is above)");
    false
}

#[test]
fn mutants_neither_crash_nor_hang_nor_claim_false_convergence() {
    if !in_child("fuzz::mutants_neither_crash_nor_hang_nor_claim_false_convergence") {
        return;
    }
    let seed = env_u64("PLANTWIDE_FUZZ_SEED").unwrap_or(DEFAULT_SEED);
    let n = env_u64("PLANTWIDE_FUZZ_MUTANTS").map_or(DEFAULT_MUTANTS, |n| n as usize);
    let skip: Vec<String> = std::env::var("PLANTWIDE_FUZZ_SKIP")
        .unwrap_or_default()
        .split(',')
        .filter(|s| !s.is_empty())
        .map(String::from)
        .collect();
    say(&format!("fuzz: seed {seed:#x}, {n} mutants; a crashed mutant is left in {}", guard::current_file().display()));
    std::panic::set_hook(Box::new(|info| {
        let msg = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_default();
        let at = info.location().map_or(String::new(), |l| format!(" at {l}"));
        *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()) = format!("{msg}{at}");
    }));
    guard::start_watchdog();
    let started = Instant::now();
    // The command line runs on the main thread's 8 MiB stack; so do the mutants.
    let worker = std::thread::Builder::new().stack_size(8 << 20).spawn(move || campaign(seed, n, &skip));
    let report = worker.expect("spawn the fuzz thread").join();
    let _ = std::panic::take_hook();
    let report = report.expect("the campaign catches every panic");
    say(&report.summary(started.elapsed()));
    for (kind, mutant, why) in report.failures.iter().take(50) {
        say(&format!("fuzz FAILURE ({kind}): {mutant}\n    {why}"));
    }
    assert!(report.failures.is_empty(), "{} mutants failed (listed above)", report.failures.len());
}

/// A refused load leaves no heap behind once recorded: its error message is the report's, not
/// the engine's. The per-kind figures measured the heap before the outcome was dropped and
/// counted every message, about 300 bytes a load, as a slow creep of `Load` mutants (issue 54).
#[test]
fn a_refused_load_leaves_no_heap_behind() {
    if !in_child("fuzz::a_refused_load_leaves_no_heap_behind") {
        return;
    }
    let corpus = Corpus::load();
    let m = Mutant {
        seed: 0,
        mode: Mode::Load,
        file: "refused.json".into(),
        text: r#"{"units": {"tank": 1}}"#.into(),
        scenario: None,
        sets: Vec::new(),
        changes: Vec::new(),
        other: None,
    };
    let mut report = Report::default();
    run_one(&m, &corpus, &mut report, false);
    let left: isize = (0..20).map(|_| run_one(&m, &corpus, &mut report, false)).sum();
    assert_eq!(report.user, 21, "the load is refused: {:?}", report.failures);
    let message = report.longest_message.0 as isize;
    assert!(message > 0 && left.abs() < message, "20 loads left {left} bytes (message: {message} bytes)");
}
