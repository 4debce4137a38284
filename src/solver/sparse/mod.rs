//! Sparse matrix storage: the compressed matrix the tangents are assembled into
//! ([`SparseMatrix`], with its per-thread blocks of lines) and the row-compressed one the
//! Krylov solvers and the multigrid multiply with ([`Csr`]). The lowest floor of the solver
//! layers: [`crate::solver::direct`], [`crate::solver::krylov`], [`crate::solver::multigrid`] and the strategy of
//! [`crate::solver::linear`] build on it, and it imports none of them.

mod column_block;
pub use column_block::ColumnBlock;
use rayon::prelude::*;
use std::sync::Arc;

/// Rows per parallel task of the sparse kernels, and the chunk of [`crate::solver::krylov::dot`]'s
/// fixed summation order. Not tuned (a power of two of the order of a cache's rows); since
/// the dot products' last bits depend on it, changing it changes iterative results at
/// round-off, so any retuning must re-run the studies that use CG.
pub const CHUNK: usize = 4096;

/// A square sparse matrix the tangents are assembled into, compressed by columns (what the
/// direct factorisations read) or by rows (what CG multiplies with, [`Self::set_by_rows`]).
/// Either way it is stored as a [`Csr`]: of K itself by rows, of Kᵀ by columns, so that CG
/// multiplies with the matrix it was assembled into, with no second copy and no gather before
/// a solve (reference/README.md item 54).
/// The inner indices are 4 bytes (`column_index`).
#[derive(Debug, Default, Clone)]
pub struct SparseMatrix {
    /// K (`by_rows`) or Kᵀ: each stored row is a column of K when compressed by columns.
    stored: Csr,
    by_rows: bool,
}

/// A borrowed column-compressed matrix: what the direct factorisations read.
#[derive(Debug, Clone, Copy)]
pub struct CscRef<'a> {
    /// Order of the (square) matrix.
    pub n: usize,
    /// Where each column's entries start in `row_idx` and `values` (n + 1 entries).
    pub col_ptr: &'a [usize],
    /// Row index of each entry, ascending within a column.
    pub row_idx: &'a [u32],
    /// Value of each entry.
    pub values: &'a [f64],
}

impl SparseMatrix {
    /// Build the pattern from `columns[c]` = rows that may be non-zero in column `c`
    /// (unsorted, duplicates allowed); the values are zeroed. The layout
    /// ([`Self::set_by_rows`]) is kept. Returns whether the pattern changed: stored by
    /// columns, a pattern equal entry for entry to the current one is kept (points that
    /// moved to other nodes may still couple the same equations).
    pub fn set_pattern(&mut self, mut columns: Vec<Vec<usize>>) -> bool {
        let n = columns.len();
        for col in columns.iter_mut() {
            col.sort_unstable();
            col.dedup();
        }
        if !self.by_rows && self.same_columns(&columns) {
            self.clear_values();
            return false;
        }
        // The old pattern goes first, so that two never coexist.
        self.stored = Csr::default();
        let mut ptr = vec![0usize; n + 1];
        if self.by_rows {
            for &r in columns.iter().flatten() {
                ptr[r + 1] += 1;
            }
        } else {
            for (c, col) in columns.iter().enumerate() {
                ptr[c + 1] = col.len();
            }
        }
        for i in 0..n {
            ptr[i + 1] += ptr[i];
        }
        let nnz = ptr[n];
        let mut idx = vec![0u32; nnz];
        if self.by_rows {
            // Columns in order, so each row's column indices come out ascending.
            let mut next = ptr.clone();
            for (c, col) in columns.iter().enumerate() {
                let c = column_index(c);
                for &r in col {
                    idx[next[r]] = c;
                    next[r] += 1;
                }
            }
        } else {
            for (c, col) in columns.iter().enumerate() {
                for (slot, &r) in idx[ptr[c]..ptr[c + 1]].iter_mut().zip(col) {
                    *slot = column_index(r);
                }
            }
        }
        drop(columns);
        self.stored = Csr::new(n, n, ptr, idx, vec![0.0; nnz]);
        true
    }

