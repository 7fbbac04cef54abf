//! "Did you mean" suggestions for unknown unit symbols.

use crate::table::{prefixes, units};

/// Words and wrong symbols people commonly write, with the symbol meant (matched ignoring case).
const ALIASES: &[(&str, &str)] = &[
    ("C", "degC"),
    ("F", "degF"),
    ("deg_C", "degC"),
    ("deg_F", "degF"),
    ("celsius", "degC"),
    ("centigrade", "degC"),
    ("fahrenheit", "degF"),
    ("kelvin", "K"),
    ("degK", "K"),
    ("rankine", "degR"),
    ("sec", "s"),
    ("second", "s"),
    ("seconds", "s"),
    ("minute", "min"),
    ("minutes", "min"),
    ("hour", "h"),
    ("hours", "h"),
    ("days", "d"),
    ("mole", "mol"),
    ("moles", "mol"),
    ("kmole", "kmol"),
    ("kmoles", "kmol"),
    ("lbmole", "lbmol"),
    ("lbmoles", "lbmol"),
    ("lb-mol", "lbmol"),
    ("lbs", "lb"),
    ("gallon", "gal"),
    ("gallons", "gal"),
    ("liter", "L"),
    ("litre", "L"),
    ("liters", "L"),
    ("litres", "L"),
    ("feet", "ft"),
    ("foot", "ft"),
    ("inch", "in"),
    ("inches", "in"),
    ("meter", "m"),
    ("metre", "m"),
    ("mmBtu", "MMBtu"),
    ("MBtu", "MMBtu"),
    ("kgs", "kg"),
    ("percent", "%"),
];

/// Prefixed forms offered as suggestions besides the plain table symbols.
const COMMON_PREFIXES: &[&str] = &["k", "M", "G", "m", "c", "µ"];

fn candidates() -> impl Iterator<Item = String> {
    let plain = units().iter().filter(|u| u.symbol != "-").map(|u| u.symbol.to_owned());
    let prefixed = units().iter().filter(|u| u.prefixable).flat_map(|u| {
        prefixes()
            .iter()
            .filter(|p| COMMON_PREFIXES.contains(&p.symbol))
            .map(move |p| format!("{}{}", p.symbol, u.symbol))
    });
    plain.chain(prefixed)
}

/// Levenshtein distance over characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let next = (row[j + 1] + 1).min(row[j] + 1).min(diagonal + usize::from(ca != cb));
            diagonal = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

/// The known symbol closest to `unknown`: an alias, the same symbol in other letter case, or the
/// nearest symbol by edit distance (at most 1 for symbols of up to 3 characters, else at most 2).
pub(crate) fn suggest(unknown: &str) -> Option<String> {
    if unknown.len() > 32 {
        return None;
    }
    if let Some((_, meant)) = ALIASES.iter().find(|(alias, _)| alias.eq_ignore_ascii_case(unknown)) {
        return Some((*meant).to_owned());
    }
    if let Some(same) = candidates().find(|c| c.to_lowercase() == unknown.to_lowercase()) {
        return Some(same);
    }
    let limit = if unknown.chars().count() <= 3 { 1 } else { 2 };
    candidates()
        .map(|c| (edit_distance(unknown, &c), c))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("kmol", "kmol"), 0);
        assert_eq!(edit_distance("°C", "°F"), 1);
    }

    #[test]
    fn suggestions() {
        assert_eq!(suggest("kmols").as_deref(), Some("kmol"));
        assert_eq!(suggest("KMOL").as_deref(), Some("kmol"));
        assert_eq!(suggest("BTU").as_deref(), Some("Btu"));
        assert_eq!(suggest("C").as_deref(), Some("degC"));
        assert_eq!(suggest("F").as_deref(), Some("degF"));
        assert_eq!(suggest("degc").as_deref(), Some("degC"));
        assert_eq!(suggest("hours").as_deref(), Some("h"));
        assert_eq!(suggest("lbmole").as_deref(), Some("lbmol"));
        assert!(matches!(suggest("psai").as_deref(), Some("psi" | "psia")));
        assert_eq!(suggest("MBtu").as_deref(), Some("MMBtu"));
        assert_eq!(suggest("furlongs"), None);
        assert_eq!(suggest("xyzzy"), None);
    }
}
