//! `docs/tutorial.md` runs as written: every ```sh block is run from the project root by `sh`
//! with this build's `plantwide` first on the PATH, and must exit 0; the ```text block that
//! follows it shows its output, and each line shown (but trims `…` and timings) must be a line
//! the command printed, so that the tutorial cannot drift from the program (issue 53 item 7).

use crate::harness::ROOT;

/// The tutorial's (command, shown output) pairs, in order.
fn blocks(text: &str) -> Vec<(String, Vec<String>)> {
    let mut out: Vec<(String, Vec<String>)> = Vec::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        let fence = line.trim_end();
        if fence != "```sh" && fence != "```text" {
            continue;
        }
        let body: Vec<String> = lines.by_ref().take_while(|l| l.trim_end() != "```").map(str::to_string).collect();
        match (fence, out.last_mut()) {
            ("```sh", _) => out.push((body.join("\n"), Vec::new())),
            (_, Some((_, shown))) if shown.is_empty() => *shown = body,
            _ => {}
        }
    }
    out
}

/// Whether a shown line is checked: not a trim mark, not a wall-clock time.
fn checked(line: &str) -> bool {
    let l = line.trim();
    !(l.is_empty()
        || l.contains('…')
        || l.starts_with("simulated ")
        || l.contains(" real time")
        || l.contains("elapsed"))
}

#[test]
fn the_tutorial_runs_as_written() {
    let text = std::fs::read_to_string(format!("{ROOT}/docs/tutorial.md")).expect("docs/tutorial.md");
    let bin = std::path::Path::new(env!("CARGO_BIN_EXE_plantwide")).parent().unwrap().display().to_string();
    let path = format!("{bin}:{}", std::env::var("PATH").unwrap_or_default());
    let blocks = blocks(&text);
    assert!(blocks.len() >= 10, "the tutorial's commands: {}", blocks.len());
    for (command, shown) in &blocks {
        let out = std::process::Command::new("sh")
            .args(["-c", command])
            .current_dir(ROOT)
            .env("PATH", &path)
            .output()
            .expect("sh runs");
        let printed = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
        assert!(out.status.success(), "`{command}` exited {:?}:\n{printed}", out.status.code());
        let got: Vec<&str> = printed.lines().map(str::trim_end).collect();
        for line in shown.iter().filter(|l| checked(l)) {
            assert!(
                got.contains(&line.trim_end()),
                "`{command}`: the tutorial shows\n  {line}\nwhich it did not print:\n{printed}"
            );
        }
    }
}
