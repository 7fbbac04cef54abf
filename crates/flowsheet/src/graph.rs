//! The flowsheet as a petgraph directed graph of units (streams as edges) and its recycles.

use petgraph::algo::tarjan_scc;
use petgraph::graph::DiGraph;

use crate::plant::{BlockKind, Plant};

impl Plant {
    /// The unit graph: one node per process unit (block index as weight), one edge per stream
    /// (stream index as weight).
    pub fn unit_graph(&self) -> DiGraph<usize, usize> {
        let mut g = DiGraph::new();
        let mut node = vec![None; self.blocks.len()];
        for (bi, b) in self.blocks.iter().enumerate() {
            if b.kind == BlockKind::Unit {
                node[bi] = Some(g.add_node(bi));
            }
        }
        for (si, s) in self.streams.iter().enumerate() {
            if let (Some(a), Some(b)) = (node[s.from.0], node[s.to.0]) {
                g.add_edge(a, b, si);
            }
        }
        g
    }

    /// Recycles: strongly connected components with more than one unit (or a unit feeding
    /// itself), as lists of unit names in precedence order of the components.
    pub fn recycles(&self) -> Vec<Vec<String>> {
        let g = self.unit_graph();
        let mut sccs = tarjan_scc(&g);
        sccs.reverse();
        sccs.into_iter()
            .filter(|c| c.len() > 1 || g.contains_edge(c[0], c[0]))
            .map(|c| {
                let mut names: Vec<(usize, String)> =
                    c.iter().map(|&n| (g[n], self.blocks[g[n]].name.clone())).collect();
                names.sort();
                names.into_iter().map(|(_, n)| n).collect()
            })
            .collect()
    }
}
