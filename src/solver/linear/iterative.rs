//! The iterative strategy of [`super::LinearSolver::Iterative`]: Krylov solves preconditioned
//! by the grid's multigrid, CG on a symmetric matrix and GMRES on an unsymmetric one, the
//! multigrid kept while it stays effective.

use super::{
    SparseSystem, DEFAULT_ITERATIVE_TOLERANCE, MAX_CG_ITERATIONS, MAX_GMRES_ITERATIONS, REUSE_FACTOR,
};
use crate::solver::error::SolverError;
use crate::solver::krylov::{gmres, pcg};
use crate::solver::multigrid::Hierarchy;
use crate::solver::sparse::Csr;

impl SparseSystem {
    /// `x = K⁻¹ b` by CG with the multigrid of the pattern's last fresh build while it stays
    /// effective: the hierarchy (prolongations, Galerkin products) is rebuilt from the current
    /// matrix when none exists for this pattern, or when a solve with the kept one needs more
    /// than [`REUSE_FACTOR`] times the iterations it took fresh (plus two), or fails; that
    /// solve is then repeated with the fresh hierarchy. Reuse changes the preconditioner, not
    /// the system: every solve still reaches its tolerance on the current matrix.
    pub(super) fn solve_cg(&mut self, b: &[f64], x: &mut [f64]) -> Result<(), SolverError> {
        // Taken out for the solve so that the strategy's state can change beside it; stored
        // by rows ([`Self::set_solver`]), it is borrowed as it is, not copied.
        // CG needs a symmetric operator: an unsymmetric tangent (F-bar, non-associated flow)
        // goes to GMRES with the same multigrid (reference/README.md item 71).
        let symmetric = self.is_symmetric();
        let matrix = std::mem::take(&mut self.matrix);
        let out = self.solve_cg_with(&matrix.csr(), b, x, symmetric);
        self.matrix = matrix;
        out
    }

    /// [`Self::solve_cg`] with the current matrix in row-compressed form.
    fn solve_cg_with(
        &mut self,
        a: &Csr,
        b: &[f64],
        x: &mut [f64],
        symmetric: bool,
    ) -> Result<(), SolverError> {
        let krylov = |a: &Csr, m: &Hierarchy, b: &[f64], x: &mut [f64], rtol: f64, max: usize| {
            if symmetric {
                pcg(a, m, b, x, rtol, max)
            } else {
                gmres(a, m, b, x, rtol, max)
            }
        };
        if !symmetric {
            self.stats.gmres_solves += 1;
        }
        let rtol = if self.tolerance > 0.0 {
            self.tolerance
        } else {
            DEFAULT_ITERATIVE_TOLERANCE
        };
        if let Some((m, fresh)) = self.hierarchy.as_ref() {
            // Given up once it needs more than the fresh count allows.
            let allowed = (REUSE_FACTOR * *fresh as f64) as usize + 2;
            let start = std::time::Instant::now();
            let report = krylov(a, m.as_ref(), b, x, rtol, allowed);
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
        let first_max = if symmetric {
            MAX_CG_ITERATIONS
        } else {
            MAX_GMRES_ITERATIONS
        };
        let report = krylov(a, &m, b, x, rtol, first_max);
        self.stats.charge(crate::solver::profile::Phase::Solve, start);
        self.stats.iterations += report.as_ref().map_or(first_max, |r| r.iterations);
        let report = match report {
            Ok(r) => r,
            Err(e) if !symmetric => return Err(e),
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
}
