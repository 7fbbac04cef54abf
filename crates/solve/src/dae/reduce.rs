//! Elimination of explicit algebraic variables from the BDF iteration matrix.
//!
//! A DAE may name algebraic variables that it computes in closed form from the others
//! ([`DaeSystem::explicit`], [`DaeSystem::complete`]): a tray's holdup `M = Σ n`, its composition
//! `x = n/M`, its liquid flow from the weir. Newton then iterates only on the *kept* variables `k`
//! and the *kept* equations; after every update the explicit variables `e` are recomputed, so
//! their equations `g_e(x_k, x_e) = 0` hold exactly. The iteration matrix is that of the reduced
//! system `F(x_k, x_e(x_k))`, whose Jacobian follows by the chain rule:
//!
//! `dx_e/dx_k = −(∂g_e/∂x_e)⁻¹ (∂g_e/∂x_k + Σ_{e' before e} ∂g_e/∂x_{e'} · dx_{e'}/dx_k)`,
//! `J_red = ∂F/∂x_k + Σ_e ∂F/∂x_e · dx_e/dx_k`,
//!
//! with the explicit variables taken in the order the system computes them, so that `∂g_e/∂x_e`
//! is triangular (an equation reading an explicit variable computed after it is a defect of the
//! system, reported as [`ReduceError::Order`]). Every gradient is a sparse row: the elimination
//! never forms a dense Schur complement, so its cost is that of the fill it creates (for a
//! column, a few entries per stage).
//!
//! **Output-only variables** ([`DaeSystem::outputs`]) are set aside too: algebraic variables that
//! no equation of the kept variables reads, through any chain of equations, so that they feed
//! nothing the integrator solves (a tray temperature the constant-α equilibrium does not use).
//! Their equations form the lower block of a block-triangular system; the integrator leaves both
//! out of its iteration and solves that block only when their values are asked for. A kept
//! equation that reads one is a defect of the system ([`ReduceError::Output`]); an explicit
//! equation may (its variable is then an output too, recomputed by the completion that follows
//! the outputs' solve).
//!
//! [`DaeSystem::explicit`]: super::DaeSystem::explicit
//! [`DaeSystem::outputs`]: super::DaeSystem::outputs
//! [`DaeSystem::complete`]: super::DaeSystem::complete

use std::borrow::Cow;

/// A matrix entry `(row, column, value)`.
type Triplet = (usize, usize, f64);

/// Why a reduced Jacobian could not be formed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReduceError {
    /// `∂g_e/∂x_e = 0`: the explicit variable does not determine its own equation there.
    #[error("explicit variable {var} does not appear in its equation {equation} (zero derivative)")]
    ZeroPivot {
        /// Global equation index.
        equation: usize,
        /// Global variable index.
        var: usize,
    },
    /// The equation of an explicit variable reads one computed after it.
    #[error("equation {equation} of explicit variable {var} reads explicit variable {later}, computed after it")]
    Order {
        /// Global equation index.
        equation: usize,
        /// Its explicit variable.
        var: usize,
        /// The later explicit variable it reads.
        later: usize,
    },
    /// A kept equation reads an output-only variable, or an explicit one computed from one: the
    /// output feeds the iteration after all.
    #[error("equation {equation} reads variable {var}, an output-only variable or computed from one")]
    Output {
        /// Global equation index.
        equation: usize,
        /// The output-only variable.
        var: usize,
    },
}

/// The partition of a DAE into kept and explicit variables and equations.
#[derive(Debug, Clone, Default)]
pub(crate) struct Reduction {
    /// `(equation, variable)` of each explicit variable, in the order the system computes them.
    explicit: Vec<(usize, usize)>,
    /// `(equation, variable)` of each output-only variable.
    outputs: Vec<(usize, usize)>,
    /// Position of each variable among the explicit ones (`usize::MAX`: kept or output).
    position: Vec<usize>,
    /// Whether each variable is output-only.
    output: Vec<bool>,
    /// Reduced index of each variable (`usize::MAX`: explicit or output).
    pub(crate) col: Vec<usize>,
    /// Reduced index of each equation (`usize::MAX`: explicit or output).
    pub(crate) row: Vec<usize>,
    /// The kept variables, ascending.
    pub(crate) kept_vars: Vec<usize>,
    /// The kept equations, ascending.
    pub(crate) kept_eqs: Vec<usize>,
}

