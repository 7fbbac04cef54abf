//! The sequential-modular plan: solve groups, their graph with streams and signals as edges, and
//! its SCCs in precedence order with tears and calculation order.

use petgraph::graph::{DiGraph, NodeIndex};
use plantwide_flowsheet::Plant;
use plantwide_flowsheet::tears::{Connection, Scc, decompose};

use super::groups::{GroupLayout, SolveGroup, solve_groups};
use crate::structure::maximum_matching;

/// The sequential-modular structure of a plant: solve groups, their graph, and its SCCs in
/// precedence order with tears and calculation order.
#[derive(Debug, Clone)]
pub struct SequentialPlan {
    /// Solve groups; node weights of `graph` index them.
    pub groups: Vec<SolveGroup>,
    /// Groups as nodes; streams and signals between groups as edges.
    pub graph: DiGraph<usize, Connection>,
    /// SCCs of `graph` in precedence order.
    pub sccs: Vec<Scc>,
}

impl SequentialPlan {
    /// Name of the group at graph node `v`.
    pub fn node_name(&self, plant: &Plant, v: NodeIndex) -> String {
        self.groups[self.graph[v]].name(plant)
    }
    /// Torn variables of `scc` (global indices, ascending, without repeats).
    pub fn tear_vars(&self, scc: &Scc) -> Vec<usize> {
        let mut v: Vec<usize> = scc.tears.iter().flat_map(|&e| self.graph[e].vars.iter().copied()).collect();
        v.sort_unstable();
        v.dedup();
        v
    }
    /// Names of the torn connections of `scc`.
    pub fn tear_names(&self, plant: &Plant, scc: &Scc) -> Vec<String> {
        scc.tears.iter().map(|&e| self.graph[e].name(plant)).collect()
    }
    /// Recycle SCCs (those with tears), in precedence order.
    pub fn recycles(&self) -> impl Iterator<Item = &Scc> {
        self.sccs.iter().filter(|s| s.is_recycle())
    }
}

/// The sequential-modular plan of `plant`: solve groups (checked for structural singularity at
/// `x` and, if needed, merged with their SCC), their graph and its torn SCCs.
pub fn plan(plant: &Plant, u: &[f64], x: &[f64]) -> SequentialPlan {
    let mut groups = solve_groups(plant);
    let mut r = vec![0.0; plant.n_eqs()];
    let (mut jx, mut ju) = (Vec::new(), Vec::new());
    plant.jacobian(x, u, 0.0, &mut r, &mut jx, &mut ju);
    loop {
        let members: Vec<Vec<usize>> = groups.iter().map(|g| g.blocks.clone()).collect();
        let graph = plant.group_graph(&members);
        let sccs = decompose(&graph);
        let singular = first_singular(plant, &groups, &jx);
        let Some(bad) = singular else { return SequentialPlan { groups, graph, sccs } };
        let node = graph.node_indices().find(|&v| graph[v] == bad).expect("every group is a node");
        let scc = sccs.iter().find(|s| s.order.contains(&node)).expect("every node is in an SCC");
        let mut join: Vec<usize> = if scc.order.len() > 1 {
            scc.order.iter().map(|&v| graph[v]).collect()
        } else {
            graph.neighbors_undirected(node).map(|v| graph[v]).chain([bad]).collect()
        };
        join.sort_unstable();
        join.dedup();
        if join.len() < 2 {
            // Nothing left to merge with: the whole-plant DOF check explains the plant.
            return SequentialPlan { groups, graph, sccs };
        }
        let why = format!(
            "`{}` is structurally singular alone (some of its variables are set by no equation of its own)",
            groups[bad].name(plant)
        );
        let mut merged = SolveGroup { blocks: Vec::new(), reasons: vec![why] };
        for &g in &join {
            merged.blocks.extend(&groups[g].blocks);
            merged.reasons.extend(groups[g].reasons.iter().cloned());
        }
        merged.blocks.sort_unstable();
        let mut rest: Vec<SolveGroup> =
            groups.into_iter().enumerate().filter(|(i, _)| !join.contains(i)).map(|(_, g)| g).collect();
        rest.push(merged);
        rest.sort_by_key(|g| g.blocks[0]);
        groups = rest;
    }
}

/// The first group whose equations cannot be matched one-to-one with its own variables. One pass
/// over the Jacobian's entries buckets those that lie inside a group (equation and variable both
/// its own), then each group is matched alone: linear in the plant's size, whatever the number of
/// groups.
fn first_singular(plant: &Plant, groups: &[SolveGroup], jx: &[(usize, usize, f64)]) -> Option<usize> {
    let blocks = plant.blocks();
    // For each block: its group, and the first local row and column of the block in that group.
    let mut at = vec![(usize::MAX, 0, 0); blocks.len()];
    let mut sizes = Vec::with_capacity(groups.len());
    for (gi, g) in groups.iter().enumerate() {
        let layout = GroupLayout::new(plant, &g.blocks);
        for (k, &b) in g.blocks.iter().enumerate() {
            at[b] = (gi, layout.row0[k], layout.col0[k]);
        }
        sizes.push((layout.n_rows(plant), layout.unknowns.len()));
    }
    let mut eq_block = vec![0; plant.n_eqs()];
    for (bi, b) in blocks.iter().enumerate() {
        eq_block[b.eq_offset..b.eq_offset + b.n_eq].fill(bi);
    }
    let mut entries: Vec<Vec<(usize, usize)>> = vec![Vec::new(); groups.len()];
    for &(i, j, _) in jx {
        let (bi, bj) = (eq_block[i], plant.vars()[j].block);
        let ((gi, row0, _), (gj, _, col0)) = (at[bi], at[bj]);
        if gi == gj && gi != usize::MAX {
            entries[gi].push((row0 + i - blocks[bi].eq_offset, col0 + j - blocks[bj].own_offset));
        }
    }
    (0..groups.len()).find(|&g| {
        let (rows, n) = sizes[g];
        rows != n || maximum_matching(n, n, &entries[g]).size() != n
    })
}
