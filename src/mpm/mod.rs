//! The implicit material point solver: load-step loop, Newton solve and commit (Figures 6–7).

mod bound_points;
mod builder;
pub mod cell_fill;
mod motion;
pub mod particles;
mod settings;
mod step;

use crate::basis::{BasisError, BasisFamily, PointSupport};
use crate::discretise::assembly::{StepWorkspace, SupportTable};
use crate::discretise::ghost::{node_share, GhostOperator};
use crate::material::constitutive::ConstitutiveModel;
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::solver::dynamics::{BodyForce, NewmarkStep};
use crate::solver::error::{InputError, StepFailure};
use cell_fill::cell_fill;
use nalgebra::SVector;
use std::sync::Arc;

pub use crate::basis::DomainUpdate;

pub use crate::discretise::point_penalty::DEFAULT_POINT_PENALTY;
pub use crate::solver::load_stepping::MAX_LOAD_STEPS;
pub use builder::MpmBuilder;
pub use settings::{MpmSettings, VolumeUpdate, WeakNodeTreatment};

/// External loads at the end of the analysis, applied proportionally over the load steps.
#[derive(Debug, Clone)]
pub struct Loads<const D: usize> {
    /// Gravitational acceleration (body force per unit mass).
    pub gravity: SVector<f64, D>,
    /// Point loads carried by material points: (point, force).
    pub point_loads: Vec<(usize, SVector<f64, D>)>,
}

/// Implicit MPM / GIMP solver for `D` dimensions.
pub struct MpmSolver<const D: usize> {
    /// The background grid, the same at every step.
    pub grid: Grid<D>,
    /// The material points with their committed states.
    pub points: MaterialPoints<D>,
    model: Box<dyn ConstitutiveModel>,
    /// Homogeneous Dirichlet conditions: (node, axis).
    pub fixed: Vec<(usize, usize)>,
    /// Loads at the end of the analysis.
    pub loads: Loads<D>,
    /// Basis, Newton, load stepping, ghost penalty and the other solver settings.
    pub settings: MpmSettings,
    step: usize,
    work: StepWorkspace<D>,
    ghost: GhostOperator<D>,
    /// The basis family: `settings.basis`'s, or one given by [`Self::with_family`].
    family: Arc<dyn BasisFamily<D>>,
    /// Nodal velocity, acceleration and predictor of the current dynamic step.
    nodal: NodalMotion,
    /// Time of the committed state (dynamic analyses).
    time: f64,
    /// A body force b₀(X, t) beside `loads` ([`Self::set_body_force`]).
    body_force: Option<BodyForce<D>>,
    /// Prescribed nodal displacements ([`Self::prescribe`]).
    prescribed: crate::discretise::prescribed::PrescribedDisplacements,
    /// The ramp of `loads.point_loads` ([`Self::set_point_load_ramp`]); linear by default.
    point_load_ramp: crate::solver::ramp::Ramp,
    /// The strength reduction the model follows ([`Self::set_strength_reduction`]).
    strength_reduction: Option<crate::material::strength_reduction::StrengthReduction>,
    /// Displacements bound to points ([`Self::bind_points`]).
    bound: Vec<crate::discretise::point_penalty::BoundPoints<D>>,
}

/// The grid's motion at the start of a dynamic step, projected from the points, and the
/// step's Newmark predictor ã (a₁ = Δu/(βΔt²) − ã), per nodal dof.
#[derive(Debug, Default)]
struct NodalMotion {
    velocity: Vec<f64>,
    acceleration: Vec<f64>,
    predictor: Vec<f64>,
}

impl<const D: usize> MpmSolver<D> {
    /// A solver of `points` (at least one) on `grid` with the constitutive `model`, the
    /// Dirichlet dofs `fixed` (node, axis), `loads` and `settings`. Every point's domain must
    /// lie inside the grid and every fixed dof and point load must name an existing node or
    /// point.
    pub fn try_new(
        grid: Grid<D>,
        points: MaterialPoints<D>,
        model: Box<dyn ConstitutiveModel>,
        fixed: Vec<(usize, usize)>,
        loads: Loads<D>,
        settings: MpmSettings,
    ) -> Result<Self, InputError> {
        settings.validate()?;
        if points.is_empty() {
            return Err(InputError::new(
                "material points",
                0,
                "at least one point is required",
            ));
        }
        for p in 0..points.len() {
            if !grid.contains_box(&points.position[p], &points.half_length[p]) {
                return Err(InputError::new(
                    format!("material point {p}"),
                    format!("{:?}", points.position[p].as_slice()),
                    "point and its domain must lie inside the background grid",
                ));
            }
        }
        for &(n, a) in &fixed {
            if n >= grid.num_nodes() || a >= D {
                return Err(InputError::new(
                    "fixed dof",
                    format!("(node {n}, axis {a})"),
                    format!("node < {} and axis < {D}", grid.num_nodes()),
                ));
            }
        }
        for a in 0..D {
            crate::solver::error::require_finite(&format!("gravity[{a}]"), loads.gravity[a])?;
        }
        for (p, f) in &loads.point_loads {
            if *p >= points.len() || f.iter().any(|v| !v.is_finite()) {
                return Err(InputError::new(
                    "point load",
                    format!("(point {p}, {:?})", f.as_slice()),
                    format!("point < {} and finite force", points.len()),
                ));
            }
        }
        let family = settings.basis.shared::<D>();
        let mut points = points;
        points.initialise_material(model.as_ref());
        if family.needs_corners() {
            points.track_corners();
        }
        Ok(Self {
            grid,
            points,
            model,
            fixed,
            loads,
            settings,
            step: 0,
            work: StepWorkspace::default(),
            ghost: GhostOperator::default(),
            family,
            nodal: NodalMotion::default(),
            time: 0.0,
            body_force: None,
            prescribed: Default::default(),
            point_load_ramp: Default::default(),
            strength_reduction: None,
            bound: vec![],
        })
    }

