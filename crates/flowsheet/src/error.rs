//! Loading and validation errors. Every diagnostic names the file and the JSON path of the
//! offending field, and says what would fix it; all problems found are reported together.

/// One problem in a flowsheet file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    /// JSON path (`units.feed.F`, `streams.s3.to`); empty for the whole file.
    pub path: String,
    /// What is wrong and what would fix it.
    pub message: String,
}

impl Diagnostic {
    /// A diagnostic at `path`.
    pub fn new(path: impl Into<String>, message: impl Into<String>) -> Diagnostic {
        Diagnostic { path: path.into(), message: message.into() }
    }
}

/// Why a flowsheet could not be loaded.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LoadError {
    /// The file could not be read.
    #[error("{file}: cannot read the file: {reason}")]
    Io {
        /// File path.
        file: String,
        /// Operating-system reason.
        reason: String,
    },
    /// The file is not valid UTF-8.
    #[error("{file}:{line}:{column}: not UTF-8 text: byte 0x{byte:02x} at offset {offset} (save the file as UTF-8)")]
    Encoding {
        /// File path.
        file: String,
        /// Byte offset of the first invalid byte.
        offset: usize,
        /// 1-based line of it.
        line: usize,
        /// 1-based column (in characters) of it.
        column: usize,
        /// The invalid byte.
        byte: u8,
    },
    /// The file is not valid JSON.
    #[error("{file}:{line}:{column}: malformed JSON: {reason}")]
    Syntax {
        /// File path.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// Parser message.
        reason: String,
    },
    /// The JSON is well formed but describes an invalid flowsheet.
    #[error("{}", render(file, diagnostics))]
    Invalid {
        /// File path.
        file: String,
        /// Every problem found.
        diagnostics: Vec<Diagnostic>,
    },
}

fn render(file: &str, diagnostics: &[Diagnostic]) -> String {
    let n = diagnostics.len();
    let mut s = format!("{file}: {n} problem{} found", if n == 1 { "" } else { "s" });
    // Every problem is kept in the error value; the text shows the first MAX_SHOWN.
    const MAX_SHOWN: usize = 50;
    if n > MAX_SHOWN {
        s.push_str(&format!(" (the first {MAX_SHOWN} shown)"));
    }
    for d in diagnostics.iter().take(MAX_SHOWN) {
        if d.path.is_empty() {
            s.push_str(&format!("\n  - {}", d.message));
        } else {
            s.push_str(&format!("\n  - {}: {}", d.path, d.message));
        }
    }
    s
}

/// The closest of `candidates` to `word` by edit distance, if it is close enough to be a likely typo.
/// Words longer than [`SUGGEST_MAX_LEN`] get no suggestion, which bounds the cost (a 10 MB name
/// against a library of names would take seconds).
pub fn suggest<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    if word.len() > SUGGEST_MAX_LEN {
        return None;
    }
    let w = word.to_lowercase();
    candidates
        .into_iter()
        .map(|c| (edit_distance(&w, &c.to_lowercase()), c))
        .filter(|(d, c)| c.len() <= SUGGEST_MAX_LEN && *d <= 2.max(c.len() / 3))
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

/// Longest word (bytes) for which [`suggest`] searches; no real name is longer.
pub const SUGGEST_MAX_LEN: usize = 64;

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != *cb)).min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// " Did you mean `x`?" or nothing.
pub fn did_you_mean<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> String {
    suggest(word, candidates).map(|s| format!(" (did you mean `{s}`?)")).unwrap_or_default()
}

/// Any failure of the flowsheet crate (the crate-level error): loading, overrides and variants,
/// rewiring, editing a file's text.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// The file or a description could not be loaded.
    #[error(transparent)]
    Load(#[from] LoadError),
    /// An override or a variant could not be applied.
    #[error(transparent)]
    Override(#[from] crate::overrides::OverrideError),
    /// A unit's own check of its input values failed.
    #[error(transparent)]
    UnitInput(#[from] crate::overrides::UnitInputError),
    /// The plant could not be rewired as asked.
    #[error(transparent)]
    Wiring(#[from] crate::wiring::WiringError),
    /// A field of a file's text could not be edited.
    #[error(transparent)]
    Edit(#[from] crate::edit::EditError),
}
