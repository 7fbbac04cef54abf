//! LU factors held in our own compressed-column arrays, refactorized in place for new values on
//! the same pattern and pivot sequence, and the triangular solves on them.
//!
//! **Why not faer alone.** faer's simplicial LU (Gilbert–Peierls, partial pivoting) repeats the
//! depth-first reach of every column and the pivot search at every factorization. When only the
//! values change, as between the BDF's iteration matrices `M − cJ` of one Jacobian or between
//! Newton iterations, both are known already: with the row permutation kept, the pattern of `L`
//! and `U` is the structural reach and closed under the elimination, so a refactorization is the
//! left-looking elimination alone (the "refactor" of KLU: T. A. Davis, E. Palamadai Natarajan,
//! *Algorithm 907: KLU*, ACM TOMS 37 (2010) 36, §2.4). faer 0.24 has no such entry point, nor an
//! LU on a given pivot sequence, hence this file (with the symbolic analysis for given
//! permutations that the diagonal order of `order.rs` and a restored run need).
//!
//! **Stability.** A pivot kept from an earlier factorization, or proposed by the diagonal order,
//! is accepted only if it is at least [`PIVOT_THRESHOLD`] times the largest entry below it in its
//! column, both measured in the row-equilibrated matrix (threshold partial pivoting with KLU's
//! default tolerance, 10⁻³, and its default scaling by row maxima), finite and nonzero; otherwise
//! the caller factorizes afresh with partial pivoting.
//!
//! Notation: `P_r A Q = L U` with `L` unit lower triangular and `U` upper triangular, both indexed
//! in the permuted order; `row_fwd[i]` is the original row of permuted row `i`.

/// Smallest ratio of a kept pivot to the largest entry below it in its column.
pub(super) const PIVOT_THRESHOLD: f64 = 1e-3;

/// Why a refactorization was refused: the caller factorizes with pivoting instead.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct NeedsPivoting {
    /// The elimination step whose pivot was refused.
    pub column: usize,
}

/// `L` (strictly lower part) and `U` (strictly upper part and diagonal) in compressed columns
/// with ascending rows, the permutations, and where each entry of the matrix goes.
#[derive(Debug, Default, Clone)]
pub(super) struct Factors {
    n: usize,
    l_ptr: Vec<usize>,
    l_row: Vec<usize>,
    l_val: Vec<f64>,
    u_ptr: Vec<usize>,
    u_row: Vec<usize>,
    u_val: Vec<f64>,
    /// Reciprocals of `U`'s diagonal (a division per column was a third of a solve).
    u_inv: Vec<f64>,
    row_fwd: Vec<usize>,
    col_inv: Vec<usize>,
    col_fwd: Vec<usize>,
    row_inv: Vec<usize>,
    /// Per permuted column: the permuted rows and value indices of the matrix's entries.
    a_ptr: Vec<usize>,
    a_row: Vec<usize>,
    a_idx: Vec<usize>,
    /// `L` and `U` by rows, for the solves with `A` ([`ByRows`]).
    l_rows: ByRows,
    u_rows: ByRows,
    /// Dense accumulator of the elimination (all zero between calls), and the solves' scratch.
    work: Vec<f64>,
    tmp: Vec<f64>,
    /// Reciprocal row maxima of the matrix refactorized (permuted rows), for the pivot test.
    row_scale: Vec<f64>,
    /// The values the factors were last computed from (indexed as the source's compressed
    /// columns), if they hold them: a refactorization resumes at the first column whose entries
    /// changed (see [`Factors::refactor`]).
    factored: Option<Vec<f64>>,
    /// For each value index, the permuted column and row it lies in.
    col_of: Vec<usize>,
    row_of: Vec<usize>,
    /// The row maxima of `|values|` over the permuted columns before `.0`, kept between
    /// refactorizations that leave those columns unchanged (the partial ones).
    head_max: Option<(usize, Vec<f64>)>,
    /// The row maxima of `|values|` over the entries outside the `changed` list of
    /// [`Factors::refactor`], kept between refactorizations that change only those entries (the
    /// shifts of the BDF's iteration matrix): only the listed entries are then folded in.
    fixed_max: Option<Vec<f64>>,
    /// Columns eliminated by refactorizations so far (tests).
    #[cfg(test)]
    eliminated: usize,
}

