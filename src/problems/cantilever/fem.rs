//! The cantilever by updated-Lagrangian FEM: Q8 in plane strain (Figure 21), Hex8/Hex20 in 3D.

use super::spec::{CantileverSpec, EndDisplacement};
use crate::fem::{
    ElementFamily, FemLoads, HexElement, HexMesh, PlaneFem, PlaneFemSettings, PlaneLoads, PlaneMesh,
    QuadElement, SolidFem,
};
use crate::solver::error::{InputError, SolveError};
use crate::solver::linear::LinearSolver;
use crate::solver::load_stepping::{LoadStepping, StepReport};
use nalgebra::SVector;

/// What a FEM comparator reports: the steps and the end displacement after each.
#[derive(Debug, Clone, PartialEq)]
pub struct FemOutcome {
    pub steps: Vec<StepReport>,
    pub end: Vec<EndDisplacement>,
    pub failure: Option<SolveError>,
}

/// Updated-Lagrangian Q8 FEM (3×3 Gauss points, LDLᵀ) on the same elements (h, so 20×2 for
/// the paper's beam), the same supports (left edge on rollers, its neutral-axis node pinned)
/// and the end load as a dead nodal force on the neutral-axis end node, as in the paper
/// (Figure 21). The end displacement is that node's.
pub fn solve_fem_q8(spec: &CantileverSpec) -> Result<FemOutcome, InputError> {
    let (fem, tip) = fem_q8(spec, 1.0)?;
    Ok(run_fem(spec, fem, tip))
}

/// The Q8 beam of [`solve_fem_q8`] at density `density`, and its tip node (L, d/2).
pub fn fem_q8(spec: &CantileverSpec, density: f64) -> Result<(PlaneFem, usize), InputError> {
    spec.validate()?;
    let h = spec.element_size;
    let cells = (
        (spec.length / h).round() as usize,
        (spec.depth / h).round() as usize,
    );
    let mesh = PlaneMesh::rectangle(
        SVector::<f64, 2>::zeros(),
        SVector::<f64, 2>::new(spec.length, spec.depth),
        cells,
        QuadElement::Q8,
    )?;
    let axis = 0.5 * spec.depth;
    let mut fixed: Vec<(usize, usize)> = mesh
        .nodes_at(0, 0.0, 1e-9 * h)
        .into_iter()
        .map(|n| (n, 0))
        .collect();
    fixed.push((mesh.nearest_node(SVector::<f64, 2>::new(0.0, axis)), 1));
    let tip = mesh.nearest_node(SVector::<f64, 2>::new(spec.length, axis));
    let loads = PlaneLoads {
        gravity: SVector::<f64, 2>::zeros(),
        nodal_forces: vec![(tip, SVector::<f64, 2>::new(0.0, -spec.load))],
    };
    let model = spec.model()?;
    let fem = PlaneFem::try_new(mesh, density, model, fixed, loads, fem_settings(spec, Some(3)))?;
    Ok((fem, tip))
}

/// Updated-Lagrangian Hex8 (2×2×2 Gauss points) or Hex20 (3×3×3) FEM of the 3D beam on the
/// same `h` (20 × 2 × 2 elements for the paper's beam), the supports of the module docs (u_x
/// on the end face, u_y along its neutral-axis line, u_z on the mid-plane), and the end load
/// as the consistent line load on the end edge along the neutral axis (per element edge
/// ½, ½ for Hex8; ⅙, ⅔, ⅙ for Hex20). The end displacement is that of the edge's middle
/// node (L, d/2, d/2).
pub fn solve_fem_3d(spec: &CantileverSpec, element: HexElement) -> Result<FemOutcome, InputError> {
    spec.validate()?;
    let (h, d) = (spec.element_size, spec.depth);
    let n = |v: f64| (v / h).round() as usize;
    let mesh = HexMesh::cuboid(
        SVector::zeros(),
        SVector::<f64, 3>::new(spec.length, d, d),
        [n(spec.length), n(d), n(d)],
        element,
    )?;
    let tol = 1e-9 * h;
    let (axis, mid) = (0.5 * d, 0.5 * d);
    let mut fixed: Vec<(usize, usize)> = vec![];
    for node in mesh.nodes_at(0, 0.0, tol) {
        fixed.push((node, 0));
        if (mesh.nodes[node][1] - axis).abs() <= tol {
            fixed.push((node, 1));
        }
    }
    fixed.extend(mesh.nodes_at(2, mid, tol).into_iter().map(|node| (node, 2)));
    let edge = mesh.nodes_on_segment(
        SVector::<f64, 3>::new(spec.length, axis, 0.0),
        SVector::<f64, 3>::new(spec.length, axis, d),
        tol,
    );
    let weights: &[f64] = if element.quadratic() {
        &[1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0]
    } else {
        &[0.5, 0.5]
    };
    let per_edge = weights.len() - 1;
    let mut force = vec![0.0; edge.len()];
    let edges = (edge.len() - 1) / per_edge;
    for e in 0..edges {
        for (k, w) in weights.iter().enumerate() {
            force[e * per_edge + k] += w * spec.load / edges as f64;
        }
    }
    let tip = mesh.nearest_node(SVector::<f64, 3>::new(spec.length, axis, mid));
    let loads = FemLoads {
        gravity: SVector::<f64, 3>::zeros(),
        nodal_forces: edge
            .iter()
            .zip(&force)
            .map(|(&node, &f)| (node, SVector::<f64, 3>::new(0.0, -f, 0.0)))
            .collect(),
    };
    let model = spec.model()?;
    let fem = SolidFem::try_new(mesh, 1.0, model, fixed, loads, fem_settings(spec, None))?;
    Ok(run_fem(spec, fem, tip))
}

fn fem_settings(spec: &CantileverSpec, gauss_points: Option<usize>) -> PlaneFemSettings {
    PlaneFemSettings {
        gauss_points,
        newton: spec.newton,
        load_steps: spec.load_steps,
        // F-bar's tangent is unsymmetric (reference/README.md item 69).
        linear_solver: if spec.f_bar {
            LinearSolver::Lu
        } else {
            LinearSolver::Ldlt
        },
        f_bar: spec.f_bar,
    }
}

/// Run a FEM beam step by step, recording the displacement of node `tip`.
fn run_fem<const D: usize, E: ElementFamily<D>>(
    spec: &CantileverSpec,
    mut fem: crate::fem::ContinuumFem<D, E>,
    tip: usize,
) -> FemOutcome {
    let mut out = FemOutcome {
        steps: vec![],
        end: vec![],
        failure: None,
    };
    while fem.steps_done() < fem.load_steps() {
        match fem.step() {
            Ok(r) => {
                let d = fem.displacement(tip);
                out.end.push(EndDisplacement {
                    step: r.step,
                    load: spec.load * r.load_factor,
                    u_over_l: d[0] / spec.length,
                    v_over_l: d[1] / spec.length,
                });
                out.steps.push(r);
            }
            Err(e) => {
                out.failure = Some(e);
                break;
            }
        }
    }
    out
}