    /// Renumber the material points cell by cell ([`MaterialPoints::sort_by_cell`]) and the
    /// point loads with them, between steps. The assembly then adds a cell's points as one
    /// run; results change at round-off only (sums over points in another order). Returns
    /// the permutation: new point `k` is old point `order[k]`.
    pub fn sort_points_by_cell(&mut self) -> Vec<usize> {
        let order = self.points.sort_by_cell(&self.grid);
        let mut new_index = vec![0; order.len()];
        for (k, &p) in order.iter().enumerate() {
            new_index[p] = k;
        }
        for (p, _) in self.loads.point_loads.iter_mut() {
            *p = new_index[*p];
        }
        self.renumber_bound(&new_index);
        order
    }

    /// Load the points with a body force per unit reference volume b₀(X, t) besides `loads`:
    /// b₀(X_p, t) V_p0 on each point, t the end time of each step (the load factor in a
    /// quasi-static analysis).
    pub fn set_body_force(&mut self, body_force: BodyForce<D>) {
        self.body_force = Some(body_force);
    }

    /// Let the point loads follow `ramp` over the load steps instead of growing linearly: a
    /// table from 1 at load factor 0 holds them at their full value from the first step
    /// (the loads that balance an initial stress, [`crate::material::prestress`]).
    pub fn set_point_load_ramp(&mut self, ramp: crate::solver::ramp::Ramp) {
        self.point_load_ramp = ramp;
    }

    /// Divide the model's strength by the reduction's factor at each increment's load factor
    /// (the model becomes the reduction's material, rebuilt before every increment).
    pub fn set_strength_reduction(
        &mut self,
        reduction: Option<crate::material::strength_reduction::StrengthReduction>,
    ) {
        self.strength_reduction = reduction;
    }

    /// Prescribe the displacement of grid dofs (node, axis, value at full load), following
    /// `ramp` over the load steps: the dofs join the fixed ones and every step moves them by
    /// their increment ([`crate::discretise::prescribed`]). The grid is reset every step, so a
    /// node prescribes the motion of whatever material its weights reach in that step: a
    /// platen on a row of nodes is exact only while the body's face lies on that row
    /// (reference/README.md item 66).
    pub fn prescribe(
        &mut self,
        dofs: &[(usize, usize, f64)],
        ramp: crate::solver::ramp::Ramp,
    ) -> Result<(), InputError> {
        self.prescribed
            .add_checked::<D>(dofs, self.grid.num_nodes(), ramp)?;
        self.fixed.extend(dofs.iter().map(|&(n, a, _)| (n, a)));
        Ok(())
    }

    /// The reaction at a fixed or prescribed dof of the last converged step: the force the
    /// support exerts on the body along `axis` at `node` ([`crate::discretise::assembly::StepWorkspace::reaction`]).
    pub fn reaction(&self, node: usize, axis: usize) -> f64 {
        self.work.reaction(node * D + axis)
    }

    /// The solver with a basis family of the caller's instead of `settings.basis`'s (e.g. one
    /// defined outside this crate against [`BasisFamily`]; `examples/custom_basis.rs`).
    /// `settings.basis` then only names the run.
    pub fn with_family(mut self, family: Arc<dyn BasisFamily<D>>) -> Self {
        if family.needs_corners() {
            self.points.track_corners();
        }
        self.family = family;
        self
    }

    /// The constitutive model.
    pub fn model(&self) -> &dyn ConstitutiveModel {
        self.model.as_ref()
    }

