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
