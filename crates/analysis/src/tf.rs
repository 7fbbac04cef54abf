//! Transfer-function matrix models: the form plant tests and identification produce, analysed
//! like a flowsheet's linearization.
//!
//! Each element from input (or disturbance) `j` to output `i` is
//! `g_ij(s) = K · Π_k (τ_lead,k s + 1) / Π_k (τ_lag,k s + 1) · e^(−θ s)`, with the gain `K` in
//! output units per input unit (the units declared for the signals), lags `τ_lag > 0`, leads
//! `τ_lead ≠ 0` (negative: a right-half-plane zero, inverse response) and dead time `θ ≥ 0`, all
//! times in seconds. A missing element is zero. The file format (`*.tf.json`) is read by
//! `plantwide_io::tf`.

use faer::{Mat, c64};

use crate::error::{AnalysisError, request};

/// An input, output or disturbance of a transfer-function model.
#[derive(Debug, Clone, PartialEq)]
pub struct TfSignal {
    /// Name used by the elements.
    pub name: String,
    /// Unit of the signal (a label: gains are in output units per input unit).
    pub unit: String,
    /// What it is.
    pub description: String,
}

/// One element `K Π(τ_lead s + 1) / Π(τ_lag s + 1) e^(−θ s)`; times in seconds.
#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    /// Steady-state gain `K`.
    pub gain: f64,
    /// Lag time constants \[s\].
    pub lags: Vec<f64>,
    /// Lead time constants \[s\].
    pub leads: Vec<f64>,
    /// Dead time \[s\].
    pub dead_time: f64,
}

/// `Π_k (τ_k s + 1)` as coefficients in descending powers of `s`, times in `per` seconds.
fn polynomial(taus: &[f64], per: f64) -> Vec<f64> {
    let mut c = vec![1.0];
    for t in taus {
        // (τ s + 1) · c(s)
        let mut next = vec![0.0; c.len() + 1];
        for (k, a) in c.iter().enumerate() {
            next[k] += a * t / per;
            next[k + 1] += a;
        }
        c = next;
    }
    c
}

impl Element {
    /// Numerator `K Π(τ_lead s + 1)`, coefficients in descending powers of `s` with `s` in
    /// rad per `per` seconds (`per = 60` for minutes): python-control's and MATLAB's `tf(num, den)`.
    pub fn numerator(&self, per: f64) -> Vec<f64> {
        polynomial(&self.leads, per).into_iter().map(|c| c * self.gain).collect()
    }
    /// Denominator `Π(τ_lag s + 1)`, as [`Element::numerator`].
    pub fn denominator(&self, per: f64) -> Vec<f64> {
        polynomial(&self.lags, per)
    }
    /// The poles `−1/τ_lag` [1/s].
    pub fn poles(&self) -> Vec<f64> {
        self.lags.iter().map(|t| -1.0 / t).collect()
    }

    /// `g(jω)` at `ω` [rad/s], from its magnitude and phase in closed form
    /// ([`Element::log_magnitude`], [`Element::phase`]): the products `Π(1 + jτω)` of a
    /// high-order element overflow long before their ratio does (90 lags of 1 h at 0.03 rad/s),
    /// and a gain of 1e308 overflows any product it enters.
    pub fn response(&self, omega: f64) -> c64 {
        let sign = if self.gain < 0.0 { std::f64::consts::PI } else { 0.0 };
        let magnitude = (self.gain.abs().ln() + self.log_magnitude(omega)).exp();
        c64::from_polar(magnitude, self.phase(omega) + sign)
    }

    /// `ln |g(jω)/K|` at `ω` [rad/s]: `Σ ½ ln(1 + (τ_lead ω)²) − Σ ½ ln(1 + (τ_lag ω)²)`.
    pub fn log_magnitude(&self, omega: f64) -> f64 {
        let term = |t: &f64| 0.5 * (t * omega).mul_add(t * omega, 1.0).ln();
        self.leads.iter().map(term).sum::<f64>() - self.lags.iter().map(term).sum::<f64>()
    }

