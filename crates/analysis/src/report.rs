//! The gain report: a gain matrix in display units with every interaction measure computed from
//! it, the same for a flowsheet (by linearization or perturbation) and for a transfer-function
//! model.

use faer::Mat;
use serde::Serialize;

use crate::error::AnalysisError;
use crate::measures::{self, Svd};
use crate::min_cond::minimized_condition_number;
use crate::perturb::PerturbCheck;
use crate::select::{BlockSpec, SignalLabel};

/// What to compute besides the always-present RGA, SVD and condition number.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReportOptions {
    /// Pairing (`pairing[i]` = input of output `i`); default: the diagonal pairing.
    pub pairing: Option<Vec<usize>>,
    /// Block pairings for block relative gains.
    pub blocks: Vec<BlockSpec>,
    /// Expected input ranges and allowed output deviations (display units) for scaling.
    pub scaling: Option<(Vec<f64>, Vec<f64>)>,
}

/// Measures of the scaled gain `D_e⁻¹ G D_u`.
#[derive(Debug, Clone)]
pub struct Scaled {
    /// Scaled gain.
    pub gain: Mat<f64>,
    /// Its singular values.
    pub singular_values: Vec<f64>,
    /// Its condition number.
    pub condition_number: f64,
    /// Morari resiliency index `σ_min`.
    pub resiliency_index: f64,
}

/// A gain matrix and its interaction measures.
#[derive(Debug, Clone)]
pub struct GainReport {
    /// How the gains were obtained (`linear`, `perturb`, `transfer_function`).
    pub method: String,
    /// Inputs (columns) with their display units.
    pub inputs: Vec<SignalLabel>,
    /// Outputs (rows) with their display units.
    pub outputs: Vec<SignalLabel>,
    /// Gains in output display units per input display unit.
    pub gain: Mat<f64>,
    /// Relative gain array (`None` when `G` is singular).
    pub rga: Option<Mat<f64>>,
    /// Singular values and directions.
    pub svd: Svd,
    /// `σ_max/σ_min`.
    pub condition_number: f64,
    /// Minimized condition number (square, nonsingular `G`).
    pub min_condition_number: Option<f64>,
    /// The pairing the pairing-dependent measures use (square `G` only).
    pub pairing: Option<Vec<usize>>,
    /// Niederlinski index of the pairing.
    pub niederlinski: Option<f64>,
    /// RGA number of the pairing.
    pub rga_number: Option<f64>,
    /// Block relative gains of the requested blocks.
    pub block_relative_gains: Vec<(BlockSpec, Mat<f64>)>,
    /// Scaled measures, when ranges were given.
    pub scaled: Option<Scaled>,
}

impl GainReport {
    /// Compute every measure of `gain` (outputs × inputs, display units).
    pub fn new(
        method: &str,
        inputs: Vec<SignalLabel>,
        outputs: Vec<SignalLabel>,
        gain: Mat<f64>,
        options: &ReportOptions,
    ) -> Result<GainReport, AnalysisError> {
        let svd = measures::svd(gain.as_ref())?;
        let cond = measures::condition_number(&svd.singular_values);
        // Judged whatever the units of the signals (a square G equilibrated first).
        let regular = measures::is_regular(gain.as_ref())?;
        // A numerically singular G has an infinite condition number (null in JSON).
        let condition_number = if regular { cond } else { f64::INFINITY };
        let rga = if regular { Some(measures::rga(gain.as_ref())?) } else { None };
        let square = gain.nrows() == gain.ncols();
        let pairing =
            square.then(|| options.pairing.clone().unwrap_or_else(|| measures::diagonal_pairing(gain.nrows())));
        let (mut niederlinski, mut rga_number, mut min_condition_number) = (None, None, None);
        if let (Some(p), Some(l)) = (&pairing, &rga) {
            niederlinski = Some(measures::niederlinski(gain.as_ref(), p)?);
            rga_number = Some(measures::rga_number(l.as_ref(), p));
            min_condition_number = Some(minimized_condition_number(gain.as_ref())?);
        }
        let mut block_relative_gains = Vec::new();
        for b in &options.blocks {
            block_relative_gains
                .push((b.clone(), measures::block_relative_gain(gain.as_ref(), &b.outputs, &b.inputs)?));
        }
        let scaled = match &options.scaling {
            Some((input_ranges, output_ranges)) => {
                let g = measures::scale(gain.as_ref(), input_ranges, output_ranges)?;
                let s = measures::svd(g.as_ref())?;
                let condition_number = measures::condition_number(&s.singular_values);
                let resiliency_index = s.singular_values[s.singular_values.len() - 1];
                Some(Scaled { gain: g, singular_values: s.singular_values, condition_number, resiliency_index })
            }
            None => None,
        };
        Ok(GainReport {
            method: method.to_string(),
            inputs,
            outputs,
            gain,
            rga,
            svd,
            condition_number,
            min_condition_number,
            pairing,
            niederlinski,
            rga_number,
            block_relative_gains,
            scaled,
        })
    }

