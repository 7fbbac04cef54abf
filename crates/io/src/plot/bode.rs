//! Bode diagrams of tuned loops: for each loop, `|L(jω)|` in dB and `∠L(jω)` in degrees against
//! ω on a log axis, the gain crossover (0 dB) and the phase crossover (−180°) marked on both, the
//! phase margin drawn as the gap from −180° at the gain crossover and the gain margin as the gap
//! from 0 dB at the phase crossover, their figures in the legend beside the data.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::{COLOURS, CurveStyle, GREY, Marker, Sample, draw_curve, draw_legend, legend_width, titled};
use super::{Figure, write_figure};
use crate::error::IoError;

/// One loop's open-loop frequency response as drawn.
#[derive(Debug, Clone, Default)]
pub struct BodeLoop {
    /// The loop, e.g. `xD ← R (Kc 0.375, τI 8.29 min)`.
    pub label: String,
    /// Frequencies, increasing, in the unit of the figure's ω axis; the crossovers among them.
    pub omega: Vec<f64>,
    /// `20 log10 |L|` \[dB\] at each frequency.
    pub magnitude_db: Vec<f64>,
    /// `∠L` \[deg\], unwrapped, at each frequency.
    pub phase_deg: Vec<f64>,
    /// Gain crossover ω_c and the phase margin there \[deg\].
    pub gain_crossover: Option<(f64, f64)>,
    /// Phase crossover ω_180 and the gain margin there (a factor).
    pub phase_crossover: Option<(f64, f64)>,
}

impl BodeLoop {
    /// The −180° line (modulo 360°) the margins are read against: the phase at the phase
    /// crossover, else the phase at the gain crossover less the phase margin, else −180°.
    pub fn critical_phase(&self) -> f64 {
        match (self.phase_crossover, self.gain_crossover) {
            (Some((w, _)), _) => at(&self.omega, &self.phase_deg, w),
            (None, Some((w, pm))) => at(&self.omega, &self.phase_deg, w) - pm,
            (None, None) => -180.0,
        }
    }
}

impl BodeLoop {
    /// The loop up to where its phase falls 200° below the critical line (a dead time turns it
    /// without end; past one turn below −180° nothing is read off a diagram).
    fn within_a_turn(&self) -> BodeLoop {
        let floor = self.critical_phase() - 200.0;
        let n = self.phase_deg.iter().position(|p| *p < floor).map_or(self.omega.len(), |k| k + 1);
        BodeLoop {
            omega: self.omega[..n].to_vec(),
            magnitude_db: self.magnitude_db[..n].to_vec(),
            phase_deg: self.phase_deg[..n].to_vec(),
            ..self.clone()
        }
    }
}

/// `values` at `w`, linear in log ω between the points around it (exact at a point).
fn at(omega: &[f64], values: &[f64], w: f64) -> f64 {
    let k = omega.partition_point(|x| *x < w).clamp(1, omega.len().max(2) - 1);
    match (omega.get(k - 1), omega.get(k)) {
        (Some(&w0), Some(&w1)) if w1 > w0 => {
            let t = (w.ln() - w0.ln()) / (w1.ln() - w0.ln());
            values[k - 1] + t * (values[k] - values[k - 1])
        }
        _ => values.first().copied().unwrap_or(f64::NAN),
    }
}

/// Write the loops' Bode diagrams to `file` (`.png` or `.svg`): for each, a magnitude and a
/// phase panel of 1000 × 230 pixels against ω (`omega_label`, e.g. `ω [rad/min]`).
pub fn write_bode(file: &Path, title: &str, omega_label: &str, loops: &[BodeLoop]) -> Result<(), IoError> {
    let legend_w =
        legend_width(loops.iter().flat_map(legend).map(|(n, _)| n).collect::<Vec<_>>().iter().map(String::as_str));
    let height = 60 + 490 * loops.len().max(1) as u32;
    write_figure(file, (1000 + legend_w, height), &Bode { title, omega_label, loops, legend_w })
}

struct Bode<'a> {
    title: &'a str,
    omega_label: &'a str,
    loops: &'a [BodeLoop],
    legend_w: u32,
}

/// The style of the gain-crossover marks.
const CROSSOVER: CurveStyle = CurveStyle { colour: COLOURS[2], width: 1, dash: Some((5, 4)), marker: Marker::None };
/// The style of the phase-crossover marks.
const PHASE_CROSSOVER: CurveStyle =
    CurveStyle { colour: COLOURS[1], width: 1, dash: Some((5, 4)), marker: Marker::None };
/// The style of the curves.
const CURVE: CurveStyle = CurveStyle { colour: COLOURS[0], width: 2, dash: None, marker: Marker::None };