    /// The phase of `g(jω)/K` at `ω` [rad/s], continuous in `ω` (unwrapped, 0 at `ω = 0`):
    /// `Σ atan(τ_lead ω) − Σ atan(τ_lag ω) − θ ω` (a negative lead, a right-half-plane zero, turns
    /// the phase down). A negative gain adds π.
    pub fn phase(&self, omega: f64) -> f64 {
        let term = |t: &f64| (t * omega).atan();
        self.leads.iter().map(term).sum::<f64>() - self.lags.iter().map(term).sum::<f64>() - self.dead_time * omega
    }
}

/// A transfer-function matrix model.
#[derive(Debug, Clone)]
pub struct TfModel {
    /// Name.
    pub name: String,
    /// Description.
    pub description: String,
    /// Manipulated inputs (columns of `G`).
    pub inputs: Vec<TfSignal>,
    /// Outputs (rows).
    pub outputs: Vec<TfSignal>,
    /// Disturbances (columns of `G_d`).
    pub disturbances: Vec<TfSignal>,
    /// Elements, outputs × (inputs then disturbances); `None` is zero.
    elements: Vec<Vec<Option<Element>>>,
}

impl TfModel {
    /// A model from its signals and its elements, outputs × (inputs then disturbances) with
    /// `None` for a zero element; refused when the element matrix does not have that shape.
    pub fn new(
        name: String,
        description: String,
        inputs: Vec<TfSignal>,
        outputs: Vec<TfSignal>,
        disturbances: Vec<TfSignal>,
        elements: Vec<Vec<Option<Element>>>,
    ) -> Result<TfModel, AnalysisError> {
        let n_cols = inputs.len() + disturbances.len();
        if elements.len() != outputs.len() || elements.iter().any(|row| row.len() != n_cols) {
            return Err(request(format!(
                "transfer-function model `{name}`: the elements must form a {} × {n_cols} matrix (outputs × inputs and disturbances)",
                outputs.len()
            )));
        }
        Ok(TfModel { name, description, inputs, outputs, disturbances, elements })
    }

    /// The element from column `j` (inputs, then disturbances) to output `i`.
    pub fn element(&self, i: usize, j: usize) -> Option<&Element> {
        self.elements.get(i)?.get(j)?.as_ref()
    }

    fn matrix(&self, cols: std::ops::Range<usize>, omega: f64) -> Mat<c64> {
        let start = cols.start;
        Mat::from_fn(self.outputs.len(), cols.len(), |i, j| {
            self.element(i, start + j).map_or(c64::new(0.0, 0.0), |e| e.response(omega))
        })
    }

    /// Steady-state gain `G(0)` (outputs × inputs).
    pub fn gain(&self) -> Mat<f64> {
        let g = self.matrix(0..self.inputs.len(), 0.0);
        Mat::from_fn(g.nrows(), g.ncols(), |i, j| g[(i, j)].re)
    }

    /// Steady-state disturbance gain `G_d(0)` (outputs × disturbances).
    pub fn disturbance_gain(&self) -> Mat<f64> {
        let n = self.inputs.len();
        let g = self.matrix(n..n + self.disturbances.len(), 0.0);
        Mat::from_fn(g.nrows(), g.ncols(), |i, j| g[(i, j)].re)
    }

    /// Frequency response `G(jω)` (outputs × inputs) at `ω` [rad/s].
    pub fn response(&self, omega: f64) -> Mat<c64> {
        self.matrix(0..self.inputs.len(), omega)
    }

