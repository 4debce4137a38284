//! Dynamic manufactured solutions (Wallstedt & Guilkey, *J. Comput. Phys.* 227 (2008) 9628,
//! §4: a prescribed motion, its body force b₀ = ρ₀ ẍ − Div P, errors against the motion) in
//! plane strain on the unit square and on the unit cube (`dimension = 3`: the fields of
//! [`super::manufactured3d`], the axis-aligned one on three axes, the vortex about z). The
//! material fills the square (cube), which is also the background grid or the FEM mesh;
//! rollers on every face, as in the static fields ([`super::manufactured`]).
//!
//! Each static field's amplitude is made to oscillate: a(t) = A sin ωt with ω = πc,
//! c = √(E/ρ₀), as Wallstedt & Guilkey's axis-aligned field u = A sin(2πX) sin(cπt):
//! - **axis-aligned**: x = X + a(t) (sin πX, sin πY) (Wallstedt & Guilkey's spatial shape is
//!   sin 2πX; sin πX is the static field's, which the rollers also satisfy);
//! - **vortex**: x = c + R(a(t) θ̂(r)) (X − c), θ̂ = (1 − 4r²)³ for r ≤ ½: a time-dependent
//!   rotation varying with radius, Wallstedt & Guilkey's "generalized vortex" on the unit
//!   square instead of their annulus, so that no cell is partly filled (F = I near the edges).
//!
//! The velocity and acceleration of the motion are ẋ = ∂x/∂a ȧ and
//! ẍ = ∂²x/∂a² ȧ² + ∂x/∂a ä, in closed form (tested against central differences in t); Div P
//! at time t is the static field's at amplitude a(t) (forward-mode automatic differentiation).
//! The analysis starts from x = X with the exact velocity and acceleration (M a₀ balances
//! f_ext(0): a wrong a₀ would cost the trapezoidal rule its order) and runs Newmark time steps
//! ([`crate::solver::dynamics`]) to `periods` × T, T = 2π/ω. The errors are the static study's
//! (displacement and stress at the points) at the end, against the motion at that time.

use super::manufactured::{
    errors, fem_point_values, mpm_point_values, mpm_settings, rollers, Exact, Field, ManufacturedSolution,
};
use super::manufactured3d::{errors_3d, point_values_3d, Exact3, Solution3, METHODS_3D};
use crate::basis::method::Method;
use crate::basis::DomainUpdate;
use crate::fem::{
    ContinuumFem, ElementFamily, ElementMesh, FemLoads, HexElement, HexMesh, PlaneFemSettings, PlaneMesh,
    QuadElement,
};
use crate::material::constitutive::{lame, LinearElastic};
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::mpm::{Loads, MpmSettings, MpmSolver};
use crate::solver::dynamics::{BodyForce, LoadHistory, MassMatrix, Newmark};
use crate::solver::error::{require_count, require_positive, InputError};
use crate::solver::linear::LinearSolver;
use crate::solver::load_stepping::{steps_and_failure, LoadStepping};
use crate::solver::newton::NewtonSettings;
use nalgebra::SVector;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The methods that solve the dynamic manufactured problem.
pub const METHODS: [Method; Method::FAMILIES + 2] = super::manufactured::METHODS;

/// One dynamic manufactured analysis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicManufacturedSpec {
    pub field: Field,
    /// A of the axis-aligned field or θ₀ (radians) of the vortex: the peak amplitude.
    pub amplitude: f64,
    pub young_modulus: f64,
    pub poisson_ratio: f64,
    /// ρ₀, mass per unit reference volume.
    pub density: f64,
    /// Cells along each side of the unit square: h = 1 / cells.
    pub cells: usize,
    /// Material points per cell along each axis; Gauss points per axis of the elements are
    /// the element's (2 for Q4, 3 for Q8).
    pub points_per_cell: usize,
    /// Time steps per period T = 2/c of the forcing.
    pub steps_per_period: usize,
    /// Simulated time in periods.
    pub periods: f64,
    pub beta: f64,
    pub gamma: f64,
    pub mass: MassMatrix,
    pub newton: NewtonSettings,
    /// Generalised-α's spectral radius ρ∞ instead of `beta`, `gamma`
    /// ([`crate::solver::dynamics::GeneralizedAlpha`]); not serialised when absent (Newmark cases keep
    /// their keys).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rho_infinity: Option<f64>,
    pub domain_update: DomainUpdate,
    /// 2 (the unit square, plane strain) or 3 (the unit cube). Not serialised at 2.
    #[serde(default = "plane", skip_serializing_if = "is_plane")]
    pub dimension: usize,
}

