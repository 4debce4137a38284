//! Manufactured solutions in plane strain: the material fills the unit square Ω₀ = [0, 1]²,
//! which is also the background grid (or the FEM mesh), so no cell is ever partly filled and
//! the errors isolate the interior discretisation and cell crossing.
//!
//! Two motions x(X), Hencky elasticity (the library's [`LinearElastic`]: τ = λ tr(ε) I + 2μ ε,
//! ε = ½ ln b, plane strain):
//! - **axis-aligned**: x = X + A (sin πX, sin πY), F diagonal;
//! - **vortex**: x = c + R(θ(r)) (X − c), c = (½, ½), r = |X − c|, θ = θ₀ (1 − 4r²)³ for r ≤ ½
//!   and 0 outside: isochoric (det F = 1), rotation up to θ₀.
//!
//! The dead body force per unit reference volume is b₀ = −Div P (P = τ F⁻ᵀ), computed by
//! forward-mode automatic differentiation of P(F(X)) ([`num_dual`]), carried by the material
//! points (Gauss points) with their initial volume and mapped like gravity (eq 40), ramped over
//! the load steps: at the full load the manufactured field is the exact solution.
//!
//! Boundary conditions: rollers on every edge (the normal displacement fixed). Both motions
//! satisfy them exactly and have no tangential traction there: the axis-aligned P is diagonal,
//! and the vortex has F = I near the whole boundary. Fixing every boundary node, as first
//! specified, would contradict the axis-aligned field (u_y = A sin πY ≠ 0 on X = 0);
//! reference/README.md records the correction.

use crate::basis::method::Method;
use crate::basis::Basis;
use crate::fem::{ElementFamily, PlaneFem, PlaneFemSettings, PlaneLoads, PlaneMesh, QuadElement};
use crate::material::constitutive::{lame, LinearElastic};
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::mpm::{DomainUpdate, Loads, MpmSettings, MpmSolver};
use crate::solver::error::{require_count, require_positive, InputError, SolveError};
use crate::solver::linear::LinearSolver;
use crate::solver::load_stepping::{steps_and_failure, LoadStepping, StepReport};
use crate::solver::newton::NewtonSettings;
use nalgebra::{Matrix3, SVector};
use num_dual::{Dual64, DualNum};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Which manufactured motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Field {
    /// x = X + A (sin πX, sin πY).
    AxisAligned,
    /// x = c + R(θ(r)) (X − c), θ = θ₀ (1 − 4r²)³ inside r ≤ ½.
    Vortex,
}

impl Field {
    pub fn name(self) -> &'static str {
        match self {
            Field::AxisAligned => "axis-aligned",
            Field::Vortex => "vortex",
        }
    }
}

/// The methods that solve the manufactured problem.
pub const METHODS: [Method; Method::FAMILIES + 2] = Method::listed(Some(2), &[]);

/// One manufactured-solution analysis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ManufacturedSpec {
    pub field: Field,
    /// A of the axis-aligned field or θ₀ (radians) of the vortex.
    pub amplitude: f64,
    pub young_modulus: f64,
    pub poisson_ratio: f64,
    /// Cells (elements) along each side of the unit square: h = 1 / cells.
    pub cells: usize,
    /// Material points per cell along each axis (MPM, iGIMP).
    pub points_per_cell: usize,
    pub load_steps: usize,
    pub newton: NewtonSettings,
    /// Domain update of iGIMP (MPM has no domains; ignored by FEM).
    pub domain_update: DomainUpdate,
    /// 2 (the unit square, plane strain) or 3 (the unit cube,
    /// [`super::manufactured3d::solve_3d`]). Not serialised at 2, so that the case hashes of
    /// the plane study stay as they were.
    #[serde(default = "plane", skip_serializing_if = "is_plane")]
    pub dimension: usize,
}

fn plane() -> usize {
    2
}

fn is_plane(d: &usize) -> bool {
    *d == 2
}

impl Default for ManufacturedSpec {
    fn default() -> Self {
        Self {
            field: Field::AxisAligned,
            amplitude: 0.1,
            young_modulus: 1.0,
            poisson_ratio: 0.3,
            cells: 8,
            points_per_cell: 2,
            load_steps: 10,
            newton: NewtonSettings::default(),
            domain_update: DomainUpdate::Stretch,
            dimension: 2,
        }
    }
}

