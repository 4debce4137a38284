//! Manufactured solutions in plane strain: the material fills the unit square Ω₀ = [0, 1]²,
//! which is also the background grid (or the FEM mesh), so no cell is ever partly filled and
//! the errors isolate the interior discretisation and cell crossing.
//!
//! Two motions x(X), Hencky elasticity (the library's [`LinearElastic`](crate::material::constitutive::LinearElastic): τ = λ tr(ε) I + 2μ ε,
//! ε = ½ ln b, plane strain):
//! - **axis-aligned**: x = X + A (sin πX, sin πY), F diagonal;
//! - **vortex**: x = c + R(θ(r)) (X − c), c = (½, ½), r = |X − c|, θ = θ₀ (1 − 4r²)³ for r ≤ ½
//!   and 0 outside: isochoric (det F = 1), rotation up to θ₀.
//!
//! The dead body force per unit reference volume is b₀ = −Div P (P = τ F⁻ᵀ), computed by
//! forward-mode automatic differentiation of P(F(X)) ([`num_dual`]), carried by the material
//! points (Gauss points) with their initial volume and mapped like gravity (eq 40), ramped over
//! the load steps: at the full load the manufactured field is the exact solution.
//!
//! Boundary conditions: rollers on every edge (the normal displacement fixed). Both motions
//! satisfy them exactly and have no tangential traction there: the axis-aligned P is diagonal,
//! and the vortex has F = I near the whole boundary. Fixing every boundary node, as first
//! specified, would contradict the axis-aligned field (u_y = A sin πY ≠ 0 on X = 0);
//! reference/README.md records the correction.
//!
//! Files: `spec` (the analysis' parameters), `exact` (the motions, their stresses and body
//! force by automatic differentiation), `measures` (the error measures of the points), `solve`
//! (the material point and Q4/Q8 solvers).

mod exact;
mod measures;
mod solve;
mod spec;

pub use exact::{
    deformation_gradient, first_piola, first_piola_block, kirchhoff, kirchhoff_block, motion, Exact, M2,
};
pub use measures::{errors, stress_deviations, Errors, PointValue};
pub(crate) use solve::{fem_point_values, mpm_point_values, mpm_settings, rollers};
pub use solve::{fem_solver, mpm_solver, solve, ManufacturedSolution};
pub use spec::{Field, ManufacturedSpec, HENCKY_ONLY, METHODS};
