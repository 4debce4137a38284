//! Sparse tangent storage and solves (faer). The pattern is built once per load step from
//! the point–node connectivity, which is fixed within a step (once per analysis for FEM,
//! whose connectivity never changes: [`crate::assembly::StepWorkspace::fixed_pattern`]); the
//! symbolic factorisation is computed once for that pattern and only the numeric
//! factorisation is repeated at each Newton iteration. [`LinearSolver::Cg`] solves
//! iteratively instead, preconditioned by the grid's multigrid ([`crate::multigrid`]).
//!
//! The factorisation is LU by default. The tangent of a hyperelastic problem, and of
//! associative perfect plasticity with its consistent tangent, is symmetric, so
//! [`LinearSolver::Ldlt`] or [`LinearSolver::Llt`] may be chosen instead: they read only
//! the lower triangle, need about half the fill and run several times faster (measured in
//! `tests/verification/fem2d.rs`). If the symmetric factorisation fails (zero pivot; for LLT any matrix
//! that is not numerically positive definite) or yields a non-finite solution, the same
//! system is solved by LU and the fallback is counted ([`SparseSystem::fallbacks`]).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, LdltRef, LltRef, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Side};
use serde::{Deserialize, Serialize};

/// Which sparse factorisation solves the Newton systems.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LinearSolver {
    /// General sparse LU (no symmetry assumed).
    #[default]
    Lu,
    /// Sparse LDLᵀ of the lower triangle (symmetric, possibly indefinite, no pivoting),
    /// LU on failure.
    Ldlt,
    /// Sparse Cholesky LLᵀ of the lower triangle (symmetric positive definite), LU on failure.
    Llt,
    /// Conjugate gradients preconditioned by a geometric multigrid V-cycle on the structured
    /// grid ([`crate::multigrid`]), to the relative tolerance the Newton solver sets from its
    /// residual ([`SparseSystem::set_tolerance`]); needs the equations' positions
    /// ([`SparseSystem::set_geometry`]). If CG breaks down (a tangent that is not positive
    /// definite) or does not converge, restarted GMRES with the same multigrid solves the
    /// system ([`crate::multigrid::gmres`]); only if that fails too is it solved by LDLᵀ
    /// (then LU). Both switches are counted.
    Cg,
}

/// Default relative tolerance of an iterative solve when no Newton solver has set one.
pub const DEFAULT_ITERATIVE_TOLERANCE: f64 = 1e-10;
/// Most CG iterations of one solve before it switches to GMRES.
pub const MAX_CG_ITERATIONS: usize = 500;
/// Most GMRES iterations of one solve before it falls back to the direct solver.
pub const MAX_GMRES_ITERATIONS: usize = 300;
/// A kept multigrid is rebuilt once a solve needs more than this many times the iterations
/// it took fresh (plus two).
pub const REUSE_FACTOR: f64 = 1.5;

/// What the linear solves of a system have cost so far (for the performance figures).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LinearStats {
    pub solves: usize,
    /// CG iterations summed over the iterative solves.
    pub iterations: usize,
    /// Seconds in symbolic analysis, numeric factorisation or multigrid set-up.
    pub setup_seconds: f64,
    /// Seconds in triangular solves or Krylov iterations.
    pub solve_seconds: f64,
    /// Non-zeros of the last factor (direct solves).
    pub factor_nnz: usize,
    /// Multigrid hierarchies rebuilt because a kept one had become ineffective.
    pub rebuilds: usize,
    /// Solves that CG could not finish and GMRES took over (iterations of both counted).
    pub gmres_solves: usize,
}

impl LinearStats {
    /// Add the wall time since `start` to `phase` (set-up or solve), here and in the case's
    /// profile ([`crate::profile`]).
    fn charge(&mut self, phase: crate::profile::Phase, start: std::time::Instant) {
        let seconds = crate::profile::charge(phase, start);
        match phase {
            crate::profile::Phase::Solve => self.solve_seconds += seconds,
            _ => self.setup_seconds += seconds,
        }
    }
}

