//! The column by updated-Lagrangian FEM: line elements in 1D, Hex8/Hex20 for the 3D prism.

use super::spec::{ColumnObserver, ColumnOutcome, ColumnSpec, ColumnState, PointRecord};
use crate::fem::{
    HexElement, HexMesh, LineElement, LineFem, LineFemSettings, LineLoads, LineMesh, PlaneFemSettings,
    SolidFem, SolidLoads,
};
use crate::solver::error::InputError;
use crate::solver::load_stepping::{steps_and_failure, LoadStepping};
use nalgebra::SVector;

impl ColumnSpec {
    /// The FEM solver for this column: `elements` equal elements on [0, L0], base node fixed,
    /// gravity along −z, `gauss_points` (default: the element's) per element.
    pub fn fem_solver(&self, element: LineElement) -> Result<LineFem, InputError> {
        self.validate()?;
        let mesh = LineMesh::uniform(element, 0.0, self.length, self.elements)?;
        let model = self.model()?;
        let loads = LineLoads {
            gravity: -self.gravity(),
            nodal_forces: vec![],
        };
        let settings = LineFemSettings {
            gauss_points: self.gauss_points.unwrap_or(element.default_gauss_points()),
            newton: self.newton,
            load_steps: self.load_steps,
        };
        LineFem::try_new(mesh, self.density, model, vec![0], loads, settings)
    }
}

/// The 3D column by updated-Lagrangian FEM: a 1 × 1 × n prism of Hex8 (2×2×2 Gauss points)
/// or Hex20 (3×3×3) elements, `gauss_points` per axis when set, rollers on every lateral
/// node (uniaxial strain) and the base on rollers. Every Gauss point of one level carries
/// the value of the 1D element's Gauss point at that height (the strain is uniaxial), with
/// volumes summing to the 1D point's, so eq (46), weighted by initial volume, is the 1D
/// linear (Hex8) or quadratic (Hex20) FEM column's.
pub(super) fn solve_fem_3d(
    spec: &ColumnSpec,
    element: HexElement,
    observer: &mut ColumnObserver<'_>,
) -> Result<ColumnOutcome, InputError> {
    spec.validate()?;
    let size = SVector::<f64, 3>::new(1.0, 1.0, spec.length);
    let mesh = HexMesh::cuboid(SVector::zeros(), size, [1, 1, spec.elements], element)?;
    let mut fixed: Vec<(usize, usize)> = (0..mesh.num_nodes()).flat_map(|n| [(n, 0), (n, 1)]).collect();
    fixed.extend(mesh.nodes_at(2, 0.0, 1e-12).into_iter().map(|n| (n, 2)));
    let top_node = mesh.nearest_node(size);
    let loads = SolidLoads {
        gravity: SVector::<f64, 3>::new(0.0, 0.0, -spec.gravity()),
        nodal_forces: vec![],
    };
    let settings = PlaneFemSettings {
        gauss_points: spec.gauss_points,
        newton: spec.newton,
        load_steps: spec.load_steps,
        linear_solver: Default::default(),
        f_bar: false,
    };
    let mut fem = SolidFem::try_new(mesh, spec.density, spec.model()?, fixed, loads, settings)?;
    observer(0, ColumnState::Fem3(&fem));
    let (steps, failure) =
        steps_and_failure(fem.run_observed(&mut |s, r| observer(r.step, ColumnState::Fem3(s))));
    let g = &fem.gauss;
    let records = (0..g.len())
        .map(|p| {
            let at = (g.position0[p][2], fem.gauss_point_position(p)[2], g.volume0[p]);
            PointRecord::of(fem.model(), &g.state[p], at, 2, 0)
        })
        .collect();
    let top = fem.displacement(top_node)[2];
    Ok(ColumnOutcome::from_records(spec, records, top, steps, failure))
}

/// Run the column with updated-Lagrangian FEM. Records one [`PointRecord`] per Gauss point
/// (their initial volumes weight eq 46); the top displacement is that of the top node and the
/// base F that of the bottom-most Gauss point (eq 47), through the same
/// [`ColumnOutcome::from_records`] as the material point methods.
pub fn solve_fem(spec: &ColumnSpec, element: LineElement) -> Result<ColumnOutcome, InputError> {
    solve_fem_observed(spec, element, &mut |_, _| {})
}

/// [`solve_fem`] showing the solver to `observer` before the first and after every
/// converged load step.
pub fn solve_fem_observed(
    spec: &ColumnSpec,
    element: LineElement,
    observer: &mut ColumnObserver<'_>,
) -> Result<ColumnOutcome, InputError> {
    let mut solver = spec.fem_solver(element)?;
    observer(0, ColumnState::Fem(&solver));
    let (steps, failure) =
        steps_and_failure(solver.run_observed(&mut |s, r| observer(r.step, ColumnState::Fem(s))));
    let records = fem_records(&solver);
    let top = solver.displacement(solver.mesh.num_nodes() - 1);
    Ok(ColumnOutcome::from_records(spec, records, top, steps, failure))
}

/// Final values at every Gauss point.
pub fn fem_records(solver: &LineFem) -> Vec<PointRecord> {
    let g = &solver.gauss;
    (0..g.len())
        .map(|p| {
            let at = (g.position0[p], solver.gauss_point_map(p).0, g.volume0[p]);
            PointRecord::of(solver.model(), &g.state[p], at, 0, 1)
        })
        .collect()
}
