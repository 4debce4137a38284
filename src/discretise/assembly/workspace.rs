//! The per-step storage of a discretisation and the step's entry points: build the system
//! (dofs, pattern, external force) and run Newton on it.

use super::forces::{map_point_forces, mass_times};
use super::pattern::PatternKey;
use super::reactions::LinearisedReactions;
use super::system::{DynamicReference, LoadStepSystem};
use crate::discretise::dofs::{DofMap, SupportTable};
use crate::discretise::ghost::GhostOperator;
use crate::material::constitutive::ConstitutiveModel;
use crate::material::kinematics::{PointState, PointTrial};
use crate::solver::dynamics::Inertia;
use crate::solver::error::{FailedAttempt, StepFailure};
use crate::solver::linear::SparseSystem;
use crate::solver::newton::{self, NewtonReport, NewtonSettings, NonlinearSystem, ResidualNorm};
use nalgebra::SVector;

/// Per-step storage of a discretisation, reused from step to step so that the hot loops do
/// not allocate: the supports, the sparse tangent, the trial point states and the nodal
/// increment. Material point and finite element solvers fill [`StepWorkspace::table`] with
/// their weights or shape functions and then share everything else.
#[derive(Debug, Default)]
pub struct StepWorkspace<const D: usize> {
    /// Each point's nodes, weights and gradients for the step, filled by the solver before it.
    pub table: SupportTable<D>,
    /// The sparse tangent with its pattern and linear solver.
    pub matrix: SparseSystem,
    /// Each point's trial state at the last evaluation (`None`: not evaluated, or it failed).
    pub trials: Vec<Option<PointTrial<D>>>,
    /// Nodal displacement increment Δu at the last evaluation (dof = node·D + axis).
    pub du_nodal: Vec<f64>,
    /// Internal force at the fixed dofs at the last evaluation (see [`LoadStepSystem`]).
    pub fixed_forces: Vec<f64>,
    /// The step's external force at every nodal dof (dof = node·D + axis).
    pub external_nodal: Vec<f64>,
    /// Linearised reactions ([`ResidualNorm::Linearised`]).
    pub linearised: LinearisedReactions,
    /// Where the nodes sit, for an iterative solver's multigrid
    /// ([`crate::solver::linear::LinearSolver::Iterative`]); set by the solver before each step.
    pub node_geometry: Option<crate::solver::multigrid::NodeGeometry>,
    /// The connectivity never changes (FEM): the sparsity pattern, its symbolic factorisation
    /// and the equations' geometry are built at the first step and kept, as long as the
    /// number of equations stays the same.
    pub fixed_pattern: bool,
    /// What the current pattern was built from, to keep it for a step whose points still
    /// touch the same nodes ([`PatternKey`]).
    pub(crate) pattern_key: PatternKey,
    /// F-bar's volume patches, filled by the solver before each step; `None`: F-bar off
    /// ([`super::fbar`]).
    pub patches: Option<crate::discretise::patches::VolumePatches>,
    /// F-bar's per-step storage.
    pub f_bar: super::fbar::FBarScratch,
    /// The last converged increment, for Newton's extrapolated start.
    pub(crate) extrapolation: super::predictor::ExtrapolatedStart<D>,
}

