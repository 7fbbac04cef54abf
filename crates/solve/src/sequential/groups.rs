//! Solve groups: the blocks that one local Newton solves together, and that Newton's system.
//!
//! A block is solved alone when its equations determine its own variables with everything it
//! reads held fixed. Three kinds of blocks cannot be, and are grouped:
//! 1. **Non-square units.** A vessel with a `free` outflow owns its outlet flow without an equation
//!    for it; the valve behind it writes that equation (one more than it owns). A unit with more
//!    equations than variables joins the producers of its inlets, one with fewer joins the
//!    consumers of its outlets, until every group is square.
//! 2. **Integrating controllers.** A controller with integral action (a differential variable)
//!    makes its error zero at steady state: that equation constrains the measurement, not the
//!    controller's own variables, so alone the controller is singular. It joins the block that
//!    owns its measurement and every block on the shortest path (streams and signals) from the
//!    block it drives to that measurement — the whole loop it closes (a level controller moving a
//!    fresh feed joins feed, mixer and vessel).
//! 3. **Local loops.** A controller that measures and drives the same group (a level on the
//!    vessel's own outflow, a column's compositions on its reflux and boilup) joins it: the
//!    vessel alone, with its outflow fixed, has no steady holdup.
//!
//! A controller that closes no loop by itself (proportional only, measuring one group and driving
//! another) stays a block of its own; its signal edges are torn like streams when they lie on a
//! cycle. A final structural check (maximum matching of each group's Jacobian) merges any group
//! still singular with its SCC.

use std::collections::VecDeque;

use plantwide_flowsheet::{BlockKind, Plant, Read, with_dense_jacobian};
use plantwide_model::{UnitIo, VarKind};

use crate::System;

/// Blocks solved together by one local Newton.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SolveGroup {
    /// Block indices, ascending.
    pub blocks: Vec<usize>,
    /// Why the blocks are solved together (empty for a single block).
    pub reasons: Vec<String>,
}

impl SolveGroup {
    /// Name: the block names joined by `+`.
    pub fn name(&self, plant: &Plant) -> String {
        self.blocks.iter().map(|&b| plant.blocks()[b].name.as_str()).collect::<Vec<_>>().join("+")
    }
}

/// Union-find over block indices with the reasons of each union.
struct Partition {
    parent: Vec<usize>,
    reasons: Vec<(usize, String)>,
}

impl Partition {
    fn new(n: usize) -> Partition {
        Partition { parent: (0..n).collect(), reasons: Vec::new() }
    }
    fn find(&mut self, mut a: usize) -> usize {
        while self.parent[a] != a {
            self.parent[a] = self.parent[self.parent[a]];
            a = self.parent[a];
        }
        a
    }
    /// Join the groups of `a` and `b`; true if they were apart.
    fn union(&mut self, a: usize, b: usize) -> bool {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra == rb {
            return false;
        }
        self.parent[ra.max(rb)] = ra.min(rb);
        true
    }
    fn join(&mut self, blocks: &[usize], reason: String) {
        let mut changed = false;
        for w in blocks.windows(2) {
            changed |= self.union(w[0], w[1]);
        }
        if changed {
            self.reasons.push((blocks[0], reason));
        }
    }
    fn groups(mut self) -> Vec<SolveGroup> {
        let n = self.parent.len();
        let roots: Vec<usize> = (0..n).map(|b| self.find(b)).collect();
        let mut groups: Vec<SolveGroup> = Vec::new();
        let mut index = vec![usize::MAX; n];
        for (b, &r) in roots.iter().enumerate() {
            if index[r] == usize::MAX {
                index[r] = groups.len();
                groups.push(SolveGroup { blocks: Vec::new(), reasons: Vec::new() });
            }
            groups[index[r]].blocks.push(b);
        }
        for (b, why) in std::mem::take(&mut self.reasons) {
            groups[index[roots[b]]].reasons.push(why);
        }
        groups
    }
}

/// Blocks that read a variable of `b` (consumers) and blocks whose variables `b` reads (sources),
/// through streams and signals.
fn neighbours(plant: &Plant) -> (Vec<Vec<usize>>, Vec<Vec<usize>>) {
    let n = plant.blocks().len();
    let (mut out, mut inn) = (vec![Vec::new(); n], vec![Vec::new(); n]);
    for (bi, b) in plant.blocks().iter().enumerate() {
        for r in &b.reads {
            if let Read::Var(v) = *r {
                let a = plant.vars()[v].block;
                if a != bi && !out[a].contains(&bi) {
                    out[a].push(bi);
                    inn[bi].push(a);
                }
            }
        }
    }
    (out, inn)
}

