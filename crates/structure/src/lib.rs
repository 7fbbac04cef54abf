//! Structural analysis of sparse systems: a maximum matching of equations (rows) to unknowns
//! (columns) of an incidence pattern.
//!
//! A square system is *structurally nonsingular* when its pattern has a perfect matching: then
//! some values of the nonzeros make it invertible; without one it is singular for every value
//! (Duff, "On algorithms for obtaining a maximum transversal", ACM TOMS 7 (1981) 315–330). An
//! unmatched unknown is determined by no equation left over; an unmatched equation
//! over-determines the system.
//!
//! One implementation serves the equation text of `plantwide-expr` (is an `equations` unit
//! square, and which row does each equation take) and the solvers of `plantwide-solve` (the
//! degrees-of-freedom check, the sequential plan, the diagonal order of the sparse LU).
//!
//! # Algorithm
//! Hopcroft and Karp, "An n^{5/2} algorithm for maximum matchings in bipartite graphs", SIAM J.
//! Comput. 2 (1973) 225–231: each phase finds, by one breadth-first search from all unmatched
//! rows, the length of the shortest augmenting paths, then a maximal set of vertex-disjoint
//! augmenting paths of that length by depth-first searches that scan each edge at most once.
//! At most `2√n + 2` phases: **O(√n · nnz)** time, O(n_rows + n_cols + nnz) memory, the searches
//! iterative (no recursion, however long a column train's chains). [`maximum_matching`] starts
//! from the cheap diagonal matching (row `i` ↔ column `i` where that entry exists: a plant's own
//! variable ↔ its own equation), so on a plant's Jacobian only a few rows are left to the phases.
//!
//! The result depends only on the pattern (not on the order of the entries, nor on repeats):
//! each row's columns are sorted, and rows and columns are scanned in ascending order.
//!
//! ```
//! use plantwide_structure::maximum_matching;
//!
//! // Row 1 reads only column 0, which the diagonal start gave to row 0: the augmenting path
//! // row 1 → column 0 → row 0 → column 1 matches both.
//! let m = maximum_matching(2, 2, &[(0, 0), (0, 1), (1, 0)]);
//! assert_eq!(m.row_to_col, vec![Some(1), Some(0)]);
//! assert!(m.is_perfect());
//! ```

#![warn(missing_docs)]

/// A maximum matching between rows (equations) and columns (unknowns).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Matching {
    /// For each row, its matched column.
    pub row_to_col: Vec<Option<usize>>,
    /// For each column, its matched row.
    pub col_to_row: Vec<Option<usize>>,
}

impl Matching {
    /// Size of the matching (the structural rank).
    pub fn size(&self) -> usize {
        self.row_to_col.iter().filter(|m| m.is_some()).count()
    }

    /// Whether every row and every column is matched (so the pattern is square).
    pub fn is_perfect(&self) -> bool {
        self.row_to_col.iter().all(Option::is_some) && self.col_to_row.iter().all(Option::is_some)
    }

    /// Unmatched rows, ascending.
    pub fn unmatched_rows(&self) -> Vec<usize> {
        (0..self.row_to_col.len()).filter(|&i| self.row_to_col[i].is_none()).collect()
    }

    /// Unmatched columns, ascending.
    pub fn unmatched_cols(&self) -> Vec<usize> {
        (0..self.col_to_row.len()).filter(|&j| self.col_to_row[j].is_none()).collect()
    }
}

/// Maximum matching of an `n_rows × n_cols` pattern given as `(row, col)` entries (repeats
/// allowed), starting from the diagonal: row `i` keeps column `i` wherever the pattern has that
/// entry and a maximum matching can keep it — on a plant's Jacobian, the units' own pairing of
/// equations and variables.
///
/// # Panics
/// If an entry's row is `>= n_rows` or its column `>= n_cols`.
pub fn maximum_matching(n_rows: usize, n_cols: usize, entries: &[(usize, usize)]) -> Matching {
    let adj = Adjacency::from_entries(n_rows, n_cols, entries);
    let mut m = Matching { row_to_col: vec![None; n_rows], col_to_row: vec![None; n_cols] };
    for i in 0..n_rows.min(n_cols) {
        if adj.row(i).binary_search(&i).is_ok() {
            m.row_to_col[i] = Some(i);
            m.col_to_row[i] = Some(i);
        }
    }
    hopcroft_karp(&adj, &mut m);
    m
}

