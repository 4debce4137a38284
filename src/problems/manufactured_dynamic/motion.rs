//! The exact motion of a dynamic manufactured analysis in time, and its body force.

use super::spec::DynamicManufacturedSpec;
use crate::problems::manufactured::{Exact, Field};
use crate::problems::manufactured3d::Exact3;
use crate::solver::dynamics::BodyForce;
use nalgebra::SVector;
use std::f64::consts::PI;

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
        let (lambda, mu) = spec.static_spec().lame();
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
}
