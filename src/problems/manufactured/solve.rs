//! The manufactured problem by material points (any family) or Q4/Q8 FEM.

use super::exact::Exact;
use super::measures::{errors, Errors, PointValue};
use super::spec::{ManufacturedSpec, METHODS};
use crate::basis::method::Method;
use crate::basis::Basis;
use crate::fem::{ElementFamily, PlaneFem, PlaneFemSettings, PlaneLoads, PlaneMesh, QuadElement};
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::mpm::{Loads, MpmSettings, MpmSolver};
use crate::solver::error::{InputError, SolveError};
use crate::solver::linear::LinearSolver;
use crate::solver::load_stepping::{steps_and_failure, LoadStepping, StepReport};
use nalgebra::{Matrix3, SVector};

/// One manufactured-solution analysis, whatever the method.
#[derive(Debug, Clone, PartialEq)]
pub struct ManufacturedSolution {
    pub steps: Vec<StepReport>,
    pub failure: Option<SolveError>,
    /// Material or Gauss points at the last converged step.
    pub points: Vec<PointValue>,
    /// Errors of a converged analysis (`None` if a step failed).
    pub errors: Option<Errors>,
}

fn sigma4(s: &Matrix3<f64>) -> [f64; 4] {
    [s[(0, 0)], s[(1, 1)], s[(0, 1)], s[(2, 2)]]
}

/// Rollers on every face of the unit square (`axes` = 2) or cube (3): (node, axis) for the
/// nodes `on(axis, value)`.
pub(crate) fn rollers(axes: usize, on: impl Fn(usize, f64) -> Vec<usize>) -> Vec<(usize, usize)> {
    let mut fixed = vec![];
    for axis in 0..axes {
        for value in [0.0, 1.0] {
            fixed.extend(on(axis, value).into_iter().map(|n| (n, axis)));
        }
    }
    fixed
}

/// Solve by `method`: iGIMP or MPM weights on material points filling the grid, or Q4/Q8 FEM
/// on the same cells.
pub fn solve(spec: &ManufacturedSpec, method: Method) -> Result<ManufacturedSolution, InputError> {
    spec.validate()?;
    if spec.dimension != 2 {
        return Err(InputError::new(
            "dimension",
            spec.dimension,
            "the plane solver takes dimension 2; problems::manufactured3d::solve_3d solves 3",
        ));
    }
    let exact = Exact::of(spec);
    let (steps, failure, points) = match method {
        Method::MaterialPoint(_) => solve_mpm(spec, method)?,
        Method::FEM_Q4 | Method::FEM_Q8 => solve_fem(spec, method)?,
        _ => return Err(method.unsupported("manufactured problem", &METHODS)),
    };
    let errors = failure.is_none().then(|| errors(&exact, &points));
    Ok(ManufacturedSolution {
        steps,
        failure,
        points,
        errors,
    })
}

type Run = (Vec<StepReport>, Option<SolveError>, Vec<PointValue>);

/// The material point settings of a manufactured case (2D or 3D): the method's family, no
/// treatment of nearly empty cells (the grid is the material: no cell is partly filled).
pub(crate) fn mpm_settings(spec: &ManufacturedSpec, method: Method) -> MpmSettings {
    MpmSettings {
        basis: method.basis().unwrap_or(Basis::Gimp),
        domain_update: spec.domain_update,
        newton: spec.newton,
        load_steps: spec.load_steps,
        weak_node_tolerance: 0.0,
        weak_node_treatment: Default::default(),
        volume_update: Default::default(),
        linear_solver: LinearSolver::Auto,
        ghost: Default::default(),
        dynamics: None,
        f_bar: false,
    }
}

/// The material point solver of `spec` (any family): points filling the unit square
/// grid, rollers on every edge, the dead load on the points, undeformed.
pub fn mpm_solver(spec: &ManufacturedSpec, method: Method) -> Result<MpmSolver<2>, InputError> {
    spec.validate()?;
    let exact = &Exact::of(spec);
    if !method.uses_material_points() {
        return Err(method.unsupported("manufactured material point solver", &Method::MATERIAL_POINT));
    }
    let h = spec.element_size();
    let grid = Grid::try_new([0.0, 0.0], [h, h], [spec.cells, spec.cells])?;
    let ppc = spec.points_per_cell;
    let points = MaterialPoints::fill_box(&grid, [0.0, 0.0], [1.0, 1.0], [ppc, ppc], 1.0)?;
    let point_loads = (0..points.len())
        .map(|p| {
            let x0 = points.position0[p];
            let b = exact.body_force([x0[0], x0[1]]);
            (p, SVector::<f64, 2>::new(b[0], b[1]) * points.volume0[p])
        })
        .collect();
    let fixed = rollers(2, |axis, value| grid.nodes_on_plane(axis, value));
    let settings = mpm_settings(spec, method);
    let model = spec.model()?;
    let loads = Loads {
        gravity: SVector::zeros(),
        point_loads,
    };
    MpmSolver::try_new(grid, points, model, fixed, loads, settings)
}