    /// Whether the stored columns (by columns) are `columns`, sorted and deduplicated.
    fn same_columns(&self, columns: &[Vec<usize>]) -> bool {
        let s = &self.stored;
        s.rows == columns.len()
            && s.ptr.len() == columns.len() + 1
            && columns.iter().enumerate().all(|(c, col)| {
                let stored = &s.idx[s.ptr[c]..s.ptr[c + 1]];
                stored.len() == col.len() && stored.iter().zip(col).all(|(&a, &b)| a as usize == b)
            })
    }

    /// Store by rows (`true`, for CG) or by columns (`false`, the default, for the direct
    /// factorisations); a matrix already built is transposed into the new layout, values
    /// and all.
    pub fn set_by_rows(&mut self, by_rows: bool) {
        if by_rows != self.by_rows {
            self.stored = self.stored.transpose();
            self.by_rows = by_rows;
        }
    }

    /// Whether the matrix is stored by rows ([`Self::set_by_rows`]).
    pub fn by_rows(&self) -> bool {
        self.by_rows
    }

    /// K compressed by columns, which is Kᵀ compressed by rows: read it with
    /// [`Csr::transpose_as_csc`] for the factorisations of [`crate::solver::direct`]. The matrix itself
    /// when stored by columns, else a transposed copy (what a direct fallback of CG pays, once
    /// per solve).
    pub fn csc(&self) -> std::borrow::Cow<'_, Csr> {
        if self.by_rows {
            std::borrow::Cow::Owned(self.stored.transpose())
        } else {
            std::borrow::Cow::Borrowed(&self.stored)
        }
    }

    /// The matrix row-compressed, for CG: itself when stored by rows, else a transposed
    /// copy.
    pub fn csr(&self) -> std::borrow::Cow<'_, Csr> {
        if self.by_rows {
            std::borrow::Cow::Borrowed(&self.stored)
        } else {
            std::borrow::Cow::Owned(self.stored.transpose())
        }
    }

    /// Split the stored lines (columns, or rows when stored by rows) into at most `parts`
    /// blocks of about equal numbers of entries, for parallel assembly: each entry is then
    /// updated by exactly one thread.
    pub fn column_blocks(&mut self, parts: usize) -> Vec<ColumnBlock<'_>> {
        let n = self.stored.rows;
        let parts = parts.max(1).min(n.max(1));
        let ptr: &[usize] = &self.stored.ptr;
        let nnz = self.stored.idx.len();
        let mut bounds = vec![0];
        for k in 1..parts {
            let target = nnz * k / parts;
            let c = ptr.partition_point(|&p| p < target).min(n);
            if c > *bounds.last().unwrap() {
                bounds.push(c);
            }
        }
        bounds.push(n);
        let mut blocks = Vec::with_capacity(bounds.len() - 1);
        let mut rest: &mut [f64] = &mut self.stored.val;
        for w in bounds.windows(2) {
            let len = ptr[w[1]] - ptr[w[0]];
            let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
            rest = tail;
            blocks.push(ColumnBlock {
                first_col: w[0],
                end_col: w[1],
                by_rows: self.by_rows,
                col_ptr: ptr,
                row_idx: &self.stored.idx,
                values: head,
            });
        }
        blocks
    }
    /// Order of the matrix: the number of equations.
    pub fn dim(&self) -> usize {
        self.stored.rows
    }
    /// Stored entries of the sparsity pattern.
    pub fn nnz(&self) -> usize {
        self.stored.idx.len()
    }
    /// Zero the values, keeping the pattern.
    pub fn clear_values(&mut self) {
        // In parallel: 250 MB at 3D's 31e6 non-zeros.
        self.stored.val.par_chunks_mut(CHUNK).for_each(|c| c.fill(0.0));
    }
    /// (stored line, index within it) of K's `(row, col)`.
    #[inline]
    fn line(&self, row: usize, col: usize) -> (usize, usize) {
        if self.by_rows {
            (row, col)
        } else {
            (col, row)
        }
    }
    /// Position of `(row, col)` in the value array, if the pattern holds it.
    #[inline]
    fn find(&self, row: usize, col: usize) -> Option<usize> {
        let (line, inner) = self.line(row, col);
        let (a, b) = (self.stored.ptr[line], self.stored.ptr[line + 1]);
        let inner = u32::try_from(inner).ok()?;
        self.stored.idx[a..b].binary_search(&inner).ok().map(|k| a + k)
    }
    /// Position of `(row, col)` in the value array. Panics if it is not in the pattern,
    /// which would be a bug in pattern construction, not a user error.
    #[inline]
    pub fn position(&self, row: usize, col: usize) -> usize {
        self.find(row, col)
            .unwrap_or_else(|| panic!("entry ({row}, {col}) is not in the sparsity pattern"))
    }
    /// `K[row, col] += v`.
    #[inline]
    pub fn add(&mut self, row: usize, col: usize, v: f64) {
        let k = self.position(row, col);
        self.stored.val[k] += v;
    }
    /// Value at `(row, col)`, zero outside the pattern.
    pub fn get(&self, row: usize, col: usize) -> f64 {
        self.find(row, col).map_or(0.0, |k| self.stored.val[k])
    }
    /// The largest absolute sum of a stored line: ‖K‖₁ stored by columns, ‖K‖∞ by rows
    /// (equal for a symmetric K, the matrices [`crate::solver::linear`]'s backward error is
    /// measured on).
    pub fn max_line_sum(&self) -> f64 {
        let s = &self.stored;
        (0..s.rows)
            .map(|r| s.val[s.ptr[r]..s.ptr[r + 1]].iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    }

    /// `y = K x`.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        if self.by_rows {
            return self.stored.mul_vec(x, y);
        }
        let s = &self.stored;
        y.iter_mut().for_each(|v| *v = 0.0);
        for (c, xc) in x.iter().enumerate().take(s.rows) {
            for k in s.ptr[c]..s.ptr[c + 1] {
                y[s.idx[k] as usize] += s.val[k] * xc;
            }
        }
    }
}

