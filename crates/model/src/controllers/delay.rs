//! Transport delay (dead time) `y(t) = u(t − θ)` by its diagonal Padé approximant of order n,
//! `P_n(s) = Σ_k (−1)^k c_k (θs)^k / Σ_k c_k (θs)^k`, `c_k = (2n − k)! n! / ((2n)! k! (n − k)!)`:
//! an all-pass filter (|P_n(iω)| = 1) whose phase matches `−ωθ` to `O((ωθ)^{2n+1})`. Use it on a
//! measurement (an analyzer line, a pipe between units: a controller reads `<delay>.op`) or, with
//! `output`, in front of an input. A step comes out with the Padé's characteristic undershoot
//! (the output first jumps by `(−1)^n` of the step); for exact sample-and-hold dead time on a
//! controller's measurement use a scenario analyzer instead.
//!
//! Realization (controllable canonical form, states scaled to the units of the signal): with
//! `a_k = c_k/c_n`, `b_k = (−1)^k a_k`, `D = (−1)^n` and states `z_0 … z_{n−1}` (differential),
//! `θ dz_i/dt = z_{i+1}` (i < n − 1), `θ dz_{n−1}/dt = a_0 u − Σ_k a_k z_k`, and the output
//! `op = D u + Σ_k (b_k − D a_k) z_k / a_0` (algebraic). At steady state `z_0 = u`, the other
//! states are 0 and `op = u`.

use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::ControllerLinks;
use crate::{BuildCx, FieldError, InputSpec, Scalar, SignalSpec, UnitIo, UnitModel, VarSpec};

/// Flowsheet description of a transport delay.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DelayConfig {
    /// Variable path of the delayed signal, e.g. `"column.x[1][light]"`.
    pub pv: String,
    /// Input driven by the delayed signal; omit to read it as `<delay>.op`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output: Option<String>,
    /// Dead time θ (e.g. `"2 min"`); > 0.
    pub delay: QuantityValue,
    /// Order n of the Padé approximant, 1 … 8 (default 4).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub order: Option<usize>,
}

impl super::ControllerConfig for DelayConfig {
    fn paths(&self) -> super::ControllerPaths {
        let driven = self.output.iter().map(|o| ("output".to_string(), o.clone())).collect();
        super::ControllerPaths { measured: vec![("pv".to_string(), self.pv.clone())], driven }
    }
    fn op_dimension(&self, pv_dim: Dimension) -> Option<Dimension> {
        Some(pv_dim)
    }
}

/// A Padé transport delay.
#[derive(Debug, Clone)]
pub struct Delay {
    pv_path: String,
    theta: f64,
    /// `a_0 … a_{n−1}` (`a_n = 1`).
    a: Vec<f64>,
    /// `b_0 … b_n`.
    b: Vec<f64>,
    dim: Dimension,
    scale: f64,
}

/// Padé coefficients `c_0 … c_n` normalized by `c_n`.
fn pade(n: usize) -> Vec<f64> {
    let fact = |k: usize| (1..=k).map(|i| i as f64).product::<f64>();
    let c: Vec<f64> = (0..=n).map(|k| fact(2 * n - k) * fact(n) / (fact(2 * n) * fact(k) * fact(n - k))).collect();
    c.iter().map(|v| v / c[n]).collect()
}

impl Delay {
    /// Build from the flowsheet description and the resolved links.
    pub fn build(c: &DelayConfig, mut cx: BuildCx<'_>, links: &ControllerLinks) -> Result<Delay, Vec<FieldError>> {
        if links.op_dim != links.pv_dim {
            cx.error(
                "output",
                format!(
                    "the delayed signal is {} but the driven input is {}",
                    links.pv_dim.describe(),
                    links.op_dim.describe()
                ),
            );
        }
        let theta = cx.positive("delay", &c.delay, Dimension::TIME);
        let n = c.order.unwrap_or(4);
        if !(1..=8).contains(&n) {
            cx.error("order", format!("the Padé order must be 1 … 8 (got {n})"));
        }
        let a = pade(n.clamp(1, 8));
        let n = a.len() - 1;
        let b: Vec<f64> = a.iter().enumerate().map(|(k, v)| if k % 2 == 0 { *v } else { -v }).collect();
        let scale = links.op_value.abs().max(links.pv_nominal.abs()).max(1e-6);
        cx.finish(Delay { pv_path: c.pv.clone(), theta, a: a[..n].to_vec(), b, dim: links.pv_dim, scale })
    }

    fn order(&self) -> usize {
        self.a.len()
    }
}