/// A sparse accumulator over the kept columns: values, and the columns touched in first-touch
/// order.
#[derive(Debug, Default)]
struct Accumulator {
    value: Vec<f64>,
    touched: Vec<usize>,
    mark: Vec<bool>,
}

impl Accumulator {
    fn new(n: usize) -> Accumulator {
        Accumulator { value: vec![0.0; n], touched: Vec::new(), mark: vec![false; n] }
    }
    fn add(&mut self, c: usize, v: f64) {
        if !self.mark[c] {
            self.mark[c] = true;
            self.touched.push(c);
        }
        self.value[c] += v;
    }
    /// The touched `(column, value)` pairs, the accumulator emptied.
    fn drain(&mut self, mut f: impl FnMut(usize, f64)) {
        for &c in &self.touched {
            f(c, self.value[c]);
            self.value[c] = 0.0;
            self.mark[c] = false;
        }
        self.touched.clear();
    }
}

impl Reduction {
    /// The partition of an `n`-variable system with the `explicit` and the output-only
    /// `outputs` `(equation, variable)` pairs. Pairs naming an index out of range or one already
    /// named are ignored.
    pub(crate) fn new(n: usize, explicit: &[(usize, usize)], outputs: &[(usize, usize)]) -> Reduction {
        let mut position = vec![usize::MAX; n];
        let mut eq_taken = vec![false; n];
        let mut pairs = Vec::with_capacity(explicit.len());
        for &(i, j) in explicit {
            if i < n && j < n && position[j] == usize::MAX && !eq_taken[i] {
                position[j] = pairs.len();
                eq_taken[i] = true;
                pairs.push((i, j));
            }
        }
        let mut output = vec![false; n];
        let mut out_pairs = Vec::with_capacity(outputs.len());
        for &(i, j) in outputs {
            if i < n && j < n && position[j] == usize::MAX && !output[j] && !eq_taken[i] {
                output[j] = true;
                eq_taken[i] = true;
                out_pairs.push((i, j));
            }
        }
        let kept_vars: Vec<usize> = (0..n).filter(|&j| position[j] == usize::MAX && !output[j]).collect();
        let kept_eqs: Vec<usize> = (0..n).filter(|&i| !eq_taken[i]).collect();
        let mut col = vec![usize::MAX; n];
        kept_vars.iter().enumerate().for_each(|(r, &j)| col[j] = r);
        let mut row = vec![usize::MAX; n];
        kept_eqs.iter().enumerate().for_each(|(r, &i)| row[i] = r);
        Reduction { explicit: pairs, outputs: out_pairs, position, output, col, row, kept_vars, kept_eqs }
    }

    /// The output-only `(equation, variable)` pairs.
    pub(crate) fn outputs(&self) -> &[(usize, usize)] {
        &self.outputs
    }

    /// Number of kept variables (= kept equations).
    pub(crate) fn n(&self) -> usize {
        self.kept_vars.len()
    }