    /// The JSON of `plantwide gains --json`: exactly `method`, `inputs`, `outputs`, `gain`, `rga`,
    /// `singular_values`, `condition_number` and `niederlinski`, in that order (null where undefined).
    pub fn json(&self) -> GainJson<'_> {
        GainJson {
            method: &self.method,
            inputs: &self.inputs,
            outputs: &self.outputs,
            gain: measures::rows(self.gain.as_ref()),
            rga: self.rga.as_ref().map(|l| measures::rows(l.as_ref())),
            singular_values: &self.svd.singular_values,
            condition_number: self.condition_number.is_finite().then_some(self.condition_number),
            niederlinski: self.niederlinski,
            perturbation: None,
            frequency: None,
        }
    }
}

/// The serialized form of a [`GainReport`] (see [`GainReport::json`]).
#[derive(Debug, Clone, Serialize)]
pub struct GainJson<'a> {
    /// `linear`, `perturb` or `transfer_function`.
    pub method: &'a str,
    /// Inputs with units.
    pub inputs: &'a [SignalLabel],
    /// Outputs with units.
    pub outputs: &'a [SignalLabel],
    /// Gain rows.
    pub gain: Vec<Vec<f64>>,
    /// RGA rows (null when `G` is singular).
    pub rga: Option<Vec<Vec<f64>>>,
    /// Singular values, non-increasing.
    pub singular_values: &'a [f64],
    /// Condition number (null when infinite).
    pub condition_number: Option<f64>,
    /// Niederlinski index of the pairing (null for non-square or singular `G`).
    pub niederlinski: Option<f64>,
    /// How perturbation gains were verified (`gains --method perturb` only; absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub perturbation: Option<&'a PerturbCheck>,
    /// `G(jω)`, its singular values and RGA at each frequency (`--frequencies` only; absent
    /// otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frequency: Option<&'a crate::frequency::FrequencyResults>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn label(p: &str) -> SignalLabel {
        SignalLabel { path: p.into(), unit: "-".into() }
    }

    #[test]
    fn json_has_exactly_the_documented_keys() {
        let g = measures::from_rows(&[vec![87.8, -86.4], vec![108.2, -109.6]]);
        let r = GainReport::new(
            "linear",
            vec![label("L"), label("V")],
            vec![label("yD"), label("xB")],
            g,
            &ReportOptions::default(),
        )
        .unwrap();
        let text = serde_json::to_string(&r.json()).unwrap();
        let order =
            ["method", "inputs", "outputs", "gain", "rga", "singular_values", "condition_number", "niederlinski"];
        let at: Vec<usize> = order.iter().map(|k| text.find(&format!("\"{k}\":")).unwrap()).collect();
        assert!(at.windows(2).all(|w| w[0] < w[1]), "{text}");
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v.as_object().unwrap().len(), order.len());
        assert_eq!(v["inputs"][1]["path"], "V");
        let hand = 87.8 * -109.6 / (87.8 * -109.6 - -86.4 * 108.2);
        assert!((v["rga"][0][0].as_f64().unwrap() - hand).abs() < 1e-12 * hand);
        assert!((v["niederlinski"].as_f64().unwrap() - 1.0 / hand).abs() < 1e-12);
        assert!((r.min_condition_number.unwrap() - 138.268).abs() < 2e-3);
    }

    #[test]
    fn a_singular_gain_is_reported_not_refused() {
        let g = measures::from_rows(&[vec![1.0, 2.0], vec![2.0, 4.0]]);
        let r = GainReport::new(
            "linear",
            vec![label("a"), label("b")],
            vec![label("c"), label("d")],
            g,
            &ReportOptions::default(),
        )
        .unwrap();
        assert!(r.rga.is_none() && r.niederlinski.is_none());
        assert!(serde_json::to_value(r.json()).unwrap()["condition_number"].is_null());
    }
}
