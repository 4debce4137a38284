//! Plane-strain updated-Lagrangian FEM on quadrilaterals ([`PlaneFem`]): the comparator of
//! the 2D examples (§5.2 compaction with Q4 and 2×2 Gauss points, §5.3 cantilever with Q8
//! and 3×3). Plane strain comes from the shared kinematics, which keep F₃₃ = 1.

use super::quad::{PlaneMesh, QuadElement};
use super::updated_lagrangian::{
    fem_advance, fem_step_system, validate_stepping, FemMesh, GaussPoints, UlCore,
};
use crate::assembly::{LoadStepSystem, SupportTable};
use crate::constitutive::ConstitutiveModel;
use crate::error::{require_finite, InputError, StepFailure};
use crate::linear::LinearSolver;
use crate::load_stepping::{Increment, LoadStepping};
use crate::newton::NewtonSettings;
use nalgebra::{Matrix3, SVector};
use serde::{Deserialize, Serialize};

type V2 = SVector<f64, 2>;

/// Settings of a [`PlaneFem`] analysis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneFemSettings {
    /// Gauss points per axis of the n×n rule, 1..=5; `None` for the element's default
    /// (2 for Q4, 3 for Q8).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gauss_points: Option<usize>,
    pub newton: NewtonSettings,
    /// Number of equal load increments.
    pub load_steps: usize,
    /// Sparse factorisation of the tangent; the symmetric ones suit elastic and associative
    /// von Mises problems (the tangent is symmetric) and fall back to LU on failure.
    #[serde(default)]
    pub linear_solver: LinearSolver,
}

impl Default for PlaneFemSettings {
    fn default() -> Self {
        Self {
            gauss_points: None,
            newton: NewtonSettings::default(),
            load_steps: 1,
            linear_solver: LinearSolver::Lu,
        }
    }
}

impl PlaneFemSettings {
    pub fn validate(&self) -> Result<(), InputError> {
        if let Some(n) = self.gauss_points {
            crate::quadrature::GaussRule::try_new(n)?;
        }
        validate_stepping(&self.newton, self.load_steps)
    }
}

/// Dead loads at the end of the analysis, applied proportionally over the load steps.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlaneLoads {
    /// Body force per unit mass (gravitational acceleration), carried by the Gauss point
    /// masses and mapped to the nodes with N (eq 40).
    pub gravity: V2,
    /// Point forces on nodes: (node, force). Fixed in direction (dead loads).
    pub nodal_forces: Vec<(usize, V2)>,
}

/// Implicit updated-Lagrangian plane-strain FEM on a quadrilateral mesh.
///
/// Each Gauss point is an integration point of the shared assembly: every load step fills the
/// support table with N_a(ξ_q) and ∂N_a/∂X̃ = J⁻ᵀ ∂N_a/∂ξ on the current (start-of-step)
/// mesh, J = ∂X̃/∂ξ (eqs 33–34); kinematics, constitutive update, assembly and Newton are
/// those of the material point solver. The Gauss point volume is the committed
/// `PointState::volume` (w_q det J₀ times det ΔF at each commit, eq 28), equal to
/// w_q det J on the current mesh (tested). Thickness is one: masses are per unit thickness
/// (ρ0 w_q det J₀) and forces are per unit thickness.
pub struct PlaneFem {
    /// Initial mesh.
    pub mesh0: PlaneMesh,
    /// Current mesh (nodes moved with the material).
    pub mesh: PlaneMesh,
    pub gauss: GaussPoints<V2>,
    /// Nodal dofs with zero displacement: (node, axis).
    pub fixed: Vec<(usize, usize)>,
    pub loads: PlaneLoads,
    pub settings: PlaneFemSettings,
    /// `loads.nodal_forces` as (dof, force) pairs.
    dof_forces: Vec<(usize, f64)>,
    core: UlCore<2>,
}

