//! The material at a point: fourth-order tensors, the finite-deformation kinematics (ΔF, log
//! strain, spatial tangent; eqs 15–19, 25, 30–36) and the constitutive models (eq 14).

pub mod constitutive;
pub mod kinematics;
pub mod prestress;
pub mod strength_reduction;
pub mod tensor;
