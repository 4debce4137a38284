//! The error measures of a converged analysis against the exact solution.

use super::exact::Exact;
use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};

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
