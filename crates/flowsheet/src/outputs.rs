//! Output-only variables: algebraic variables that nothing the dynamic integrator solves
//! depends on.
//!
//! A variable is *needed* when it is differential, when the caller reads it during the run (the
//! roots: recorded paths, sampled measurements, the flows of integrated totals), or when the
//! equation of a needed variable reads it — own variable `k` of a block is paired with the
//! block's equation `k`, and an equation without a variable of its own (a unit's extra equation)
//! is needed with everything it reads. The rest is *output-only*: the equations of the needed
//! variables form a closed system, and the others follow from its solution, one block-triangular
//! solve later. Modelica tools make the same partition (the equations "needed for output only",
//! evaluated at output points, not at every integrator iteration; OpenModelica's backend keeps
//! them out of its ODE section). In Skogestad's column A (constant relative volatility) the 41
//! tray temperatures are output-only: only the outlets' temperature and enthalpy read them, and
//! nothing reads those but the product sinks' totals.
//!
//! Reads are taken from the declared patterns, a dense unit reading everything, so a coarse
//! pattern only makes fewer variables output-only.

use plantwide_model::VarKind;

use crate::plant::{Block, Plant, Read};

impl Plant {
    /// Whether each plant variable is needed (module documentation) when the caller reads
    /// `roots` (plant variable indices; out-of-range ones are ignored) during the run.
    pub fn needed_variables(&self, roots: &[usize]) -> Vec<bool> {
        let vars = self.vars();
        let mut needed = vec![false; vars.len()];
        let mut stack: Vec<usize> = Vec::new();
        let mut mark = |v: usize, stack: &mut Vec<usize>| {
            if !needed[v] {
                needed[v] = true;
                stack.push(v);
            }
        };
        roots.iter().filter(|&&v| v < vars.len()).for_each(|&v| mark(v, &mut stack));
        (0..vars.len()).filter(|&v| vars[v].spec.kind == VarKind::Differential).for_each(|v| mark(v, &mut stack));
        let rows: Vec<Rows> = self.blocks().iter().map(Rows::new).collect();
        for (b, r) in self.blocks().iter().zip(&rows) {
            let n_own = b.layout.n_own();
            // Equations without a variable of their own, and variables without an equation.
            for k in n_own..b.n_eq {
                r.reads(b, k).for_each(|v| mark(v, &mut stack));
            }
            (b.n_eq..n_own).for_each(|k| mark(b.own_offset + k, &mut stack));
        }
        while let Some(v) = stack.pop() {
            let bi = vars[v].block;
            let (b, k) = (&self.blocks()[bi], v - self.blocks()[bi].own_offset);
            if k < b.n_eq {
                rows[bi].reads(b, k).for_each(|w| mark(w, &mut stack));
            }
        }
        needed
    }
}

/// A block's pattern grouped by row: the local columns of row `k` are `col[ptr[k]..ptr[k + 1]]`;
/// `None` for a dense block.
pub(crate) struct Rows(Option<(Vec<usize>, Vec<usize>)>);

impl Rows {
    pub(crate) fn new(b: &Block) -> Rows {
        Rows(b.pattern.as_ref().map(|p| {
            let mut ptr = vec![0usize; b.n_eq + 1];
            p.iter().filter(|e| e.0 < b.n_eq).for_each(|&(k, _)| ptr[k + 1] += 1);
            (0..b.n_eq).for_each(|k| ptr[k + 1] += ptr[k]);
            let mut next = ptr.clone();
            let mut col = vec![0usize; ptr[b.n_eq]];
            for &(k, c) in p.iter().filter(|e| e.0 < b.n_eq) {
                col[next[k]] = c;
                next[k] += 1;
            }
            (ptr, col)
        }))
    }

    /// The local columns equation `k` of block `b` reads: its declared row, or (dense) every
    /// local column.
    pub(crate) fn local<'a>(&'a self, b: &Block, k: usize) -> impl Iterator<Item = usize> + 'a {
        let (declared, dense) = match &self.0 {
            Some((ptr, col)) => (&col[ptr[k]..ptr[k + 1]], 0..0),
            None => (&[][..], 0..b.layout.len()),
        };
        declared.iter().copied().chain(dense)
    }

    /// The plant variables equation `k` of block `b` reads (own variables and the variables it
    /// reads through its inlets and signals; inputs are not variables).
    fn reads<'a>(&'a self, b: &'a Block, k: usize) -> impl Iterator<Item = usize> + 'a {
        let n_own = b.layout.n_own();
        self.local(b, k).filter_map(move |c| {
            if c < n_own {
                Some(b.own_offset + c)
            } else {
                match b.reads.get(c - n_own) {
                    Some(&Read::Var(i)) => Some(i),
                    _ => None,
                }
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::load_str;

    /// Column A (constant α, LV with P level loops) with the streams' flows and compositions
    /// read (as the dynamic driver's totals read them): nothing but the two outlets'
    /// temperature and enthalpy reads a tray temperature, and nothing reads those or the
    /// outlets' (constant) pressure; those are output-only, every other variable is needed — and
    /// recording a temperature makes it and nothing else needed again.
    #[test]
    fn column_a_temperatures_are_output_only() {
        let plant = load_str(include_str!("../../../flowsheets/column_a.json"), "column_a.json").unwrap();
        let mut roots = Vec::new();
        for s in 0..plant.streams().len() {
            roots.push(plant.stream_flow_var(s));
            roots.extend(plant.stream_composition_vars(s));
        }
        let needed = plant.needed_variables(&roots);
        let mut free: Vec<&str> =
            plant.vars().iter().zip(&needed).filter(|(_, n)| !**n).map(|(v, _)| v.path.as_str()).collect();
        free.sort_unstable();
        let mut expect: Vec<String> = (1..=41).map(|s| format!("column.T[{s}]")).collect();
        expect.extend(["distillate", "bottoms"].iter().flat_map(|s| ["T", "h", "P"].map(|f| format!("{s}.{f}"))));
        expect.sort_unstable();
        assert_eq!(free, expect);
        let t21 = plant.var("column.T[21]").unwrap();
        roots.push(t21);
        let with = plant.needed_variables(&roots);
        let changed: Vec<usize> = (0..needed.len()).filter(|&v| with[v] != needed[v]).collect();
        assert_eq!(changed, vec![t21]);
    }
}
