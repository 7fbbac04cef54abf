//! The verdict on an identified model: can its step responses drive a model predictive
//! controller? A model study knows what a plant test cannot — the plant's own response without the
//! noise and the exact linearization's `G(0) = −C J⁻¹ B` — so the model is judged against them.
//!
//! Criteria that decide (any failure: not reliable, `identify` exits 2 and writes no MPC model):
//! - **fit**: per output, the model simulated on the fresh validation inputs against the plant's
//!   own response there, `100 (1 − ‖y − ŷ‖/‖y − ȳ‖)` ≥ [`MIN_FIT`] %;
//! - **denominator**: `|A(1)|`, `|F(1)|` ≥ [`MIN_DENOMINATOR`] (a pole at z = 1 leaves no gain);
//! - **gain sign**: every element of `Ĝ(0)` of the sign of `G(0)`'s (elements that move their
//!   output by less than [`NEGLIGIBLE`] of the row's largest test response are not judged);
//! - **gain error**: `|Ĝ_ij − G_ij| / s_ij` ≤ [`MAX_GAIN_ERROR`], `s_ij = max(|G_ij|, NEGLIGIBLE ·
//!   max_k |G_ik a_k| / a_j)` (`a`: the test's amplitudes), so that a negligible element is measured
//!   against the row's scale, not against itself;
//! - square, two inputs or more: **RGA sign** (every `λ̂_ij` of the sign of `λ_ij`), **RGA error**
//!   (`|λ̂_ij − λ_ij| / max(|λ_ij|, 1)` ≤ [`MAX_RGA_ERROR`]), and **integral controllability**
//!   (every eigenvalue of `Ĝ(0)⁻¹ G(0)` with a positive real part).
//!
//! Criteria that warn: residual **whiteness** and **independence** from the inputs (ch. 7 §7-4,
//! Eq. 7-59/7-60, at most 5 % of the lags outside ±1.96/√N).

use faer::Mat;
use faer::linalg::solvers::Solve;
use plantwide_analysis::measures::rga;
use plantwide_analysis::select::Signal;
use serde::Serialize;

use super::estimate::{Fitted, OutputValidation};

/// Least fit \[%\] of the model to the plant's own response on the fresh test.
pub const MIN_FIT: f64 = 50.0;
/// Largest relative error of an element of the identified `G(0)`.
pub const MAX_GAIN_ERROR: f64 = 0.2;
/// Largest error of an element of the identified RGA, relative to `max(|λ_ij|, 1)`.
pub const MAX_RGA_ERROR: f64 = 0.2;
/// An element moving its output by less than this fraction of its row's largest test response is
/// negligible: its sign is not judged and its error is measured against that fraction.
pub const NEGLIGIBLE: f64 = 0.01;
/// Least denominator `|A(1)|`, `|F(1)|` of a model with a gain.
pub const MIN_DENOMINATOR: f64 = 1e-3;

const SOURCE_FIT: &str = "plantwide's threshold (the reference gives none): the model's simulation error at most \
    half the plant's own response; the models whose gains pass on column A (open and closed loop) and on the \
    newcomer columns fit their plant's response by 66-94 %, while a 43 % fit left more of the response unexplained \
    than explained";
const SOURCE_DENOMINATOR: &str = "a pole at z = 1 makes the steady-state gain B(1)/F(1) meaningless";
const SOURCE_SIGN: &str = "Practical Distillation Control ch. 7 §7-4: a step response of the wrong sign sends the \
    identification back (reference L9786-9857); a controller acting on it moves the plant the wrong way";
const SOURCE_GAIN: &str = "plantwide's tolerance (the reference gives none): a loop tuned on the model with a gain \
    margin of 1.7, the least usually recommended (Seborg, Edgar & Mellichamp), keeps 1.4 under a 20 % gain error; \
    column A's directional test is within 5 %";
const SOURCE_RGA_SIGN: &str = "Grosdidier, Morari & Holt (1985): a pairing on a negative relative gain is unstable \
    closed, alone, or with another loop open; a model whose relative gains differ in sign from the plant's picks \
    such pairings";
