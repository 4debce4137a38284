//! The dynamic manufactured problem by material points (any family) or elements, 2D and 3D.

use super::motion::ExactMotion;
use super::spec::{DynamicManufacturedSpec, METHODS};
use crate::basis::method::Method;
use crate::fem::{
    ContinuumFem, ElementFamily, ElementMesh, FemLoads, HexElement, HexMesh, PlaneFemSettings, PlaneMesh,
    QuadElement,
};
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::mpm::{Loads, MpmSettings, MpmSolver};
use crate::problems::manufactured::{
    errors, fem_point_values, mpm_point_values, mpm_settings, rollers, ManufacturedSolution,
};
use crate::problems::manufactured3d::{errors_3d, point_values_3d, Solution3, METHODS_3D};
use crate::solver::error::InputError;
use crate::solver::linear::LinearSolver;
use crate::solver::load_stepping::{steps_and_failure, LoadStepping};
use nalgebra::SVector;

/// The material point solver of `spec` (any family) in D = `spec.dimension` dimensions:
/// points of density ρ₀ filling the unit square (cube) grid with the exact initial velocity and
/// acceleration, rollers on every face, the body force b₀(X, t), Newmark steps over the
/// duration.
pub fn mpm_solver<const D: usize>(
    spec: &DynamicManufacturedSpec,
    method: Method,
) -> Result<MpmSolver<D>, InputError> {
    spec.validate()?;
    check_dimension::<D>(spec)?;
    if !method.uses_material_points() {
        return Err(method.unsupported(
            "dynamic manufactured material point solver",
            &Method::MATERIAL_POINT,
        ));
    }
    let exact = ExactMotion::of(spec);
    let h = spec.element_size();
    let grid = Grid::<D>::try_new([0.0; D], [h; D], [spec.cells; D])?;
    let ppc = spec.points_per_cell;
    let mut points = MaterialPoints::fill_box(&grid, [0.0; D], [1.0; D], [ppc; D], spec.density)?;
    for p in 0..points.len() {
        let (v, a) = exact.motion_rates(&points.position0[p], 0.0);
        points.velocity[p] = v;
        points.acceleration[p] = a;
    }
    let fixed = rollers(D, |axis, value| grid.nodes_on_plane(axis, value));
    // The static field's settings (its family, no treatment of nearly empty cells), made
    // dynamic.
    let settings = MpmSettings {
        dynamics: Some(spec.newmark()),
        ..mpm_settings(&spec.static_spec(), method)
    };
    let model = spec.static_spec().model()?;
    let loads = Loads {
        gravity: SVector::zeros(),
        point_loads: vec![],
    };
    let mut solver = MpmSolver::try_new(grid, points, model, fixed, loads, settings)?;
    solver.set_body_force(exact.body_force_field());
    Ok(solver)
}

fn check_dimension<const D: usize>(spec: &DynamicManufacturedSpec) -> Result<(), InputError> {
    if spec.dimension != D {
        return Err(InputError::new(
            "dimension",
            spec.dimension,
            format!("must be {D} for this solver"),
        ));
    }
    Ok(())
}

/// The element solver of `spec` on `mesh` (the unit square or cube meshed by its cells): the
/// exact nodal velocities and accelerations at t = 0, rollers on every face, the body force at
/// the Gauss points (the element's default rule: 2 per axis for the linear elements, 3 for the
/// serendipity ones).
fn fem_solver_on<const D: usize, E: ElementFamily<D>>(
    spec: &DynamicManufacturedSpec,
    mesh: ElementMesh<D, E>,
    linear_solver: LinearSolver,
) -> Result<ContinuumFem<D, E>, InputError> {
    let exact = ExactMotion::of(spec);
    let n = spec.cells;
    let fixed = rollers(D, |axis, value| mesh.nodes_at(axis, value, 1e-9 / n as f64));
    let (velocity, acceleration): (Vec<_>, Vec<_>) =
        mesh.nodes.iter().map(|x| exact.motion_rates(x, 0.0)).unzip();
    let settings = PlaneFemSettings {
        gauss_points: None,
        newton: spec.newton,
        load_steps: spec.time_steps(),
        linear_solver,
        f_bar: false,
    };
    let model = spec.static_spec().model()?;
    let loads = FemLoads {
        gravity: SVector::zeros(),
        nodal_forces: vec![],
    };
    let mut fem = ContinuumFem::try_new(mesh, spec.density, model, fixed, loads, settings)?;
    fem.set_dynamics(spec.newmark(), &velocity, Some(&acceleration))?;
    fem.set_body_force(exact.body_force_field());
    Ok(fem)
}

