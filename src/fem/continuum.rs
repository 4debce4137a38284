//! Updated-Lagrangian FEM on tensor-product elements in 2D and 3D ([`ContinuumFem`]): the
//! plane-strain comparator of the 2D examples ([`PlaneFem`]: §5.2 compaction with Q4 and 2×2
//! Gauss points, §5.3 cantilever with Q8 and 3×3; plane strain comes from the shared
//! kinematics, which keep F₃₃ = 1) and the solid comparator of the 3D examples
//! ([`SolidFem`]: Hex8 with 2×2×2, Hex20 with 3×3×3). One generic solver, so the two differ
//! only in their element tables.

use super::hex::HexElement;
use super::mesh::{ElementFamily, ElementMesh};
use super::quad::QuadElement;
use super::updated_lagrangian::{
    fem_advance, fem_step_system, validate_stepping, FemMesh, GaussPoints, UlCore,
};
use crate::discretise::assembly::{LoadStepSystem, SupportTable};
use crate::material::constitutive::ConstitutiveModel;
use crate::solver::dynamics::{BodyForce, Newmark};
use crate::solver::error::{require_finite, FailedAttempt, InputError, StepFailure};
use crate::solver::linear::LinearSolver;
use crate::solver::load_stepping::{Increment, LoadStepping};
use crate::solver::newton::NewtonSettings;
use nalgebra::{Matrix3, SVector};
use serde::{Deserialize, Serialize};

/// Settings of a [`ContinuumFem`] analysis (plane or solid).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneFemSettings {
    /// Gauss points per axis of the tensor rule, 1..=5; `None` for the element's default
    /// (2 for Q4 and Hex8, 3 for Q8 and Hex20).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gauss_points: Option<usize>,
    /// Newton iteration settings of each load step.
    pub newton: NewtonSettings,
    /// Number of equal load increments.
    pub load_steps: usize,
    /// Sparse factorisation of the tangent; the symmetric ones suit elastic and associative
    /// von Mises problems (the tangent is symmetric) and fall back to LU on failure.
    #[serde(default)]
    pub linear_solver: LinearSolver,
    /// F-bar: each Gauss point's volume change replaced by its element's average
    /// ([`crate::discretise::assembly::FBar`]); off by default (reference/README.md item 69).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub f_bar: bool,
}

impl Default for PlaneFemSettings {
    fn default() -> Self {
        Self {
            gauss_points: None,
            newton: NewtonSettings::default(),
            load_steps: 1,
            linear_solver: LinearSolver::Auto,
            f_bar: false,
        }
    }
}

impl PlaneFemSettings {
    /// Check the Gauss rule (if given), the Newton settings and the number of load steps.
    pub fn validate(&self) -> Result<(), InputError> {
        if let Some(n) = self.gauss_points {
            crate::mesh::quadrature::GaussRule::try_new(n)?;
        }
        validate_stepping(&self.newton, self.load_steps)
    }
}

/// Dead loads at the end of the analysis, applied proportionally over the load steps.
#[derive(Debug, Clone, PartialEq)]
pub struct FemLoads<const D: usize> {
    /// Body force per unit mass (gravitational acceleration), carried by the Gauss point
    /// masses and mapped to the nodes with N (eq 40).
    pub gravity: SVector<f64, D>,
    /// Point forces on nodes: (node, force). Fixed in direction (dead loads).
    pub nodal_forces: Vec<(usize, SVector<f64, D>)>,
}

impl<const D: usize> Default for FemLoads<D> {
    fn default() -> Self {
        Self {
            gravity: SVector::zeros(),
            nodal_forces: vec![],
        }
    }
}

/// Loads of a plane-strain analysis (per unit thickness).
pub type PlaneLoads = FemLoads<2>;
/// Loads of a 3D analysis.
pub type SolidLoads = FemLoads<3>;
/// Plane-strain FEM on quadrilaterals.
pub type PlaneFem = ContinuumFem<2, QuadElement>;
/// 3D FEM on hexahedra.
pub type SolidFem = ContinuumFem<3, HexElement>;

