//! The comparison's verdict: one paragraph an engineer reads first, built from the comparison's
//! own evidence and nothing else — the utility cost of each scheme, the modes that make one
//! depend on its loops, a pairing that fails integrity, the closed-loop responses scheme against
//! scheme, the runs a scheme could not ride through, and the parts that failed. It recommends no scheme its evidence contradicts: where the
//! cheapest scheme is not the one that rejects the disturbances best, it says the choice is a
//! trade-off and gives both sides in figures.

use super::{Comparison, Scheme};
use crate::screen::pairings::dynamic::DynamicResult;

/// Relative difference in utility cost under which two schemes cost the same.
const SAME_COST: f64 = 0.005;

/// Relative difference in IAE under which two schemes' responses are alike. The runs are
/// integrated to a relative tolerance of 1e-6, and the IAE of a small response over a long run
/// sums that error over the whole run: the built-in CSTR and its `equations` twin (one plant,
/// other states) differ by 1.2e-3 in the IAE of T after a −5 K coolant step (60.3 K·s over
/// 40 000 s). A 1 % difference is no evidence that one scheme rejects a disturbance better.
const SAME_IAE: f64 = 1e-2;

/// The verdict on `c`, one paragraph.
pub fn verdict(c: &Comparison) -> String {
    let mut parts: Vec<String> = Vec::new();
    let cheapest = energy(c, &mut parts);
    stability(c, &mut parts);
    structure(c, &mut parts);
    let responses = Responses::of(c);
    if let Some(r) = &responses {
        parts.push(r.sentence(c));
    }
    let lost: Vec<String> =
        c.schemes.iter().flat_map(|s| s.tests().into_iter().flat_map(|(label, d)| d.losses(&label))).collect();
    if !lost.is_empty() {
        parts.push(format!(
            "The plant left its operating range (a vessel ran dry or overflowed, a flow would reverse) in {}: that \
             scheme cannot ride through that disturbance, and its figures there are left out.",
            lost.join("; ")
        ));
    }
    if !c.failed.is_empty() {
        parts.push(format!(
            "{} part{} of the comparison failed (listed under \"failed\"): what follows rests on the rest.",
            c.failed.len(),
            if c.failed.len() == 1 { "" } else { "s" }
        ));
    }
    parts.push(conclusion(c, cheapest, responses.as_ref()));
    let losers: Vec<&str> = c
        .schemes
        .iter()
        .filter(|s| s.tests().iter().any(|(_, d)| !d.losses("").is_empty()))
        .map(|s| s.name.as_str())
        .collect();
    if !losers.is_empty() {
        parts.push(format!(
            "Whatever the figures above, {} cannot ride through every disturbance asked for.",
            losers.join(" and ")
        ));
    }
    // A scheme compared with itself says its findings once.
    parts.dedup();
    parts.join(" ")
}

/// The cost sentence; the cheapest scheme, unless all cost the same.
fn energy(c: &Comparison, parts: &mut Vec<String>) -> Option<usize> {
    let costs: Vec<f64> = c.schemes.iter().map(|s| s.cost.total).collect();
    let (lo, hi) = costs.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let p = &c.prices;
    let basis = format!("heating at {} $/GJ, cooling at {} $/GJ, {} h/yr", p.heating, p.cooling, p.hours);
    let uncosted: Vec<&str> = c.schemes.iter().flat_map(|s| &s.cost.uncosted).map(String::as_str).collect();
    let uncosted = match uncosted.is_empty() {
        true => String::new(),
        false => format!(" Not costed (no duty in the model): {}.", uncosted.join(", ")),
    };
    if hi - lo <= SAME_COST * hi {
        parts.push(format!("The schemes cost the same in utilities, {}/yr ({basis}).{uncosted}", money(hi)));
        return None;
    }
    let k = costs.iter().position(|&v| v == lo)?;
    let others: Vec<String> = c
        .schemes
        .iter()
        .enumerate()
        .filter(|&(j, _)| j != k)
        .map(|(_, s)| format!("{} {}/yr", s.name, money(s.cost.total)))
        .collect();
    parts.push(format!(
        "{} costs the least in utilities, {}/yr against {} ({basis}): {}/yr less than the dearest.{uncosted}",
        c.schemes[k].name,
        money(lo),
        others.join(", "),
        money(hi - lo)
    ));
    Some(k)
}

/// A sentence per scheme that is unstable with its quality loops in manual.
fn stability(c: &Comparison, parts: &mut Vec<String>) {
    for s in c.schemes.iter().filter(|s| s.stability.open_loop_unstable) {
        let fastest = s.stability.open_loop.unstable.iter().map(|m| m[0]).fold(0.0, f64::max);
        let doubling = if fastest > 0.0 {
            format!(", a deviation doubling every {:.3} min", std::f64::consts::LN_2 / fastest / 60.0)
        } else {
            " (integrating)".to_string()
        };
        parts.push(format!(
            "{} is unstable with its quality loops in manual (growth rate {fastest:.4e} 1/s{doubling}): its loops \
             must stay in auto, and their trip needs an interlock.",
            s.name
        ));
    }
}

/// A sentence per scheme whose pairing fails integrity (Niederlinski index ≤ 0 or not DIC).
fn structure(c: &Comparison, parts: &mut Vec<String>) {
    for s in &c.schemes {
        let Some(t) = &s.structure else { continue };
        if t.pairs.len() > 1 && (t.niederlinski <= 0.0 || !t.dic) {
            parts.push(format!(
                "{}'s pairing fails integrity (Niederlinski index {:.4}{}): a loop put in manual can destabilize \
                 the others.",
                s.name,
                t.niederlinski,
                if t.dic { "" } else { ", not decentralized integral controllable" }
            ));
        }
    }
}

