//! The one sparse LU of the solvers (Newton, pseudo-transient, BDF, perturbation analysis): KLU's
//! scheme on faer's orderings, with faer's partial-pivoting LU as the fallback.
//!
//! **Pattern.** The plant's Jacobian comes as triplets whose positions are the units' declared
//! structural patterns, the same at every point. Declared patterns are generous (column A:
//! 15 708 structural entries, 1 675 nonzero values at any point), and the factorization cost grows
//! with the pattern it is given, so the matrix factorized is the *live* pattern: the structural
//! entries that have ever held a nonzero value. An entry that turns nonzero later (a controller
//! leaving its limit, a tray that fills) joins it and the symbolic analysis is redone; an entry
//! that returns to zero stays, as an explicit zero. The live pattern is therefore exact wherever the
//! Jacobian has been evaluated, and never loses a value — until [`SparseLu::forget_values`], which
//! an integrator run again calls to factorize as a new LU would, keeping what the pattern alone
//! determines.
//!
//! **Work per factorization.** The triplet → compressed-column map and the diagonal order
//! (matching + AMD, `order.rs`) are computed once per live pattern, and the order with the
//! pattern of its factors once per process (`cache.rs`: the next run of the same plant finds
//! it). A fresh factorization first pivots on that diagonal; where a pivot fails the threshold
//! test it runs faer's simplicial (left-looking, partial-pivoting) numeric LU in COLAMD's column
//! order, made on first need. Later factorizations sum the triplet values into the held matrix in
//! place and refactorize on the held pivot sequence and `L`/`U` pattern (`factors.rs`) from the
//! first column whose entries changed, starting afresh when a held pivot has become too small.
//! Pinned entries (below) are the ones a caller changes between factorizations
//! ([`SparseLu::factor_shifted`]); the diagonal order puts their columns last. Solves run in place, with `A` or `Aᵀ`, on the held factors. Everything
//! runs on the calling thread (the solvers parallelize over independent solves instead).

mod cache;
mod factors;
mod order;

use std::mem::MaybeUninit;
use std::sync::Arc;

use faer::dyn_stack::{MemStack, StackReq};
use faer::perm::PermRef;
use faer::sparse::linalg::LuError;
use faer::sparse::linalg::lu::simplicial::{
    SimplicialLu, factorize_simplicial_numeric_lu, factorize_simplicial_numeric_lu_scratch,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};

use cache::Analysis;
use factors::{Factors, Source};
use order::column_order;

/// Why a sparse factorization failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SparseError {
    /// A triplet lies outside the `n × n` matrix (a wiring bug, never user input).
    #[error("invalid sparse matrix: entry ({row}, {col}) outside the {n} × {n} matrix")]
    OutOfBounds {
        /// Row of the entry.
        row: usize,
        /// Column of the entry.
        col: usize,
        /// Order of the matrix.
        n: usize,
    },
    /// faer could not allocate, or an index overflowed.
    #[error("sparse LU of order {n} with {nnz} entries: out of memory or index overflow")]
    Resources {
        /// Order of the matrix.
        n: usize,
        /// Number of stored entries.
        nnz: usize,
    },
    /// No pivot at elimination step `index`: the matrix is structurally or numerically singular.
    #[error("sparse LU failed: no pivot at step {index} of {n} (singular matrix)")]
    Singular {
        /// The elimination step.
        index: usize,
        /// Order of the matrix.
        n: usize,
    },
    /// The solution is not finite: the matrix is numerically singular.
    #[error("sparse LU failed: the matrix of order {n} is numerically singular (non-finite solution)")]
    NonFinite {
        /// Order of the matrix.
        n: usize,
    },
    /// A solve was asked for before any factorization succeeded.
    #[error("sparse LU: no factorization is held")]
    NotFactored,
}

/// The structural pattern of the triplets and where each one goes.
#[derive(Debug, Default)]
struct Structure {
    /// Triplet positions, in the caller's order (the key: another order is another structure),
    /// then the pinned positions.
    positions: Vec<(usize, usize)>,
    /// How many of `positions` are triplets (the rest are pinned).
    n_triplets: usize,
    /// For each triplet, its slot in the structural compressed-column arrays (duplicates share).
    slot: Vec<usize>,
    /// Row index of each structural slot, and for each slot whether it has ever been nonzero.
    row: Vec<usize>,
    col_ptr: Vec<usize>,
    live: Vec<bool>,
    /// Values summed per structural slot (scratch of every refill).
    sum: Vec<f64>,
}

impl Structure {
    fn new(n: usize, triplets: &[(usize, usize, f64)], pinned: &[(usize, usize)]) -> Result<Structure, SparseError> {
        let positions: Vec<(usize, usize)> =
            triplets.iter().map(|&(i, j, _)| (i, j)).chain(pinned.iter().copied()).collect();
        if let Some(&(row, col)) = positions.iter().find(|t| t.0 >= n || t.1 >= n) {
            return Err(SparseError::OutOfBounds { row, col, n });
        }
        // Counting sort by column, then by row within each column: O(nnz + n) and stable.
        let mut start = vec![0usize; n + 1];
        positions.iter().for_each(|&(_, j)| start[j + 1] += 1);
        for j in 0..n {
            start[j + 1] += start[j];
        }
        let mut order = vec![0usize; positions.len()];
        let mut next = start.clone();
        for (k, &(_, j)) in positions.iter().enumerate() {
            order[next[j]] = k;
            next[j] += 1;
        }
        for j in 0..n {
            order[start[j]..start[j + 1]].sort_unstable_by_key(|&k| positions[k].0);
        }
        let (mut row, mut col_ptr, mut slot) = (Vec::new(), vec![0; n + 1], vec![0; positions.len()]);
        let mut last = None;
        for k in order {
            let (i, j) = positions[k];
            if last != Some((i, j)) {
                row.push(i);
                col_ptr[j + 1] += 1;
                last = Some((i, j));
            }
            slot[k] = row.len() - 1;
        }
        for j in 0..n {
            col_ptr[j + 1] += col_ptr[j];
        }
        let m = row.len();
        let mut live = vec![false; m];
        slot[triplets.len()..].iter().for_each(|&k| live[k] = true);
        Ok(Structure { positions, n_triplets: triplets.len(), slot, row, col_ptr, live, sum: vec![0.0; m] })
    }

