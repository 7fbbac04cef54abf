//! Structural analysis: can each equation be assigned its own unknown?
//!
//! A square system is *structurally nonsingular* when its incidence matrix (equation `i` reads
//! unknown `j`) has a perfect matching: then some values of the nonzeros make the Jacobian
//! invertible; without one, it is singular for every value (Duff, "On algorithms for obtaining
//! a maximum transversal", ACM TOMS 7 (1981) 315–330; Pantelides, SIAM J. Sci. Stat. Comput. 9
//! (1988) 213–231, for the index of DAEs). The matching itself is `plantwide-structure`'s.

use crate::compiled::Equation;
use crate::symbols::{SymbolTable, VarKind};

/// A maximum matching of equations (rows) to unknowns (columns).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Matching {
    /// The unknown assigned to each equation.
    pub unknown_of: Vec<Option<usize>>,
    /// The equation assigned to each unknown.
    pub equation_of: Vec<Option<usize>>,
}

impl Matching {
    /// Number of matched pairs.
    pub fn size(&self) -> usize {
        self.unknown_of.iter().flatten().count()
    }

    /// Whether every equation and every unknown is matched (so the system is square).
    pub fn is_perfect(&self) -> bool {
        self.unknown_of.iter().all(Option::is_some) && self.equation_of.iter().all(Option::is_some)
    }

    /// Equations without an unknown, ascending.
    pub fn unmatched_equations(&self) -> Vec<usize> {
        (0..self.unknown_of.len()).filter(|&i| self.unknown_of[i].is_none()).collect()
    }

    /// Unknowns without an equation, ascending.
    pub fn unmatched_unknowns(&self) -> Vec<usize> {
        (0..self.equation_of.len()).filter(|&j| self.equation_of[j].is_none()).collect()
    }
}

/// A maximum bipartite matching of `rows.len()` equations to `n_unknowns` unknowns, where
/// `rows[i]` lists the unknowns equation `i` reads (entries `>= n_unknowns` are ignored).
///
/// Hopcroft–Karp ([`plantwide_structure::maximum_matching_of_rows`], shared with the solvers):
/// **O(√n · nnz)** time, O(n_equations + n_unknowns + nnz) memory, no recursion.
pub fn maximum_matching(n_unknowns: usize, rows: &[Vec<usize>]) -> Matching {
    let m = plantwide_structure::maximum_matching_of_rows(n_unknowns, rows);
    Matching { unknown_of: m.row_to_col, equation_of: m.col_to_row }
}

/// Which unknowns the incidence pattern is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StructureMode {
    /// Steady state: `der(x) = 0`, so an equation's unknowns are the variables it reads.
    Steady,
    /// Dynamics (index 1): a differential variable is a known state and its derivative is the
    /// unknown; an algebraic variable is itself the unknown. An equation's unknowns are the
    /// derivatives it reads plus the algebraic variables it reads.
    Dynamic,
}

/// A structurally singular equation set.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "the equations are structurally singular ({n_equations} equations, {n_unknowns} unknowns); \
     left without an unknown: {}; left without an equation: {}",
    name_list(.unmatched_equations), name_list(.unmatched_unknowns)
)]
pub struct StructuralError {
    /// Number of equations.
    pub n_equations: usize,
    /// Number of unknowns.
    pub n_unknowns: usize,
    /// Texts of the equations left unmatched by a maximum matching.
    pub unmatched_equations: Vec<String>,
    /// Names of the unknowns left unmatched (`der(x)` for derivatives in dynamic mode).
    pub unmatched_unknowns: Vec<String>,
}

/// Most names [`name_list`] writes out: an equation set flooded with copies (a file with 10 000
/// repeated equations) is named by its first few and a count, not by a message of megabytes.
pub const MAX_LISTED: usize = 10;

/// Names for a message: each quoted, comma-separated, at most [`MAX_LISTED`] of them and then how
/// many more; `none` for none.
pub fn name_list<S: AsRef<str>>(items: &[S]) -> String {
    if items.is_empty() {
        return "none".to_owned();
    }
    let shown: Vec<String> = items.iter().take(MAX_LISTED).map(|s| format!("`{}`", s.as_ref())).collect();
    match items.len().saturating_sub(MAX_LISTED) {
        0 => shown.join(", "),
        more => format!("{}, … and {more} more", shown.join(", ")),
    }
}

/// Checks that `equations` determine the variables at indices `unknowns`: a perfect matching of
/// equations to unknowns in `mode`. Returns the unknown (an index into `x`, or into `dx` for a
/// differential variable in [`StructureMode::Dynamic`]) assigned to each equation.
///
/// A maximum matching is not unique, so which equations and unknowns are reported unmatched is
/// one valid choice; their counts are exact (the deficiency of the system).
///
/// # Errors
/// [`StructuralError`] naming the unmatched equations (by text) and unknowns (by name).
pub fn check_structure(
    equations: &[Equation],
    unknowns: &[usize],
    mode: StructureMode,
    symbols: &SymbolTable,
) -> Result<Vec<usize>, StructuralError> {
    let column_of = |i: usize| unknowns.iter().position(|&u| u == i);
    let differential = |i: usize| symbols.variable_kind(i) == Some(VarKind::Differential);
    let rows: Vec<Vec<usize>> = equations
        .iter()
        .map(|eq| {
            let algebraic = eq.variables().iter().filter(|&&i| mode == StructureMode::Steady || !differential(i));
            let ders = eq.derivatives().iter().filter(|_| mode == StructureMode::Dynamic);
            algebraic.chain(ders).filter_map(|&i| column_of(i)).collect()
        })
        .collect();
    let m = maximum_matching(unknowns.len(), &rows);
    if m.is_perfect() {
        return Ok(m.unknown_of.iter().map(|u| unknowns[u.unwrap_or_default()]).collect());
    }
    let name = |j: usize| {
        let i = unknowns[j];
        let base = symbols.variable_name(i).map_or_else(|| format!("x[{i}]"), str::to_owned);
        if mode == StructureMode::Dynamic && differential(i) { format!("der({base})") } else { base }
    };
    Err(StructuralError {
        n_equations: equations.len(),
        n_unknowns: unknowns.len(),
        unmatched_equations: m.unmatched_equations().into_iter().map(|i| equations[i].text().to_owned()).collect(),
        unmatched_unknowns: m.unmatched_unknowns().into_iter().map(name).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matching_needs_augmenting_paths() {
        // Greedy would give eq0 → 0 and leave eq1 (which reads only 0) unmatched; the
        // augmenting path eq1 → 0 → eq0 → 1 matches both.
        let m = maximum_matching(2, &[vec![0, 1], vec![0]]);
        assert!(m.is_perfect());
        assert_eq!(m.unknown_of, vec![Some(1), Some(0)]);
    }

    #[test]
    fn deficiency_is_reported() {
        // Two equations read only unknown 0; unknown 2 is read by nobody.
        let m = maximum_matching(3, &[vec![0], vec![0], vec![1]]);
        assert_eq!(m.size(), 2);
        assert_eq!(m.unmatched_equations(), vec![1]);
        assert_eq!(m.unmatched_unknowns(), vec![2]);
    }
}
