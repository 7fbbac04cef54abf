//! The report of the built-in component library ([`Library`]): one row per component (formula,
//! molar mass, normal boiling point, critical temperature and pressure), then the binary pairs
//! and their sources. `plantwide components` prints [`text`] (or the library's JSON with
//! `--json`).

use plantwide_thermo::Library;

/// The library as a table, then its binary pairs (model, components, source).
pub fn text(lib: &Library) -> String {
    let mut t =
        format!("{:<16} {:<10} {:>10} {:>9} {:>9} {:>8}\n", "name", "formula", "MW g/mol", "Tb K", "Tc K", "Pc bar");
    for c in &lib.components {
        let opt = |v: Option<f64>, s: f64| v.map_or("-".to_string(), |v| format!("{:.2}", v / s));
        t.push_str(&format!(
            "{:<16} {:<10} {:>10.3} {:>9.2} {:>9} {:>8}\n",
            c.name,
            c.formula,
            c.mw * 1e3,
            c.tb,
            opt(c.tc, 1.0),
            opt(c.pc, 1e5)
        ));
    }
    t.push_str(&format!("\n{} components; binary pairs:\n", lib.components.len()));
    for p in &lib.binary_pairs {
        t.push_str(&format!("  {:<7} {}–{}  ({})\n", p.model, p.i, p.j, p.source));
    }
    t
}
