//! The solver strategy: how a Newton system is solved (a direct factorisation, or
//! multigrid-preconditioned CG with its GMRES and direct fallbacks), when a multigrid is
//! reused, and what the solves cost. The storage is [`crate::solver::sparse::SparseMatrix`], which
//! [`SparseSystem`] dereferences to for assembly; the factorisations are [`crate::solver::direct`]'s,
//! the Krylov methods [`crate::solver::krylov`]'s, the preconditioner [`crate::solver::multigrid`]'s.
//!
//! The pattern is built once per load step from
//! the point–node connectivity, which is fixed within a step (once per analysis for FEM,
//! whose connectivity never changes: [`crate::discretise::assembly::StepWorkspace::fixed_pattern`]); the
//! symbolic factorisation is computed once for that pattern and only the numeric
//! factorisation is repeated at each Newton iteration. [`LinearSolver::Iterative`] solves
//! iteratively instead, preconditioned by the grid's multigrid ([`crate::solver::multigrid`]).
//!
//! The factorisation is LU by default. The tangent of a hyperelastic problem, and of
//! associative perfect plasticity with its consistent tangent, is symmetric, so
//! [`LinearSolver::Ldlt`] or [`LinearSolver::Llt`] may be chosen instead: they read only
//! the lower triangle, need about half the fill and run several times faster (measured in
//! `tests/verification/fem2d.rs`). If the symmetric factorisation fails (zero pivot; for LLT any matrix
//! that is not numerically positive definite) or yields a non-finite solution, the same
//! system is solved by LU and the fallback is counted ([`SparseSystem::fallbacks`]).

use crate::solver::direct::{DirectSolver, Factorisation};
use crate::solver::error::SolverError;
use crate::solver::krylov::{gmres, pcg};
use crate::solver::multigrid::{DofGeometry, Hierarchy};
use crate::solver::sparse::{Csr, SparseMatrix};
use serde::{Deserialize, Serialize};

/// How the Newton systems are solved: one of three sparse factorisations, or the iterative
/// strategy (multigrid-preconditioned CG, then GMRES, then a factorisation).
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
    /// grid ([`crate::solver::multigrid`]), to the relative tolerance the Newton solver sets from its
    /// residual ([`SparseSystem::set_tolerance`]); needs the equations' positions
    /// ([`SparseSystem::set_geometry`]). If CG breaks down (a tangent that is not positive
    /// definite) or does not converge, restarted GMRES with the same multigrid solves the
    /// system ([`crate::solver::krylov::gmres`]); only if that fails too is it solved by LDLᵀ
    /// (then LU). Both switches are counted. Written `cg` in study files.
    #[serde(rename = "cg")]
    Iterative,
}

/// Default relative tolerance of an iterative solve when no Newton solver has set one.
pub const DEFAULT_ITERATIVE_TOLERANCE: f64 = 1e-10;
/// Most CG iterations of one solve before it switches to GMRES. A safety bound, not a tuned
/// value: the multigrid CG takes 5–8 iterations per solve from 4e3 to 1e6 unknowns
/// (reference/README.md item 33), so a solve that reaches 500 is failing, not slow.
pub const MAX_CG_ITERATIONS: usize = 500;
/// Most GMRES iterations of one solve before it falls back to the direct solver. Also a
/// safety bound: GMRES took 7–8 iterations on the indefinite and non-symmetric test
/// operators and the cantilever's indefinite iterates (item 33); at 300 it had stalled
/// (the LDLᵀ-coarsened variant stood at 4e-5 there).
pub const MAX_GMRES_ITERATIONS: usize = 300;
/// A kept multigrid is rebuilt once a solve needs more than this many times the iterations
/// it took fresh, plus two (a fresh count of 5–8, item 33's, may grow by four to six before
/// the rebuild; the two keeps tiny counts from rebuilding on a one-iteration change). Not
/// tuned by a sweep; reuse changes the preconditioner only, never the converged solution.
pub const REUSE_FACTOR: f64 = 1.5;

