//! Updated-Lagrangian finite element comparators (§5.1 Table 1 and Figure 11; §5.2 Figure 17;
//! §5.3 Figure 21).
//!
//! The entry points are [`LineFem`], a 1D solver on a [`LineMesh`] of linear or quadratic
//! elements with a Gauss rule of 1 to 5 points, and [`ContinuumFem`] on an [`ElementMesh`] of
//! one tensor-product family: [`PlaneFem`], plane strain on 4-node or 8-node serendipity
//! quadrilaterals ([`QuadElement`], [`PlaneMesh`]) with an n×n Gauss rule (default 2×2 for
//! Q4, 3×3 for Q8), and [`SolidFem`], 3D on 8-node or 20-node serendipity hexahedra
//! ([`HexElement`], [`HexMesh`]) with an n×n×n rule (default 2×2×2 for Hex8, 3×3×3 for
//! Hex20); one shape-function formula serves all four ([`serendipity_shape`]). Both implement
//! [`LoadStepping`] through the same generic load step
//! (`fem_step` over the [`FemMesh`] trait: a mesh supplies its shape functions and moves its
//! nodes; Gauss point storage is [`GaussPoints`]). Each shares everything below the load-step loop
//! with the material point solver ([`crate::mpm::MpmSolver`]): Gauss points are integration
//! points like material points, so each load step fills a [`SupportTable`] with the element
//! shape functions N_a(ξ_q) and their gradients ∂N_a/∂X̃ on the start-of-step mesh
//! (eqs 33–34), and the kinematics ([`crate::material::kinematics`], eqs 15–19, 25, 30–36), the
//! constitutive update, the assembly ([`LoadStepSystem`], eqs 27, 29, 36), the sparse solve and
//! Newton ([`crate::solver::newton`]) are the same code.
//!
//! # Updated Lagrangian
//! Nodes move with the material. At the start of a step the reference configuration X̃ is
//! the current node positions; at the end of it the nodes move by the converged increment Δu.
//! A Gauss point keeps its local coordinate ξ_q, so in 1D
//! ΔF = 1 + ∂Δu/∂X̃ = J_{n+1}(ξ_q) / J_n(ξ_q) with J = dx/dξ, and the product of the increments
//! telescopes to F = J(ξ_q) / J_0(ξ_q), the exact deformation gradient of the mesh.
//!
//! # Gauss point volume
//! The start-of-step volume V_n used in eqs (27)–(29) is the committed `PointState::volume`,
//! i.e. V_0 = w_q det(∂X/∂ξ) at the start, multiplied by det ΔF at every commit (eq 28): the
//! same commit path as a material point. By the telescoping above it equals
//! w_q det(∂X̃/∂ξ) on the current mesh to round-off (tested), so nothing FEM-specific is needed.
//!
//! # Loads
//! Each Gauss point carries the mass m_q = ρ0 w_q det(∂X/∂ξ)|₀, so gravity maps to the nodes as
//! f_a = Σ_q N_a(ξ_q) m_q g (eq 40 with Gauss points), the Gauss-rule approximation of
//! ∫ N_a ρ0 g dX over the reference element. Nodal point loads may be added.
//!
//! # Exact sampling points for the self-weight column
//! The exact Cauchy stress σ(Z) is linear in the initial height Z (eq 42) and a function of F
//! alone (eq 45). For linear elements F is constant per element, and nodal equilibrium with
//! the consistent load makes σ_h = σ(Z_centre) exactly (the column above a node weighs the
//! same in both): sampled at the element centre (1 Gauss point) the stress is exact for any
//! mesh; with 2 Gauss points the same constant is compared at ξ = ±1/√3 and the error eq (46)
//! is O(h). For quadratic elements with 2 Gauss points, F_h is linear in each element and can
//! take the exact values at the two points; σ(F(Z_q)) then is the exact linear σ, the
//! internal force Σ_q σ_q N_a' w_q (degree ≤ 2) and the load Σ_q N_a ρ0 g w_q J_0
//! (degree 2) are integrated exactly, so that field satisfies the discrete equations: the
//! stress at the 2 Gauss points is exact (round-off) for any number of elements. With 3
//! Gauss points the error is O(h²). The paper states both facts (§5.1); the tests pin them.

mod continuum;
mod hex;
mod line;
mod mesh;
mod quad;
mod updated_lagrangian;

