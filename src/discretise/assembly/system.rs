//! One load step's nonlinear system: residual and tangent over the points (eqs 27, 29), the
//! inertia term of a dynamic step and the residual norms Newton tests (eqs 22–23).

use super::forces::mass_times;
use super::kernel::{point_equations, PointKernel, MAX_POINT_EQS};
use super::local::spatial_gradients;
use super::reactions::LinearisedReactions;
use crate::discretise::dofs::{DofMap, SupportTable, MAX_POINT_NODES};
use crate::discretise::ghost::GhostOperator;
use crate::discretise::point_penalty::{self, PointPenalty};
use crate::material::constitutive::ConstitutiveModel;
use crate::material::kinematics::{evaluate_point, PointState, PointTrial};
use crate::solver::dynamics::{Inertia, MassMatrix};
use crate::solver::error::StepFailure;
use crate::solver::linear::SparseSystem;
use crate::solver::newton::{NonlinearSystem, ResidualNorm};
use nalgebra::SVector;
use rayon::prelude::*;

/// One load step's nonlinear system over a set of integration points.
pub struct LoadStepSystem<'a, const D: usize> {
    /// The material's constitutive model.
    pub model: &'a dyn ConstitutiveModel,
    /// Each point's committed state at the start of the step.
    pub states: &'a [PointState],
    /// Each point's nodes, weights and gradients on the step's start configuration.
    pub table: &'a SupportTable<D>,
    /// The equation number of each nodal dof.
    pub dofs: &'a DofMap,
    /// External force in equation order.
    pub f_ext: &'a [f64],
    /// The tangent K of eq (22) (eq 27 plus any ghost and inertia terms) with its linear solver.
    pub matrix: &'a mut SparseSystem,
    /// Per-point trial results at the last evaluation (committed by the caller on convergence).
    pub trials: &'a mut Vec<Option<PointTrial<D>>>,
    /// Nodal displacement increment at the last evaluation.
    pub du_nodal: &'a mut Vec<f64>,
    /// Ghost penalty of the step (material point solvers), if on.
    pub ghost: Option<&'a GhostOperator<D>>,
    /// Internal force at the dofs without an equation (fixed ones: the support reactions
    /// plus the external force there), indexed by nodal dof, at the last evaluation.
    pub fixed_forces: &'a mut Vec<f64>,
    /// The step's increments of prescribed dofs (dof, Δu): every evaluation imposes them.
    pub prescribed: &'a [(usize, f64)],
    /// Linearised reaction update ([`ResidualNorm::Linearised`]); `None`: not tracked.
    pub linearised: Option<&'a mut LinearisedReactions>,
    /// The inertia term M a₁(Δu) of a dynamic step ([`crate::solver::dynamics`]); `None`: static.
    pub inertia: Option<Inertia<'a>>,
    /// The scale of the convergence test of a dynamic step; `None` (static): f_ext.
    pub dynamic_reference: Option<DynamicReference<'a>>,
    /// The F-bar treatment ([`super::fbar`]); `None`: off.
    pub f_bar: Option<super::fbar::FBar<'a>>,
    /// Displacements bound to points by a penalty ([`crate::discretise::point_penalty`]).
    pub point_penalties: &'a [PointPenalty],
}

/// What normalises the residual of a dynamic step: √(‖f_ext + M ã‖² + ‖M a₀‖²) over the free
/// dofs. f_ext + M ã is the effective load that drives the increment (the residual at Δu = 0
/// is f_int(u₀) − f_ext − M ã) and M a₀ the inertia force the step starts with. Either alone
/// vanishes at instants of a motion: f_ext of a free vibration always, and of a manufactured
/// body force at a(t) = 0 (where the static normalisation by ‖f_ext‖ made the relative residual
/// 1e19); f_ext + M ã where 4v₀/Δt + a₀ = 0 (β = 1/4), where the vibrating bar's steps
/// stalled at their round-off floor and were cut back, changing Δt (reference/README item 48).
/// a₀ and ã = 4v₀/Δt + a₀ vanish together only at rest, where the scale is ‖f_ext‖ as in a
/// static step.
#[derive(Debug, Clone, Copy)]
pub struct DynamicReference<'a> {
    /// f_ext + M ã in equation order.
    pub effective_load: &'a [f64],
    /// ‖M a₀‖ over the free dofs.
    pub start_inertia: f64,
}

