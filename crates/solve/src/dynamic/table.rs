//! A run's recorded rows: rows of one width stored one after another.
//!
//! A run records a row at every interval (column A's 2000-minute feed step: 1001 rows of a
//! handful of values). One vector per row was an allocation and a free per row, and the
//! allocator a tenth of the run's time; here a run grows one buffer. Rows are read as slices:
//! `table[i]`, `table.iter()`, `table.last()`, as the vector of vectors they replace was.

use std::ops::Index;

/// Rows of `width` values (the recorded columns), in recording order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Table {
    width: usize,
    rows: usize,
    data: Vec<f64>,
}

impl Table {
    /// An empty table of rows of `width` values, with room for `rows` of them.
    pub fn with_capacity(width: usize, rows: usize) -> Table {
        Table { width, rows: 0, data: Vec::with_capacity(width.saturating_mul(rows)) }
    }

    /// Values per row.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.rows
    }

    /// Whether there is no row.
    pub fn is_empty(&self) -> bool {
        self.rows == 0
    }

    /// Append the row of `values`.
    ///
    /// # Panics
    /// If `values` does not hold exactly [`Table::width`] values (a caller's bug: every row of a
    /// run has the same columns).
    pub fn push(&mut self, values: impl IntoIterator<Item = f64>) {
        let before = self.data.len();
        self.data.extend(values);
        assert_eq!(self.data.len() - before, self.width, "a row of a table of width {}", self.width);
        self.rows += 1;
    }

    /// Append a row that `fill` writes into its [`Table::width`] values (zero before): a recorded
    /// row is written in place, not collected from an iterator of unknown length.
    pub fn push_with(&mut self, fill: impl FnOnce(&mut [f64])) {
        let start = self.data.len();
        self.data.resize(start + self.width, 0.0);
        fill(&mut self.data[start..]);
        self.rows += 1;
    }

    /// Remove every row (the width and the storage are kept).
    pub fn clear(&mut self) {
        self.data.clear();
        self.rows = 0;
    }

    /// Row `i`, if there is one.
    pub fn get(&self, i: usize) -> Option<&[f64]> {
        (i < self.rows).then(|| &self.data[i * self.width..(i + 1) * self.width])
    }

    /// The last row, if any.
    pub fn last(&self) -> Option<&[f64]> {
        self.rows.checked_sub(1).and_then(|i| self.get(i))
    }

    /// The rows in order.
    pub fn iter(&self) -> Rows<'_> {
        Rows { table: self, front: 0, back: self.rows }
    }

    /// Column `k` over the rows.
    ///
    /// # Panics
    /// If `k` is not below [`Table::width`].
    pub fn column(&self, k: usize) -> impl ExactSizeIterator<Item = f64> + '_ {
        assert!(k < self.width, "column {k} of a table of width {}", self.width);
        self.iter().map(move |row| row[k])
    }
}

impl Index<usize> for Table {
    type Output = [f64];

    /// Row `i`.
    ///
    /// # Panics
    /// If there is no row `i`.
    fn index(&self, i: usize) -> &[f64] {
        self.get(i).unwrap_or_else(|| panic!("row {i} of a table of {} rows", self.rows))
    }
}

/// The rows of a [`Table`], as slices.
#[derive(Debug, Clone)]
pub struct Rows<'a> {
    table: &'a Table,
    front: usize,
    back: usize,
}

impl<'a> Iterator for Rows<'a> {
    type Item = &'a [f64];

    fn next(&mut self) -> Option<&'a [f64]> {
        (self.front < self.back).then(|| {
            self.front += 1;
            &self.table[self.front - 1]
        })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.back - self.front;
        (n, Some(n))
    }
}

impl DoubleEndedIterator for Rows<'_> {
    fn next_back(&mut self) -> Option<Self::Item> {
        (self.front < self.back).then(|| {
            self.back -= 1;
            &self.table[self.back]
        })
    }
}

impl ExactSizeIterator for Rows<'_> {}

impl<'a> IntoIterator for &'a Table {
    type Item = &'a [f64];
    type IntoIter = Rows<'a>;

    fn into_iter(self) -> Rows<'a> {
        self.iter()
    }
}

#[cfg(test)]
mod tests {
    use super::Table;

    #[test]
    fn rows_read_back_as_pushed_from_both_ends() {
        let mut t = Table::with_capacity(2, 1);
        t.push([1.0, 2.0]);
        t.push([3.0, 4.0]);
        t.push([5.0, 6.0]);
        assert_eq!((t.len(), t.width()), (3, 2));
        assert_eq!(&t[1], &[3.0, 4.0]);
        assert_eq!(t.last(), Some(&[5.0, 6.0][..]));
        assert_eq!(t.get(3), None);
        let rows: Vec<&[f64]> = t.iter().collect();
        assert_eq!(rows, [&[1.0, 2.0][..], &[3.0, 4.0], &[5.0, 6.0]]);
        assert_eq!(t.iter().next_back(), Some(&[5.0, 6.0][..]));
        assert_eq!(t.column(1).collect::<Vec<_>>(), [2.0, 4.0, 6.0]);
        assert_eq!(t.iter().len(), 3);
        t.clear();
        assert!(t.is_empty() && t.last().is_none() && t.iter().next().is_none());
    }

    /// A row written in place is the row pushed from its values; the closure sees exactly the
    /// table's width (zeros), also for a table of no columns.
    #[test]
    fn a_row_written_in_place_is_the_row_pushed() {
        let (mut a, mut b) = (Table::with_capacity(3, 2), Table::with_capacity(3, 0));
        a.push([1.0, 2.0, 3.0]);
        b.push_with(|row| {
            assert_eq!(row, [0.0; 3]);
            row.copy_from_slice(&[1.0, 2.0, 3.0]);
        });
        assert_eq!((a.len(), a.last()), (b.len(), b.last()));
        let mut empty = Table::with_capacity(0, 1);
        empty.push_with(|row| assert!(row.is_empty()));
        assert_eq!(empty.len(), 1);
    }

    /// A run that records no column still has one (empty) row per recorded time.
    #[test]
    fn rows_of_no_values_are_counted() {
        let mut t = Table::with_capacity(0, 4);
        t.push([]);
        t.push([]);
        assert_eq!(t.len(), 2);
        assert_eq!(t.iter().map(<[f64]>::len).collect::<Vec<_>>(), [0, 0]);
    }

    #[test]
    #[should_panic(expected = "a row of a table of width 2")]
    fn a_row_of_another_width_is_refused() {
        Table::with_capacity(2, 1).push([1.0]);
    }
}
