//! Direct sparse solves (faer): LU, LDLᵀ and LLᵀ of a column-compressed matrix, the symbolic
//! analysis cached per pattern and only the numeric factorisation repeated. Serves the
//! Newton systems through [`crate::solver::linear`] and the multigrid's coarsest level; imports only
//! [`crate::solver::sparse`].
//!
//! LDLᵀ and LLᵀ read the lower triangle, need about half of LU's fill and run several times
//! faster on the symmetric tangents (measured in `tests/verification/fem2d.rs`).

use crate::solver::error::SolverError;
use crate::solver::sparse::CscRef;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, LdltRef, LltRef, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Side};

/// Which factorisation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Factorisation {
    /// General sparse LU (no symmetry assumed).
    Lu,
    /// LDLᵀ of the lower triangle (symmetric, possibly indefinite, no pivoting).
    Ldlt,
    /// Cholesky LLᵀ of the lower triangle (symmetric positive definite).
    Llt,
}

/// The factorisations of one pattern: symbolic analyses kept until [`Self::reset`], and the
/// numeric factor of the last [`Self::factorize`].
#[derive(Debug, Default)]
pub struct DirectSolver {
    symbolic: Option<SymbolicLu<usize>>,
    symbolic_cholesky: Option<SymbolicCholesky<usize>>,
    /// Numeric factor values of the symmetric factorisation, reused between factorisations.
    factor: Vec<f64>,
    /// The LU factor of the last [`Self::factorize`] with [`Factorisation::Lu`].
    lu: Option<Lu<usize, f64>>,
    /// What the last [`Self::factorize`] computed.
    last: Option<Factorisation>,
    /// The pattern's row indices widened to faer's index type (the matrix keeps them in 4
    /// bytes, faer takes one type for pointers and indices), kept with the symbolic analyses.
    rows: Vec<usize>,
}

/// `Ok` if every entry of a solution is finite, else the singular-tangent error.
pub fn finite(x: &[f64]) -> Result<(), SolverError> {
    if x.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(SolverError::NotFinite)
    }
}

/// faer's view of `a`'s pattern, with the row indices `rows` widened from it
/// ([`widen`]).
fn pattern<'a>(a: &CscRef<'a>, rows: &'a [usize]) -> SymbolicSparseColMatRef<'a, usize> {
    SymbolicSparseColMatRef::new_checked(a.n, a.n, a.col_ptr, None, rows)
}

/// `a`'s row indices in `rows`, unless they are there already: the pattern is fixed until
/// [`DirectSolver::reset`], like the symbolic analyses.
fn widen(a: &CscRef<'_>, rows: &mut Vec<usize>) {
    if rows.len() != a.row_idx.len() {
        rows.clear();
        rows.extend(a.row_idx.iter().map(|&r| r as usize));
    }
}

impl DirectSolver {
    /// Forget the symbolic analyses and the factor (the pattern changed).
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// Non-zeros of the symmetric factor's symbolic structure (0 before any LDLᵀ/LLᵀ).
    pub fn factor_nnz(&self) -> usize {
        self.symbolic_cholesky.as_ref().map_or(0, |s| s.len_val())
    }

    /// LU of `a`, the symbolic analysis cached; the factor is returned, not kept.
    pub fn lu(&mut self, a: CscRef<'_>) -> Result<Lu<usize, f64>, SolverError> {
        widen(&a, &mut self.rows);
        let sym = pattern(&a, &self.rows);
        if self.symbolic.is_none() {
            self.symbolic =
                Some(SymbolicLu::try_new(sym).map_err(|e| SolverError::Factorisation(format!("{e:?}")))?);
        }
        let symbolic = self.symbolic.clone().expect("symbolic factorisation present");
        let mat = SparseColMatRef::new(sym, a.values);
        Lu::try_new_with_symbolic(symbolic, mat).map_err(|e| SolverError::Factorisation(format!("{e:?}")))
    }

    /// Factorise `a` for later [`Self::solve_in_place`].
    pub fn factorize(&mut self, a: CscRef<'_>, kind: Factorisation) -> Result<(), SolverError> {
        self.last = None;
        match kind {
            Factorisation::Lu => self.lu = Some(self.lu(a)?),
            Factorisation::Ldlt | Factorisation::Llt => self.factorize_symmetric(a, kind)?,
        }
        self.last = Some(kind);
        Ok(())
    }

    /// Solve with the factor of the last [`Self::factorize`]; an error if the solution is
    /// not finite.
    pub fn solve_in_place(&self, rhs: &mut [f64]) -> Result<(), SolverError> {
        let n = rhs.len();
        if n == 0 {
            return Ok(());
        }
        match self.last {
            None => Err(SolverError::Usage("solve_factorized: not factorised")),
            Some(Factorisation::Lu) => {
                let lu = self
                    .lu
                    .as_ref()
                    .ok_or(SolverError::Usage("solve_factorized: not factorised"))?;
                lu.solve_in_place(MatMut::from_column_major_slice_mut(rhs, n, 1));
                finite(rhs)
            }
            Some(kind) => {
                let symbolic = self
                    .symbolic_cholesky
                    .as_ref()
                    .ok_or(SolverError::Usage("solve_factorized: not factorised"))?;
                let par = faer::get_global_parallelism();
                let scratch = symbolic.solve_in_place_scratch::<f64>(1, par);
                let mut buf =
                    MemBuffer::try_new(scratch).map_err(|e| SolverError::Factorisation(format!("{e:?}")))?;
                let stack = MemStack::new(&mut buf);
                let mat = MatMut::from_column_major_slice_mut(rhs, n, 1);
                if kind == Factorisation::Llt {
                    LltRef::new(symbolic, &self.factor).solve_in_place_with_conj(Conj::No, mat, par, stack)
                } else {
                    LdltRef::new(symbolic, &self.factor).solve_in_place_with_conj(Conj::No, mat, par, stack)
                }
                finite(rhs)
            }
        }
    }

    /// LDLᵀ or LLᵀ of the lower triangle (faer's supernodal/simplicial Cholesky with an AMD
    /// ordering), symbolic analysis cached per pattern.
    fn factorize_symmetric(&mut self, a: CscRef<'_>, kind: Factorisation) -> Result<(), SolverError> {
        widen(&a, &mut self.rows);
        if self.symbolic_cholesky.is_none() {
            let analysed = factorize_symbolic_cholesky(
                pattern(&a, &self.rows),
                Side::Lower,
                SymmetricOrdering::Amd,
                Default::default(),
            )
            .map_err(|e| SolverError::Factorisation(format!("{e:?}")))?;
            self.symbolic_cholesky = Some(analysed);
        }
        let symbolic = self
            .symbolic_cholesky
            .as_ref()
            .expect("symbolic factorisation present");
        let mat = SparseColMatRef::new(pattern(&a, &self.rows), a.values);
        self.factor.resize(symbolic.len_val(), 0.0);
        let par = faer::get_global_parallelism();
        let ldlt = kind == Factorisation::Ldlt;
        let scratch = if ldlt {
            symbolic.factorize_numeric_ldlt_scratch::<f64>(par, Default::default())
        } else {
            symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default())
        };
        let mut buf =
            MemBuffer::try_new(scratch).map_err(|e| SolverError::Factorisation(format!("{e:?}")))?;
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
                .map_err(|e| SolverError::Factorisation(format!("{e:?}")))?;
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
                .map_err(|e| SolverError::Factorisation(format!("{e:?}")))?;
        }
        Ok(())
    }
}
