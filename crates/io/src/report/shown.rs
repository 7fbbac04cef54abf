//! Display units of the paths a study's text and figures show (`compare`, `screen`).

use plantwide_flowsheet::Plant;
use plantwide_units::{Dimension, Display, UnitSystem};

use crate::IoError;

/// Display units of the paths a study shows (outputs, loops' CVs and MVs, watched variables): the
/// unit a `PATH@unit` entry names, else the `--units` system's unit of the path's dimension.
pub struct Shown {
    by_path: std::collections::HashMap<String, Display>,
}

impl Shown {
    /// The display of each `(path, unit asked for)`, looked up in the first plant that has it
    /// (paths that name nothing are shown in SI).
    pub fn new(
        plants: &[Plant],
        paths: impl IntoIterator<Item = (String, Option<String>)>,
        system: UnitSystem,
    ) -> Result<Shown, IoError> {
        let dim = |path: &str| {
            plants.iter().find_map(|p| {
                p.var(path).map(|v| p.vars()[v].spec.dim).or_else(|| p.input(path).map(|i| p.inputs()[i].dim))
            })
        };
        let system_unit =
            |d: Dimension| if d == Dimension::DIMENSIONLESS { "1".to_string() } else { system.unit_for(d) };
        let mut by_path = std::collections::HashMap::new();
        for (path, unit) in paths {
            if by_path.contains_key(&path) {
                continue;
            }
            let Some(d) = dim(&path) else { continue };
            let unit = unit.unwrap_or_else(|| system_unit(d));
            let bad = |why: String| IoError::DisplayUnit { path: path.clone(), unit: unit.clone(), why };
            let shown = Display::new(&unit).map_err(|e| bad(e.to_string()))?;
            if plantwide_units::unit_dimension(&unit).ok() != Some(d) {
                return Err(bad(format!("`{unit}` is not a unit of {}", d.describe())));
            }
            by_path.insert(path, shown);
        }
        Ok(Shown { by_path })
    }

    /// The path with its unit, `path [unit]`.
    pub fn label(&self, path: &str) -> String {
        format!("{path} [{}]", self.unit(path))
    }
    /// A value of `path` (SI) in its display unit.
    pub fn value(&self, path: &str, si: f64) -> f64 {
        self.by_path.get(path).map_or(si, |d| d.value(si))
    }
    /// A difference of `path` (SI) in its display unit (offsets dropped).
    pub fn difference(&self, path: &str, si: f64) -> f64 {
        self.by_path.get(path).map_or(si, |d| d.difference(si))
    }
    /// The display unit of `path` (`-` for a dimensionless one, `SI` where none is known).
    pub fn unit(&self, path: &str) -> String {
        match self.by_path.get(path).map(Display::unit) {
            Some("1") => "-".to_string(),
            Some(u) => u.to_string(),
            None => "SI".to_string(),
        }
    }
}
