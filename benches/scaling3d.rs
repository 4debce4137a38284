//! Scaling of one 3D Newton iteration of the compaction problem (the quarter of the
//! 8 × 8 × 8 block, `CompactionSpec::mpm_solver_3d`) with the number of material points,
//! split as `scaling2d` is: weights, constitutive (residual pass), tangent assembly,
//! factorisation + solve (direct, the library's only solver so far), peak memory. One process
//! per size; a size whose child fails (e.g. runs out of memory) stops the sweep and says so:
//!
//! `cargo bench --bench scaling3d -- 1e4 1e5 1e6` (sizes are target point counts, 2×2×2
//! points per cell: 1024 / h³ points). The same `SCALING_*` variables as `scaling2d`.
mod scaling;

use igimp::problems::compaction::CompactionSpec;
use std::time::Instant;

fn run(target: f64) {
    // 2×2×2 points per cell in the 4 × 4 × 8 quarter block: 1024 / h³ points; the 10 × 10 × 10
    // grid needs 10 h to be whole, so h = 1/n.
    let cells_per_unit = (target / 1024.0).cbrt().round().max(1.0);
    let h = 1.0 / cells_per_unit;
    let spec = CompactionSpec {
        element_size: h,
        dimension: 3,
        linear_solver: scaling::solver_from_env(),
        ghost: scaling::ghost_from_env(),
        ..CompactionSpec::default()
    };
    let t = Instant::now();
    let solver = spec.mpm_solver_3d().expect("valid 3D compaction");
    let setup = t.elapsed().as_secs_f64();
    scaling::time_iteration(solver, spec.ghost.is_on(), spec.linear_solver, h, setup);
}

fn main() {
    scaling::drive(&[1e4, 1e5], run);
}