    fn matches(&self, triplets: &[(usize, usize, f64)], pinned: &[(usize, usize)]) -> bool {
        let (t, p) = self.positions.split_at(self.n_triplets);
        t.len() == triplets.len() && p == pinned && t.iter().zip(triplets).all(|(p, t)| p.0 == t.0 && p.1 == t.1)
    }

    /// Sum the triplet values per slot; a slot outside the live pattern that became nonzero is
    /// added to it.
    fn accumulate(&mut self, triplets: &[(usize, usize, f64)]) {
        self.sum.iter_mut().for_each(|s| *s = 0.0);
        for (t, &s) in triplets.iter().zip(&self.slot) {
            self.sum[s] += t.2;
        }
        for (live, &v) in self.live.iter_mut().zip(&self.sum) {
            *live |= v != 0.0;
        }
    }

    /// The live pattern back to the pinned slots alone, as [`Structure::new`] leaves it.
    fn reset_live(&mut self) {
        self.live.iter_mut().for_each(|l| *l = false);
        self.slot[self.n_triplets..].iter().for_each(|&k| self.live[k] = true);
    }
}

/// The live pattern as a compressed-column matrix, its symbolic LU and the map from structural
/// slots to stored entries.
#[derive(Debug)]
struct Live {
    col_ptr: Vec<usize>,
    row: Vec<usize>,
    /// Column of each stored entry.
    col: Vec<usize>,
    /// Structural slot of each stored entry.
    from: Vec<usize>,
    /// The loaded (summed) values, and the values factorized (mapped from them).
    base: Vec<f64>,
    values: Vec<f64>,
    /// The fill-reducing column order `(forward, inverse)` for partial pivoting (COLAMD), made
    /// when partial pivoting is first needed.
    col_perm: Option<(Vec<usize>, Vec<usize>)>,
    /// The order for diagonal pivots, tried first, and the pattern of its factors (`cache.rs`).
    analysis: Arc<Analysis>,
    /// The stored entries at pinned positions.
    pinned: Vec<usize>,
    /// `Some(a)` while `values` are `a·base`, plus a shift on the pinned entries
    /// ([`SparseLu::factor_shifted`]): another shift then changes the pinned entries alone.
    shifted: Option<u64>,
}

impl Live {
    /// The factors of the live matrix on the row and column permutations `(forward, inverse)`,
    /// if the permutations reach every diagonal and the refactorization accepts its pivots
    /// (`check`: against the threshold, else only nonzero and finite).
    fn factors_on(&self, rows: (&[usize], &[usize]), columns: (&[usize], &[usize]), check: bool) -> Option<Factors> {
        let source = Source { col_ptr: &self.col_ptr, row: &self.row, col_perm: columns, row_perm: rows };
        let mut f = Factors::symbolic(&source)?;
        f.refactor(&self.values, check, None).ok()?;
        Some(f)
    }

    /// Whether this is the live matrix of the slots `s.live` marks (its entries are those slots).
    fn is_pattern_of(&self, s: &Structure) -> bool {
        self.from.len() == s.live.iter().filter(|&&l| l).count() && self.from.iter().all(|&k| s.live[k])
    }

    fn new(n: usize, s: &Structure) -> Live {
        let (mut col_ptr, mut row, mut col, mut from) = (vec![0; n + 1], Vec::new(), Vec::new(), Vec::new());
        for j in 0..n {
            for k in s.col_ptr[j]..s.col_ptr[j + 1] {
                if s.live[k] {
                    row.push(s.row[k]);
                    col.push(j);
                    from.push(k);
                }
            }
            col_ptr[j + 1] = row.len();
        }
        let nnz = row.len();
        let mut last = vec![false; n];
        s.positions[s.n_triplets..].iter().for_each(|&(_, j)| last[j] = true);
        let analysis = cache::analysis(n, &col_ptr, &row, &last);
        let mut entry_of_slot = vec![usize::MAX; s.row.len()];
        from.iter().enumerate().for_each(|(k, &slot)| entry_of_slot[slot] = k);
        let pinned = s.slot[s.n_triplets..].iter().map(|&slot| entry_of_slot[slot]).collect();
        let values = vec![0.0; nnz];
        Live { col_ptr, row, col, from, base: values.clone(), values, col_perm: None, analysis, pinned, shifted: None }
    }
}

/// A sparse LU that keeps its pattern, symbolic analysis, factors and workspace between
/// factorizations (see the module documentation).
#[derive(Debug, Default)]
pub struct SparseLu {
    n: usize,
    structure: Structure,
    live: Option<Live>,
    /// Left-looking LU with partial pivoting (Gilbert–Peierls) of the column-permuted matrix,
    /// and its row permutation `(forward, inverse)`.
    numeric: SimplicialLu<usize, f64>,
    row_perm: (Vec<usize>, Vec<usize>),
    /// The factors in our own arrays (solves, and refactorizations on the same pivots), for the
    /// current live pattern.
    factors: Option<Factors>,
    factored: bool,
    work: Vec<MaybeUninit<u8>>,
    /// Symbolic analyses, factorizations with pivoting and refactorizations, for tests and benchmarks.
    counts: (usize, usize, usize),
}

