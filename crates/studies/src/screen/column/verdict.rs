//! Ranks and verdicts of a column's configurations: by the steady state (the relative gain of the
//! recommended pairing closest to 1, then γ*), and by the dynamic check (scaled IAE) when it ran;
//! each configuration's verdict says what its numbers say and where the tool's own evidence
//! contradicts its recommendation, and the screen's verdict says what the recommendation rests on.

use super::ColumnStructure;

/// How far apart two scaled IAEs must be for the dynamic check to contradict the steady-state
/// order: the configuration the steady state puts behind has less than half the other's.
const CONTRADICTION: f64 = 0.5;

/// `steady_rank` of the regular configurations (a recommended pairing, not failed): the relative
/// gain `λ` of the recommended pairing closest to 1 (by `|ln λ|`; Skogestad & Morari 1987: large
/// relative gains mean strong interaction and sensitivity to input uncertainty), then γ*.
pub(super) fn rank_steady(structures: &mut [ColumnStructure]) {
    let score = |s: &ColumnStructure| {
        let l = s.relative_gain.map_or(f64::INFINITY, |l| if l > 0.0 { l.ln().abs() } else { f64::INFINITY });
        (l, s.minimized_condition_number.unwrap_or(f64::INFINITY))
    };
    let mut order: Vec<usize> = (0..structures.len())
        .filter(|&k| structures[k].relative_gain.is_some() && structures[k].failure.is_none())
        .collect();
    order.sort_by(|&a, &b| {
        score(&structures[a]).partial_cmp(&score(&structures[b])).unwrap_or(std::cmp::Ordering::Equal)
    });
    for (place, k) in order.into_iter().enumerate() {
        structures[k].steady_rank = Some(place + 1);
    }
}

/// `rank`: by scaled IAE when the dynamic check ran (a configuration whose check failed is not
/// ranked), else the steady rank.
pub(super) fn rank(structures: &mut [ColumnStructure], dynamic: bool) {
    if !dynamic {
        structures.iter_mut().for_each(|s| s.rank = s.steady_rank);
        return;
    }
    let mut order: Vec<usize> = (0..structures.len()).filter(|&k| structures[k].iae_scaled.is_some()).collect();
    order.sort_by(|&a, &b| {
        let key = |s: &ColumnStructure| (s.iae_scaled.unwrap_or(f64::INFINITY), s.steady_rank);
        key(&structures[a]).partial_cmp(&key(&structures[b])).unwrap_or(std::cmp::Ordering::Equal)
    });
    for (place, k) in order.into_iter().enumerate() {
        structures[k].rank = Some(place + 1);
    }
}

/// Write each regular configuration's verdict and return the screen's.
pub(super) fn judge(structures: &mut [ColumnStructure], dynamic: bool) -> String {
    let words: Vec<Option<String>> = structures.iter().map(|s| configuration(s, structures, dynamic)).collect();
    for (s, w) in structures.iter_mut().zip(words) {
        if let Some(w) = w {
            s.verdict = w;
        }
    }
    overall(structures, dynamic)
}

/// The recommended pairing in words.
fn pairing(s: &ColumnStructure) -> String {
    let p = s.pairing.as_deref().unwrap_or_default();
    match p {
        [top, bottom] => format!("pair the top quality with {top} and the bottom quality with {bottom}"),
        _ => String::new(),
    }
}

/// What the steady-state measures say of `s`: its recommended pairing and the interaction.
fn steady_words(s: &ColumnStructure) -> Option<String> {
    let (l11, lambda) = (s.rga.as_ref()?[0][0], s.relative_gain?);
    let pair = pairing(s);
    let why = match l11 {
        l if l < 0.0 => {
            format!("λ11 = {l:.3} < 0: the diagonal pairing is not integral controllable; {pair} (λ = {lambda:.3})")
        }
        l if l < 0.5 => format!("λ11 = {l:.3}: the diagonal pairing is the weak one; {pair} (λ = {lambda:.3})"),
        l => format!("λ11 = {l:.3}: {pair}"),
    };
    let interaction = match lambda {
        l if l <= 2.0 => "little interaction",
        l if l <= 10.0 => "moderate interaction; detune the loops together (BLT)",
        _ => {
            "strong interaction; the loops fight and the large relative gains make the column sensitive to input \
             uncertainty (Skogestad & Morari 1987)"
        }
    };
    Some(format!("{why}; {interaction}"))
}

