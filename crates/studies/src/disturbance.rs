//! Disturbances of the studies — `--disturbances` of `compare` and `screen`, `--disturbance` of
//! `size` — read by one parser and judged by one rule.
//!
//! Written `PATH` (a +10 % step), `PATH=+x%`, `PATH=-x%`, `PATH=±x%` (a fraction of the input's
//! steady value), or an amount with its unit: `PATH=+5 K`, `PATH=-10 kmol/h`, `PATH=±2 K` (a
//! difference: `+5 degC` is 5 K; a bare number is in SI units of the input, as everywhere). The
//! sign is the direction of the step a closed-loop run takes; `±` asks for both, one run each.
//! Steady-state sweeps always go to both sides of the base case by the step's size, so there
//! `+x%`, `-x%` and `±x%` ask for the same sweep.
//!
//! A step is judged against the plant ([`Disturbance::check`]) before anything is run: its input
//! exists and no controller drives it, an amount has the input's dimension, a fraction is of a
//! nonzero value, and the value each step reaches is inside the input's physical range by the
//! rule that judges the file's values, `--set` and scenario events
//! ([`plantwide_flowsheet::overrides::check_input_value`]; a composition's sum by
//! [`plantwide_flowsheet::overrides::check_compositions`]).

use plantwide_flowsheet::Plant;
use plantwide_model::limits::number;
use plantwide_units::{Dimension, parse_difference};

/// How far a disturbance moves its input (a magnitude: the direction is apart).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepSize {
    /// A fraction of the input's steady value (0.1 for 10 %).
    Fraction(f64),
    /// An amount in SI units; `dim` is the dimension its unit has, `None` for a bare number (taken
    /// as SI in the input's own dimension).
    Amount {
        /// The amount (SI).
        si: f64,
        /// The dimension of the unit written, if any.
        dim: Option<Dimension>,
    },
}

/// Which way a disturbance steps its input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Up (`+`, or no sign).
    Up,
    /// Down (`-`).
    Down,
    /// Both (`±`): one closed-loop run each way.
    Both,
}

/// A disturbance: input `path` stepped by `size` in `direction`.
#[derive(Debug, Clone, PartialEq)]
pub struct Disturbance {
    /// Input path (or alias).
    pub path: String,
    /// The step's size.
    pub size: StepSize,
    /// Its direction.
    pub direction: Direction,
    /// The size as shown in labels: `10 %`, `5 K`.
    pub shown: String,
}

/// A disturbance that cannot be read or that its plant refuses.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DisturbanceError {
    /// The text is not a disturbance.
    #[error(
        "{text}: {why}; expected PATH (+10 %), PATH=±x% or PATH=±AMOUNT with a unit (e.g. feed.F=+10%, feed.F=-10%, \
         feed.F=±10%, feed.T=+5 K, feed.F=-10 kmol/h)"
    )]
    Syntax {
        /// The disturbance as written.
        text: String,
        /// What is wrong.
        why: String,
    },
    /// No input has the path.
    #[error("{text}: no input `{path}` in {file}{hint}")]
    NoInput {
        /// The disturbance (`path +10 %`).
        text: String,
        /// Its path.
        path: String,
        /// The flowsheet file.
        file: String,
        /// A suggestion, or empty.
        hint: String,
    },
    /// A controller drives the input: a step of it would be overwritten.
    #[error(
        "{text}: `{path}` is driven by `{op}` in {file}; disturb an input no controller drives (a feed's flow, \
         composition or temperature), or that controller's setpoint"
    )]
    Driven {
        /// The disturbance (`path +10 %`).
        text: String,
        /// Its path.
        path: String,
        /// The controller output driving it.
        op: String,
        /// The flowsheet file.
        file: String,
    },
    /// The amount's unit is not the input's.
    #[error("{text}: {why}")]
    Unit {
        /// The disturbance (`path +10 %`).
        text: String,
        /// What the input and the step are, and the unit to give (`` `feed.F` is a molar flow
        /// (mol/s) and the step a temperature; give the step in a unit of mol/s ``).
        why: String,
    },
    /// A fraction of an input whose value is zero.
    #[error("{text}: `{path}` is 0 in {file}, so a fraction of it is no step; give the step as an amount with a unit")]
    ZeroBase {
        /// The disturbance (`path +10 %`).
        text: String,
        /// Its path.
        path: String,
        /// The flowsheet file.
        file: String,
    },
    /// A step that takes its input outside its physical range.
    #[error("{text}: the step takes {values} in {file}: {why}; give a smaller step")]
    Range {
        /// The disturbance (`path +10 %`).
        text: String,
        /// The flowsheet file.
        file: String,
        /// The input and its values before and after the step (`` `z[a]` from 0.45 to 1.035 ``,
        /// SI with the unit).
        values: String,
        /// The range rule's verdict (the value and the range).
        why: String,
    },
}

