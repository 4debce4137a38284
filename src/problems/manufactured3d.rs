//! The manufactured solutions of [`super::manufactured`] in 3D (reference/README.md item 31): the unit cube is the
//! material, the background grid and the FEM mesh, rollers on all six faces.
//!
//! - **axis-aligned**: x_i = X_i + A sin πX_i on every axis, F diagonal;
//! - **vortex about z**: the plane vortex in (x, y) with u_z = 0, F = diag(F₂, 1).
//!
//! Both have F = diag(F₂, f₃₃), so the Hencky stress is the plane closed form with a stretch
//! along z ([`super::manufactured::kirchhoff_block`]), P is block diagonal and the body force
//! b₀ = −Div P comes from forward-mode automatic differentiation as in 2D. The rollers are
//! exact for both: the normal displacement vanishes on every face and P has no tangential
//! traction there (the axis-aligned P is diagonal, the vortex has F = I near x, y faces and
//! P_xz = P_yz = 0 on z faces). The vortex about z is plane strain, so its 3D solution must
//! equal the 2D one: a test compares them.

use super::manufactured::{
    deformation_gradient, first_piola_block, kirchhoff_block, motion, mpm_settings, rollers, Errors, Field,
    ManufacturedSpec, M2,
};
use crate::basis::method::Method;
use crate::fem::{ElementFamily, FemLoads, HexElement, HexMesh, PlaneFemSettings, SolidFem};
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::mpm::{Loads, MpmSolver};
use crate::solver::error::{InputError, SolveError};
use crate::solver::linear::LinearSolver;
use crate::solver::load_stepping::{steps_and_failure, LoadStepping, StepReport};
use nalgebra::{Matrix3, SVector};
use num_dual::{Dual64, DualNum};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

type V3 = SVector<f64, 3>;

/// The methods that solve the 3D manufactured problem.
pub const METHODS_3D: [Method; Method::FAMILIES + 2] = Method::listed(Some(3), &[]);

/// F = diag(F₂(X, Y), f₃₃(Z)) of the 3D fields.
fn block_gradient<T: DualNum<Primitive = f64> + Copy>(field: Field, a: f64, x: [T; 3]) -> (M2<T>, T) {
    let f2 = deformation_gradient(field, a, [x[0], x[1]]);
    let f33 = match field {
        Field::AxisAligned => (x[2] * PI).cos() * (a * PI) + 1.0,
        Field::Vortex => T::one(),
    };
    (f2, f33)
}

/// The exact 3D solution of a spec (its `field`, `amplitude` and material).
#[derive(Debug, Clone, Copy)]
pub struct Exact3 {
    pub field: Field,
    pub amplitude: f64,
    pub lambda: f64,
    pub mu: f64,
}

impl Exact3 {
    pub fn of(spec: &ManufacturedSpec) -> Self {
        let (lambda, mu) = spec.lame();
        Exact3 {
            field: spec.field,
            amplitude: spec.amplitude,
            lambda,
            mu,
        }
    }

    /// x(X).
    pub fn position(&self, x: [f64; 3]) -> [f64; 3] {
        let p = motion(self.field, self.amplitude, [x[0], x[1]]);
        let z = match self.field {
            Field::AxisAligned => x[2] + self.amplitude * (PI * x[2]).sin(),
            Field::Vortex => x[2],
        };
        [p[0], p[1], z]
    }

    /// F at X (3×3).
    pub fn deformation_gradient(&self, x: [f64; 3]) -> Matrix3<f64> {
        let (f, f33) = block_gradient(self.field, self.amplitude, x);
        Matrix3::new(f[0][0], f[0][1], 0.0, f[1][0], f[1][1], 0.0, 0.0, 0.0, f33)
    }

    /// Cauchy stress σ = τ / det F at X.
    pub fn cauchy(&self, x: [f64; 3]) -> Matrix3<f64> {
        let (f, f33) = block_gradient(self.field, self.amplitude, x);
        let (tau, tzz) = kirchhoff_block(&f, f33, self.lambda, self.mu);
        let j = (f[0][0] * f[1][1] - f[0][1] * f[1][0]) * f33;
        Matrix3::new(
            tau[0][0], tau[0][1], 0.0, tau[1][0], tau[1][1], 0.0, 0.0, 0.0, tzz,
        ) / j
    }

    /// First Piola–Kirchhoff stress at X (3×3, block diagonal).
    pub fn first_piola(&self, x: [f64; 3]) -> Matrix3<f64> {
        let (f, f33) = block_gradient(self.field, self.amplitude, x);
        let (p, pzz) = first_piola_block(&f, f33, self.lambda, self.mu);
        Matrix3::new(p[0][0], p[0][1], 0.0, p[1][0], p[1][1], 0.0, 0.0, 0.0, pzz)
    }