/// A column index of a [`Csr`] (and a row index of a [`SparseMatrix`] stored by columns): 4
/// bytes, not 8, since the matrix–vector products that dominate a CG solve stream the
/// indices beside the values (12 bytes per non-zero instead of 16; the 3D 1e6-point tangent
/// has 31e6 non-zeros).
fn column_index(c: usize) -> u32 {
    u32::try_from(c).expect("a row-compressed matrix has fewer than 2^32 columns")
}

/// A sparse matrix in compressed sparse row form. The structure (`ptr`, `idx`) is shared
/// between clones, so a clone of a matrix copies only its values: the multigrid's finest
/// level keeps the values of the matrix it was built from beside the solver's current
/// ones without a second copy of the pattern (at 31e6 non-zeros, 372 MB).
#[derive(Debug, Clone, PartialEq)]
pub struct Csr {
    /// Number of rows.
    pub rows: usize,
    /// Number of columns.
    pub cols: usize,
    /// Where each row's entries start in `idx` and `val` (rows + 1 entries).
    pub ptr: Arc<[usize]>,
    /// Column indices, each row's ascending.
    pub idx: Arc<[u32]>,
    /// Value of each entry, in the order of `idx`.
    pub val: Vec<f64>,
}

impl Default for Csr {
    fn default() -> Self {
        Csr::new(0, 0, vec![0], vec![], vec![])
    }
}

impl Csr {
    /// The `rows` × `cols` matrix of row pointers `ptr`, column indices `idx` (ascending in
    /// each row) and values `val`.
    pub fn new(rows: usize, cols: usize, ptr: Vec<usize>, idx: Vec<u32>, val: Vec<f64>) -> Csr {
        assert!(
            ptr.len() == rows + 1 && idx.len() == val.len() && ptr[rows] == idx.len(),
            "Csr::new: {} row pointers for {rows} rows, {} indices, {} values",
            ptr.len(),
            idx.len(),
            val.len()
        );
        Csr {
            rows,
            cols,
            ptr: ptr.into(),
            idx: idx.into(),
            val,
        }
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.idx.len()
    }

    /// Σ_j a_ij x_j from `start` (the products summed in column order).
    #[inline]
    fn row_dot(&self, i: usize, x: &[f64], start: f64, sign: f64) -> f64 {
        let (a, b) = (self.ptr[i], self.ptr[i + 1]);
        let mut s = start;
        for (v, &j) in self.val[a..b].iter().zip(&self.idx[a..b]) {
            s += sign * v * x[j as usize];
        }
        s
    }

