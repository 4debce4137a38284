//! A block of a [`super::SparseMatrix`]'s stored lines that one thread of a parallel assembly
//! owns, and the search for a point's stretch of rows in it.

use super::column_index;

/// Entries [`ColumnBlock::stretch_with_hint`] scans forward before it searches: a 3D point's
/// rows skip at most a few nodes' dofs of its column (27 nodes of 3 dofs in a GIMP stencil).
/// Not tuned.
const FORWARD_SCAN: usize = 32;

/// A contiguous range of the stored lines of a [`super::SparseMatrix`] (columns, or rows when it
/// is stored by rows) whose values one thread may update while other threads update other
/// blocks. The names below say columns and rows for the column layout; by rows, they swap.
pub struct ColumnBlock<'a> {
    pub(super) first_col: usize,
    pub(super) end_col: usize,
    pub(super) by_rows: bool,
    pub(super) col_ptr: &'a [usize],
    pub(super) row_idx: &'a [u32],
    /// Values of columns `first_col..end_col`, starting at `col_ptr[first_col]`.
    pub(super) values: &'a mut [f64],
}

impl ColumnBlock<'_> {
    /// The columns `first..end` this block owns.
    #[inline]
    pub fn columns(&self) -> (usize, usize) {
        (self.first_col, self.end_col)
    }
    /// Whether the lines are K's rows: a dense block is then added transposed.
    #[inline]
    pub fn by_rows(&self) -> bool {
        self.by_rows
    }
    /// Where column `col`'s entries start in the matrix's values (the positions
    /// [`Self::stretch_with_hint`] takes and leaves are counted from the matrix's first entry).
    #[inline]
    pub fn column_start(&self, col: usize) -> usize {
        self.col_ptr[col]
    }
    /// The values of rows `row..row + len` of an owned column, which the pattern must hold
    /// as consecutive entries (a stretch of consecutive equations a point reaches), searched
    /// forward from position `*hint`, which is left just past them. A point's stretches
    /// ascend, and between two of them a column holds only the rows of the few nodes the
    /// point skips, so a short scan finds the next one; a hint outside the column, past the
    /// row, or more than `FORWARD_SCAN` entries short of it falls back to a binary search.
    /// The position found is the same either way.
    #[inline]
    pub fn stretch_with_hint(&mut self, row: usize, col: usize, len: usize, hint: &mut usize) -> &mut [f64] {
        let (a, b) = (self.col_ptr[col], self.col_ptr[col + 1]);
        let row32 = column_index(row);
        let mut k = *hint;
        let found = if k >= a && k < b && self.row_idx[k] <= row32 {
            let stop = (k + FORWARD_SCAN).min(b);
            while k < stop && self.row_idx[k] < row32 {
                k += 1;
            }
            k < b && self.row_idx[k] == row32
        } else {
            false
        };
        if !found {
            k = match self.row_idx[a..b].binary_search(&row32) {
                Ok(k) => a + k,
                Err(_) => panic!("entry ({row}, {col}) is not in the sparsity pattern"),
            };
        }
        assert!(
            k + len <= b && self.row_idx[k + len - 1] as usize == row + len - 1,
            "rows {row}..{} of column {col} are not all in the sparsity pattern",
            row + len
        );
        *hint = k + len;
        let offset = self.col_ptr[self.first_col];
        &mut self.values[k - offset..k + len - offset]
    }
}