impl SparseLu {
    /// Factorize the `n × n` matrix given by `triplets` (duplicates summed).
    pub fn factor(&mut self, n: usize, triplets: &[(usize, usize, f64)]) -> Result<(), SparseError> {
        self.load(n, triplets)?;
        self.factor_mapped(|_, _, v| v)
    }

    /// Load the matrix given by `triplets` (duplicates summed) without factorizing it; the live
    /// pattern grows if a new entry is nonzero.
    pub fn load(&mut self, n: usize, triplets: &[(usize, usize, f64)]) -> Result<(), SparseError> {
        self.load_pinned(n, triplets, &[])
    }

    /// [`SparseLu::load`] with the positions `pinned` in the live pattern whatever their loaded
    /// value (zero unless a triplet is there too): entries that [`SparseLu::factor_mapped`] fills,
    /// such as the mass-matrix diagonal of `M − cJ`, which a loaded `J_ii = −1` must not cancel.
    /// Their columns come last in the diagonal order, so that a factorization that changes only
    /// them redoes only those columns.
    pub fn load_pinned(
        &mut self,
        n: usize,
        triplets: &[(usize, usize, f64)],
        pinned: &[(usize, usize)],
    ) -> Result<(), SparseError> {
        self.load_with_live(n, triplets, pinned, &[])
    }

    /// [`SparseLu::load_pinned`] with the structural slots marked in `live` (as
    /// [`SparseLu::live_slots`] returned them for the same triplet positions) joined to the live
    /// pattern: a restored integrator factorizes the pattern it had, not the one its current
    /// Jacobian alone would give.
    pub fn load_with_live(
        &mut self,
        n: usize,
        triplets: &[(usize, usize, f64)],
        pinned: &[(usize, usize)],
        live: &[bool],
    ) -> Result<(), SparseError> {
        self.factored = false;
        if self.n != n || self.live.is_none() || !self.structure.matches(triplets, pinned) {
            self.structure = Structure::new(n, triplets, pinned)?;
            self.live = None;
            self.n = n;
        }
        self.structure.accumulate(triplets);
        if live.len() == self.structure.live.len() {
            self.structure.live.iter_mut().zip(live).for_each(|(l, &m)| *l |= m);
        }
        // The held live matrix serves while its entries are the live slots: they only grow,
        // except after [`SparseLu::forget_values`], where the same slots come back on the same
        // pattern (a plant run again) and the live matrix, its analysis and the map are kept.
        if self.live.as_ref().is_none_or(|l| !l.is_pattern_of(&self.structure)) {
            self.factors = None;
            self.live = Some(Live::new(n, &self.structure));
            self.counts.0 += 1;
        }
        let Some(live) = &mut self.live else { unreachable!("live pattern built above") };
        for (v, &k) in live.base.iter_mut().zip(&live.from) {
            *v = self.structure.sum[k];
        }
        live.shifted = None;
        Ok(())
    }

    /// Which structural slots are in the live pattern (for [`SparseLu::load_with_live`]).
    pub fn live_slots(&self) -> &[bool] {
        &self.structure.live
    }

    /// The row and column permutations of the held factors (`rows[i]`, `columns[i]`: the matrix
    /// row and column of the pivot of elimination step `i`).
    pub fn pivots(&self) -> Option<(&[usize], &[usize])> {
        self.factors.as_ref().filter(|_| self.factored).map(|f| f.pivots())
    }

    /// Factorize the loaded matrix with each entry `(row, col, value)` replaced by
    /// `map(row, col, value)` (the map must keep zero entries' positions meaningful: entries are
    /// those of the live pattern). Cheap to repeat: the BDF iteration matrix `M − cJ` for a new `c`.
    pub fn factor_mapped(&mut self, map: impl Fn(usize, usize, f64) -> f64) -> Result<(), SparseError> {
        self.map_values(map)?;
        self.refactor_or_pivot(false)
    }

    /// Refactorize the held factors for the live values (`only_pinned`: only the pinned entries
    /// can have changed since they were computed), else factorize afresh with pivoting.
    fn refactor_or_pivot(&mut self, only_pinned: bool) -> Result<(), SparseError> {
        let Some(live) = &self.live else { return Err(SparseError::NotFactored) };
        let changed = only_pinned.then_some(live.pinned.as_slice());
        if let Some(f) = &mut self.factors
            && f.refactor(&live.values, true, changed).is_ok()
        {
            self.counts.2 += 1;
            self.factored = true;
            return Ok(());
        }
        self.factor_pivoting()
    }

    /// [`SparseLu::factor_mapped`] on the row permutation `pivots` (as [`SparseLu::pivots`] gave
    /// it for the same live pattern): the factors are then those a run that held these pivots
    /// computes, bit for bit (a restored integrator). Pivots that do not fit, or give a zero pivot,
    /// are replaced by a pivoting factorization.
    pub fn factor_mapped_on(
        &mut self,
        map: impl Fn(usize, usize, f64) -> f64,
        (rows, columns): (&[usize], &[usize]),
    ) -> Result<(), SparseError> {
        self.map_values(map)?;
        let (n, Some(live)) = (self.n, &self.live) else { return Err(SparseError::NotFactored) };
        if let (Some(row_inv), Some(col_inv)) = (inverse(rows, n), inverse(columns, n))
            && let Some(f) = live.factors_on((rows, &row_inv), (columns, &col_inv), false)
        {
            self.hold(f, false);
            return Ok(());
        }
        self.factor_pivoting()
    }