    /// The failure of a point whose weights cannot be formed at (x, h).
    fn basis_failure(p: usize, x: &SVector<f64, D>, h: &SVector<f64, D>, e: BasisError) -> StepFailure {
        match e {
            BasisError::DegenerateDomain { .. } | BasisError::InvertedDomain => StepFailure::Kinematics {
                point: p,
                reason: format!("{e} (half-lengths {:?})", h.as_slice()),
            },
            _ => StepFailure::LeftGrid {
                point: p,
                position: format!("{:?}: {e}", x.as_slice()),
            },
        }
    }

    /// Evaluate the weights of every point on the grid at the current positions and domains.
    pub fn build_supports(&mut self) -> Result<(), StepFailure> {
        crate::solver::profile::timed(crate::solver::profile::Phase::Weights, || {
            self.build_supports_untimed()
        })
    }

    /// The solver's basis family (shared, so that it can be used while the solver's fields are
    /// borrowed mutably).
    fn family(&self) -> Arc<dyn BasisFamily<D>> {
        Arc::clone(&self.family)
    }

    fn build_supports_untimed(&mut self) -> Result<(), StepFailure> {
        let family = self.family();
        self.work.table.clear();
        let mut sup = PointSupport::<D>::default();
        for p in 0..self.points.len() {
            family
                .evaluate(&self.grid, &self.points.view(p), &mut sup)
                .map_err(|e| {
                    Self::basis_failure(p, &self.points.position[p], &self.points.half_length[p], e)
                })?;
            for k in 0..sup.len() {
                let (node, s, g) = sup.node(k);
                self.work.table.push_node(node, s, g);
            }
            self.work.table.finish_point();
        }
        if self.settings.f_bar {
            let patches = self.work.patches.get_or_insert_with(Default::default);
            let grid = &self.grid;
            patches.set(self.points.position.iter().map(|x| grid.cell_holding(x)));
        } else {
            self.work.patches = None;
        }
        Ok(())
    }

    /// What the linear solves have cost so far (solves, Krylov iterations, seconds) and how
    /// many fell back to another solver.
    pub fn linear_stats(&self) -> (crate::solver::linear::LinearStats, usize) {
        (self.work.matrix.stats(), self.work.matrix.fallbacks())
    }

    /// Unknowns and non-zeros of the last tangent.
    pub fn system_size(&self) -> (usize, usize) {
        (self.work.matrix.dim(), self.work.matrix.nnz())
    }

    /// Nodal displacement increment Δu of the last converged load step (node-major:
    /// `node * D + axis`; empty before the first step). The grid is reset every step, so this
    /// is the only nodal displacement the solver has.
    pub fn step_increment(&self) -> &[f64] {
        &self.work.du_nodal
    }

    /// The ghost operator of the last increment (faces, cell fill fractions).
    pub fn ghost(&self) -> &GhostOperator<D> {
        &self.ghost
    }

    /// Form the ghost operator for the current configuration (after [`Self::build_supports`]).
    pub fn build_ghost(&mut self) {
        let start = std::time::Instant::now();
        if self.settings.ghost.is_on() {
            cell_fill(&self.grid, &*self.family, &self.points, self.ghost.fill_mut());
        }
        if self.settings.ghost.is_on() && self.settings.ghost.cut_share > 0.0 {
            node_share(
                &self.grid,
                &self.work.table,
                self.points.state.iter().map(|s| s.volume),
                self.ghost.share_mut(),
            );
        }
        self.ghost
            .build(&self.grid, &self.settings.ghost, self.model.young_modulus());
        self.ghost.retain_reached(&self.work.table);
        crate::solver::profile::charge(crate::solver::profile::Phase::Weights, start);
    }

    /// Supports of the last [`Self::build_supports`].
    pub fn supports(&self) -> &SupportTable<D> {
        &self.work.table
    }

    /// Nodes whose material volume share Σ_p S_vp V_p^n is positive but below
    /// `weak_node_tolerance` × element volume, from the current supports, and the
    /// (slave, master) ties chosen for them under [`WeakNodeTreatment::Tie`].
    pub fn weak_nodes(&self) -> (Vec<usize>, Vec<(usize, usize)>) {
        let tol = self.settings.weak_node_tolerance;
        if tol <= 0.0 {
            return (vec![], vec![]);
        }
        let cell: f64 = self.grid.spacing().iter().product();
        let mut share = vec![0.0; self.grid.num_nodes()];
        let mut touched = vec![false; self.grid.num_nodes()];
        let table = &self.work.table;
        for p in 0..table.num_points() {
            let (nodes, s, _) = table.point(p);
            for (&n, &w) in nodes.iter().zip(s) {
                share[n] += w * self.points.state[p].volume;
                touched[n] = true;
            }
        }
        let threshold = tol * cell;
        let weak: Vec<usize> = (0..share.len())
            .filter(|&n| touched[n] && share[n] < threshold)
            .collect();
        let mut ties = Vec::new();
        if self.settings.weak_node_treatment == WeakNodeTreatment::Tie {
            for &n in &weak {
                let idx = self.grid.node_coords(n);
                let mut best: Option<(usize, f64)> = None;
                for a in 0..D {
                    for up in [false, true] {
                        let mut j = idx;
                        if up {
                            if j[a] + 1 >= self.grid.nodes_along(a) {
                                continue;
                            }
                            j[a] += 1;
                        } else {
                            if j[a] == 0 {
                                continue;
                            }
                            j[a] -= 1;
                        }
                        let m = self.grid.node_index(j);
                        if share[m] >= threshold && best.is_none_or(|(_, s)| share[m] > s) {
                            best = Some((m, share[m]));
                        }
                    }
                }
                if let Some((m, _)) = best {
                    ties.push((n, m));
                }
            }
        }
        (weak, ties)
    }