    /// b₀ = −Div P at X: one dual evaluation per reference axis J gives ∂P_iJ/∂X_J.
    pub fn body_force(&self, x: [f64; 3]) -> [f64; 3] {
        let mut div = [0.0; 3];
        for jj in 0..3 {
            let xd: [Dual64; 3] = std::array::from_fn(|a| Dual64::new(x[a], if a == jj { 1.0 } else { 0.0 }));
            let (f, f33) = block_gradient(self.field, self.amplitude, xd);
            let (p, pzz) = first_piola_block(&f, f33, self.lambda, self.mu);
            if jj < 2 {
                for (i, d) in div.iter_mut().take(2).enumerate() {
                    *d += p[i][jj].eps;
                }
            } else {
                div[2] += pzz.eps;
            }
        }
        [-div[0], -div[1], -div[2]]
    }
}

/// One material or Gauss point at the end of a 3D analysis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PointValue3 {
    /// Reference position X_p.
    pub x0: [f64; 3],
    /// Current position x_p.
    pub x: [f64; 3],
    /// Initial volume v_p0.
    pub volume0: f64,
    /// Cauchy stress, rows.
    pub sigma: [[f64; 3]; 3],
    /// Domain half-lengths (material points; zero for Gauss points), for ParaView.
    pub half: [f64; 3],
}

impl PointValue3 {
    pub fn cauchy(&self) -> Matrix3<f64> {
        Matrix3::from_fn(|i, j| self.sigma[i][j])
    }
}

/// The material points of a 3D solver as the error measures and point files take them.
pub(crate) fn point_values_3d(p: &MaterialPoints<3>) -> Vec<PointValue3> {
    let arr = |v: &V3| [v[0], v[1], v[2]];
    (0..p.len())
        .map(|i| PointValue3 {
            x0: arr(&p.position0[i]),
            x: arr(&p.position[i]),
            volume0: p.volume0[i],
            sigma: rows(&p.state[i].cauchy()),
            half: arr(&p.half_length[i]),
        })
        .collect()
}

/// The Gauss points of a solid FEM solver as the error measures and point files take them.
pub(crate) fn gauss_values_3d(fem: &SolidFem) -> Vec<PointValue3> {
    (0..fem.gauss.len())
        .map(|g| {
            let (x, x0) = (fem.gauss_point_position(g), fem.gauss.position0[g]);
            PointValue3 {
                x0: [x0[0], x0[1], x0[2]],
                x: [x[0], x[1], x[2]],
                volume0: fem.gauss.volume0[g],
                sigma: rows(&fem.cauchy_stress(g)),
                half: [0.0; 3],
            }
        })
        .collect()
}

fn rows(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)]))
}

/// Each point's ‖σ_p − σ(X_p)‖_F and σ_max, the largest exact ‖σ(X_p)‖_F: the summands and
/// the scale of the stress measure (as [`super::manufactured::stress_deviations`] in 2D).
pub fn stress_deviations_3d(exact: &Exact3, points: &[PointValue3]) -> (Vec<f64>, f64) {
    let mut smax = 0.0_f64;
    let deviation = points
        .iter()
        .map(|p| {
            let se = exact.cauchy(p.x0);
            smax = smax.max(se.norm());
            (p.cauchy() - se).norm()
        })
        .collect();
    (deviation, smax)
}

/// The measures of [`super::manufactured::errors`], in 3D: the relative discrete L2
/// displacement error and Σ_p ‖σ_p − σ(X_p)‖_F v_p0 / (σ_max |Ω₀|).
pub fn errors_3d(exact: &Exact3, points: &[PointValue3]) -> Errors {
    let (deviation, smax) = stress_deviations_3d(exact, points);
    let (mut num, mut den, mut serr, mut vol) = (0.0, 0.0, 0.0, 0.0);
    for (p, d) in points.iter().zip(&deviation) {
        let xe = exact.position(p.x0);
        for a in 0..3 {
            num += p.volume0 * (p.x[a] - xe[a]).powi(2);
            den += p.volume0 * (xe[a] - p.x0[a]).powi(2);
        }
        serr += d * p.volume0;
        vol += p.volume0;
    }
    Errors {
        displacement: (num / den).sqrt(),
        stress: serr / (smax * vol),
    }
}

/// One 3D manufactured-solution analysis.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution3 {
    pub steps: Vec<StepReport>,
    pub failure: Option<SolveError>,
    /// Material or Gauss points at the last converged step.
    pub points: Vec<PointValue3>,
    /// Errors of a converged analysis.
    pub errors: Option<Errors>,
}

