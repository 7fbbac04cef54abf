//! Mutants of the other inputs the engine takes (issue 54): transfer-function model files, MPC
//! step-model files, snapshots, study command lines and requests to the live server. Each kind
//! starts from a valid input of the shipped plants, mutates it structurally ([`mutate`]) and runs
//! it the way its command does; an honest engine refuses it (exit 1), fails naming why (exit 2)
//! or answers with finite numbers that pass an independent check.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use serde_json::{Value, json};

use super::doc::Doc;
use super::exec::{Dishonest, Outcome};
use super::mutate::{Names, mutate};
use super::rng::Rng;
use plantwide::flowsheet::scenario::{parse_scenario, resolve};
use plantwide::flowsheet::{Plant, load_file, load_str};
use plantwide::solve::dynamic::{Progress, SimError, Snapshot, Start, file_model, simulate};
use plantwide::solve::{StrategySettings, converge};

/// The repository root.
fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A scratch folder of this campaign.
fn scratch() -> PathBuf {
    let dir = root().join("target").join(format!("fuzz-scratch-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    dir
}

/// A classified library error: a user error or a numerical failure.
fn classify(user: bool, msg: String) -> Outcome {
    if user { Outcome::User(msg) } else { Outcome::Numerical(msg) }
}

/// The inputs the kinds start from (read once per campaign).
pub struct Seeds {
    /// Transfer-function model files: (file, JSON).
    pub tf: Vec<(String, Value)>,
    /// A step-response model of column A's `quality_mpc` (its CVs and MVs), as identify writes it.
    pub step_model: Value,
    /// Column A with its MPC reading `sm.json` (flowsheet text).
    pub mpc_flowsheet: String,
    /// A snapshot of the surge tank run and the scenario text it belongs to.
    pub snapshot: (Value, String),
}

impl Seeds {
    /// Read the shipped models and make the snapshot.
    pub fn load() -> Seeds {
        let mut tf = Vec::new();
        let dir = root().join("flowsheets").join("transfer_functions");
        for e in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
            let text = std::fs::read_to_string(e.path()).expect("shipped model readable");
            tf.push((format!("flowsheets/transfer_functions/{}", e.file_name().to_string_lossy()), json_of(&text)));
        }
        tf.sort_by(|a, b| a.0.cmp(&b.0));
        let step_model =
            json_of(&std::fs::read_to_string(root().join("docs/identify_column_a/step_model.json")).unwrap());
        let mut mpc: Value = json_of(&std::fs::read_to_string(root().join("flowsheets/column_a_mpc.json")).unwrap());
        mpc["controllers"]["quality_mpc"]["model"] = json!({"file": "sm.json"});
        mpc["controllers"]["quality_mpc"]["sample_time"] = json!(format!("{} s", step_model["ts"]));
        Seeds { tf, step_model, mpc_flowsheet: mpc.to_string(), snapshot: surge_snapshot() }
    }
}

fn json_of(text: &str) -> Value {
    serde_json::from_str(text).expect("shipped JSON")
}

/// The surge tank's inflow step, snapshotted at 400 s.
const SURGE_SCENARIO: &str = r#"{"format_version": 1, "duration": "1200 s", "record": {"interval": "20 s"},
  "events": [{"type": "step", "at": "100 s", "path": "F_in", "to": "60 mol/s"},
             {"type": "valve_stuck", "at": "300 s", "path": "tank.outflow", "to": "45 mol/s"},
             {"type": "valve_repaired", "at": "600 s", "path": "tank.outflow"}],
  "snapshots": [{"at": "400 s", "file": "s.json"}]}"#;

fn surge_plant() -> Plant {
    load_file(&root().join("flowsheets/surge_tank_pi.json")).expect("shipped")
}

fn surge_snapshot() -> (Value, String) {
    let plant = surge_plant();
    let x = converge(&plant, &StrategySettings::default()).expect("converges").x;
    let sc = resolve(&parse_scenario(SURGE_SCENARIO, "s").unwrap(), &plant, "s").unwrap();
    let mut snap = None;
    simulate(&plant, &sc, Start::Steady(&x), "fuzz", &mut |p| {
        if let Progress::Snapshot { snapshot, .. } = p {
            snap = Some(serde_json::to_value(snapshot).expect("serializes"));
        }
    })
    .expect("runs");
    (snap.expect("a snapshot"), SURGE_SCENARIO.to_string())
}

