//! Structural analysis: a maximum matching of equations to unknowns (Hopcroft–Karp would be
//! asymptotically faster; augmenting paths by depth-first search are ample for flowsheets).
//! An unmatched unknown is not determined by any equation left over; an unmatched equation
//! over-determines the system.

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
    /// Unmatched rows.
    pub fn unmatched_rows(&self) -> Vec<usize> {
        (0..self.row_to_col.len()).filter(|&i| self.row_to_col[i].is_none()).collect()
    }
    /// Unmatched columns.
    pub fn unmatched_cols(&self) -> Vec<usize> {
        (0..self.col_to_row.len()).filter(|&j| self.col_to_row[j].is_none()).collect()
    }
}

/// Maximum matching of an `n_rows × n_cols` pattern given as `(row, col)` entries.
pub fn maximum_matching(n_rows: usize, n_cols: usize, entries: &[(usize, usize)]) -> Matching {
    let adj = Adjacency::new(n_rows, entries);
    let mut m = Matching { row_to_col: vec![None; n_rows], col_to_row: vec![None; n_cols] };
    // Cheap greedy start, prefers the diagonal (own variable ↔ own equation).
    for i in 0..n_rows.min(n_cols) {
        if adj.row(i).binary_search(&i).is_ok() && m.col_to_row[i].is_none() {
            m.row_to_col[i] = Some(i);
            m.col_to_row[i] = Some(i);
        }
    }
    let mut search = Search { visited: vec![usize::MAX; n_cols], stack: Vec::new(), path: Vec::new() };
    for i in 0..n_rows {
        if m.row_to_col[i].is_none() {
            search.augment(i, &adj, &mut m);
        }
    }
    m
}

/// The columns of each row, sorted and without repeats, in one compressed array (one allocation
/// however many rows: the matching runs at every symbolic analysis of a plant's matrix).
struct Adjacency {
    ptr: Vec<usize>,
    col: Vec<usize>,
}

impl Adjacency {
    fn new(n_rows: usize, entries: &[(usize, usize)]) -> Adjacency {
        let mut ptr = vec![0usize; n_rows + 1];
        entries.iter().for_each(|&(i, _)| ptr[i + 1] += 1);
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

    fn row(&self, i: usize) -> &[usize] {
        &self.col[self.ptr[i]..self.ptr[i + 1]]
    }
}

/// The scratch of the augmenting-path searches, reused across rows.
struct Search {
    visited: Vec<usize>,
    stack: Vec<(usize, usize)>,
    path: Vec<(usize, usize)>,
}

impl Search {
    /// Look for an augmenting path from the unmatched row `root` (iterative depth-first search:
    /// columns with hundreds of trays make long chains) and flip it into `m` if found.
    fn augment(&mut self, root: usize, adj: &Adjacency, m: &mut Matching) {
        let Search { visited, stack, path } = self;
        stack.clear();
        path.clear();
        stack.push((root, 0));
        while let Some(&mut (r, ref mut k)) = stack.last_mut() {
            let Some(&c) = adj.row(r).get(*k) else {
                stack.pop();
                path.pop();
                continue;
            };
            *k += 1;
            if visited[c] == root {
                continue;
            }
            visited[c] = root;
            path.truncate(stack.len() - 1);
            path.push((r, c));
            match m.col_to_row[c] {
                None => {
                    for &(pr, pc) in path.iter() {
                        m.row_to_col[pr] = Some(pc);
                        m.col_to_row[pc] = Some(pr);
                    }
                    return;
                }
                Some(next) => stack.push((next, 0)),
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
        // Greedy diagonal takes (0,0); row 1 only has col 0, so row 0 must move to col 1.
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
        assert_eq!(m.unmatched_rows().len(), 1);
    }
}