    /// The explicit variables, in the order they are computed.
    pub(crate) fn explicit_vars(&self) -> impl Iterator<Item = usize> + '_ {
        self.explicit.iter().map(|&(_, j)| j)
    }

    /// Whether nothing is eliminated or set aside.
    pub(crate) fn is_identity(&self) -> bool {
        self.explicit.is_empty() && self.outputs.is_empty()
    }

    /// The reduced Jacobian `J_red` (module documentation) of the full Jacobian `jac` (triplets,
    /// duplicates summed), as triplets in reduced indices into `out` (cleared first). Entries
    /// that are zero at this point are not propagated: the declared patterns of units are coarse
    /// (a column declares a stage's every variable in each of its rows), and carried through the
    /// chain rule their zeros multiplied the reduced pattern by thirteen for column A. The
    /// reduced pattern may then change between points; the sparse LU's live pattern follows it
    /// as it follows the full Jacobian's nonzeros.
    ///
    /// # Errors
    /// [`ReduceError`] when an explicit variable's equation does not determine it or reads an
    /// explicit variable computed after it.
    pub(crate) fn jacobian(
        &self,
        jac: &[(usize, usize, f64)],
        out: &mut Vec<(usize, usize, f64)>,
    ) -> Result<(), ReduceError> {
        out.clear();
        let n = self.position.len();
        if self.is_identity() {
            out.extend_from_slice(jac);
            return Ok(());
        }
        let (ptr, rows) = by_row(n, jac);
        let row_of = |i: usize| &rows[ptr[i]..ptr[i + 1]];
        let mut acc = Accumulator::new(self.n());
        // The gradients `dx_e/dx_k`, one sparse row per explicit variable, in compressed rows.
        let (mut g_ptr, mut g) = (vec![0usize], Vec::<(usize, f64)>::new());
        let mut reads_output = vec![false; self.explicit.len()];
        for (k, &(i, j)) in self.explicit.iter().enumerate() {
            let mut pivot = 0.0;
            // An output read by an explicit equation makes its variable an output too (`reads`
            // marks it): no kept equation may read it (checked below), so the gradient left
            // without the output's column never reaches the iteration.
            for &(_, c, v) in row_of(i).iter().filter(|e| e.2 != 0.0) {
                match self.position[c] {
                    _ if self.output[c] => reads_output[k] = true,
                    usize::MAX => acc.add(self.col[c], v),
                    p if p == k => pivot += v,
                    p if p < k => {
                        reads_output[k] |= reads_output[p];
                        g[g_ptr[p]..g_ptr[p + 1]].iter().for_each(|&(cc, gv)| acc.add(cc, v * gv));
                    }
                    _ => return Err(ReduceError::Order { equation: i, var: j, later: c }),
                }
            }
            if pivot == 0.0 {
                acc.drain(|_, _| {});
                return Err(ReduceError::ZeroPivot { equation: i, var: j });
            }
            acc.drain(|c, v| g.push((c, -v / pivot)));
            g_ptr.push(g.len());
        }
        for (r, &i) in self.kept_eqs.iter().enumerate() {
            for &(_, c, v) in row_of(i).iter().filter(|e| e.2 != 0.0) {
                match self.position[c] {
                    p if self.output[c] || (p != usize::MAX && reads_output[p]) => {
                        acc.drain(|_, _| {});
                        return Err(ReduceError::Output { equation: i, var: c });
                    }
                    usize::MAX => acc.add(self.col[c], v),
                    p => g[g_ptr[p]..g_ptr[p + 1]].iter().for_each(|&(cc, gv)| acc.add(cc, v * gv)),
                }
            }
            acc.drain(|c, v| out.push((r, c, v)));
        }
        Ok(())
    }

    /// The block `dF_o/dx_o` of the output-only equations and variables of the full Jacobian
    /// `jac`, through the explicit variables computed from outputs (the chain rule of the module
    /// documentation restricted to the output columns: an explicit variable that reads no output,
    /// directly or through another, contributes nothing), as triplets in output positions
    /// (the order of [`Reduction::outputs`]). Its cost is that of the output rows and the
    /// explicit rows, not of the whole reduction.
    ///
    /// # Errors
    /// [`ReduceError::ZeroPivot`] when an explicit variable computed from an output does not
    /// appear in its own equation.
    pub(crate) fn output_block(&self, jac: &[(usize, usize, f64)]) -> Result<Vec<(usize, usize, f64)>, ReduceError> {
        let n = self.position.len();
        let (ptr, rows) = by_row(n, jac);
        let row_of = |i: usize| rows[ptr[i]..ptr[i + 1]].iter().filter(|e| e.2 != 0.0);
        let mut out_pos = vec![usize::MAX; n];
        self.outputs.iter().enumerate().for_each(|(k, &(_, j))| out_pos[j] = k);
        let mut acc = Accumulator::new(self.outputs.len());
        // `dx_e/dx_o` of each explicit variable (empty: it reads no output).
        let (mut g_ptr, mut g) = (vec![0usize], Vec::<(usize, f64)>::new());
        for (k, &(i, j)) in self.explicit.iter().enumerate() {
            let mut pivot = 0.0;
            for &(_, c, v) in row_of(i) {
                match self.position[c] {
                    _ if out_pos[c] != usize::MAX => acc.add(out_pos[c], v),
                    p if p == k => pivot += v,
                    p if p < k => g[g_ptr[p]..g_ptr[p + 1]].iter().for_each(|&(cc, gv)| acc.add(cc, v * gv)),
                    _ => {}
                }
            }
            if pivot == 0.0 && !acc.touched.is_empty() {
                acc.drain(|_, _| {});
                return Err(ReduceError::ZeroPivot { equation: i, var: j });
            }
            acc.drain(|c, v| g.push((c, -v / pivot)));
            g_ptr.push(g.len());
        }
        let mut out = Vec::new();
        for (r, &(i, _)) in self.outputs.iter().enumerate() {
            for &(_, c, v) in row_of(i) {
                match self.position[c] {
                    _ if out_pos[c] != usize::MAX => acc.add(out_pos[c], v),
                    usize::MAX => {}
                    p => g[g_ptr[p]..g_ptr[p + 1]].iter().for_each(|&(cc, gv)| acc.add(cc, v * gv)),
                }
            }
            acc.drain(|c, v| out.push((r, c, v)));
        }
        Ok(out)
    }
}

