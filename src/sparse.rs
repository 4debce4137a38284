//! Sparse matrix storage: the column-compressed matrix the tangents are assembled into
//! ([`SparseMatrix`], with its per-thread column blocks) and the row-compressed one the
//! Krylov solvers and the multigrid multiply with ([`Csr`]). The lowest floor of the solver
//! layers: [`crate::direct`], [`crate::krylov`], [`crate::multigrid`] and the strategy of
//! [`crate::linear`] build on it, and it imports none of them.

use rayon::prelude::*;
use std::sync::Arc;

/// Rows per parallel task of the sparse kernels, and the chunk of [`crate::krylov::dot`]'s
/// fixed summation order. Not tuned (a power of two of the order of a cache's rows); since
/// the dot products' last bits depend on it, changing it changes iterative results at
/// round-off, so any retuning must re-run the studies that use CG.
pub const CHUNK: usize = 4096;

/// A square sparse matrix in compressed sparse column form: the pattern and values the
/// tangents are assembled into.
#[derive(Debug, Default, Clone)]
pub struct SparseMatrix {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
}

/// A borrowed column-compressed matrix: what the direct factorisations read.
#[derive(Debug, Clone, Copy)]
pub struct CscRef<'a> {
    pub n: usize,
    pub col_ptr: &'a [usize],
    pub row_idx: &'a [usize],
    pub values: &'a [f64],
}

impl SparseMatrix {
    /// Build the pattern from `columns[c]` = rows that may be non-zero in column `c`
    /// (unsorted, duplicates allowed); the values are zeroed.
    pub fn set_pattern(&mut self, mut columns: Vec<Vec<usize>>) {
        self.n = columns.len();
        self.col_ptr.clear();
        self.row_idx.clear();
        self.col_ptr.push(0);
        for col in columns.iter_mut() {
            col.sort_unstable();
            col.dedup();
            self.row_idx.extend_from_slice(col);
            self.col_ptr.push(self.row_idx.len());
        }
        self.values.clear();
        self.values.resize(self.row_idx.len(), 0.0);
    }

    /// The matrix as faer's column-compressed view, for the factorisations of
    /// [`crate::direct`].
    pub fn csc(&self) -> CscRef<'_> {
        CscRef {
            n: self.n,
            col_ptr: &self.col_ptr,
            row_idx: &self.row_idx,
            values: &self.values,
        }
    }

    /// Split the columns into at most `parts` blocks of about equal numbers of entries, for
    /// parallel assembly: each entry is then updated by exactly one thread.
    pub fn column_blocks(&mut self, parts: usize) -> Vec<ColumnBlock<'_>> {
        let parts = parts.max(1).min(self.n.max(1));
        let nnz = self.row_idx.len();
        let mut bounds = vec![0];
        for k in 1..parts {
            let target = nnz * k / parts;
            let c = self.col_ptr.partition_point(|&p| p < target).min(self.n);
            if c > *bounds.last().unwrap() {
                bounds.push(c);
            }
        }
        bounds.push(self.n);
        let mut blocks = Vec::with_capacity(bounds.len() - 1);
        let mut rest: &mut [f64] = &mut self.values;
        for w in bounds.windows(2) {
            let len = self.col_ptr[w[1]] - self.col_ptr[w[0]];
            let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
            rest = tail;
            blocks.push(ColumnBlock {
                first_col: w[0],
                end_col: w[1],
                col_ptr: &self.col_ptr,
                row_idx: &self.row_idx,
                values: head,
            });
        }
        blocks
    }
    pub fn dim(&self) -> usize {
        self.n
    }
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }
    /// Zero the values, keeping the pattern.
    pub fn clear_values(&mut self) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
    }
    /// Position of `(row, col)` in the value array. Panics if it is not in the pattern,
    /// which would be a bug in pattern construction, not a user error.
    #[inline]
    pub fn position(&self, row: usize, col: usize) -> usize {
        let (a, b) = (self.col_ptr[col], self.col_ptr[col + 1]);
        match self.row_idx[a..b].binary_search(&row) {
            Ok(k) => a + k,
            Err(_) => panic!("entry ({row}, {col}) is not in the sparsity pattern"),
        }
    }
    /// `K[row, col] += v`.
    #[inline]
    pub fn add(&mut self, row: usize, col: usize, v: f64) {
        let k = self.position(row, col);
        self.values[k] += v;
    }
    /// Value at `(row, col)`, zero outside the pattern.
    pub fn get(&self, row: usize, col: usize) -> f64 {
        let (a, b) = (self.col_ptr[col], self.col_ptr[col + 1]);
        match self.row_idx[a..b].binary_search(&row) {
            Ok(k) => self.values[a + k],
            Err(_) => 0.0,
        }
    }
    /// `y = K x`.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for (c, xc) in x.iter().enumerate().take(self.n) {
            for k in self.col_ptr[c]..self.col_ptr[c + 1] {
                y[self.row_idx[k]] += self.values[k] * xc;
            }
        }
    }
    /// The pattern and values as a row-compressed matrix (the transpose of the stored
    /// column-compressed one).
    pub fn to_csr(&self) -> Csr {
        Csr::from_csc(self.n, &self.col_ptr, &self.row_idx, &self.values)
    }
}