pub use continuum::{ContinuumFem, FemLoads, PlaneFem, PlaneFemSettings, PlaneLoads, SolidFem, SolidLoads};
pub use hex::{HexElement, HexMesh};
pub use line::{LineElement, LineMesh, MAX_LINE_NODES};
pub use mesh::{serendipity_shape, ElementFamily, ElementMesh, Shape, MAX_ELEMENT_NODES};
pub use quad::{PlaneMesh, QuadElement, MAX_QUAD_NODES};
pub use updated_lagrangian::{validate_stepping, FemMesh, GaussPoints, MAX_LOAD_STEPS};

use crate::discretise::assembly::{LoadStepSystem, SupportTable};
use crate::material::constitutive::ConstitutiveModel;
use crate::mesh::quadrature::GaussRule;
use crate::solver::dynamics::Newmark;
use crate::solver::error::{require_finite, FailedAttempt, InputError, StepFailure};
use crate::solver::load_stepping::{Increment, LoadStepping};
use crate::solver::newton::NewtonSettings;
use nalgebra::SVector;
use updated_lagrangian::{fem_advance, fem_step_system, UlCore};

/// The solver of a FEM comparator asked for `requested`: the iterative strategy, or a
/// direct factorisation named, if asked for; otherwise LDLᵀ where the model's tangent is
/// symmetric (the symmetric factorisation the comparators' committed answers come from) and
/// LU where it is not (non-associated plasticity: LDLᵀ would read one triangle of an
/// unsymmetric matrix, and Newton on the compaction in Drucker–Prager with ψ = 5° fell to a
/// linear rate with it, reference/README.md item 68). F-bar's tangent is unsymmetric whatever
/// the model (Q4 on the compaction: residuals 3.9e-4, 3.5e-7, 2.4e-10 by LDLᵀ, item 69).
pub fn comparator_solver(
    requested: crate::solver::linear::LinearSolver,
    symmetric_tangent: bool,
) -> crate::solver::linear::LinearSolver {
    use crate::solver::linear::LinearSolver;
    match requested {
        LinearSolver::Auto if symmetric_tangent => LinearSolver::Ldlt,
        LinearSolver::Auto => LinearSolver::Lu,
        other => other,
    }
}

/// Settings of a [`LineFem`] analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineFemSettings {
    /// Gauss points per element, 1..=5.
    pub gauss_points: usize,
    /// Newton iteration settings of each load step.
    pub newton: NewtonSettings,
    /// Number of equal load increments.
    pub load_steps: usize,
}

impl LineFemSettings {
    /// Check the Gauss rule, the Newton settings and the number of load steps.
    pub fn validate(&self) -> Result<(), InputError> {
        GaussRule::try_new(self.gauss_points)?;
        validate_stepping(&self.newton, self.load_steps)
    }
}

/// Loads at the end of the analysis, applied proportionally over the load steps.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LineLoads {
    /// Gravitational acceleration along the line (body force per unit mass).
    pub gravity: f64,
    /// Point forces on nodes: (node, force).
    pub nodal_forces: Vec<(usize, f64)>,
}

/// Implicit updated-Lagrangian FEM on a line mesh.
pub struct LineFem {
    /// Initial mesh.
    pub mesh0: LineMesh,
    /// Current mesh (nodes moved with the material).
    pub mesh: LineMesh,
    /// The Gauss points with their committed states.
    pub gauss: GaussPoints,
    /// Nodes with zero displacement.
    pub fixed: Vec<usize>,
    /// Loads at the end of the analysis.
    pub loads: LineLoads,
    /// Gauss rule, Newton and load-stepping settings.
    pub settings: LineFemSettings,
    rule: GaussRule,
    core: UlCore<1>,
}

impl LineFem {
    /// A solver on `mesh` with material density `density` (mass per unit initial length).
    pub fn try_new(
        mesh: LineMesh,
        density: f64,
        model: Box<dyn ConstitutiveModel>,
        fixed: Vec<usize>,
        loads: LineLoads,
        settings: LineFemSettings,
    ) -> Result<Self, InputError> {
        settings.validate()?;
        crate::solver::error::require_positive("density", density)?;
        require_finite("gravity", loads.gravity)?;
        for &n in &fixed {
            if n >= mesh.num_nodes() {
                return Err(InputError::new(
                    "fixed node",
                    n,
                    format!("must be < {}", mesh.num_nodes()),
                ));
            }
        }
        for &(n, f) in &loads.nodal_forces {
            if n >= mesh.num_nodes() || !f.is_finite() {
                return Err(InputError::new(
                    "nodal force",
                    format!("(node {n}, {f})"),
                    format!("node < {} and finite force", mesh.num_nodes()),
                ));
            }
        }
        let rule = GaussRule::try_new(settings.gauss_points)?;
        let k = mesh.element.nodes_per_element();
        let mut gauss = GaussPoints::default();
        for e in 0..mesh.num_elements() {
            let x = mesh.element_coordinates(e);
            for (&xi, &w) in rule.points().iter().zip(rule.weights()) {
                let (pos, jac) = mesh.element.map(&x[..k], xi);
                gauss.push(e, xi, pos, w * jac, density);
            }
        }
        gauss.initialise_material(model.as_ref());
        let fixed_dofs = fixed.iter().map(|&n| (n, 0)).collect();
        Ok(Self {
            mesh0: mesh.clone(),
            mesh,
            gauss,
            fixed,
            loads,
            settings,
            rule,
            core: UlCore::new(model, fixed_dofs),
        })
    }