/// The triplets `jac` of an `n`-row matrix grouped by row: row `i`'s triplets are
/// `rows[ptr[i]..ptr[i + 1]]`, in the order they come (duplicates kept: the reduction sums
/// them). A plant's Jacobian comes row by row (each block's declared pattern is sorted, the
/// blocks follow their equations) and is then its own grouping, borrowed; any other order is
/// grouped by a counting sort.
fn by_row(n: usize, jac: &[Triplet]) -> (Vec<usize>, Cow<'_, [Triplet]>) {
    let mut ptr = vec![0usize; n + 1];
    let (mut sorted, mut last) = (true, 0);
    for &(i, j, _) in jac {
        let inside = i < n && j < n;
        if inside {
            ptr[i + 1] += 1;
        }
        sorted &= inside && i >= last;
        last = i;
    }
    for i in 0..n {
        ptr[i + 1] += ptr[i];
    }
    if sorted {
        return (ptr, Cow::Borrowed(jac));
    }
    let mut next = ptr.clone();
    let mut rows = vec![(0, 0, 0.0); ptr[n]];
    for &t in jac.iter().filter(|t| t.0 < n && t.1 < n) {
        rows[next[t.0]] = t;
        next[t.0] += 1;
    }
    (ptr, Cow::Owned(rows))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Triplets that come row by row are their own grouping (borrowed); in another order, or with
    /// an entry outside the matrix, they are grouped by the counting sort into the same rows, each
    /// in the order its entries came.
    #[test]
    fn triplets_in_row_order_are_grouped_as_they_come() {
        let sorted = vec![(0, 1, 1.0), (0, 0, 2.0), (0, 1, 3.0), (2, 2, 4.0), (2, 0, 5.0), (3, 3, 6.0)];
        let (ptr, rows) = by_row(4, &sorted);
        assert!(matches!(rows, Cow::Borrowed(_)));
        assert_eq!(ptr, [0, 3, 3, 5, 6]);
        let mut shuffled = vec![(2, 2, 4.0), (0, 1, 1.0), (3, 3, 6.0), (0, 0, 2.0), (2, 0, 5.0), (0, 1, 3.0)];
        shuffled.push((1, 4, 7.0));
        let (ptr_s, rows_s) = by_row(4, &shuffled);
        assert!(matches!(rows_s, Cow::Owned(_)));
        assert_eq!((ptr_s, rows_s.to_vec()), (ptr, rows.to_vec()));
    }

    /// Dense matrix of reduced triplets (`m × m`).
    fn dense(m: usize, t: &[(usize, usize, f64)]) -> Vec<f64> {
        let mut a = vec![0.0; m * m];
        t.iter().for_each(|&(i, j, v)| a[i * m + j] += v);
        a
    }

    /// `F(x) = [x0 + x2·x3, x2 − 2 x1, x3 − x2², x1 − 1]`: with `x2 = 2 x1` and `x3 = x2²`
    /// explicit (in that order), the reduced system in `(x0, x1)` is
    /// `F_0 = x0 + 2x1·4x1² = x0 + 8 x1³` and `F_3 = x1 − 1`, whose Jacobian is
    /// `[[1, 24 x1²], [0, 1]]` — the chain rule through two explicit levels, by hand.
    #[test]
    fn chain_rule_through_two_explicit_levels_matches_the_hand_derivative() {
        let x1: f64 = 0.7;
        let (x2, x3) = (2.0 * x1, 4.0 * x1 * x1);
        // Full Jacobian of F at x (rows: equations 0..4), with a duplicate entry split in two.
        let jac = vec![
            (0, 0, 1.0),
            (0, 2, 0.5 * x3),
            (0, 2, 0.5 * x3),
            (0, 3, x2),
            (1, 2, 1.0),
            (1, 1, -2.0),
            (2, 3, 1.0),
            (2, 2, -2.0 * x2),
            (3, 1, 1.0),
        ];
        let red = Reduction::new(4, &[(1, 2), (2, 3)], &[]);
        assert_eq!(red.kept_vars, vec![0, 1]);
        assert_eq!(red.kept_eqs, vec![0, 3]);
        let mut out = Vec::new();
        red.jacobian(&jac, &mut out).unwrap();
        let a = dense(2, &out);
        let expect = [1.0, 24.0 * x1 * x1, 0.0, 1.0];
        for (got, want) in a.iter().zip(expect) {
            assert!((got - want).abs() < 1e-14, "{a:?} vs {expect:?}");
        }
    }

    /// `F = [x0 − 1, x1 − 2 x0, x2³ − x1, x3 − x2]` with `x1`, `x3` explicit and `x2` output-only:
    /// the iteration keeps `x0` alone (the explicit `x3` reads the output, which no kept
    /// equation reads); a kept equation that reads the output, directly or through `x3`, is
    /// reported.
    #[test]
    fn outputs_leave_the_iteration_and_a_kept_equation_may_not_read_them() {
        let x2 = 2f64.cbrt();
        let jac = vec![
            (0, 0, 1.0),
            (1, 1, 1.0),
            (1, 0, -2.0),
            (2, 2, 3.0 * x2 * x2),
            (2, 1, -1.0),
            (3, 3, 1.0),
            (3, 2, -1.0),
        ];
        let red = Reduction::new(4, &[(1, 1), (3, 3)], &[(2, 2)]);
        assert_eq!((red.kept_vars.clone(), red.kept_eqs.clone()), (vec![0], vec![0]));
        let mut out = Vec::new();
        red.jacobian(&jac, &mut out).unwrap();
        assert_eq!(dense(1, &out), vec![1.0]);
        // The output block `d(x2³ − x1)/dx2 = 3 x2²`; with `x3 = x2` and a second output `x4`
        // whose equation `x4 − x3²` reads it, the chain rule through `x3`: `−2 x3·1`.
        assert_eq!(red.output_block(&jac).unwrap(), vec![(0, 0, 3.0 * x2 * x2)]);
        let mut wide = jac.clone();
        wide.extend([(4, 4, 1.0), (4, 3, -2.0 * x2)]);
        let red5 = Reduction::new(5, &[(1, 1), (3, 3)], &[(2, 2), (4, 4)]);
        let mut block = red5.output_block(&wide).unwrap();
        block.sort_by_key(|e| (e.0, e.1));
        assert_eq!(block, vec![(0, 0, 3.0 * x2 * x2), (1, 0, -2.0 * x2), (1, 1, 1.0)]);
        for (c, var) in [(2, 2), (3, 3)] {
            let mut reads = jac.clone();
            reads.push((0, c, 0.5));
            assert_eq!(red.jacobian(&reads, &mut out), Err(ReduceError::Output { equation: 0, var }));
        }
    }

    /// An explicit equation that reads an explicit variable computed after it is reported, and so
    /// is one that does not contain its own variable.
    #[test]
    fn misordered_or_absent_explicit_variables_are_reported() {
        let jac = vec![(0, 0, 1.0), (1, 1, 1.0), (1, 2, 3.0), (2, 2, 1.0), (2, 0, 1.0)];
        let mut out = Vec::new();
        let red = Reduction::new(3, &[(1, 1), (2, 2)], &[]);
        assert_eq!(red.jacobian(&jac, &mut out), Err(ReduceError::Order { equation: 1, var: 1, later: 2 }));
        let red = Reduction::new(3, &[(2, 1)], &[]);
        assert_eq!(red.jacobian(&jac, &mut out), Err(ReduceError::ZeroPivot { equation: 2, var: 1 }));
        // In the right order the same matrix reduces to the 1×1 `1` (row 0 reads nothing eliminated).
        let red = Reduction::new(3, &[(2, 2), (1, 1)], &[]);
        red.jacobian(&jac, &mut out).unwrap();
        assert_eq!(dense(1, &out), vec![1.0]);
    }
}
