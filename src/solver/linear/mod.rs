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
//! The default, [`LinearSolver::Auto`], looks at each assembled matrix: symmetric to
//! round-off (the tangents of hyperelasticity, of associative plasticity with its
//! consistent tangent, and the ghost penalty), it is factorised by LDLᵀ, which reads the
//! lower triangle, needs about half of LU's fill and ran 5.4 times faster on the
//! compaction's tangents (reference/README.md item 64); otherwise by LU. [`LinearSolver::Lu`],
//! [`LinearSolver::Ldlt`] and [`LinearSolver::Llt`] force one. If a symmetric factorisation
//! fails (zero pivot; for LLᵀ any matrix that is not numerically positive definite), yields
//! a non-finite solution or, under `Auto`, misses [`BACKWARD_ERROR_LIMIT`], the same system
//! is solved by LU and the fallback is counted ([`SparseSystem::fallbacks`]).

use crate::solver::direct::{DirectSolver, Factorisation};
use crate::solver::error::SolverError;
use crate::solver::multigrid::{DofGeometry, Hierarchy};

mod iterative;
use crate::solver::sparse::SparseMatrix;
use serde::{Deserialize, Serialize};

/// How the Newton systems are solved: one of three sparse factorisations, or the iterative
/// strategy (multigrid-preconditioned CG on a symmetric matrix, GMRES on an unsymmetric one
/// or where CG fails, then a factorisation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LinearSolver {
    /// LDLᵀ when the assembled matrix is symmetric to round-off ([`SYMMETRY_TOLERANCE`]) and
    /// the solve's backward error stays below [`BACKWARD_ERROR_LIMIT`], else LU: the
    /// symmetric solve where it is exact, the general one where it is needed, decided per
    /// matrix.
    #[default]
    Auto,
    /// General sparse LU (no symmetry assumed).
    Lu,
    /// Sparse LDLᵀ of the lower triangle (symmetric, possibly indefinite, no pivoting),
    /// LU on failure.
    Ldlt,
    /// Sparse Cholesky LLᵀ of the lower triangle (symmetric positive definite), LU on failure.
    Llt,
    /// Conjugate gradients preconditioned by a geometric multigrid V-cycle on the structured
    /// grid ([`crate::solver::multigrid`]), to the relative tolerance the Newton solver sets from its
    /// residual ([`SparseSystem::set_tolerance`]); needs the equations' positions
    /// ([`SparseSystem::set_geometry`]). CG only on a symmetric matrix (to
    /// [`SYMMETRY_TOLERANCE`]): an unsymmetric one (F-bar, non-associated flow) is solved by
    /// restarted GMRES with the same multigrid ([`crate::solver::krylov::gmres`]) from the
    /// start. If CG breaks down (a tangent that is not positive definite) or does not
    /// converge, GMRES takes over; only if that fails too is the system factorised (LDLᵀ if
    /// symmetric, else LU). Both switches are counted. Written `cg` in study files.
    #[serde(rename = "cg")]
    Iterative,
}

