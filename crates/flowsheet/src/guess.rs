//! Cold-start initial guess: units guessed in flow order from the feeds, three sweeps so that
//! recycles carry something sensible, then controllers.

use std::collections::VecDeque;

use plantwide_model::UnitIo;
use plantwide_model::stream::{F, H, P, T, Z0};

use crate::plant::{BlockKind, Plant};

impl Plant {
    /// Blocks in guessing order: units breadth-first from those without inlets, then the rest, then
    /// controllers.
    pub fn flow_order(&self) -> Vec<usize> {
        let n = self.blocks.len();
        let mut seen = vec![false; n];
        let mut order = Vec::with_capacity(n);
        let mut queue: VecDeque<usize> =
            (0..n).filter(|&b| self.blocks[b].kind == BlockKind::Unit && self.blocks[b].layout.n_inlets == 0).collect();
        loop {
            while let Some(b) = queue.pop_front() {
                if std::mem::replace(&mut seen[b], true) {
                    continue;
                }
                order.push(b);
                for &k in self.streams_out_of(b) {
                    let to = self.streams[k].to.0;
                    if !seen[to] {
                        queue.push_back(to);
                    }
                }
            }
            match (0..n).find(|&b| !seen[b] && self.blocks[b].kind == BlockKind::Unit) {
                Some(b) => queue.push_back(b),
                None => break,
            }
        }
        order.extend((0..n).filter(|&b| !seen[b]));
        order
    }

    /// A cold-start guess of every variable at the flowsheet's input values.
    pub fn initial_guess(&self) -> Vec<f64> {
        self.initial_guess_at(&self.input_values())
    }

    /// A cold-start guess of every variable at inputs `u`, from the units' own guess rules.
    pub fn initial_guess_at(&self, u: &[f64]) -> Vec<f64> {
        let mut x = vec![0.0; self.n_vars()];
        let nc = self.components.len();
        let z = vec![1.0 / nc as f64; nc];
        let h = self.thermo.h_liq(300.0, &z);
        for s in &self.streams {
            let v = &mut x[s.offset..s.offset + self.stream_layout.len()];
            v[F] = 1.0;
            v[T] = 300.0;
            v[P] = 101_325.0;
            v[H] = h;
            v[Z0..].copy_from_slice(&z);
        }
        let order = self.flow_order();
        let mut local = Vec::new();
        for _sweep in 0..3 {
            for &bi in &order {
                let b = &self.blocks[bi];
                self.gather(b, &x, u, &mut local);
                let mut own = local[..b.layout.n_own()].to_vec();
                let io = UnitIo { local: &local, layout: &b.layout, thermo: &self.thermo, time: 0.0 };
                b.unit.guess(&io, &mut own);
                x[b.own_offset..b.own_offset + own.len()].copy_from_slice(&own);
            }
        }
        x
    }
}