impl ManufacturedSpec {
    pub fn validate(&self) -> Result<(), InputError> {
        require_positive("young_modulus", self.young_modulus)?;
        require_count("cells", self.cells, 1)?;
        require_count("points_per_cell", self.points_per_cell, 1)?;
        if !matches!(self.dimension, 2 | 3) {
            return Err(InputError::new("dimension", self.dimension, "must be 2 or 3"));
        }
        // 3D: 256³ cells are 1.7e7 cells, beyond what the direct solver holds.
        let max_cells = if self.dimension == 3 { 256 } else { 4096 };
        if self.cells > max_cells {
            return Err(InputError::new(
                "cells",
                self.cells,
                format!("must be <= {max_cells} in {}D", self.dimension),
            ));
        }
        if self.points_per_cell > 8 {
            return Err(InputError::new(
                "points_per_cell",
                self.points_per_cell,
                "must be <= 8",
            ));
        }
        let max_amplitude = match self.field {
            // F_xx = 1 + Aπ cos πX must stay positive.
            Field::AxisAligned => 1.0 / PI,
            Field::Vortex => PI,
        };
        let key = match self.field {
            Field::AxisAligned => "amplitude.axis_aligned",
            Field::Vortex => "amplitude.vortex",
        };
        if self.amplitude == 0.0 {
            // The undeformed body: every error is zero and no rate can be fitted.
            return Err(InputError::new(
                key,
                self.amplitude,
                "must not be 0 (the field would leave the body undeformed: every error 0, no rate)",
            ));
        }
        if !(self.amplitude.is_finite() && self.amplitude.abs() < max_amplitude) {
            return Err(InputError::new(
                key,
                self.amplitude,
                format!(
                    "must be finite with |amplitude| < {max_amplitude:.4} for {}",
                    self.field.name()
                ),
            ));
        }
        crate::fem::validate_stepping(&self.newton, self.load_steps)?;
        self.newton.validate()?;
        LinearElastic::try_new(self.young_modulus, self.poisson_ratio)?;
        Ok(())
    }

    pub fn element_size(&self) -> f64 {
        1.0 / self.cells as f64
    }
}

/// A 2×2 matrix of (dual) numbers, row-major.
pub type M2<T> = [[T; 2]; 2];

/// θ(r²) of the vortex: θ₀ (1 − 4r²)³ for r² < ¼, else 0 (smooth to second order at r = ½).
fn vortex_angle<T: DualNum<Primitive = f64> + Copy>(theta0: f64, r2: T) -> T {
    if r2.re() >= 0.25 {
        T::zero()
    } else {
        (T::one() - r2 * 4.0).powi(3) * theta0
    }
}

/// The manufactured motion x(X).
pub fn motion<T: DualNum<Primitive = f64> + Copy>(field: Field, a: f64, x: [T; 2]) -> [T; 2] {
    match field {
        Field::AxisAligned => [x[0] + (x[0] * PI).sin() * a, x[1] + (x[1] * PI).sin() * a],
        Field::Vortex => {
            let y = [x[0] - 0.5, x[1] - 0.5];
            let th = vortex_angle(a, y[0] * y[0] + y[1] * y[1]);
            let (s, c) = (th.sin(), th.cos());
            [c * y[0] - s * y[1] + 0.5, s * y[0] + c * y[1] + 0.5]
        }
    }
}

/// F = ∂x/∂X in closed form (checked against automatic differentiation of [`motion`]).
pub fn deformation_gradient<T: DualNum<Primitive = f64> + Copy>(field: Field, a: f64, x: [T; 2]) -> M2<T> {
    match field {
        Field::AxisAligned => [
            [(x[0] * PI).cos() * (a * PI) + 1.0, T::zero()],
            [T::zero(), (x[1] * PI).cos() * (a * PI) + 1.0],
        ],
        Field::Vortex => {
            let y = [x[0] - 0.5, x[1] - 0.5];
            let r2 = y[0] * y[0] + y[1] * y[1];
            let th = vortex_angle(a, r2);
            let (s, c) = (th.sin(), th.cos());
            // ∇θ = θ'(r²) 2y, θ'(r²) = −12 θ₀ (1 − 4r²)².
            let g = if r2.re() >= 0.25 {
                T::zero()
            } else {
                (T::one() - r2 * 4.0).powi(2) * (-24.0 * a)
            };
            let grad = [y[0] * g, y[1] * g];
            // F = R + (dR/dθ) y ⊗ ∇θ, dR/dθ y = (−s y0 − c y1, c y0 − s y1).
            let ry = [-(s * y[0]) - c * y[1], c * y[0] - s * y[1]];
            [
                [c + ry[0] * grad[0], -s + ry[0] * grad[1]],
                [s + ry[1] * grad[0], c + ry[1] * grad[1]],
            ]
        }
    }
}

/// atanh(√s)/√s, smooth in s ≥ 0 (series below 10⁻³, truncation < 10⁻¹⁸).
fn atanh_sqrt_over_sqrt<T: DualNum<Primitive = f64> + Copy>(s: T) -> T {
    if s.re() < 1e-3 {
        T::one()
            + s * (1.0 / 3.0)
            + s.powi(2) * 0.2
            + s.powi(3) * (1.0 / 7.0)
            + s.powi(4) * (1.0 / 9.0)
            + s.powi(5) * (1.0 / 11.0)
    } else {
        let r = s.sqrt();
        r.atanh() / r
    }
}