/// The closed-loop responses scheme against scheme: per scheme, the responses (a disturbance
/// and a variable all schemes ran) in which its IAE is the least, and its largest IAE relative
/// to the best one's, with where.
struct Responses {
    /// Responses compared.
    n: usize,
    /// Per scheme: responses won (its IAE within [`SAME_IAE`] of the least).
    wins: Vec<usize>,
    /// Per scheme: the largest ratio of its IAE to the least, the variable and the disturbance.
    worst: Vec<(f64, String, String)>,
}

impl Responses {
    fn of(c: &Comparison) -> Option<Responses> {
        let runs: Vec<&DynamicResult> = c.schemes.iter().map(Scheme::runs).collect::<Option<_>>()?;
        if runs.len() < 2 {
            return None;
        }
        let mut r =
            Responses { n: 0, wins: vec![0; runs.len()], worst: vec![(1.0, String::new(), String::new()); runs.len()] };
        for (d, first) in runs[0].runs.iter().enumerate() {
            for v in &first.cvs {
                let iae: Option<Vec<f64>> = runs
                    .iter()
                    .map(|t| {
                        let run = t.runs.get(d).filter(|r| r.failure.is_none() && r.lost.is_none())?;
                        run.cvs.iter().find(|f| f.cv == v.cv).map(|f| f.iae)
                    })
                    .collect();
                let Some(iae) = iae else { continue };
                let best = iae.iter().copied().fold(f64::INFINITY, f64::min);
                if !(best.is_finite() && best > 0.0) {
                    continue;
                }
                r.n += 1;
                for (s, &e) in iae.iter().enumerate() {
                    if e <= best * (1.0 + SAME_IAE) {
                        r.wins[s] += 1;
                    }
                    if e / best > r.worst[s].0 {
                        r.worst[s] = (e / best, v.cv.clone(), first.disturbance.clone());
                    }
                }
            }
        }
        (r.n > 0).then_some(r)
    }

    /// The schemes with the most responses won, the one with the smaller worst ratio first.
    fn leaders(&self) -> Vec<usize> {
        let most = self.wins.iter().copied().max().unwrap_or(0);
        let mut l: Vec<usize> = (0..self.wins.len()).filter(|&s| self.wins[s] == most).collect();
        l.sort_by(|&a, &b| self.worst[a].0.total_cmp(&self.worst[b].0));
        l
    }

    fn sentence(&self, c: &Comparison) -> String {
        let each: Vec<String> = (0..self.wins.len())
            .map(|s| {
                let (ratio, var, dist) = &self.worst[s];
                let worst = if *ratio > 1.0 + SAME_IAE {
                    format!(", at worst {ratio:.2}× the least ({var}, {dist})")
                } else {
                    String::new()
                };
                format!("{} has the least IAE in {} of {}{worst}", c.schemes[s].name, self.wins[s], self.n)
            })
            .collect();
        format!("In the closed-loop responses (each disturbance, each variable), {}.", each.join("; "))
    }
}

/// The closing sentence: one scheme better on both counts, or the trade-off in figures.
fn conclusion(c: &Comparison, cheapest: Option<usize>, responses: Option<&Responses>) -> String {
    let Some(r) = responses else {
        return match cheapest {
            Some(k) => format!(
                "Without closed-loop responses of every scheme to weigh against it, the evidence is {}'s lower cost alone.",
                c.schemes[k].name
            ),
            None => "Without closed-loop responses of every scheme, nothing here tells the schemes apart.".into(),
        };
    };
    let leaders = r.leaders();
    let name = |k: usize| c.schemes[k].name.as_str();
    let names: Vec<&str> = leaders.iter().map(|&k| name(k)).collect();
    match cheapest {
        None if leaders.len() == c.schemes.len() => {
            "The schemes cost the same and reject these disturbances alike: nothing here tells them apart.".into()
        }
        None if leaders.len() > 1 => format!(
            "At the same cost, {} reject these disturbances best, alike (the least IAE in {} of {} each).",
            names.join(" and "),
            r.wins[leaders[0]],
            r.n
        ),
        None => format!("At the same cost, {} is the better scheme: it rejects these disturbances best.", names[0]),
        Some(k) if leaders.contains(&k) => format!(
            "{} is the better scheme on both counts: the cheapest to run and {} at rejecting these disturbances{}.",
            name(k),
            if leaders.len() > 1 { "among the best" } else { "the best" },
            if c.schemes[k].stability.open_loop_unstable { ", provided its loops stay in auto" } else { "" }
        ),
        Some(k) => {
            let best = leaders[0];
            let saving = c.schemes[best].cost.total - c.schemes[k].cost.total;
            let (ratio, var, dist) = &r.worst[k];
            format!(
                "The choice is a trade-off: {} saves {}/yr over {}, which rejects the disturbances better ({}'s IAE is \
                 up to {ratio:.2}× the least, on {var} at {dist}); weigh the saving against that loss of control, or \
                 close it (tighter tuning, a feedforward, surge capacity).",
                name(k),
                money(saving),
                name(best),
                name(k)
            )
        }
    }
}

/// Dollars for a sentence: `$245k`, `$1.23M`, `$812`.
fn money(v: f64) -> String {
    match v.abs() {
        a if a >= 1e6 => format!("${:.3}M", v / 1e6),
        a if a >= 1e3 => format!("${:.1}k", v / 1e3),
        _ => format!("${v:.0}"),
    }
}
