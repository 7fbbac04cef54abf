//! The plant's explicit algebraic variables: those its units compute in closed form
//! ([`plantwide_model::UnitModel::explicit`]), which the dynamic integrator eliminates from its
//! Newton iteration.
//!
//! Completion runs block by block in plant order, each unit in its own declared order, so an
//! explicit variable may read kept variables, explicit variables of earlier blocks and earlier
//! explicit variables of its own block. The plan keeps a declared variable explicit only while
//! that holds, read off each block's Jacobian pattern, and otherwise *demotes* it to a kept
//! variable, which Newton solves with its equation as before:
//! - an explicit variable that an earlier block's explicit equation reads is demoted (its value
//!   would be read before it is computed): a controller output that sets a column's product flow;
//! - an explicit variable whose equation reads a demoted variable of its own block is demoted (the
//!   unit computes that one too, and would read its own value, not the kept one).
//!
//! Demotion only shrinks the explicit set, so the sweep repeats until nothing changes.

use plantwide_model::{UnitIo, VarKind};

use crate::outputs::Rows;
use crate::plant::{Block, Plant, Read, VarInfo};

/// The explicit variables of a plant and the order that computes them.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ExplicitPlan {
    /// `(global equation, global variable)` of each explicit variable, in completion order.
    pairs: Vec<(usize, usize)>,
    /// The blocks to complete, in plant order.
    blocks: Vec<PlanBlock>,
    /// `(global equation, global variable)` of each output-only variable that is not explicit
    /// (see [`Plant::explicit_plan_for`]).
    outputs: Vec<(usize, usize)>,
}

/// A block with explicit variables.
#[derive(Debug, Clone, PartialEq, Eq)]
struct PlanBlock {
    /// Block index.
    block: usize,
    /// The own (local) indices of its variables that stay explicit, in completion order.
    keep: Vec<usize>,
    /// Whether that is every variable the unit declared: its residual at a completed point is
    /// then [`plantwide_model::Unit::residual_kept`].
    whole: bool,
    /// The own equations of output-only variables, which that residual may skip (empty: none).
    skip: Vec<bool>,
}

impl ExplicitPlan {
    /// `(global equation, global variable)` of each explicit variable, in completion order.
    pub fn pairs(&self) -> &[(usize, usize)] {
        &self.pairs
    }

    /// `(global equation, global variable)` of each output-only variable the plan does not
    /// compute explicitly: a dynamic integrator leaves them and their equations out of its
    /// iteration and solves them when their values are asked for.
    pub fn outputs(&self) -> &[(usize, usize)] {
        &self.outputs
    }
}

/// Whether a variable is kept, explicit, or declared explicit but demoted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Status {
    Kept,
    Explicit,
    Demoted,
}

/// The explicit variables a block declares (algebraic, with an equation of their own) and the
/// block's pattern by rows ([`Rows`]), for the local columns each one's equation reads.
struct Declared {
    /// Own (local) indices, in the unit's completion order.
    own: Vec<usize>,
    /// The pattern by rows, when `own` is not empty.
    rows: Option<Rows>,
}

impl Declared {
    /// What `b` declares; `vars` are the plant's variables.
    fn of(b: &Block, vars: &[VarInfo]) -> Declared {
        let n_own = b.layout.n_own().min(b.n_eq);
        let own: Vec<usize> = b
            .unit
            .explicit(&b.layout)
            .into_iter()
            .filter(|&k| k < n_own && vars[b.own_offset + k].spec.kind != VarKind::Differential)
            .collect();
        let rows = (!own.is_empty()).then(|| Rows::new(b));
        Declared { own, rows }
    }

    /// The local columns the equation of `own[s]` reads (`b`: its block).
    fn reads<'a>(&'a self, s: usize, b: &'a Block) -> impl Iterator<Item = usize> + 'a {
        let k = self.own[s];
        self.rows.iter().flat_map(move |r| r.local(b, k))
    }
}

thread_local! {
    /// The local vector and the own block of [`Plant::complete`] (the local vectors of whole and
    /// of other blocks in [`Plant::residual_completed`]), one per thread.
    static SCRATCH: std::cell::RefCell<(Vec<f64>, Vec<f64>)> = const { std::cell::RefCell::new((Vec::new(), Vec::new())) };
}

impl Plant {
    /// The explicit variables of the plant as wired now (module documentation).
    pub fn explicit_plan(&self) -> ExplicitPlan {
        let vars = self.vars();
        let mut status = vec![Status::Kept; vars.len()];
        let declared: Vec<Declared> = self.blocks().iter().map(|b| Declared::of(b, vars)).collect();
        for (b, d) in self.blocks().iter().zip(&declared) {
            d.own.iter().for_each(|&k| status[b.own_offset + k] = Status::Explicit);
        }
        while self.demote(&declared, &mut status) {}
        let mut plan = ExplicitPlan::default();
        for (i, (b, d)) in self.blocks().iter().zip(&declared).enumerate() {
            let keep: Vec<usize> =
                d.own.iter().copied().filter(|&k| status[b.own_offset + k] == Status::Explicit).collect();
            if !keep.is_empty() {
                plan.pairs.extend(keep.iter().map(|&k| (b.eq_offset + k, b.own_offset + k)));
                plan.blocks.push(PlanBlock { block: i, whole: keep.len() == d.own.len(), keep, skip: Vec::new() });
            }
        }
        plan
    }