/// Maximum matching of `rows.len()` rows to `n_cols` columns, `rows[i]` listing the columns row
/// `i` reads (entries `>= n_cols` are ignored, repeats allowed). No diagonal start: the rows and
/// columns are of different kinds (the equations of a unit and its unknowns). Each row tries its
/// columns in the order listed (an equation's variables in the order it reads them), so the
/// result depends on that order as well as on the pattern.
pub fn maximum_matching_of_rows(n_cols: usize, rows: &[Vec<usize>]) -> Matching {
    let mut ptr = Vec::with_capacity(rows.len() + 1);
    let mut col = Vec::new();
    // seen[j] == i + 1: column j already listed for row i.
    let mut seen = vec![0usize; n_cols];
    ptr.push(0);
    for (i, r) in rows.iter().enumerate() {
        for &j in r {
            if j < n_cols && seen[j] != i + 1 {
                seen[j] = i + 1;
                col.push(j);
            }
        }
        ptr.push(col.len());
    }
    let adj = Adjacency { ptr, col };
    let mut m = Matching { row_to_col: vec![None; rows.len()], col_to_row: vec![None; n_cols] };
    hopcroft_karp(&adj, &mut m);
    m
}

/// The columns of each row, sorted and without repeats, in one compressed array (one allocation
/// however many rows: the matching runs at every symbolic analysis of a plant's matrix).
struct Adjacency {
    ptr: Vec<usize>,
    col: Vec<usize>,
}

impl Adjacency {
    fn from_entries(n_rows: usize, n_cols: usize, entries: &[(usize, usize)]) -> Adjacency {
        let mut ptr = vec![0usize; n_rows + 1];
        for &(i, j) in entries {
            assert!(i < n_rows && j < n_cols, "entry ({i}, {j}) outside the {n_rows} × {n_cols} pattern");
            ptr[i + 1] += 1;
        }
        (0..n_rows).for_each(|i| ptr[i + 1] += ptr[i]);
        let mut next = ptr.clone();
        let mut col = vec![0usize; entries.len()];
        for &(i, j) in entries {
            col[next[i]] = j;
            next[i] += 1;
        }
        // Sort and deduplicate each row, compacting in place.
        let mut kept = 0;
        for i in 0..n_rows {
            let (start, end) = (ptr[i], ptr[i + 1]);
            col[start..end].sort_unstable();
            ptr[i] = kept;
            for k in start..end {
                if k == start || col[k] != col[k - 1] {
                    col[kept] = col[k];
                    kept += 1;
                }
            }
        }
        ptr[n_rows] = kept;
        col.truncate(kept);
        Adjacency { ptr, col }
    }

    fn n_rows(&self) -> usize {
        self.ptr.len() - 1
    }

    fn row(&self, i: usize) -> &[usize] {
        &self.col[self.ptr[i]..self.ptr[i + 1]]
    }
}

/// Unreached rows in the breadth-first layering (and rows a phase found to be dead ends).
const UNREACHED: usize = usize::MAX;

