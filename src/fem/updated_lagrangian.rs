//! What the updated-Lagrangian FEM solvers share whatever their element: Gauss point storage,
//! the validation of load-step settings, and one load step (loads scaled by the load factor,
//! Newton on the shared [`StepWorkspace`], commit of the Gauss point states and of the node
//! positions). A solver adds only its shape functions: it fills the [`SupportTable`] with
//! N_a(ξ_q) and ∂N_a/∂X̃ on the start-of-step mesh and moves its nodes by the increment.

use crate::discretise::assembly::{LoadStepSystem, StartForces, StepInput, StepWorkspace, SupportTable};
use crate::material::constitutive::ConstitutiveModel;
use crate::material::kinematics::PointState;
use crate::solver::dynamics::{BodyForce, Inertia, Newmark, TimeStep};
use crate::solver::error::{require_count, FailedAttempt, InputError, StepFailure};
use crate::solver::load_stepping::Increment;
use crate::solver::newton::NewtonSettings;
use nalgebra::SVector;

pub use crate::solver::load_stepping::MAX_LOAD_STEPS;

/// Check the Newton settings and the number of load steps (1..=[`MAX_LOAD_STEPS`]).
pub fn validate_stepping(newton: &NewtonSettings, load_steps: usize) -> Result<(), InputError> {
    newton.validate()?;
    require_count("load_steps", load_steps, 1)?;
    if load_steps > MAX_LOAD_STEPS {
        return Err(InputError::new(
            "load_steps",
            load_steps,
            format!("must be <= {MAX_LOAD_STEPS}"),
        ));
    }
    Ok(())
}

/// The Gauss points of a FEM solver, element by element (point `p = e * n_q + q`). `X` is
/// the type of a local coordinate and of a position: `f64` for line elements,
/// `SVector<f64, 2>` for plane elements.
#[derive(Debug, Clone)]
pub struct GaussPoints<X = f64> {
    /// Element of each point.
    pub element: Vec<usize>,
    /// Local coordinate ξ_q.
    pub xi: Vec<X>,
    /// Initial position X(ξ_q).
    pub position0: Vec<X>,
    /// Initial volume w_q det(∂X/∂ξ)|₀ (a length in 1D, an area per unit thickness in 2D).
    pub volume0: Vec<f64>,
    /// Mass ρ0 w_q det(∂X/∂ξ)|₀.
    pub mass: Vec<f64>,
    /// Committed F, volume and constitutive state.
    pub state: Vec<PointState>,
}

impl<X> Default for GaussPoints<X> {
    fn default() -> Self {
        Self {
            element: vec![],
            xi: vec![],
            position0: vec![],
            volume0: vec![],
            mass: vec![],
            state: vec![],
        }
    }
}

impl<X> GaussPoints<X> {
    /// Number of Gauss points.
    pub fn len(&self) -> usize {
        self.xi.len()
    }
    /// True if there are no Gauss points.
    pub fn is_empty(&self) -> bool {
        self.xi.is_empty()
    }
    /// Append an undeformed point of element `e` at ξ with initial position and volume.
    pub fn push(&mut self, e: usize, xi: X, position0: X, volume0: f64, density: f64) {
        self.element.push(e);
        self.xi.push(xi);
        self.position0.push(position0);
        self.volume0.push(volume0);
        self.mass.push(density * volume0);
        self.state.push(PointState::undeformed(volume0));
    }
    /// Give every point that holds no internal variables `model`'s initial ones
    /// ([`crate::material::constitutive::MaterialState::initialise`]).
    pub fn initialise_material(&mut self, model: &dyn ConstitutiveModel) {
        for s in &mut self.state {
            s.material.initialise(model);
        }
    }
    /// Reserve room for `n` more points.
    pub fn reserve(&mut self, n: usize) {
        self.element.reserve(n);
        self.xi.reserve(n);
        self.position0.reserve(n);
        self.volume0.reserve(n);
        self.mass.reserve(n);
        self.state.reserve(n);
    }
}