/// The verdict of a regular configuration `s` among `all` (`None`: singular or failed at steady
/// state, whose verdict stands).
fn configuration(s: &ColumnStructure, all: &[ColumnStructure], dynamic: bool) -> Option<String> {
    let mut text = steady_words(s)?;
    if !dynamic {
        return Some(text);
    }
    let Some(d) = s.dynamic.as_ref() else { return Some(text) };
    let Some(iae) = s.iae_scaled else {
        text.push_str(match s.lost {
            Some(_) => "; dynamic check: cannot ride through the disturbances (see lost); not ranked",
            None => "; dynamic check failed (see failure); not ranked",
        });
        return Some(text);
    };
    let best = all.iter().filter_map(|o| o.iae_scaled).fold(f64::INFINITY, f64::min);
    text.push_str(&match s.rank {
        Some(1) => format!("; dynamic check: the smallest scaled IAE ({iae:.4e} s)"),
        _ => format!("; dynamic check: scaled IAE {iae:.4e} s, {:.2}× the best", iae / best),
    });
    let mut saturated: Vec<&str> = d.runs.iter().flat_map(|r| r.saturated.iter().map(String::as_str)).collect();
    saturated.sort_unstable();
    saturated.dedup();
    if !saturated.is_empty() {
        text.push_str(&format!("; {} reached a limit ([0, 2u₀]) in a run", saturated.join(" and ")));
    }
    let steady = s.steady_rank.unwrap_or(usize::MAX);
    let behind: Vec<String> = all
        .iter()
        .filter(|o| o.steady_rank.is_some_and(|r| r > steady))
        .filter_map(|o| Some((o, o.iae_scaled?)))
        .filter(|(_, v)| *v < CONTRADICTION * iae)
        .map(|(o, v)| format!("{} ({:.2}× less)", o.name, iae / v))
        .collect();
    if !behind.is_empty() {
        text.push_str(&format!(
            "; CONTRADICTED by the dynamic check: the steady-state measures put it ahead of {}, whose scaled IAE \
             is less than half its own",
            behind.join(", ")
        ));
    }
    Some(text)
}

/// The recommendation and what it rests on.
fn overall(structures: &[ColumnStructure], dynamic: bool) -> String {
    let by = |f: fn(&ColumnStructure) -> Option<usize>| structures.iter().find(|s| f(s) == Some(1));
    let Some(best) = by(|s| s.rank) else {
        return "no configuration recommended: none is regular, or every dynamic check failed or lost the plant".into();
    };
    let lambda = best.relative_gain.unwrap_or(f64::NAN);
    if !dynamic {
        return format!(
            "recommended: {} ({}, λ = {lambda:.3}) — ranked by steady-state λ11 only; the dynamic check was not run \
             (the recommended pairing's relative gain is the closest to 1, γ* breaks ties)",
            best.name,
            pairing(best)
        );
    }
    let checked = structures.iter().filter(|s| s.iae_scaled.is_some()).count();
    let steps = best.dynamic.as_ref().map_or(0, |d| d.runs.len());
    let mut text = format!(
        "recommended: {} ({}, λ = {lambda:.3}) — the smallest scaled IAE ({:.4e} s) of {checked} configuration{} \
         tuned by BLT and stepped by {steps} disturbance{} on the nonlinear plant",
        best.name,
        pairing(best),
        best.iae_scaled.unwrap_or(f64::NAN),
        if checked == 1 { "" } else { "s" },
        if steps == 1 { "" } else { "s" }
    );
    let unranked = |lost: bool| -> Vec<&str> {
        let out = structures.iter().filter(|s| s.dynamic.is_some() && s.iae_scaled.is_none());
        out.filter(|s| s.lost.is_some() == lost).map(|s| s.name.as_str()).collect()
    };
    let (lost, failed) = (unranked(true), unranked(false));
    if !lost.is_empty() {
        text.push_str(&format!(
            "; not ranked: {} cannot ride through the disturbances (the plant left its operating range, see lost)",
            lost.join(", ")
        ));
    }
    if !failed.is_empty() {
        text.push_str(&format!("; not compared: {} (dynamic check failed, see failed)", failed.join(", ")));
    }
    if let Some(first) = by(|s| s.steady_rank).filter(|f| f.name != best.name) {
        let dynamic = match (first.rank, first.iae_scaled, best.iae_scaled) {
            (Some(r), Some(v), Some(b)) => format!("ranks {r} (scaled IAE {:.2}× the best)", v / b),
            _ if first.lost.is_some() => "finds cannot ride through the disturbances".to_string(),
            _ => "could not run".to_string(),
        };
        text.push_str(&format!(
            "; the evidence disagrees: the steady-state measures alone would recommend {} (λ = {:.3}), which the \
             dynamic check {dynamic}; the ranking follows the dynamic check",
            first.name,
            first.relative_gain.unwrap_or(f64::NAN)
        ));
    }
    text
}