/// `Ok` if every entry of a solution is finite, else the singular-tangent error.
fn finite(x: &[f64]) -> Result<(), String> {
    if x.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err("the solution of the linear system is not finite (singular tangent)".into())
    }
}

/// A square sparse matrix in compressed sparse column form with cached symbolic
/// factorisations.
#[derive(Debug, Default)]
pub struct SparseSystem {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
    solver: LinearSolver,
    symbolic: Option<SymbolicLu<usize>>,
    symbolic_cholesky: Option<SymbolicCholesky<usize>>,
    /// Numeric factor values of the symmetric factorisation, reused between iterations.
    factor: Vec<f64>,
    fallbacks: usize,
    /// Where the equations sit ([`LinearSolver::Cg`]).
    geometry: Option<crate::multigrid::DofGeometry>,
    /// Relative residual an iterative solve must reach (0: the default).
    tolerance: f64,
    stats: LinearStats,
    /// The multigrid of an earlier matrix of this pattern and the CG iterations it took when
    /// fresh ([`Self::solve_cg`] reuses it).
    hierarchy: Option<(Box<crate::multigrid::Hierarchy>, usize)>,
    /// The LU factor of the last [`Self::factorize`] under [`LinearSolver::Lu`].
    lu: Option<Lu<usize, f64>>,
    /// The row-compressed copy CG multiplies with, kept per pattern ([`CsrMirror`]).
    mirror: Option<CsrMirror>,
}

/// The row-compressed copy of a column-compressed matrix, kept per pattern: its structure and
/// where each entry sits in the column-compressed values (`from`) are built once, and each
/// solve only gathers the current values, in parallel, into the same arrays: no transpose
/// and no allocation of a matrix-sized buffer per solve (at 2e6 unknowns, 36e6 non-zeros:
/// 0.6 s and 577 MB a solve before).
#[derive(Debug)]
struct CsrMirror {
    csr: crate::multigrid::Csr,
    from: Vec<u32>,
}

impl CsrMirror {
    /// The mirror of an `n` × `n` pattern, or `None` if it has 2³² or more non-zeros.
    fn of_pattern(n: usize, col_ptr: &[usize], row_idx: &[usize]) -> Option<Self> {
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
        let mut idx = vec![0usize; nnz];
        let mut from = vec![0u32; nnz];
        // Columns in order, so each row's column indices come out sorted.
        for c in 0..n {
            for k in col_ptr[c]..col_ptr[c + 1] {
                let r = row_idx[k];
                idx[next[r]] = c;
                from[next[r]] = k as u32;
                next[r] += 1;
            }
        }
        let csr = crate::multigrid::Csr {
            rows: n,
            cols: n,
            ptr,
            idx,
            val: vec![0.0; nnz],
        };
        Some(CsrMirror { csr, from })
    }

    /// Gather the current values.
    fn refresh(&mut self, values: &[f64]) {
        use rayon::prelude::*;
        self.csr
            .val
            .par_iter_mut()
            .zip(self.from.par_iter())
            .for_each(|(v, &k)| *v = values[k as usize]);
    }
}