    /// `y = A x`, rows in parallel.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        y.par_chunks_mut(CHUNK).enumerate().for_each(|(c, ys)| {
            let first = c * CHUNK;
            for (k, yi) in ys.iter_mut().enumerate() {
                *yi = self.row_dot(first + k, x, 0.0, 1.0);
            }
        });
    }

    /// `r = b − A x`.
    pub fn residual(&self, b: &[f64], x: &[f64], r: &mut [f64]) {
        r.par_chunks_mut(CHUNK).enumerate().for_each(|(c, rs)| {
            let first = c * CHUNK;
            for (k, ri) in rs.iter_mut().enumerate() {
                let i = first + k;
                *ri = self.row_dot(i, x, b[i], -1.0);
            }
        });
    }

    /// The diagonal a_ii (0 where the pattern has no entry).
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.rows)
            .map(|i| {
                (self.ptr[i]..self.ptr[i + 1])
                    .find(|&j| self.idx[j] as usize == i)
                    .map_or(0.0, |j| self.val[j])
            })
            .collect()
    }

    /// Aᵀ column-compressed: the same arrays read the other way, for the direct
    /// factorisations ([`SparseMatrix::csc`] stores K by columns as Kᵀ by rows).
    pub fn transpose_as_csc(&self) -> CscRef<'_> {
        assert_eq!(
            self.rows, self.cols,
            "a column-compressed view of a square matrix"
        );
        CscRef {
            n: self.rows,
            col_ptr: &self.ptr,
            row_idx: &self.idx,
            values: &self.val,
        }
    }

    /// Aᵀ, row-compressed (a new matrix; the structure is not shared).
    pub fn transpose(&self) -> Csr {
        transposed(self.rows, self.cols, &self.ptr, &self.idx, &self.val)
    }

    /// The row-compressed form of an `n` × `n` column-compressed matrix.
    pub fn from_csc(n: usize, col_ptr: &[usize], row_idx: &[usize], values: &[f64]) -> Csr {
        transposed(n, n, col_ptr, row_idx, values)
    }

    /// `A B` (Gustavson's row-by-row product with a dense accumulator per task; column
    /// indices of each row sorted, so the result does not depend on the thread count).
    pub fn matmul(&self, b: &Csr) -> Csr {
        assert_eq!(self.cols, b.rows, "matmul: inner dimensions");
        let chunks: Vec<(Vec<usize>, Vec<u32>, Vec<f64>)> = (0..self.rows.div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let rows = c * CHUNK..((c + 1) * CHUNK).min(self.rows);
                let mut acc = vec![0.0; b.cols];
                let mut seen = vec![false; b.cols];
                let mut cols: Vec<u32> = vec![];
                let (mut len, mut idx, mut val) = (vec![], vec![], vec![]);
                for i in rows {
                    cols.clear();
                    for k in self.ptr[i]..self.ptr[i + 1] {
                        let (j, a) = (self.idx[k] as usize, self.val[k]);
                        for m in b.ptr[j]..b.ptr[j + 1] {
                            let col = b.idx[m] as usize;
                            if !seen[col] {
                                seen[col] = true;
                                cols.push(b.idx[m]);
                            }
                            acc[col] += a * b.val[m];
                        }
                    }
                    cols.sort_unstable();
                    len.push(cols.len());
                    for &col in &cols {
                        idx.push(col);
                        let col = col as usize;
                        val.push(acc[col]);
                        acc[col] = 0.0;
                        seen[col] = false;
                    }
                }
                (len, idx, val)
            })
            .collect();
        let mut ptr = Vec::with_capacity(self.rows + 1);
        let (mut out_idx, mut out_val) = (vec![], vec![]);
        ptr.push(0);
        for (len, idx, val) in chunks {
            for l in len {
                ptr.push(ptr.last().unwrap() + l);
            }
            out_idx.extend(idx);
            out_val.extend(val);
        }
        Csr::new(self.rows, b.cols, ptr, out_idx, out_val)
    }
}