    /// Hold `f` as the factors (`fresh`: a new pivot sequence, else a refactorization).
    fn hold(&mut self, f: Factors, fresh: bool) {
        self.factors = Some(f);
        if fresh {
            self.counts.1 += 1;
        } else {
            self.counts.2 += 1;
        }
        self.factored = true;
    }

    /// Factorize `a·A + s·P` for the loaded matrix `A` and the pinned positions `P` (ones there):
    /// the BDF's row-scaled iteration matrix `M/c − J` is `a = −1`, `s = 1/c`. Between two such
    /// factorizations of one loaded matrix with the same `a` only the pinned entries change, and
    /// the refactorization redoes only their columns, which the diagonal order puts last.
    pub fn factor_shifted(&mut self, a: f64, s: f64) -> Result<(), SparseError> {
        self.factored = false;
        let Some(live) = &mut self.live else { return Err(SparseError::NotFactored) };
        let only_pinned = live.shifted == Some(a.to_bits());
        if !only_pinned {
            live.values.iter_mut().zip(&live.base).for_each(|(v, b)| *v = a * b);
            live.shifted = Some(a.to_bits());
        }
        for &k in &live.pinned {
            live.values[k] = a * live.base[k] + s;
        }
        self.refactor_or_pivot(only_pinned)
    }

    /// The loaded values with `map` applied, into the live matrix.
    fn map_values(&mut self, map: impl Fn(usize, usize, f64) -> f64) -> Result<(), SparseError> {
        self.factored = false;
        let Some(live) = &mut self.live else { return Err(SparseError::NotFactored) };
        live.shifted = None;
        for k in 0..live.values.len() {
            live.values[k] = map(live.row[k], live.col[k], live.base[k]);
        }
        Ok(())
    }

    /// Factorize the live matrix afresh: on the diagonal order if its pivots pass the threshold
    /// test, else with partial pivoting (faer chooses the pivots in COLAMD's column order) and the
    /// held factors computed on those pivots with [`Factors::refactor`], so that the factors depend
    /// on the values and the pivots only, however they were reached.
    fn factor_pivoting(&mut self) -> Result<(), SparseError> {
        let n = self.n;
        let Some(live) = &mut self.live else { return Err(SparseError::NotFactored) };
        if let Some(symbolic) = &live.analysis.factors {
            let mut f = symbolic.clone();
            if f.refactor(&live.values, true, None).is_ok() {
                self.hold(f, true);
                return Ok(());
            }
        }
        let nnz = live.values.len();
        if live.col_perm.is_none() {
            let pattern = SymbolicSparseColMatRef::new_checked(n, n, &live.col_ptr, None, &live.row);
            live.col_perm = Some(column_order(pattern).ok_or(SparseError::Resources { n, nnz })?);
        }
        let Some(live) = &self.live else { unreachable!("live pattern checked above") };
        let Some(live_perm) = &live.col_perm else { unreachable!("column order made above") };
        let symbolic = SymbolicSparseColMatRef::new_checked(n, n, &live.col_ptr, None, &live.row);
        let req = factorize_simplicial_numeric_lu_scratch::<usize, f64>(n, n);
        let stack = workspace(&mut self.work, req).ok_or(SparseError::Resources { n, nnz })?;
        let a = SparseColMatRef::new(symbolic, &live.values);
        let (fwd, inv) = &mut self.row_perm;
        fwd.resize(n, 0);
        inv.resize(n, 0);
        let col_perm = PermRef::new_checked(&live_perm.0, &live_perm.1, n);
        factorize_simplicial_numeric_lu(fwd, inv, &mut self.numeric, a, col_perm, stack).map_err(|e| match e {
            LuError::SymbolicSingular { index } => SparseError::Singular { index, n },
            LuError::Generic(_) => SparseError::Resources { n, nnz },
        })?;
        let source =
            Source { col_ptr: &live.col_ptr, row: &live.row, col_perm: col_perm.arrays(), row_perm: (fwd, inv) };
        let mut f = Factors::symbolic(&source).ok_or(SparseError::Singular { index: 0, n })?;
        f.refactor(&live.values, false, None).map_err(|e| SparseError::Singular { index: e.column, n })?;
        self.hold(f, true);
        Ok(())
    }

    /// Solve `A x = b` in place with the held factors.
    pub fn solve_in_place(&mut self, b: &mut [f64]) -> Result<(), SparseError> {
        self.solve_with(b, false)
    }

    /// Solve `Aᵀ x = b` in place with the held factors.
    pub fn solve_transpose_in_place(&mut self, b: &mut [f64]) -> Result<(), SparseError> {
        self.solve_with(b, true)
    }

    fn solve_with(&mut self, b: &mut [f64], transpose: bool) -> Result<(), SparseError> {
        let (Some(f), true) = (&mut self.factors, self.factored) else { return Err(SparseError::NotFactored) };
        f.solve(b, transpose);
        // Every entry is looked at (no early exit): the or-reduction runs as wide vector operations.
        let non_finite = b.iter().fold(false, |acc, v| acc | !v.is_finite());
        if non_finite { Err(SparseError::NonFinite { n: self.n }) } else { Ok(()) }
    }

    /// Factorize and solve `A x = b` in place.
    pub fn solve(&mut self, n: usize, triplets: &[(usize, usize, f64)], b: &mut [f64]) -> Result<(), SparseError> {
        self.factor(n, triplets)?;
        self.solve_in_place(b)
    }

    /// Whether factors are held.
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// Drop the numeric factors (the pattern and its symbolic analysis are kept).
    pub fn invalidate(&mut self) {
        self.factored = false;
    }