/// Loads at the end of the analysis in the form one step needs: gravity (body force per unit
/// mass) carried by the Gauss point masses, and forces on nodal dofs (dof = node·D + axis).
pub(crate) struct FullLoads<'a, const D: usize> {
    pub gravity: SVector<f64, D>,
    pub mass: &'a [f64],
    pub dof_forces: &'a [(usize, f64)],
}

/// The load-step state of a FEM solver: model, Dirichlet dofs, steps done and the per-step
/// workspace.
pub(crate) struct UlCore<const D: usize> {
    pub model: Box<dyn ConstitutiveModel>,
    /// Nodal dofs without an equation, as (node, axis): fixed at zero, or prescribed.
    pub fixed_dofs: Vec<(usize, usize)>,
    /// Prescribed displacements (their dofs are in `fixed_dofs`) and the step's increments.
    pub prescribed: crate::discretise::prescribed::PrescribedDisplacements,
    prescribed_step: Vec<(usize, f64)>,
    pub step: usize,
    pub work: StepWorkspace<D>,
    /// Newmark time integration ([`crate::solver::dynamics`]); `None`: quasi-static.
    pub dynamics: Option<Newmark>,
    pub motion: NodalState,
    /// A body force b₀(X, t) and the Gauss points' reference positions X_q and volumes V_q0 it
    /// is applied at (b₀(X_q, t) V_q0 mapped with N_a: the consistent nodal force).
    pub body_force: Option<(BodyForce<D>, Vec<SVector<f64, D>>, Vec<f64>)>,
    /// The ramp of the nodal forces (linear by default; a table from 1 at load factor 0 holds
    /// them at full value from the first step, [`crate::material::prestress`]).
    pub nodal_ramp: crate::solver::ramp::Ramp,
    /// The strength reduction `model` follows: rebuilt before every increment (none: fixed).
    pub strength_reduction: Option<crate::material::strength_reduction::StrengthReduction>,
}

/// The nodes' velocity and acceleration (node·D + axis) and the time of the committed state of
/// a dynamic analysis, and the Newmark step being solved with its predictor ã.
#[derive(Debug, Default)]
pub(crate) struct NodalState {
    pub time: f64,
    pub velocity: Vec<f64>,
    pub acceleration: Vec<f64>,
    predictor: Vec<f64>,
    pending: Option<TimeStep>,
}

impl<const D: usize> UlCore<D> {
    pub fn new(model: Box<dyn ConstitutiveModel>, fixed_dofs: Vec<(usize, usize)>) -> Self {
        Self {
            model,
            fixed_dofs,
            prescribed: Default::default(),
            prescribed_step: vec![],
            step: 0,
            work: StepWorkspace {
                fixed_pattern: true,
                ..StepWorkspace::default()
            },
            dynamics: None,
            motion: NodalState::default(),
            body_force: None,
            nodal_ramp: Default::default(),
            strength_reduction: None,
        }
    }

    /// Make the analysis dynamic from the nodal velocities `velocity` and accelerations
    /// `acceleration` (node·D + axis; `None`: zero; the fixed dofs' taken as zero) at time 0.
    pub fn start_dynamics(&mut self, newmark: Newmark, velocity: Vec<f64>, acceleration: Option<Vec<f64>>) {
        let m = &mut self.motion;
        m.acceleration = acceleration.unwrap_or_else(|| vec![0.0; velocity.len()]);
        m.velocity = velocity;
        for &(n, a) in &self.fixed_dofs {
            m.velocity[n * D + a] = 0.0;
            m.acceleration[n * D + a] = 0.0;
        }
        m.time = 0.0;
        self.dynamics = Some(newmark);
    }

    /// The time step to `load_factor` × duration and its predictor from the committed nodal
    /// velocity and acceleration (`None` for a static step); the load factor the loads take.
    fn prepare_motion(&mut self, load_factor: f64) -> f64 {
        let Some(d) = self.dynamics else {
            self.motion.pending = None;
            return load_factor;
        };
        let m = &mut self.motion;
        let t = d.step_to(m.time, load_factor);
        m.predictor.clear();
        m.predictor.extend(
            m.velocity
                .iter()
                .zip(&m.acceleration)
                .map(|(&v, &a)| t.newmark.predictor(v, a)),
        );
        m.pending = Some(t);
        t.load_factor
    }

