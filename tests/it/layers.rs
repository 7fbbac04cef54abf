//! The layering rules of issue 55, checked on the source tree so that they stay true: the faces
//! only translate (no report or `json!` result built in `src/cli`), the library names request
//! fields rather than command-line flags, holds no process-global parallelism switch, reads no
//! environment (the faces install the limits), and passes no JSON text or `serde_json::Value`
//! plant description or scenario between the studies and the flowsheet.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every `.rs` file under `dir`, outside `tests` folders.
fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display())) {
            let path = entry.unwrap().path();
            if path.is_dir() {
                if path.file_name().is_some_and(|n| n != "tests" && n != "target") {
                    stack.push(path);
                }
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// The library crates: every crate but the Python face.
fn library() -> Vec<PathBuf> {
    let crates = root().join("crates");
    let mut files = Vec::new();
    for entry in std::fs::read_dir(&crates).unwrap() {
        let dir = entry.unwrap().path();
        if dir.is_dir() && dir.file_name().is_some_and(|n| n != "python") {
            files.extend(sources(&dir.join("src")));
        }
    }
    assert!(files.len() > 100, "{} library sources", files.len());
    files
}

/// The lines of `file` that are code (not comments or doc comments), with their numbers, up to
/// its unit-test module.
fn code_lines(file: &Path) -> Vec<(usize, String)> {
    let text = std::fs::read_to_string(file).unwrap();
    text.lines()
        .take_while(|l| !l.starts_with("#[cfg(test)]"))
        .enumerate()
        .filter(|(_, l)| {
            let t = l.trim_start();
            !(t.starts_with("//") || t.starts_with('*'))
        })
        .map(|(k, l)| (k + 1, l.to_string()))
        .collect()
}

/// `file:line: text` of every code line in `files` that `bad` finds.
fn offences(files: &[PathBuf], bad: impl Fn(&str) -> bool) -> Vec<String> {
    let mut found = Vec::new();
    for f in files {
        for (k, line) in code_lines(f) {
            if bad(&line) {
                found.push(format!("{}:{k}: {}", f.strip_prefix(root()).unwrap_or(f).display(), line.trim()));
            }
        }
    }
    found
}

/// A `--flag` in a line: two dashes after a non-dash and before a lowercase letter.
fn names_flag(line: &str) -> bool {
    let b = line.as_bytes();
    (0..b.len().saturating_sub(2)).any(|i| {
        b[i] == b'-'
            && b[i + 1] == b'-'
            && b[i + 2].is_ascii_lowercase()
            && (i == 0 || !(b[i - 1] == b'-' || b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'!'))
    })
}

#[test]
fn the_flag_finder_finds_flags_and_nothing_else() {
    assert!(names_flag(r#"    "increase --step""#));
    assert!(names_flag(r#"#[error("--set {path}: {why}")]"#));
    assert!(!names_flag("    let x = a--b;"));
    assert!(!names_flag("    x -= 1; y --; // --"));
    assert!(!names_flag(r#"    "a-b 1e--3""#));
}

/// No library message names a command-line flag: Python users read them too; the command line
/// maps the request fields they name to its flags.
#[test]
fn library_messages_name_request_fields_not_flags() {
    let found = offences(&library(), names_flag);
    assert!(found.is_empty(), "library lines that name a --flag:\n{}", found.join("\n"));
}

/// Results do not depend on who calls: no process-global parallelism switch anywhere.
#[test]
fn nothing_sets_a_process_global_parallelism() {
    let mut files = library();
    files.extend(sources(&root().join("src")));
    files.extend(sources(&root().join("crates/python/src")));
    let found = offences(&files, |l| l.contains("set_global_parallelism"));
    assert!(found.is_empty(), "{}", found.join("\n"));
}

/// The command line holds no report: no `json!` result, no figure drawn.
#[test]
fn the_command_line_builds_no_json_result_or_figure() {
    let found = offences(&sources(&root().join("src/cli")), |l| {
        l.contains("json!") || l.contains("plotters") || l.contains("<svg") || l.contains("<html")
    });
    assert!(found.is_empty(), "{}", found.join("\n"));
}

/// The library reads no environment: the limits are read once by a face and installed
/// (`Limits::from_env` is the face's reader, in the one file that defines the limits).
#[test]
fn the_library_reads_no_environment() {
    let files: Vec<PathBuf> = library().into_iter().filter(|f| !f.ends_with("model/src/limits.rs")).collect();
    let found = offences(&files, |l| l.contains("env::var"));
    assert!(found.is_empty(), "{}", found.join("\n"));
}

/// Studies, analysis and the solver pass typed values to the flowsheet: no plant description or
/// scenario built as JSON or parsed back from text they wrote.
#[test]
fn studies_build_no_json_plants_or_scenarios() {
    let mut files = Vec::new();
    for c in ["studies", "analysis", "solve"] {
        files.extend(sources(&root().join("crates").join(c).join("src")));
    }
    let found = offences(&files, |l| l.contains("json!") || l.contains("parse_scenario(") || l.contains("load_str("));
    assert!(found.is_empty(), "{}", found.join("\n"));
}

/// Product code reports errors as typed values, never `Result<_, String>`.
#[test]
fn no_string_errors() {
    let mut files = library();
    files.extend(sources(&root().join("src")));
    files.extend(sources(&root().join("crates/python/src")));
    let found = offences(&files, |l| {
        l.split("Result<").skip(1).any(|rest| {
            // The error type: after the first top-level comma of the generic arguments.
            let mut depth = 0;
            for (k, ch) in rest.char_indices() {
                match ch {
                    '<' | '(' => depth += 1,
                    '>' | ')' if depth == 0 => return false,
                    '>' | ')' => depth -= 1,
                    ',' if depth == 0 => return rest[k + 1..].trim_start().starts_with("String>"),
                    _ => {}
                }
            }
            false
        })
    });
    assert!(found.is_empty(), "{}", found.join("\n"));
}