/// What a load step applies, besides the material model and the committed states.
pub struct StepInput<'a, const D: usize> {
    /// The material's constitutive model.
    pub model: &'a dyn ConstitutiveModel,
    /// Each point's committed state at the start of the step.
    pub states: &'a [PointState],
    /// Number of nodes of the grid or mesh.
    pub num_nodes: usize,
    /// Homogeneous Dirichlet conditions (node, axis).
    pub fixed: &'a [(usize, usize)],
    /// Nodes tied to a master node (slave, master): u_slave = u_master.
    pub ties: &'a [(usize, usize)],
    /// The step's increments of prescribed dofs (dof = node·D + axis, Δu), each also in
    /// `fixed` ([`crate::discretise::prescribed`]).
    pub prescribed: &'a [(usize, f64)],
    /// Force carried by each point (body force × mass, point loads), mapped with the weights (eq 40).
    pub point_forces: &'a [SVector<f64, D>],
    /// Forces applied directly to nodal dofs (dof = node·D + axis).
    pub nodal_forces: &'a [(usize, f64)],
    /// Ghost penalty of the step, built on the same grid ([`crate::discretise::ghost`]).
    pub ghost: Option<&'a GhostOperator<D>>,
    /// Displacements bound to points by a penalty ([`crate::discretise::point_penalty`]).
    pub point_penalties: &'a [crate::discretise::point_penalty::PointPenalty],
    /// The inertia term of a dynamic step; `None`: quasi-static.
    pub inertia: Option<Inertia<'a>>,
    /// Generalised-α only: the point and nodal forces at the step's start t₀, for its term
    /// c_f (f_int(u₀) − f_ext(t₀)) ([`crate::solver::dynamics::GeneralizedAlpha`]); `None`: Newmark.
    pub start_forces: Option<StartForces<'a, D>>,
}

/// The external forces at the start of a step, as [`StepInput`] gives those at its end.
#[derive(Debug, Clone, Copy)]
pub struct StartForces<'a, const D: usize> {
    /// Force carried by each point at t₀.
    pub point_forces: &'a [SVector<f64, D>],
    /// Forces applied directly to nodal dofs at t₀ (dof = node·D + axis).
    pub nodal_forces: &'a [(usize, f64)],
}

/// f_ext of `point_forces` (mapped with the weights, eq 40) and `nodal_forces`, gathered in
/// equation order.
fn external_force<const D: usize>(
    table: &SupportTable<D>,
    dofs: &DofMap,
    point_forces: &[SVector<f64, D>],
    nodal_forces: &[(usize, f64)],
    nodal: &mut Vec<f64>,
) -> Vec<f64> {
    nodal.clear();
    nodal.resize(dofs.num_dofs(), 0.0);
    map_point_forces(table, point_forces, nodal);
    for &(dof, force) in nodal_forces {
        nodal[dof] += force;
    }
    let mut f_ext = vec![0.0; dofs.len()];
    dofs.gather_forces(nodal, &mut f_ext);
    f_ext
}