impl std::str::FromStr for Disturbance {
    type Err = DisturbanceError;

    /// `PATH`, `PATH=±x%` or `PATH=±AMOUNT UNIT` (see the module's documentation).
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let syntax = |why: &str| DisturbanceError::Syntax { text: text.trim().to_string(), why: why.to_string() };
        let Some((path, step)) = text.split_once('=') else {
            let path = text.trim();
            if path.is_empty() {
                return Err(syntax("no input path"));
            }
            let size = StepSize::Fraction(0.1);
            return Ok(Disturbance { path: path.into(), size, direction: Direction::Up, shown: "10 %".into() });
        };
        let (path, step) = (path.trim(), step.trim());
        if path.is_empty() {
            return Err(syntax("no input path before `=`"));
        }
        let (direction, magnitude) = direction(step);
        let magnitude = magnitude.trim();
        if magnitude.starts_with(['+', '-', '−', '±']) {
            return Err(syntax("one sign only"));
        }
        let (size, shown) = match magnitude.strip_suffix('%') {
            Some(pct) => {
                let pct: f64 = pct.trim().parse().map_err(|_| syntax(&format!("`{}` is not a number", pct.trim())))?;
                (StepSize::Fraction(pct / 100.0), format!("{pct} %"))
            }
            None => {
                let q = parse_difference(magnitude).map_err(|e| syntax(&e.to_string()))?;
                let bare = magnitude.parse::<f64>().is_ok();
                (StepSize::Amount { si: q.value_si, dim: (!bare).then_some(q.dim) }, magnitude.to_string())
            }
        };
        let value = match size {
            StepSize::Fraction(f) => f,
            StepSize::Amount { si, .. } => si,
        };
        if !(value.is_finite() && value > 0.0) {
            return Err(syntax("the step must be a nonzero finite size after its sign"));
        }
        Ok(Disturbance { path: path.into(), size, direction, shown })
    }
}

/// The direction a step's sign gives and the rest of the text.
fn direction(step: &str) -> (Direction, &str) {
    for (sign, d) in [("±", Direction::Both), ("+/-", Direction::Both), ("+-", Direction::Both)] {
        if let Some(rest) = step.strip_prefix(sign) {
            return (d, rest);
        }
    }
    match step.strip_prefix('+') {
        Some(rest) => (Direction::Up, rest),
        None => match step.strip_prefix('-').or_else(|| step.strip_prefix('−')) {
            Some(rest) => (Direction::Down, rest),
            None => (Direction::Up, step),
        },
    }
}

impl Disturbance {
    /// The steps a closed-loop test runs: this one, or for `±` one up and one down.
    pub fn steps(&self) -> Vec<Disturbance> {
        let one = |direction| Disturbance { direction, ..self.clone() };
        match self.direction {
            Direction::Both => vec![one(Direction::Up), one(Direction::Down)],
            d => vec![one(d)],
        }
    }

    /// The signed change of the input from its steady value `u0` (SI) by a one-way step (`±` is
    /// taken up; [`Disturbance::steps`] splits it).
    pub fn change(&self, u0: f64) -> f64 {
        let sign = if self.direction == Direction::Down { -1.0 } else { 1.0 };
        sign * self.magnitude(u0)
    }

    /// The size of the step from `u0`, signed as `u0` for a fraction.
    fn magnitude(&self, u0: f64) -> f64 {
        match self.size {
            StepSize::Fraction(f) => f * u0,
            StepSize::Amount { si, .. } => si,
        }
    }

