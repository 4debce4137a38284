//! One load (or time) step of the material point solver: prepare it (supports, ghost term,
//! forces, weak-node constraints, the grid's motion), solve it with Newton on the step
//! workspace, commit it ([`LoadStepping`]).

use super::MpmSolver;
use crate::discretise::assembly::{StartForces, StepInput, StepWorkspace};
use crate::solver::dynamics::{Inertia, TimeStep};
use crate::solver::error::{FailedAttempt, StepFailure};
use crate::solver::load_stepping::{Increment, LoadStepping};
use crate::solver::newton::NewtonSettings;
use nalgebra::SVector;

/// What one load step of the material point solver assembles from: the point forces at its
/// load factor and the constraints of its weak nodes.
struct PreparedStep<const D: usize> {
    forces: Vec<SVector<f64, D>>,
    fixed: Vec<(usize, usize)>,
    ties: Vec<(usize, usize)>,
    /// The step's increments of the prescribed dofs.
    prescribed: Vec<(usize, f64)>,
    /// The step's penalties of the points bound to a displacement.
    penalties: Vec<crate::discretise::point_penalty::PointPenalty>,
    weak_nodes: usize,
    /// The time step of a dynamic analysis.
    time_step: Option<TimeStep>,
    /// Generalised-α: the point forces at the step's start.
    start_forces: Option<Vec<SVector<f64, D>>>,
}

impl<const D: usize> MpmSolver<D> {
    /// The [`StepInput`] of a prepared step, borrowing the model side of the solver.
    fn step_input<'a>(&'a self, step: &'a PreparedStep<D>) -> StepInput<'a, D> {
        StepInput {
            model: self.model.as_ref(),
            states: &self.points.state,
            num_nodes: self.grid.num_nodes(),
            fixed: &step.fixed,
            ties: &step.ties,
            prescribed: &step.prescribed,
            point_penalties: &step.penalties,
            point_forces: &step.forces,
            nodal_forces: &[],
            ghost: self.settings.ghost.is_on().then_some(&self.ghost),
            inertia: step.time_step.map(|t| Inertia {
                step: t.newmark,
                predictor: &self.nodal.predictor,
                acceleration: &self.nodal.acceleration,
                mass: self.settings.dynamics.map(|d| d.mass).unwrap_or_default(),
                point_masses: &self.points.mass,
            }),
            start_forces: step.start_forces.as_deref().map(|f| StartForces {
                point_forces: f,
                nodal_forces: &[],
            }),
        }
    }

    /// `f` on the step workspace with the step's input. The workspace is moved out for the
    /// call (its buffers move, nothing is allocated) so that the input borrows the model side
    /// of the solver while the workspace is written: the model and the per-step storage are
    /// owned apart.
    fn with_workspace<R>(
        &mut self,
        step: &PreparedStep<D>,
        f: impl FnOnce(&mut StepWorkspace<D>, &StepInput<'_, D>) -> R,
    ) -> R {
        let mut work = std::mem::take(&mut self.work);
        let out = f(&mut work, &self.step_input(step));
        self.work = work;
        out
    }

    /// Weights, ghost term, forces and constraints of a step at `load_factor` (of a dynamic
    /// analysis: to time `load_factor` × duration, the forces at that time, the grid's motion
    /// projected and the Newmark predictor formed).
    fn prepare_step(&mut self, load_factor: f64) -> Result<PreparedStep<D>, StepFailure> {
        self.build_supports()?;
        self.build_ghost();
        let time_step = self.settings.dynamics.map(|d| d.step_to(self.time, load_factor));
        let mut forces = self.external_point_forces(time_step.map_or(load_factor, |t| t.load_factor));
        if let Some(b) = &self.body_force {
            let t = time_step.map_or(load_factor, |t| t.end);
            b.add_to(&self.points.position0, &self.points.volume0, t, &mut forces)?;
        }
        let start_forces = match (self.settings.dynamics, &time_step) {
            (Some(d), Some(t)) if !t.newmark.is_newmark() => {
                let mut f = self.external_point_forces(d.load.factor(self.time));
                if let Some(b) = &self.body_force {
                    b.add_to(&self.points.position0, &self.points.volume0, self.time, &mut f)?;
                }
                Some(f)
            }
            _ => None,
        };
        let (weak, ties) = self.weak_nodes();
        let mut fixed = self.fixed.clone();
        let tied: Vec<usize> = ties.iter().map(|t| t.0).collect();
        fixed.extend(
            weak.iter()
                .filter(|n| !tied.contains(n))
                .flat_map(|&n| (0..D).map(move |a| (n, a))),
        );
        if let Some(t) = &time_step {
            self.project_motion(&t.newmark, &fixed);
        }
        let mut prescribed = vec![];
        self.prescribed.increments(load_factor, &mut prescribed);
        let mut penalties = vec![];
        self.point_penalties(load_factor, &mut penalties);
        Ok(PreparedStep {
            forces,
            fixed,
            ties,
            prescribed,
            penalties,
            weak_nodes: weak.len(),
            time_step,
            start_forces,
        })
    }

    /// With F-bar on, also give each cell's points the cell's mean pressure
    /// ([`crate::discretise::assembly`]'s pressure projection, reference/README.md item 75).
    pub fn set_pressure_projection(&mut self, on: bool) {
        self.work.f_bar.project_pressure = on;
    }

    /// The nonlinear system of the next load step at `load_factor` (unknowns: the nodal
    /// displacement increment from the committed state), for evaluations outside Newton, e.g.
    /// the residual of a prescribed field. Nothing is committed.
    pub fn with_step_system<R>(
        &mut self,
        load_factor: f64,
        f: impl FnOnce(&mut crate::discretise::assembly::LoadStepSystem<'_, D>) -> R,
    ) -> Result<R, StepFailure> {
        let step = self.prepare_step(load_factor)?;
        Ok(self.with_workspace(&step, |work, input| work.with_system(input, f)))
    }
}

impl<const D: usize> LoadStepping for MpmSolver<D> {
    fn advance(&mut self, load_factor: f64) -> Result<Increment, FailedAttempt> {
        if let Some(r) = &self.strength_reduction {
            self.model = r.model_at(load_factor);
        }
        let step = self.prepare_step(load_factor).map_err(FailedAttempt::from)?;
        if self.settings.linear_solver == crate::solver::linear::LinearSolver::Iterative
            && self.work.node_geometry.is_none()
        {
            self.work.node_geometry = Some(crate::solver::multigrid::NodeGeometry::of_grid(&self.grid));
        }
        self.work.matrix.set_solver(self.settings.linear_solver);
        let before = self.work.matrix.stats().iterations;
        let newton = self.settings.newton;
        let report = self.with_workspace(&step, |work, input| work.solve(input, &newton))?;
        let linear = self.work.linear_record(before);
        self.commit(step.time_step.map(|t| t.newmark))
            .map_err(|failure| FailedAttempt {
                failure,
                residuals: report.residuals.clone(),
            })?;
        if let Some(t) = step.time_step {
            self.time = t.end;
        }
        self.prescribed.commit(load_factor);
        self.commit_bound_reactions(load_factor);
        Ok(Increment {
            newton: report,
            weak_nodes: step.weak_nodes,
            linear,
        })
    }
    fn steps_done(&self) -> usize {
        self.step
    }
    fn set_steps_done(&mut self, n: usize) {
        self.step = n;
    }
    fn load_steps(&self) -> usize {
        self.settings.load_steps
    }
    fn newton_settings(&self) -> &NewtonSettings {
        &self.settings.newton
    }
}