    /// After a converged dynamic step: a₁ (N1), v₁ (N2) at every node, and the step's time.
    fn commit_motion(&mut self) {
        let m = &mut self.motion;
        let Some(t) = m.pending.take() else {
            return;
        };
        let (du, step) = (&self.work.du_nodal, t.newmark);
        for k in 0..m.velocity.len() {
            let a1 = step.acceleration_after(du[k], m.predictor[k]);
            m.velocity[k] += step.velocity_change(m.acceleration[k], a1);
            m.acceleration[k] = a1;
        }
        m.time = t.end;
    }

    /// Build the [`StepInput`] at `load_factor` (the supports must be in `work.table`) and
    /// hand it with the workspace to `f`; fails if the body force is not finite.
    pub fn with_input<R>(
        &mut self,
        states: &[PointState],
        num_nodes: usize,
        loads: &FullLoads<'_, D>,
        load_factor: f64,
        f: impl FnOnce(&mut StepWorkspace<D>, &StepInput<'_, D>) -> R,
    ) -> Result<R, StepFailure> {
        self.prescribed.increments(load_factor, &mut self.prescribed_step);
        let factor = self.prepare_motion(load_factor);
        // Dead loads: gravity m_q g mapped with N (eq 40) and nodal forces, both ∝ load factor.
        let mut forces: Vec<SVector<f64, D>> =
            loads.mass.iter().map(|&m| loads.gravity * (m * factor)).collect();
        if let Some((b, x0, v0)) = &self.body_force {
            let t = self.motion.pending.map_or(load_factor, |t| t.end);
            b.add_to(x0, v0, t, &mut forces)?;
        }
        let nodal_factor = self.nodal_ramp.applied(factor);
        let nodal: Vec<(usize, f64)> = loads
            .dof_forces
            .iter()
            .map(|&(dof, force)| (dof, force * nodal_factor))
            .collect();
        // Generalised-α: the same loads at the step's start t₀.
        let start = match (self.dynamics, self.motion.pending) {
            (Some(d), Some(t)) if !t.newmark.is_newmark() => {
                let (t0, f0) = (self.motion.time, d.load.factor(self.motion.time));
                let mut forces: Vec<SVector<f64, D>> =
                    loads.mass.iter().map(|&m| loads.gravity * (m * f0)).collect();
                if let Some((b, x0, v0)) = &self.body_force {
                    b.add_to(x0, v0, t0, &mut forces)?;
                }
                let nodal: Vec<(usize, f64)> = loads
                    .dof_forces
                    .iter()
                    .map(|&(dof, force)| (dof, force * self.nodal_ramp.applied(f0)))
                    .collect();
                Some((forces, nodal))
            }
            _ => None,
        };
        let input = StepInput {
            model: self.model.as_ref(),
            states,
            num_nodes,
            fixed: &self.fixed_dofs,
            ties: &[],
            prescribed: &self.prescribed_step,
            point_forces: &forces,
            nodal_forces: &nodal,
            ghost: None,
            point_penalties: &[],
            inertia: self.motion.pending.map(|t| Inertia {
                step: t.newmark,
                predictor: &self.motion.predictor,
                acceleration: &self.motion.acceleration,
                mass: self.dynamics.map(|d| d.mass).unwrap_or_default(),
                point_masses: loads.mass,
            }),
            start_forces: start.as_ref().map(|(f, n)| StartForces {
                point_forces: f,
                nodal_forces: n,
            }),
        };
        Ok(f(&mut self.work, &input))
    }

    /// Solve and commit one increment to the total load factor `load_factor` (the ramp of
    /// the material point solver). `build_supports` fills the support table on the
    /// start-of-step mesh; on convergence the Gauss point states are committed, and the
    /// caller moves its nodes by the converged increment `work.du_nodal` (node·D + axis). On
    /// failure nothing is committed.
    pub fn advance(
        &mut self,
        newton: &NewtonSettings,
        load_factor: f64,
        states: &mut [PointState],
        num_nodes: usize,
        loads: &FullLoads<'_, D>,
        build_supports: impl FnOnce(&mut SupportTable<D>) -> Result<(), StepFailure>,
    ) -> Result<Increment, FailedAttempt> {
        crate::solver::profile::timed(crate::solver::profile::Phase::Weights, || {
            build_supports(&mut self.work.table)
        })
        .map_err(FailedAttempt::from)?;
        let before = self.work.matrix.stats().iterations;
        let report = self
            .with_input(states, num_nodes, loads, load_factor, |work, input| {
                work.solve(input, newton)
            })
            .map_err(FailedAttempt::from)??;
        self.work.commit_states(states);
        self.commit_motion();
        self.prescribed.commit(load_factor);
        Ok(Increment {
            newton: report,
            weak_nodes: 0,
            linear: self.work.linear_record(before),
        })
    }
}

/// A finite element mesh as the load-step machinery sees it: nodes that move with the material
/// and shape functions evaluated at Gauss points on the current configuration.
pub trait FemMesh<const D: usize> {
    /// Local coordinate of a Gauss point in its element.
    type Local;
    /// Number of mesh nodes.
    fn num_nodes(&self) -> usize;
    /// Fill `table` with, for each Gauss point (element `elements[p]`, local coordinate
    /// `xis[p]`), its element's nodes, N_a(ξ_q) and ∂N_a/∂X̃ on the current mesh (eqs 33–34).
    /// Fails if an element is inverted at a Gauss point.
    fn fill_supports(
        &self,
        elements: &[usize],
        xis: &[Self::Local],
        table: &mut SupportTable<D>,
    ) -> Result<(), StepFailure>;
    /// Move the nodes by a nodal increment (dof = node·D + axis).
    fn move_nodes(&mut self, du: &[f64]);
}

/// One increment of an updated-Lagrangian FEM solver on `mesh` (the shared body of
/// `LoadStepping::advance`): supports on the start-of-step mesh, Newton, commit of the Gauss
/// point states, and the nodes moved by the converged increment, which makes the converged
/// configuration the next reference.
pub(crate) fn fem_advance<const D: usize, M: FemMesh<D>>(
    core: &mut UlCore<D>,
    mesh: &mut M,
    gauss: &mut GaussPoints<M::Local>,
    gravity: SVector<f64, D>,
    dof_forces: &[(usize, f64)],
    newton: &NewtonSettings,
    load_factor: f64,
) -> Result<Increment, FailedAttempt> {
    let loads = FullLoads {
        gravity,
        mass: &gauss.mass,
        dof_forces,
    };
    let (elements, xis) = (&gauss.element, &gauss.xi);
    let m: &M = mesh;
    let inc = core.advance(
        newton,
        load_factor,
        &mut gauss.state,
        m.num_nodes(),
        &loads,
        |table| m.fill_supports(elements, xis, table),
    )?;
    mesh.move_nodes(&core.work.du_nodal);
    Ok(inc)
}

/// The nonlinear system of a load step at `load_factor` on the current mesh and committed
/// states (supports, dof map, sparsity pattern, external force), handed to `f`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn fem_step_system<const D: usize, M: FemMesh<D>, R>(
    core: &mut UlCore<D>,
    mesh: &M,
    gauss: &GaussPoints<M::Local>,
    gravity: SVector<f64, D>,
    dof_forces: &[(usize, f64)],
    load_factor: f64,
    f: impl FnOnce(&mut LoadStepSystem<'_, D>) -> R,
) -> Result<R, StepFailure> {
    mesh.fill_supports(&gauss.element, &gauss.xi, &mut core.work.table)?;
    let loads = FullLoads {
        gravity,
        mass: &gauss.mass,
        dof_forces,
    };
    core.with_input(
        &gauss.state,
        mesh.num_nodes(),
        &loads,
        load_factor,
        |work, input| work.with_system(input, f),
    )
}
