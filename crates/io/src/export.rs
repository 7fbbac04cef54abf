//! Export of a linearized plant as JSON for MATLAB and python-control users.
//!
//! The model is `dx/dt = A x + B u`, `y = C x + D u` in deviations from the steady state; states
//! in SI units, inputs and outputs in their display units, time in the chosen unit (`A` and `B`
//! are per that unit). Matrices are nested row arrays:
//!
//! ```python
//! import json, numpy as np, control
//! m = json.load(open("model.json"))
//! n = m["names"]   # python-control-safe signal names; m["labels"] maps each back to its path
//! sys = control.ss(*(np.array(m[k]) for k in "ABCD"), states=n["states"], inputs=n["inputs"], outputs=n["outputs"])
//! # control.dcgain(sys) == m["steady_state_gain"]
//! ```
//! ```matlab
//! m = jsondecode(fileread('model.json'));  sys = ss(m.A, m.B, m.C, m.D);   % dcgain(sys)
//! ```

use faer::Mat;
use serde::Serialize;

use plantwide_analysis::measures::rows;
use plantwide_analysis::plant_model::PlantModel;
use plantwide_analysis::select::Signal;

/// A plant's linear model with its labels, ready to serialize.
#[derive(Debug, Clone)]
pub struct ModelExport<'a> {
    /// Flowsheet name.
    pub name: &'a str,
    /// The model, its steady values, eigenvalues and frequency response (SI; `G(jω)` in display
    /// units).
    pub model: &'a PlantModel,
    /// Inputs with display units.
    pub inputs: &'a [Signal],
    /// Outputs with display units.
    pub outputs: &'a [Signal],
    /// Time unit name and its length in seconds.
    pub time_unit: (&'a str, f64),
}

/// `A, B, C, D` and the steady-state gain as row arrays: `A` and `B` per time unit, inputs and
/// outputs in their display units, states in SI.
#[derive(Debug, Clone, PartialEq)]
pub struct Matrices {
    /// State matrix.
    pub a: Vec<Vec<f64>>,
    /// Input matrix.
    pub b: Vec<Vec<f64>>,
    /// Output matrix.
    pub c: Vec<Vec<f64>>,
    /// Feedthrough matrix.
    pub d: Vec<Vec<f64>>,
    /// `D − C A⁻¹ B` (`None` when `A` is singular: an integrating mode).
    pub steady_state_gain: Option<Vec<Vec<f64>>>,
}

/// python-control-safe names of the states, inputs and outputs (each list free of repeats) and
/// the path each stands for: python-control reads `.` in a signal name as `system.signal` and
/// `[…]` as an index range, which paths such as `distillate.x[light]` are full of.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SignalNames {
    /// One per state (row of `A`).
    pub states: Vec<String>,
    /// One per input (column of `B`).
    pub inputs: Vec<String>,
    /// One per output (row of `C`).
    pub outputs: Vec<String>,
}

/// `paths` as identifiers (`[A-Za-z_][A-Za-z0-9_]*`): every run of other characters becomes one
/// `_` (`distillate.x[light]` → `distillate_x_light`, a trailing one dropped), a leading digit is
/// prefixed by `s_`, and a name met before gets `_2`, `_3`, … until it is new.
pub fn safe_names(paths: &[String]) -> Vec<String> {
    let mut seen = std::collections::HashSet::new();
    paths
        .iter()
        .map(|p| {
            let mut base = String::with_capacity(p.len());
            for c in p.chars() {
                if c.is_ascii_alphanumeric() {
                    base.push(c);
                } else if !base.ends_with('_') {
                    base.push('_');
                }
            }
            let trimmed = base.trim_end_matches('_');
            let base = match trimmed.chars().next() {
                Some(c) if c.is_ascii_digit() => format!("s_{trimmed}"),
                Some(_) => trimmed.to_string(),
                None => "s".to_string(),
            };
            let mut name = base.clone();
            let mut k = 2;
            while !seen.insert(name.clone()) {
                name = format!("{base}_{k}");
                k += 1;
            }
            name
        })
        .collect()
}

#[derive(Serialize)]
struct Labelled<'a> {
    path: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    unit: Option<&'a str>,
    value: f64,
}

fn signals<'a>(list: &'a [Signal], values: &[f64]) -> Vec<Labelled<'a>> {
    list.iter()
        .zip(values)
        .map(|(s, v)| Labelled { path: &s.path, unit: Some(&s.unit), value: s.display_value(*v) })
        .collect()
}

#[derive(Serialize)]
struct Complex {
    re: f64,
    im: f64,
}

#[derive(Serialize)]
struct Response {
    omega: f64,
    re: Vec<Vec<f64>>,
    im: Vec<Vec<f64>>,
}

#[derive(Serialize)]
#[allow(non_snake_case)]
struct Document<'a> {
    format: &'a str,
    format_version: u32,
    name: &'a str,
    description: String,
    time_unit: &'a str,
    states: Vec<Labelled<'a>>,
    inputs: Vec<Labelled<'a>>,
    outputs: Vec<Labelled<'a>>,
    A: Vec<Vec<f64>>,
    B: Vec<Vec<f64>>,
    C: Vec<Vec<f64>>,
    D: Vec<Vec<f64>>,
    steady_state_gain: Option<Vec<Vec<f64>>>,
    eigenvalues: Vec<Complex>,
    time_constants: Vec<f64>,
    frequency_response: Vec<Response>,
    names: SignalNames,
    labels: Labels,
}

/// Each safe name's path, per list.
#[derive(Serialize)]
struct Labels {
    states: std::collections::BTreeMap<String, String>,
    inputs: std::collections::BTreeMap<String, String>,
    outputs: std::collections::BTreeMap<String, String>,
}

