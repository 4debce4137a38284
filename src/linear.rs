//! Sparse tangent storage and solves (faer). The pattern is built once per load step from
//! the point–node connectivity, which is fixed within a step; the symbolic LU factorisation
//! is computed once for that pattern and only the numeric factorisation is repeated at each
//! Newton iteration.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::MatMut;

/// A square sparse matrix in compressed sparse column form with a cached symbolic LU.
#[derive(Debug, Default)]
pub struct SparseSystem {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
    symbolic: Option<SymbolicLu<usize>>,
}

impl SparseSystem {
    /// Build the pattern from `columns[c]` = rows that may be non-zero in column `c`
    /// (unsorted, duplicates allowed). Resets the cached symbolic factorisation.
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
        self.symbolic = None;
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

    /// Solve `K x = rhs` in place, reusing the symbolic factorisation of the pattern.
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), String> {
        if self.n == 0 {
            return Ok(());
        }
        let sym = SymbolicSparseColMatRef::new_checked(self.n, self.n, &self.col_ptr, None, &self.row_idx);
        if self.symbolic.is_none() {
            self.symbolic = Some(SymbolicLu::try_new(sym).map_err(|e| format!("{e:?}"))?);
        }
        let symbolic = self.symbolic.clone().expect("symbolic factorisation present");
        let mat = SparseColMatRef::new(sym, &self.values);
        let lu = Lu::try_new_with_symbolic(symbolic, mat).map_err(|e| format!("{e:?}"))?;
        let n = self.n;
        lu.solve_in_place(MatMut::from_column_major_slice_mut(rhs, n, 1));
        if rhs.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err("the solution of the linear system is not finite (singular tangent)".into())
        }
    }
}
