//! The algebra of a load step, knowing no grid, no material point and no element: sparse
//! storage, direct and Krylov solvers, the multigrid preconditioner, the solver strategy,
//! Newton (eqs 22–23), load stepping, time integration, vector norms, timers and errors.
//! Floors, each importing only those below it (`tests/verification/layering.rs`): `sparse` →
//! `direct`, `krylov` → `multigrid` → `linear` → `newton` → `load_stepping`.

pub mod direct;
pub mod dynamics;
pub mod error;
pub mod krylov;
pub mod linear;
pub mod load_stepping;
pub mod multigrid;
pub mod newton;
pub mod norms;
pub mod profile;
pub mod ramp;
pub mod sparse;
