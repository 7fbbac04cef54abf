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
    let mut adj = vec![Vec::new(); n_rows];
    for &(i, j) in entries {
        adj[i].push(j);
    }
    for a in &mut adj {
        a.sort_unstable();
        a.dedup();
    }
    let mut m = Matching { row_to_col: vec![None; n_rows], col_to_row: vec![None; n_cols] };
    // Cheap greedy start, prefers the diagonal (own variable ↔ own equation).
    for (i, row) in adj.iter().enumerate() {
        if i < n_cols && row.binary_search(&i).is_ok() && m.col_to_row[i].is_none() {
            m.row_to_col[i] = Some(i);
            m.col_to_row[i] = Some(i);
        }
    }
    let mut visited = vec![usize::MAX; n_cols];
    for i in 0..n_rows {
        if m.row_to_col[i].is_some() {
            continue;
        }
        augment(i, i, &adj, &mut m, &mut visited);
    }
    m
}

fn augment(root: usize, row: usize, adj: &[Vec<usize>], m: &mut Matching, visited: &mut [usize]) -> bool {
    // Iterative DFS to avoid deep recursion on long chains (columns with hundreds of trays).
    let mut stack: Vec<(usize, usize)> = vec![(row, 0)];
    let mut path: Vec<(usize, usize)> = Vec::new();
    while let Some(&mut (r, ref mut k)) = stack.last_mut() {
        if *k >= adj[r].len() {
            stack.pop();
            path.pop();
            continue;
        }
        let c = adj[r][*k];
        *k += 1;
        if visited[c] == root {
            continue;
        }
        visited[c] = root;
        path.truncate(stack.len() - 1);
        path.push((r, c));
        match m.col_to_row[c] {
            None => {
                for &(pr, pc) in &path {
                    m.row_to_col[pr] = Some(pc);
                    m.col_to_row[pc] = Some(pr);
                }
                return true;
            }
            Some(next) => stack.push((next, 0)),
        }
    }
    false
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