fn solve_mpm(spec: &ManufacturedSpec, method: Method) -> Result<Run, InputError> {
    let mut solver = mpm_solver(spec, method)?;
    let (steps, failure) = steps_and_failure(solver.run());
    Ok((steps, failure, mpm_point_values(&solver)))
}

/// The material points of a plane solver as the error measures and point files take them.
pub(crate) fn mpm_point_values(solver: &MpmSolver<2>) -> Vec<PointValue> {
    let p = &solver.points;
    (0..p.len())
        .map(|i| PointValue {
            x0: [p.position0[i][0], p.position0[i][1]],
            x: [p.position[i][0], p.position[i][1]],
            volume0: p.volume0[i],
            sigma: sigma4(&p.state[i].cauchy()),
            half: [p.half_length[i][0], p.half_length[i][1]],
        })
        .collect()
}

/// The Q4 (`fem-q4`) or Q8 (`fem-q8`) solver of `spec`: the unit square meshed by its cells,
/// rollers on every edge, the dead load as consistent nodal forces, undeformed.
pub fn fem_solver(spec: &ManufacturedSpec, method: Method) -> Result<PlaneFem, InputError> {
    spec.validate()?;
    let exact = &Exact::of(spec);
    if !matches!(method, Method::FEM_Q4 | Method::FEM_Q8) {
        return Err(method.unsupported("manufactured FEM solver", &[Method::FEM_Q4, Method::FEM_Q8]));
    }
    let element = if method == Method::FEM_Q4 {
        QuadElement::Q4
    } else {
        QuadElement::Q8
    };
    let n = spec.cells;
    let mesh = PlaneMesh::rectangle(
        SVector::zeros(),
        SVector::<f64, 2>::new(1.0, 1.0),
        (n, n),
        element,
    )?;
    let gauss = if element == QuadElement::Q4 { 2 } else { 3 };
    // The consistent nodal force of the dead load: Σ_g N_a(ξ_g) b₀(X_g) w_g det J₀.
    let mut force = vec![SVector::<f64, 2>::zeros(); mesh.num_nodes()];
    let rule = QuadElement::tensor_rule(gauss)?;
    for e in 0..mesh.num_elements() {
        for (xi, w) in &rule {
            let (x0, jac) = mesh.map(e, xi);
            let b = exact.body_force([x0[0], x0[1]]);
            let (shape, _) = element.shape(xi);
            let v0 = w * jac.determinant();
            for (a, &node) in mesh.element_nodes(e).iter().enumerate() {
                force[node] += SVector::<f64, 2>::new(b[0], b[1]) * (shape[a] * v0);
            }
        }
    }
    let fixed = rollers(2, |axis, value| mesh.nodes_at(axis, value, 1e-9 / n as f64));
    let loads = PlaneLoads {
        gravity: SVector::zeros(),
        nodal_forces: force.into_iter().enumerate().collect(),
    };
    let settings = PlaneFemSettings {
        gauss_points: Some(gauss),
        newton: spec.newton,
        load_steps: spec.load_steps,
        linear_solver: LinearSolver::Auto,
        f_bar: false,
    };
    let model = spec.model()?;
    PlaneFem::try_new(mesh, 1.0, model, fixed, loads, settings)
}

fn solve_fem(spec: &ManufacturedSpec, method: Method) -> Result<Run, InputError> {
    let mut fem = fem_solver(spec, method)?;
    let (steps, failure) = steps_and_failure(fem.run());
    Ok((steps, failure, fem_point_values(&fem)))
}

/// The Gauss points of a plane FEM solver as the error measures and point files take them.
pub(crate) fn fem_point_values(fem: &PlaneFem) -> Vec<PointValue> {
    (0..fem.gauss.len())
        .map(|g| {
            let x = fem.gauss_point_position(g);
            PointValue {
                x0: [fem.gauss.position0[g][0], fem.gauss.position0[g][1]],
                x: [x[0], x[1]],
                volume0: fem.gauss.volume0[g],
                sigma: sigma4(&fem.cauchy_stress(g)),
                half: [0.0, 0.0],
            }
        })
        .collect()
}