    /// [`Plant::explicit_plan`] with the output-only variables ([`Plant::needed_variables`])
    /// when the caller reads `roots` during the run: those not explicit are listed in
    /// [`ExplicitPlan::outputs`] and their equations skipped by [`Plant::residual_completed`]
    /// where the unit allows. A plan computed before for the same structure and roots is taken
    /// from the process's cache (`plan_cache.rs`).
    pub fn explicit_plan_for(&self, roots: &[usize]) -> ExplicitPlan {
        crate::plan_cache::plan_for(self, roots, || self.plan_for(roots))
    }

    /// [`Plant::explicit_plan_for`], computed.
    pub(crate) fn plan_for(&self, roots: &[usize]) -> ExplicitPlan {
        let mut plan = self.explicit_plan();
        let needed = self.needed_variables(roots);
        let mut explicit = vec![false; needed.len()];
        plan.pairs.iter().for_each(|&(_, j)| explicit[j] = true);
        for b in self.blocks() {
            let square = b.layout.n_own().min(b.n_eq);
            let free = (0..square).filter(|&k| !needed[b.own_offset + k] && !explicit[b.own_offset + k]);
            plan.outputs.extend(free.map(|k| (b.eq_offset + k, b.own_offset + k)));
        }
        let mut next = plan.outputs.iter().peekable();
        for p in &mut plan.blocks {
            let b = &self.blocks()[p.block];
            while next.next_if(|&&(eq, _)| eq < b.eq_offset).is_some() {}
            while let Some(&(eq, _)) = next.next_if(|&&(eq, _)| eq < b.eq_offset + b.n_eq) {
                p.skip.resize(b.n_eq, false);
                p.skip[eq - b.eq_offset] = true;
            }
        }
        plan
    }

    /// One sweep of the demotion rules over the `declared` explicit variables (local index and
    /// the local columns its equation reads, per block); returns whether anything was demoted.
    fn demote(&self, declared: &[Declared], status: &mut [Status]) -> bool {
        let mut changed = false;
        for (bi, (b, d)) in self.blocks().iter().zip(declared).enumerate() {
            let n_own = b.layout.n_own();
            for (s, &k) in d.own.iter().enumerate() {
                if status[b.own_offset + k] != Status::Explicit {
                    continue;
                }
                for c in d.reads(s, b) {
                    if c < n_own {
                        if status[b.own_offset + c] == Status::Demoted {
                            status[b.own_offset + k] = Status::Demoted;
                            changed = true;
                            break;
                        }
                    } else if let Some(&Read::Var(i)) = b.reads.get(c - n_own)
                        && status[i] == Status::Explicit
                        && self.vars()[i].block > bi
                    {
                        status[i] = Status::Demoted;
                        changed = true;
                    }
                }
            }
        }
        changed
    }

    /// Overwrite the explicit variables of `x` (plant variables) with their values from the others
    /// at inputs `u` and time `t`, block by block in `plan`'s order.
    pub fn complete(&self, plan: &ExplicitPlan, x: &mut [f64], u: &[f64], t: f64) {
        SCRATCH.with_borrow_mut(|(local, own)| {
            for p in &plan.blocks {
                let b = &self.blocks()[p.block];
                let range = b.own_offset..b.own_offset + b.layout.n_own();
                let local = self.gather_reads(b, x, u, local);
                let io = UnitIo { local, layout: &b.layout, thermo: self.thermo(), time: t };
                if p.whole {
                    // The unit overwrites its explicit variables only: in place.
                    b.unit.complete(&io, &mut x[range]);
                } else {
                    own.clear();
                    own.extend_from_slice(&x[range.clone()]);
                    b.unit.complete(&io, own);
                    p.keep.iter().for_each(|&k| x[range.start + k] = own[k]);
                }
            }
        });
    }

