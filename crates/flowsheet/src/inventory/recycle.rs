//! The recycle rule (Aske & Skogestad 2009): a recycle loop's total inventory is controlled only
//! by a flow into or out of the loop that an inventory inside it sets.

use std::collections::{BTreeSet, HashMap, HashSet};

use petgraph::Direction as Edge;

use super::network::{Flow, Network, Origin};
use super::{Reach, RecycleVerdict, origin_name};

/// Each recycle loop that holds an inventory, judged by the recycle rule.
pub(super) fn recycles(
    net: &Network<'_>,
    reach: &Reach,
    origins: &HashMap<Flow, BTreeSet<Origin>>,
) -> Vec<RecycleVerdict> {
    let g = &reach.graph;
    let mut sccs = petgraph::algo::tarjan_scc(g);
    sccs.reverse();
    let mut out = Vec::new();
    for scc in sccs.into_iter().filter(|c| c.len() > 1 || g.contains_edge(c[0], c[0])) {
        let blocks: BTreeSet<usize> = scc.iter().map(|&n| g[n]).collect();
        let inside: Vec<usize> =
            (0..net.inventories.len()).filter(|&k| blocks.contains(&net.inventories[k].block)).collect();
        if inside.is_empty() {
            continue;
        }
        out.push(recycle(net, reach, &blocks, &inside, origins));
    }
    out
}

/// One recycle loop (`blocks`, holding inventories `inside`): consistent if a flow across it is
/// set by an inventory inside it.
fn recycle(
    net: &Network<'_>,
    reach: &Reach,
    blocks: &BTreeSet<usize>,
    inside: &[usize],
    origins: &HashMap<Flow, BTreeSet<Origin>>,
) -> RecycleVerdict {
    let streams = net.plant.streams();
    let across: Vec<usize> = (0..streams.len())
        .filter(|&s| blocks.contains(&streams[s].from.0) != blocks.contains(&streams[s].to.0))
        .collect();
    let entry = across.iter().map(|&s| streams[s].to.0).find(|b| blocks.contains(b));
    let name = cycle_name(net, reach, blocks, entry);
    let set_inside = |s: &usize| {
        origins
            .get(&Flow::Stream(*s))
            .is_some_and(|o| o.iter().any(|o| matches!(o, Origin::Inventory(k) if inside.contains(k))))
    };
    if across.iter().any(set_inside) {
        return RecycleVerdict { recycle: name, consistent: true, why: None };
    }
    let why = if across.is_empty() {
        format!(
            "the recycle loop {name} is closed: no stream enters or leaves it, so its total inventory is its initial \
             charge and its inventory loops cannot all hold their setpoints"
        )
    } else {
        across_why(net, &name, &across, origins)
    };
    RecycleVerdict { recycle: name, consistent: false, why: Some(why) }
}

/// Why recycle `name`, whose flows `across` no inventory inside it sets, is not consistent: what
/// sets each of them, and whether quality loops among those could hold its total inventory
/// indirectly (consistent at best, not self-consistent).
fn across_why(net: &Network<'_>, name: &str, across: &[usize], origins: &HashMap<Flow, BTreeSet<Origin>>) -> String {
    let streams = net.plant.streams();
    let mut quality = BTreeSet::new();
    let list: Vec<String> = across
        .iter()
        .map(|&s| {
            let o: Vec<&Origin> = origins.get(&Flow::Stream(s)).map(|o| o.iter().collect()).unwrap_or_default();
            quality.extend(o.iter().filter_map(|o| match o {
                Origin::Controller(c) => Some(net.plant.blocks()[*c].name.clone()),
                _ => None,
            }));
            let by: Vec<String> = o.iter().map(|o| origin_name(net, o)).collect();
            let by = if by.is_empty() { "nothing declared".to_string() } else { by.join(" and ") };
            format!("{} by {by}", streams[s].name)
        })
        .collect();
    let held = if quality.is_empty() {
        "nothing holds its total inventory".to_string()
    } else {
        format!(
            "its total inventory is held, if at all, only indirectly by {} (not self-consistent)",
            quality.into_iter().collect::<Vec<_>>().join(", ")
        )
    };
    format!(
        "the recycle loop {name} has no flow into or out of it set by an inventory inside it, only flows inside it \
         (flows across it: {}): {held}",
        list.join(", ")
    )
}

/// A cycle of a recycle through `entry` (where material enters it; else its first unit),
/// `a→b→c→a`, with the recycle's other units after it.
fn cycle_name(net: &Network<'_>, reach: &Reach, blocks: &BTreeSet<usize>, entry: Option<usize>) -> String {
    let g = &reach.graph;
    let name = |b: usize| net.plant.blocks()[b].name.clone();
    let Some(start) = entry.or_else(|| blocks.first().copied()) else { return String::new() };
    // Breadth-first from the start's successors back to the start, within the recycle.
    let mut parent: HashMap<usize, usize> = HashMap::new();
    let mut queue = std::collections::VecDeque::from([start]);
    let mut seen = HashSet::from([start]);
    let mut last = None;
    'search: while let Some(b) = queue.pop_front() {
        for n in g.neighbors_directed(reach.node[&b], Edge::Outgoing) {
            let next = g[n];
            if next == start {
                last = Some(b);
                break 'search;
            }
            if blocks.contains(&next) && seen.insert(next) {
                parent.insert(next, b);
                queue.push_back(next);
            }
        }
    }
    let mut path = vec![start];
    let mut at = last;
    while let Some(b) = at.filter(|&b| b != start) {
        path.push(b);
        at = parent.get(&b).copied();
    }
    path[1..].reverse();
    path.push(start);
    let mut text = path.iter().map(|&b| name(b)).collect::<Vec<_>>().join("→");
    let others: Vec<String> = blocks.iter().filter(|b| !path.contains(b)).map(|&b| name(b)).collect();
    if !others.is_empty() {
        text.push_str(&format!(" (with {})", others.join(", ")));
    }
    text
}