    /// `path +10 %`, `path -5 K`, `path ±10 %`.
    pub fn label(&self) -> String {
        let sign = match self.direction {
            Direction::Up => "+",
            Direction::Down => "-",
            Direction::Both => "±",
        };
        format!("{} {sign}{}", self.path, self.shown)
    }

    /// The label of its steady-state sweep (both sides): `path ±10 %`.
    pub fn sweep_label(&self) -> String {
        format!("{} ±{}", self.path, self.shown)
    }

    /// The sweep `PATH=LOW:HIGH` to both sides of the base value `u0` by the step's size (as
    /// `plantwide_analysis::sensitivity::Disturbance::parse` reads it).
    pub fn sweep_range(&self, u0: f64) -> String {
        match self.size {
            StepSize::Fraction(f) => format!("{}=-{}%:+{}%", self.path, 100.0 * f, 100.0 * f),
            StepSize::Amount { si, .. } => format!("{}={:e}:{:e}", self.path, u0 - si, u0 + si),
        }
    }

    /// True when `other` asks for the same sweep (same input, same size).
    pub fn same_sweep(&self, other: &Disturbance) -> bool {
        self.path == other.path && self.size == other.size
    }

    /// Judge the steps against `plant` at its input values: the input exists and no controller
    /// drives it, an amount has its dimension, a fraction is of a nonzero value, and every step's
    /// end is a value the input may take (its physical range; a feed's mole fractions summing to
    /// at most 1).
    ///
    /// # Errors
    /// [`DisturbanceError`] naming the disturbance as written, the input, the file and, for a
    /// step out of range, the values and the range.
    pub fn check(&self, plant: &Plant) -> Result<(), DisturbanceError> {
        let text = self.label();
        let file = plant.file().to_string();
        let Some(i) = plantwide_flowsheet::overrides::resolve_input(plant, &self.path) else {
            let names = plant.inputs().iter().map(|v| v.path.as_str());
            let hint = plantwide_flowsheet::error::did_you_mean(&self.path, names);
            return Err(DisturbanceError::NoInput { text, path: self.path.clone(), file, hint });
        };
        let info = &plant.inputs()[i];
        if let Some(op) = info.driven_by {
            return Err(DisturbanceError::Driven {
                text,
                path: self.path.clone(),
                op: plant.vars()[op].path.clone(),
                file,
            });
        }
        match self.size {
            StepSize::Amount { dim: Some(d), .. } if d != info.dim => {
                let why = format!(
                    "`{}` is {} ({}) and the step {}; give the step in a unit of {}",
                    self.path,
                    info.dim.describe(),
                    info.dim,
                    d.describe(),
                    info.dim
                );
                return Err(DisturbanceError::Unit { text, why });
            }
            StepSize::Fraction(f) if info.dim == Dimension::TEMPERATURE => {
                let (k, c) = (f * info.value, f * (info.value - 273.15));
                let why = format!(
                    "`{}` is a temperature, and a percentage of one depends on its scale: {} % of {} K is {} K, of \
                     {} degC {} K; give the step as a temperature difference, e.g. {}=+5 K",
                    self.path,
                    number(100.0 * f),
                    number(info.value),
                    number(k),
                    number(info.value - 273.15),
                    number(c),
                    self.path
                );
                return Err(DisturbanceError::Unit { text, why });
            }
            StepSize::Fraction(_) if info.value == 0.0 => {
                return Err(DisturbanceError::ZeroBase { text, path: self.path.clone(), file });
            }
            _ => {}
        }
        let shown = |v: f64| match info.dim.is_dimensionless() {
            true => number(v),
            false => format!("{} {}", number(v), info.dim),
        };
        for step in self.steps() {
            let to = info.value + step.change(info.value);
            let range = |why: String| DisturbanceError::Range {
                text: text.clone(),
                file: file.clone(),
                values: format!("`{}` from {} to {}", self.path, shown(info.value), shown(to)),
                why,
            };
            plantwide_flowsheet::overrides::check_input_value(plant, i, to).map_err(|e| range(e.to_string()))?;
            let mut u = plant.input_values();
            u[i] = to;
            plantwide_flowsheet::overrides::check_compositions(plant, &u).map_err(|e| range(e.to_string()))?;
        }
        Ok(())
    }
}