impl UnitModel for Delay {
    fn type_name(&self) -> &'static str {
        "delay"
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        let mut v: Vec<VarSpec> =
            (1..=self.order()).map(|k| VarSpec::differential(format!("z[{k}]"), self.dim, self.scale)).collect();
        v.push(VarSpec::algebraic("op", self.dim, self.scale));
        v
    }
    fn inputs(&self) -> Vec<InputSpec> {
        Vec::new()
    }
    fn signals(&self) -> Vec<SignalSpec> {
        vec![SignalSpec { role: "pv".into(), path: self.pv_path.clone() }]
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        let n = self.order();
        let u = io.signal(0);
        let z = io.vars(0, n);
        for i in 0..n - 1 {
            r[i] = z[i + 1] / self.theta;
        }
        let mut acc = u * self.a[0];
        let d = self.b[n];
        let mut y = u * d;
        for (k, zk) in z.iter().enumerate() {
            acc -= *zk * self.a[k];
            y += *zk * ((self.b[k] - d * self.a[k]) / self.a[0]);
        }
        r[n - 1] = acc / self.theta;
        r[n] = io.var(n) - y;
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        own.fill(0.0);
        own[0] = io.signal(0);
        own[self.order()] = io.signal(0);
    }
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    use super::*;
    use crate::testing::{binary_package, jacobian_error};
    use crate::{LocalLayout, StreamLayout, Unit};

    fn build(order: usize) -> Delay {
        let c: DelayConfig = serde_json::from_value(json!({"pv": "s.F", "delay": "10 s", "order": order})).unwrap();
        let thermo = binary_package();
        let comps = vec!["light".to_string(), "heavy".to_string()];
        let links = ControllerLinks {
            measured_dims: Vec::new(),
            driven: Vec::new(),
            pv_dim: Dimension::MOLAR_FLOW,
            op_dim: Dimension::MOLAR_FLOW,
            op_value: 0.0,
            pv_nominal: 5.0,
            measured_ranges: Vec::new(),
            driven_ranges: Vec::new(),
        };
        Delay::build(&c, BuildCx::new(&comps, &thermo, "controllers.d"), &links).unwrap()
    }

    fn layout(n: usize) -> LocalLayout {
        LocalLayout {
            stream: StreamLayout { n_comp: 2 },
            n_outlets: 0,
            n_internal: n + 1,
            n_inlets: 0,
            n_inputs: 0,
            n_signals: 1,
        }
    }

    #[test]
    fn pade_coefficients_match_the_textbook_forms() {
        // n = 1: (1 − θs/2)/(1 + θs/2) → a = [2, 1]; n = 2: 1 + θs/2 + θ²s²/12 → a = [12, 6, 1].
        assert_eq!(pade(1), vec![2.0, 1.0]);
        let p2 = pade(2);
        assert!((p2[0] - 12.0).abs() < 1e-12 && (p2[1] - 6.0).abs() < 1e-12 && p2[2] == 1.0, "{p2:?}");
    }

    #[test]
    fn steady_state_passes_the_signal_and_the_jacobian_is_exact() {
        for n in [1, 2, 4, 8] {
            let d = build(n);
            let lay = layout(n);
            let thermo = binary_package();
            let mut local = vec![0.0; n + 2];
            local[0] = 3.0;
            local[n] = 3.0;
            local[n + 1] = 3.0;
            let mut r = vec![f64::NAN; n + 1];
            Unit::residual(&d, &UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 }, &mut r);
            assert!(r.iter().all(|v| v.abs() < 1e-12), "order {n}: {r:?}");
            let perturbed: Vec<f64> = local.iter().enumerate().map(|(i, v)| v + 0.1 * i as f64).collect();
            assert!(jacobian_error(&d, &lay, &thermo, &perturbed, n + 1) < 1e-7);
        }
    }

    /// The realization's transfer function `C (iωI − A)⁻¹ B + D` is all-pass and its phase is
    /// `−ωθ` to the Padé accuracy.
    #[test]
    fn frequency_response_is_all_pass_with_the_delay_phase() {
        for n in [1, 3, 6] {
            let d = build(n);
            // Padé-1's phase −2 atan(ωθ/2) is close to −ωθ only for small ωθ.
            let wts: &[f64] = if n == 1 { &[0.1] } else { &[0.1, 0.5, 1.0] };
            for &wt in wts {
                let w = wt / d.theta;
                let s = (0.0, w * d.theta);
                let mul = |a: (f64, f64), b: (f64, f64)| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
                let mut pw = vec![(1.0, 0.0)];
                for _ in 0..n {
                    let last = *pw.last().unwrap();
                    pw.push(mul(last, s));
                }
                let mut den = (0.0, 0.0);
                for (k, p) in pw.iter().enumerate() {
                    let ak = if k < n { d.a[k] } else { 1.0 };
                    den = (den.0 + ak * p.0, den.1 + ak * p.1);
                }
                // With x_k = z_k/a_0: x_k = s^k/den(s) and y = D + Σ (b_k − D a_k) x_k.
                let dd = d.b[n];
                let mut num = (0.0, 0.0);
                for (k, p) in pw.iter().take(n).enumerate() {
                    let c = d.b[k] - dd * d.a[k];
                    num = (num.0 + c * p.0, num.1 + c * p.1);
                }
                let inv = (den.0 / (den.0 * den.0 + den.1 * den.1), -den.1 / (den.0 * den.0 + den.1 * den.1));
                let g = mul(num, inv);
                let g = (g.0 + dd, g.1);
                let (mag, phase) = ((g.0 * g.0 + g.1 * g.1).sqrt(), g.1.atan2(g.0));
                let want = (-wt + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
                assert!((mag - 1.0).abs() < 1e-12, "order {n}, ωθ {wt}: |G| = {mag}");
                assert!((phase - want).abs() < 1e-3 * wt, "order {n}, ωθ {wt}: phase {phase} vs {want}");
            }
        }
    }
}
