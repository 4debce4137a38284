//! Plane-strain compaction of a block under its own weight (§5.2, Figures 15–18, Tables 2–3).
//!
//! Geometry as we read the paper: the full block is `2 × half_width` wide and `height` high; by
//! symmetry the half `0 ≤ x ≤ half_width` is modelled, with a roller (u_x = 0) on the symmetry
//! line x = 0 and u_y = 0 on the bottom edge y = 0. It sits in a background grid covering
//! `[0, grid_extent[0]] × [0, grid_extent[1]]`, which leaves room for the material to spread.
//! `weight` is the weight of the full block; the modelled half carries half of it, applied by
//! gravity ramped over the load steps (ρ0 g = weight / (2 half_width · height), density 1).
//!
//! Files: `spec` (the block's parameters, material and methods), `material_points` (iGIMP and
//! the other families, the plane block and the 3D quarter block), `fem` (the Q4/Q8 and
//! Hex8/Hex20 comparators), `solve` (the dispatch on the method and the dimension).

mod fem;
mod material_points;
mod solve;
mod spec;

pub use fem::{fem_solver, fem_solver_3d, solve_fem, solve_fem_3d, FemOutcome};
pub use material_points::{solve_mpm, solve_mpm_3d, CompactionOutcome, Domain3dRecord, DomainRecord};
pub use solve::{solve, CompactionSolution};
pub use spec::{methods, CompactionSpec, METHODS, METHODS_3D};