/// A loop's legend: its curve, and each crossover with its margin.
fn legend(l: &BodeLoop) -> Vec<(String, Sample)> {
    let mut entries = vec![(l.label.clone(), Sample::Line(CURVE))];
    if let Some((w, pm)) = l.gain_crossover {
        let text = format!("gain crossover ω = {}: |L| = 0 dB, PM {pm:.1}°", number(w));
        entries.push((text, Sample::Line(CROSSOVER)));
    }
    if let Some((w, gm)) = l.phase_crossover {
        let (db, gm) = (20.0 * gm.log10(), number(gm));
        let text = format!("phase crossover ω = {}: ∠L = −180°, GM {gm} ({db:.1} dB)", number(w));
        entries.push((text, Sample::Line(PHASE_CROSSOVER)));
    }
    if l.phase_crossover.is_none() {
        entries.push(("GM ∞: the phase does not reach −180° where |L| < 1".into(), Sample::Note));
    }
    entries
}

/// `v` to four significant digits, without trailing zeros.
fn number(v: f64) -> String {
    let decimals = (3.0 - v.abs().log10().floor()).clamp(0.0, 12.0) as usize;
    let rounded = format!("{v:.decimals$}");
    rounded.parse::<f64>().map_or(rounded, |x| x.to_string())
}

/// The range of `values` with `extra`, padded by 8 %.
fn padded(values: &[f64], extra: f64) -> (f64, f64) {
    let finite = values.iter().copied().chain([extra]).filter(|v| v.is_finite());
    let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    let pad = 0.08 * (hi - lo).max(1.0);
    (lo - pad, hi + pad)
}

impl Bode<'_> {
    /// One panel of loop `l`: `values` against ω, the horizontal line at `critical` (0 dB or
    /// −180°), the crossovers as vertical lines, and the margin `at_omega` drawn as a gap.
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        l: &BodeLoop,
        (values, desc): (&[f64], &str),
        critical: f64,
        margin_at: Option<f64>,
    ) -> Result<(), IoError> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| IoError::Draw(e.to_string());
        let (w0, w1) = (l.omega.first().copied().unwrap_or(1e-3), l.omega.last().copied().unwrap_or(1.0));
        let (lo, hi) = padded(values, critical);
        let mut chart = ChartBuilder::on(area)
            .margin(10)
            .margin_right(25)
            .x_label_area_size(35)
            .y_label_area_size(80)
            .build_cartesian_2d((w0..w1.max(w0 * 10.0)).log_scale(), lo..hi)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(self.omega_label)
            .y_desc(desc)
            .axis_desc_style(("sans-serif", 15))
            .x_label_formatter(&|v| number(*v))
            .y_label_formatter(&|v| format!("{v:.0}"))
            .draw()
            .map_err(err)?;
        draw_curve(&mut chart, &[(w0, critical), (w1, critical)], &CurveStyle::dashed(GREY, (2, 3)), (0, 1))?;
        let marks = [(l.gain_crossover, CROSSOVER), (l.phase_crossover, PHASE_CROSSOVER)];
        for (w, style) in marks.iter().filter_map(|(c, s)| c.map(|c| (c.0, s))) {
            draw_curve(&mut chart, &[(w, lo), (w, hi)], style, (0, 1))?;
        }
        let points: Vec<(f64, f64)> = l.omega.iter().copied().zip(values.iter().copied()).collect();
        draw_curve(&mut chart, &points, &CURVE, (0, 1))?;
        if let Some(w) = margin_at {
            let v = at(&l.omega, values, w);
            let gap = BLACK.stroke_width(3);
            chart.draw_series([PathElement::new(vec![(w, critical), (w, v)], gap)]).map_err(err)?;
            chart.draw_series([Circle::new((w, v), 4, BLACK.filled())]).map_err(err)?;
        }
        Ok(())
    }
}

impl Figure for Bode<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), IoError> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| IoError::Draw(e.to_string());
        root.fill(&WHITE).map_err(err)?;
        let root = titled(&root, self.title, 24.0)?;
        for (area, l) in root.split_evenly((self.loops.len().max(1), 1)).iter().zip(self.loops) {
            let l = &l.within_a_turn();
            let (w, h) = area.dim_in_pixel();
            let (plots, legend_area) = area.split_horizontally(w.saturating_sub(self.legend_w));
            let halves = plots.split_evenly((2, 1));
            let magnitude = (l.magnitude_db.as_slice(), "|L| [dB]");
            self.panel(&halves[0], l, magnitude, 0.0, l.phase_crossover.map(|c| c.0))?;
            let phase = (l.phase_deg.as_slice(), "∠L [deg]");
            self.panel(&halves[1], l, phase, l.critical_phase(), l.gain_crossover.map(|c| c.0))?;
            draw_legend(&legend_area, &legend(l), &[], h as i32 - 45)?;
        }
        root.present().map_err(err)
    }
}
