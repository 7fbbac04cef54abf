//! Byte spans into the source text, and the caret display of a span under its line.

use std::fmt;

/// A half-open byte range `start..end` into the text an equation was parsed from.
///
/// Offsets are bytes, as `str` slicing uses them; [`render_caret`] converts them to character
/// columns for display.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Span {
    /// Offset of the first byte.
    pub start: usize,
    /// Offset one past the last byte.
    pub end: usize,
}

impl Span {
    /// The span `start..end`.
    pub const fn new(start: usize, end: usize) -> Self {
        Span { start, end }
    }

    /// The smallest span covering both.
    pub fn join(self, other: Span) -> Span {
        Span { start: self.start.min(other.start), end: self.end.max(other.end) }
    }

    /// The covered slice of `text`, or `""` when the span does not fall on character boundaries.
    pub fn slice(self, text: &str) -> &str {
        text.get(self.start..self.end).unwrap_or("")
    }
}

impl fmt::Display for Span {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}..{}", self.start, self.end)
    }
}

/// The text on one line and a line of carets under `span` (at least one caret, also for an
/// empty span such as the end of the text):
///
/// ```text
/// F = k*T + 1
///     ^^^^^^^
/// ```
///
/// Columns count characters, not bytes, so the carets line up under non-ASCII text. Line breaks
/// and tabs in the text are shown as spaces so that the caret line stays aligned.
pub fn render_caret(text: &str, span: Span) -> String {
    let shown: String = text.chars().map(|c| if c == '\n' || c == '\t' || c == '\r' { ' ' } else { c }).collect();
    let column = |byte: usize| text.char_indices().take_while(|&(i, _)| i < byte).count();
    let start = column(span.start.min(text.len()));
    let end = column(span.end.min(text.len())).max(start + 1);
    format!("{shown}\n{}{}", " ".repeat(start), "^".repeat(end - start))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn caret_under_span() {
        assert_eq!(render_caret("a + bb", Span::new(4, 6)), "a + bb\n    ^^");
        assert_eq!(render_caret("a +", Span::new(3, 3)), "a +\n   ^");
        // `·` is two bytes but one column.
        assert_eq!(render_caret("a·b + c", Span::new(7, 8)), "a·b + c\n      ^");
    }
}