const SOURCE_RGA: &str = "plantwide's tolerance, as for the gains; an ill-conditioned plant's RGA magnifies element \
    errors (Skogestad & Morari 1987), so this catches a lost low-gain direction the elements hide";
const SOURCE_IC: &str = "Morari (1985): an integral controller built on the model's inverse is stable at low \
    frequency on the plant only if every eigenvalue of Ĝ(0)⁻¹ G(0) has a positive real part";
const SOURCE_WHITE: &str = "ch. 7 §7-4, Eq. 7-59: at most 5 % of the lags 1..20 outside ±1.96/√N; a warning, as \
    the book's own final model (§7-6, Fig. 7-10a) kept correlated residuals without a disturbance model";
const SOURCE_INDEPENDENT: &str = "ch. 7 §7-4, Eq. 7-60: at most 5 % of the (input, lag 0..20) pairs outside \
    ±1.96/√N; a warning, as on a nonlinear plant the residual holds the response's curvature at the test's \
    amplitude, which the gain and fit criteria measure directly";

/// One criterion of the verdict.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Criterion {
    /// What is judged: `fit`, `denominator`, `gain_sign`, `gain_error`, `rga_sign`, `rga_error`,
    /// `integral_controllability`, `whiteness`, `independence`.
    pub criterion: &'static str,
    /// Where: an output, the worst element (`output ← input`, `λij`), or the whole matrix
    /// (`G(0)`, `RGA`) for a count.
    pub at: String,
    /// The value found.
    pub value: f64,
    /// How it must compare with the threshold (`≥`, `≤`, `>`).
    pub must_be: &'static str,
    /// The threshold.
    pub threshold: f64,
    /// Whether it passes.
    pub pass: bool,
    /// Whether a failure makes the model unusable (otherwise it is a warning).
    pub decides: bool,
    /// Where the threshold comes from.
    pub source: &'static str,
    /// The numbers behind a failure, in display units.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub detail: Option<String>,
}

impl Criterion {
    fn new(criterion: &'static str, at: String, value: f64, rule: (&'static str, f64), source: &'static str) -> Self {
        let (must_be, threshold) = rule;
        let pass = match must_be {
            "≥" => value >= threshold,
            ">" => value > threshold,
            _ => value <= threshold,
        };
        Criterion { criterion, at, value, must_be, threshold, pass, decides: true, source, detail: None }
    }

    fn warning(self) -> Self {
        Criterion { decides: false, ..self }
    }

    fn detail(self, d: impl FnOnce() -> String) -> Self {
        let detail = (!self.pass).then(d);
        Criterion { detail, ..self }
    }

    /// One line: the criterion, its value against the threshold, and where.
    pub fn line(&self) -> String {
        let detail = self.detail.as_ref().map_or(String::new(), |d| format!(" ({d})"));
        format!(
            "{} {} at {}, must be {} {}{detail}",
            self.criterion,
            number(self.value),
            self.at,
            self.must_be,
            number(self.threshold)
        )
    }
}

/// A number as messages print it: a count as an integer, else four significant digits.
pub fn number(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e6 {
        format!("{v:.0}")
    } else if (1e-3..1e5).contains(&v.abs()) {
        let decimals = (3 - v.abs().log10().floor() as i32).max(0) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.3e}")
    }
}

/// Whether the identified model can be used, and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verdict {
    /// Every deciding criterion passes: the model's step responses may drive a model predictive
    /// controller.
    pub reliable: bool,
    /// The structure judged (the one reported).
    pub model: String,
    /// Every criterion, deciding ones first.
    pub criteria: Vec<Criterion>,
    /// The deciding criteria that failed, one line each (empty for a usable model): the
    /// `failed` entry every study's JSON carries for a part it could not do.
    pub failed: Vec<String>,
}

impl Verdict {
    /// The deciding criteria that failed.
    pub fn failed(&self) -> impl Iterator<Item = &Criterion> {
        self.criteria.iter().filter(|c| c.decides && !c.pass)
    }