fn plane() -> usize {
    2
}

fn is_plane(d: &usize) -> bool {
    *d == 2
}

impl Default for DynamicManufacturedSpec {
    /// The axis-aligned field at A = 0.05 (F_xx from 0.84 to 1.16), E = ρ₀ = 1 (c = 1, T = 2),
    /// ν = 0.3, 8 × 8 cells of 2 × 2 points, 32 steps per period over 5/8 of a period (the end
    /// at ωt = 5π/4, where both a(t) and ȧ(t) are non-zero, so that a phase error shows in the
    /// displacement at first order), trapezoidal rule, consistent mass.
    fn default() -> Self {
        DynamicManufacturedSpec {
            field: Field::AxisAligned,
            amplitude: 0.05,
            young_modulus: 1.0,
            poisson_ratio: 0.3,
            density: 1.0,
            cells: 8,
            points_per_cell: 2,
            steps_per_period: 32,
            periods: 0.625,
            beta: 0.25,
            gamma: 0.5,
            mass: MassMatrix::Consistent,
            newton: NewtonSettings::default(),
            rho_infinity: None,
            domain_update: DomainUpdate::Stretch,
            dimension: 2,
        }
    }
}

impl DynamicManufacturedSpec {
    pub fn validate(&self) -> Result<(), InputError> {
        require_positive("young_modulus", self.young_modulus)?;
        require_positive("density", self.density)?;
        require_count("cells", self.cells, 1)?;
        // 1024² cells are 4e6 points at 2 × 2 per cell; 128³ are 1.7e7 at 2 × 2 × 2.
        let max_cells = if self.dimension == 3 { 128 } else { 1024 };
        if self.cells > max_cells {
            return Err(InputError::new(
                "cells",
                self.cells,
                format!("must be <= {max_cells} in {}D", self.dimension),
            ));
        }
        // Points per cell, the amplitude's range, the dimension and the material: the static
        // field's checks (below).
        require_count("steps_per_period", self.steps_per_period, 1)?;
        require_positive("periods", self.periods)?;
        // The step count first: the static spec's checks read it as `load_steps`.
        crate::solver::load_stepping::require_time_steps("periods", self.periods, self.steps_per_period)?;
        self.static_spec().validate()?;
        crate::solver::load_stepping::require_time_scales(
            ("periods", self.periods),
            self.steps_per_period,
            self.period(),
            ("density", self.density, "(T = 2/c, c = √(E/ρ0))"),
        )?;
        self.newmark().validate()
    }

    /// Wave speed c = √(E/ρ₀).
    pub fn wave_speed(&self) -> f64 {
        (self.young_modulus / self.density).sqrt()
    }

    /// ω = πc (Wallstedt & Guilkey's sin(cπt)).
    pub fn omega(&self) -> f64 {
        PI * self.wave_speed()
    }

    /// T = 2π/ω.
    pub fn period(&self) -> f64 {
        2.0 * PI / self.omega()
    }

    /// The end time, `periods` × T.
    pub fn duration(&self) -> f64 {
        self.periods * self.period()
    }

    pub fn time_steps(&self) -> usize {
        (self.periods * self.steps_per_period as f64).round().max(1.0) as usize
    }

    pub fn element_size(&self) -> f64 {
        1.0 / self.cells as f64
    }

    /// The static spec of the same field at the peak amplitude (for validation and the
    /// static field's functions).
    fn static_spec(&self) -> super::manufactured::ManufacturedSpec {
        super::manufactured::ManufacturedSpec {
            field: self.field,
            amplitude: self.amplitude,
            young_modulus: self.young_modulus,
            poisson_ratio: self.poisson_ratio,
            cells: self.cells,
            points_per_cell: self.points_per_cell,
            load_steps: self.time_steps(),
            newton: self.newton,
            domain_update: self.domain_update,
            dimension: self.dimension,
        }
    }

    /// The methods of this spec's dimension.
    pub fn methods(&self) -> &'static [Method] {
        if self.dimension == 3 {
            &METHODS_3D
        } else {
            &METHODS
        }
    }

    pub fn newmark(&self) -> Newmark {
        Newmark {
            duration: self.duration(),
            beta: self.beta,
            gamma: self.gamma,
            mass: self.mass,
            load: LoadHistory::None,
            rho_infinity: self.rho_infinity,
        }
    }
}

