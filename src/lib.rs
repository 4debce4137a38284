//! # igimp — implicit Generalised Interpolation Material Point method
//!
//! A reference implementation of Charlton, Coombs & Augarde, *iGIMP: An implicit Generalised
//! Interpolation Material Point Method for large deformations* (the paper; equation numbers in
//! the docs refer to it), with the verification studies that reproduce its results.
//!
//! ## Layers
//! The library, each folder importing only those above it in this list
//! (`tests/verification/layering.rs`):
//! - [`solver`]: the algebra of a load step, knowing no grid, point or element — sparse
//!   storage, faer's direct factorisations, PCG and GMRES, the geometric multigrid
//!   preconditioner, the solver strategy ([`solver::linear`]), Newton (eqs 22–23), load
//!   stepping and time integration (Newmark, generalised-α).
//! - [`mesh`]: the background grid, Gauss rules, size estimates.
//! - [`material`]: ΔF, log strain and the spatial tangent (eqs 15–19, 25, 30–36) and the
//!   constitutive models (eq 14).
//! - [`basis`]: the basis families (MPM, iGIMP eqs 7–10, CPDI2, B-splines, TLMPM) and the
//!   method table ([`basis::method`]).
//! - [`discretise`]: degrees of freedom, per-point residual and tangent assembly (eqs 27–29,
//!   36, 41), ghost penalty.
//! - [`mpm`]: the material points and their solver (load steps, commit, domain update eqs
//!   37–39);
//!   [`fem`]: the updated-Lagrangian line, Q4/Q8 and Hex8/Hex20 comparators on the same
//!   assembly, kinematics and Newton.
//! - [`problems`]: the paper's examples with their analytical solutions and the error
//!   measures (eqs 46–47, [`problems::norms`]).
//!
//! The harness (the default feature `harness`; `default-features = false` builds the
//! library alone): `study` parses the study files (`studies/*.toml`) and runs their cases
//! (compute → `results.json`), `study::render` draws tables and SVG figures from that file
//! alone, and the `study` binary is its front door (`cargo run --release --bin study -- column`).
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
//! let gravity = weight / (density * length);
//! // The base (node 0) fixed along axis 0; iGIMP and 20 load steps are the defaults.
//! let mut solver = MpmSolver::builder(grid, points)
//!     .material(LinearElastic::try_new(young, 0.0)?)
//!     .fix(0, 0)
//!     .gravity(SVector::<f64, 1>::new(-gravity))
//!     .build()?;
//! solver.run()?;
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

pub mod basis;
pub mod discretise;
pub mod fem;
pub mod material;
pub mod mesh;
pub mod mpm;
pub mod problems;
pub mod solver;
#[cfg(feature = "harness")]
pub mod study;

#[cfg(feature = "seeded-bugs")]
pub mod seeded {
    //! Deliberately wrong kernels, compiled only with the `seeded-bugs` feature, so that the test
    //! `tests/seeded.rs` can show each key check failing on a broken variant. The default build has
    //! none of this: every call site is behind `#[cfg(feature = "seeded-bugs")]`.
    //!
    //! One process-wide switch (the solvers assemble on rayon threads, so a thread-local would not
    //! reach them); the test that sets it runs its variants one after another in one test function.

    use std::sync::atomic::{AtomicU8, Ordering};

    /// A seeded bug.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    #[repr(u8)]
    pub enum Bug {
        /// The correct kernels.
        None = 0,
        /// The spatial tangent without its geometric term −σ_il δ_jk (eq 25).
        NoGeometricTerm = 1,
        /// Eq (36) without ΔF⁻¹: start-of-step gradients used as current ones.
        NoDeltaFInverse = 2,
        /// V_p = V_p^n instead of det(ΔF) V_p^n (eq 28).
        NoVolumeChange = 3,
        /// GIMP weights without the per-element split of eqs (7)–(10) (Figure 3): the whole
        /// domain integrated against the shape functions of the element holding its centre.
        NoElementSplit = 4,
        /// Multigrid prolongation with the two weights along each axis swapped (t for the lower
        /// node, 1 − t for the upper): a fine node on a coarse node draws on its neighbour.
        SwappedProlongation = 5,
        /// B-splines without their boundary treatment: the weights of nodes beyond the grid
        /// dropped instead of folded back by linear extrapolation.
        SplineWithoutBoundary = 6,
        /// CPDI corners moved against the grid: x_α − Σ N_v(x_α) Δu_v.
        CornersAgainstGrid = 7,
        /// TLMPM with the reference gradients ∇₀S used as the start-of-step ones (no Fₙ⁻ᵀ).
        ReferenceGradients = 8,
        /// The effective tangent of a dynamic step without its mass term M/(βΔt²).
        NoMassInTangent = 9,
        /// Drucker–Prager's apex treated as a smooth part of the cone: the cone's return
        /// applied past it.
        DruckerPragerSmoothApex = 10,
        /// F-bar's tangent without its F-bar terms: the plain tangent at F̄.
        FBarWithoutItsTangent = 11,
        /// Mohr–Coulomb's edge states returned with one multiplier: the main plane's return
        /// accepted even where it breaks the ordering τ₁ ≥ τ₂ ≥ τ₃.
        MohrCoulombEdgeOneMultiplier = 12,
        /// Modified Cam-Clay's consistent tangent without the hardening of p_c: the terms of
        /// ∂p_c/∂εᵥᵉ and ∂p_c/∂εᵥᵗ left out of the linearised return.
        CamClayTangentWithoutHardening = 13,
        /// The pressure projection's tangent without its patch block R Pᵀ: the rate of the
        /// cell's mean pressure left out.
        PressureProjectionWithoutItsBlock = 14,
        /// The strength reduction dividing the cohesion alone: tan φ (and tan ψ) left as given.
        StrengthReductionCohesionOnly = 15,
        /// The point penalty's residual without its tangent k_p S_ip S_jp.
        PointPenaltyWithoutItsTangent = 16,
        /// Newton's extrapolated start repeating the last increment, not scaled to this one's
        /// load.
        ExtrapolatedStartUnscaled = 17,
    }

    static ACTIVE: AtomicU8 = AtomicU8::new(0);

    /// Switch the kernels to `bug` (or back, with [`Bug::None`]).
    pub fn set(bug: Bug) {
        ACTIVE.store(bug as u8, Ordering::SeqCst);
    }

    /// Is `bug` the one switched on?
    pub fn active(bug: Bug) -> bool {
        ACTIVE.load(Ordering::Relaxed) == bug as u8
    }
}

/// What a program that builds and runs a solver from its parts needs: the grid, the material
/// points, the models, the solver and its settings, the load stepping, the errors, and the
/// column's closed form for checking.
pub mod prelude {
    pub use crate::basis::Basis;
    pub use crate::discretise::ghost::GhostSettings;
    pub use crate::fem::{HexElement, HexMesh, LineElement, LineMesh, PlaneMesh, QuadElement};
    pub use crate::material::constitutive::{ConstitutiveModel, LinearElastic, Material, VonMises};
    pub use crate::mesh::grid::Grid;
    pub use crate::mpm::particles::MaterialPoints;
    pub use crate::mpm::{DomainUpdate, Loads, MpmBuilder, MpmSettings, MpmSolver};
    pub use crate::problems::column::AnalyticalColumn;
    pub use crate::solver::error::{InputError, SolveError};
    pub use crate::solver::load_stepping::{LoadStepping, RunFailure};
    pub use crate::solver::newton::NewtonSettings;
    pub use nalgebra::SVector;
}