    /// The warnings (criteria that failed without deciding).
    pub fn warnings(&self) -> impl Iterator<Item = &Criterion> {
        self.criteria.iter().filter(|c| !c.decides && !c.pass)
    }
}

/// What a model is judged against: the exact `G(0)` and the test's amplitudes (SI), and the
/// signals (for names and display units).
pub(super) struct Reference<'a> {
    pub exact: &'a Mat<f64>,
    pub amplitude: &'a [f64],
    pub inputs: &'a [Signal],
    pub outputs: &'a [Signal],
}

impl Reference<'_> {
    /// The largest test response in row `i`, `max_k |G_ik a_k|`.
    fn row_response(&self, i: usize) -> f64 {
        (0..self.exact.ncols()).map(|k| (self.exact[(i, k)] * self.amplitude[k]).abs()).fold(0.0, f64::max)
    }

    /// The scale element `(i, j)`'s error is measured against.
    fn scale(&self, i: usize, j: usize) -> f64 {
        self.exact[(i, j)].abs().max(NEGLIGIBLE * self.row_response(i) / self.amplitude[j])
    }

    fn significant(&self, i: usize, j: usize) -> bool {
        (self.exact[(i, j)] * self.amplitude[j]).abs() >= NEGLIGIBLE * self.row_response(i)
    }

    fn element(&self, i: usize, j: usize) -> String {
        format!("`{}` ← `{}`", self.outputs[i].path, self.inputs[j].path)
    }

    fn display(&self, i: usize, j: usize, g: f64) -> f64 {
        g * self.inputs[j].factor / self.outputs[i].factor
    }

    /// Row `i`'s elements of the wrong sign and its worst relative error `(error, j)`.
    fn row_errors(&self, i: usize, gain: &[f64]) -> (Vec<usize>, (f64, usize)) {
        let wrong = (0..gain.len())
            .filter(|&j| self.significant(i, j) && gain[j].signum() != self.exact[(i, j)].signum())
            .collect();
        let error = |j: usize| {
            let e = (gain[j] - self.exact[(i, j)]).abs() / self.scale(i, j);
            if e.is_nan() { f64::INFINITY } else { e }
        };
        let worst = (0..gain.len()).map(|j| (error(j), j)).fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a });
        (wrong, worst)
    }

    /// Whether a model of output `i` passes the criteria of one output.
    pub fn output_passes(&self, i: usize, f: &Fitted) -> bool {
        let (wrong, (worst, _)) = self.row_errors(i, &f.gain);
        f.denominator >= MIN_DENOMINATOR
            && wrong.is_empty()
            && worst <= MAX_GAIN_ERROR
            && f.validation.fit_noise_free >= MIN_FIT
    }
}

/// The verdict on `chosen`, one fitted model per output (the same structure).
pub(super) fn judge(r: &Reference<'_>, chosen: &[&Fitted]) -> Verdict {
    let mut criteria = Vec::new();
    for (f, o) in chosen.iter().zip(r.outputs) {
        let at = format!("`{}`", o.path);
        criteria.push(Criterion::new("fit", at.clone(), f.validation.fit_noise_free, ("≥", MIN_FIT), SOURCE_FIT));
        if f.denominator < MIN_DENOMINATOR {
            criteria.push(Criterion::new("denominator", at, f.denominator, ("≥", MIN_DENOMINATOR), SOURCE_DENOMINATOR));
        }
    }
    let gains: Vec<&[f64]> = chosen.iter().map(|f| f.gain.as_slice()).collect();
    criteria.extend(gain_criteria(r, &gains));
    let (n, m) = (r.exact.nrows(), r.exact.ncols());
    if n == m && n >= 2 {
        let identified = Mat::from_fn(n, m, |i, j| gains[i][j]);
        criteria.extend(rga_criteria(r, &identified));
        criteria.push(integral_controllability(r, &identified));
    }
    for (f, o) in chosen.iter().zip(r.outputs) {
        criteria.extend(residual_criteria(&f.validation, &o.path));
    }
    criteria.sort_by_key(|c| !c.decides);
    let failed = criteria.iter().filter(|c| c.decides && !c.pass).map(Criterion::line).collect();
    Verdict {
        reliable: criteria.iter().all(|c| c.pass || !c.decides),
        model: chosen.first().map_or_else(String::new, |f| f.model.to_string()),
        criteria,
        failed,
    }
}