/// The exact motion of one spec in time.
#[derive(Debug, Clone, Copy)]
pub struct ExactMotion {
    pub field: Field,
    /// Peak amplitude A.
    pub amplitude: f64,
    pub omega: f64,
    pub density: f64,
    pub lambda: f64,
    pub mu: f64,
}

impl ExactMotion {
    pub fn of(spec: &DynamicManufacturedSpec) -> Self {
        let (lambda, mu) = lame(spec.young_modulus, spec.poisson_ratio);
        ExactMotion {
            field: spec.field,
            amplitude: spec.amplitude,
            omega: spec.omega(),
            density: spec.density,
            lambda,
            mu,
        }
    }

    /// (a, ȧ, ä) at t: a = A sin ωt.
    pub fn amplitude_at(&self, t: f64) -> (f64, f64, f64) {
        let (s, c) = (self.omega * t).sin_cos();
        let a = self.amplitude;
        (a * s, a * self.omega * c, -a * self.omega * self.omega * s)
    }

    /// The static field at time t (position, stresses, Div P at amplitude a(t)).
    pub fn at(&self, t: f64) -> Exact {
        Exact {
            field: self.field,
            amplitude: self.amplitude_at(t).0,
            lambda: self.lambda,
            mu: self.mu,
        }
    }

    /// ∂x/∂a and ∂²x/∂a² at X for amplitude a.
    fn amplitude_derivatives(&self, a: f64, x: [f64; 2]) -> ([f64; 2], [f64; 2]) {
        match self.field {
            Field::AxisAligned => ([(PI * x[0]).sin(), (PI * x[1]).sin()], [0.0, 0.0]),
            Field::Vortex => {
                let y = [x[0] - 0.5, x[1] - 0.5];
                let r2 = y[0] * y[0] + y[1] * y[1];
                let shape = if r2 >= 0.25 { 0.0 } else { (1.0 - 4.0 * r2).powi(3) };
                let (s, c) = (a * shape).sin_cos();
                // x = c + R(φ) y, φ = a θ̂: ∂x/∂a = R'(φ) y θ̂, ∂²x/∂a² = −R(φ) y θ̂².
                let dr = [-s * y[0] - c * y[1], c * y[0] - s * y[1]];
                let r = [c * y[0] - s * y[1], s * y[0] + c * y[1]];
                (
                    [dr[0] * shape, dr[1] * shape],
                    [-r[0] * shape * shape, -r[1] * shape * shape],
                )
            }
        }
    }

    /// ∂x/∂a along z at Z (3D fields; ∂²x/∂a² is zero there): the axis-aligned field moves z
    /// as x and y, the vortex about z not at all.
    fn amplitude_derivative_z(&self, z: f64) -> f64 {
        match self.field {
            Field::AxisAligned => (PI * z).sin(),
            Field::Vortex => 0.0,
        }
    }

    /// (ẋ, ẍ) at X, t in D = 2 or 3 dimensions.
    pub fn motion_rates<const D: usize>(
        &self,
        x: &SVector<f64, D>,
        t: f64,
    ) -> (SVector<f64, D>, SVector<f64, D>) {
        let (a, da, dda) = self.amplitude_at(t);
        let (d1, d2) = self.amplitude_derivatives(a, [x[0], x[1]]);
        let mut v = SVector::<f64, D>::zeros();
        let mut acc = SVector::<f64, D>::zeros();
        for i in 0..2 {
            v[i] = d1[i] * da;
            acc[i] = d2[i] * da * da + d1[i] * dda;
        }
        if D == 3 {
            let dz = self.amplitude_derivative_z(x[2]);
            v[2] = dz * da;
            acc[2] = dz * dda;
        }
        (v, acc)
    }

    /// The 3D field at time t (position, stresses, −Div P at amplitude a(t)).
    pub fn at_3d(&self, t: f64) -> Exact3 {
        Exact3 {
            field: self.field,
            amplitude: self.amplitude_at(t).0,
            lambda: self.lambda,
            mu: self.mu,
        }
    }