/// A mutated copy of `value`: one to three mutations; the lines describing them.
pub fn mutated(rng: &mut Rng, value: &Value) -> (String, Vec<String>) {
    let names = Names::of(value);
    let mut doc = Doc::new(value.clone());
    let n = *rng.pick(&[1, 1, 1, 2, 3]);
    let lines = (0..n).map(|_| mutate(rng, &mut doc, &names)).collect();
    (doc.render(), lines)
}

/// A transfer-function model: parsed, tuned (ZN, BLT), exported; an answer must be finite.
pub fn tf(file: &str, text: &str) -> Result<Outcome, Dishonest> {
    use plantwide::studies::tune::{BltSettings, PiRule, blt, single_loop};
    let model = match plantwide::io::tf::parse(text, file) {
        Ok(m) => m,
        Err(e) => return Ok(Outcome::User(e.to_string())),
    };
    let finite = |t: &plantwide::studies::tune::Tuning| {
        t.loops.iter().all(|l| [l.ku, l.pu, l.kc, l.tau_i].iter().all(|v| v.is_finite()))
            && t.detuning_factor.is_none_or(f64::is_finite)
    };
    for result in [single_loop(&model, PiRule::ZieglerNichols), blt(&model, &BltSettings::default())] {
        match result {
            Ok(t) if !finite(&t) => return Err(Dishonest(format!("tuning with a non-finite setting: {t:?}"))),
            Ok(_) | Err(_) => {}
        }
    }
    match plantwide::io::tf::export(&model, ("s", 1.0), None) {
        Ok(doc) if doc.to_string().contains("null") && !text.contains("null") => {
            Err(Dishonest("exported model with a null coefficient".into()))
        }
        Ok(_) => Ok(Outcome::Ok),
        Err(e) => Ok(Outcome::Numerical(e.to_string())),
    }
}

/// A step-model file read by column A's MPC: a model accepted must name the controller's own
/// channels in order, be of its shape and finite.
pub fn step_model(flowsheet: &str, text: &str) -> Result<Outcome, Dishonest> {
    let dir = scratch();
    std::fs::write(dir.join("sm.json"), text).expect("scratch writable");
    let file = dir.join("mpc.json").display().to_string();
    let plant = match load_str(flowsheet, &file) {
        Ok(p) => p,
        Err(e) => return Ok(Outcome::User(e.to_string())),
    };
    match file_model(&plant, "quality_mpc") {
        Err(e) => Ok(Outcome::User(e.to_string())),
        Ok(m) => {
            let v: Value = serde_json::from_str(text).map_err(|e| Dishonest(format!("accepted unparsable: {e}")))?;
            let names = |k: &str| v[k].as_array().map(|a| a.iter().filter_map(Value::as_str).collect::<Vec<_>>());
            let (ins, outs) = (names("inputs"), names("outputs"));
            let same = |a: &str, b: &str, var: bool| {
                if var {
                    plant.var(a).is_some() && plant.var(a) == plant.var(b)
                } else {
                    plant.input(a) == plant.input(b)
                }
            };
            let matches = |got: Option<Vec<&str>>, want: [&str; 2], var: bool| {
                got.is_some_and(|g| g.len() == 2 && g.iter().zip(want).all(|(a, b)| same(a, b, var)))
            };
            let channels = matches(ins, ["column.reflux", "column.boilup"], false)
                && matches(outs, ["distillate.x[light]", "bottoms.x[light]"], true);
            let finite = m.steps.iter().flatten().all(|c| c.is_finite());
            if channels && finite && m.ny == 2 && m.nu == 2 {
                Ok(Outcome::Ok)
            } else {
                Err(Dishonest(format!("accepted a model of other channels or shape: {}", &text[..text.len().min(300)])))
            }
        }
    }
}

/// A snapshot resumed on the surge tank: refused, failed by name, or a finite run.
pub fn snapshot(text: &str, scenario: &str) -> Result<Outcome, Dishonest> {
    let snap: Snapshot = match serde_json::from_str(text) {
        Ok(s) => s,
        Err(e) => return Ok(Outcome::User(e.to_string())),
    };
    let plant = surge_plant();
    let sc = resolve(&parse_scenario(scenario, "s").unwrap(), &plant, "s").unwrap();
    match simulate(&plant, &sc, Start::Snapshot(&snap), "fuzz", &mut |_| {}) {
        Ok(res) => super::certificate::run(&res).map(|()| Outcome::Ok).map_err(|e| Dishonest(format!("resumed: {e}"))),
        Err(e @ (SimError::Snapshot { .. } | SimError::Wiring(_))) => Ok(Outcome::User(e.to_string())),
        Err(e) => Ok(classify(e.is_user_error(), e.to_string())),
    }
}