impl ModelExport<'_> {
    /// The python-control-safe names of the states, inputs and outputs.
    pub fn names(&self) -> SignalNames {
        let paths = |s: &[Signal]| s.iter().map(|s| s.path.clone()).collect::<Vec<_>>();
        SignalNames {
            states: safe_names(&self.model.states),
            inputs: safe_names(&paths(self.inputs)),
            outputs: safe_names(&paths(self.outputs)),
        }
    }

    /// The matrices in the export's units.
    pub fn matrices(&self) -> Matrices {
        let ts = self.time_unit.1;
        let m = &self.model.model;
        let (fi, fo) = (|j: usize| self.inputs[j].factor, |i: usize| self.outputs[i].factor);
        // Per time unit: A·ts, B·ts; inputs and outputs in display units.
        let scaled = |x: &Mat<f64>, f: &dyn Fn(usize, usize) -> f64| {
            rows(Mat::from_fn(x.nrows(), x.ncols(), |i, j| x[(i, j)] * f(i, j)).as_ref())
        };
        Matrices {
            a: scaled(&m.a, &|_, _| ts),
            b: scaled(&m.b, &|_, j| ts * fi(j)),
            c: scaled(&m.c, &|i, _| 1.0 / fo(i)),
            d: scaled(&m.d, &|i, j| fi(j) / fo(i)),
            steady_state_gain: m.steady_gain().ok().map(|g| scaled(&g, &|i, j| fi(j) / fo(i))),
        }
    }

    /// The JSON document, pretty-printed with every matrix row on one line.
    pub fn to_json_string(&self) -> String {
        let (tu, ts) = self.time_unit;
        let pm = self.model;
        let Matrices { a, b, c, d, steady_state_gain } = self.matrices();
        let names = self.names();
        let map = |n: &[String], p: &mut dyn Iterator<Item = &String>| n.iter().cloned().zip(p.cloned()).collect();
        let labels = Labels {
            states: map(&names.states, &mut pm.states.iter()),
            inputs: map(&names.inputs, &mut self.inputs.iter().map(|s| &s.path)),
            outputs: map(&names.outputs, &mut self.outputs.iter().map(|s| &s.path)),
        };
        let doc = Document {
            format: "plantwide-state-space",
            format_version: 1,
            name: self.name,
            description: format!(
                "dx/dt = A x + B u, y = C x + D u in deviations from the steady state; states in SI units, inputs and outputs in the units listed, time in {tu}"
            ),
            time_unit: tu,
            states: pm
                .states
                .iter()
                .zip(&pm.state_values)
                .map(|(p, v)| Labelled { path: p, unit: None, value: *v })
                .collect(),
            inputs: signals(self.inputs, &pm.input_values),
            outputs: signals(self.outputs, &pm.output_values),
            A: a,
            B: b,
            C: c,
            D: d,
            steady_state_gain,
            eigenvalues: pm.eigenvalues.iter().map(|l| Complex { re: l.re * ts, im: l.im * ts }).collect(),
            time_constants: pm
                .eigenvalues
                .iter()
                .filter(|l| l.re < 0.0 && l.im >= 0.0)
                .map(|l| -1.0 / (l.re * ts))
                .collect(),
            frequency_response: pm
                .responses
                .iter()
                .map(|(w, g)| Response {
                    omega: w * ts,
                    re: (0..g.nrows()).map(|i| (0..g.ncols()).map(|j| g[(i, j)].re).collect()).collect(),
                    im: (0..g.nrows()).map(|i| (0..g.ncols()).map(|j| g[(i, j)].im).collect()).collect(),
                })
                .collect(),
            names,
            labels,
        };
        // Serializing plain numbers and strings cannot fail.
        let text = serde_json::to_string_pretty(&doc).unwrap_or_default();
        collapse_number_arrays(&text)
    }
}

/// Put every array that holds only numbers on one line.
pub fn collapse_number_arrays(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(open) = rest.find('[') {
        out.push_str(&rest[..open]);
        let tail = &rest[open..];
        let close = tail.find(']');
        let inner = close.map(|c| &tail[1..c]);
        match (close, inner) {
            (Some(c), Some(inner)) if !inner.contains(['[', '{', '"']) => {
                let items: Vec<&str> = inner.split(',').map(str::trim).filter(|s| !s.is_empty()).collect();
                out.push('[');
                out.push_str(&items.join(", "));
                out.push(']');
                rest = &tail[c + 1..];
            }
            _ => {
                out.push('[');
                rest = &tail[1..];
            }
        }
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn safe_names_are_identifiers_without_repeats() {
        let paths: Vec<String> =
            ["distillate.x[light]", "distillate_x_light", "column.T[21]", "1st.F", "..."].map(String::from).to_vec();
        let names = safe_names(&paths);
        assert_eq!(names, ["distillate_x_light", "distillate_x_light_2", "column_T_21", "s_1st_F", "s"]);
        let ident = |n: &String| {
            n.chars().next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
                && n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        };
        assert!(names.iter().all(ident), "{names:?}");
    }

    #[test]
    fn number_arrays_go_on_one_line() {
        let v = serde_json::json!({"A": [[1.0, -2.5], [3.0, 4.0]], "s": ["x", "y"], "e": []});
        let text = collapse_number_arrays(&serde_json::to_string_pretty(&v).unwrap());
        assert!(text.contains("[1.0, -2.5]") && text.contains("[3.0, 4.0]") && text.contains("\"e\": []"), "{text}");
        let back: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(back, v);
    }
}
