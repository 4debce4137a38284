//! One-dimensional column compressed under its own weight (§5.1).
//!
//! The column of initial length L0 stands on a fixed base; gravity is ramped linearly over the
//! load steps to g = W/(ρ0 L0). Axis 0 is the vertical z; the out-of-plane stretches stay one
//! (uniaxial strain).
//!
//! Files: `analytical` (the closed form, eqs 42–45, 48–54), `spec` (the problem's parameters
//! and what a solve reports), `material_points` and `fem` (the discrete solves, 1D and the 3D
//! prism), `solve` (the dispatch on the method).

mod analytical;
mod fem;
mod material_points;
mod solve;
mod spec;

pub use crate::basis::method::Method;
pub use analytical::{f_from_cauchy_stress, AnalyticalColumn};
pub use fem::{fem_records, solve_fem, solve_fem_observed};
pub use material_points::solve_mpm;
pub use solve::{solve_column, solve_column_observed};
pub use spec::{
    yield_height_estimate, ColumnObserver, ColumnOutcome, ColumnSpec, ColumnState, PointRecord, METHODS,
    METHODS_3D,
};