/// Study command lines on the shipped plants, each valid as written.
const STUDIES: &[&[&str]] = &[
    &[
        "gains",
        "flowsheets/column_a.json",
        "--inputs",
        "column.reflux,column.boilup",
        "--outputs",
        "distillate.x[light],bottoms.x[light]",
        "--json",
    ],
    &[
        "gains",
        "flowsheets/column_a.json",
        "--inputs",
        "column.reflux,column.boilup",
        "--outputs",
        "distillate.x[light],bottoms.x[light]",
        "--method",
        "perturb",
        "--json",
    ],
    &[
        "tune",
        "flowsheets/column_a_lv.json",
        "--loops",
        "top_composition,bottom_composition",
        "--method",
        "blt",
        "--measurement-dead-time",
        "1 min",
        "--json",
    ],
    &["tune", "flowsheets/surge_tank_pi.json", "--loop", "lc", "--method", "averaging", "--json"],
    &["tune", "flowsheets/surge_tank_pi.json", "--loop", "lc", "--method", "simc", "--json"],
    &["tune", "--tf", "flowsheets/transfer_functions/wood_berry.tf.json", "--method", "blt", "--json"],
    &[
        "size",
        "flowsheets/surge_tank_pi.json",
        "--vessel",
        "tank",
        "--disturbance",
        "inflow.F=+10%",
        "--level-band",
        "0.2 m",
        "--max-outflow-rate",
        "0.1 mol/s/s",
        "--json",
    ],
    &[
        "screen",
        "flowsheets/column_a_lv.json",
        "--cvs",
        "distillate.x[light],bottoms.x[light]",
        "--mvs",
        "column.reflux,column.boilup",
        "--candidates",
        "0",
        "--json",
    ],
    &[
        "sensitivity",
        "flowsheets/column_a_lv.json",
        "--disturb",
        "feed_source.F=-10%:+10%",
        "--outputs",
        "distillate.x[light]",
        "--points",
        "3",
    ],
    &["steady", "flowsheets/surge_tank_pi.json", "--spec", "tank.level=1.2 m", "--vary", "lc.sp", "--json"],
];

/// Replacement values for a study flag's argument.
const HOSTILE: &[&str] = &[
    "",
    ",",
    "x",
    "nope.F",
    "1e308 mol/s",
    "-1e308",
    "0 s",
    "-5 min",
    "nan",
    "inf",
    "1e-300 s",
    "5 furlong",
    "100%",
    "+1e9%",
    "±",
    "=",
    "feed_source.F,feed_source.F",
    "column.reflux,column.reflux",
    "a,b,c,d,e,f,g,h,i,j",
    "tank.level=",
    "1e6",
    "0",
    "-1",
    "18446744073709551616",
    "tank",
    "column.drum",
    "lc,lc",
    "99999999 h",
];

/// A study command line with one to two hostile changes.
pub fn study_args(rng: &mut Rng) -> (Vec<String>, Vec<String>) {
    let mut args: Vec<String> = rng.pick(STUDIES).iter().map(|s| s.to_string()).collect();
    let mut changes = Vec::new();
    for _ in 0..*rng.pick(&[1, 1, 2]) {
        let values: Vec<usize> = (1..args.len()).filter(|&k| !args[k].starts_with("--")).collect();
        match rng.below(5) {
            0 if args.len() > 2 => {
                let k = 1 + rng.below(args.len() - 1);
                changes.push(format!("dropped `{}`", args.remove(k)));
            }
            1 => {
                let (flag, v) = *rng.pick(&[
                    ("--set", "lc.sp=-1 m"),
                    ("--set", "feed_source.F=1e9 kmol/h"),
                    ("--units", "metric"),
                    ("--bogus", "1"),
                    ("--set", "tank.area=0 m2"),
                ]);
                args.extend([flag.to_string(), v.to_string()]);
                changes.push(format!("added {flag} {v}"));
            }
            _ if !values.is_empty() => {
                let k = *rng.pick(&values);
                let new = rng.pick(HOSTILE).to_string();
                changes.push(format!("`{}` -> `{new}`", args[k]));
                args[k] = new;
            }
            _ => {}
        }
    }
    (args, changes)
}