/// An index type of compressed storage: the column-compressed matrix's `usize` rows or the
/// row-compressed one's `u32` columns.
trait Index: Copy {
    fn get(self) -> usize;
}
impl Index for usize {
    #[inline]
    fn get(self) -> usize {
        self
    }
}
impl Index for u32 {
    #[inline]
    fn get(self) -> usize {
        self as usize
    }
}

/// The transpose of the `rows` × `cols` compressed matrix (ptr, idx, val), compressed the
/// other way (rows of the result sorted by index).
fn transposed<I: Index>(rows: usize, cols: usize, ptr: &[usize], idx: &[I], val: &[f64]) -> Csr {
    let mut count = vec![0usize; cols + 1];
    for &j in idx {
        count[j.get() + 1] += 1;
    }
    for j in 0..cols {
        count[j + 1] += count[j];
    }
    let out_ptr = count.clone();
    let mut next = count;
    let mut out_idx = vec![0u32; idx.len()];
    let mut out_val = vec![0.0; idx.len()];
    for i in 0..rows {
        let row = column_index(i);
        for k in ptr[i]..ptr[i + 1] {
            let j = idx[k].get();
            out_idx[next[j]] = row;
            out_val[next[j]] = val[k];
            next[j] += 1;
        }
    }
    Csr::new(cols, rows, out_ptr, out_idx, out_val)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A non-symmetric 5 × 5 matrix (structurally non-symmetric too) assembled into both
    /// layouts, in parallel blocks as the tangent kernel does and by single adds: every
    /// entry, product and compressed view agrees, and converting a filled matrix from one
    /// layout to the other keeps its values. A block kernel that forgot to transpose its
    /// dense block for the row layout fails the `get` comparison.
    #[test]
    fn both_layouts_hold_the_same_matrix() {
        let entries = [
            (0, 0, 4.0),
            (1, 0, -1.0),
            (0, 2, 2.5),
            (3, 1, 7.0),
            (4, 4, 1.0),
            (2, 3, -3.0),
        ];
        let mut columns = vec![Vec::new(); 5];
        for &(r, c, _) in &entries {
            columns[c].push(r);
            columns[c].push(r);
        }
        let build = |by_rows: bool| {
            let mut m = SparseMatrix::default();
            m.set_by_rows(by_rows);
            m.set_pattern(columns.clone());
            for block in m.column_blocks(2) {
                let mut block = block;
                let (lo, hi) = block.columns();
                for &(r, c, v) in &entries {
                    let (line, inner) = if block.by_rows() { (r, c) } else { (c, r) };
                    if (lo..hi).contains(&line) {
                        let start = block.column_start(line);
                        let mut hint = start;
                        block.stretch_with_hint(inner, line, 1, &mut hint)[0] += v;
                    }
                }
            }
            m.add(4, 4, 0.5);
            m
        };
        let (cols, rows) = (build(false), build(true));
        assert!(!cols.by_rows() && rows.by_rows());
        for m in [&cols, &rows] {
            assert_eq!(m.nnz(), entries.len());
            for &(r, c, v) in &entries {
                let expected = if (r, c) == (4, 4) { v + 0.5 } else { v };
                assert_eq!(m.get(r, c), expected, "({r}, {c})");
                assert_eq!(
                    m.get(c, r) != 0.0,
                    r == c || entries.iter().any(|e| (e.0, e.1) == (c, r))
                );
            }
        }
        let x = [1.0, -2.0, 0.5, 3.0, 0.25];
        let (mut y1, mut y2, mut y3) = ([0.0; 5], [0.0; 5], [0.0; 5]);
        cols.mul_vec(&x, &mut y1);
        rows.mul_vec(&x, &mut y2);
        rows.csr().mul_vec(&x, &mut y3);
        assert_eq!(y1, y2);
        assert_eq!(y1, y3);
        assert_eq!(*cols.csr(), *rows.csr());
        assert_eq!(*cols.csc(), *rows.csc());
        let mut converted = rows.clone();
        converted.set_by_rows(false);
        assert_eq!(*converted.csc(), *cols.csc());
        assert!(!converted.by_rows());
    }
}