/// The matrix pattern and permutations a set of factors was made for.
pub(super) struct Source<'a> {
    /// Compressed columns of the matrix (original order).
    pub col_ptr: &'a [usize],
    pub row: &'a [usize],
    /// Column permutation `(forward, inverse)`: permuted column `j` is original `col_fwd[j]`.
    pub col_perm: (&'a [usize], &'a [usize]),
    /// Row permutation `(forward, inverse)`.
    pub row_perm: (&'a [usize], &'a [usize]),
}

impl Factors {
    /// The pattern of `L` and `U` of `P_r A Q` for the permutations of `src` (values zero): column
    /// `j`'s rows are those reachable from the rows of `Â_{·j}` through the columns `k < j` of `L`
    /// (Gilbert & Peierls, SIAM J. Sci. Stat. Comput. 9 (1988) 862), each sorted. `None` if the
    /// diagonal is not reached (the permutations leave a structurally zero pivot).
    pub(super) fn symbolic(src: &Source<'_>) -> Option<Factors> {
        let n = src.col_ptr.len() - 1;
        let mut f = Factors { n, work: vec![0.0; n], tmp: vec![0.0; n], u_inv: vec![0.0; n], ..Factors::default() };
        f.row_fwd = src.row_perm.0.to_vec();
        f.row_inv = src.row_perm.1.to_vec();
        f.col_fwd = src.col_perm.0.to_vec();
        f.col_inv = src.col_perm.1.to_vec();
        f.a_ptr.push(0);
        for j in 0..n {
            let c = f.col_fwd[j];
            for k in src.col_ptr[c]..src.col_ptr[c + 1] {
                f.a_row.push(f.row_inv[src.row[k]]);
                f.a_idx.push(k);
            }
            f.a_ptr.push(f.a_row.len());
        }
        (f.col_of, f.row_of) = (vec![0; f.a_idx.len()], vec![0; f.a_idx.len()]);
        for j in 0..n {
            for p in f.a_ptr[j]..f.a_ptr[j + 1] {
                (f.col_of[f.a_idx[p]], f.row_of[f.a_idx[p]]) = (j, f.a_row[p]);
            }
        }
        let (mut mark, mut stack, mut reach) = (vec![usize::MAX; n], Vec::new(), Vec::new());
        f.l_ptr.push(0);
        f.u_ptr.push(0);
        for j in 0..n {
            reach.clear();
            for &i in &f.a_row[f.a_ptr[j]..f.a_ptr[j + 1]] {
                if mark[i] != j {
                    mark[i] = j;
                    stack.push(i);
                }
                while let Some(k) = stack.pop() {
                    reach.push(k);
                    if k < j {
                        for &r in &f.l_row[f.l_ptr[k]..f.l_ptr[k + 1]] {
                            if mark[r] != j {
                                mark[r] = j;
                                stack.push(r);
                            }
                        }
                    }
                }
            }
            if mark[j] != j {
                return None;
            }
            reach.sort_unstable();
            f.u_row.extend(reach.iter().filter(|&&i| i < j));
            f.u_ptr.push(f.u_row.len());
            f.l_row.extend(reach.iter().filter(|&&i| i > j));
            f.l_ptr.push(f.l_row.len());
        }
        f.u_val = vec![0.0; f.u_row.len()];
        f.l_val = vec![0.0; f.l_row.len()];
        f.l_rows = ByRows::new(n, &f.l_ptr, &f.l_row, |i, k| i == k + 1);
        f.u_rows = ByRows::new(n, &f.u_ptr, &f.u_row, |i, k| i + 1 == k);
        Some(f)
    }

    /// Columns eliminated by the refactorizations of these factors.
    #[cfg(test)]
    pub(super) fn eliminated(&self) -> usize {
        self.eliminated
    }

    /// Entries of `L + U` (the diagonal counted once).
    pub(super) fn nnz(&self) -> usize {
        self.l_row.len() + self.u_row.len() + self.n
    }

    /// The row and column permutations (`row_fwd[i]`, `col_fwd[i]`: the original row and column
    /// of pivot `i`).
    pub(super) fn pivots(&self) -> (&[usize], &[usize]) {
        (&self.row_fwd, &self.col_fwd)
    }

