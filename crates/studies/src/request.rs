//! Checks every study applies to the lists of its request (CVs, MVs, loops, candidate vessels),
//! and the one message of a result with parts that have no answer.

/// The message every face gives for a result whose `failed` parts have no answer (after the
/// report, which marks them; the CLI's exit 2, Python's `ConvergenceError`): `size: 1 part failed
/// (marked in the report): …`. None when every part has its answer.
pub fn failed_parts(study: &str, failed: &[String]) -> Option<String> {
    match failed {
        [] => None,
        [one] => Some(format!("{study}: 1 part failed (marked in the report): {one}")),
        many => Some(format!("{study}: {} parts failed (marked in the report): {}", many.len(), many.join("; "))),
    }
}

/// A list of a request that names one item twice.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{list}: `{item}` is given twice (entries {first} and {second}, counted from 1): give each once")]
pub struct Duplicate {
    /// The list (the request's field: `cvs`, `loops`, …).
    pub list: String,
    /// The item as given the second time.
    pub item: String,
    /// Where it first appears (1-based).
    pub first: usize,
    /// Where it appears again (1-based).
    pub second: usize,
}

/// The first item of `items` that an earlier one equals under `same` (e.g. two paths of one
/// variable), as an error on `list`.
///
/// # Errors
/// [`Duplicate`] naming both places.
pub fn unique<T: AsRef<str>>(list: &str, items: &[T], same: impl Fn(&str, &str) -> bool) -> Result<(), Duplicate> {
    for (k, b) in items.iter().enumerate() {
        if let Some(j) = items[..k].iter().position(|a| same(a.as_ref(), b.as_ref())) {
            return Err(Duplicate {
                list: list.to_string(),
                item: b.as_ref().to_string(),
                first: j + 1,
                second: k + 1,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_second_of_two_equal_items_is_named_with_both_places() {
        let e = unique("cvs", &["a", "b", "c", "b"], |x, y| x == y).unwrap_err();
        assert_eq!((e.item.as_str(), e.first, e.second), ("b", 2, 4));
        assert!(e.to_string().contains("entries 2 and 4"), "{e}");
        assert!(unique("cvs", &["a", "b"], |x, y| x == y).is_ok());
        let aliases = unique("cvs", &["s.x[a]", "s.z[a]"], |x, y| x.replace(".z[", ".x[") == y.replace(".z[", ".x["));
        assert!(aliases.is_err());
    }
}