/// Kirchhoff stress of Hencky elasticity in plane strain: the in-plane block and τ_zz.
///
/// ln b of the symmetric 2×2 b = F Fᵀ is α I + β b with β = atanh(t)/(t m), t = g/m (m the
/// mean and g the half-gap of the eigenvalues) and α = ½ ln det b − β m: the same as the
/// spectral form, smooth where the eigenvalues coincide (F = I), so it differentiates there.
pub fn kirchhoff<T: DualNum<Primitive = f64> + Copy>(f: &M2<T>, lambda: f64, mu: f64) -> (M2<T>, T) {
    kirchhoff_block(f, T::one(), lambda, mu)
}

/// Kirchhoff stress of Hencky elasticity for F = diag(F₂, f₃₃) (an in-plane block and a
/// stretch along z): the in-plane block of τ and τ_zz. Plane strain is f₃₃ = 1
/// ([`kirchhoff`]); the 3D manufactured fields ([`super::manufactured3d`]) have this form.
pub fn kirchhoff_block<T: DualNum<Primitive = f64> + Copy>(
    f: &M2<T>,
    f33: T,
    lambda: f64,
    mu: f64,
) -> (M2<T>, T) {
    let b00 = f[0][0] * f[0][0] + f[0][1] * f[0][1];
    let b01 = f[0][0] * f[1][0] + f[0][1] * f[1][1];
    let b11 = f[1][0] * f[1][0] + f[1][1] * f[1][1];
    let m = (b00 + b11) * 0.5;
    let d = (b00 - b11) * 0.5;
    let q = d * d + b01 * b01;
    let det = b00 * b11 - b01 * b01;
    let beta = atanh_sqrt_over_sqrt(q / (m * m)) / m;
    let alpha = det.ln() * 0.5 - beta * m;
    // ε = ½ ln b.
    let e00 = (alpha + beta * b00) * 0.5;
    let e11 = (alpha + beta * b11) * 0.5;
    let e01 = beta * b01 * 0.5;
    let e33 = f33.ln();
    let tr = (e00 + e11 + e33) * lambda;
    (
        [
            [tr + e00 * (2.0 * mu), e01 * (2.0 * mu)],
            [e01 * (2.0 * mu), tr + e11 * (2.0 * mu)],
        ],
        tr + e33 * (2.0 * mu),
    )
}

/// First Piola–Kirchhoff stress P = τ F⁻ᵀ (in-plane).
pub fn first_piola<T: DualNum<Primitive = f64> + Copy>(f: &M2<T>, lambda: f64, mu: f64) -> M2<T> {
    first_piola_block(f, T::one(), lambda, mu).0
}

/// P = τ F⁻ᵀ for F = diag(F₂, f₃₃): the in-plane block and P_zz = τ_zz / f₃₃.
pub fn first_piola_block<T: DualNum<Primitive = f64> + Copy>(
    f: &M2<T>,
    f33: T,
    lambda: f64,
    mu: f64,
) -> (M2<T>, T) {
    let (tau, tzz) = kirchhoff_block(f, f33, lambda, mu);
    let j = f[0][0] * f[1][1] - f[0][1] * f[1][0];
    // F⁻¹ = adj(F) / J; P_iJ = Σ_K τ_iK (F⁻¹)_JK.
    let inv = [[f[1][1] / j, -f[0][1] / j], [-f[1][0] / j, f[0][0] / j]];
    let mut p = [[T::zero(); 2]; 2];
    for i in 0..2 {
        for jj in 0..2 {
            p[i][jj] = tau[i][0] * inv[jj][0] + tau[i][1] * inv[jj][1];
        }
    }
    (p, tzz / f33)
}

/// The exact solution of one spec: motion, stresses and body force at a reference point.
#[derive(Debug, Clone, Copy)]
pub struct Exact {
    pub field: Field,
    pub amplitude: f64,
    pub lambda: f64,
    pub mu: f64,
}

impl Exact {
    pub fn of(spec: &ManufacturedSpec) -> Self {
        let (lambda, mu) = lame(spec.young_modulus, spec.poisson_ratio);
        Exact {
            field: spec.field,
            amplitude: spec.amplitude,
            lambda,
            mu,
        }
    }

    pub fn position(&self, x: [f64; 2]) -> [f64; 2] {
        motion(self.field, self.amplitude, x)
    }

    /// First Piola–Kirchhoff stress at X.
    pub fn first_piola(&self, x: [f64; 2]) -> M2<f64> {
        first_piola(
            &deformation_gradient(self.field, self.amplitude, x),
            self.lambda,
            self.mu,
        )
    }