    /// Refactorize for new `values` of the same pattern (indexed as the source's compressed
    /// columns), keeping the pivot sequence: the left-looking elimination of column `j` of
    /// `P_r A Q`, `x = Â_j; x_k −= L_{·k} x_k` for the rows `k` of `U_{·j}` in ascending order,
    /// `U_{kj} = x_k`, `L_{ij} = x_i / x_j`. With `check`, a pivot below [`PIVOT_THRESHOLD`] of
    /// its column is refused; a zero or non-finite pivot always is. On [`NeedsPivoting`] the
    /// factors are left invalid.
    ///
    /// **Partial refactorization.** Column `j` of `L` and `U` is a function of `Â_{·j}` and the
    /// columns `k < j` of `L` only, so when the factors hold earlier values that agree with
    /// `values` (bit for bit) in the columns before `j₀`, the elimination resumes at `j₀` and
    /// the result is the full refactorization's, bit for bit. The BDF's iteration matrix changes
    /// only on its mass diagonal with the step coefficient, and the diagonal order puts those
    /// columns last (`order.rs`): column A's refactorization redoes 88 of 436 columns. The pivot
    /// test of the kept columns is repeated with the new row scaling, on their stored `L`
    /// (`|L_ij|·s_i ≤ s_j/τ` is the test `|x_i|·s_i ≤ |x_j|·s_j/τ` divided by `|x_j|`).
    ///
    /// `changed`, when given, lists the only value indices that can differ from the values the
    /// factors hold (the caller rewrote no others); otherwise every entry is compared.
    pub(super) fn refactor(
        &mut self,
        values: &[f64],
        check: bool,
        changed: Option<&[usize]>,
    ) -> Result<(), NeedsPivoting> {
        let start = match changed {
            Some(ks) => self.first_changed_among(values, ks),
            None => self.first_changed(values),
        };
        debug_assert!(start <= self.first_changed(values), "an entry changed outside `changed`");
        let factored = self.factored.take();
        // The maxima outside `changed` hold only while nothing else can have changed.
        if factored.is_none() || changed.is_none() {
            self.fixed_max = None;
        }
        self.eliminate(values, check, start, changed)?;
        let mut held = factored.unwrap_or_default();
        held.clear();
        held.extend_from_slice(values);
        self.factored = Some(held);
        Ok(())
    }

    /// The first permuted column with an entry that differs from the values the factors hold
    /// (`0` if they hold none, `n` if none differs).
    fn first_changed(&self, values: &[f64]) -> usize {
        let Some(old) = self.factored.as_ref().filter(|old| old.len() == values.len()) else { return 0 };
        let changed = |p: usize| values[self.a_idx[p]].to_bits() != old[self.a_idx[p]].to_bits();
        (0..self.n).find(|&j| (self.a_ptr[j]..self.a_ptr[j + 1]).any(changed)).unwrap_or(self.n)
    }

    /// [`Factors::first_changed`] when only the value indices `ks` can have changed.
    fn first_changed_among(&self, values: &[f64], ks: &[usize]) -> usize {
        let Some(old) = self.factored.as_ref().filter(|old| old.len() == values.len()) else { return 0 };
        ks.iter().filter(|&&k| values[k].to_bits() != old[k].to_bits()).map(|&k| self.col_of[k]).min().unwrap_or(self.n)
    }

    /// Reciprocal row maxima of `|values|` into `row_scale`: with `changed` (the only entries
    /// that can differ from the values factored last) by [`Factors::scale_rows_changed`];
    /// otherwise the maxima over the columns before `start` (unchanged since the last
    /// refactorization from the same `start`) come from `head_max`, else are computed and kept
    /// there.
    fn scale_rows(&mut self, values: &[f64], start: usize, changed: Option<&[usize]>) {
        if let Some(ks) = changed {
            self.scale_rows_changed(values, ks);
            return;
        }
        let row_max = |range: std::ops::Range<usize>, into: &mut [f64]| {
            for (&i, &k) in self.a_row[range.clone()].iter().zip(&self.a_idx[range]) {
                into[i] = into[i].max(values[k].abs());
            }
        };
        let head = match self.head_max.take() {
            Some((b, head)) if b == start => head,
            _ => {
                let mut head = vec![0.0; self.n];
                row_max(0..self.a_ptr[start], &mut head);
                head
            }
        };
        let scale = &mut self.row_scale;
        scale.clear();
        scale.extend_from_slice(&head);
        row_max(self.a_ptr[start]..self.a_ptr[self.n], scale);
        scale.iter_mut().for_each(|s| *s = if *s > 0.0 { 1.0 / *s } else { 1.0 });
        self.head_max = Some((start, head));
    }