    /// [`Plant::gather`] without the own block, which [`plantwide_model::UnitModel::complete`]
    /// reads from its `own` argument: the local vector of `b` is the returned prefix of `local`,
    /// whose own part is left as it was (NaN in builds with debug assertions, so that a unit
    /// reading it there fails its tests), saving a copy of the block per completion. `local` only
    /// grows: a smaller block before this one does not shorten it, so its own part is not
    /// refilled on every call either (that fill was 1.4 % of a column-A run).
    fn gather_reads<'l>(&self, b: &Block, x: &[f64], u: &[f64], local: &'l mut Vec<f64>) -> &'l [f64] {
        let n_own = b.layout.n_own();
        let n = n_own + b.reads.len();
        if local.len() < n {
            local.resize(n, f64::NAN);
        }
        if cfg!(debug_assertions) {
            local[..n_own].fill(f64::NAN);
        }
        for (l, r) in local[n_own..n].iter_mut().zip(&b.reads) {
            *l = match *r {
                Read::Var(i) => x[i],
                Read::Input(j) => u[j],
            };
        }
        &local[..n]
    }

    /// [`Plant::residual`] at a point `x` that [`Plant::complete`] has just completed for `plan`:
    /// the explicit equations hold there, so a unit whose declared explicit variables all are
    /// evaluates only its other equations ([`plantwide_model::Unit::residual_kept`]) and leaves
    /// the explicit rows of `r`, and those of the plan's output-only variables, as they were.
    pub fn residual_completed(&self, plan: &ExplicitPlan, x: &[f64], u: &[f64], t: f64, r: &mut [f64]) {
        // Whole blocks gather into `local`, the others into `small`: a small block's gather
        // (cleared, refilled) then does not shorten the vector a large block's reads keep.
        SCRATCH.with_borrow_mut(|(local, small)| {
            let mut next = plan.blocks.iter().peekable();
            for (i, b) in self.blocks().iter().enumerate() {
                let rows = &mut r[b.eq_offset..b.eq_offset + b.n_eq];
                match next.next_if(|p| p.block == i) {
                    Some(p) if p.whole => {
                        // The own variables are read in place, not copied into `local`; the
                        // explicit rows are left as they are.
                        let local = self.gather_reads(b, x, u, local);
                        let io = UnitIo { local, layout: &b.layout, thermo: self.thermo(), time: t };
                        let own = &x[b.own_offset..b.own_offset + b.layout.n_own()];
                        b.unit.residual_kept(&io, own, rows, &p.skip);
                    }
                    _ => {
                        self.gather(b, x, u, small);
                        let io = UnitIo { local: small, layout: &b.layout, thermo: self.thermo(), time: t };
                        b.unit.residual(&io, rows);
                    }
                }
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use serde_json::{Value, json};

    use super::Status;
    use crate::load_str;

    /// Column A (`column`) fed from the bottoms of a second copy (`lower`), which comes after it
    /// in the file. The vapour-flow equation of `column`'s feed stage is explicit and reads its
    /// feed's flow and enthalpy, `lower`'s bottoms outlet — explicit too but computed later — so
    /// those two outlet variables are demoted (no other equation of `lower` reads them). Every
    /// other variable both columns declare stays explicit: 2 × 299 − 2.
    #[test]
    fn an_explicit_variable_read_before_it_is_computed_is_demoted() {
        let text = include_str!("../../../flowsheets/column_a.json");
        let mut fs: Value = serde_json::from_str(text).unwrap();
        let column = fs["units"]["column"].clone();
        fs["units"]["lower"] = column;
        fs["units"]["lower_top"] = json!({"type": "product"});
        fs["streams"]["feed"] = json!({"from": "feed_source", "to": "lower.feed"});
        fs["streams"]["lower_bottoms"] = json!({"from": "lower.bottoms", "to": "column.feed"});
        fs["streams"]["lower_distillate"] = json!({"from": "lower.distillate", "to": "lower_top"});
        let plant = load_str(&fs.to_string(), "two_columns.json").unwrap();
        let (upper, lower) = (plant.block_index("column").unwrap(), plant.block_index("lower").unwrap());
        assert!(upper < lower, "the test needs the fed column first");
        let plan = plant.explicit_plan();
        assert_eq!(plan.pairs().len(), 2 * 299 - 2);
        let explicit: Vec<usize> = plan.pairs().iter().map(|&(_, j)| j).collect();
        let outlet = plant.stream_flow_var(plant.streams().iter().position(|s| s.name == "lower_bottoms").unwrap());
        for j in outlet..outlet + 6 {
            let path = &plant.vars()[j].path;
            let demoted = path.ends_with(".F") || path.ends_with(".h");
            assert_eq!(!explicit.contains(&j), demoted, "{path}: demoted {}", !demoted);
        }
        // The plan's order is the completion order: each explicit equation reads only explicit
        // variables of its own or an earlier block.
        let mut status = vec![Status::Kept; plant.n_vars()];
        explicit.iter().for_each(|&j| status[j] = Status::Explicit);
        for &(eq, j) in plan.pairs() {
            let b = &plant.blocks()[plant.vars()[j].block];
            let k = eq - b.eq_offset;
            let reads = b.pattern.as_ref().unwrap().iter().filter(|&&(r, _)| r == k);
            for &(_, c) in reads.filter(|&&(_, c)| c >= b.layout.n_own()) {
                if let crate::Read::Var(i) = b.reads[c - b.layout.n_own()] {
                    let later = plant.vars()[i].block > plant.vars()[j].block;
                    assert!(
                        !(later && status[i] == Status::Explicit),
                        "{} reads {}",
                        plant.vars()[j].path,
                        plant.vars()[i].path
                    );
                }
            }
        }
    }
}