    fn external_point_forces(&self, load_factor: f64) -> Vec<SVector<f64, D>> {
        let mut forces: Vec<SVector<f64, D>> = self
            .points
            .mass
            .iter()
            .map(|&m| self.loads.gravity * (m * load_factor))
            .collect();
        let factor = self.point_load_ramp.applied(load_factor);
        for (p, f) in &self.loads.point_loads {
            forces[*p] += f * factor;
        }
        forces
    }

    /// Domain half-lengths after committing F (eqs 37/39).
    fn updated_half_length(&self, p: usize, f: &nalgebra::Matrix3<f64>) -> SVector<f64, D> {
        self.settings
            .domain_update
            .half_length(&self.points.half_length0[p], f)
    }

    /// Commit the converged step: states, positions (x += Σ S Δu) and domains (eqs 37/39).
    /// A domain that would collapse (length ≤ 0) fails the increment before anything is
    /// committed, so that the load stepping can retry it with a smaller one.
    fn commit(&mut self, newmark: Option<NewmarkStep>) -> Result<(), StepFailure> {
        let family = self.family();
        let mut probe = PointSupport::<D>::default();
        let corners_per_point = if family.needs_corners() { 1 << D } else { 0 };
        let mut corners = [SVector::<f64, D>::zeros(); crate::basis::cpdi::MAX_CORNERS];
        for p in 0..self.points.len() {
            let trial = self.work.trials[p].as_ref().expect("converged trial");
            let f = trial.f(&self.points.state[p]);
            let h = self.updated_half_length(p, &f);
            if let Some(a) = (0..D).find(|&a| !(h[a] > 0.0 && h[a].is_finite())) {
                return Err(StepFailure::Kinematics {
                    point: p,
                    reason: format!(
                        "domain collapsed along axis {a} (updated half-length {:.3e})",
                        h[a]
                    ),
                });
            }
            // Weights the next step could not form (a point leaving the grid, a domain longer
            // than the basis allows, a folded CPDI domain) are caught here, before anything is
            // committed, so that the increment can be cut; found at the next step's weights
            // they would fail every retry from the already committed state.
            let x = self.points.position[p] + self.work.table.interpolate(p, &self.work.du_nodal);
            let c = &mut corners[..corners_per_point];
            c.copy_from_slice(self.points.corners_of(p));
            family
                .update_corners(&self.grid, &self.work.du_nodal, c)
                .map_err(|e| Self::basis_failure(p, &x, &h, e))?;
            let view = crate::basis::PointView {
                position: &x,
                half_length: &h,
                position0: &self.points.position0[p],
                half_length0: &self.points.half_length0[p],
                f: &f,
                corners: c,
            };
            family
                .evaluate(&self.grid, &view, &mut probe)
                .map_err(|e| Self::basis_failure(p, &x, &h, e))?;
        }
        if let Some(n) = newmark {
            self.commit_motion(&n);
        }
        for p in 0..self.points.len() {
            let trial = self.work.trials[p].as_ref().expect("converged trial");
            let new_state = trial.committed(&self.points.state[p]);
            self.points.state[p] = new_state;
            let du = self.work.table.interpolate(p, &self.work.du_nodal);
            self.points.position[p] += du;
            self.points.half_length[p] = self.updated_half_length(p, &new_state.f);
            if corners_per_point > 0 {
                let c = &mut self.points.corners[p * corners_per_point..(p + 1) * corners_per_point];
                family
                    .update_corners(&self.grid, &self.work.du_nodal, c)
                    .expect("corner update checked above");
            }
            if self.settings.volume_update == VolumeUpdate::DomainProduct {
                // The paper's V_p^n: the product of the domain lengths (unit out-of-plane).
                let h = self.points.half_length[p];
                self.points.state[p].volume = (0..D).map(|a| 2.0 * h[a]).product();
            }
        }
        Ok(())
    }
}
