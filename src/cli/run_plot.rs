//! The earlier runs `plantwide run --compare OTHER.csv` overlays on its trend plot, read from
//! their CSV files; the plot itself is `plantwide_io::report::run_plot`'s.

use std::path::Path;

use plantwide::io::report::run_plot::OtherRun;
use plantwide::units::convert_to_si;

use super::CliError;

/// An earlier run's CSV: its time column converted to seconds, and each column by header.
pub fn read_other(path: &Path) -> Result<OtherRun, CliError> {
    let bad = |why: String| CliError::user(format!("--compare {}: {why}", path.display()));
    // The library's reader: its size limit holds for a CSV as for a flowsheet.
    let text = plantwide::flowsheet::read_text(path).map_err(|e| CliError::user(format!("--compare {e}")))?;
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .ok_or_else(|| bad("empty file".into()))?
        .split(',')
        .map(|h| h.trim_matches('"').to_string())
        .collect();
    let time_unit = header[0].strip_prefix("time [").and_then(|h| h.strip_suffix(']'));
    let time_unit = time_unit.ok_or_else(|| {
        bad(format!("the first column is `{}`, not `time [unit]`: not a `plantwide run` CSV", header[0]))
    })?;
    let mut rows: Vec<Vec<f64>> = Vec::new();
    for (i, l) in lines.enumerate() {
        let row: Result<Vec<f64>, _> = l.split(',').map(str::parse).collect();
        let row = row.map_err(|_| bad(format!("line {} is not numbers", i + 2)))?;
        if row.len() != header.len() {
            return Err(bad(format!("line {} has {} fields for {} columns", i + 2, row.len(), header.len())));
        }
        rows.push(row);
    }
    let times = rows
        .iter()
        .map(|r| convert_to_si(r[0], time_unit))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| bad(e.to_string()))?;
    let columns = (1..header.len()).map(|k| (header[k].clone(), rows.iter().map(|r| r[k]).collect())).collect();
    let name = path.file_stem().map_or_else(|| path.display().to_string(), |s| s.to_string_lossy().to_string());
    Ok(OtherRun { name, times, columns })
}