impl PlaneFem {
    /// A solver on `mesh` with density `density` (mass per unit initial area and unit
    /// thickness).
    pub fn try_new(
        mesh: PlaneMesh,
        density: f64,
        model: Box<dyn ConstitutiveModel>,
        fixed: Vec<(usize, usize)>,
        loads: PlaneLoads,
        settings: PlaneFemSettings,
    ) -> Result<Self, InputError> {
        settings.validate()?;
        crate::error::require_positive("density", density)?;
        for a in 0..2 {
            require_finite(&format!("gravity[{a}]"), loads.gravity[a])?;
        }
        let nn = mesh.num_nodes();
        for &(n, a) in &fixed {
            if n >= nn || a >= 2 {
                return Err(InputError::new(
                    "fixed dof",
                    format!("(node {n}, axis {a})"),
                    format!("node < {nn} and axis < 2"),
                ));
            }
        }
        let mut dof_forces = Vec::with_capacity(2 * loads.nodal_forces.len());
        for &(n, f) in &loads.nodal_forces {
            if n >= nn || !f.iter().all(|v| v.is_finite()) {
                return Err(InputError::new(
                    "nodal force",
                    format!("(node {n}, {:?})", f.as_slice()),
                    format!("node < {nn} and finite force"),
                ));
            }
            dof_forces.extend([(2 * n, f[0]), (2 * n + 1, f[1])]);
        }
        let points = QuadElement::tensor_rule(
            settings
                .gauss_points
                .unwrap_or(mesh.element.default_gauss_points()),
        )?;
        let mut gauss = GaussPoints::default();
        gauss.reserve(mesh.num_elements() * points.len());
        for e in 0..mesh.num_elements() {
            for (xi, w) in &points {
                let (pos, jac) = mesh.map(e, xi);
                gauss.push(e, *xi, pos, w * jac.determinant(), density);
            }
        }
        let mut core = UlCore::new(model, fixed.clone());
        core.work.matrix.set_solver(settings.linear_solver);
        Ok(Self {
            mesh0: mesh.clone(),
            mesh,
            gauss,
            fixed,
            loads,
            settings,
            dof_forces,
            core,
        })
    }

    /// The constitutive model.
    pub fn model(&self) -> &dyn ConstitutiveModel {
        self.core.model.as_ref()
    }

    /// Fill the support table: for each Gauss point its element's nodes, N_a(ξ_q) and
    /// ∂N_a/∂X̃ = J⁻ᵀ ∂N_a/∂ξ on the current mesh (eqs 33–34).
    pub fn build_supports(&mut self) -> Result<(), StepFailure> {
        self.mesh
            .fill_supports(&self.gauss.element, &self.gauss.xi, &mut self.core.work.table)
    }

    /// Supports of the last [`Self::build_supports`].
    pub fn supports(&self) -> &SupportTable<2> {
        &self.core.work.table
    }

    /// Set up the nonlinear system of a load step at `load_factor` on the current mesh and
    /// committed states and hand it to `f` (tests probe residual and tangent through it).
    pub fn with_step_system<R>(
        &mut self,
        load_factor: f64,
        f: impl FnOnce(&mut LoadStepSystem<'_, 2>) -> R,
    ) -> Result<R, StepFailure> {
        fem_step_system(
            &mut self.core,
            &self.mesh,
            &self.gauss,
            self.loads.gravity,
            &self.dof_forces,
            load_factor,
            f,
        )
    }

    /// Displacement of node `n` since the start of the analysis.
    pub fn displacement(&self, n: usize) -> V2 {
        self.mesh.nodes[n] - self.mesh0.nodes[n]
    }

    /// Displacements of all nodes since the start of the analysis.
    pub fn displacements(&self) -> Vec<V2> {
        (0..self.mesh.num_nodes()).map(|n| self.displacement(n)).collect()
    }

    /// Current position x(ξ_q) of Gauss point `p`.
    pub fn gauss_point_position(&self, p: usize) -> V2 {
        self.mesh.map(self.gauss.element[p], &self.gauss.xi[p]).0
    }

    /// Cauchy stress σ at Gauss point `p` (3×3; σ₃₃ is the out-of-plane stress).
    pub fn cauchy_stress(&self, p: usize) -> Matrix3<f64> {
        self.gauss.state[p].cauchy()
    }

    /// Deformation gradient F at Gauss point `p` (F₃₃ = 1).
    pub fn deformation_gradient(&self, p: usize) -> Matrix3<f64> {
        self.gauss.state[p].f
    }

    /// Current volume (area per unit thickness) of Gauss point `p`.
    pub fn volume(&self, p: usize) -> f64 {
        self.gauss.state[p].volume
    }

    /// How many linear solves fell back from the symmetric factorisation to LU.
    pub fn linear_solver_fallbacks(&self) -> usize {
        self.core.work.matrix.fallbacks()
    }
}

impl LoadStepping for PlaneFem {
    fn advance(&mut self, load_factor: f64) -> Result<Increment, (StepFailure, Vec<f64>)> {
        fem_advance(
            &mut self.core,
            &mut self.mesh,
            &mut self.gauss,
            self.loads.gravity,
            &self.dof_forces,
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
