//! Orderings of the live pattern.
//!
//! - [`column_order`]: COLAMD, for faer's partial-pivoting factorization; it bounds the fill
//!   whatever rows the pivoting picks.
//! - [`DiagonalOrder`]: KLU's default (T. A. Davis, E. Palamadai Natarajan, *Algorithm 907: KLU*,
//!   ACM TOMS 37 (2010) 36, §2; without its block triangular form): a maximum matching puts a
//!   structurally nonzero entry on every diagonal position (preferring equation `i` for variable
//!   `i`, the units' own pairing), and AMD orders the symmetrized pattern for pivots on that
//!   diagonal. The plant's matrices pair each equation with a variable it defines, and most
//!   algebraic equations (`x = n/M`, `y = K x`, `L = L₀ + (M − M₀)/τ`) have a unit coefficient
//!   there, so the order eliminates them first with no fill and leaves the states' coupling:
//!   column A's iteration matrix (436 × 436, 1 693 entries) factorizes into 2 469 entries of
//!   `L + U` against COLAMD's 4 480 with partial pivoting. With AMD and partial pivoting instead,
//!   the pivots leave the diagonal and the fill explodes (38 627 entries): diagonal pivots are
//!   used only where they pass the refactorization's threshold test, else COLAMD and partial
//!   pivoting take over. Columns the caller marks (those of pinned entries: the BDF's mass
//!   diagonal) keep their AMD order among themselves but come after all others, so that a change
//!   of the step coefficient, which moves only those entries, is refactorized from the first of
//!   them on (the Schur complement onto the differential variables, [`super::factors`]): for
//!   column A 88 of 436 columns at a cost of 2 598 entries of `L + U` instead of 2 469.

use faer::sparse::SymbolicSparseColMatRef;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::amd;
use faer::sparse::linalg::lu::{LuSymbolicParams, factorize_symbolic_lu};

use super::workspace;
use crate::structure::maximum_matching;

/// The COLAMD column order `(forward, inverse)` of `pattern`.
pub(super) fn column_order(pattern: SymbolicSparseColMatRef<'_, usize>) -> Option<(Vec<usize>, Vec<usize>)> {
    let params = LuSymbolicParams {
        supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
        ..Default::default()
    };
    let symbolic = factorize_symbolic_lu(pattern, params).ok()?;
    let (fwd, inv) = symbolic.col_perm().arrays();
    Some((fwd.to_vec(), inv.to_vec()))
}

/// Row and column permutations `(forward, inverse)` that put matched entries on the diagonal in
/// AMD order: permuted column `j` is column `col.0[j]`, pivoted on row `row.0[j]`.
#[derive(Debug, Clone)]
pub(super) struct DiagonalOrder {
    pub col: (Vec<usize>, Vec<usize>),
    pub row: (Vec<usize>, Vec<usize>),
}

impl DiagonalOrder {
    /// The order of the `n × n` compressed-column pattern, the columns marked `last` after the
    /// others; `None` if it is structurally singular (no perfect matching) or AMD cannot allocate.
    pub(super) fn new(n: usize, col_ptr: &[usize], row: &[usize], last: &[bool]) -> Option<DiagonalOrder> {
        let entries: Vec<(usize, usize)> =
            (0..n).flat_map(|j| row[col_ptr[j]..col_ptr[j + 1]].iter().map(move |&i| (i, j))).collect();
        let m = maximum_matching(n, n, &entries);
        let col_of_row: Vec<usize> = m.row_to_col.iter().map(|c| c.unwrap_or(usize::MAX)).collect();
        if col_of_row.contains(&usize::MAX) {
            return None;
        }
        // The matched pattern: row r renumbered as the column it is matched to.
        let matched: Vec<usize> = row.iter().map(|&r| col_of_row[r]).collect();
        let pattern = SymbolicSparseColMatRef::new_unsorted_checked(n, n, col_ptr, None, &matched);
        let (mut fwd, mut inv) = (vec![0usize; n], vec![0usize; n]);
        let req = amd::order_maybe_unsorted_scratch::<usize>(n, matched.len());
        let mut buf = Vec::new();
        amd::order_maybe_unsorted(&mut fwd, &mut inv, pattern, amd::Control::default(), workspace(&mut buf, req)?)
            .ok()?;
        let (mut fwd, rest): (Vec<usize>, Vec<usize>) = fwd.into_iter().partition(|&c| !last[c]);
        fwd.extend(rest);
        fwd.iter().enumerate().for_each(|(i, &c)| inv[c] = i);
        let row_of_col: Vec<usize> = m.col_to_row.iter().map(|r| r.unwrap_or(usize::MAX)).collect();
        let row_fwd: Vec<usize> = fwd.iter().map(|&c| row_of_col[c]).collect();
        let mut row_inv = vec![0usize; n];
        row_fwd.iter().enumerate().for_each(|(i, &r)| row_inv[r] = i);
        Some(DiagonalOrder { col: (fwd, inv), row: (row_fwd, row_inv) })
    }
}