    /// [`Factors::scale_rows`] when only the entries `ks` can have changed: the maxima over the
    /// other entries come from `fixed_max` (computed once and kept there) and only the `ks` are
    /// folded in. A maximum is the same whatever the order its entries are taken in: the scales,
    /// and so the pivot test, are those of one pass over every entry.
    fn scale_rows_changed(&mut self, values: &[f64], ks: &[usize]) {
        let fixed = match self.fixed_max.take() {
            Some(fixed) => fixed,
            None => {
                let mut listed = vec![false; values.len()];
                ks.iter().for_each(|&k| listed[k] = true);
                let mut fixed = vec![0.0f64; self.n];
                for (&i, &k) in self.a_row.iter().zip(&self.a_idx).filter(|&(_, &k)| !listed[k]) {
                    fixed[i] = fixed[i].max(values[k].abs());
                }
                fixed
            }
        };
        let scale = &mut self.row_scale;
        scale.clear();
        scale.extend_from_slice(&fixed);
        for &k in ks {
            let i = self.row_of[k];
            scale[i] = scale[i].max(values[k].abs());
        }
        scale.iter_mut().for_each(|s| *s = if *s > 0.0 { 1.0 / *s } else { 1.0 });
        self.fixed_max = Some(fixed);
        // The listed entries may lie in any column: the head maxima no longer hold.
        self.head_max = None;
    }

    /// The elimination of [`Factors::refactor`] from column `start` on (the columns before it kept,
    /// their pivot test repeated under `check`).
    fn eliminate(
        &mut self,
        values: &[f64],
        check: bool,
        start: usize,
        changed: Option<&[usize]>,
    ) -> Result<(), NeedsPivoting> {
        let threshold = if check { PIVOT_THRESHOLD } else { 0.0 };
        // The test is on the row-equilibrated matrix (KLU's default scaling by row maxima): the
        // plant's equations have their own units, a pivot is small or large against its row.
        if check {
            self.scale_rows(values, start, changed);
        } else {
            self.head_max = None;
            self.row_scale.clear();
            self.row_scale.resize(self.n, 0.0);
        }
        let scale = &self.row_scale;
        if check {
            for (j, w) in self.l_ptr.windows(2).enumerate().take(start) {
                let l = &self.l_row[w[0]..w[1]];
                let largest =
                    l.iter().zip(&self.l_val[w[0]..w[1]]).fold(0.0f64, |m, (&i, v)| m.max(v.abs() * scale[i]));
                if scale[j] < threshold * largest {
                    return Err(NeedsPivoting { column: j });
                }
            }
        }
        #[cfg(test)]
        {
            self.eliminated += self.n - start;
        }
        // Every array as a local slice: its pointer and length are then values the loops keep,
        // where through `self` they were reloaded after each store into `x` (which the compiler
        // cannot tell from the vectors' headers): a tenth of the refactorization's instructions.
        let (a_ptr, a_row, a_idx) = (&self.a_ptr[..], &self.a_row[..], &self.a_idx[..]);
        let (l_ptr, l_row, l_val) = (&self.l_ptr[..], &self.l_row[..], &mut self.l_val[..]);
        let (u_ptr, u_row, u_val) = (&self.u_ptr[..], &self.u_row[..], &mut self.u_val[..]);
        let (u_inv, x) = (&mut self.u_inv[..], &mut self.work[..]);
        for j in start..self.n {
            let a = a_ptr[j]..a_ptr[j + 1];
            for (&i, &k) in a_row[a.clone()].iter().zip(&a_idx[a]) {
                x[i] = values[k];
            }
            let u = u_ptr[j]..u_ptr[j + 1];
            for (&k, uv) in u_row[u.clone()].iter().zip(&mut u_val[u]) {
                let xk = x[k];
                x[k] = 0.0;
                *uv = xk;
                if xk != 0.0 {
                    let l = l_ptr[k]..l_ptr[k + 1];
                    for (&i, &v) in l_row[l.clone()].iter().zip(&l_val[l]) {
                        x[i] -= v * xk;
                    }
                }
            }
            let pivot = x[j];
            x[j] = 0.0;
            let l = l_ptr[j]..l_ptr[j + 1];
            let largest = l_row[l.clone()].iter().fold(0.0f64, |m, &i| m.max(x[i].abs() * scale[i]));
            if !(pivot.is_finite() && pivot != 0.0 && pivot.abs() * scale[j] >= threshold * largest) {
                x.iter_mut().for_each(|v| *v = 0.0);
                return Err(NeedsPivoting { column: j });
            }
            let inv = 1.0 / pivot;
            for (&i, lv) in l_row[l.clone()].iter().zip(&mut l_val[l]) {
                *lv = x[i] * inv;
                x[i] = 0.0;
            }
            u_inv[j] = inv;
        }
        self.copy_by_rows(start);
        Ok(())
    }

