//! `plantwide serve`: the server started on a loopback address and an ephemeral port, driven
//! over HTTP (a raw `TcpStream` client): every command and every bad input, the token beyond
//! 127.0.0.1, the rate limit, the trend stream; every cross-site attack refused (a command not in
//! JSON, from a foreign origin or without the session token, a foreign host reading the state);
//! and on column A a live feed step that equals the scenario-file run of the same event and
//! settles on the steady state `steady --set` gives.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

use plantwide::flowsheet::scenario::{ScenarioSpec, resolve};
use plantwide::flowsheet::{Override, load_with};
use plantwide::solve::dynamic::{Start, simulate};
use plantwide::solve::{Method, StrategySettings, converge};
use serde_json::{Value, json};

use crate::harness::{command, flowsheet, plantwide};

/// A server process, killed when dropped (and stopping by itself after 15 min in any case).
struct Server {
    child: Child,
    addr: String,
    /// The session token it printed.
    token: String,
}

impl Server {
    fn start(file: &str, extra: &[&str]) -> Server {
        Server::start_with(file, extra, &[])
    }

    /// [`Server::start`] with environment variables set.
    fn start_with(file: &str, extra: &[&str], env: &[(&str, &str)]) -> Server {
        let mut child = command()
            .envs(env.iter().copied())
            .args(["serve", file, "--port", "0", "--exit-after", "900"])
            .args(extra)
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("plantwide serve starts");
        let mut out = BufReader::new(child.stdout.take().expect("stdout"));
        let (mut addr, mut token) = (None, None);
        let mut line = String::new();
        // The address, then the session token (every server prints one).
        while addr.is_none() || token.is_none() {
            line.clear();
            assert!(out.read_line(&mut line).expect("reads stdout") > 0, "the server ended before listening");
            if let Some(rest) = line.split("http://").nth(1) {
                addr = Some(rest.split('/').next().expect("host:port").to_string());
            }
            if let Some(t) = line.trim().strip_prefix("token: ") {
                token = t.split_whitespace().next().map(str::to_string);
            }
        }
        Server { child, addr: addr.expect("address"), token: token.expect("a token") }
    }

    /// One request with exactly these header lines (and `Content-Length`, `Connection: close`);
    /// the status and the body.
    fn raw(&self, method: &str, path: &str, headers: &[(&str, &str)], body: &str) -> (u16, String) {
        let mut s = TcpStream::connect(&self.addr).expect("connects");
        s.set_read_timeout(Some(Duration::from_secs(60))).expect("timeout");
        let mut head = format!("{method} {path} HTTP/1.1\r\nConnection: close\r\nContent-Length: {}\r\n", body.len());
        headers.iter().for_each(|(k, v)| head.push_str(&format!("{k}: {v}\r\n")));
        head.push_str("\r\n");
        s.write_all(head.as_bytes()).and_then(|()| s.write_all(body.as_bytes())).expect("writes");
        let mut text = String::new();
        s.read_to_string(&mut text).expect("reads the response");
        let status = text.split(' ').nth(1).and_then(|c| c.parse().ok()).expect("a status line");
        let body = text.split_once("\r\n\r\n").map(|(_, b)| b.to_string()).unwrap_or_default();
        (status, body)
    }

    /// One request as the page makes it: this server's host, JSON, and (if `auth`) the token.
    fn request(&self, method: &str, path: &str, body: &str, auth: bool) -> (u16, String) {
        let mut headers = vec![("Host", self.addr.as_str()), ("Content-Type", "application/json")];
        if auth {
            headers.push(("X-Plantwide-Token", &self.token));
        }
        self.raw(method, path, &headers, body)
    }

    fn get(&self, path: &str) -> Value {
        let (status, body) = self.request("GET", path, "", true);
        assert_eq!(status, 200, "GET {path}: {body}");
        serde_json::from_str(&body).unwrap_or_else(|e| panic!("GET {path}: {e}: {body}"))
    }

    /// POST a command; the status and the JSON answer.
    fn command(&self, cmd: &str) -> (u16, Value) {
        let (status, body) = self.request("POST", "/api/command", cmd, true);
        (status, serde_json::from_str(&body).unwrap_or_else(|e| panic!("{cmd}: {e}: {body}")))
    }