/// Implicit updated-Lagrangian FEM on a mesh of one element family (plane strain in 2D).
///
/// Each Gauss point is an integration point of the shared assembly: every load step fills the
/// support table with N_a(ξ_q) and ∂N_a/∂X̃ = J⁻ᵀ ∂N_a/∂ξ on the current (start-of-step)
/// mesh, J = ∂X̃/∂ξ (eqs 33–34); kinematics, constitutive update, assembly and Newton are
/// those of the material point solver. The Gauss point volume is the committed
/// `PointState::volume` (w_q det J₀ times det ΔF at each commit, eq 28), equal to
/// w_q det J on the current mesh (tested). Thickness is one: masses are per unit thickness
/// (ρ0 w_q det J₀) and forces are per unit thickness; in 3D they are absolute.
pub struct ContinuumFem<const D: usize, E> {
    /// Initial mesh.
    pub mesh0: ElementMesh<D, E>,
    /// Current mesh (nodes moved with the material).
    pub mesh: ElementMesh<D, E>,
    /// The Gauss points with their committed states.
    pub gauss: GaussPoints<SVector<f64, D>>,
    /// Nodal dofs with zero displacement: (node, axis).
    pub fixed: Vec<(usize, usize)>,
    /// Loads at the end of the analysis.
    pub loads: FemLoads<D>,
    /// Gauss rule, Newton, load-stepping and linear solver settings.
    pub settings: PlaneFemSettings,
    /// `loads.nodal_forces` as (dof, force) pairs.
    dof_forces: Vec<(usize, f64)>,
    core: UlCore<D>,
}

