//! `plantwide components`: the built-in library.

use plantwide::io::report;
use plantwide::thermo::Library;

use super::CliError;

pub fn run(json: bool) -> Result<(), CliError> {
    let lib = Library::builtin().map_err(|e| CliError::user(e.to_string()))?;
    if json {
        let text = serde_json::to_string_pretty(&lib).map_err(|e| CliError::user(e.to_string()))?;
        outln!("{text}");
        return Ok(());
    }
    out!("{}", report::components::text(&lib));
    Ok(())
}
