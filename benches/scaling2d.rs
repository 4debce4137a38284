//! Scaling of one 2D Newton iteration of the compaction problem (§5.2) with the number of
//! material points: time split into weights, constitutive (residual pass), tangent assembly
//! and factorisation + solve, and the process's peak memory. One process per size, so that
//! the peak memory belongs to that size alone:
//!
//! `cargo bench --bench scaling2d -- 1e4 1e5 1e6` (sizes are target point counts).
//! `SCALING_GHOST=<gamma>[:all]` adds the ghost penalty (cut faces, or every face) to the
//! residual, pattern and tangent, to measure its cost against the same run without it.
//! `SCALING_SHIFT=<s>` translates every point by s·h in x and y first, so that the block's
//! boundary cells are partially filled (the block starts cell-aligned: no cut faces).
//! `SCALING_SOLVER=lu|llt|ldlt|cg` picks the factorisation (default LDLᵀ) or multigrid CG.
//! `SCALING_REPEAT=<k>` times the constitutive pass, assembly and solve k times and reports
//! each one's fastest (the shared machine's timings wander from run to run).
mod scaling;

use igimp::problems::compaction::CompactionSpec;
use std::time::Instant;

fn run(target: f64) {
    // 2×2 points per cell in the 4 × 8 half block: 128 / h² points.
    let cells_per_unit = (target / 128.0).sqrt().round().max(1.0);
    let h = 1.0 / cells_per_unit;
    let spec = CompactionSpec {
        element_size: h,
        linear_solver: scaling::solver_from_env(),
        ghost: scaling::ghost_from_env(),
        ..CompactionSpec::default()
    };
    let t = Instant::now();
    let solver = spec.mpm_solver().expect("valid compaction");
    let setup = t.elapsed().as_secs_f64();
    scaling::time_iteration(solver, spec.ghost.is_on(), spec.linear_solver, h, setup);
}

fn main() {
    scaling::drive(&[1e4, 1e5], run);
}