impl<const D: usize, E: ElementFamily<D>> ContinuumFem<D, E> {
    /// A solver on `mesh` with density `density` (mass per unit initial volume; in 2D per
    /// unit area and unit thickness).
    pub fn try_new(
        mesh: ElementMesh<D, E>,
        density: f64,
        model: Box<dyn ConstitutiveModel>,
        fixed: Vec<(usize, usize)>,
        loads: FemLoads<D>,
        settings: PlaneFemSettings,
    ) -> Result<Self, InputError> {
        settings.validate()?;
        crate::solver::error::require_positive("density", density)?;
        for a in 0..D {
            require_finite(&format!("gravity[{a}]"), loads.gravity[a])?;
        }
        let nn = mesh.num_nodes();
        for &(n, a) in &fixed {
            if n >= nn || a >= D {
                return Err(InputError::new(
                    "fixed dof",
                    format!("(node {n}, axis {a})"),
                    format!("node < {nn} and axis < {D}"),
                ));
            }
        }
        let mut dof_forces = Vec::with_capacity(D * loads.nodal_forces.len());
        for &(n, f) in &loads.nodal_forces {
            if n >= nn || !f.iter().all(|v| v.is_finite()) {
                return Err(InputError::new(
                    "nodal force",
                    format!("(node {n}, {:?})", f.as_slice()),
                    format!("node < {nn} and finite force"),
                ));
            }
            dof_forces.extend((0..D).map(|a| (D * n + a, f[a])));
        }
        let points = crate::mesh::quadrature::tensor_rule::<D>(
            settings
                .gauss_points
                .unwrap_or(mesh.element.default_gauss_points()),
        )?;
        let mut gauss = GaussPoints::default();
        gauss.reserve(mesh.num_elements() * points.len());
        for e in 0..mesh.num_elements() {
            for (xi, w) in &points {
                let (pos, jac) = mesh.map(e, xi);
                gauss.push(e, *xi, pos, w * super::mesh::det_inverse(&jac).0, density);
            }
        }
        gauss.initialise_material(model.as_ref());
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

    /// Make the analysis dynamic ([`crate::solver::dynamics`]): the load steps become Newmark time
    /// steps over `newmark.duration`, from the nodal velocities `velocity` and accelerations
    /// `acceleration` (one vector per node, `None`: zero; the fixed dofs' are taken as zero) at
    /// t = 0. The acceleration must balance the loads at t = 0 (M a₀ = f_ext(0) − f_int): a
    /// wrong a₀ leaves an O(Δt) velocity error that costs the trapezoidal rule its order.
    pub fn set_dynamics(
        &mut self,
        newmark: Newmark,
        velocity: &[SVector<f64, D>],
        acceleration: Option<&[SVector<f64, D>]>,
    ) -> Result<(), InputError> {
        newmark.validate()?;
        if newmark.mass == crate::solver::dynamics::MassMatrix::Lumped {
            self.check_lumped_masses()?;
        }
        let nn = self.mesh.num_nodes();
        let flat = |key: &str, v: &[SVector<f64, D>]| {
            if v.len() != nn || v.iter().any(|v| v.iter().any(|x| !x.is_finite())) {
                return Err(InputError::new(
                    key,
                    format!("{} vectors", v.len()),
                    format!("one finite vector per node ({nn})"),
                ));
            }
            Ok(v.iter().flat_map(|v| v.iter().copied()).collect::<Vec<f64>>())
        };
        let v = flat("initial velocity", velocity)?;
        let a = acceleration
            .map(|a| flat("initial acceleration", a))
            .transpose()?;
        self.core.start_dynamics(newmark, v, a);
        Ok(())
    }

    /// Row-sum lumping Σ_q N_a(ξ_q) m_q must give every node of every element a positive mass:
    /// it does for Q4 and Hex8, but the serendipity Q8 and Hex20 get negative corner masses
    /// (−1/12 and −1/9 of an undistorted element's mass), which make the lumped mass matrix
    /// indefinite and the analysis unstable (measured: Q8 on the dynamic manufactured vortex
    /// inverted an element at the second step).
    fn check_lumped_masses(&self) -> Result<(), InputError> {
        let g = &self.gauss;
        let mut lumped = vec![0.0; self.mesh.element.nodes_per_element()];
        // The Gauss points are stored element by element ([`Self::try_new`]): one pass, each
        // element's row sums checked when its last point is added.
        for q in 0..g.len() {
            let e = g.element[q];
            let (n, _) = self.mesh.element.shape(&g.xi[q]);
            for (m, n) in lumped.iter_mut().zip(n) {
                *m += n * g.mass[q];
            }
            if g.element.get(q + 1) == Some(&e) {
                continue;
            }
            if let Some(a) = lumped.iter().position(|&m| m <= 0.0) {
                return Err(InputError::new(
                    "dynamics.mass",
                    "lumped",
                    format!(
                        "must be consistent for this element: row-sum lumping gives local node {a} of element {e} the mass {:.3e} <= 0 (serendipity Q8/Hex20 corners)",
                        lumped[a]
                    ),
                ));
            }
            lumped.iter_mut().for_each(|m| *m = 0.0);
        }
        Ok(())
    }

    /// Let the nodal forces follow `ramp` over the load steps instead of growing linearly.
    pub fn set_nodal_force_ramp(&mut self, ramp: crate::solver::ramp::Ramp) {
        self.core.nodal_ramp = ramp;
    }

    /// Divide the model's strength by the reduction's factor at each increment's load factor
    /// (the model becomes the reduction's material, rebuilt before every increment).
    pub fn set_strength_reduction(
        &mut self,
        reduction: Option<crate::material::strength_reduction::StrengthReduction>,
    ) {
        self.core.strength_reduction = reduction;
    }

    /// Load the Gauss points with a body force per unit reference volume b₀(X, t) besides
    /// `loads`: b₀(X_q, t) V_q0 at each Gauss point, mapped with N_a (the consistent nodal
    /// force of the element's quadrature), t the end time of each step (the load factor in a
    /// quasi-static analysis).
    pub fn set_body_force(&mut self, body_force: BodyForce<D>) {
        self.core.body_force = Some((
            body_force,
            self.gauss.position0.clone(),
            self.gauss.volume0.clone(),
        ));
    }

    /// Nodal velocities of the committed state (node·D + axis; dynamic analyses, empty
    /// otherwise).
    pub fn velocity(&self) -> &[f64] {
        &self.core.motion.velocity
    }

    /// Time of the committed state (0 for quasi-static analyses).
    pub fn time(&self) -> f64 {
        self.core.motion.time
    }

    /// Fill the support table: for each Gauss point its element's nodes, N_a(ξ_q) and
    /// ∂N_a/∂X̃ = J⁻ᵀ ∂N_a/∂ξ on the current mesh (eqs 33–34).
    pub fn build_supports(&mut self) -> Result<(), StepFailure> {
        self.mesh
            .fill_supports(&self.gauss.element, &self.gauss.xi, &mut self.core.work.table)
    }

    /// Supports of the last [`Self::build_supports`].
    pub fn supports(&self) -> &SupportTable<D> {
        &self.core.work.table
    }

    /// With F-bar on, also give each element's Gauss points the element's mean pressure
    /// (reference/README.md item 75).
    pub fn set_pressure_projection(&mut self, on: bool) {
        self.core.work.f_bar.project_pressure = on;
    }

    /// Set up the nonlinear system of a load step at `load_factor` on the current mesh and
    /// committed states and hand it to `f` (tests probe residual and tangent through it).
    pub fn with_step_system<R>(
        &mut self,
        load_factor: f64,
        f: impl FnOnce(&mut LoadStepSystem<'_, D>) -> R,
    ) -> Result<R, StepFailure> {
        self.sync_f_bar();
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

    /// Prescribe the displacement of nodal dofs (node, axis, value at full load), following
    /// `ramp` over the load steps: the dofs lose their equations (they join `fixed`) and every
    /// step imposes its increment ([`crate::discretise::prescribed`]).
    pub fn prescribe(
        &mut self,
        dofs: &[(usize, usize, f64)],
        ramp: crate::solver::ramp::Ramp,
    ) -> Result<(), InputError> {
        self.core
            .prescribed
            .add_checked::<D>(dofs, self.mesh.num_nodes(), ramp)?;
        for &(n, a, _) in dofs {
            self.fixed.push((n, a));
            self.core.fixed_dofs.push((n, a));
        }
        Ok(())
    }

    /// The reaction at a fixed or prescribed dof of the last converged step: the force the
    /// support exerts on the body along `axis` at `node` ([`crate::discretise::assembly::StepWorkspace::reaction`]).
    pub fn reaction(&self, node: usize, axis: usize) -> f64 {
        self.core.work.reaction(node * D + axis)
    }

    /// Displacement of node `n` since the start of the analysis.
    pub fn displacement(&self, n: usize) -> SVector<f64, D> {
        self.mesh.nodes[n] - self.mesh0.nodes[n]
    }

    /// Displacements of all nodes since the start of the analysis.
    pub fn displacements(&self) -> Vec<SVector<f64, D>> {
        (0..self.mesh.num_nodes()).map(|n| self.displacement(n)).collect()
    }

    /// Current position x(ξ_q) of Gauss point `p`.
    pub fn gauss_point_position(&self, p: usize) -> SVector<f64, D> {
        self.mesh.map(self.gauss.element[p], &self.gauss.xi[p]).0
    }

    /// Cauchy stress σ at Gauss point `p` (3×3; in 2D σ₃₃ is the out-of-plane stress).
    pub fn cauchy_stress(&self, p: usize) -> Matrix3<f64> {
        self.gauss.state[p].cauchy()
    }

    /// Deformation gradient F at Gauss point `p` (F₃₃ = 1 in 2D).
    pub fn deformation_gradient(&self, p: usize) -> Matrix3<f64> {
        self.gauss.state[p].f
    }

    /// Current volume of Gauss point `p` (area per unit thickness in 2D).
    pub fn volume(&self, p: usize) -> f64 {
        self.gauss.state[p].volume
    }

    /// How many linear solves fell back from the symmetric factorisation to LU.
    pub fn linear_solver_fallbacks(&self) -> usize {
        self.core.work.matrix.fallbacks()
    }

    /// What the linear solves have cost so far (solves, Krylov iterations, seconds).
    pub fn linear_stats(&self) -> crate::solver::linear::LinearStats {
        self.core.work.matrix.stats()
    }

    /// Unknowns and non-zeros of the last tangent.
    pub fn system_size(&self) -> (usize, usize) {
        (self.core.work.matrix.dim(), self.core.work.matrix.nnz())
    }

    /// F-bar's patches (each element's Gauss points) as [`PlaneFemSettings::f_bar`] asks.
    fn sync_f_bar(&mut self) {
        let work = &mut self.core.work;
        if self.settings.f_bar != work.patches.is_some() {
            work.patches = self.settings.f_bar.then(|| {
                let mut patches = crate::discretise::patches::VolumePatches::default();
                patches.set(self.gauss.element.iter().copied());
                patches
            });
        }
    }
}

impl<const D: usize, E: ElementFamily<D>> LoadStepping for ContinuumFem<D, E> {
    fn advance(&mut self, load_factor: f64) -> Result<Increment, FailedAttempt> {
        // The multigrid coarsens the initial (structured) mesh: its nodes nest in the coarse
        // grids, which the deformed ones need not.
        if self.settings.linear_solver == LinearSolver::Iterative && self.core.work.node_geometry.is_none() {
            self.core.work.node_geometry = Some(crate::solver::multigrid::NodeGeometry::of_mesh(&self.mesh0));
        }
        if let Some(r) = &self.core.strength_reduction {
            self.core.model = r.model_at(load_factor);
        }
        self.sync_f_bar();
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
