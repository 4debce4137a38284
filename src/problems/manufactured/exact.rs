//! The manufactured motions, their Hencky stresses and the body force −Div P (forward-mode
//! automatic differentiation).

use super::spec::{Field, ManufacturedSpec};
use nalgebra::Matrix3;
use num_dual::{Dual64, DualNum};
use std::f64::consts::PI;

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
/// ([`kirchhoff`]); the 3D manufactured fields ([`crate::problems::manufactured3d`]) have this form.
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
        let (lambda, mu) = spec.lame();
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
