//! `plantwide components`: the built-in library.

use plantwide::thermo::Library;

use super::CliError;

pub fn run(json: bool) -> Result<(), CliError> {
    let lib = Library::builtin().map_err(|e| CliError::user(e.to_string()))?;
    if json {
        let text = serde_json::to_string_pretty(&lib).map_err(|e| CliError::user(e.to_string()))?;
        outln!("{text}");
        return Ok(());
    }
    outln!("{:<16} {:<10} {:>10} {:>9} {:>9} {:>8}", "name", "formula", "MW g/mol", "Tb K", "Tc K", "Pc bar");
    for c in &lib.components {
        let opt = |v: Option<f64>, s: f64| v.map_or("-".to_string(), |v| format!("{:.2}", v / s));
        outln!(
            "{:<16} {:<10} {:>10.3} {:>9.2} {:>9} {:>8}",
            c.name,
            c.formula,
            c.mw * 1e3,
            c.tb,
            opt(c.tc, 1.0),
            opt(c.pc, 1e5)
        );
    }
    outln!("\n{} components; binary pairs:", lib.components.len());
    for p in &lib.binary_pairs {
        outln!("  {:<7} {}–{}  ({})", p.model, p.i, p.j, p.source);
    }
    Ok(())
}