/// The disturbances of the steady-state sweeps (to both sides of the base case), each input and
/// size once, in the order given.
pub fn sweeps(disturbances: &[Disturbance]) -> Vec<&Disturbance> {
    let mut out: Vec<&Disturbance> = Vec::new();
    for d in disturbances {
        if !out.iter().any(|o| o.same_sweep(d)) {
            out.push(d);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Disturbance {
        text.parse().unwrap_or_else(|e| panic!("{text}: {e}"))
    }

    #[test]
    fn every_written_form_reads_as_its_step() {
        let cases: [(&str, Direction, StepSize, &str); 10] = [
            ("feed.F", Direction::Up, StepSize::Fraction(0.1), "feed.F +10 %"),
            ("feed.F=+10%", Direction::Up, StepSize::Fraction(0.1), "feed.F +10 %"),
            ("feed.F=10%", Direction::Up, StepSize::Fraction(0.1), "feed.F +10 %"),
            ("feed.F=-5%", Direction::Down, StepSize::Fraction(0.05), "feed.F -5 %"),
            ("feed.F=−5%", Direction::Down, StepSize::Fraction(0.05), "feed.F -5 %"),
            ("feed.F=±2.5%", Direction::Both, StepSize::Fraction(0.025), "feed.F ±2.5 %"),
            ("feed.F=+-2.5 %", Direction::Both, StepSize::Fraction(0.025), "feed.F ±2.5 %"),
            (
                "feed.T=+5K",
                Direction::Up,
                StepSize::Amount { si: 5.0, dim: Some(Dimension::TEMPERATURE) },
                "feed.T +5K",
            ),
            (
                "feed.T = -5 degC",
                Direction::Down,
                StepSize::Amount { si: 5.0, dim: Some(Dimension::TEMPERATURE) },
                "feed.T -5 degC",
            ),
            ("feed.F=±3", Direction::Both, StepSize::Amount { si: 3.0, dim: None }, "feed.F ±3"),
        ];
        for (text, direction, size, label) in cases {
            let d = parse(text);
            assert_eq!((d.direction, d.size, d.label().as_str()), (direction, size, label), "{text}");
        }
        // kmol/h to mol/s: 36 kmol/h = 10 mol/s.
        let d = parse("feed.F=-36 kmol/h");
        assert_eq!(d.direction, Direction::Down);
        let StepSize::Amount { si, dim } = d.size else { panic!("{d:?}") };
        assert!((si - 10.0).abs() < 1e-12 && dim == Some(Dimension::MOLAR_FLOW), "{si}");
    }

    #[test]
    fn the_sign_gives_the_change_and_both_ways_split_into_two_runs() {
        let d = parse("feed.F=±10%");
        let changes: Vec<f64> = d.steps().iter().map(|s| s.change(40.0)).collect();
        assert_eq!(changes, [4.0, -4.0]);
        assert_eq!(parse("feed.F=-10%").change(40.0), -4.0);
        assert_eq!(parse("feed.T=+5 K").change(300.0), 5.0);
        assert_eq!(parse("feed.T=-5 K").steps().len(), 1);
        // One sweep whatever the sign; to both sides by the size.
        assert!(parse("feed.F=-10%").same_sweep(&parse("feed.F=±10%")));
        assert_eq!(parse("feed.F=-10%").sweep_label(), "feed.F ±10 %");
        assert_eq!(parse("feed.T=+5 K").sweep_range(300.0), "feed.T=2.95e2:3.05e2");
    }

    #[test]
    fn malformed_steps_are_refused_with_the_forms_accepted() {
        for text in
            ["feed.F=ten%", "feed.F=+0%", "feed.F=+", "=+10%", "feed.F=++10%", "feed.F=+5 furlongs", "feed.F=inf%"]
        {
            let e = text.parse::<Disturbance>().unwrap_err().to_string();
            assert!(e.starts_with(text.trim()) && e.contains("expected PATH (+10 %), PATH=±x%"), "{text}: {e}");
        }
    }
}
