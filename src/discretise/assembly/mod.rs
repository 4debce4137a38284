//! Residual and sparse tangent assembly over integration points, shared by the material point
//! solvers (points = material points, supports = GIMP/MPM weights) and the finite element
//! comparators (points = Gauss points, supports = element shape functions).
//!
//! Each point contributes `f_p = [G]ᵀ{σ} V_p` (eq 29) and `K_p = [G]ᵀ[a][G] V_p` (eq 27),
//! where \[G\] holds ∂S/∂x = ∂S/∂X̃ · ΔF⁻¹ (eqs 36, 41). The residual's points are evaluated
//! in parallel into per-point slots and summed in point order; the tangent's threads each own
//! a block of columns and add every point's block to them in point order, so results do not
//! depend on the thread count.

mod fbar;
mod forces;
mod kernel;
mod local;
mod pattern;
mod predictor;
mod pressure;
mod reactions;
mod system;
mod workspace;

pub use crate::discretise::dofs::{DofMap, SupportTable, MAX_POINT_NODES};
pub use fbar::{FBar, FBarScratch};
pub use forces::map_point_forces;
pub use reactions::LinearisedReactions;
pub use system::{DynamicReference, LoadStepSystem};
pub use workspace::{StartForces, StepInput, StepWorkspace};