/// Gain sign and gain error over the whole matrix (`gains[i][j]`, SI).
fn gain_criteria(r: &Reference<'_>, gains: &[&[f64]]) -> [Criterion; 2] {
    let rows: Vec<_> = gains.iter().enumerate().map(|(i, g)| r.row_errors(i, g)).collect();
    let wrong: Vec<(usize, usize)> =
        rows.iter().enumerate().flat_map(|(i, (w, _))| w.iter().map(move |&j| (i, j))).collect();
    let value = |i: usize, j: usize| {
        format!(
            "identified {}, exact {}",
            number(r.display(i, j, gains[i][j])),
            number(r.display(i, j, r.exact[(i, j)]))
        )
    };
    let both = |i: usize, j: usize| format!("{}: {}", r.element(i, j), value(i, j));
    let sign = Criterion::new("gain_sign", "G(0)".to_string(), wrong.len() as f64, ("≤", 0.0), SOURCE_SIGN)
        .detail(|| wrong.iter().map(|&(i, j)| both(i, j)).collect::<Vec<_>>().join("; "));
    let (i, (worst, j)) = rows
        .iter()
        .enumerate()
        .map(|(i, (_, w))| (i, *w))
        .fold((0, (0.0, 0)), |a, b| if b.1.0 > a.1.0 { b } else { a });
    let error =
        Criterion::new("gain_error", r.element(i, j), worst, ("≤", MAX_GAIN_ERROR), SOURCE_GAIN).detail(|| value(i, j));
    [sign, error]
}

/// RGA sign and error of the identified gain against the exact one's.
fn rga_criteria(r: &Reference<'_>, identified: &Mat<f64>) -> Vec<Criterion> {
    let Ok(exact) = rga(r.exact.as_ref()) else { return Vec::new() };
    let n = exact.nrows();
    let Ok(model) = rga(identified.as_ref()) else {
        let singular = || "the identified G(0) is singular".to_string();
        return vec![
            Criterion::new("rga_sign", "RGA".into(), (n * n) as f64, ("≤", 0.0), SOURCE_RGA_SIGN).detail(singular),
            Criterion::new("rga_error", "RGA".into(), f64::MAX, ("≤", MAX_RGA_ERROR), SOURCE_RGA).detail(singular),
        ];
    };
    let cells = || (0..n).flat_map(|i| (0..n).map(move |j| (i, j)));
    let wrong: Vec<(usize, usize)> =
        cells().filter(|&(i, j)| model[(i, j)].signum() != exact[(i, j)].signum()).collect();
    let error = |i: usize, j: usize| (model[(i, j)] - exact[(i, j)]).abs() / exact[(i, j)].abs().max(1.0);
    let (wi, wj) = cells().fold((0, 0), |a, b| if error(b.0, b.1) > error(a.0, a.1) { b } else { a });
    let name = |i: usize, j: usize| format!("λ{}{}", i + 1, j + 1);
    let value = |i: usize, j: usize| format!("identified {}, exact {}", number(model[(i, j)]), number(exact[(i, j)]));
    let worst = format!("{} ({})", name(wi, wj), r.element(wi, wj));
    vec![
        Criterion::new("rga_sign", "RGA".to_string(), wrong.len() as f64, ("≤", 0.0), SOURCE_RGA_SIGN).detail(|| {
            wrong.iter().map(|&(i, j)| format!("{} {}", name(i, j), value(i, j))).collect::<Vec<_>>().join("; ")
        }),
        Criterion::new("rga_error", worst, error(wi, wj), ("≤", MAX_RGA_ERROR), SOURCE_RGA).detail(|| value(wi, wj)),
    ]
}

