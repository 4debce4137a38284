//! The column by material points: the 1D column of the paper and the 3D prism.

use super::spec::{ColumnObserver, ColumnOutcome, ColumnSpec, ColumnState, PointRecord};
use crate::basis::Basis;
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::mpm::{DomainUpdate, Loads, MpmSettings, MpmSolver};
use crate::solver::error::{InputError, SolveError};
use crate::solver::load_stepping::{steps_and_failure, LoadStepping, StepReport};
use nalgebra::SVector;

impl ColumnSpec {
    /// Solver settings of the material point column (1D or 3D).
    fn mpm_settings(&self, basis: Basis) -> MpmSettings {
        MpmSettings {
            basis,
            domain_update: DomainUpdate::Stretch,
            newton: self.newton,
            load_steps: self.load_steps,
            weak_node_tolerance: 0.0,
            weak_node_treatment: Default::default(),
            volume_update: Default::default(),
            linear_solver: Default::default(),
            ghost: self.ghost,
            dynamics: None,
            f_bar: self.f_bar,
        }
    }

    /// The MPM/GIMP solver for this column: grid [0, L0], base node fixed, gravity along −z.
    pub fn mpm_solver(&self, basis: Basis) -> Result<MpmSolver<1>, InputError> {
        self.validate()?;
        let h = self.length / self.elements as f64;
        let grid = Grid::try_new([0.0], [h], [self.elements])?;
        let points =
            MaterialPoints::fill_box(&grid, [0.0], [self.length], [self.points_per_cell], self.density)?;
        let model = self.model()?;
        let loads = Loads {
            gravity: SVector::<f64, 1>::new(-self.gravity()),
            point_loads: vec![],
        };
        let settings = self.mpm_settings(basis);
        MpmSolver::try_new(grid, points, model, vec![(0, 0)], loads, settings)
    }
}

impl ColumnSpec {
    /// The 3D prism of this column (`dimension = 3`): a grid of 1 × 1 × `elements` cells of
    /// 1 × 1 × h (unit cross section), points 2 × 2 × `points_per_cell` per cell, every lateral
    /// node on rollers (u_x = u_y = 0, so the strain is uniaxial as in 1D), the base fixed,
    /// gravity along −z. Two points across, not one: with one, the mode u_z ∝ (x − ½)(y − ½)
    /// of each level's four nodes has no stiffness (the point sits where its value and
    /// gradient vanish) and the tangent is singular.
    pub fn mpm_solver_3d(&self, basis: Basis) -> Result<MpmSolver<3>, InputError> {
        self.validate()?;
        let h = self.length / self.elements as f64;
        let grid = Grid::try_new([0.0; 3], [1.0, 1.0, h], [1, 1, self.elements])?;
        let points = MaterialPoints::fill_box(
            &grid,
            [0.0; 3],
            [1.0, 1.0, self.length],
            [2, 2, self.points_per_cell],
            self.density,
        )?;
        let mut fixed: Vec<(usize, usize)> = (0..grid.num_nodes()).flat_map(|n| [(n, 0), (n, 1)]).collect();
        fixed.extend(grid.nodes_on_plane(2, 0.0).into_iter().map(|n| (n, 2)));
        let loads = Loads {
            gravity: SVector::<f64, 3>::new(0.0, 0.0, -self.gravity()),
            point_loads: vec![],
        };
        let settings = self.mpm_settings(basis);
        MpmSolver::try_new(grid, points, self.model()?, fixed, loads, settings)
    }
}

pub(super) fn solve_mpm_3d(
    spec: &ColumnSpec,
    basis: Basis,
    observer: &mut ColumnObserver<'_>,
) -> Result<ColumnOutcome, InputError> {
    let mut solver = spec.mpm_solver_3d(basis)?;
    observer(0, ColumnState::Mpm3(&solver));
    let (steps, failure) =
        steps_and_failure(solver.run_observed(&mut |s, r| observer(r.step, ColumnState::Mpm3(s))));
    Ok(mpm_outcome(spec, &solver, 2, 0, steps, failure))
}

/// Run the column with a material point method of basis `basis`.
pub fn solve_mpm(spec: &ColumnSpec, basis: Basis) -> Result<ColumnOutcome, InputError> {
    solve_mpm_observed(spec, basis, &mut |_, _| {})
}

pub(super) fn solve_mpm_observed(
    spec: &ColumnSpec,
    basis: Basis,
    observer: &mut ColumnObserver<'_>,
) -> Result<ColumnOutcome, InputError> {
    let mut solver = spec.mpm_solver(basis)?;
    observer(0, ColumnState::Mpm(&solver));
    let (steps, failure) =
        steps_and_failure(solver.run_observed(&mut |s, r| observer(r.step, ColumnState::Mpm(s))));
    Ok(mpm_outcome(spec, &solver, 0, 1, steps, failure))
}

/// The outcome of a material point column whose axis is `axis` (1D: 0; the 3D prism: 2):
/// one [`PointRecord`] per point (σ_xx from the lateral axis `lateral`) and the top point's
/// displacement.
fn mpm_outcome<const D: usize>(
    spec: &ColumnSpec,
    solver: &MpmSolver<D>,
    axis: usize,
    lateral: usize,
    steps: Vec<StepReport>,
    failure: Option<SolveError>,
) -> ColumnOutcome {
    let pts = &solver.points;
    let records: Vec<PointRecord> = (0..pts.len())
        .map(|p| {
            let at = (pts.position0[p][axis], pts.position[p][axis], pts.volume0[p]);
            PointRecord::of(solver.model(), &pts.state[p], at, axis, lateral)
        })
        .collect();
    let top = (0..pts.len())
        .max_by(|&a, &b| pts.position0[a][axis].total_cmp(&pts.position0[b][axis]))
        .map_or(f64::NAN, |p| pts.displacement(p)[axis]);
    ColumnOutcome::from_records(spec, records, top, steps, failure)
}
