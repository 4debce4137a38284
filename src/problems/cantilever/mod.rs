//! Cantilever under a dead end load (§5.3, Figures 19–21).
//!
//! A beam `length × depth` (plane strain by default) sits with its left end on the grid line
//! x = 0 and its neutral axis on a grid line. Supports as in the paper: every grid node on the
//! left boundary x = 0 is on a roller (u_x = 0) and the node on the neutral axis is also fixed
//! vertically. The end load P (vertical, fixed direction) is split equally between the two
//! end-most material points just above and just below the neutral axis, and applied over the
//! load steps. The background grid extends below the beam far enough for the deflected shape.
//!
//! In 3D (`dimension = 3`, reference/README.md items 29 and 38) the beam is `length × depth × depth` (a square section),
//! x along the beam, y up, z across. The supports are those of 2D on the end face x = 0 (u_x = 0
//! on every node, u_y = 0 along its neutral-axis line), plus u_z = 0 on the mid-plane
//! z = depth / 2, which is exact by symmetry and removes the rigid motions across. The end
//! load is split equally over the end-most points of the two rows straddling the neutral axis,
//! across the whole width (a line load); Hex8/Hex20 FEM carry it as the consistent line load on
//! the end edge along the neutral axis.
//!
//! Files: `spec` (the beam's parameters, its methods, the end displacement every solve
//! records), `material_points` (iGIMP and the other families, 2D and 3D), `fem` (the Q8 and
//! Hex8/Hex20 comparators), `solve` (the dispatch on the method).

mod fem;
mod material_points;
mod solve;
mod spec;

pub use fem::{fem_q8, solve_fem_3d, solve_fem_q8, FemOutcome};
pub use material_points::{solve_mpm, solve_mpm_with, CantileverOutcome, DomainSnapshot, SolidSnapshot};
pub use solve::{solve, CantileverSolution};
pub use spec::{methods, CantileverSpec, EndDisplacement, METHODS, METHODS_3D};