    fn ok(&self, cmd: Value) -> Value {
        let (status, v) = self.command(&cmd.to_string());
        assert_eq!(status, 200, "{cmd}: {v}");
        v
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A command refused with HTTP 400 whose message holds `needle`.
fn refused(s: &Server, cmd: &str, needle: &str) {
    let (status, v) = s.command(cmd);
    assert_eq!(status, 400, "{cmd}: {v}");
    let msg = v["error"].as_str().expect("an error message");
    assert!(msg.contains(needle), "{cmd}: `{msg}` does not mention `{needle}`");
}

#[test]
fn serve_applies_every_command_and_refuses_every_bad_input_with_400() {
    let s = Server::start(&flowsheet("column_a.json"), &["--paused"]);
    let st = s.get("/api/state");
    assert_eq!(st["time"], json!(0.0));
    assert_eq!(st["running"], json!(false));
    // `values` holds every path `steady --json` lists.
    let out = plantwide(&["steady", &flowsheet("column_a.json"), "--json"]);
    let steady: Value = serde_json::from_slice(&out.stdout).expect("steady --json");
    let keys = |v: &Value| v.as_object().expect("object").keys().cloned().collect::<Vec<_>>();
    assert_eq!(keys(&st["values"]), keys(&steady["values"]));

    s.ok(json!({"set": {"feed_source.F": "1.005 kmol/min"}}));
    s.ok(json!({"set": {"condenser_level.sp": "0.55 kmol", "zF": "0.51"}}));
    s.ok(json!({"speed": 100}));
    s.ok(json!({"resume": true}));
    s.ok(json!({"pause": true}));
    s.ok(json!({"step": true}));
    s.ok(json!({"mode": {"reboiler_level": "manual"}}));
    s.ok(json!({"mode": {"reboiler_level": "auto"}}));
    s.ok(json!({"event": {"type": "ramp", "path": "column.reflux", "by": "0.01 kmol/min", "duration": "5 min"}}));
    s.ok(json!({"event": {"type": "pulse", "path": "column.boilup", "to": "3.3 kmol/min", "width": "1 min"}}));
    s.ok(json!({"snapshot": "before"}));
    s.ok(json!({"step": true}));
    let t_step = s.get("/api/state")["time"].as_f64().expect("time");
    assert!(t_step > 0.0, "the steps moved the clock");
    s.ok(json!({"load": "before"}));
    assert!(s.get("/api/state")["time"].as_f64().expect("time") < t_step, "load went back");
    assert_eq!(s.get("/api/snapshots"), json!(["before"]));

    refused(&s, r#"{"set": {"feed_source.Q": "1 kmol/min"}}"#, "no input `feed_source.Q`");
    refused(&s, r#"{"set": {"nowhere.F": "1 kmol/min"}}"#, "no input `nowhere.F`");
    refused(&s, r#"{"set": {"feed_source.F": "1 kPa"}}"#, "feed_source.F");
    refused(&s, r#"{"set": {"feed_source.F": "1 furlong"}}"#, "feed_source.F");
    refused(&s, r#"{"set": {"feed_source.F": "-1 kmol/min"}}"#, "feed_source.F=-1 kmol/min");
    refused(&s, r#"{"set": {"feed_source.F": "fast"}}"#, "feed_source.F");
    refused(&s, r#"{"set": {"column.distillate": "0.5 kmol/min"}}"#, "driven by a controller");
    refused(&s, r#"{"set": {"feed_source.F": 1.0}}"#, "give a string");
    refused(&s, r#"{"set": {}}"#, "empty");
    refused(&s, r#"{"set": "feed_source.F=1"}"#, "give an object");
    refused(&s, r#"{"mode": {"condenser_level": "cascade"}}"#, "give \"auto\" or \"manual\"");
    refused(&s, r#"{"mode": {"no_such_loop": "manual"}}"#, "no controller `no_such_loop`");
    refused(&s, r#"{"speed": 0}"#, "speed 0");
    refused(&s, r#"{"speed": -5}"#, "speed -5");
    refused(&s, r#"{"speed": 1e9}"#, "at most");
    refused(&s, r#"{"speed": "fast"}"#, "give a number");
    refused(&s, r#"{"pause": false}"#, "pause: give true");
    refused(&s, r#"{"resume": 1}"#, "resume: give true");
    refused(&s, r#"{"step": "yes"}"#, "step: give true");
    refused(&s, r#"{"snapshot": "../etc/passwd"}"#, "snapshot name");
    refused(&s, r#"{"snapshot": 3}"#, "give a name");
    refused(&s, r#"{"load": "never_saved"}"#, "no snapshot named `never_saved`");
    refused(&s, r#"{"event": {"type": "explode", "path": "feed_source.F"}}"#, "event:");
    refused(&s, r#"{"event": {"type": "feed_lost", "unit": "column"}}"#, "no feed unit `column`");
    refused(
        &s,
        r#"{"event": {"type": "step", "path": "feed_source.F", "by": "-2 kmol/min"}}"#,
        "takes `feed_source.F`",
    );
    refused(&s, r#"{"launch": true}"#, "unknown command `launch`");
    refused(&s, r#"{"pause": true, "resume": true}"#, "exactly one");
    refused(&s, r#"[1, 2]"#, "one JSON object");
    refused(&s, r#"{"set": "#, "malformed JSON");
    let (status, _) = s.request("POST", "/api/command", &format!("{{\"snapshot\": \"{}\"}}", "x".repeat(20_000)), true);
    assert_eq!(status, 413, "a body over the limit");
    let (status, _) = s.request("GET", "/api/state?at=yesterday", "", true);
    assert_eq!(status, 400);
    let (status, body) = s.request("GET", "/api/stream?paths=no.such.path", "", true);
    assert_eq!((status, body.contains("no path `no.such.path`")), (400, true));

    // The run goes on: commands still apply, the clock still steps.
    let st = s.get("/api/state");
    assert!(st["failure"].is_null(), "{}", st["failure"]);
    s.ok(json!({"step": true}));
    assert!(s.get("/api/state")["time"].as_f64().expect("time") > st["time"].as_f64().expect("time"));
    // The page and its assets.
    let (status, page) = s.request("GET", "/", "", false);
    assert!(status == 200 && page.contains("faceplates"), "{status}");
    assert_eq!(s.request("GET", "/app.js", "", false).0, 200);
}

/// A request refused with `status` whose `{"error"}` message holds `needle`.
fn refused_with(answer: (u16, String), status: u16, needle: &str) {
    let (got, body) = answer;
    assert_eq!(got, status, "{body}");
    let v: Value = serde_json::from_str(&body).unwrap_or_else(|e| panic!("{e}: {body}"));
    let msg = v["error"].as_str().unwrap_or_else(|| panic!("an error message: {body}"));
    assert!(msg.contains(needle), "`{msg}` does not mention `{needle}`");
}

#[test]
fn serve_on_loopback_refuses_a_command_not_in_json_from_a_foreign_origin_or_without_the_token() {
    // What a web page open in the user's browser can send to 127.0.0.1 without a CORS preflight
    // (text/plain, a form), or with its own origin; none may resume the paused clock.
    let s = Server::start(&flowsheet("column_a.json"), &["--paused"]);
    let (host, token) = (s.addr.as_str(), s.token.as_str());
    let resume = r#"{"resume": true}"#;
    let post = |headers: &[(&str, &str)]| s.raw("POST", "/api/command", headers, resume);
    let needs_json = "Content-Type: application/json";
    let text_plain = post(&[("Host", host), ("X-Plantwide-Token", token), ("Content-Type", "text/plain")]);
    refused_with(text_plain, 415, needs_json);
    let form = [("Host", host), ("X-Plantwide-Token", token), ("Content-Type", "application/x-www-form-urlencoded")];
    refused_with(post(&form), 415, needs_json);
    let multipart = ("Content-Type", "multipart/form-data; boundary=x");
    refused_with(post(&[("Host", host), ("X-Plantwide-Token", token), multipart]), 415, needs_json);
    refused_with(post(&[("Host", host), ("X-Plantwide-Token", token)]), 415, needs_json);
    let json = ("Content-Type", "application/json");
    let foreign = post(&[("Host", host), ("X-Plantwide-Token", token), json, ("Origin", "http://evil.example")]);
    refused_with(foreign, 403, "origin `http://evil.example`");
    refused_with(post(&[("Host", host), ("X-Plantwide-Token", token), json, ("Origin", "null")]), 403, "origin `null`");
    refused_with(post(&[("Host", host), json]), 403, "X-Plantwide-Token");
    let wrong = "0123456789abcdef0123456789abcdef";
    refused_with(post(&[("Host", host), ("X-Plantwide-Token", wrong), json]), 403, "X-Plantwide-Token");
    let cross_site = ("Sec-Fetch-Site", "cross-site");
    refused_with(post(&[("Host", host), ("X-Plantwide-Token", token), json, cross_site]), 403, "another site");
    assert_eq!(s.get("/api/state")["running"], json!(false), "no refused command was obeyed");
}

#[test]
fn serve_refuses_a_foreign_host_so_a_rebound_name_reads_nothing() {
    // DNS rebinding: a page of rebind.example whose name now points at 127.0.0.1 reads with its
    // own host name (and from its own origin); neither the state, the journal nor the page (which
    // carries the token) is served.
    let s = Server::start(&flowsheet("column_a.json"), &["--paused"]);
    let port = s.addr.rsplit(':').next().expect("a port");
    let rebound = format!("rebind.example:{port}");
    for path in ["/api/state", "/api/journal", "/api/snapshots", "/api/plant", "/api/stream", "/"] {
        refused_with(s.raw("GET", path, &[("Host", &rebound)], ""), 403, &format!("host `{rebound}`"));
    }
    let other_port = format!("127.0.0.1:{}", port.parse::<u32>().expect("a port") + 1);
    refused_with(s.raw("GET", "/api/state", &[("Host", &other_port)], ""), 403, "host `127.0.0.1:");
    refused_with(s.raw("GET", "/api/state", &[], ""), 403, "host `(none)`");
    let origin = format!("http://{rebound}");
    let from_rebound = s.raw("GET", "/api/journal", &[("Host", &s.addr), ("Origin", &origin)], "");
    refused_with(from_rebound, 403, &format!("origin `{origin}`"));
    let json = ("Content-Type", "application/json");
    let command = [("Host", rebound.as_str()), ("X-Plantwide-Token", s.token.as_str()), json];
    refused_with(s.raw("POST", "/api/command", &command, r#"{"resume": true}"#), 403, "host `rebind.example");
    assert_eq!(s.get("/api/state")["running"], json!(false));
}

#[test]
fn serve_refuses_a_key_given_twice_in_a_command_naming_it() {
    // serde_json keeps the last of two equal keys: `{"pause": true, "pause": true}` would pass as
    // one pause, and a set naming one input twice would apply one value unseen.
    let s = Server::start(&flowsheet("column_a.json"), &["--paused"]);
    refused(&s, r#"{"resume": true, "resume": true}"#, "`resume`: this key appears twice");
    refused(
        &s,
        r#"{"set": {"feed_source.F": "1.01 kmol/min", "feed_source.F": "0.99 kmol/min"}}"#,
        "`set.feed_source.F`: this key appears twice",
    );
    refused(&s, r#"{"event": {"type": "step", "type": "ramp", "path": "feed_source.F"}}"#, "`event.type`");
    assert_eq!(s.get("/api/state")["running"], json!(false));
    assert_eq!(s.get("/api/journal")["events"], json!([]));
}

#[test]
fn serve_takes_its_own_pages_requests_and_the_page_carries_the_token() {
    let s = Server::start(&flowsheet("column_a.json"), &["--paused"]);
    let (page_status, page) = s.raw("GET", "/", &[("Host", &s.addr)], "");
    assert_eq!(page_status, 200);
    assert!(page.contains(&format!(r#"<meta name="plantwide-token" content="{}">"#, s.token)), "{page}");
    // As a browser sends them from the page, under any loopback name of this server.
    let port = s.addr.rsplit(':').next().expect("a port");
    for name in ["127.0.0.1", "localhost", "[::1]"] {
        let host = format!("{name}:{port}");
        let origin = format!("http://{host}");
        let headers = [
            ("Host", host.as_str()),
            ("Origin", origin.as_str()),
            ("Sec-Fetch-Site", "same-origin"),
            ("Content-Type", "application/json; charset=utf-8"),
            ("X-Plantwide-Token", s.token.as_str()),
        ];
        let (status, body) = s.raw("POST", "/api/command", &headers, r#"{"step": true}"#);
        assert_eq!(status, 200, "{host}: {body}");
        assert_eq!(s.raw("GET", "/api/state", &headers[..3], "").0, 200, "{host}");
    }
    // A client without Origin (curl, scripts): reads need nothing more than the right host.
    assert_eq!(s.raw("GET", "/api/journal", &[("Host", &s.addr)], "").0, 200);
    let bearer = format!("Bearer {}", s.token);
    let curl = [("Host", s.addr.as_str()), ("Content-Type", "application/json"), ("Authorization", bearer.as_str())];
    assert_eq!(s.raw("POST", "/api/command", &curl, r#"{"step": true}"#).0, 200);
    assert!(s.get("/api/state")["time"].as_f64().expect("time") > 0.0, "the steps were taken");
}

/// Read the trend stream until `n` samples arrived; the paths event and the samples.
fn stream_samples(s: &Server, paths: &str, n: usize) -> (Value, Vec<Value>) {
    let mut sock = TcpStream::connect(&s.addr).expect("connects");
    sock.set_read_timeout(Some(Duration::from_secs(30))).expect("timeout");
    write!(sock, "GET /api/stream?paths={paths} HTTP/1.1\r\nHost: {}\r\n\r\n", s.addr).expect("writes");
    let mut r = BufReader::new(sock);
    let (mut head, mut samples, mut event) = (Value::Null, Vec::new(), String::new());
    let mut line = String::new();
    while samples.len() < n {
        line.clear();
        assert!(r.read_line(&mut line).expect("reads") > 0, "the stream ended");
        if let Some(e) = line.strip_prefix("event: ") {
            event = e.trim().to_string();
        } else if let Some(d) = line.strip_prefix("data: ") {
            let v: Value = serde_json::from_str(d.trim()).expect("JSON data");
            if event == "paths" {
                head = v
            } else {
                samples.push(v)
            }
            event.clear();
        }
    }
    (head, samples)
}

#[test]
fn serve_streams_trend_samples_to_several_clients() {
    let s = Server::start(&flowsheet("column_a.json"), &["--speed", "60"]);
    let a = std::thread::scope(|sc| {
        let one = sc.spawn(|| stream_samples(&s, "column.M[41],bottoms.x[light]", 3));
        let two = stream_samples(&s, "condenser_level.sp", 3);
        assert_eq!(two.0, json!(["condenser_level.sp"]));
        one.join().expect("first client")
    });
    assert_eq!(a.0, json!(["column.M[41]", "bottoms.x[light]"]));
    let t: Vec<f64> = a.1.iter().map(|v| v["t"].as_f64().expect("t")).collect();
    assert!(t.windows(2).all(|w| w[1] >= w[0]) && t[2] > t[0], "time runs: {t:?}");
    assert_eq!(a.1[0]["v"].as_array().expect("values").len(), 2);
    // The drawing: the column's distillate (its first outlet) goes to the unit drawn above the one
    // its bottoms go to, so the two product lines do not cross (the blocks come in name order).
    let plant = s.get("/api/plant");
    let at = |name: &str| {
        let u = plant["units"].as_array().expect("units").iter().find(|u| u["name"] == name).expect("unit");
        (u["col"].as_u64().expect("col"), u["row"].as_u64().expect("row"))
    };
    let (top, bottom) = (at("top_product"), at("bottom_product"));
    assert_eq!(top.0, bottom.0);
    assert!(top.1 < bottom.1, "top_product {top:?}, bottom_product {bottom:?}");
}

#[test]
fn serve_beyond_127_0_0_1_asks_for_the_token_and_limits_the_rate() {
    let s = Server::start(&flowsheet("column_a.json"), &["--bind", "127.0.0.2", "--paused", "--rate", "5"]);
    let token = s.token.clone();
    assert_eq!(token.len(), 32);
    let (status, body) = s.request("GET", "/api/state", "", false);
    assert_eq!(status, 401, "{body}");
    assert!(body.contains("token"), "{body}");
    assert_eq!(s.request("POST", "/api/command", r#"{"resume": true}"#, false).0, 401);
    assert_eq!(s.request("GET", &format!("/api/state?token={token}"), "", false).0, 200);
    let bearer = format!("Bearer {token}");
    assert_eq!(s.raw("GET", "/api/state", &[("Host", &s.addr), ("Authorization", &bearer)], "").0, 200);
    // Beyond loopback the page does not carry the token: whoever reaches it must have been given it.
    let (status, page) = s.request("GET", "/", "", false);
    assert!(status == 200 && !page.contains(&token), "{status}");
    assert_eq!(s.request("GET", "/api/state?token=0123456789abcdef0123456789abcdef", "", false).0, 401);
    // 5 per second, 10 in a burst: 30 at once meet 429s.
    let statuses: Vec<u16> = (0..30).map(|_| s.request("GET", "/api/state", "", true).0).collect();
    assert!(statuses.contains(&200) && statuses.contains(&429), "{statuses:?}");
}

/// The largest difference between the live values and a state vector, over the plant variables.
fn max_difference(plant: &plantwide::flowsheet::Plant, values: &Value, x: &[f64]) -> f64 {
    plant
        .vars()
        .iter()
        .zip(x)
        .map(|(v, xv)| (values[&v.path].as_f64().expect("a value") - xv).abs())
        .fold(0.0, f64::max)
}

#[test]
fn a_live_feed_step_equals_the_scenario_run_and_settles_on_the_steady_state() {
    let scenario = flowsheet("scenarios/column_a_live.json");
    let s = Server::start(&flowsheet("column_a.json"), &["--scenario", &scenario, "--paused"]);
    for _ in 0..5 {
        s.ok(json!({"step": true}));
    }
    let at = s.ok(json!({"set": {"feed_source.F": "1.01 kmol/min"}}))["at"].as_f64().expect("at");
    assert!(at > 0.0);
    s.ok(json!({"speed": 1e6}));
    s.ok(json!({"resume": true}));
    let started = Instant::now();
    while s.get("/api/state")["time"].as_f64().expect("time") < 3000.0 * 60.0 {
        assert!(started.elapsed() < Duration::from_secs(300), "the live run reaches 3000 min");
        std::thread::sleep(Duration::from_millis(200));
    }
    s.ok(json!({"pause": true}));
    // Pause stops the clock.
    let (a, b) = (s.get("/api/state"), {
        std::thread::sleep(Duration::from_millis(700));
        s.get("/api/state")
    });
    assert_eq!(a["time"], b["time"]);
    assert_eq!(a["running"], json!(false));
    let live = s.get("/api/state?at=sync");
    let journal: ScenarioSpec = serde_json::from_value(s.get("/api/journal")).expect("a scenario");
    assert_eq!(journal.events.len(), 1);

    // The same event in a scenario file, run by the library as `run` runs it.
    let plant = load_with(std::path::Path::new(&flowsheet("column_a.json")), &[]).expect("loads");
    let settings = StrategySettings { method: Method::Auto, ..StrategySettings::default() };
    let x0 = converge(&plant, &settings).expect("converges").x;
    let sc = resolve(&journal, &plant, "journal").expect("the journal resolves");
    let res = simulate(&plant, &sc, Start::Steady(&x0), "test", &mut |_| {}).expect("runs");
    assert_eq!(res.t, live["time"].as_f64().expect("time"));
    let diff = max_difference(&plant, &live["values"], &res.x);
    eprintln!("live vs scenario file at t = {} s: max |Δx| = {diff:.3e}", res.t);
    assert!(diff <= 1e-10, "live and scenario-file runs differ by {diff:e}");

    // And the steady state of the stepped plant.
    let stepped = load_with(
        std::path::Path::new(&flowsheet("column_a.json")),
        &[Override::new("feed_source.F", "1.01 kmol/min")],
    )
    .expect("loads");
    let ss = converge(&stepped, &settings).expect("converges");
    let xb = stepped.var("bottoms.x[light]").expect("xB");
    let (live_xb, steady_xb) = (live["values"]["bottoms.x[light]"].as_f64().expect("xB"), ss.x[xb]);
    eprintln!(
        "xB live at 3000 min {live_xb:.10}, steady --set {steady_xb:.10}, |Δ| = {:.3e}",
        (live_xb - steady_xb).abs()
    );
    assert!((live_xb - steady_xb).abs() <= 1e-6 * steady_xb, "xB {live_xb} against the steady state {steady_xb}");
}

#[test]
fn the_live_journal_holds_no_more_events_than_a_scenario_may() {
    // PLANTWIDE_MAX_EVENTS bounds what a command can make the server keep: the journal is a scenario.
    let s = Server::start_with(&flowsheet("column_a.json"), &["--paused"], &[("PLANTWIDE_MAX_EVENTS", "2")]);
    s.ok(json!({"set": {"feed_source.F": "1.01 kmol/min"}}));
    s.ok(json!({"set": {"column.reflux": "2.7 kmol/min"}}));
    refused(&s, r#"{"set": {"column.boilup": "3.2 kmol/min"}}"#, "journal holds 2 events, the most a scenario may");
    assert_eq!(s.get("/api/state")["running"], json!(false), "the run goes on, paused as it was");
}

#[test]
fn serve_keeps_at_most_64_snapshots_and_says_how_to_replace_one() {
    // Each snapshot holds the integrator's state: a session saving under ever new names would grow.
    let s = Server::start(&flowsheet("column_a.json"), &["--paused"]);
    for k in 0..plantwide::solve::dynamic::MAX_SNAPSHOTS {
        s.ok(json!({ "snapshot": format!("s{k}") }));
    }
    refused(&s, r#"{"snapshot": "one_more"}"#, "64 snapshots are kept already");
    refused(&s, r#"{"snapshot": "one_more"}"#, "save under one of their names to replace it");
    s.ok(json!({"step": true}));
    s.ok(json!({"snapshot": "s0"}));
    assert_eq!(s.get("/api/snapshots").as_array().expect("names").len(), 64);
}

/// A unit written as equations (issue 57) is served as any other: the first state is the steady
/// state the library converges, and a step in the coolant temperature runs.
#[test]
fn serve_runs_a_plant_with_an_equations_unit() {
    let file = crate::harness::fixture("data/cstr_equations.json");
    let s = Server::start(&file, &["--paused"]);
    let plant = load_with(std::path::Path::new(&file), &[]).expect("loads");
    let settings = StrategySettings { method: Method::Auto, ..StrategySettings::default() };
    let x0 = converge(&plant, &settings).expect("converges").x;
    let diff = max_difference(&plant, &s.get("/api/state?at=sync")["values"], &x0);
    assert!(diff <= 1e-9, "served first state against the steady state: {diff:e}");
    s.ok(json!({"set": {"reactor.coolant_T": "305 K"}}));
    for _ in 0..3 {
        s.ok(json!({"step": true}));
    }
    let t0 = s.get("/api/state?at=sync")["values"]["effluent.T"].as_f64().expect("T");
    assert!(t0 > x0[plant.var("effluent.T").expect("T")], "warmer coolant warms the reactor");
}

/// A tag's name is a trend path of the page (issue 56, item 5): `/api/plant` lists the tags with
/// the value path each names and its unit, and a pen on the name streams that path's values.
#[test]
fn serve_trends_a_tag_by_its_name() {
    let s = Server::start(&crate::harness::fixture("data/column_a_tags.json"), &["--paused"]);
    let plant = s.get("/api/plant");
    let tags = plant["tags"].as_array().expect("tags");
    let cost = tags.iter().find(|t| t["name"] == "cost").expect("the cost tag");
    assert_eq!(cost["path"], "cost.value");
    assert_eq!(cost["unit"], "$/h");
    assert!(tags.iter().any(|t| t["name"] == "impurity" && t["unit"].is_null()), "{tags:?}");
    let (head, samples) = stream_samples(&s, "cost,cost.value", 2);
    assert_eq!(head, json!(["cost", "cost.value"]));
    for v in &samples {
        let v = v["v"].as_array().expect("values");
        assert!(v[0].as_f64().is_some() && v[0] == v[1], "{v:?}");
    }
}