/// What the linear solves of a system have cost so far (for the performance figures).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LinearStats {
    /// Linear solves performed (empty systems not counted).
    pub solves: usize,
    /// Krylov iterations summed over the iterative solves: CG's, and GMRES's where CG gave up
    /// ([`Self::gmres_solves`]).
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
    /// profile ([`crate::solver::profile`]).
    fn charge(&mut self, phase: crate::solver::profile::Phase, start: std::time::Instant) {
        let seconds = crate::solver::profile::charge(phase, start);
        match phase {
            crate::solver::profile::Phase::Solve => self.solve_seconds += seconds,
            _ => self.setup_seconds += seconds,
        }
    }
}

/// A Newton system's matrix with its solver state: the cached factorisations, the kept
/// multigrid, the fallbacks taken and the statistics. Dereferences to its
/// [`SparseMatrix`], into which the tangents are assembled.
#[derive(Debug, Default)]
pub struct SparseSystem {
    matrix: SparseMatrix,
    solver: LinearSolver,
    direct: DirectSolver,
    fallbacks: usize,
    /// Where the equations sit ([`LinearSolver::Iterative`]).
    geometry: Option<DofGeometry>,
    /// Relative residual an iterative solve must reach (0: the default).
    tolerance: f64,
    stats: LinearStats,
    /// The multigrid of an earlier matrix of this pattern and the CG iterations it took when
    /// fresh ([`Self::solve_cg`] reuses it).
    hierarchy: Option<(Box<Hierarchy>, usize)>,
}

impl std::ops::Deref for SparseSystem {
    type Target = SparseMatrix;
    fn deref(&self) -> &SparseMatrix {
        &self.matrix
    }
}

impl std::ops::DerefMut for SparseSystem {
    fn deref_mut(&mut self) -> &mut SparseMatrix {
        &mut self.matrix
    }
}

impl SparseSystem {
    /// Build the pattern from `columns[c]` = rows that may be non-zero in column `c`
    /// (unsorted, duplicates allowed). Resets the cached factorisations and multigrid.
    pub fn set_pattern(&mut self, columns: Vec<Vec<usize>>) {
        self.matrix.set_pattern(columns);
        self.direct.reset();
        self.hierarchy = None;
    }

    /// Drop the kept multigrid (the next CG solve builds one from its matrix) but keep the
    /// pattern and its symbolic factorisations: for a new system
    /// of the same pattern whose solves must not depend on the previous system's matrix.
    pub fn forget_preconditioner(&mut self) {
        self.hierarchy = None;
    }

    /// Choose the factorisation (kept across [`Self::set_pattern`]). The iterative strategy
    /// stores the matrix by rows, which CG multiplies with, the factorisations by columns
    /// ([`SparseMatrix::set_by_rows`]); a matrix already assembled is transposed.
    pub fn set_solver(&mut self, solver: LinearSolver) {
        self.solver = solver;
        self.matrix.set_by_rows(solver == LinearSolver::Iterative);
    }

    /// The chosen factorisation or iterative strategy.
    pub fn solver(&self) -> LinearSolver {
        self.solver
    }

    /// How many solves fell back from a symmetric factorisation to LU, or from CG to a direct
    /// solve.
    pub fn fallbacks(&self) -> usize {
        self.fallbacks
    }

    /// The positions and components of the equations, for the multigrid of
    /// [`LinearSolver::Iterative`] (kept until the next [`Self::set_geometry`]).
    pub fn set_geometry(&mut self, geometry: DofGeometry) {
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

    /// Solve `K x = rhs` in place, reusing the symbolic factorisation of the pattern.
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), SolverError> {
        if self.matrix.dim() == 0 {
            return Ok(());
        }
        self.stats.solves += 1;
        if self.solver == LinearSolver::Iterative {
            let original = rhs.to_vec();
            match self.solve_cg(&original, rhs) {
                Ok(()) if rhs.iter().all(|v| v.is_finite()) => return Ok(()),
                _ => {
                    self.fallbacks += 1;
                    rhs.copy_from_slice(&original);
                    // LDLᵀ, then LU (solve_symmetric's choice for the iterative strategy).
                    return self.solve_direct(rhs);
                }
            }
        }
        self.solve_direct(rhs)
    }

