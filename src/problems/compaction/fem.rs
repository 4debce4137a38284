//! The compaction by updated-Lagrangian FEM: Q4/Q8 on the half block, Hex8/Hex20 on the quarter.

use super::spec::CompactionSpec;
use crate::fem::{
    ContinuumFem, ElementFamily, ElementMesh, FemLoads, HexElement, HexMesh, PlaneFemSettings, PlaneMesh,
    QuadElement,
};
use crate::solver::error::{InputError, SolveError};
use crate::solver::load_stepping::{steps_and_failure, LoadStepping, StepReport};
use nalgebra::SVector;

/// What the FEM comparator reports.
#[derive(Debug, Clone, PartialEq)]
pub struct FemOutcome {
    pub steps: Vec<StepReport>,
    pub failure: Option<SolveError>,
    /// Horizontal displacement of the bottom-right node.
    pub max_horizontal_displacement: f64,
    pub elements: usize,
}

/// Updated-Lagrangian FEM of the modelled half block with the same supports (roller on
/// x = 0, u_y = 0 on the base), material and gravity ramp: Q4 with 2×2 Gauss points (the
/// paper's Figure 17 reference) or Q8 with 3×3 (a comparison for plastic flow, where Q4
/// locks). LDLᵀ solves.
pub fn solve_fem(spec: &CompactionSpec, element: QuadElement) -> Result<FemOutcome, InputError> {
    let (fem, corner) = fem_solver(spec, element)?;
    Ok(run_fem_block(fem, corner))
}

/// The plane-strain FEM solver of `spec` with `element` (Q4 or Q8 on the modelled half block,
/// h = `element_size`), undeformed, and the node whose u_x is Figure 17's measure.
pub fn fem_solver(
    spec: &CompactionSpec,
    element: QuadElement,
) -> Result<(crate::fem::PlaneFem, usize), InputError> {
    let h = spec.element_size;
    let cells = [
        (spec.half_width / h).round() as usize,
        (spec.height / h).round() as usize,
    ];
    let size = SVector::<f64, 2>::new(spec.half_width, spec.height);
    fem_block(
        spec,
        PlaneMesh::structured(SVector::zeros(), size, cells, element)?,
    )
}

/// The FEM block of either dimension on `mesh` (the modelled part, from the origin): rollers
/// on every coordinate plane through the origin (the symmetry planes and the base), gravity
/// along the last axis, the element's default Gauss rule (2 per axis for Q4/Hex8, 3 for
/// Q8/Hex20), LDLᵀ (or the spec's iterative solver). Returns the solver and the node at
/// (half_width, 0, …), whose u_x is the measure.
fn fem_block<const D: usize, E: ElementFamily<D>>(
    spec: &CompactionSpec,
    mesh: ElementMesh<D, E>,
) -> Result<(ContinuumFem<D, E>, usize), InputError> {
    let tol = 1e-9 * spec.element_size;
    let mut fixed: Vec<(usize, usize)> = vec![];
    for axis in 0..D {
        fixed.extend(mesh.nodes_at(axis, 0.0, tol).into_iter().map(|node| (node, axis)));
    }
    let mut corner = SVector::<f64, D>::zeros();
    corner[0] = spec.half_width;
    let corner = mesh.nearest_node(corner);
    let mut gravity = SVector::<f64, D>::zeros();
    gravity[D - 1] = -spec.unit_weight();
    let loads = FemLoads {
        gravity,
        nodal_forces: vec![],
    };
    let model = spec.model()?;
    let settings = PlaneFemSettings {
        gauss_points: None,
        newton: spec.newton,
        load_steps: spec.load_steps,
        // LDLᵀ for a symmetric tangent unless the spec names a solver (its default is the
        // material point methods' choice).
        linear_solver: crate::fem::comparator_solver(
            spec.linear_solver,
            model.tangent_is_symmetric() && !spec.f_bar,
        ),
        f_bar: spec.f_bar,
    };
    let fem = ContinuumFem::try_new(mesh, 1.0, model, fixed, loads, settings)?;
    Ok((fem, corner))
}

/// Run the FEM block of [`fem_block`] to the end.
fn solve_fem_block<const D: usize, E: ElementFamily<D>>(
    spec: &CompactionSpec,
    mesh: ElementMesh<D, E>,
) -> Result<FemOutcome, InputError> {
    let (fem, corner) = fem_block(spec, mesh)?;
    Ok(run_fem_block(fem, corner))
}

/// All load steps of an FEM block; the measure is u_x of `corner`.
fn run_fem_block<const D: usize, E: ElementFamily<D>>(
    mut fem: ContinuumFem<D, E>,
    corner: usize,
) -> FemOutcome {
    let elements = fem.mesh.num_elements();
    let (steps, failure) = steps_and_failure(fem.run());
    FemOutcome {
        steps,
        failure,
        max_horizontal_displacement: fem.displacement(corner)[0],
        elements,
    }
}

/// Updated-Lagrangian FEM of the 3D quarter block with the same supports (rollers on x = 0,
/// y = 0 and the base), material and gravity ramp: Hex8 with 2×2×2 Gauss points or Hex20 with
/// 3×3×3, LDLᵀ. The measure is u_x of the node at (half_width, 0, 0).
pub fn solve_fem_3d(spec: &CompactionSpec, element: HexElement) -> Result<FemOutcome, InputError> {
    spec.validate()?;
    solve_fem_block(spec, quarter_mesh(spec, element)?)
}

/// The 3D quarter block's solver ([`solve_fem_3d`]), undeformed, and the measure's node.
pub fn fem_solver_3d(
    spec: &CompactionSpec,
    element: HexElement,
) -> Result<(crate::fem::SolidFem, usize), InputError> {
    spec.validate()?;
    fem_block(spec, quarter_mesh(spec, element)?)
}

fn quarter_mesh(spec: &CompactionSpec, element: HexElement) -> Result<HexMesh, InputError> {
    let h = spec.element_size;
    let (n, nz) = (
        (spec.half_width / h).round() as usize,
        (spec.height / h).round() as usize,
    );
    let size = SVector::<f64, 3>::new(spec.half_width, spec.half_width, spec.height);
    HexMesh::cuboid(SVector::zeros(), size, [n, n, nz], element)
}
