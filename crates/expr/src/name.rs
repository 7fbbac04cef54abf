//! The grammar of names: the one place that decides what a name token is.
//!
//! ```text
//! name    := segment ('.' segment)*
//! segment := ident ('[' index ']')*
//! ident   := [A-Za-z_] [A-Za-z0-9_]*
//! index   := [A-Za-z0-9_-]+
//! ```
//!
//! So `T`, `in.F`, `x[benzene]`, `feed.x[n-butane]` and `column.T[12]` are each one name; no
//! white space is allowed inside a name. A name may not be one of the [`KEYWORDS`].

use winnow::combinator::repeat;
use winnow::prelude::*;
use winnow::stream::LocatingSlice;
use winnow::token::{one_of, take_while};

/// The parser's input: the text with byte offsets.
pub(crate) type Input<'a> = LocatingSlice<&'a str>;

/// Words of the expression grammar, which cannot be names.
pub const KEYWORDS: [&str; 8] = ["if", "then", "else", "elseif", "and", "or", "not", "der"];

fn ident<'a>(i: &mut Input<'a>) -> ModalResult<&'a str> {
    (
        one_of(|c: char| c.is_ascii_alphabetic() || c == '_'),
        take_while(0.., |c: char| c.is_ascii_alphanumeric() || c == '_'),
    )
        .take()
        .parse_next(i)
}

fn index<'a>(i: &mut Input<'a>) -> ModalResult<&'a str> {
    ('[', take_while(1.., |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-'), ']').take().parse_next(i)
}

fn segment<'a>(i: &mut Input<'a>) -> ModalResult<&'a str> {
    (ident, repeat::<_, _, (), _, _>(0.., index)).take().parse_next(i)
}

/// One name token (keywords included: the caller decides what a keyword means where it is).
pub(crate) fn name<'a>(i: &mut Input<'a>) -> ModalResult<&'a str> {
    (segment, repeat::<_, _, (), _, _>(0.., ('.', segment))).take().parse_next(i)
}

/// Whether `word` is a keyword of the grammar.
pub fn is_keyword(word: &str) -> bool {
    KEYWORDS.contains(&word)
}

/// Whether `text` is exactly one name token and not a keyword.
pub fn is_valid_name(text: &str) -> bool {
    !is_keyword(text) && name.parse(LocatingSlice::new(text)).is_ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn valid_and_invalid_names() {
        for ok in ["T", "in.F", "x[benzene]", "feed.x[n-butane]", "column.T[12]", "_a1", "x[3][light]"] {
            assert!(is_valid_name(ok), "{ok}");
        }
        for bad in ["", "1x", "a b", "a.", ".a", "x[]", "x[a b]", "a+b", "if", "der", "a..b", "T[12"] {
            assert!(!is_valid_name(bad), "{bad}");
        }
    }
}
