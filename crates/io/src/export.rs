//! Export of a linearized plant as JSON for MATLAB and python-control users.
//!
//! The model is `dx/dt = A x + B u`, `y = C x + D u` in deviations from the steady state; states
//! in SI units, inputs and outputs in their display units, time in the chosen unit (`A` and `B`
//! are per that unit). Matrices are nested row arrays:
//!
//! ```python
//! import json, numpy as np, control
//! m = json.load(open("model.json"))
//! sys = control.ss(*(np.array(m[k]) for k in "ABCD"))   # control.dcgain(sys) == m["steady_state_gain"]
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
}

impl ModelExport<'_> {
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
    fn number_arrays_go_on_one_line() {
        let v = serde_json::json!({"A": [[1.0, -2.5], [3.0, 4.0]], "s": ["x", "y"], "e": []});
        let text = collapse_number_arrays(&serde_json::to_string_pretty(&v).unwrap());
        assert!(text.contains("[1.0, -2.5]") && text.contains("[3.0, 4.0]") && text.contains("\"e\": []"), "{text}");
        let back: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(back, v);
    }
}
