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

/// Euclidean norm of the concatenation of `parts`, without overflow or underflow: the plain
/// sum of squares where it is a normal float (bit for bit the textbook formula, so results in
/// the usual range are unchanged), else rescaled by the largest magnitude (as LAPACK's
/// `dnrm2`). Forces of a model with E = 1e-300 square to below the smallest float, and the
/// plain formula then reports a zero norm: a load step "converged" at zero displacement with
/// 100 % error (measured with the manufactured vortex before this rule).
pub fn l2_of(parts: &[&[f64]]) -> f64 {
    let s: f64 = parts.iter().flat_map(|p| p.iter()).map(|x| x * x).sum();
    if s.is_normal() {
        return s.sqrt();
    }
    let m =
        parts
            .iter()
            .flat_map(|p| p.iter())
            .fold(0.0f64, |m, x| if x.abs() > m || x.is_nan() { x.abs() } else { m });
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    let t: f64 = parts
        .iter()
        .flat_map(|p| p.iter())
        .map(|x| (x / m) * (x / m))
        .sum();
    m * t.sqrt()
}

/// [`l2_of`] of one vector.
pub fn l2(v: &[f64]) -> f64 {
    l2_of(&[v])
}

#[cfg(test)]
mod l2_tests {
    use super::*;

    #[test]
    fn l2_is_exact_in_range_and_finite_at_the_extremes() {
        let v = [3.0, 4.0, 12.0];
        assert_eq!(l2(&v), 13.0);
        let plain = (0.1f64 * 0.1 + 0.7 * 0.7).sqrt();
        assert_eq!(l2(&[0.1, 0.7]), plain, "bit for bit the plain formula in range");
        for scale in [1e-300, 1e-200, 1e200, 1e300] {
            let w: Vec<f64> = v.iter().map(|x| x * scale).collect();
            let r = l2(&w) / (13.0 * scale);
            assert!((r - 1.0).abs() < 1e-14, "scale {scale}: {r}");
        }
        assert_eq!(l2(&[]), 0.0);
        assert_eq!(l2(&[0.0, 0.0]), 0.0);
        assert!(l2(&[1.0, f64::NAN]).is_nan());
        assert_eq!(l2_of(&[&[3e-300], &[4e-300]]) / 5e-300, 1.0);
    }
}