    /// Forget every value this LU has seen: the numeric factors and their pivot sequence, and
    /// the entries that joined the live pattern by turning nonzero. The next load and
    /// factorization are then those of a new `SparseLu`, bit for bit (the same live pattern,
    /// the same pivots), while what the triplet pattern alone determines is kept: the
    /// triplet → slot map and, when the same slots turn live again, the live matrix with its
    /// analysis. For an integrator run again on the same plant.
    pub fn forget_values(&mut self) {
        self.factored = false;
        self.factors = None;
        self.structure.reset_live();
        if let Some(live) = &mut self.live {
            live.shifted = None;
        }
    }

    /// Entries of the live pattern (the matrix factorized).
    pub fn live_nnz(&self) -> usize {
        self.live.as_ref().map_or(0, |l| l.values.len())
    }

    /// Entries of the held factors `L + U` (0 when none are held).
    pub fn factor_nnz(&self) -> usize {
        self.factors.as_ref().filter(|_| self.factored).map_or(0, Factors::nnz)
    }

    /// The column eliminated at step `index` of the partial-pivoting path (COLAMD's order, where
    /// every [`SparseError::Singular`] comes from), to name the column of that error.
    pub fn pivot_column(&self, index: usize) -> Option<usize> {
        let live = self.live.as_ref()?;
        live.col_perm.as_ref()?.0.get(index).copied()
    }

    /// Symbolic analyses, numeric factorizations with pivoting and refactorizations on held pivots
    /// done so far.
    pub fn counts(&self) -> (usize, usize, usize) {
        self.counts
    }
}

/// The inverse of `p` if it is a permutation of `0..n`.
fn inverse(p: &[usize], n: usize) -> Option<Vec<usize>> {
    let mut inv = vec![usize::MAX; n];
    let ok =
        p.len() == n && p.iter().enumerate().all(|(i, &v)| v < n && std::mem::replace(&mut inv[v], i) == usize::MAX);
    ok.then_some(inv)
}

