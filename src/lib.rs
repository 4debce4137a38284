//! # igimp — implicit Generalised Interpolation Material Point method
//!
//! A reference implementation of Charlton, Coombs & Augarde, *iGIMP: An implicit Generalised
//! Interpolation Material Point Method for large deformations* (the paper; equation numbers in
//! the docs refer to it), with the verification studies that reproduce its results.
//!
//! ## Pipeline
//! [`grid`] (regular background grid) → [`basis`] (MPM / GIMP weights, eqs 7–10) →
//! [`assembly`] (per-point residual and tangent, eqs 27–29, 36, 41) with [`kinematics`]
//! (ΔF, log strain, spatial tangent; eqs 15–19, 25, 30–36) and [`constitutive`] (eq 14) →
//! [`linear`] (the solver strategy: a direct factorisation, or multigrid-preconditioned CG
//! with GMRES and direct fallbacks) → [`newton`] (eqs 22–23) → [`mpm`] (load steps, commit,
//! domain update eqs 37–39). The solver floors, each importing only those below it
//! (`tests/verification/layering.rs`): [`sparse`] (CSC assembly storage, CSR products) →
//! [`direct`] (faer LU, LDLᵀ, LLᵀ with cached symbolic analysis) and [`krylov`] (PCG,
//! GMRES) → [`multigrid`] (the geometric V-cycle preconditioner) → [`linear`]. [`fem`] runs
//! the same assembly, kinematics and Newton on Gauss points ([`quadrature`]) of
//! updated-Lagrangian line (1D), Q4/Q8 (plane strain) and Hex8/Hex20 (3D) elements, the
//! paper's comparators. [`problems`] holds the paper's
//! examples with their analytical solutions; [`norms`] the error measures (eqs 46–47).
//!
//! Verification studies are data (`studies/*.toml`): `study` parses them and runs the
//! cases (compute → `results.json`), `render` and `plot` render tables and SVG figures
//! from that file alone. These modules, `kinds` and the `study` binary (the harness's front
//! door: `cargo run --release --bin study -- column`) are the default feature `harness`;
//! `default-features = false` builds the solver library alone.
//!
//! ## Notation
//! | paper | Rust |
//! |---|---|
//! | S_vp, ∇S_vp | `Support::node`, `SupportTable::point` |
//! | F, ΔF | `PointState::f`, `PointTrial::delta_f` |
//! | b^e, ε^e | `MaterialState::b_e`, `MaterialState::eps_e` |
//! | τ, σ | `MaterialResponse::tau`, `PointTrial::sigma` |
//! | D^alg, a_ijkl | `ConstitutiveModel::tangent`, `PointTrial::spatial_tangent` |
//! | V_p, V_p^n | `PointTrial::volume`, `PointState::volume` |
//! | l_p | `MaterialPoints::half_length` (half of l_p) |

//!
//! ## The library from its parts
//!
//! The elastic column of §5.1 (L0 = 50, E = 1e6, W = 40,000) by iGIMP with 2 points in each
//! of 50 elements, against its closed form (eq 45):
//!
//! ```
//! use igimp::prelude::*;
//!
//! let (length, young, density, weight) = (50.0, 1.0e6, 80.0, 40_000.0);
//! let elements = 50;
//! let grid = Grid::try_new([0.0], [length / elements as f64], [elements])?;
//! let points = MaterialPoints::fill_box(&grid, [0.0], [length], [2], density)?;
//! let model = Box::new(LinearElastic::try_new(young, 0.0)?);
//! let gravity = weight / (density * length);
//! let loads = Loads { gravity: SVector::<f64, 1>::new(-gravity), point_loads: vec![] };
//! // Node 0 (the base) fixed along axis 0; iGIMP, 20 load steps: the defaults.
//! let mut solver = MpmSolver::try_new(grid, points, model, vec![(0, 0)], loads, MpmSettings::default())?;
//! solver.run().map_err(|(_, e)| e)?;
//!
//! let exact = AnalyticalColumn {
//!     lambda: 0.0,
//!     mu: young / 2.0,
//!     unit_weight: weight / length,
//!     length,
//!     yield_stress: None,
//! };
//! let pts = &solver.points;
//! let top = (0..pts.len()).max_by(|&a, &b| pts.position0[a][0].total_cmp(&pts.position0[b][0])).unwrap();
//! let (u, u_exact) = (pts.displacement(top)[0], exact.displacement(pts.position0[top][0]));
//! // iGIMP's discretisation error here is 8.2e-5 (the committed column study's case
//! // igimp-w40000-e50-p2-s20 gives the same u); the band is 2.5 times it.
//! assert!(((u - u_exact) / u_exact).abs() < 2e-4, "u = {u}, exact {u_exact}");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

// Tensor kernels index several arrays with the same component indices; iterator forms would
// obscure the index notation of the paper.
#![allow(clippy::needless_range_loop)]

pub mod assembly;
pub mod atomic_file;
pub mod basis;
pub mod budget;
pub mod constitutive;
pub mod direct;
pub mod dofs;
pub mod dynamics;
pub mod error;
pub mod fem;
pub mod ghost;
pub mod grid;
#[cfg(feature = "harness")]
pub mod kinds;
pub mod kinematics;
pub mod krylov;
pub mod linear;
pub mod load_stepping;
pub mod method;
pub mod mpm;
pub mod multigrid;
pub mod newton;
pub mod norms;
pub mod particles;
#[cfg(feature = "harness")]
pub mod plot;
#[cfg(feature = "harness")]
pub mod plot2d;
pub mod problems;
pub mod profile;
pub mod quadrature;
#[cfg(feature = "harness")]
pub mod render;
#[cfg(feature = "seeded-bugs")]
pub mod seeded;
pub mod sparse;
#[cfg(feature = "harness")]
pub mod study;
pub mod tensor;
pub mod vtk;

/// What a program that builds and runs a solver from its parts needs: the grid, the material
/// points, the models, the solver and its settings, the load stepping, the errors, and the
/// column's closed form for checking.
pub mod prelude {
    pub use crate::basis::Basis;
    pub use crate::constitutive::{ConstitutiveModel, LinearElastic, VonMises};
    pub use crate::error::{InputError, SolveError};
    pub use crate::fem::{HexElement, HexMesh, LineElement, LineMesh, PlaneMesh, QuadElement};
    pub use crate::ghost::GhostSettings;
    pub use crate::grid::Grid;
    pub use crate::load_stepping::LoadStepping;
    pub use crate::mpm::{DomainUpdate, Loads, MpmSettings, MpmSolver};
    pub use crate::newton::NewtonSettings;
    pub use crate::particles::MaterialPoints;
    pub use crate::problems::column::AnalyticalColumn;
    pub use nalgebra::SVector;
}