/// [`LinearSolver::Auto`] solves by LDLᵀ when every |K_ij − K_ji| ≤ this · √(|K_ii| |K_jj|).
/// The symmetric tangents of the studies (elasticity, associative plasticity, the ghost
/// penalty) differ from their transposes by round-off only, the non-symmetric ones by many
/// orders more (reference/README.md item 64).
pub const SYMMETRY_TOLERANCE: f64 = 1e-12;
/// An LDLᵀ solve of [`LinearSolver::Auto`] is redone by LU when its backward error
/// ‖b − K x‖∞ / (‖K‖∞ ‖x‖∞ + ‖b‖∞) exceeds this: LDLᵀ does not pivot, and a growing
/// pivot on an indefinite tangent would show here (reference/README.md item 64).
pub const BACKWARD_ERROR_LIMIT: f64 = 1e-12;

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
    /// Solves [`LinearSolver::Auto`] made by LDLᵀ (the others by LU).
    pub symmetric_solves: usize,
    /// Solves by GMRES: every solve of an unsymmetric matrix (CG is for symmetric ones
    /// only), and the symmetric ones CG could not finish (iterations of both counted).
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
    /// The right-hand side of the solve under way, kept for a fallback or a residual check.
    rhs: Vec<f64>,
    /// K x of that check.
    product: Vec<f64>,
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
    /// (unsorted, duplicates allowed). Resets the multigrid, and the cached factorisations
    /// unless the pattern is the current one ([`SparseMatrix::set_pattern`]): a symbolic
    /// analysis is a function of the pattern only.
    pub fn set_pattern(&mut self, columns: Vec<Vec<usize>>) {
        if self.matrix.set_pattern(columns) {
            self.direct.reset();
        }
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

    /// The direct factorisation of a direct solver choice (`None` for the iterative one);
    /// [`LinearSolver::Auto`] looks at the current values.
    fn factorisation(&mut self) -> Option<Factorisation> {
        match self.solver {
            LinearSolver::Auto => Some(if self.is_symmetric() {
                Factorisation::Ldlt
            } else {
                Factorisation::Lu
            }),
            LinearSolver::Lu => Some(Factorisation::Lu),
            LinearSolver::Ldlt => Some(Factorisation::Ldlt),
            LinearSolver::Llt => Some(Factorisation::Llt),
            LinearSolver::Iterative => None,
        }
    }

    /// Factorise (LDLᵀ, LLᵀ or LU) for later [`Self::solve_factorized`]. Under
    /// [`LinearSolver::Auto`] the choice is by symmetry alone (LU if LDLᵀ fails): the
    /// backward-error check of [`Self::solve_in_place`] needs a right-hand side, which a
    /// factorisation kept for later solves does not have.
    pub fn factorize(&mut self) -> Result<(), SolverError> {
        if self.matrix.dim() == 0 {
            return Ok(());
        }
        let kind = self.factorisation().ok_or(SolverError::Usage(
            "factorize: a direct solver only (LDLᵀ, LLᵀ or LU)",
        ))?;
        let mut out = self.direct.factorize(self.matrix.csc().transpose_as_csc(), kind);
        if out.is_err() && self.solver == LinearSolver::Auto && kind != Factorisation::Lu {
            self.fallbacks += 1;
            out = self
                .direct
                .factorize(self.matrix.csc().transpose_as_csc(), Factorisation::Lu);
        }
        self.stats.factor_nnz = self.direct.factor_nnz();
        out
    }

    /// Solve with the factor of the last [`Self::factorize`].
    pub fn solve_factorized(&mut self, rhs: &mut [f64]) -> Result<(), SolverError> {
        if self.matrix.dim() == 0 {
            return Ok(());
        }
        self.direct.solve_in_place_reusing(rhs)
    }

    /// Whether the current matrix is symmetric to [`SYMMETRY_TOLERANCE`] (set-up time).
    fn is_symmetric(&mut self) -> bool {
        let start = std::time::Instant::now();
        let symmetric = self
            .direct
            .is_symmetric(self.matrix.csc().transpose_as_csc(), SYMMETRY_TOLERANCE);
        self.stats.charge(crate::solver::profile::Phase::Setup, start);
        symmetric
    }

    /// ‖b − K x‖∞ / (‖K‖ ‖x‖∞ + ‖b‖∞) (‖K‖ the largest line sum) of the solution `x` of `K x = b`, b in `self.rhs`.
    fn backward_error(&mut self, x: &[f64]) -> f64 {
        self.product.resize(x.len(), 0.0);
        self.matrix.mul_vec(x, &mut self.product);
        let inf = |v: &[f64]| v.iter().fold(0.0f64, |m, a| m.max(a.abs()));
        let residual = self
            .product
            .iter()
            .zip(&self.rhs)
            .fold(0.0f64, |m, (kx, b)| m.max((b - kx).abs()));
        residual / (self.matrix.max_line_sum() * inf(x) + inf(&self.rhs))
    }

    /// Factorise (set-up) and solve (solve), LU when a symmetric factorisation fails (or,
    /// for [`LinearSolver::Auto`], misses [`BACKWARD_ERROR_LIMIT`]).
    fn solve_direct(&mut self, rhs: &mut [f64]) -> Result<(), SolverError> {
        let symmetric = match self.solver {
            LinearSolver::Lu => None,
            LinearSolver::Llt => Some(Factorisation::Llt),
            LinearSolver::Auto => self.is_symmetric().then_some(Factorisation::Ldlt),
            // The iterative strategy's last resort is LDLᵀ.
            LinearSolver::Ldlt => Some(Factorisation::Ldlt),
            // The iterative strategy's last resort factorises as Auto does: LDLᵀ would read
            // one triangle of an unsymmetric tangent.
            LinearSolver::Iterative => self.is_symmetric().then_some(Factorisation::Ldlt),
        };
        if let Some(kind) = symmetric {
            self.rhs.clear();
            self.rhs.extend_from_slice(rhs);
            match self.solve_symmetric(rhs, kind) {
                Ok(()) if rhs.iter().all(|v| v.is_finite()) => {
                    if self.solver != LinearSolver::Auto {
                        return Ok(());
                    }
                    let start = std::time::Instant::now();
                    let accurate = self.backward_error(rhs) <= BACKWARD_ERROR_LIMIT;
                    self.stats.charge(crate::solver::profile::Phase::Solve, start);
                    if accurate {
                        self.stats.symmetric_solves += 1;
                        return Ok(());
                    }
                }
                _ => {}
            }
            self.fallbacks += 1;
            rhs.copy_from_slice(&self.rhs);
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
    fn solve_symmetric(&mut self, rhs: &mut [f64], kind: Factorisation) -> Result<(), SolverError> {
        let start = std::time::Instant::now();
        let factored = self.direct.factorize(self.matrix.csc().transpose_as_csc(), kind);
        self.stats.factor_nnz = self.direct.factor_nnz();
        self.stats.charge(crate::solver::profile::Phase::Setup, start);
        factored?;
        let start = std::time::Instant::now();
        let solved = self.direct.solve_in_place_reusing(rhs);
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

    /// The default solver takes LDLᵀ exactly where the matrix is symmetric to round-off and
    /// its solve is accurate: a symmetric system goes to LDLᵀ; one entry changed by 1e-9 of
    /// the diagonal's scale sends it to LU; a well-conditioned indefinite symmetric system whose
    /// LDLᵀ pivots grow (δ = 1e-10 on the diagonal, 1 elsewhere: any first pivot is δ, the
    /// growth 1/δ: a backward error of 2.9e-11, the solution off by 1.5e-10) passes as finite
    /// but fails the backward-error check and is redone by LU. Every solution is LU's.
    #[test]
    fn auto_takes_ldlt_only_where_symmetric_and_accurate() {
        let reference = |sys: &mut SparseSystem, rhs: &[f64]| solve(sys, LinearSolver::Lu, rhs);
        let close = |x: &[f64], y: &[f64]| {
            let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            x.iter().zip(y).all(|(a, b)| (a - b).abs() <= 1e-10 * scale)
        };
        let mut sys = laplacian(12, 0.5);
        let n = sys.dim();
        let rhs: Vec<f64> = (0..n).map(|i| ((i * 7919) % 13) as f64 - 6.0).collect();
        let lu = reference(&mut sys, &rhs);
        let x = solve(&mut sys, LinearSolver::Auto, &rhs);
        assert!(close(&x, &lu));
        assert_eq!((sys.stats().symmetric_solves, sys.fallbacks()), (1, 0));
        // Not symmetric: K_01 = −1 + 4.5e-9 against K_10 = −1 (√(K_00 K_11) = 4.5).
        sys.add(0, 1, 4.5e-9);
        let lu = reference(&mut sys, &rhs);
        let x = solve(&mut sys, LinearSolver::Auto, &rhs);
        assert!(close(&x, &lu));
        assert_eq!((sys.stats().symmetric_solves, sys.fallbacks()), (1, 0));
        // Symmetric, but LDLᵀ without pivoting is unstable on it.
        let delta = 1e-10;
        let mut sys = SparseSystem::default();
        sys.set_pattern(vec![vec![0, 1, 2]; 3]);
        for r in 0..3 {
            for c in 0..3 {
                sys.add(r, c, if r == c { delta } else { 1.0 });
            }
        }
        let rhs = [1.0, 2.0, 3.0];
        let lu = reference(&mut sys, &rhs);
        let x = solve(&mut sys, LinearSolver::Auto, &rhs);
        assert!(close(&x, &lu), "{x:?} {lu:?}");
        assert_eq!((sys.stats().symmetric_solves, sys.fallbacks()), (0, 1));
    }

    /// A pattern that is not structurally symmetric is never taken for symmetric, whatever
    /// its values; the mirror positions of a symmetric one pair every entry.
    #[test]
    fn a_structurally_unsymmetric_pattern_is_not_symmetric() {
        let mut sys = SparseSystem::default();
        sys.set_pattern(vec![vec![0, 1], vec![1]]);
        sys.add(0, 0, 2.0);
        sys.add(1, 1, 2.0);
        let x = solve(&mut sys, LinearSolver::Auto, &[2.0, 4.0]);
        assert_eq!(x, vec![1.0, 2.0]);
        assert_eq!(sys.stats().symmetric_solves, 0);
        sys.set_pattern(vec![vec![0, 1], vec![0, 1]]);
        sys.add(0, 0, 2.0);
        sys.add(1, 1, 2.0);
        let x = solve(&mut sys, LinearSolver::Auto, &[2.0, 4.0]);
        assert_eq!(x, vec![1.0, 2.0]);
        assert_eq!(sys.stats().symmetric_solves, 1);
    }

    /// Setting the current pattern again keeps it (and the symbolic analysis) but zeroes the
    /// values; a different one replaces it.
    #[test]
    fn an_equal_pattern_is_kept_and_zeroed() {
        let mut m = SparseMatrix::default();
        assert!(m.set_pattern(vec![vec![1, 0], vec![0, 1, 1]]));
        m.add(1, 0, 3.0);
        assert!(!m.set_pattern(vec![vec![0, 1], vec![1, 0]]));
        assert_eq!(m.get(1, 0), 0.0);
        assert!(m.set_pattern(vec![vec![0], vec![1]]));
        assert_eq!(m.nnz(), 2);
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
