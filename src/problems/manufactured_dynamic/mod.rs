//! Dynamic manufactured solutions (Wallstedt & Guilkey, *J. Comput. Phys.* 227 (2008) 9628,
//! §4: a prescribed motion, its body force b₀ = ρ₀ ẍ − Div P, errors against the motion) in
//! plane strain on the unit square and on the unit cube (`dimension = 3`: the fields of
//! [`super::manufactured3d`], the axis-aligned one on three axes, the vortex about z). The
//! material fills the square (cube), which is also the background grid or the FEM mesh;
//! rollers on every face, as in the static fields ([`super::manufactured`]).
//!
//! Each static field's amplitude is made to oscillate: a(t) = A sin ωt with ω = πc,
//! c = √(E/ρ₀), as Wallstedt & Guilkey's axis-aligned field u = A sin(2πX) sin(cπt):
//! - **axis-aligned**: x = X + a(t) (sin πX, sin πY) (Wallstedt & Guilkey's spatial shape is
//!   sin 2πX; sin πX is the static field's, which the rollers also satisfy);
//! - **vortex**: x = c + R(a(t) θ̂(r)) (X − c), θ̂ = (1 − 4r²)³ for r ≤ ½: a time-dependent
//!   rotation varying with radius, Wallstedt & Guilkey's "generalized vortex" on the unit
//!   square instead of their annulus, so that no cell is partly filled (F = I near the edges).
//!
//! The velocity and acceleration of the motion are ẋ = ∂x/∂a ȧ and
//! ẍ = ∂²x/∂a² ȧ² + ∂x/∂a ä, in closed form (tested against central differences in t); Div P
//! at time t is the static field's at amplitude a(t) (forward-mode automatic differentiation).
//! The analysis starts from x = X with the exact velocity and acceleration (M a₀ balances
//! f_ext(0): a wrong a₀ would cost the trapezoidal rule its order) and runs Newmark time steps
//! ([`crate::solver::dynamics`]) to `periods` × T, T = 2π/ω. The errors are the static study's
//! (displacement and stress at the points) at the end, against the motion at that time.
//!
//! Files: `spec` (the analysis' parameters and time scales), `motion` (the exact motion in
//! time and its body force), `solve` (the material point and element solvers, 2D and 3D).

mod motion;
mod solve;
mod spec;

pub use motion::ExactMotion;
pub use solve::{fem_solver, fem_solver_3d, mpm_solver, solve, solve_3d};
pub use spec::{DynamicManufacturedSpec, METHODS};
