//! The symbolic analyses of the live patterns this process has factorized, kept for the next
//! [`super::SparseLu`] that meets the same pattern.
//!
//! A study runs many simulations and steady states of one plant (tuning, screening, sizing, the
//! perturbation gains), and each one builds its own LU: without this cache every run repeats the
//! matching, AMD and the `L`/`U` pattern of the iteration matrix, about 7 % of a column-A
//! simulation. The analysis is a function of the pattern alone, so a cached one is the one that
//! would have been computed, and the factors are bit-identical with or without the cache. The
//! key is the whole pattern (compared entry by entry, not hashed), the order of the matrix and
//! the columns placed last, so a hit is never a collision. The cache is bounded: at most
//! [`MAX_ENTRIES`] patterns, each of at most [`MAX_PATTERN`] entries (a larger plant's analysis is
//! a small part of its factorization cost anyway), the least recently used evicted first. This is
//! the role of a solver object built once and called many times (CasADi's `integrator`, SUNDIALS'
//! reused memory), kept here behind the `SparseLu` interface so that no caller has to carry one.

use std::sync::{Arc, Mutex, PoisonError};

use super::factors::{Factors, Source};
use super::order::DiagonalOrder;

/// Most patterns kept (in unit tests, enough that no test evicts another's pattern while it
/// checks a hit: the eviction itself is tested on a cache of its own).
#[cfg(not(test))]
const MAX_ENTRIES: usize = 8;
#[cfg(test)]
const MAX_ENTRIES: usize = 4096;
/// Largest pattern (stored entries) kept.
const MAX_PATTERN: usize = 200_000;

/// What the pattern of a live matrix alone determines: the `L`/`U` pattern (values zero) on its
/// diagonal order, which holds the order's permutations; none for a structurally singular
/// pattern or an order that does not reach every diagonal.
#[derive(Debug)]
pub(super) struct Analysis {
    pub factors: Option<Factors>,
}

impl Analysis {
    fn new(n: usize, col_ptr: &[usize], row: &[usize], last: &[bool]) -> Analysis {
        let factors = DiagonalOrder::new(n, col_ptr, row, last).and_then(|d| {
            let src = Source { col_ptr, row, col_perm: (&d.col.0, &d.col.1), row_perm: (&d.row.0, &d.row.1) };
            Factors::symbolic(&src)
        });
        Analysis { factors }
    }
}

/// A cached analysis and its key.
struct Entry {
    n: usize,
    col_ptr: Vec<usize>,
    row: Vec<usize>,
    last: Vec<bool>,
    analysis: Arc<Analysis>,
}

impl Entry {
    /// Whether this is the entry of the key `(n, col_ptr, row, last)`.
    fn is(&self, n: usize, col_ptr: &[usize], row: &[usize], last: &[bool]) -> bool {
        self.n == n && self.col_ptr == col_ptr && self.row == row && self.last == last
    }
}

/// Most recently used first.
static CACHE: Mutex<Vec<Entry>> = Mutex::new(Vec::new());

/// The analysis of the `n × n` compressed-column pattern `(col_ptr, row)` with the columns
/// marked `last` ordered after the others: from the cache, else computed (and kept if small
/// enough).
pub(super) fn analysis(n: usize, col_ptr: &[usize], row: &[usize], last: &[bool]) -> Arc<Analysis> {
    if let Some(a) = lookup(&mut CACHE.lock().unwrap_or_else(PoisonError::into_inner), n, col_ptr, row, last) {
        return a;
    }
    let analysis = Arc::new(Analysis::new(n, col_ptr, row, last));
    if row.len() <= MAX_PATTERN {
        let entry = Entry {
            n,
            col_ptr: col_ptr.to_vec(),
            row: row.to_vec(),
            last: last.to_vec(),
            analysis: Arc::clone(&analysis),
        };
        insert(&mut CACHE.lock().unwrap_or_else(PoisonError::into_inner), entry, MAX_ENTRIES);
    }
    analysis
}

/// The cached analysis of the key, moved to the front.
fn lookup(cache: &mut Vec<Entry>, n: usize, col_ptr: &[usize], row: &[usize], last: &[bool]) -> Option<Arc<Analysis>> {
    let k = cache.iter().position(|e| e.is(n, col_ptr, row, last))?;
    let entry = cache.remove(k);
    let analysis = Arc::clone(&entry.analysis);
    cache.insert(0, entry);
    Some(analysis)
}

/// `entry` at the front (unless another thread put its key there meanwhile), the least recently
/// used beyond `max` dropped.
fn insert(cache: &mut Vec<Entry>, entry: Entry, max: usize) {
    if !cache.iter().any(|e| e.is(entry.n, &entry.col_ptr, &entry.row, &entry.last)) {
        cache.insert(0, entry);
        cache.truncate(max);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The `n × n` tridiagonal pattern in compressed columns.
    fn tridiagonal(n: usize) -> (Vec<usize>, Vec<usize>) {
        let (mut col_ptr, mut row) = (vec![0], Vec::new());
        for j in 0..n {
            row.extend((j.saturating_sub(1)..(j + 2).min(n)).collect::<Vec<_>>());
            col_ptr.push(row.len());
        }
        (col_ptr, row)
    }

    /// The same key returns the same analysis (no second matching and AMD), and it is the one a
    /// fresh analysis computes; another `last` is another key, with those columns pivoted last.
    #[test]
    fn a_pattern_met_again_reuses_its_analysis_and_another_key_gets_its_own() {
        let n = 23; // no other test uses this order
        let (col_ptr, row) = tridiagonal(n);
        let none = vec![false; n];
        let first = analysis(n, &col_ptr, &row, &none);
        let again = analysis(n, &col_ptr, &row, &none);
        assert!(Arc::ptr_eq(&first, &again));
        let fresh = Analysis::new(n, &col_ptr, &row, &none);
        let (cached, fresh) = (first.factors.as_ref().unwrap(), fresh.factors.as_ref().unwrap());
        assert_eq!((cached.pivots(), cached.nnz()), (fresh.pivots(), fresh.nnz()));
        let mut last = none.clone();
        last[4] = true;
        let other = analysis(n, &col_ptr, &row, &last);
        assert!(!Arc::ptr_eq(&first, &other));
        assert_eq!(other.factors.as_ref().unwrap().pivots().1[n - 1], 4, "column 4 is eliminated last");
    }

    /// Beyond its bound the cache drops the least recently used key; a lookup makes a key the most
    /// recently used.
    #[test]
    fn the_least_recently_used_pattern_is_evicted() {
        let entry = |n: usize| {
            let (col_ptr, row) = tridiagonal(n);
            let last = vec![false; n];
            let analysis = Arc::new(Analysis::new(n, &col_ptr, &row, &last));
            Entry { n, col_ptr, row, last, analysis }
        };
        let mut cache = Vec::new();
        for n in [3, 4, 5] {
            insert(&mut cache, entry(n), 3);
        }
        let (col_ptr, row) = tridiagonal(3);
        assert!(lookup(&mut cache, 3, &col_ptr, &row, &[false; 3]).is_some());
        insert(&mut cache, entry(6), 3);
        let kept: Vec<usize> = cache.iter().map(|e| e.n).collect();
        assert_eq!(kept, [6, 3, 5], "4 was the least recently used");
        insert(&mut cache, entry(6), 3);
        assert_eq!(cache.len(), 3, "a key already held is not added twice");
    }
}