    /// Cauchy stress σ = τ / det F at X (3×3, σ_zz from plane strain).
    pub fn cauchy(&self, x: [f64; 2]) -> Matrix3<f64> {
        let f = deformation_gradient(self.field, self.amplitude, x);
        let (tau, tzz) = kirchhoff(&f, self.lambda, self.mu);
        let j = f[0][0] * f[1][1] - f[0][1] * f[1][0];
        Matrix3::new(
            tau[0][0], tau[0][1], 0.0, tau[1][0], tau[1][1], 0.0, 0.0, 0.0, tzz,
        ) / j
    }

    /// Div P at X by forward-mode automatic differentiation: one dual evaluation per
    /// reference axis J gives ∂P_iJ/∂X_J.
    pub fn div_first_piola(&self, x: [f64; 2]) -> [f64; 2] {
        let mut div = [0.0; 2];
        for jj in 0..2 {
            let xd = [
                Dual64::new(x[0], if jj == 0 { 1.0 } else { 0.0 }),
                Dual64::new(x[1], if jj == 1 { 1.0 } else { 0.0 }),
            ];
            let p = first_piola(
                &deformation_gradient(self.field, self.amplitude, xd),
                self.lambda,
                self.mu,
            );
            for (i, d) in div.iter_mut().enumerate() {
                *d += p[i][jj].eps;
            }
        }
        div
    }

    /// The dead body force per unit reference volume, b₀ = −Div P.
    pub fn body_force(&self, x: [f64; 2]) -> [f64; 2] {
        let d = self.div_first_piola(x);
        [-d[0], -d[1]]
    }
}

/// One material (or Gauss) point at the end of the analysis, for the error measures and the
/// point files.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PointValue {
    /// Reference position X_p.
    pub x0: [f64; 2],
    /// Current position x_p.
    pub x: [f64; 2],
    /// Initial volume v_p0.
    pub volume0: f64,
    /// Cauchy stress (σxx, σyy, σxy, σzz).
    pub sigma: [f64; 4],
    /// Domain half-lengths (material points; zero for Gauss points), for the figures.
    pub half: [f64; 2],
}

/// The error measures of a converged analysis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Errors {
    /// ‖x_p − x(X_p)‖ / ‖u(X_p)‖, discrete L2 norms weighted by v_p0.
    pub displacement: f64,
    /// Σ_p ‖σ_p − σ(X_p)‖_F v_p0 / (σ_max |Ω₀|), the form of eq (46), σ_max the largest
    /// exact ‖σ(X_p)‖_F.
    pub stress: f64,
}

/// The error measures of `points` against the exact solution.
pub fn errors(exact: &Exact, points: &[PointValue]) -> Errors {
    let (deviation, smax) = stress_deviations(exact, points);
    let (mut num, mut den, mut serr, mut vol) = (0.0, 0.0, 0.0, 0.0);
    for (p, d) in points.iter().zip(&deviation) {
        let xe = exact.position(p.x0);
        let du = [p.x[0] - xe[0], p.x[1] - xe[1]];
        let u = [xe[0] - p.x0[0], xe[1] - p.x0[1]];
        num += p.volume0 * (du[0] * du[0] + du[1] * du[1]);
        den += p.volume0 * (u[0] * u[0] + u[1] * u[1]);
        serr += d * p.volume0;
        vol += p.volume0;
    }
    Errors {
        displacement: (num / den).sqrt(),
        stress: serr / (smax * vol),
    }
}

/// Each point's ‖σ_p − σ(X_p)‖_F (3×3, σ_zz included) and σ_max, the largest exact
/// ‖σ(X_p)‖_F: the summands and the scale of the stress measure.
pub fn stress_deviations(exact: &Exact, points: &[PointValue]) -> (Vec<f64>, f64) {
    let mut smax = 0.0_f64;
    let deviation = points
        .iter()
        .map(|p| {
            let se = exact.cauchy(p.x0);
            smax = smax.max(se.norm());
            Matrix3::new(
                p.sigma[0] - se[(0, 0)],
                p.sigma[2] - se[(0, 1)],
                0.0,
                p.sigma[2] - se[(1, 0)],
                p.sigma[1] - se[(1, 1)],
                0.0,
                0.0,
                0.0,
                p.sigma[3] - se[(2, 2)],
            )
            .norm()
        })
        .collect();
    (deviation, smax)
}

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
        linear_solver: LinearSolver::Lu,
        ghost: Default::default(),
        dynamics: None,
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
    let model = Box::new(LinearElastic::try_new(spec.young_modulus, spec.poisson_ratio)?);
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
        linear_solver: LinearSolver::Lu,
    };
    let model = Box::new(LinearElastic::try_new(spec.young_modulus, spec.poisson_ratio)?);
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