/// Shortest path `from → … → to` through `out`, avoiding `skip`.
fn shortest_path(out: &[Vec<usize>], from: usize, to: usize, skip: usize) -> Option<Vec<usize>> {
    let mut parent = vec![usize::MAX; out.len()];
    let mut queue = VecDeque::from([from]);
    parent[from] = from;
    while let Some(v) = queue.pop_front() {
        if v == to {
            let mut path = vec![to];
            while *path.last()? != from {
                path.push(parent[*path.last()?]);
            }
            path.reverse();
            return Some(path);
        }
        for &w in &out[v] {
            if w != skip && parent[w] == usize::MAX {
                parent[w] = v;
                queue.push_back(w);
            }
        }
    }
    None
}

/// The solve groups of `plant` by the rules of the module documentation (before the structural
/// check, which needs a point).
pub fn solve_groups(plant: &Plant) -> Vec<SolveGroup> {
    let n = plant.blocks().len();
    let name = |b: usize| plant.blocks()[b].name.as_str();
    let mut part = Partition::new(n);
    let (out, inn) = neighbours(plant);

    // 1. Non-square units, grown until every group is square.
    for (bi, b) in plant.blocks().iter().enumerate() {
        let n_own = b.layout.n_own();
        if b.n_eq > n_own {
            for &k in plant.streams_into(bi) {
                let from = plant.streams()[k].from.0;
                let why = format!("`{}` writes the equation for the outflow of `{}`", name(bi), name(from));
                part.join(&[from, bi], why);
            }
        }
    }
    loop {
        let mut balance = vec![0isize; n];
        for (bi, b) in plant.blocks().iter().enumerate() {
            let r = part.find(bi);
            balance[r] += b.n_eq as isize - b.layout.n_own() as isize;
        }
        let Some(bad) = (0..n).find(|&b| part.find(b) == b && balance[b] != 0) else { break };
        let members: Vec<usize> = (0..n).filter(|&b| part.find(b) == bad).collect();
        let side = if balance[bad] > 0 { &inn } else { &out };
        let mut others: Vec<usize> = members.iter().flat_map(|&b| side[b].iter().copied()).collect();
        others.retain(|&o| part.find(o) != bad);
        if others.is_empty() {
            break; // The DOF check reports a plant that is not square.
        }
        let excess = if balance[bad] > 0 { "equations" } else { "variables" };
        for o in others {
            part.join(&[bad, o], format!("`{}` has more {excess} than its own: solved with `{}`", name(bad), name(o)));
        }
    }

    // 2. Integrating controllers with the loop they close.
    let controllers: Vec<usize> = (0..n).filter(|&b| plant.blocks()[b].kind == BlockKind::Controller).collect();
    for &c in &controllers {
        let b = &plant.blocks()[c];
        let integrating = plant.vars()[b.own_offset..b.own_offset + b.layout.n_own()]
            .iter()
            .any(|v| v.spec.kind == VarKind::Differential);
        if !integrating {
            continue;
        }
        for &s in &inn[c] {
            part.join(
                &[c, s],
                format!(
                    "`{}` has integral action: its zero-error equation is solved with `{}`, which owns its measurement",
                    name(c),
                    name(s)
                ),
            );
            for &k in &out[c] {
                let path = shortest_path(&out, k, s, c).unwrap_or_else(|| vec![k, s]);
                if path.len() > 1 {
                    let names: Vec<&str> = path.iter().map(|&p| name(p)).collect();
                    part.join(&path, format!("`{}` closes its loop through {}", name(c), names.join(" -> ")));
                }
            }
        }
    }

    // 3. Controllers that measure and drive the same group, to a fixed point.
    loop {
        let mut changed = false;
        for &c in &controllers {
            let local =
                inn[c].iter().find_map(|&s| out[c].iter().find(|&&k| part.find(k) == part.find(s)).map(|&k| (s, k)));
            if let Some((s, k)) = local
                && part.find(c) != part.find(k)
            {
                let why = if s == k {
                    format!("`{}` measures and drives `{}`", name(c), name(k))
                } else {
                    format!("`{}` measures `{}` and drives `{}`, solved together", name(c), name(s), name(k))
                };
                part.join(&[k, c], why);
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    part.groups()
}

/// One group's unknowns and equations inside the plant vector.
#[derive(Debug, Clone)]
pub(crate) struct GroupLayout {
    /// Blocks, ascending.
    pub blocks: Vec<usize>,
    /// First local unknown of each block (its own variables are contiguous).
    pub col0: Vec<usize>,
    /// First local equation of each block.
    pub row0: Vec<usize>,
    /// Global indices of the unknowns.
    pub unknowns: Vec<usize>,
}

impl GroupLayout {
    pub fn new(plant: &Plant, blocks: &[usize]) -> GroupLayout {
        debug_assert!(blocks.windows(2).all(|w| w[0] < w[1]), "a group's blocks are ascending");
        let (mut col0, mut row0, mut unknowns) = (Vec::new(), Vec::new(), Vec::new());
        let mut rows = 0;
        for &b in blocks {
            let blk = &plant.blocks()[b];
            col0.push(unknowns.len());
            row0.push(rows);
            unknowns.extend(blk.own_offset..blk.own_offset + blk.layout.n_own());
            rows += blk.n_eq;
        }
        GroupLayout { blocks: blocks.to_vec(), col0, row0, unknowns }
    }
    /// Number of equations.
    pub fn n_rows(&self, plant: &Plant) -> usize {
        self.blocks.iter().map(|&b| plant.blocks()[b].n_eq).sum()
    }
    /// Local index of global variable `v`, if it is an unknown of the group.
    pub fn local(&self, plant: &Plant, v: usize) -> Option<usize> {
        let b = plant.vars()[v].block;
        let k = self.blocks.binary_search(&b).ok()?;
        Some(self.col0[k] + v - plant.blocks()[b].own_offset)
    }
    /// Global equation index and block of local row `row`.
    pub fn global_row(&self, plant: &Plant, row: usize) -> usize {
        let k = self.row0.iter().rposition(|&r| r <= row).unwrap_or(0);
        plant.blocks()[self.blocks[k]].eq_offset + row - self.row0[k]
    }
}

/// A group's equations in its own variables, everything else held at `base`.
pub(crate) struct GroupSystem<'a> {
    pub plant: &'a Plant,
    pub u: &'a [f64],
    pub base: &'a [f64],
    pub layout: &'a GroupLayout,
}

impl GroupSystem<'_> {
    /// Block `k`'s local vector with the group's unknowns from `y`.
    fn gather(&self, k: usize, y: &[f64], local: &mut Vec<f64>) {
        let b = &self.plant.blocks()[self.layout.blocks[k]];
        let c0 = self.layout.col0[k];
        local.clear();
        local.extend_from_slice(&y[c0..c0 + b.layout.n_own()]);
        local.extend(b.reads.iter().map(|r| match *r {
            Read::Var(i) => self.layout.local(self.plant, i).map_or(self.base[i], |j| y[j]),
            Read::Input(j) => self.u[j],
        }));
    }
}

impl System for GroupSystem<'_> {
    fn n(&self) -> usize {
        self.layout.unknowns.len()
    }
    fn residual(&self, y: &[f64], r: &mut [f64]) {
        let mut local = Vec::new();
        for (k, &bi) in self.layout.blocks.iter().enumerate() {
            let b = &self.plant.blocks()[bi];
            self.gather(k, y, &mut local);
            let io = UnitIo { local: &local, layout: &b.layout, thermo: self.plant.thermo(), time: 0.0 };
            let r0 = self.layout.row0[k];
            b.unit.residual(&io, &mut r[r0..r0 + b.n_eq]);
        }
    }
    fn jacobian(&self, y: &[f64], r: &mut [f64], jac: &mut Vec<(usize, usize, f64)>) {
        jac.clear();
        let mut local = Vec::new();
        for (k, &bi) in self.layout.blocks.iter().enumerate() {
            let b = &self.plant.blocks()[bi];
            self.gather(k, y, &mut local);
            let n = local.len();
            let io = UnitIo { local: &local, layout: &b.layout, thermo: self.plant.thermo(), time: 0.0 };
            let (r0, c0, n_own) = (self.layout.row0[k], self.layout.col0[k], b.layout.n_own());
            with_dense_jacobian(b.n_eq * n, |dense| {
                b.unit.jacobian_colored(&io, &mut r[r0..r0 + b.n_eq], dense, b.coloring.as_ref());
                let mut push = |row: usize, j: usize| {
                    let col = if j < n_own {
                        Some(c0 + j)
                    } else {
                        match b.reads[j - n_own] {
                            Read::Var(i) => self.layout.local(self.plant, i),
                            Read::Input(_) => None,
                        }
                    };
                    if let Some(col) = col {
                        jac.push((r0 + row, col, dense[row * n + j]));
                    }
                };
                match &b.pattern {
                    Some(p) => p.iter().for_each(|&(row, j)| push(row, j)),
                    None => (0..b.n_eq).for_each(|row| (0..n).for_each(|j| push(row, j))),
                }
            });
        }
    }
    fn nominal(&self, i: usize) -> f64 {
        self.plant.vars()[self.layout.unknowns[i]].spec.nominal
    }
    fn bounds(&self, i: usize) -> (f64, f64) {
        let s = &self.plant.vars()[self.layout.unknowns[i]].spec;
        (s.lower, s.upper)
    }
    fn mass(&self) -> Vec<(usize, usize)> {
        let mut m = Vec::new();
        for (k, &bi) in self.layout.blocks.iter().enumerate() {
            let b = &self.plant.blocks()[bi];
            for j in 0..b.layout.n_own().min(b.n_eq) {
                if self.plant.vars()[b.own_offset + j].spec.kind == VarKind::Differential {
                    m.push((self.layout.row0[k] + j, self.layout.col0[k] + j));
                }
            }
        }
        m
    }
}