/// A contiguous range of columns of a [`SparseSystem`] whose values one thread may update
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
    /// Does this block own column `col`?
    #[inline]
    pub fn owns(&self, col: usize) -> bool {
        col >= self.first_col && col < self.end_col
    }
    /// `K[row, col] += v` for an owned column, trying position `*hint` first and leaving
    /// the next position in it: runs of consecutive rows (the dofs of neighbouring nodes)
    /// then need one search per run instead of one per entry.
    #[inline]
    pub fn add_with_hint(&mut self, row: usize, col: usize, v: f64, hint: &mut usize) {
        let (a, b) = (self.col_ptr[col], self.col_ptr[col + 1]);
        let k = if *hint >= a && *hint < b && self.row_idx[*hint] == row {
            *hint
        } else {
            match self.row_idx[a..b].binary_search(&row) {
                Ok(k) => a + k,
                Err(_) => panic!("entry ({row}, {col}) is not in the sparsity pattern"),
            }
        };
        self.values[k - self.col_ptr[self.first_col]] += v;
        *hint = k + 1;
    }

    /// `K[row, col] += v` for an owned column.
    #[inline]
    pub fn add(&mut self, row: usize, col: usize, v: f64) {
        let (a, b) = (self.col_ptr[col], self.col_ptr[col + 1]);
        match self.row_idx[a..b].binary_search(&row) {
            Ok(k) => self.values[a + k - self.col_ptr[self.first_col]] += v,
            Err(_) => panic!("entry ({row}, {col}) is not in the sparsity pattern"),
        }
    }
}