    /// The entries of the columns from `start` on into the row copies, `U`'s scaled by the
    /// reciprocal of their row's pivot (the rows before `start` keep theirs: a kept column's
    /// pivot is unchanged).
    fn copy_by_rows(&mut self, start: usize) {
        for p in self.l_ptr[start]..self.l_row.len() {
            self.l_rows.set(p, self.l_val[p]);
        }
        for p in self.u_ptr[start]..self.u_row.len() {
            self.u_rows.set(p, self.u_val[p] * self.u_inv[self.u_row[p]]);
        }
    }

    /// Solve `A x = b` (`x = Q U⁻¹ L⁻¹ P_r b`) or, with `transpose`, `Aᵀ x = b`
    /// (`x = P_rᵀ L⁻ᵀ U⁻ᵀ Qᵀ b`), in place.
    pub(super) fn solve(&mut self, b: &mut [f64], transpose: bool) {
        let t = &mut self.tmp;
        let l = Triangle { ptr: &self.l_ptr, row: &self.l_row, val: &self.l_val };
        let u = Triangle { ptr: &self.u_ptr, row: &self.u_row, val: &self.u_val };
        let (into, out) = if transpose { (&self.col_fwd, &self.row_inv) } else { (&self.row_fwd, &self.col_inv) };
        t.iter_mut().zip(into).for_each(|(ti, &r)| *ti = b[r]);
        if transpose {
            u.transposed_forward(t, &self.u_inv);
            l.transposed_backward(t);
        } else {
            self.l_rows.forward(t);
            self.u_rows.backward(t, &self.u_inv);
        }
        b.iter_mut().zip(out).for_each(|(bi, &r)| *bi = t[r]);
    }
}

/// A triangular factor's strict part by rows, for the solves with `A`: row `i`'s entries in
/// compressed rows, except the one next to the diagonal (column `i − 1` of `L`, `i + 1` of `U`),
/// kept apart in `near` (zero where there is none).
///
/// **Why by rows, and why apart.** The solves are a chain: each unknown needs the one before it
/// (column A's block-tridiagonal factors carry a dependency from every row to the next). By
/// columns (`t_i −= L_ij x_j` over column `j`), each link is a store, a load of the value just
/// stored, a multiplication and a subtraction; by rows (`x_i = t_i − Σ_j L_ij x_j`) with the
/// entry next to the diagonal taken last, from the value just computed and still in a register,
/// it is the multiplication and subtraction alone, the rest of the row computed while the
/// previous unknown is. `U`'s rows are stored divided by their pivot, which takes the
/// multiplication by the pivot's reciprocal off the chain too. On column A's feed-step run the
/// solves take 0.73 of their time by columns (perf samples over 1500 runs). The solves with
/// `Aᵀ` read the columns, which are the rows of `Lᵀ` and `Uᵀ`.
#[derive(Debug, Default, Clone)]
struct ByRows {
    ptr: Vec<usize>,
    col: Vec<usize>,
    val: Vec<f64>,
    near: Vec<f64>,
    /// For each entry of the factor by columns: its index in `val`, or `val.len() + i` for the
    /// `near` entry of row `i`.
    to: Vec<usize>,
}