/// The least real part of the eigenvalues of `Ĝ(0)⁻¹ G(0)` (0 for a singular `Ĝ(0)`).
fn integral_controllability(r: &Reference<'_>, identified: &Mat<f64>) -> Criterion {
    let least = rga(identified.as_ref()).ok().and_then(|_| {
        let x = identified.partial_piv_lu().solve(r.exact);
        let ev = x.eigenvalues().ok()?;
        ev.iter().map(|v| v.re).reduce(f64::min).filter(|v| v.is_finite())
    });
    Criterion::new("integral_controllability", "eig(Ĝ(0)⁻¹ G(0))".into(), least.unwrap_or(0.0), (">", 0.0), SOURCE_IC)
        .detail(|| if least.is_some() { "least real part".into() } else { "the identified G(0) is singular".into() })
}

/// Whiteness and independence of one output's residuals, as warnings.
fn residual_criteria(v: &OutputValidation, output: &str) -> [Criterion; 2] {
    let at = format!("`{output}`");
    let outside = |r: &[f64]| r.iter().filter(|c| c.abs() > v.bound).count();
    let lags = v.autocorrelation.len().saturating_sub(1);
    let pairs: usize = v.cross_correlation.iter().map(Vec::len).sum();
    let allowed = |n: usize| (0.05 * n as f64).floor();
    let white_value = outside(v.autocorrelation.get(1..).unwrap_or(&[])) as f64;
    let cross_value = v.cross_correlation.iter().map(|c| outside(c)).sum::<usize>() as f64;
    [
        Criterion::new("whiteness", at.clone(), white_value, ("≤", allowed(lags)), SOURCE_WHITE).warning(),
        Criterion::new("independence", at, cross_value, ("≤", allowed(pairs)), SOURCE_INDEPENDENT).warning(),
    ]
}

