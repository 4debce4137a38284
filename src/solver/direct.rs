//! Direct sparse solves (faer): LU, LDLᵀ and LLᵀ of a column-compressed matrix, the symbolic
//! analysis cached per pattern and only the numeric factorisation repeated. Serves the
//! Newton systems through [`crate::solver::linear`] and the multigrid's coarsest level; imports only
//! [`crate::solver::sparse`].
//!
//! LDLᵀ and LLᵀ read the lower triangle, need about half of LU's fill and run several times
//! faster on the symmetric tangents (measured in `tests/verification/fem2d.rs`).

use crate::solver::error::SolverError;
use crate::solver::sparse::CscRef;
use faer::dyn_stack::MemStack;
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
    /// Where each entry's mirror `(j, i)` sits in the values, once asked
    /// ([`Self::is_symmetric`]); the inner `None` if the pattern is not structurally symmetric.
    mirror: Option<Option<Vec<usize>>>,
    /// Work space of the symmetric factorisations and solves, kept so that a Newton
    /// iteration allocates none.
    scratch: Vec<std::mem::MaybeUninit<u8>>,
    /// √|a_ii| of the last [`Self::is_symmetric`].
    scale: Vec<f64>,
}

/// A work space of at least `req` bytes in `scratch`, grown (never shrunk) as needed.
fn stack_of(scratch: &mut Vec<std::mem::MaybeUninit<u8>>, req: faer::dyn_stack::StackReq) -> &mut MemStack {
    let bytes = req.unaligned_bytes_required();
    if scratch.len() < bytes {
        scratch.resize(bytes, std::mem::MaybeUninit::uninit());
    }
    MemStack::new(scratch)
}

/// The position of each entry's mirror in a column-compressed pattern whose rows ascend in
/// each column, or `None` if some `(i, j)` has no `(j, i)`. One pass: the columns are read
/// in order, so each column's mirrors are met in its own row order (a cursor per column).
fn mirror_positions(a: &CscRef<'_>) -> Option<Vec<usize>> {
    let mut cursor: Vec<usize> = a.col_ptr[..a.n].to_vec();
    let mut mirror = vec![0usize; a.row_idx.len()];
    for j in 0..a.n {
        for k in a.col_ptr[j]..a.col_ptr[j + 1] {
            let i = a.row_idx[k] as usize;
            let p = cursor[i];
            if p >= a.col_ptr[i + 1] || a.row_idx[p] as usize != j {
                return None;
            }
            mirror[k] = p;
            cursor[i] += 1;
        }
    }
    (0..a.n).all(|i| cursor[i] == a.col_ptr[i + 1]).then_some(mirror)
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
        // The buffers keep their capacity: the next pattern is of about the same size.
        let scratch = std::mem::take(&mut self.scratch);
        let mut factor = std::mem::take(&mut self.factor);
        let mut scale = std::mem::take(&mut self.scale);
        factor.clear();
        scale.clear();
        *self = Self {
            scratch,
            factor,
            scale,
            ..Self::default()
        };
    }

    /// Whether `a` (of the kept pattern) is symmetric to round-off: every
    /// |a_ij − a_ji| ≤ `tolerance` · √(|a_ii| |a_jj|), the scale a symmetric factorisation's
    /// pivots work at, and no zero on the diagonal. `false` for a pattern that is not
    /// structurally symmetric. O(non-zeros); the mirror positions are found once per pattern.
    pub fn is_symmetric(&mut self, a: CscRef<'_>, tolerance: f64) -> bool {
        let mirror = self.mirror.get_or_insert_with(|| mirror_positions(&a));
        let Some(mirror) = mirror.as_ref() else {
            return false;
        };
        // The diagonal entry of column j is the one that is its own mirror; rows ascend, so
        // the entries after it are the strictly lower ones, each compared with its mirror once.
        let diagonal_at = |j: usize| (a.col_ptr[j]..a.col_ptr[j + 1]).find(|&k| mirror[k] == k);
        let diagonal = &mut self.scale;
        diagonal.clear();
        for j in 0..a.n {
            match diagonal_at(j).map(|k| a.values[k].abs().sqrt()) {
                Some(d) if d > 0.0 && d.is_finite() => diagonal.push(d),
                _ => return false,
            }
        }
        (0..a.n).all(|j| {
            let lower = a.row_idx[a.col_ptr[j]..a.col_ptr[j + 1]].partition_point(|&r| r as usize <= j);
            (a.col_ptr[j] + lower..a.col_ptr[j + 1]).all(|k| {
                let i = a.row_idx[k] as usize;
                (a.values[k] - a.values[mirror[k]]).abs() <= tolerance * diagonal[i] * diagonal[j]
            })
        })
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
    /// not finite. Allocates its work space (the multigrid's coarsest level, shared by
    /// threads, solves so); [`Self::solve_in_place_reusing`] keeps it.
    pub fn solve_in_place(&self, rhs: &mut [f64]) -> Result<(), SolverError> {
        let mut scratch = Vec::new();
        self.solve_with(rhs, &mut scratch)
    }

    /// [`Self::solve_in_place`] with the solver's own work space (no allocation once it has
    /// grown to the pattern's size).
    pub fn solve_in_place_reusing(&mut self, rhs: &mut [f64]) -> Result<(), SolverError> {
        let mut scratch = std::mem::take(&mut self.scratch);
        let out = self.solve_with(rhs, &mut scratch);
        self.scratch = scratch;
        out
    }

    fn solve_with(
        &self,
        rhs: &mut [f64],
        scratch: &mut Vec<std::mem::MaybeUninit<u8>>,
    ) -> Result<(), SolverError> {
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
                let stack = stack_of(scratch, symbolic.solve_in_place_scratch::<f64>(1, par));
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
        let stack = stack_of(&mut self.scratch, scratch);
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