impl<const D: usize> StepWorkspace<D> {
    /// From the filled [`Self::table`]: the dof map, sparsity pattern (and so a fresh symbolic
    /// factorisation, unless [`Self::fixed_pattern`] keeps the first step's) and external
    /// force of one load step; the resulting system is handed to `f`.
    pub fn with_system<R>(
        &mut self,
        input: &StepInput<'_, D>,
        f: impl FnOnce(&mut LoadStepSystem<'_, D>) -> R,
    ) -> R {
        self.with_system_tracking(input, false, f)
    }

    /// [`Self::with_system`], tracking the linearised reactions if `track`.
    fn with_system_tracking<R>(
        &mut self,
        input: &StepInput<'_, D>,
        track: bool,
        f: impl FnOnce(&mut LoadStepSystem<'_, D>) -> R,
    ) -> R {
        let start = std::time::Instant::now();
        let dofs = DofMap::build(input.num_nodes, &self.table, input.fixed, input.ties);
        // FEM: the connectivity never changes. Material points: they still touch the nodes
        // they touched when the pattern was built.
        let kept = self.matrix.nnz() > 0
            && self.matrix.dim() == dofs.len()
            && (self.fixed_pattern
                || self
                    .pattern_key
                    .matches(&dofs, &self.table, input.ghost, self.patches.as_ref()));
        if kept {
            self.matrix.clear_values();
            if !self.fixed_pattern {
                // As a fresh pattern would, minus the work: the step's first CG solve still
                // builds its multigrid from the step's own tangent, so results are those of a
                // rebuilt pattern to the bit. The equations' geometry is unchanged with them.
                self.matrix.forget_preconditioner();
            }
        } else {
            let mut columns = dofs.pattern(&self.table);
            if let Some(g) = input.ghost {
                g.add_pattern(&dofs, &mut columns);
            }
            if let Some(p) = &self.patches {
                p.add_pattern(&dofs, &self.table, &mut columns);
            }
            self.matrix.set_pattern(columns);
            if !self.fixed_pattern {
                self.pattern_key
                    .record(&dofs, &self.table, input.ghost, self.patches.as_ref());
            }
            if self.matrix.solver() == crate::solver::linear::LinearSolver::Iterative {
                if let Some(g) = &self.node_geometry {
                    self.matrix
                        .set_geometry(crate::solver::multigrid::DofGeometry::of_equations(g, &dofs));
                }
            }
        }
        crate::solver::profile::charge(crate::solver::profile::Phase::Setup, start);
        let mut f_ext = external_force(
            &self.table,
            &dofs,
            input.point_forces,
            input.nodal_forces,
            &mut self.external_nodal,
        );
        if let (Some(i), Some(start)) = (input.inertia, input.start_forces) {
            let weight = i.step.start_force_weight();
            if weight != 0.0 {
                // f_ext(t₁) − c_f (f_int(u₀) − f_ext(t₀)): f_int(u₀) is the internal force at a
                // zero increment (the committed stresses on this step's grid or mesh).
                let f_ext0 = external_force(
                    &self.table,
                    &dofs,
                    start.point_forces,
                    start.nodal_forces,
                    &mut Vec::new(),
                );
                let mut f_int0 = vec![0.0; dofs.len()];
                self.du_nodal.clear();
                self.du_nodal.resize(dofs.num_dofs(), 0.0);
                let mut at_rest = LoadStepSystem {
                    model: input.model,
                    states: input.states,
                    table: &self.table,
                    dofs: &dofs,
                    f_ext: &f_ext0,
                    matrix: &mut self.matrix,
                    trials: &mut self.trials,
                    du_nodal: &mut self.du_nodal,
                    ghost: input.ghost,
                    fixed_forces: &mut self.fixed_forces,
                    prescribed: &[],
                    linearised: None,
                    inertia: None,
                    dynamic_reference: None,
                    // At no increment every ΔJ is 1 and F-bar changes nothing.
                    f_bar: None,
                    // Refused with dynamics ([`crate::mpm::MpmSolver::bind_points`]).
                    point_penalties: &[],
                };
                if at_rest.assemble_residual(&mut f_int0).is_ok() {
                    for ((f, fi), fe) in f_ext.iter_mut().zip(&f_int0).zip(&f_ext0) {
                        *f -= weight * (fi - fe);
                    }
                } else {
                    // The committed states evaluated at no increment cannot fail unless they
                    // are already invalid; Newton's first evaluation reports that failure.
                    f_ext.iter_mut().for_each(|f| *f = f64::NAN);
                }
            }
        }
        let reference = input.inertia.map(|i| {
            let mut load = f_ext.clone();
            let mut start = vec![0.0; dofs.len()];
            mass_times(
                &self.table,
                &i,
                |dof| i.step.inertia_predictor(i.predictor[dof], i.acceleration[dof]),
                |dof, f| {
                    if let Some(e) = dofs.eq(dof) {
                        load[e] += f;
                    }
                },
            );
            mass_times(
                &self.table,
                &i,
                |dof| i.acceleration[dof],
                |dof, f| {
                    if let Some(e) = dofs.eq(dof) {
                        start[e] += f;
                    }
                },
            );
            (load, crate::solver::norms::l2(&start))
        });
        let mut system = LoadStepSystem {
            model: input.model,
            states: input.states,
            table: &self.table,
            dofs: &dofs,
            f_ext: &f_ext,
            matrix: &mut self.matrix,
            trials: &mut self.trials,
            du_nodal: &mut self.du_nodal,
            ghost: input.ghost,
            fixed_forces: &mut self.fixed_forces,
            prescribed: input.prescribed,
            linearised: track.then_some(&mut self.linearised),
            inertia: input.inertia,
            dynamic_reference: reference.as_ref().map(|(load, start)| DynamicReference {
                effective_load: load,
                start_inertia: *start,
            }),
            f_bar: self
                .patches
                .as_ref()
                .map(|patches| super::fbar::FBar::new(patches, &mut self.f_bar, &self.table, &dofs)),
            point_penalties: input.point_penalties,
        };
        f(&mut system)
    }

    /// Newton on one load step from a zero increment. On success [`Self::trials`] and
    /// [`Self::du_nodal`] hold the converged state for the caller to commit.
    pub fn solve(
        &mut self,
        input: &StepInput<'_, D>,
        settings: &NewtonSettings,
    ) -> Result<NewtonReport, FailedAttempt> {
        self.linearised.clear();
        let track = settings.residual_norm == ResidualNorm::Linearised;
        let extrapolate = settings.predictor == newton::Predictor::Extrapolated && input.inertia.is_none();
        let start = std::mem::take(&mut self.extrapolation);
        let drive = super::predictor::Drive {
            prescribed: input.prescribed,
            point_penalties: input.point_penalties,
            point_forces: input.point_forces,
            nodal_forces: input.nodal_forces,
        };
        let out = self.with_system_tracking(input, track, |system| {
            let mut u = vec![0.0; system.num_unknowns()];
            if extrapolate && start.fill(drive, system.dofs, &mut u) {
                // A failure from the extrapolated start (or a start that cannot be evaluated:
                // it inverts a point) asks the load stepping to try the same increment again,
                // from zero, before it cuts it: a run then takes the zero start's path
                // wherever extrapolation fails (reference/README.md item 82).
                return newton::solve(system, &mut u, settings).map_err(|f| FailedAttempt {
                    failure: StepFailure::Extrapolated(Box::new(f.failure)),
                    residuals: f.residuals,
                });
            }
            newton::solve(system, &mut u, settings)
        });
        self.extrapolation = start;
        match (&out, extrapolate) {
            (Ok(_), true) => self.extrapolation.record(drive, &self.du_nodal),
            (Err(_), true) => self.extrapolation.failed(),
            _ => {}
        }
        out
    }

    /// The size of the last step's system and the Krylov iterations (CG and GMRES) since `iterations_before`
    /// (the matrix's count before the step's solves).
    pub fn linear_record(&self, iterations_before: usize) -> crate::solver::load_stepping::LinearRecord {
        crate::solver::load_stepping::LinearRecord {
            unknowns: self.matrix.dim(),
            nonzeros: self.matrix.nnz(),
            // A CG run's factor (of a fallback) is not its linear system's cost.
            factor_nonzeros: match self.matrix.solver() {
                crate::solver::linear::LinearSolver::Iterative => 0,
                _ => self.matrix.stats().factor_nnz,
            },
            iterations: self.matrix.stats().iterations - iterations_before,
        }
    }

    /// The reaction at fixed dof `dof` (node·D + axis) of the last evaluation: the force the
    /// support exerts on the body, f_int − f_ext there (inertia and ghost terms included in
    /// f_int). Meaningful at fixed and prescribed dofs only; 0 before any step.
    pub fn reaction(&self, dof: usize) -> f64 {
        self.fixed_forces.get(dof).copied().unwrap_or(0.0)
            - self.external_nodal.get(dof).copied().unwrap_or(0.0)
    }

    /// Replace each point's state (the step's start) by the converged step's.
    pub fn commit_states(&self, states: &mut [PointState]) {
        for (state, t) in states.iter_mut().zip(&self.trials) {
            *state = t.as_ref().expect("converged trial").committed(state);
        }
    }
}
