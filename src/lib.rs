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
//! Verification studies are data (`studies/*.toml`): [`study`] parses them and runs the
//! cases (compute → `results.json`), [`render`] and [`plot`] render tables and SVG figures
//! from that file alone. The `study` binary is the front door:
//! `cargo run --release --bin study -- column`.
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
pub mod plot;
pub mod plot2d;
pub mod problems;
pub mod profile;
pub mod quadrature;
pub mod render;
#[cfg(feature = "seeded-bugs")]
pub mod seeded;
pub mod sparse;
pub mod study;
pub mod tensor;
pub mod vtk;