/// Grow `m` (any matching of `adj`) to a maximum one by Hopcroft–Karp phases.
fn hopcroft_karp(adj: &Adjacency, m: &mut Matching) {
    let n_rows = adj.n_rows();
    // dist[r]: layer of row r in this phase's breadth-first search from the unmatched rows.
    let mut dist = vec![UNREACHED; n_rows];
    // next[r]: the position in `adj.col` of the next edge of row r the phase's searches try.
    let mut next = vec![0usize; n_rows];
    let mut queue: Vec<usize> = Vec::with_capacity(n_rows);
    let mut stack: Vec<usize> = Vec::new();
    loop {
        // Layers: unmatched rows at 0; a matched column leads to its row one layer down. `limit`
        // is the layer below the first one that reaches an unmatched column.
        queue.clear();
        for (r, d) in dist.iter_mut().enumerate() {
            if m.row_to_col[r].is_none() {
                *d = 0;
                queue.push(r);
            } else {
                *d = UNREACHED;
            }
        }
        let mut limit = UNREACHED;
        let mut head = 0;
        while head < queue.len() {
            let r = queue[head];
            head += 1;
            if dist[r] + 1 >= limit {
                continue;
            }
            for &c in adj.row(r) {
                match m.col_to_row[c] {
                    None => limit = dist[r] + 1,
                    Some(owner) if dist[owner] == UNREACHED => {
                        dist[owner] = dist[r] + 1;
                        queue.push(owner);
                    }
                    Some(_) => {}
                }
            }
        }
        if limit == UNREACHED {
            return;
        }
        // Vertex-disjoint shortest augmenting paths, from the unmatched rows in ascending order.
        next.copy_from_slice(&adj.ptr[..n_rows]);
        for root in 0..n_rows {
            if m.row_to_col[root].is_some() || dist[root] != 0 {
                continue;
            }
            stack.clear();
            stack.push(root);
            while let Some(&r) = stack.last() {
                if next[r] == adj.ptr[r + 1] {
                    // Every edge of r tried: a dead end for the rest of the phase.
                    dist[r] = UNREACHED;
                    stack.pop();
                    continue;
                }
                let c = adj.col[next[r]];
                next[r] += 1;
                match m.col_to_row[c] {
                    None if dist[r] + 1 == limit => {
                        // Flip the path: each row on the stack takes the column it last tried.
                        for &pr in &stack {
                            let pc = adj.col[next[pr] - 1];
                            m.row_to_col[pr] = Some(pc);
                            m.col_to_row[pc] = Some(pr);
                        }
                        break;
                    }
                    Some(owner) if dist[owner] != UNREACHED && dist[owner] == dist[r] + 1 => stack.push(owner),
                    _ => {}
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_matching_of_a_permuted_diagonal() {
        let m = maximum_matching(3, 3, &[(0, 2), (1, 0), (2, 1), (0, 0)]);
        assert_eq!(m.size(), 3);
    }

    #[test]
    fn needs_augmenting_path() {
        // The diagonal start takes (0,0); row 1 only has col 0, so row 0 must move to col 1.
        let m = maximum_matching(2, 2, &[(0, 0), (0, 1), (1, 0)]);
        assert_eq!(m.size(), 2);
        assert_eq!(m.row_to_col, vec![Some(1), Some(0)]);
    }

    #[test]
    fn structurally_singular_system_reports_the_loose_unknown() {
        // Two equations both only in x0: x1 appears nowhere.
        let m = maximum_matching(2, 2, &[(0, 0), (1, 0)]);
        assert_eq!(m.size(), 1);
        assert_eq!(m.unmatched_cols(), vec![1]);
        assert_eq!(m.unmatched_rows(), vec![1]);
    }

    #[test]
    fn rows_form_ignores_columns_out_of_range_and_keeps_the_order_given() {
        let m = maximum_matching_of_rows(2, &[vec![0, 1, 7], vec![0]]);
        assert_eq!(m.row_to_col, vec![Some(1), Some(0)]);
        // Row 2 takes the first of its columns: 2, not 1.
        let m = maximum_matching_of_rows(3, &[vec![0], vec![0], vec![2, 1, 2]]);
        assert_eq!((m.unmatched_cols(), m.row_to_col), (vec![1], vec![Some(0), None, Some(2)]));
        let m = maximum_matching_of_rows(3, &[vec![0], vec![0], vec![1]]);
        assert_eq!((m.size(), m.unmatched_rows(), m.unmatched_cols()), (2, vec![1], vec![2]));
    }

    /// SplitMix64: a fixed, dependency-free stream of test patterns.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        }
        fn below(&mut self, n: usize) -> usize {
            (self.next() % n as u64) as usize
        }
    }

    /// Maximum matching size by exhaustive search over the columns each row may take (memoized
    /// on the set of columns used, so 8 × 8 patterns stay cheap).
    fn brute_force_size(n_cols: usize, rows: &[Vec<usize>]) -> usize {
        fn best(rows: &[Vec<usize>], i: usize, used: usize, memo: &mut [Vec<Option<usize>>]) -> usize {
            if i == rows.len() {
                return 0;
            }
            if let Some(v) = memo[i][used] {
                return v;
            }
            let mut res = best(rows, i + 1, used, memo); // row i left unmatched
            for &c in &rows[i] {
                if used & (1 << c) == 0 {
                    res = res.max(1 + best(rows, i + 1, used | (1 << c), memo));
                }
            }
            memo[i][used] = Some(res);
            res
        }
        best(rows, 0, 0, &mut vec![vec![None; 1 << n_cols]; rows.len()])
    }

    fn is_valid(m: &Matching, n_cols: usize, rows: &[Vec<usize>]) -> bool {
        let rows_ok = m.row_to_col.iter().enumerate().all(|(i, c)| match *c {
            Some(c) => c < n_cols && rows[i].contains(&c) && m.col_to_row[c] == Some(i),
            None => true,
        });
        let cols_ok = m.col_to_row.iter().enumerate().all(|(j, r)| r.is_none_or(|r| m.row_to_col[r] == Some(j)));
        rows_ok && cols_ok
    }

    /// Random patterns up to 8 × 8 at several densities (square, tall and wide): both forms give a
    /// valid matching of the brute-force maximum size, and the same one whatever the entry order.
    #[test]
    fn equals_brute_force_on_random_patterns() {
        let mut rng = Rng(61);
        for case in 0..3000 {
            let (n_rows, n_cols) = (1 + rng.below(8), 1 + rng.below(8));
            let density = 1 + rng.below(5); // in fifths
            let rows: Vec<Vec<usize>> = (0..n_rows)
                .map(|_| (0..n_cols).filter(|_| rng.below(5) < density.min(4) || rng.below(20) == 0).collect())
                .collect();
            let want = brute_force_size(n_cols, &rows);
            let mut entries: Vec<(usize, usize)> =
                rows.iter().enumerate().flat_map(|(i, r)| r.iter().map(move |&j| (i, j))).collect();
            let m = maximum_matching(n_rows, n_cols, &entries);
            assert!(is_valid(&m, n_cols, &rows), "case {case}: invalid matching {m:?} of {rows:?}");
            assert_eq!(m.size(), want, "case {case}: {rows:?}");
            let mr = maximum_matching_of_rows(n_cols, &rows);
            assert!(is_valid(&mr, n_cols, &rows), "case {case}: invalid matching {mr:?} of {rows:?}");
            assert_eq!(mr.size(), want, "case {case}: {rows:?}");
            // Deterministic: shuffled and repeated entries give the same matching.
            let extra: Vec<(usize, usize)> = entries.iter().step_by(2).copied().collect();
            entries.extend(extra);
            for k in (1..entries.len()).rev() {
                entries.swap(k, rng.below(k + 1));
            }
            assert_eq!(maximum_matching(n_rows, n_cols, &entries), m, "case {case}: depends on the entry order");
        }
    }

    /// The diagonal start is kept where it is part of a maximum matching.
    #[test]
    fn keeps_a_full_diagonal() {
        let n = 50;
        let entries: Vec<(usize, usize)> = (0..n).flat_map(|i| [(i, i), (i, (i + 1) % n), (i, (i + 7) % n)]).collect();
        let m = maximum_matching(n, n, &entries);
        assert!((0..n).all(|i| m.row_to_col[i] == Some(i)));
    }

    /// A long chain that the diagonal start gets wrong everywhere: row i reads columns i and
    /// i + 1, except the last row, which reads only column 0. The only perfect matching shifts
    /// every row by one, found by one augmenting path of length n (no recursion).
    #[test]
    fn long_augmenting_path() {
        let n = 200_000;
        let mut entries: Vec<(usize, usize)> = (0..n - 1).flat_map(|i| [(i, i), (i, i + 1)]).collect();
        entries.push((n - 1, 0));
        let m = maximum_matching(n, n, &entries);
        assert!(m.is_perfect());
        assert!((0..n - 1).all(|i| m.row_to_col[i] == Some(i + 1)) && m.row_to_col[n - 1] == Some(0));
    }
}
