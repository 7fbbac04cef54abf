//! `plantwide` as a child process: one command in a plant's folder, its exit code, output and
//! JSON, killed (by its own process id) when it runs over its time.

use std::io::Read;
use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};

use serde_json::Value;

/// What a command did.
#[derive(Debug, Clone)]
pub struct Output {
    /// The command line, as a user would type it in the plant's folder.
    pub line: String,
    /// Exit code (`None`: killed, over its time or by a signal).
    pub code: Option<i32>,
    /// Standard output.
    pub stdout: String,
    /// Standard error.
    pub stderr: String,
    /// Wall time [s].
    pub secs: f64,
}

impl Output {
    /// Exit code 0.
    pub fn ok(&self) -> bool {
        self.code == Some(0)
    }

    /// Stdout parsed as JSON.
    pub fn json(&self) -> Option<Value> {
        serde_json::from_str(&self.stdout).ok()
    }

    /// The exit and the first lines of the message, for a report.
    pub fn brief(&self) -> String {
        let msg: String = self.stderr.trim().chars().take(600).collect();
        match self.code {
            Some(c) => format!("exit {c}: {msg}"),
            None => format!("killed after {:.1} s (over its time): {msg}", self.secs),
        }
    }
}

/// A shell word: quoted when it holds anything but plain path characters.
fn word(s: &str) -> String {
    let plain = s.chars().all(|c| c.is_ascii_alphanumeric() || "-_./=,:@%+".contains(c));
    if plain && !s.is_empty() { s.to_string() } else { format!("'{}'", s.replace('\'', "'\\''")) }
}

/// The command line of `args`.
pub fn line(args: &[String]) -> String {
    std::iter::once("plantwide".to_string()).chain(args.iter().map(|a| word(a))).collect::<Vec<_>>().join(" ")
}

/// Run `plantwide ARGS` in `dir`, killing it after `limit`.
pub fn run(dir: &Path, args: &[String], limit: Duration) -> Output {
    let started = Instant::now();
    let mut child = crate::harness::command()
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the plantwide binary starts");
    let drain = |mut r: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut s = Vec::new();
            let _ = r.read_to_end(&mut s);
            String::from_utf8_lossy(&s).into_owned()
        })
    };
    let out = drain(Box::new(child.stdout.take().expect("piped stdout")));
    let err = drain(Box::new(child.stderr.take().expect("piped stderr")));
    let code = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status.code(),
            Ok(None) if started.elapsed() > limit => {
                // Only this child, which this function started.
                let _ = child.kill();
                let _ = child.wait();
                break None;
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(5)),
            Err(e) => panic!("waiting for plantwide: {e}"),
        }
    };
    Output {
        line: line(args),
        code,
        stdout: out.join().unwrap_or_default(),
        stderr: err.join().unwrap_or_default(),
        secs: started.elapsed().as_secs_f64(),
    }
}