/// The row-compressed copy of a column-compressed matrix, kept per pattern: its structure and
/// where each entry sits in the column-compressed values (`from`) are built once, and each
/// solve only gathers the current values, in parallel, into the same arrays: no transpose
/// and no allocation of a matrix-sized buffer per solve (at 2e6 unknowns, 36e6 non-zeros:
/// 0.6 s and 577 MB a solve before).
#[derive(Debug)]
pub(crate) struct CsrMirror {
    pub(crate) csr: Csr,
    pub(crate) from: Vec<u32>,
}

impl CsrMirror {
    /// The mirror of an `n` × `n` pattern, or `None` if it has 2³² or more non-zeros.
    pub(crate) fn of_pattern(n: usize, col_ptr: &[usize], row_idx: &[usize]) -> Option<Self> {
        let nnz = row_idx.len();
        u32::try_from(nnz).ok()?;
        let mut ptr = vec![0usize; n + 1];
        for &r in row_idx {
            ptr[r + 1] += 1;
        }
        for i in 0..n {
            ptr[i + 1] += ptr[i];
        }
        let mut next = ptr.clone();
        let mut idx = vec![0u32; nnz];
        let mut from = vec![0u32; nnz];
        // Columns in order, so each row's column indices come out sorted.
        for c in 0..n {
            let c32 = column_index(c);
            for k in col_ptr[c]..col_ptr[c + 1] {
                let r = row_idx[k];
                idx[next[r]] = c32;
                from[next[r]] = k as u32;
                next[r] += 1;
            }
        }
        let csr = Csr::new(n, n, ptr, idx, vec![0.0; nnz]);
        Some(CsrMirror { csr, from })
    }

    /// Gather the current values.
    pub(crate) fn refresh(&mut self, values: &[f64]) {
        use rayon::prelude::*;
        self.csr
            .val
            .par_iter_mut()
            .zip(self.from.par_iter())
            .for_each(|(v, &k)| *v = values[k as usize]);
    }
}

/// Entries [`ColumnBlock::stretch_with_hint`] scans forward before it searches: a 3D point's
/// rows skip at most a few nodes' dofs of its column (27 nodes of 3 dofs in a GIMP stencil).
/// Not tuned.
const FORWARD_SCAN: usize = 32;

/// A contiguous range of columns of a [`SparseMatrix`] whose values one thread may update
/// while other threads update other blocks.
pub struct ColumnBlock<'a> {
    first_col: usize,
    end_col: usize,
    col_ptr: &'a [usize],
    row_idx: &'a [usize],
    /// Values of columns `first_col..end_col`, starting at `col_ptr[first_col]`.
    values: &'a mut [f64],
}

impl ColumnBlock<'_> {
    /// The columns `first..end` this block owns.
    #[inline]
    pub fn columns(&self) -> (usize, usize) {
        (self.first_col, self.end_col)
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
    /// row, or more than [`FORWARD_SCAN`] entries short of it falls back to a binary search.
    /// The position found is the same either way.
    #[inline]
    pub fn stretch_with_hint(&mut self, row: usize, col: usize, len: usize, hint: &mut usize) -> &mut [f64] {
        let (a, b) = (self.col_ptr[col], self.col_ptr[col + 1]);
        let mut k = *hint;
        let found = if k >= a && k < b && self.row_idx[k] <= row {
            let stop = (k + FORWARD_SCAN).min(b);
            while k < stop && self.row_idx[k] < row {
                k += 1;
            }
            k < b && self.row_idx[k] == row
        } else {
            false
        };
        if !found {
            k = match self.row_idx[a..b].binary_search(&row) {
                Ok(k) => a + k,
                Err(_) => panic!("entry ({row}, {col}) is not in the sparsity pattern"),
            };
        }
        assert!(
            k + len <= b && self.row_idx[k + len - 1] == row + len - 1,
            "rows {row}..{} of column {col} are not all in the sparsity pattern",
            row + len
        );
        *hint = k + len;
        let offset = self.col_ptr[self.first_col];
        &mut self.values[k - offset..k + len - offset]
    }
}

/// A column index of a [`Csr`]: 4 bytes, not 8, since the matrix–vector products that
/// dominate a CG solve stream the indices beside the values (12 bytes per non-zero instead
/// of 16; the 3D 1e6-point tangent has 31e6 non-zeros).
fn column_index(c: usize) -> u32 {
    u32::try_from(c).expect("a row-compressed matrix has fewer than 2^32 columns")
}

/// A sparse matrix in compressed sparse row form. The structure (`ptr`, `idx`) is shared
/// between clones, so a clone of a matrix copies only its values: the multigrid's finest
/// level keeps the values of the matrix it was built from beside the solver's current
/// ones without a second copy of the pattern (at 31e6 non-zeros, 372 MB).
#[derive(Debug, Clone, PartialEq)]
pub struct Csr {
    pub rows: usize,
    pub cols: usize,
    pub ptr: Arc<[usize]>,
    /// Column indices, each row's ascending.
    pub idx: Arc<[u32]>,
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

    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.rows)
            .map(|i| {
                (self.ptr[i]..self.ptr[i + 1])
                    .find(|&j| self.idx[j] as usize == i)
                    .map_or(0.0, |j| self.val[j])
            })
            .collect()
    }

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
