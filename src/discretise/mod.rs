//! From points (or Gauss points) and their supports to equations: the degrees of freedom and
//! their sparsity pattern, the assembly of residuals and tangents (eqs 27–29, 36, 41), and the
//! ghost-penalty stabilisation of cut cells. Shared by the material point ([`crate::mpm`]) and
//! the finite element ([`crate::fem`]) solvers.

pub mod assembly;
pub mod dofs;
pub mod ghost;
pub mod patches;
pub mod point_penalty;
pub mod prescribed;