    /// The constitutive model.
    pub fn model(&self) -> &dyn ConstitutiveModel {
        self.core.model.as_ref()
    }

    /// The Gauss rule on [−1, 1].
    pub fn rule(&self) -> &GaussRule {
        &self.rule
    }

    /// Make the analysis dynamic ([`crate::solver::dynamics`]): the load steps become Newmark time
    /// steps over `newmark.duration`, from the nodal velocities `velocity` (one per node; the
    /// fixed nodes' are taken as zero) and zero acceleration.
    pub fn set_dynamics(&mut self, newmark: Newmark, velocity: Vec<f64>) -> Result<(), InputError> {
        newmark.validate()?;
        if velocity.len() != self.mesh.num_nodes() || velocity.iter().any(|v| !v.is_finite()) {
            return Err(InputError::new(
                "initial velocity",
                format!("{} values", velocity.len()),
                format!("one finite value per node ({})", self.mesh.num_nodes()),
            ));
        }
        self.core.start_dynamics(newmark, velocity, None);
        Ok(())
    }

    /// Nodal velocities of the committed state (dynamic analyses; empty otherwise).
    pub fn velocity(&self) -> &[f64] {
        &self.core.motion.velocity
    }

    /// Time of the committed state (0 for quasi-static analyses).
    pub fn time(&self) -> f64 {
        self.core.motion.time
    }

    /// Fill the support table: for each Gauss point its element's nodes, N_a(ξ_q) and
    /// ∂N_a/∂X̃ = (dX̃/dξ)⁻¹ dN_a/dξ on the current mesh (eqs 33–34).
    pub fn build_supports(&mut self) -> Result<(), StepFailure> {
        self.mesh
            .fill_supports(&self.gauss.element, &self.gauss.xi, &mut self.core.work.table)
    }

    /// Supports of the last [`Self::build_supports`].
    pub fn supports(&self) -> &SupportTable<1> {
        &self.core.work.table
    }

    /// Set up the nonlinear system of a load step at `load_factor` on the current mesh and
    /// committed states (supports, dof map, sparsity pattern, external force) and hand it to
    /// `f`. [`Self::step`] runs Newton on it; tests use it to probe residual and tangent.
    pub fn with_step_system<R>(
        &mut self,
        load_factor: f64,
        f: impl FnOnce(&mut LoadStepSystem<'_, 1>) -> R,
    ) -> Result<R, StepFailure> {
        let gravity = SVector::<f64, 1>::new(self.loads.gravity);
        fem_step_system(
            &mut self.core,
            &self.mesh,
            &self.gauss,
            gravity,
            &self.loads.nodal_forces,
            load_factor,
            f,
        )
    }

    /// Current position x(ξ_q) and Jacobian dx/dξ of Gauss point `p` on the current mesh.
    pub fn gauss_point_map(&self, p: usize) -> (f64, f64) {
        let k = self.mesh.element.nodes_per_element();
        let x = self.mesh.element_coordinates(self.gauss.element[p]);
        self.mesh.element.map(&x[..k], self.gauss.xi[p])
    }

    /// Displacement of node `n` since the start of the analysis.
    pub fn displacement(&self, n: usize) -> f64 {
        self.mesh.nodes[n] - self.mesh0.nodes[n]
    }
}

impl LoadStepping for LineFem {
    fn advance(&mut self, load_factor: f64) -> Result<Increment, FailedAttempt> {
        fem_advance(
            &mut self.core,
            &mut self.mesh,
            &mut self.gauss,
            SVector::<f64, 1>::new(self.loads.gravity),
            &self.loads.nodal_forces,
            &self.settings.newton,
            load_factor,
        )
    }
    fn set_steps_done(&mut self, n: usize) {
        self.core.step = n;
    }
    fn newton_settings(&self) -> &NewtonSettings {
        &self.settings.newton
    }
    fn steps_done(&self) -> usize {
        self.core.step
    }
    fn load_steps(&self) -> usize {
        self.settings.load_steps
    }
}