impl ByRows {
    /// The rows of the `n × n` compressed columns `(ptr, row)` (values zero); `near(i, k)` tells
    /// whether the entry at row `i`, column `k` is the one kept apart.
    fn new(n: usize, ptr: &[usize], row: &[usize], near: impl Fn(usize, usize) -> bool) -> ByRows {
        let mut rows = ByRows { ptr: vec![0; n + 1], near: vec![0.0; n], to: vec![0; row.len()], ..ByRows::default() };
        for k in 0..n {
            for &i in &row[ptr[k]..ptr[k + 1]] {
                if !near(i, k) {
                    rows.ptr[i + 1] += 1;
                }
            }
        }
        for i in 0..n {
            rows.ptr[i + 1] += rows.ptr[i];
        }
        let total = rows.ptr[n];
        let mut next = rows.ptr[..n].to_vec();
        rows.col = vec![0; total];
        rows.val = vec![0.0; total];
        for (k, w) in ptr.windows(2).enumerate() {
            for (p, &i) in (w[0]..w[1]).zip(&row[w[0]..w[1]]) {
                rows.to[p] = if near(i, k) {
                    total + i
                } else {
                    rows.col[next[i]] = k;
                    next[i] += 1;
                    next[i] - 1
                };
            }
        }
        rows
    }

    /// Value `v` for entry `p` of the factor by columns.
    fn set(&mut self, p: usize, v: f64) {
        let (to, total) = (self.to[p], self.val.len());
        if to < total {
            self.val[to] = v;
        } else {
            self.near[to - total] = v;
        }
    }

    /// `s − Σ_k v_ik t_k` over the entries of row `i`.
    #[inline(always)]
    fn row_sum(&self, t: &[f64], i: usize, s: f64) -> f64 {
        let (a, b) = (self.ptr[i], self.ptr[i + 1]);
        self.col[a..b].iter().zip(&self.val[a..b]).fold(s, |s, (&k, &v)| s - v * t[k])
    }

    /// `t ← L⁻¹ t` for unit lower triangular `L`.
    fn forward(&self, t: &mut [f64]) {
        let mut prev = 0.0;
        for i in 0..t.len() {
            let x = self.row_sum(t, i, t[i]) - self.near[i] * prev;
            t[i] = x;
            prev = x;
        }
    }

    /// `t ← U⁻¹ t` for these rows of `U` divided by their pivot, and the pivots' reciprocals
    /// `inv`.
    fn backward(&self, t: &mut [f64], inv: &[f64]) {
        let mut next = 0.0;
        for i in (0..t.len()).rev() {
            let x = self.row_sum(t, i, t[i] * inv[i]) - self.near[i] * next;
            t[i] = x;
            next = x;
        }
    }
}

/// A triangular factor's strict part in compressed columns (rows ascending).
struct Triangle<'a> {
    ptr: &'a [usize],
    row: &'a [usize],
    val: &'a [f64],
}

impl Triangle<'_> {
    /// The (row, value) pairs of each column in turn.
    fn columns(&self) -> impl DoubleEndedIterator<Item = (&[usize], &[f64])> + ExactSizeIterator {
        self.ptr.windows(2).map(|w| (&self.row[w[0]..w[1]], &self.val[w[0]..w[1]]))
    }

    /// `t ← U⁻ᵀ t` for `U` of these strict entries and diagonal reciprocals `inv` (the columns
    /// of `U` are the rows of `Uᵀ`: `t_j ← (t_j − Σ_i U_ij t_i)·inv_j`).
    fn transposed_forward(&self, t: &mut [f64], inv: &[f64]) {
        for (j, (rows, vals)) in self.columns().enumerate() {
            let s: f64 = rows.iter().zip(vals).map(|(&i, &v)| v * t[i]).sum();
            t[j] = (t[j] - s) * inv[j];
        }
    }

    /// `t ← L⁻ᵀ t` for unit lower triangular `L`.
    fn transposed_backward(&self, t: &mut [f64]) {
        for (j, (rows, vals)) in self.columns().enumerate().rev() {
            let s: f64 = rows.iter().zip(vals).map(|(&i, &v)| v * t[i]).sum();
            t[j] -= s;
        }
    }
}