/// The structure to report: of those whose every output passes and whose verdict is reliable, the
/// best mean fit to the plant's response; when none is, the best mean fit of those with a
/// denominator (the verdict then says why it is not reliable).
pub(super) fn choose(r: &Reference<'_>, per_output: &[Vec<Fitted>]) -> usize {
    let n = per_output.first().map_or(0, Vec::len);
    let of = |s: usize| -> Vec<&Fitted> { per_output.iter().map(|f| &f[s]).collect() };
    let mean_fit = |s: usize| of(s).iter().map(|f| f.validation.fit_noise_free).sum::<f64>() / per_output.len() as f64;
    let best =
        |ok: &dyn Fn(usize) -> bool| (0..n).filter(|&s| ok(s)).max_by(|&a, &b| mean_fit(a).total_cmp(&mean_fit(b)));
    best(&|s| judge(r, &of(s)).reliable)
        .or_else(|| best(&|s| of(s).iter().all(|f| f.denominator >= MIN_DENOMINATOR)))
        .unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Column A's published G(0) (S&P 2005 eq. 12.17), λ11 = 1/(1 − g12 g21/(g11 g22)) = 35.1.
    const COLUMN_A: [[f64; 2]; 2] = [[0.878, -0.864], [1.082, -1.096]];

    fn signal(path: &str) -> Signal {
        Signal { path: path.into(), unit: "-".into(), factor: 1.0, index: 0 }
    }

    fn fitted(model: &'static str, gain: [f64; 2], fit: f64) -> Fitted {
        let validation = OutputValidation {
            output: String::new(),
            fit_percent: fit,
            fit_noise_free: fit,
            autocorrelation: vec![1.0; 21],
            cross_correlation: vec![vec![0.0; 21]; 2],
            bound: 0.1,
            white: false,
            independent: true,
            predicted: Vec::new(),
        };
        Fitted {
            model,
            orders: String::new(),
            gain: gain.to_vec(),
            gain_std: None,
            denominator: 1.0,
            validation,
            step: Vec::new(),
        }
    }

    /// The verdict on a model of gain `g` (rows per output) against `exact`, fit 90 %.
    fn verdict_of(exact: [[f64; 2]; 2], g: [[f64; 2]; 2]) -> Verdict {
        let exact = Mat::from_fn(2, 2, |i, j| exact[i][j]);
        let (inputs, outputs) = ([signal("L"), signal("V")], [signal("yD"), signal("xB")]);
        let r = Reference { exact: &exact, amplitude: &[1.0, 1.0], inputs: &inputs, outputs: &outputs };
        let fits = [fitted("oe", g[0], 90.0), fitted("oe", g[1], 90.0)];
        judge(&r, &[&fits[0], &fits[1]])
    }

    fn criterion<'a>(v: &'a Verdict, name: &str) -> &'a Criterion {
        v.criteria.iter().find(|c| c.criterion == name).unwrap_or_else(|| panic!("no {name} in {v:?}"))
    }

    #[test]
    fn the_exact_gain_is_reliable_and_residual_tests_only_warn() {
        let v = verdict_of(COLUMN_A, COLUMN_A);
        assert!(v.reliable, "{v:?}");
        assert_eq!(criterion(&v, "gain_error").value, 0.0);
        assert!((criterion(&v, "integral_controllability").value - 1.0).abs() < 1e-9);
        // Every lag of the autocorrelation is outside the bound: a warning, not a failure.
        let white = criterion(&v, "whiteness");
        assert!(!white.pass && !white.decides && white.value == 20.0 && white.threshold == 1.0, "{white:?}");
        assert_eq!(v.warnings().count(), 2);
        assert!(v.criteria.iter().take_while(|c| c.decides).count() >= 7, "deciding criteria first: {v:?}");
    }

    #[test]
    fn a_wrong_sign_or_a_gain_100_times_off_is_not_reliable() {
        let mut g = COLUMN_A;
        g[1][0] = -g[1][0];
        let v = verdict_of(COLUMN_A, g);
        let sign = criterion(&v, "gain_sign");
        assert!(!v.reliable && !sign.pass && sign.value == 1.0, "{sign:?}");
        assert!(
            sign.detail.as_deref().unwrap_or("").contains("`xB` ← `L`: identified -1.082, exact 1.082"),
            "{sign:?}"
        );
        let mut g = COLUMN_A;
        g[0][1] *= 100.0;
        let v = verdict_of(COLUMN_A, g);
        let e = criterion(&v, "gain_error");
        assert!(!v.reliable && (e.value - 99.0).abs() < 1e-9 && e.at == "`yD` ← `V`", "{e:?}");
        assert!(criterion(&v, "gain_sign").pass);
    }

    /// An element error of −1/λ11 makes G singular (Yu & Luyben 1987): g11 3 % low (1/35.1 = 2.85 %)
    /// passes the element tolerance, but det Ĝ changes sign, so λ̂11 < 0 and Ĝ⁻¹G has a negative
    /// eigenvalue (their product is det G / det Ĝ < 0). Independent 2 % errors that keep the sign
    /// move the relative gains by far more than 20 %: λ̂11 = 1/(1 − g12 g21/(1.02² g11 g22)).
    #[test]
    fn rga_and_integral_controllability_catch_errors_the_elements_hide() {
        let l11 = |g: [[f64; 2]; 2]| 1.0 / (1.0 - g[0][1] * g[1][0] / (g[0][0] * g[1][1]));
        assert!((l11(COLUMN_A) - 35.1).abs() < 0.1);
        let mut g = COLUMN_A;
        g[0][0] *= 0.97;
        let v = verdict_of(COLUMN_A, g);
        assert!(criterion(&v, "gain_error").pass && criterion(&v, "gain_sign").pass, "{v:?}");
        assert!(!criterion(&v, "rga_sign").pass && criterion(&v, "rga_sign").value == 4.0, "{v:?}");
        let ic = criterion(&v, "integral_controllability");
        let det = |g: [[f64; 2]; 2]| g[0][0] * g[1][1] - g[0][1] * g[1][0];
        assert!(det(COLUMN_A) / det(g) < 0.0 && !ic.pass && ic.value < 0.0, "{ic:?}");
        let mut g = COLUMN_A;
        g[0][0] *= 1.02;
        g[1][1] *= 1.02;
        let v = verdict_of(COLUMN_A, g);
        let rga = criterion(&v, "rga_error");
        // In a 2×2 RGA λ12 = 1 − λ11 moves as much as λ11 and is smaller (λ11 > 1), so its relative
        // error is the largest: |Δλ11| / (λ11 − 1).
        let expected = (l11(g) - l11(COLUMN_A)).abs() / (l11(COLUMN_A) - 1.0);
        assert!(rga.at.starts_with("λ12") && (rga.value - expected).abs() < 1e-9 && expected > 0.5, "{rga:?}");
        assert!(!v.reliable && criterion(&v, "gain_error").value < 0.021 && criterion(&v, "rga_sign").pass);
    }

    /// An element that moves its output by less than 1 % of the row's largest test response is not
    /// judged by its sign, and its error is measured against that 1 %.
    #[test]
    fn a_negligible_element_is_measured_against_its_row() {
        let exact = [[1.0, 1e-6], [0.5, 2.0]];
        let v = verdict_of(exact, [[1.0, -1e-4], [0.5, 2.0]]);
        assert!(criterion(&v, "gain_sign").pass, "{v:?}");
        let e = criterion(&v, "gain_error");
        assert!((e.value - (1e-4 + 1e-6) / 1e-2).abs() < 1e-12 && e.pass, "{e:?}");
    }

    /// Issue 53 #11: a model row (one output, one structure) is marked reliable only when each of
    /// its gains has the exact one's sign and is within 20 % of it: a wrong sign or a gain 100× off
    /// fails however well the model fits (95 % here).
    #[test]
    fn a_model_row_with_a_wrong_sign_or_a_gain_100_times_off_is_not_reliable() {
        let exact = Mat::from_fn(2, 2, |i, j| COLUMN_A[i][j]);
        let (inputs, outputs) = ([signal("L"), signal("V")], [signal("yD"), signal("xB")]);
        let r = Reference { exact: &exact, amplitude: &[1.0, 1.0], inputs: &inputs, outputs: &outputs };
        let row = |g: [f64; 2]| fitted("oe", g, 95.0);
        assert!(r.output_passes(1, &row(COLUMN_A[1])));
        assert!(!r.output_passes(1, &row([-COLUMN_A[1][0], COLUMN_A[1][1]])), "wrong sign");
        assert!(!r.output_passes(1, &row([COLUMN_A[1][0], 100.0 * COLUMN_A[1][1]])), "100× off");
        assert!(!r.output_passes(1, &row([COLUMN_A[1][0], 0.01 * COLUMN_A[1][1]])), "100× below");
        assert!(r.output_passes(1, &row([COLUMN_A[1][0], 1.19 * COLUMN_A[1][1]])), "19 % off passes");
    }

    #[test]
    fn the_best_reliable_structure_is_chosen_over_a_better_fit() {
        let exact = Mat::from_fn(2, 2, |i, j| COLUMN_A[i][j]);
        let (inputs, outputs) = ([signal("L"), signal("V")], [signal("yD"), signal("xB")]);
        let r = Reference { exact: &exact, amplitude: &[1.0, 1.0], inputs: &inputs, outputs: &outputs };
        let wrong = [COLUMN_A[1][0] * 17.0, COLUMN_A[1][1]];
        let per_output = vec![
            vec![fitted("fir", COLUMN_A[0], 80.0), fitted("oe", COLUMN_A[0], 95.0)],
            vec![fitted("fir", COLUMN_A[1], 80.0), fitted("oe", wrong, 95.0)],
        ];
        assert_eq!(choose(&r, &per_output), 0);
        assert!(!r.output_passes(1, &per_output[1][1]) && r.output_passes(1, &per_output[1][0]));
        // A fit under the threshold fails the output too.
        assert!(!r.output_passes(0, &fitted("oe", COLUMN_A[0], MIN_FIT - 1.0)));
    }

    #[test]
    fn numbers_print_counts_as_integers_and_four_significant_digits() {
        assert_eq!(number(2.0), "2");
        assert_eq!(number(0.87541), "0.8754");
        assert_eq!(number(-49133.767), "-49134");
        assert_eq!(number(-2.95423e-7), "-2.954e-7");
    }
}