impl<const D: usize> LoadStepSystem<'_, D> {
    /// Evaluate all points at the nodal increment and assemble the internal force (in
    /// equation order).
    pub fn assemble_residual(&mut self, f_int: &mut [f64]) -> Result<(), StepFailure> {
        crate::solver::profile::timed(crate::solver::profile::Phase::Constitutive, || {
            self.assemble_residual_untimed(f_int)
        })
    }

    fn assemble_residual_untimed(&mut self, f_int: &mut [f64]) -> Result<(), StepFailure> {
        let model = self.model;
        let table = self.table;
        let du = &*self.du_nodal;
        if let Some(f) = self.f_bar.as_mut() {
            f.average(table, self.states, du)
                .map_err(|(point, reason)| StepFailure::Kinematics { point, reason })?;
        }
        let f_bar = self.f_bar.as_ref();
        self.trials.resize(self.states.len(), None);
        let first_error = self
            .trials
            .par_iter_mut()
            .zip(self.states.par_iter())
            .enumerate()
            .map(|(p, (slot, state))| {
                let grad = table.gradient(p, du);
                // F-bar: the constitutive update sees ΔF̄ = s ΔF; the gradients ∂S/∂x keep
                // the actual ΔF⁻¹ = s ΔF̄⁻¹.
                let s = f_bar.map_or(1.0, |f| f.scale(p));
                match evaluate_point::<D>(model, state, &super::fbar::scaled_gradient(&grad, s)) {
                    Ok(mut t) => {
                        if s != 1.0 {
                            t.delta_f_inv *= s;
                        }
                        *slot = Some(t);
                        None
                    }
                    Err(e) => {
                        *slot = None;
                        Some((p, e.to_string()))
                    }
                }
            })
            .reduce(
                || None,
                |a, b| match (a, b) {
                    (Some(x), Some(y)) => Some(if x.0 <= y.0 { x } else { y }),
                    (x, None) => x,
                    (None, y) => y,
                },
            );
        if let Some((point, reason)) = first_error {
            return Err(StepFailure::Kinematics { point, reason });
        }
        if let Some(f) = self.f_bar.as_ref() {
            f.project(self.states, self.trials);
        }
        f_int.iter_mut().for_each(|v| *v = 0.0);
        self.fixed_forces.clear();
        self.fixed_forces.resize(self.dofs.num_dofs(), 0.0);
        let mut gx = [SVector::<f64, D>::zeros(); MAX_POINT_NODES];
        let mut eqs = [None; MAX_POINT_EQS];
        for p in 0..self.states.len() {
            let t = self.trials[p].as_ref().expect("evaluated");
            let m = spatial_gradients(self.table, p, t, &mut gx);
            point_equations(self.table, self.dofs, p, &mut eqs);
            let v = t.volume;
            let sigma = t.sigma();
            let nodes = self.table.point(p).0;
            for k in 0..m {
                for i in 0..D {
                    let s: f64 = (0..D).map(|j| sigma[(i, j)] * gx[k][j]).sum();
                    match eqs[k * D + i] {
                        Some(e) => f_int[e] += s * v, // eq (29)
                        None => self.fixed_forces[nodes[k] * D + i] += s * v,
                    }
                }
            }
        }
        if let Some(g) = self.ghost {
            g.add_residual(self.dofs, self.du_nodal, f_int, Some(self.fixed_forces));
        }
        point_penalty::add_residual(
            self.point_penalties,
            self.table,
            self.dofs,
            self.du_nodal,
            f_int,
            self.fixed_forces,
        );
        if let Some(inertia) = self.inertia {
            self.add_inertia_residual(&inertia, f_int);
        }
        Ok(())
    }

    /// f += M a₁ with a₁ = Δu/(βΔt²) − ã per nodal dof (generalised-α: M (c_m a₁ + c_a a₀),
    /// [`crate::solver::dynamics::GeneralizedAlpha`]): consistent, Σ_p m_p S_ap (Σ_b S_bp a₁_b); lumped,
    /// (Σ_p m_p S_ap) a₁_a. Fixed dofs take theirs into the reactions.
    fn add_inertia_residual(&mut self, inertia: &Inertia<'_>, f_int: &mut [f64]) {
        let (du, dofs, fixed) = (&*self.du_nodal, self.dofs, &mut *self.fixed_forces);
        mass_times(
            self.table,
            inertia,
            |dof| {
                inertia
                    .step
                    .inertia_acceleration(du[dof], inertia.predictor[dof], inertia.acceleration[dof])
            },
            |dof, f| match dofs.eq(dof) {
                Some(e) => f_int[e] += f,
                None => fixed[dof] += f,
            },
        );
    }

    /// The out-of-balance left at the fixed dofs by the linearised reaction update, at `u`.
    fn update_fixed_out_of_balance(&mut self, u: &[f64]) {
        if let Some(lin) = self.linearised.as_deref_mut() {
            lin.update(u, self.fixed_forces, self.dofs, self.ghost);
        }
    }

    /// Assemble the tangent `K = Σ_p [G]ᵀ[a][G] V_p` (eq 27) at the trial states of the last
    /// [`Self::assemble_residual`].
    ///
    /// Points are processed in chunks: their local matrices are formed in parallel into a
    /// buffer reused across chunks, then scattered in parallel by column blocks, each block
    /// owned by one thread and filled in point order. Every entry thus receives its
    /// contributions in the same order whatever the thread count.
    pub fn assemble_tangent(&mut self) {
        crate::solver::profile::timed(crate::solver::profile::Phase::Assembly, || {
            self.assemble_tangent_untimed()
        });
    }

    fn assemble_tangent_untimed(&mut self) {
        self.matrix.clear_values();
        if let Some(lin) = self.linearised.as_deref_mut() {
            lin.start_tangent(self.fixed_forces);
        }
        let n = self.states.len();
        if let Some(f) = self.f_bar.as_mut() {
            f.form_q(self.model, self.states, self.trials);
        }
        let f_bar = self.f_bar.as_ref().map(|f| f.view());
        #[cfg(feature = "seeded-bugs")]
        let inertia = self
            .inertia
            .filter(|_| !crate::seeded::active(crate::seeded::Bug::NoMassInTangent));
        #[cfg(not(feature = "seeded-bugs"))]
        let inertia = self.inertia;
        let kernel = PointKernel {
            table: self.table,
            dofs: self.dofs,
            model: self.model,
            states: self.states,
            trials: self.trials,
            inertia,
            f_bar,
        };
        let runs = kernel.runs(n);
        // Each thread owns a block of columns and walks every run in point order, forming the
        // blocks of the runs that reach its columns (a run straddling two blocks is formed by
        // both) and adding them at once: no buffer of every point's block (4.6 KB a 3D point,
        // written and read again at memory speed), and every entry sums the same terms in the
        // same order whatever the thread count.
        let threads = rayon::current_num_threads();
        let runs = &runs;
        self.matrix
            .column_blocks(threads)
            .into_par_iter()
            .for_each(|mut block| {
                kernel.add_runs(&mut block, runs);
                if let Some(f) = &f_bar {
                    super::fbar::add_patches(f, self.table, self.trials, self.states, &mut block);
                }
            });
        if let Some(lin) = self.linearised.as_deref_mut() {
            kernel.linearised_rows(n, lin.rows_mut());
            if let Some(f) = &f_bar {
                super::fbar::linearised_rows(f, self.table, self.trials, self.states, lin.rows_mut());
            }
        }
        if let Some(g) = self.ghost {
            g.add_tangent(self.dofs, self.matrix);
        }
        point_penalty::add_tangent(self.point_penalties, self.table, self.dofs, self.matrix);
        if let Some(i) = inertia.filter(|i| i.mass == MassMatrix::Lumped) {
            // α m_a on the diagonal, m_a = Σ_p m_p S_ap.
            for p in 0..n {
                let (nodes, s, _) = self.table.point(p);
                for (&node, &w) in nodes.iter().zip(s) {
                    for a in 0..D {
                        if let Some(e) = self.dofs.eq(node * D + a) {
                            self.matrix
                                .add(e, e, i.step.tangent_mass_factor() * i.point_masses[p] * w);
                        }
                    }
                }
            }
        }
    }
}