/// Run a study command line in a child process: exit 0, 1 or 2 within the time limit, no panic,
/// and exit 0 only when no part of the answer is marked failed.
pub fn study(args: &[String]) -> Result<Outcome, Dishonest> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_plantwide"))
        .args(args)
        .current_dir(root())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the plantwide binary runs");
    let started = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().expect("waits") {
            break s;
        }
        if super::guard::over_limit(started.elapsed(), super::guard::cpu_time(Some(child.id()))) {
            let _ = child.kill();
            let _ = child.wait();
            return Err(Dishonest(format!("over the time limit: plantwide {}", args.join(" "))));
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let (mut out, mut err) = (String::new(), String::new());
    let _ = child.stdout.take().map(|mut s| s.read_to_string(&mut out));
    let _ = child.stderr.take().map(|mut s| s.read_to_string(&mut err));
    if err.contains("panicked") {
        return Err(Dishonest(format!("panic: {err}")));
    }
    match status.code() {
        Some(0) => {
            let failed = serde_json::from_str::<Value>(&out).ok().is_some_and(|v| marks_failure(&v));
            if failed {
                Err(Dishonest(format!("exit 0 with a failed part: {}", &out[..out.len().min(500)])))
            } else {
                Ok(Outcome::Ok)
            }
        }
        Some(1) => Ok(Outcome::User(err)),
        Some(2) => Ok(Outcome::Numerical(err)),
        other => Err(Dishonest(format!("exit {other:?}: {err}"))),
    }
}

/// Whether a study's JSON marks a part failed: a non-empty `failed` list or a `failure` value.
fn marks_failure(v: &Value) -> bool {
    match v {
        Value::Object(m) => m.iter().any(|(k, x)| {
            (k == "failed" && x.as_array().is_some_and(|a| !a.is_empty()))
                || (k == "failure" && !x.is_null())
                || marks_failure(x)
        }),
        Value::Array(a) => a.iter().any(marks_failure),
        _ => false,
    }
}

/// The live server the serve mutants talk to (started on first use, stopped by [`stop_server`]).
static SERVER: Mutex<Option<Server>> = Mutex::new(None);

struct Server {
    child: Child,
    port: u16,
    token: String,
}

fn start_server() -> Server {
    let mut child = Command::new(env!("CARGO_BIN_EXE_plantwide"))
        .args(["serve", "flowsheets/surge_tank_pi.json", "--port", "0", "--speed", "100", "--rate", "1000000"])
        .current_dir(root())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("serve starts");
    let mut out = child.stdout.take().expect("stdout");
    let (mut text, mut buf) = (String::new(), [0u8; 256]);
    while !text.contains("token: ") || !text[text.find("token: ").unwrap()..].contains([' ', '\n']) {
        let n = out.read(&mut buf).expect("serve prints its address");
        assert!(n > 0, "serve ended: {text}");
        text.push_str(&String::from_utf8_lossy(&buf[..n]));
    }
    let port = text.split("127.0.0.1:").nth(1).and_then(|s| s.split(['/', ' ', '\n']).next()?.parse().ok());
    let token = text.split("token: ").nth(1).and_then(|s| s.split([' ', '\n']).next()).unwrap_or_default();
    Server { child, port: port.expect("a port"), token: token.to_string() }
}

/// Stop the server, if one was started; `Err` if it had died.
pub fn stop_server() -> Result<(), String> {
    let Some(mut s) = SERVER.lock().unwrap_or_else(|e| e.into_inner()).take() else { return Ok(()) };
    let alive = s.child.try_wait().ok().flatten().is_none();
    let state = request(s.port, &format!("GET /api/state HTTP/1.1\r\nHost: 127.0.0.1:{}\r\n\r\n", s.port));
    let _ = s.child.kill();
    let _ = s.child.wait();
    match (alive, state) {
        (true, Ok(200)) => Ok(()),
        (alive, state) => Err(format!("after the campaign the server is alive: {alive}, GET /api/state: {state:?}")),
    }
}