/// The material point solver of a 3D `spec` (any family): `points_per_cell`³ points per cell
/// of the `cells`³ grid, rollers on the six faces, the dead load b₀ V_p0 on the points, ramped
/// over the load steps.
pub fn mpm_solver_3d(spec: &ManufacturedSpec, method: Method) -> Result<MpmSolver<3>, InputError> {
    spec.validate()?;
    if !method.uses_material_points() {
        return Err(method.unsupported("3D manufactured material point solver", &Method::MATERIAL_POINT));
    }
    let exact = Exact3::of(spec);
    let h = spec.element_size();
    let grid = Grid::try_new([0.0; 3], [h; 3], [spec.cells; 3])?;
    let ppc = spec.points_per_cell;
    let points = MaterialPoints::fill_box(&grid, [0.0; 3], [1.0; 3], [ppc; 3], 1.0)?;
    let point_loads = (0..points.len())
        .map(|p| {
            let x0 = points.position0[p];
            (
                p,
                V3::from(exact.body_force([x0[0], x0[1], x0[2]])) * points.volume0[p],
            )
        })
        .collect();
    let fixed = rollers(3, |axis, value| grid.nodes_on_plane(axis, value));
    let settings = mpm_settings(spec, method);
    let loads = Loads {
        gravity: V3::zeros(),
        point_loads,
    };
    let model = spec.model()?;
    MpmSolver::try_new(grid, points, model, fixed, loads, settings)
}

/// Solve the 3D field of `spec` by `method`: iGIMP or MPM on `points_per_cell`³ points per
/// cell of the `cells`³ grid, or Hex8 (2×2×2) / Hex20 (3×3×3) FEM on the same cells, the
/// dead load carried by the points (Gauss points) as in 2D.
pub fn solve_3d(spec: &ManufacturedSpec, method: Method) -> Result<Solution3, InputError> {
    spec.validate()?;
    if spec.dimension != 3 {
        return Err(InputError::new(
            "dimension",
            spec.dimension,
            "solve_3d takes dimension 3; problems::manufactured::solve solves 2",
        ));
    }
    let exact = Exact3::of(spec);
    let model = || spec.model();
    let (steps, failure, values) = match method {
        Method::MaterialPoint(_) => {
            let mut solver = mpm_solver_3d(spec, method)?;
            let (steps, failure) = steps_and_failure(solver.run());
            let values = point_values_3d(&solver.points);
            (steps, failure, values)
        }
        Method::FEM_HEX8 | Method::FEM_HEX20 => {
            let element = if method == Method::FEM_HEX8 {
                HexElement::Hex8
            } else {
                HexElement::Hex20
            };
            let n = spec.cells;
            let mesh = HexMesh::cuboid(V3::zeros(), V3::repeat(1.0), [n; 3], element)?;
            // The consistent nodal force of the dead load: Σ_g N_a(ξ_g) b₀(X_g) w_g det J₀.
            let mut force = vec![V3::zeros(); mesh.num_nodes()];
            for e in 0..mesh.num_elements() {
                for (xi, w) in crate::mesh::quadrature::tensor_rule::<3>(element.default_gauss_points())? {
                    let (x0, jac) = mesh.map(e, &xi);
                    let b = V3::from(exact.body_force([x0[0], x0[1], x0[2]]));
                    let (shape, _) = element.shape(&xi);
                    let v0 = w * jac.determinant();
                    for (a, &node) in mesh.element_nodes(e).iter().enumerate() {
                        force[node] += b * (shape[a] * v0);
                    }
                }
            }
            let fixed = rollers(3, |axis, value| mesh.nodes_at(axis, value, 1e-9 / n as f64));
            let loads = FemLoads {
                gravity: V3::zeros(),
                nodal_forces: force.into_iter().enumerate().collect(),
            };
            let settings = PlaneFemSettings {
                gauss_points: None,
                newton: spec.newton,
                load_steps: spec.load_steps,
                linear_solver: LinearSolver::Ldlt,
                f_bar: false,
            };
            let mut fem = SolidFem::try_new(mesh, 1.0, model()?, fixed, loads, settings)?;
            let (steps, failure) = steps_and_failure(fem.run());
            let values = gauss_values_3d(&fem);
            (steps, failure, values)
        }
        _ => return Err(method.unsupported("3D manufactured problem", &METHODS_3D)),
    };
    let errors = failure.is_none().then(|| errors_3d(&exact, &values));
    Ok(Solution3 {
        steps,
        failure,
        points: values,
        errors,
    })
}