    /// The model restricted to the channels `inputs` → `outputs`, named as in the model and in
    /// the order given (an empty list keeps all); disturbances stay.
    ///
    /// # Errors
    /// A name the model does not have, with the names it has.
    pub fn select(&self, inputs: &[String], outputs: &[String]) -> Result<TfModel, AnalysisError> {
        let pick = |names: &[String], signals: &[TfSignal], what: &str| -> Result<Vec<usize>, AnalysisError> {
            if names.is_empty() {
                return Ok((0..signals.len()).collect());
            }
            names
                .iter()
                .map(|n| {
                    signals.iter().position(|s| s.name == *n).ok_or_else(|| {
                        let all: Vec<&str> = signals.iter().map(|s| s.name.as_str()).collect();
                        request(format!("model `{}` has no {what} `{n}`; its {what}s: {}", self.name, all.join(", ")))
                    })
                })
                .collect()
        };
        let (ii, oo) = (pick(inputs, &self.inputs, "input")?, pick(outputs, &self.outputs, "output")?);
        let n = self.inputs.len();
        let cols: Vec<usize> = ii.iter().copied().chain(n..n + self.disturbances.len()).collect();
        let elements = oo.iter().map(|&i| cols.iter().map(|&j| self.elements[i][j].clone()).collect()).collect();
        Ok(TfModel {
            name: self.name.clone(),
            description: self.description.clone(),
            inputs: ii.iter().map(|&j| self.inputs[j].clone()).collect(),
            outputs: oo.iter().map(|&i| self.outputs[i].clone()).collect(),
            disturbances: self.disturbances.clone(),
            elements,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn signal(name: &str) -> TfSignal {
        TfSignal { name: name.into(), unit: String::new(), description: String::new() }
    }

    #[test]
    fn polynomials_multiply_out_the_time_constants() {
        let e = Element { gain: 2.0, lags: vec![60.0, 120.0], leads: vec![-30.0], dead_time: 60.0 };
        // In minutes: 2 (−0.5 s + 1) / ((s + 1)(2 s + 1)) = (−s + 2) / (2 s² + 3 s + 1).
        assert_eq!(e.numerator(60.0), vec![-1.0, 2.0]);
        assert_eq!(e.denominator(60.0), vec![2.0, 3.0, 1.0]);
        assert_eq!(e.poles(), vec![-1.0 / 60.0, -1.0 / 120.0]);
    }

    #[test]
    fn channels_are_selected_by_name_in_the_order_given() {
        let e = |k: f64| Some(Element { gain: k, lags: vec![], leads: vec![], dead_time: 0.0 });
        let m = TfModel::new(
            "m".into(),
            String::new(),
            vec![signal("u1"), signal("u2")],
            vec![signal("y1"), signal("y2")],
            vec![signal("d")],
            vec![vec![e(1.0), e(2.0), e(5.0)], vec![e(3.0), e(4.0), e(6.0)]],
        )
        .unwrap();
        let s = m.select(&["u2".into()], &["y2".into(), "y1".into()]).unwrap();
        let g = s.gain();
        assert_eq!((g.nrows(), g.ncols(), g[(0, 0)], g[(1, 0)]), (2, 1, 4.0, 2.0));
        assert_eq!(s.disturbance_gain()[(0, 0)], 6.0);
        let err = m.select(&["u3".into()], &[]).unwrap_err().to_string();
        assert!(err.contains("no input `u3`") && err.contains("u1, u2"), "{err}");
    }

    #[test]
    fn a_model_needs_an_outputs_by_columns_element_matrix() {
        let g = Element { gain: 2.0, lags: vec![10.0], leads: vec![], dead_time: 0.0 };
        let m = TfModel::new(
            "m".into(),
            String::new(),
            vec![signal("u")],
            vec![signal("y")],
            vec![signal("d")],
            vec![vec![Some(g), None]],
        )
        .unwrap();
        assert_eq!((m.gain()[(0, 0)], m.disturbance_gain()[(0, 0)]), (2.0, 0.0));
        let e = TfModel::new("m".into(), String::new(), vec![signal("u")], vec![signal("y")], vec![], vec![]);
        assert!(e.unwrap_err().to_string().contains("must form a 1 × 1 matrix"));
    }
}