impl SparseSystem {
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
        self.symbolic_cholesky = None;
        self.hierarchy = None;
        self.mirror = None;
    }

    /// Choose the factorisation (kept across [`Self::set_pattern`]).
    pub fn set_solver(&mut self, solver: LinearSolver) {
        self.solver = solver;
    }

    pub fn solver(&self) -> LinearSolver {
        self.solver
    }

    /// How many solves fell back from a symmetric factorisation to LU, or from CG to a direct
    /// solve.
    pub fn fallbacks(&self) -> usize {
        self.fallbacks
    }

    /// The positions and components of the equations, for the multigrid of
    /// [`LinearSolver::Cg`] (kept until the next [`Self::set_geometry`]).
    pub fn set_geometry(&mut self, geometry: crate::multigrid::DofGeometry) {
        self.geometry = Some(geometry);
        self.hierarchy = None;
    }

    /// The relative residual ‖b − K x‖ / ‖b‖ an iterative solve must reach (the Newton
    /// solver ties it to its own residual); ignored by the direct solvers.
    pub fn set_tolerance(&mut self, relative: f64) {
        self.tolerance = relative;
    }

    /// The cost of the solves so far.
    pub fn stats(&self) -> LinearStats {
        self.stats
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
        self.stats.solves += 1;
        if self.solver == LinearSolver::Cg {
            let original = rhs.to_vec();
            match self.solve_cg(&original, rhs) {
                Ok(()) if rhs.iter().all(|v| v.is_finite()) => return Ok(()),
                _ => {
                    self.fallbacks += 1;
                    rhs.copy_from_slice(&original);
                    let solver = std::mem::replace(&mut self.solver, LinearSolver::Ldlt);
                    let out = self.solve_direct(rhs);
                    self.solver = solver;
                    return out;
                }
            }
        }
        self.solve_direct(rhs)
    }

    /// The pattern and values as a row-compressed matrix (the transpose of the stored
    /// column-compressed one).
    pub fn to_csr(&self) -> crate::multigrid::Csr {
        crate::multigrid::Csr::from_csc(self.n, &self.col_ptr, &self.row_idx, &self.values)
    }

    /// `x = K⁻¹ b` by CG with the multigrid of the pattern's last fresh build while it stays
    /// effective: the hierarchy (prolongations, Galerkin products) is rebuilt from the current
    /// matrix when none exists for this pattern, or when a solve with the kept one needs more
    /// than [`REUSE_FACTOR`] times the iterations it took fresh (plus two), or fails; that
    /// solve is then repeated with the fresh hierarchy. Reuse changes the preconditioner, not
    /// the system: every solve still reaches its tolerance on the current matrix.
    fn solve_cg(&mut self, b: &[f64], x: &mut [f64]) -> Result<(), String> {
        let start = std::time::Instant::now();
        if self.mirror.is_none() {
            self.mirror = CsrMirror::of_pattern(self.n, &self.col_ptr, &self.row_idx);
        }
        let mirror = match self.mirror.take() {
            Some(mut m) => {
                m.refresh(&self.values);
                m
            }
            // Too many non-zeros for the kept positions: a fresh transpose.
            None => CsrMirror {
                csr: self.to_csr(),
                from: vec![],
            },
        };
        self.stats.charge(crate::profile::Phase::Setup, start);
        let out = self.solve_cg_with(&mirror.csr, b, x);
        if !mirror.from.is_empty() {
            self.mirror = Some(mirror);
        }
        out
    }

    /// [`Self::solve_cg`] with the current matrix in row-compressed form.
    fn solve_cg_with(&mut self, a: &crate::multigrid::Csr, b: &[f64], x: &mut [f64]) -> Result<(), String> {
        use crate::multigrid::{gmres, pcg, Hierarchy};
        let rtol = if self.tolerance > 0.0 {
            self.tolerance
        } else {
            DEFAULT_ITERATIVE_TOLERANCE
        };
        if let Some((m, fresh)) = self.hierarchy.as_ref() {
            // Given up once it needs more than the fresh count allows.
            let allowed = (REUSE_FACTOR * *fresh as f64) as usize + 2;
            let start = std::time::Instant::now();
            let report = pcg(a, m, b, x, rtol, allowed);
            self.stats.charge(crate::profile::Phase::Solve, start);
            self.stats.iterations += report.as_ref().map_or(allowed, |r| r.iterations);
            match report {
                Ok(_) => return Ok(()),
                Err(_) => self.stats.rebuilds += 1,
            }
        }
        let geometry = self
            .geometry
            .as_ref()
            .ok_or("the CG solver needs the equations' positions (SparseSystem::set_geometry)")?;
        let start = std::time::Instant::now();
        self.hierarchy = None;
        let m = Hierarchy::build(a, geometry)?;
        self.stats.charge(crate::profile::Phase::Setup, start);
        let start = std::time::Instant::now();
        let report = pcg(a, &m, b, x, rtol, MAX_CG_ITERATIONS);
        self.stats.charge(crate::profile::Phase::Solve, start);
        self.stats.iterations += report.as_ref().map_or(MAX_CG_ITERATIONS, |r| r.iterations);
        let report = match report {
            Ok(r) => r,
            Err(cg) => {
                let start = std::time::Instant::now();
                let report = gmres(a, &m, b, x, rtol, MAX_GMRES_ITERATIONS);
                self.stats.charge(crate::profile::Phase::Solve, start);
                self.stats.gmres_solves += 1;
                self.stats.iterations += report.as_ref().map_or(MAX_GMRES_ITERATIONS, |r| r.iterations);
                report.map_err(|e| format!("{cg}; {e}"))?
            }
        };
        self.hierarchy = Some((Box::new(m), report.iterations));
        Ok(())
    }

    /// Factorise (LDLᵀ, LLᵀ or LU) for later [`Self::solve_factorized`].
    pub fn factorize(&mut self) -> Result<(), String> {
        if self.n == 0 {
            return Ok(());
        }
        match self.solver {
            LinearSolver::Ldlt | LinearSolver::Llt => self.factorize_symmetric(),
            LinearSolver::Lu => {
                self.lu = Some(self.factor_lu()?);
                Ok(())
            }
            LinearSolver::Cg => Err("factorize: a direct solver only (LDLᵀ, LLᵀ or LU)".into()),
        }
    }

    /// Solve with the factor of the last [`Self::factorize`].
    pub fn solve_factorized(&self, rhs: &mut [f64]) -> Result<(), String> {
        if self.n == 0 {
            return Ok(());
        }
        if self.solver == LinearSolver::Lu {
            let lu = self.lu.as_ref().ok_or("solve_factorized: not factorised")?;
            let n = self.n;
            lu.solve_in_place(MatMut::from_column_major_slice_mut(rhs, n, 1));
            return finite(rhs);
        }
        let symbolic = self
            .symbolic_cholesky
            .as_ref()
            .ok_or("solve_factorized: not factorised")?;
        let par = faer::get_global_parallelism();
        let scratch = symbolic.solve_in_place_scratch::<f64>(1, par);
        let mut buf = MemBuffer::try_new(scratch).map_err(|e| format!("{e:?}"))?;
        let stack = MemStack::new(&mut buf);
        let n = self.n;
        let mat = MatMut::from_column_major_slice_mut(rhs, n, 1);
        match self.solver {
            LinearSolver::Llt => {
                LltRef::new(symbolic, &self.factor).solve_in_place_with_conj(Conj::No, mat, par, stack)
            }
            _ => LdltRef::new(symbolic, &self.factor).solve_in_place_with_conj(Conj::No, mat, par, stack),
        }
        finite(rhs)
    }

    /// Factorise (set-up) and solve (solve), LU when a symmetric factorisation fails.
    fn solve_direct(&mut self, rhs: &mut [f64]) -> Result<(), String> {
        if self.solver != LinearSolver::Lu {
            let original = rhs.to_vec();
            match self.solve_symmetric(rhs) {
                Ok(()) if rhs.iter().all(|v| v.is_finite()) => return Ok(()),
                _ => {
                    self.fallbacks += 1;
                    rhs.copy_from_slice(&original);
                }
            }
        }
        self.solve_lu(rhs)?;
        finite(rhs)
    }

    /// LU of the current values, the symbolic analysis cached per pattern.
    fn factor_lu(&mut self) -> Result<Lu<usize, f64>, String> {
        let sym = SymbolicSparseColMatRef::new_checked(self.n, self.n, &self.col_ptr, None, &self.row_idx);
        if self.symbolic.is_none() {
            self.symbolic = Some(SymbolicLu::try_new(sym).map_err(|e| format!("{e:?}"))?);
        }
        let symbolic = self.symbolic.clone().expect("symbolic factorisation present");
        let mat = SparseColMatRef::new(sym, &self.values);
        Lu::try_new_with_symbolic(symbolic, mat).map_err(|e| format!("{e:?}"))
    }

    fn solve_lu(&mut self, rhs: &mut [f64]) -> Result<(), String> {
        let start = std::time::Instant::now();
        let lu = self.factor_lu()?;
        self.stats.charge(crate::profile::Phase::Setup, start);
        let start = std::time::Instant::now();
        let n = self.n;
        lu.solve_in_place(MatMut::from_column_major_slice_mut(rhs, n, 1));
        self.stats.charge(crate::profile::Phase::Solve, start);
        Ok(())
    }

    /// LDLᵀ or LLᵀ of the lower triangle, then the solve.
    fn solve_symmetric(&mut self, rhs: &mut [f64]) -> Result<(), String> {
        let start = std::time::Instant::now();
        let factored = self.factorize_symmetric();
        self.stats.charge(crate::profile::Phase::Setup, start);
        factored?;
        let start = std::time::Instant::now();
        let solved = self.solve_factorized(rhs);
        self.stats.charge(crate::profile::Phase::Solve, start);
        solved
    }

    /// LDLᵀ or LLᵀ of the lower triangle (faer's supernodal/simplicial Cholesky with an AMD
    /// ordering), symbolic analysis cached per pattern.
    fn factorize_symmetric(&mut self) -> Result<(), String> {
        let n = self.n;
        if self.symbolic_cholesky.is_none() {
            let sym = SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx);
            let analysed =
                factorize_symbolic_cholesky(sym, Side::Lower, SymmetricOrdering::Amd, Default::default())
                    .map_err(|e| format!("{e:?}"))?;
            self.symbolic_cholesky = Some(analysed);
        }
        let symbolic = self
            .symbolic_cholesky
            .as_ref()
            .expect("symbolic factorisation present");
        let mat = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx),
            &self.values,
        );
        self.factor.resize(symbolic.len_val(), 0.0);
        self.stats.factor_nnz = symbolic.len_val();
        let par = faer::get_global_parallelism();
        let ldlt = match self.solver {
            LinearSolver::Ldlt => true,
            LinearSolver::Llt => false,
            _ => unreachable!("not a symmetric factorisation"),
        };
        let scratch = if ldlt {
            symbolic.factorize_numeric_ldlt_scratch::<f64>(par, Default::default())
        } else {
            symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default())
        };
        let mut buf = MemBuffer::try_new(scratch).map_err(|e| format!("{e:?}"))?;
        let stack = MemStack::new(&mut buf);
        let side = Side::Lower;
        if ldlt {
            symbolic
                .factorize_numeric_ldlt(
                    &mut self.factor,
                    mat,
                    side,
                    Default::default(),
                    par,
                    stack,
                    Default::default(),
                )
                .map_err(|e| format!("{e:?}"))?;
        } else {
            symbolic
                .factorize_numeric_llt(
                    &mut self.factor,
                    mat,
                    side,
                    Default::default(),
                    par,
                    stack,
                    Default::default(),
                )
                .map_err(|e| format!("{e:?}"))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 5-point Laplacian on an m × m grid plus `shift` on the diagonal (SPD for shift > −λ_min).
    fn laplacian(m: usize, shift: f64) -> SparseSystem {
        let n = m * m;
        let id = |i: usize, j: usize| j * m + i;
        let mut columns = vec![Vec::new(); n];
        let mut entries = Vec::new();
        for j in 0..m {
            for i in 0..m {
                let c = id(i, j);
                entries.push((c, c, 4.0 + shift));
                let mut near = vec![];
                if i > 0 {
                    near.push(id(i - 1, j));
                }
                if i + 1 < m {
                    near.push(id(i + 1, j));
                }
                if j > 0 {
                    near.push(id(i, j - 1));
                }
                if j + 1 < m {
                    near.push(id(i, j + 1));
                }
                for r in near {
                    entries.push((r, c, -1.0));
                }
            }
        }
        for &(r, c, _) in &entries {
            columns[c].push(r);
        }
        let mut sys = SparseSystem::default();
        sys.set_pattern(columns);
        for (r, c, v) in entries {
            sys.add(r, c, v);
        }
        sys
    }

    fn solve(sys: &mut SparseSystem, solver: LinearSolver, rhs: &[f64]) -> Vec<f64> {
        sys.set_solver(solver);
        let mut x = rhs.to_vec();
        sys.solve_in_place(&mut x).unwrap();
        x
    }

    /// LDLᵀ and LLᵀ give the LU solution of an SPD system (to round-off, also on a second
    /// solve that reuses the cached symbolic analysis); on a symmetric indefinite system LLᵀ
    /// fails and falls back to LU, while LDLᵀ still solves it (the shift avoids the exact zero
    /// pivots an integer indefinite matrix can produce without pivoting).
    #[test]
    fn symmetric_factorisations_match_lu() {
        for (shift, definite) in [(0.5, true), (-4.877, false)] {
            let mut sys = laplacian(12, shift);
            let n = sys.dim();
            let rhs: Vec<f64> = (0..n).map(|i| ((i * 7919) % 13) as f64 - 6.0).collect();
            let lu = solve(&mut sys, LinearSolver::Lu, &rhs);
            let scale = lu.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for solver in [LinearSolver::Ldlt, LinearSolver::Llt] {
                for _ in 0..2 {
                    let before = sys.fallbacks();
                    let x = solve(&mut sys, solver, &rhs);
                    let err = x.iter().zip(&lu).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                    assert!(err < 1e-12 * scale, "{solver:?} shift {shift}: {err:e}");
                    let fell_back = sys.fallbacks() > before;
                    assert_eq!(
                        fell_back,
                        solver == LinearSolver::Llt && !definite,
                        "{solver:?} shift {shift}"
                    );
                }
            }
        }
    }
}