impl<const D: usize> NonlinearSystem for LoadStepSystem<'_, D> {
    fn num_unknowns(&self) -> usize {
        self.dofs.len()
    }
    fn evaluate(&mut self, u: &[f64], residual: &mut [f64]) -> Result<(), StepFailure> {
        self.du_nodal.resize(self.dofs.num_dofs(), 0.0);
        self.dofs.expand(u, self.du_nodal);
        // Prescribed dofs have no equation, so `expand` left them at 0; a dof in two groups
        // takes both increments.
        for &(dof, du) in self.prescribed {
            self.du_nodal[dof] += du;
        }
        self.assemble_residual(residual)?;
        for (r, f) in residual.iter_mut().zip(self.f_ext) {
            *r -= f;
        }
        self.update_fixed_out_of_balance(u);
        Ok(())
    }
    fn fixed_out_of_balance_sq(&self) -> f64 {
        self.linearised
            .as_deref()
            .map_or(0.0, LinearisedReactions::out_of_balance_sq)
    }
    fn set_linear_tolerance(&mut self, relative: f64) {
        self.matrix.set_tolerance(relative);
    }
    fn solve_tangent(&mut self, rhs: &mut [f64]) -> Result<(), StepFailure> {
        self.assemble_tangent();
        self.matrix.solve_in_place(rhs).map_err(StepFailure::LinearSolve)
    }
    fn reference_norm(&self, norm: ResidualNorm) -> f64 {
        let (load, inertia) = match self.dynamic_reference {
            Some(d) => (d.effective_load, d.start_inertia),
            None => (self.f_ext, 0.0),
        };
        let ext: f64 = load.iter().map(|x| x * x).sum::<f64>() + inertia * inertia;
        match norm {
            ResidualNorm::External if inertia == 0.0 => crate::solver::norms::l2(load),
            ResidualNorm::External => crate::solver::norms::l2(&[crate::solver::norms::l2(load), inertia]),
            // ‖f_ext + f_reaction‖ over all dofs: f_ext at the free dofs and, at the fixed
            // ones, f_ext + reaction = f_int of the last evaluation.
            ResidualNorm::Total => {
                let sq = ext + self.fixed_forces.iter().map(|x| x * x).sum::<f64>();
                if sq.is_normal() {
                    sq.sqrt()
                } else {
                    crate::solver::norms::l2_of(&[load, self.fixed_forces, &[inertia]])
                }
            }
            // f_ext + f_rct at the fixed dofs = f_int + f^ob there.
            ResidualNorm::Linearised => {
                let fixed: f64 = match self.linearised.as_deref() {
                    Some(l) => l.reactions_sq(self.fixed_forces),
                    None => self.fixed_forces.iter().map(|x| x * x).sum(),
                };
                (ext + fixed).sqrt()
            }
        }
    }
}
