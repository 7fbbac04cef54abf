//! The explicit plans this process has computed ([`Plant::explicit_plan_for`]), kept for the next
//! run of the same plant structure.
//!
//! Every dynamic run plans its explicit and output-only variables from the plant's wiring and the
//! variables it records: the demotion sweep and the reachability pass of
//! [`Plant::needed_variables`] over every block's pattern, about 16 µs of column A's 0.65 ms
//! feed-step run. A study runs many simulations of one plant (tuning, screening, sizing), each
//! with the same plan. The plan is a function of the plant's structure and the roots alone, so a
//! cached one is the one that would be computed. The key is exact, never a hash:
//! - the plant's variables (`Arc`, compared by identity: copies of a plant share them, and every
//!   variable's kind and block come from assembly);
//! - each block's unit (`Arc`, by identity: its explicit declaration and pattern are functions of
//!   the unit and its layout), layout, offsets, equation count and reads (compared by value:
//!   rewiring, [`Plant::hold_input`] or [`Plant::hold_measurement`], changes only the reads);
//! - the roots.
//!
//! The entry holds its `Arc`s, so no other plant's variables or units can take their addresses
//! while it is kept. At most [`MAX_ENTRIES`] plans are kept, the least recently used evicted
//! first, and only of plants of at most [`MAX_VARS`] variables: an entry keeps its plant's
//! variables alive, and a larger plant's plan is a small part of its run anyway.

use std::sync::{Arc, Mutex, PoisonError};

use plantwide_model::{LocalLayout, Unit};

use crate::explicit::ExplicitPlan;
use crate::plant::{Block, Plant, Read, VarInfo};

/// Most plans kept.
const MAX_ENTRIES: usize = 8;
/// Largest plant (variables) whose plan is kept: eight entries then hold at most a few MB.
const MAX_VARS: usize = 20_000;

/// What a plan is a function of, for one block.
struct BlockKey {
    unit: Arc<dyn Unit>,
    layout: LocalLayout,
    own_offset: usize,
    eq_offset: usize,
    n_eq: usize,
    reads: Vec<Read>,
}

impl BlockKey {
    fn of(b: &Block) -> BlockKey {
        BlockKey {
            unit: Arc::clone(&b.unit),
            layout: b.layout.clone(),
            own_offset: b.own_offset,
            eq_offset: b.eq_offset,
            n_eq: b.n_eq,
            reads: b.reads.clone(),
        }
    }

    fn is(&self, b: &Block) -> bool {
        Arc::ptr_eq(&self.unit, &b.unit)
            && self.own_offset == b.own_offset
            && self.eq_offset == b.eq_offset
            && self.n_eq == b.n_eq
            && self.layout == b.layout
            && self.reads == b.reads
    }
}

/// A kept plan and its key.
struct Entry {
    vars: Arc<Vec<VarInfo>>,
    blocks: Vec<BlockKey>,
    roots: Vec<usize>,
    plan: ExplicitPlan,
}

impl Entry {
    fn is(&self, plant: &Plant, roots: &[usize]) -> bool {
        Arc::ptr_eq(&self.vars, &plant.vars)
            && self.roots == roots
            && self.blocks.len() == plant.blocks.len()
            && self.blocks.iter().zip(&plant.blocks).all(|(k, b)| k.is(b))
    }
}

static PLANS: Mutex<Vec<Entry>> = Mutex::new(Vec::new());

/// The plan of `plant` for `roots` from the cache, or from `compute` (then kept).
pub(crate) fn plan_for(plant: &Plant, roots: &[usize], compute: impl FnOnce() -> ExplicitPlan) -> ExplicitPlan {
    if plant.vars.len() > MAX_VARS {
        return compute();
    }
    // A panic while the lock was held leaves whole entries: the data is still consistent.
    let mut plans = PLANS.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(k) = plans.iter().position(|e| e.is(plant, roots)) {
        let entry = plans.remove(k);
        let plan = entry.plan.clone();
        plans.insert(0, entry);
        return plan;
    }
    drop(plans);
    let plan = compute();
    let entry = Entry {
        vars: Arc::clone(&plant.vars),
        blocks: plant.blocks.iter().map(BlockKey::of).collect(),
        roots: roots.to_vec(),
        plan: plan.clone(),
    };
    let mut plans = PLANS.lock().unwrap_or_else(PoisonError::into_inner);
    plans.insert(0, entry);
    plans.truncate(MAX_ENTRIES);
    plan
}

#[cfg(test)]
mod tests {
    use crate::load_str;

    /// A cached plan is the computed one; a copy of the plant whose distillate is held (the level
    /// controller's output then feeds nothing, so it becomes output-only) gets its own plan, not
    /// the original's, and the original still gets its own.
    #[test]
    fn a_cached_plan_is_the_computed_one_and_rewiring_is_seen() {
        let plant = load_str(include_str!("../../../flowsheets/column_a.json"), "column_a.json").unwrap();
        let roots = [plant.var("column.M[1]").unwrap()];
        let first = plant.explicit_plan_for(&roots);
        assert_eq!(first, plant.plan_for(&roots));
        assert_eq!(plant.explicit_plan_for(&roots), first, "a hit");
        let mut held = plant.clone();
        assert!(held.hold_input(held.input("column.distillate").unwrap()).is_some());
        let rewired = held.explicit_plan_for(&roots);
        assert_eq!(rewired, held.plan_for(&roots));
        assert_ne!(rewired, first, "holding the input changes the plan");
        assert_eq!(plant.explicit_plan_for(&roots), first);
        // A tray temperature is output-only unless it is read.
        let t10 = [plant.var("column.T[10]").unwrap()];
        assert_ne!(plant.explicit_plan_for(&t10), first, "other roots, another plan");
        assert_eq!(plant.explicit_plan_for(&t10), plant.plan_for(&t10));
    }
}