/// A memory stack over `buf`, grown to hold `req`; `None` if it cannot be allocated.
fn workspace(buf: &mut Vec<MaybeUninit<u8>>, req: StackReq) -> Option<&mut MemStack> {
    let bytes = req.unaligned_bytes_required();
    if buf.len() < bytes {
        buf.try_reserve_exact(bytes - buf.len()).ok()?;
        buf.resize(bytes, MaybeUninit::uninit());
    }
    Some(MemStack::new(buf))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `[[2, 1, 0], [1, 3, 1], [0, 1, 4]]` with a structural zero at (0, 2) and a duplicate at (1, 1).
    fn triplets(a02: f64) -> Vec<(usize, usize, f64)> {
        vec![
            (0, 0, 2.0),
            (0, 1, 1.0),
            (1, 0, 1.0),
            (1, 1, 1.0),
            (1, 1, 2.0),
            (1, 2, 1.0),
            (2, 1, 1.0),
            (2, 2, 4.0),
            (0, 2, a02),
        ]
    }

    fn residual(t: &[(usize, usize, f64)], x: &[f64], b: &[f64]) -> f64 {
        let mut r = b.to_vec();
        t.iter().for_each(|&(i, j, v)| r[i] -= v * x[j]);
        r.iter().fold(0.0, |m, v| m.max(v.abs()))
    }

    #[test]
    fn solves_and_transposes_and_grows_its_live_pattern() {
        let mut lu = SparseLu::default();
        let b = [1.0, 2.0, 3.0];
        let t = triplets(0.0);
        let mut x = b;
        lu.solve(3, &t, &mut x).unwrap();
        assert!(residual(&t, &x, &b) < 1e-14);
        assert_eq!(lu.live_nnz(), 7, "the structural zero is left out, the duplicate summed");
        let mut y = b;
        lu.solve_transpose_in_place(&mut y).unwrap();
        let tt: Vec<_> = t.iter().map(|&(i, j, v)| (j, i, v)).collect();
        assert!(residual(&tt, &y, &b) < 1e-14);
        // The structural zero turns nonzero: it joins the pattern, a new analysis is made.
        let t = triplets(0.5);
        let mut x = b;
        lu.solve(3, &t, &mut x).unwrap();
        assert!(residual(&t, &x, &b) < 1e-14);
        assert_eq!((lu.live_nnz(), lu.counts()), (8, (2, 2, 0)));
        // Back to zero: kept as an explicit zero, no new analysis; refactorized on the held pivots.
        let t = triplets(0.0);
        let mut x = b;
        lu.solve(3, &t, &mut x).unwrap();
        assert!(residual(&t, &x, &b) < 1e-14);
        assert_eq!((lu.live_nnz(), lu.counts()), (8, (2, 2, 1)));
    }

    /// A 40 × 40 nonsymmetric matrix: diagonal `diag(u)`, a cyclic superdiagonal and one more
    /// entry per row, the values `u` uniform on [0, 1) from a linear congruential generator seeded
    /// `seed`; and a right-hand side from the same generator.
    fn ring_matrix(seed: u64, diag: impl Fn(f64) -> f64) -> (Vec<(usize, usize, f64)>, Vec<f64>) {
        let n = 40;
        let mut s = seed;
        let mut next = || {
            s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut t: Vec<(usize, usize, f64)> = (0..n).map(|i| (i, i, diag(next()))).collect();
        for i in 0..n {
            t.push((i, (i + 1) % n, 1.0 + next()));
            t.push((i, (i * 7 + 3) % n, next() - 0.5));
        }
        let b = (0..n).map(|_| next() - 0.5).collect();
        (t, b)
    }

    #[test]
    fn a_matrix_that_needs_row_pivots_and_a_fill_reducing_order_is_solved_both_ways() {
        // Tiny diagonal (partial pivoting must exchange rows), random off-diagonal entries: the
        // residuals of A x = b and Aᵀ y = b are at round-off.
        let (t, b) = ring_matrix(12345, |u| 1e-6 * u);
        let n = b.len();
        let mut lu = SparseLu::default();
        let mut x = b.clone();
        lu.solve(n, &t, &mut x).unwrap();
        assert!(residual(&t, &x, &b) < 1e-12, "{}", residual(&t, &x, &b));
        let mut y = b.clone();
        lu.solve_transpose_in_place(&mut y).unwrap();
        let tt: Vec<_> = t.iter().map(|&(i, j, v)| (j, i, v)).collect();
        assert!(residual(&tt, &y, &b) < 1e-12, "{}", residual(&tt, &y, &b));
        let (fwd, _) = &lu.row_perm;
        assert!(fwd.iter().enumerate().any(|(i, &p)| i != p), "rows were exchanged");
    }

    /// A matrix of `ring_matrix`'s shape with a dominant diagonal, then its values scaled entry by
    /// entry: refactorized on the held pivots, the solve is at round-off and equal to a fresh
    /// factorization's.
    #[test]
    fn a_refactorization_on_held_pivots_solves_like_a_fresh_factorization() {
        let (t, b) = ring_matrix(777, |u| 4.0 + u);
        let n = b.len();
        let mut held = SparseLu::default();
        let mut x = b.clone();
        held.solve(n, &t, &mut x).unwrap();
        let t2: Vec<_> = t
            .iter()
            .enumerate()
            .map(|(k, &(i, j, v))| (i, j, v * (0.8 + 0.4 * ((k * 37) % 101) as f64 / 101.0)))
            .collect();
        let mut x = b.clone();
        held.solve(n, &t2, &mut x).unwrap();
        assert_eq!(held.counts(), (1, 1, 1), "the second matrix is refactorized on the held pivots");
        assert!(residual(&t2, &x, &b) < 1e-13, "{}", residual(&t2, &x, &b));
        let mut fresh = SparseLu::default();
        let mut y = b.clone();
        fresh.solve(n, &t2, &mut y).unwrap();
        let diff = x.iter().zip(&y).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(diff < 1e-13, "{diff}");
        let mut z = b.clone();
        held.solve_transpose_in_place(&mut z).unwrap();
        let tt: Vec<_> = t2.iter().map(|&(i, j, v)| (j, i, v)).collect();
        assert!(residual(&tt, &z, &b) < 1e-13, "{}", residual(&tt, &z, &b));
    }

    /// A second `SparseLu` given the first one's pivots and live pattern factorizes a matrix into
    /// the same factors, bit for bit, though the first reached them by refactorizing and the second
    /// alone would pivot differently (the snapshot of a BDF run is restored this way).
    #[test]
    fn factors_on_given_pivots_are_reproduced_bit_for_bit() {
        let a = |a00: f64, a10: f64| vec![(0, 0, a00), (0, 1, 1.0), (1, 0, a10), (1, 1, 3.0), (1, 2, 1.0), (2, 2, 2.0)];
        let b = [1.0, 2.0, 3.0];
        let mut first = SparseLu::default();
        let mut x = b;
        // A negligible a00: the diagonal order is refused, partial pivoting takes row 1 for column 0.
        first.solve(3, &a(1e-9, 0.6), &mut x).unwrap();
        // The held pivots still pass; alone, the diagonal order would be taken now.
        let t = a(0.3, 0.6);
        let mut x = b;
        first.solve(3, &t, &mut x).unwrap();
        assert_eq!(first.counts(), (1, 1, 1));
        let (rows, columns) = first.pivots().map(|(r, c)| (r.to_vec(), c.to_vec())).unwrap();
        let live = first.live_slots().to_vec();
        let mut fresh = SparseLu::default();
        let mut y = b;
        fresh.solve(3, &t, &mut y).unwrap();
        assert_ne!(
            fresh.pivots().unwrap(),
            (rows.as_slice(), columns.as_slice()),
            "a fresh factorization pivots otherwise"
        );
        let mut restored = SparseLu::default();
        restored.load_with_live(3, &t, &[], &live).unwrap();
        restored.factor_mapped_on(|_, _, v| v, (&rows, &columns)).unwrap();
        let mut z = b;
        restored.solve_in_place(&mut z).unwrap();
        assert_eq!(x.map(f64::to_bits), z.map(f64::to_bits));
        assert_eq!(restored.pivots().unwrap(), (rows.as_slice(), columns.as_slice()));
    }

    /// After [`SparseLu::forget_values`] an LU factorizes as a new one does, bit for bit: it
    /// drops the pivots a refactorization kept (which a new LU would not take), and the entries
    /// that joined the live pattern; it keeps the live matrix and its analysis when the same
    /// slots turn live again.
    #[test]
    fn a_forgetful_lu_factorizes_as_a_new_one_and_keeps_its_analysis() {
        let a = |a00: f64, a10: f64| vec![(0, 0, a00), (0, 1, 1.0), (1, 0, a10), (1, 1, 3.0), (1, 2, 1.0), (2, 2, 2.0)];
        let b = [1.0, 2.0, 3.0];
        let mut reused = SparseLu::default();
        let mut x = b;
        // Pivoting (a negligible a00), then a matrix refactorized on those pivots.
        reused.solve(3, &a(1e-9, 0.6), &mut x).unwrap();
        let t = a(0.3, 0.6);
        reused.solve(3, &t, &mut x).unwrap();
        let held = reused.pivots().map(|(r, c)| (r.to_vec(), c.to_vec())).unwrap();
        let mut fresh = SparseLu::default();
        let mut y = b;
        fresh.solve(3, &t, &mut y).unwrap();
        assert_ne!(fresh.pivots().unwrap(), (held.0.as_slice(), held.1.as_slice()));
        reused.forget_values();
        let mut x = b;
        reused.solve(3, &t, &mut x).unwrap();
        assert_eq!(reused.pivots(), fresh.pivots(), "the pivots of a new LU");
        assert_eq!(x.map(f64::to_bits), y.map(f64::to_bits));
        assert_eq!(reused.counts().0, 1, "the live matrix and its analysis kept");
        // A structural zero that turned nonzero leaves the live pattern with the values.
        let mut lu = SparseLu::default();
        let mut x = [1.0, 2.0, 3.0];
        lu.solve(3, &triplets(0.5), &mut x).unwrap();
        assert_eq!(lu.live_nnz(), 8);
        lu.forget_values();
        let mut x = [1.0, 2.0, 3.0];
        lu.solve(3, &triplets(0.0), &mut x).unwrap();
        let mut y = [1.0, 2.0, 3.0];
        SparseLu::default().solve(3, &triplets(0.0), &mut y).unwrap();
        assert_eq!((lu.live_nnz(), lu.counts().0), (7, 2), "the pattern of the values loaded, analysed anew");
        assert_eq!(x.map(f64::to_bits), y.map(f64::to_bits));
    }

    /// A tridiagonal matrix with its rows and columns permuted alike: the matching keeps the
    /// diagonal and AMD finds an order without fill (the partial-pivoting path would fill in).
    /// With the rows scrambled besides (no structurally nonzero diagonal left), the matching finds
    /// another diagonal and the solve is still at round-off.
    #[test]
    fn the_diagonal_order_factorizes_a_permuted_tridiagonal_matrix_without_fill() {
        let n = 50;
        let pi = |i: usize| (i * 17 + 5) % n;
        let tridiagonal = |sigma: &dyn Fn(usize) -> usize| {
            let mut t = Vec::new();
            for i in 0..n {
                t.push((sigma(pi(i)), pi(i), 4.0 + i as f64 * 0.01));
                if i + 1 < n {
                    t.push((sigma(pi(i)), pi(i + 1), -1.0));
                    t.push((sigma(pi(i + 1)), pi(i), -1.5));
                }
            }
            t
        };
        let b: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        for (sigma, no_fill) in [(&(|i| i) as &dyn Fn(usize) -> usize, true), (&|i| (i * 31 + 11) % n, false)] {
            let t = tridiagonal(sigma);
            let mut lu = SparseLu::default();
            let mut x = b.clone();
            lu.solve(n, &t, &mut x).unwrap();
            assert!(residual(&t, &x, &b) < 1e-14, "{}", residual(&t, &x, &b));
            assert_eq!(lu.counts(), (1, 1, 0));
            if no_fill {
                assert_eq!(lu.factor_nnz(), 3 * n - 2, "no fill");
            }
        }
    }

    /// A held pivot that has become small against the entries below it is not kept: the matrix
    /// is factorized afresh with row exchanges (a refactorization would divide by 1e-12).
    #[test]
    fn a_pivot_that_became_small_is_replaced_by_pivoting() {
        let m = |a00: f64, a10: f64| vec![(0, 0, a00), (0, 1, 1.0), (1, 0, a10), (1, 1, 1.0)];
        let mut lu = SparseLu::default();
        let mut x = [1.0, 2.0];
        lu.solve(2, &m(1.0, 0.5), &mut x).unwrap();
        let t = m(1e-12, 1.0);
        let mut x = [1.0, 2.0];
        lu.solve(2, &t, &mut x).unwrap();
        assert_eq!(lu.counts(), (1, 2, 0), "factorized again with pivoting");
        assert!(residual(&t, &x, &[1.0, 2.0]) < 1e-15, "{x:?}");
    }

    /// `M/c − J` of a 6 × 6 `J` whose last three equations carry the time derivatives of the last
    /// three variables: a new `c` refactorizes only their columns (ordered last), and the factors
    /// are the ones a fresh factorization at that `c` computes, bit for bit.
    #[test]
    fn a_new_shift_refactorizes_only_the_pinned_columns_and_matches_a_fresh_factorization() {
        let jac = vec![
            (0, 0, 1.0),
            (0, 3, -0.5),
            (1, 1, -2.0),
            (1, 0, 0.3),
            (1, 4, 1.0),
            (2, 2, 1.0),
            (2, 1, -0.7),
            (2, 5, 0.2),
            (3, 0, 0.4),
            (3, 3, -1.0),
            (3, 4, 0.5),
            (4, 1, 0.6),
            (4, 3, 0.5),
            (4, 4, -1.5),
            (5, 2, -0.9),
            (5, 4, 0.25),
            (5, 5, -0.8),
        ];
        let mass = [(3, 3), (4, 4), (5, 5)];
        let b = [1.0, -2.0, 0.5, 3.0, -1.0, 2.0];
        let solve = |lu: &mut SparseLu| {
            let mut x = b;
            lu.solve_in_place(&mut x).unwrap();
            x
        };
        let mut held = SparseLu::default();
        held.load_pinned(6, &jac, &mass).unwrap();
        held.factor_shifted(-1.0, 1.0 / 0.5).unwrap();
        let before = held.factors.as_ref().unwrap().eliminated();
        held.factor_shifted(-1.0, 1.0 / 0.8).unwrap();
        let again = held.factors.as_ref().unwrap().eliminated() - before;
        assert_eq!(again, 3, "only the three pinned columns are eliminated again");
        let mut fresh = SparseLu::default();
        fresh.load_pinned(6, &jac, &mass).unwrap();
        fresh.factor_shifted(-1.0, 1.0 / 0.8).unwrap();
        let (x, y) = (solve(&mut held), solve(&mut fresh));
        assert!(x.iter().zip(&y).all(|(a, b)| a.to_bits() == b.to_bits()), "{x:?} != {y:?}");
        // The matrix solved is M/c − J at c = 0.8.
        let mut a: Vec<(usize, usize, f64)> = jac.iter().map(|&(i, j, v)| (i, j, -v)).collect();
        a.extend(mass.iter().map(|&(i, j)| (i, j, 1.0 / 0.8)));
        assert!(residual(&a, &x, &b) < 1e-14, "{x:?}");
    }

    /// Shifts of `M/c − J` over twelve orders of magnitude on a 40 × 40 matrix with small
    /// diagonal entries (pivots near the threshold test's bound) and every other diagonal pinned,
    /// one after another: the refactorizations of the shifted pinned entries alone, whose pivot
    /// test folds only those entries into the row maxima of the others (kept between shifts),
    /// keep and replace the same pivots, and give the same solutions bit for bit, as the same
    /// sequence of factorizations of the whole matrix (the maxima taken over every entry), also
    /// across new Jacobians. A pinned entry a million times the rest of its row changes that
    /// row's scale in the test.
    #[test]
    fn a_sequence_of_shifts_pivots_as_factorizations_of_the_whole_matrix_do() {
        let (jac, b) = ring_matrix(4242, |u| 1e-3 * u);
        let n = b.len();
        let mass: Vec<(usize, usize)> = (0..n).step_by(2).map(|i| (i, i)).collect();
        let (mut shifted, mut whole) = (SparseLu::default(), SparseLu::default());
        shifted.load_pinned(n, &jac, &mass).unwrap();
        whole.load_pinned(n, &jac, &mass).unwrap();
        // Shifts log-uniform over [1e-6, 1e6], from a linear congruential generator.
        let mut state = 99u64;
        let shifts = (0..60).map(|_| {
            state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            10f64.powf(12.0 * (state >> 11) as f64 / (1u64 << 53) as f64 - 6.0)
        });
        for (step, s) in shifts.enumerate() {
            // Every seventh shift, a new Jacobian: the maxima kept for the old one are stale.
            if step % 7 == 6 {
                let scaled: Vec<_> = jac.iter().map(|&(i, j, v)| (i, j, v * (1.0 + s.ln().abs()))).collect();
                shifted.load_pinned(n, &scaled, &mass).unwrap();
                whole.load_pinned(n, &scaled, &mass).unwrap();
            }
            shifted.factor_shifted(-1.0, s).unwrap();
            whole.factor_mapped(|i, j, v| if i == j && i % 2 == 0 { -v + s } else { -v }).unwrap();
            assert_eq!(shifted.pivots(), whole.pivots(), "pivots at shift {s}");
            let (mut x, mut y) = (b.clone(), b.clone());
            shifted.solve_in_place(&mut x).unwrap();
            whole.solve_in_place(&mut y).unwrap();
            assert!(x.iter().zip(&y).all(|(a, b)| a.to_bits() == b.to_bits()), "solution at shift {s}");
        }
        let (_, pivoting, refactors) = shifted.counts();
        assert!(pivoting > 1 && refactors > 1, "both paths taken: {pivoting} pivoting, {refactors} refactorizations");
    }

    /// A non-finite entry anywhere in the solution, NaN or infinite, first or last, is an error;
    /// finite solutions, however large, are not.
    #[test]
    fn a_non_finite_solution_is_an_error_wherever_it_is() {
        let (t, b) = ring_matrix(31, |u| 4.0 + u);
        let n = b.len();
        let mut lu = SparseLu::default();
        lu.factor(n, &t).unwrap();
        for (k, bad) in [(0, f64::NAN), (n - 1, f64::INFINITY), (n / 2, f64::NEG_INFINITY)] {
            let mut x = b.clone();
            x[k] = bad;
            assert!(matches!(lu.solve_in_place(&mut x), Err(SparseError::NonFinite { .. })), "{bad} at {k}");
        }
        let mut x: Vec<f64> = b.iter().map(|v| v * 1e300).collect();
        assert!(lu.solve_in_place(&mut x).is_ok(), "large but finite");
    }

    #[test]
    fn singular_and_out_of_bounds_are_errors() {
        let mut lu = SparseLu::default();
        let mut x = [1.0, 1.0];
        let e = lu.solve(2, &[(0, 0, 1.0), (1, 0, 1.0)], &mut x).unwrap_err();
        assert!(matches!(e, SparseError::Singular { .. } | SparseError::NonFinite { .. }), "{e:?}");
        let e = lu.solve(2, &[(0, 0, 1.0), (2, 1, 1.0)], &mut x).unwrap_err();
        assert_eq!(e, SparseError::OutOfBounds { row: 2, col: 1, n: 2 });
        let mut fresh = SparseLu::default();
        assert_eq!(fresh.solve_in_place(&mut x), Err(SparseError::NotFactored));
        let mut x = [1.0, 1.0];
        let e = lu.solve(2, &[(0, 0, 1.0), (0, 1, 1.0), (1, 0, 1.0), (1, 1, 1.0)], &mut x).unwrap_err();
        assert!(matches!(e, SparseError::NonFinite { .. } | SparseError::Singular { .. }), "{e:?}");
    }
}
