//! Vector norms of residuals and loads.

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