    /// `x = K⁻¹ b` by CG with the multigrid of the pattern's last fresh build while it stays
    /// effective: the hierarchy (prolongations, Galerkin products) is rebuilt from the current
    /// matrix when none exists for this pattern, or when a solve with the kept one needs more
    /// than [`REUSE_FACTOR`] times the iterations it took fresh (plus two), or fails; that
    /// solve is then repeated with the fresh hierarchy. Reuse changes the preconditioner, not
    /// the system: every solve still reaches its tolerance on the current matrix.
    fn solve_cg(&mut self, b: &[f64], x: &mut [f64]) -> Result<(), SolverError> {
        // Taken out for the solve so that the strategy's state can change beside it; stored
        // by rows ([`Self::set_solver`]), it is borrowed as it is, not copied.
        let matrix = std::mem::take(&mut self.matrix);
        let out = self.solve_cg_with(&matrix.csr(), b, x);
        self.matrix = matrix;
        out
    }

    /// [`Self::solve_cg`] with the current matrix in row-compressed form.
    fn solve_cg_with(&mut self, a: &Csr, b: &[f64], x: &mut [f64]) -> Result<(), SolverError> {
        let rtol = if self.tolerance > 0.0 {
            self.tolerance
        } else {
            DEFAULT_ITERATIVE_TOLERANCE
        };
        if let Some((m, fresh)) = self.hierarchy.as_ref() {
            // Given up once it needs more than the fresh count allows.
            let allowed = (REUSE_FACTOR * *fresh as f64) as usize + 2;
            let start = std::time::Instant::now();
            let report = pcg(a, m.as_ref(), b, x, rtol, allowed);
            self.stats.charge(crate::solver::profile::Phase::Solve, start);
            self.stats.iterations += report.as_ref().map_or(allowed, |r| r.iterations);
            match report {
                Ok(_) => return Ok(()),
                Err(_) => self.stats.rebuilds += 1,
            }
        }
        let geometry = self.geometry.as_ref().ok_or(SolverError::Usage(
            "the CG solver needs the equations' positions (SparseSystem::set_geometry)",
        ))?;
        let start = std::time::Instant::now();
        self.hierarchy = None;
        let m = Hierarchy::build(a, geometry)?;
        self.stats.charge(crate::solver::profile::Phase::Setup, start);
        let start = std::time::Instant::now();
        let report = pcg(a, &m, b, x, rtol, MAX_CG_ITERATIONS);
        self.stats.charge(crate::solver::profile::Phase::Solve, start);
        self.stats.iterations += report.as_ref().map_or(MAX_CG_ITERATIONS, |r| r.iterations);
        let report = match report {
            Ok(r) => r,
            Err(cg) => {
                let start = std::time::Instant::now();
                let report = gmres(a, &m, b, x, rtol, MAX_GMRES_ITERATIONS);
                self.stats.charge(crate::solver::profile::Phase::Solve, start);
                self.stats.gmres_solves += 1;
                self.stats.iterations += report.as_ref().map_or(MAX_GMRES_ITERATIONS, |r| r.iterations);
                report.map_err(|e| SolverError::Krylov(format!("{cg}; {e}")))?
            }
        };
        self.hierarchy = Some((Box::new(m), report.iterations));
        Ok(())
    }