/// Send `raw` and read the status code.
fn request(port: u16, raw: &str) -> Result<u16, String> {
    let mut s = TcpStream::connect(("127.0.0.1", port)).map_err(|e| format!("connect: {e}"))?;
    s.set_read_timeout(Some(Duration::from_secs(5))).map_err(|e| e.to_string())?;
    s.write_all(raw.as_bytes()).map_err(|e| format!("send: {e}"))?;
    let mut head = [0u8; 64];
    let n = s.read(&mut head).map_err(|e| format!("no answer: {e}"))?;
    let line = String::from_utf8_lossy(&head[..n]);
    line.split(' ').nth(1).and_then(|c| c.parse().ok()).ok_or_else(|| format!("not HTTP: {line}"))
}

/// Commands of the page, each valid.
const COMMANDS: &[&str] = &[
    r#"{"set": {"F_in": "55 mol/s"}}"#,
    r#"{"pause": true}"#,
    r#"{"resume": true}"#,
    r#"{"speed": 1000}"#,
    r#"{"step": true}"#,
    r#"{"mode": {"lc": "manual"}}"#,
    r#"{"mode": {"lc": "auto"}}"#,
    r#"{"snapshot": "a"}"#,
    r#"{"load": "a"}"#,
    r#"{"event": {"type": "ramp", "path": "F_in", "to": "45 mol/s", "duration": "2 min"}}"#,
    r#"{"event": {"type": "feed_lost", "unit": "inflow"}}"#,
    r#"{"event": {"type": "feed_restored", "unit": "inflow"}}"#,
    r#"{"event": {"type": "valve_stuck", "path": "tank.outflow", "to": "40 mol/s"}}"#,
    r#"{"event": {"type": "valve_repaired", "path": "tank.outflow"}}"#,
];

/// A request to the live server: a command (mutated) or a read, with headers right or wrong.
pub fn serve_request(rng: &mut Rng) -> (String, Vec<String>) {
    let mut changes = Vec::new();
    let host = if rng.chance(0.9) { "127.0.0.1:{port}" } else { "rebind.example:{port}" };
    let mut head = vec![format!("Host: {host}")];
    if rng.chance(0.1) {
        head.push("Origin: http://evil.example".into());
        changes.push("foreign origin".into());
    }
    let raw = if rng.chance(0.25) {
        let path = *rng.pick(&[
            "/api/state",
            "/api/plant",
            "/api/journal",
            "/api/snapshots",
            "/api/state?at=sync",
            "/",
            "/api/nope",
            "/app.js",
            "/api/stream?paths=tank.level",
        ]);
        changes.push(format!("GET {path}"));
        format!("GET {path} HTTP/1.1\r\n{}\r\nConnection: close\r\n\r\n", head.join("\r\n"))
    } else {
        let command: &&str = rng.pick(COMMANDS);
        let base: Value = serde_json::from_str(command).expect("valid command");
        let (body, lines) = if rng.chance(0.8) { mutated(rng, &base) } else { (base.to_string(), Vec::new()) };
        changes.extend(lines);
        let ct = *rng.pick(&[
            "application/json",
            "application/json",
            "application/json",
            "text/plain",
            "application/x-www-form-urlencoded",
            "",
        ]);
        if !ct.is_empty() {
            head.push(format!("Content-Type: {ct}"));
        }
        if rng.chance(0.9) {
            head.push("X-Plantwide-Token: {token}".into());
        }
        changes.push(format!("POST /api/command ({ct}): {}", &body[..body.len().min(120)]));
        format!(
            "POST /api/command HTTP/1.1\r\n{}\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
            head.join("\r\n"),
            body.len()
        )
    };
    (raw, changes)
}

/// Send a serve mutant: answered, with a status the API documents (never 5xx).
pub fn serve(raw: &str) -> Result<Outcome, Dishonest> {
    let mut guard = SERVER.lock().unwrap_or_else(|e| e.into_inner());
    let s = guard.get_or_insert_with(start_server);
    let raw = raw.replace("{port}", &s.port.to_string()).replace("{token}", &s.token);
    match request(s.port, &raw) {
        Ok(200) => Ok(Outcome::Ok),
        Ok(c @ (400 | 401 | 403 | 404 | 405 | 409 | 413 | 415 | 429)) => Ok(Outcome::User(format!("HTTP {c}"))),
        Ok(c) => Err(Dishonest(format!("HTTP {c}"))),
        Err(e) => Err(Dishonest(format!("the server did not answer: {e}"))),
    }
}
