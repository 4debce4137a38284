//! Error measures of the paper's convergence studies.

/// Dimensionless stress error, eq (46): Σ_p |σ(Z_p) − σ_p| v_p0 / (W L0).
///
/// `exact` and `computed` are Cauchy stresses at the points (or Gauss points), `volume0` their
/// initial volumes, `weight` the total weight W (force per unit area in 1D) and `length` L0.
pub fn stress_error(exact: &[f64], computed: &[f64], volume0: &[f64], weight: f64, length: f64) -> f64 {
    exact
        .iter()
        .zip(computed)
        .zip(volume0)
        .map(|((e, c), v)| (e - c).abs() * v)
        .sum::<f64>()
        / (weight * length)
}

/// Relative deformation-gradient error, eq (47): |F_p − F_(0)| / F_(0).
pub fn f_error(computed: f64, exact: f64) -> f64 {
    (computed - exact).abs() / exact.abs()
}

/// Least-squares slope of log(error) against log(h) (a convergence rate: error ∝ h^slope).
/// Returns `None` with fewer than two usable (positive, finite) points.
pub fn fitted_rate(h: &[f64], error: &[f64]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = h
        .iter()
        .zip(error)
        .filter(|(a, b)| **a > 0.0 && **b > 0.0 && a.is_finite() && b.is_finite())
        .map(|(a, b)| (a.ln(), b.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    if sxx == 0.0 {
        None
    } else {
        Some(sxy / sxx)
    }
}