    /// The direct factorisation of a direct solver choice (`None` for the iterative one).
    fn factorisation(&self) -> Option<Factorisation> {
        match self.solver {
            LinearSolver::Lu => Some(Factorisation::Lu),
            LinearSolver::Ldlt => Some(Factorisation::Ldlt),
            LinearSolver::Llt => Some(Factorisation::Llt),
            LinearSolver::Iterative => None,
        }
    }

    /// Factorise (LDLᵀ, LLᵀ or LU) for later [`Self::solve_factorized`].
    pub fn factorize(&mut self) -> Result<(), SolverError> {
        if self.matrix.dim() == 0 {
            return Ok(());
        }
        let kind = self.factorisation().ok_or(SolverError::Usage(
            "factorize: a direct solver only (LDLᵀ, LLᵀ or LU)",
        ))?;
        let out = self.direct.factorize(self.matrix.csc().transpose_as_csc(), kind);
        self.stats.factor_nnz = self.direct.factor_nnz();
        out
    }

    /// Solve with the factor of the last [`Self::factorize`].
    pub fn solve_factorized(&self, rhs: &mut [f64]) -> Result<(), SolverError> {
        if self.matrix.dim() == 0 {
            return Ok(());
        }
        self.direct.solve_in_place(rhs)
    }

    /// Factorise (set-up) and solve (solve), LU when a symmetric factorisation fails.
    fn solve_direct(&mut self, rhs: &mut [f64]) -> Result<(), SolverError> {
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
        crate::solver::direct::finite(rhs)
    }

    /// LU of the current values (not kept), then the solve.
    fn solve_lu(&mut self, rhs: &mut [f64]) -> Result<(), SolverError> {
        use faer::linalg::solvers::Solve;
        let start = std::time::Instant::now();
        let lu = self.direct.lu(self.matrix.csc().transpose_as_csc())?;
        self.stats.charge(crate::solver::profile::Phase::Setup, start);
        let start = std::time::Instant::now();
        let n = self.matrix.dim();
        lu.solve_in_place(faer::MatMut::from_column_major_slice_mut(rhs, n, 1));
        self.stats.charge(crate::solver::profile::Phase::Solve, start);
        Ok(())
    }

    /// LDLᵀ or LLᵀ of the lower triangle, then the solve.
    fn solve_symmetric(&mut self, rhs: &mut [f64]) -> Result<(), SolverError> {
        let kind = match self.solver {
            LinearSolver::Llt => Factorisation::Llt,
            // The iterative strategy's last resort is LDLᵀ.
            _ => Factorisation::Ldlt,
        };
        let start = std::time::Instant::now();
        let factored = self.direct.factorize(self.matrix.csc().transpose_as_csc(), kind);
        self.stats.factor_nnz = self.direct.factor_nnz();
        self.stats.charge(crate::solver::profile::Phase::Setup, start);
        factored?;
        let start = std::time::Instant::now();
        let solved = self.direct.solve_in_place(rhs);
        self.stats.charge(crate::solver::profile::Phase::Solve, start);
        solved
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
    /// A singular system fails with its cause, not a generic "could not be factorised": a
    /// zero matrix is rejected by faer's LU (or gives a non-finite solution), and the step
    /// failure says it was the linear solve.
    #[test]
    fn a_singular_system_reports_its_cause() {
        let mut sys = SparseSystem::default();
        sys.set_pattern(vec![vec![0], vec![1]]);
        let mut rhs = [1.0, 1.0];
        let e = sys.solve_in_place(&mut rhs).unwrap_err();
        assert!(
            matches!(e, SolverError::Factorisation(_) | SolverError::NotFinite),
            "{e:?}"
        );
        let failure = crate::solver::error::StepFailure::LinearSolve(e);
        assert!(
            failure.to_string().starts_with("the linear solve failed: "),
            "{failure}"
        );
        // Asking the iterative strategy for a factorisation is the caller's mistake.
        sys.set_solver(LinearSolver::Iterative);
        assert!(matches!(sys.factorize(), Err(SolverError::Usage(_))));
    }

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