    /// b₀(X, t) = ρ₀ ẍ − Div P per unit reference volume, in D = 2 or 3 dimensions.
    pub fn body_force_at<const D: usize>(&self, x: &SVector<f64, D>, t: f64) -> SVector<f64, D> {
        let acc = self.motion_rates(x, t).1;
        let minus_div: SVector<f64, D> = if D == 3 {
            let b = self.at_3d(t).body_force([x[0], x[1], x[2]]);
            SVector::<f64, D>::from_fn(|i, _| b[i])
        } else {
            let d = self.at(t).div_first_piola([x[0], x[1]]);
            SVector::<f64, D>::from_fn(|i, _| -d[i])
        };
        acc * self.density + minus_div
    }

    /// The body force as the solvers take it.
    pub fn body_force_field<const D: usize>(&self) -> BodyForce<D> {
        let m = *self;
        BodyForce::new(move |x, t| m.body_force_at(x, t))
    }
}

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
    let model = Box::new(LinearElastic::try_new(spec.young_modulus, spec.poisson_ratio)?);
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
    };
    let model = Box::new(LinearElastic::try_new(spec.young_modulus, spec.poisson_ratio)?);
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
            (r, super::manufactured3d::gauss_values_3d(&f))
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

#[cfg(test)]
mod tests {
    use super::*;

    /// ẋ and ẍ of the closed forms against central differences of x(X, t) in t, and the body
    /// force's inertia part with them, for both fields at points inside and outside the
    /// vortex's core.
    #[test]
    fn velocity_and_acceleration_are_the_time_derivatives_of_the_motion() {
        for field in [Field::AxisAligned, Field::Vortex] {
            let spec = DynamicManufacturedSpec {
                field,
                amplitude: if field == Field::Vortex { 0.6 } else { 0.05 },
                ..Default::default()
            };
            let m = ExactMotion::of(&spec);
            let dt = 1e-4;
            for x in [[0.3, 0.4], [0.55, 0.62], [0.9, 0.1], [0.5, 0.5]] {
                for t in [0.0, 0.37, 1.1] {
                    let pos = |t: f64| m.at(t).position(x);
                    let (p0, pm, pp) = (pos(t), pos(t - dt), pos(t + dt));
                    let (v, a) = m.motion_rates(&SVector::<f64, 2>::from(x), t);
                    for i in 0..2 {
                        let fd_v = (pp[i] - pm[i]) / (2.0 * dt);
                        let fd_a = (pp[i] - 2.0 * p0[i] + pm[i]) / (dt * dt);
                        assert!(
                            (fd_v - v[i]).abs() < 1e-7,
                            "{field:?} v {x:?} {t}: {fd_v} vs {}",
                            v[i]
                        );
                        assert!(
                            (fd_a - a[i]).abs() < 1e-5,
                            "{field:?} a {x:?} {t}: {fd_a} vs {}",
                            a[i]
                        );
                    }
                }
            }
        }
    }

    /// At t = 0 the body is undeformed, so b₀ = ρ₀ ẍ: the initial acceleration the solvers
    /// are given balances the load exactly.
    #[test]
    fn the_initial_load_is_the_initial_inertia() {
        let spec = DynamicManufacturedSpec {
            field: Field::Vortex,
            amplitude: 0.6,
            density: 2.0,
            ..Default::default()
        };
        let m = ExactMotion::of(&spec);
        for x in [[0.3, 0.4], [0.55, 0.62]] {
            let x = SVector::<f64, 2>::from(x);
            let (b, a) = (m.body_force_at(&x, 0.0), m.motion_rates(&x, 0.0).1);
            for i in 0..2 {
                assert!((b[i] - 2.0 * a[i]).abs() < 1e-12, "{b:?} {a:?}");
            }
            assert!(
                a.iter().any(|v| v.abs() > 1e-3),
                "the vortex's centripetal a0 vanished"
            );
        }
    }

    #[test]
    fn bad_inputs_name_their_key() {
        let bad = |f: &dyn Fn(&mut DynamicManufacturedSpec), key: &str| {
            let mut s = DynamicManufacturedSpec::default();
            f(&mut s);
            let e = s.validate().unwrap_err().to_string();
            assert!(e.contains(key), "{e}");
        };
        bad(&|s| s.density = 0.0, "density");
        bad(&|s| s.density = -1.0, "density");
        bad(&|s| s.periods = 0.0, "periods");
        bad(&|s| s.steps_per_period = 0, "steps_per_period");
        bad(&|s| s.beta = 0.7, "dynamics.beta");
        bad(&|s| s.gamma = 0.3, "dynamics.gamma");
        bad(&|s| s.amplitude = 0.5, "amplitude");
    }
}