/// The Q4 (`fem-q4`) or Q8 (`fem-q8`) solver of a plane `spec`.
pub fn fem_solver(
    spec: &DynamicManufacturedSpec,
    method: Method,
) -> Result<ContinuumFem<2, QuadElement>, InputError> {
    spec.validate()?;
    check_dimension::<2>(spec)?;
    let element = match method {
        Method::FEM_Q4 => QuadElement::Q4,
        Method::FEM_Q8 => QuadElement::Q8,
        _ => {
            return Err(method.unsupported(
                "dynamic manufactured FEM solver",
                &[Method::FEM_Q4, Method::FEM_Q8],
            ))
        }
    };
    let n = spec.cells;
    let mesh = PlaneMesh::rectangle(
        SVector::zeros(),
        SVector::<f64, 2>::new(1.0, 1.0),
        (n, n),
        element,
    )?;
    fem_solver_on(spec, mesh, LinearSolver::Lu)
}

/// The Hex8 (`fem-hex8`) or Hex20 (`fem-hex20`) solver of a 3D `spec`.
pub fn fem_solver_3d(
    spec: &DynamicManufacturedSpec,
    method: Method,
) -> Result<ContinuumFem<3, HexElement>, InputError> {
    spec.validate()?;
    check_dimension::<3>(spec)?;
    let element = match method {
        Method::FEM_HEX8 => HexElement::Hex8,
        Method::FEM_HEX20 => HexElement::Hex20,
        _ => {
            return Err(method.unsupported(
                "dynamic manufactured 3D FEM solver",
                &[Method::FEM_HEX8, Method::FEM_HEX20],
            ))
        }
    };
    let n = spec.cells;
    let mesh = HexMesh::cuboid(SVector::zeros(), SVector::<f64, 3>::repeat(1.0), [n; 3], element)?;
    // The effective tangent of a hyperelastic model is symmetric: LDLᵀ (LU its fallback), as
    // in the static 3D study.
    fem_solver_on(spec, mesh, LinearSolver::Ldlt)
}

/// Solve one plane dynamic manufactured analysis by `method` and measure its errors at the end.
pub fn solve(spec: &DynamicManufacturedSpec, method: Method) -> Result<ManufacturedSolution, InputError> {
    spec.validate()?;
    check_dimension::<2>(spec)?;
    let (result, points) = match method {
        Method::MaterialPoint(_) => {
            let mut s = mpm_solver::<2>(spec, method)?;
            (s.run(), mpm_point_values(&s))
        }
        Method::FEM_Q4 | Method::FEM_Q8 => {
            let mut f = fem_solver(spec, method)?;
            (f.run(), fem_point_values(&f))
        }
        _ => return Err(method.unsupported("dynamic manufactured problem", &METHODS)),
    };
    let (steps, failure) = steps_and_failure(result);
    let exact = ExactMotion::of(spec).at(spec.duration());
    let errors = failure.is_none().then(|| errors(&exact, &points));
    Ok(ManufacturedSolution {
        steps,
        failure,
        points,
        errors,
    })
}

/// Solve one 3D dynamic manufactured analysis by `method` and measure its errors at the end.
pub fn solve_3d(spec: &DynamicManufacturedSpec, method: Method) -> Result<Solution3, InputError> {
    spec.validate()?;
    check_dimension::<3>(spec)?;
    let (result, points) = match method {
        Method::MaterialPoint(_) => {
            let mut s = mpm_solver::<3>(spec, method)?;
            let r = s.run();
            (r, point_values_3d(&s.points))
        }
        Method::FEM_HEX8 | Method::FEM_HEX20 => {
            let mut f = fem_solver_3d(spec, method)?;
            let r = f.run();
            (r, crate::problems::manufactured3d::gauss_values_3d(&f))
        }
        _ => return Err(method.unsupported("dynamic manufactured 3D problem", &METHODS_3D)),
    };
    let (steps, failure) = steps_and_failure(result);
    let exact = ExactMotion::of(spec).at_3d(spec.duration());
    let errors = failure.is_none().then(|| errors_3d(&exact, &points));
    Ok(Solution3 {
        steps,
        failure,
        points,
        errors,
    })
}
