//! The one checks module: a claim of the paper or a study file measured against the results
//! ([`CheckRecord`]), and the measures checks are made of — bounded deviations and spreads,
//! fitted convergence rates in a band, Richardson extrapolation — for every study kind.

use serde::{Deserialize, Serialize};

/// A claim of the paper or the issue, checked against the results.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CheckRecord {
    /// Short identifier, e.g. `fig17-within-1pc`.
    pub id: String,
    /// What is checked, in one sentence.
    pub description: String,
    /// The measured quantity compared with `limit` (e.g. a largest relative difference).
    pub measured: Option<f64>,
    pub limit: f64,
    /// `None`: could not be evaluated (e.g. the cases it needs were rejected or not run).
    pub pass: Option<bool>,
    pub source: String,
}

/// A check whose measured value must not exceed `limit`; not evaluated without a value.
pub fn check_at_most(
    id: &str,
    description: String,
    measured: Option<f64>,
    limit: f64,
    source: &str,
) -> CheckRecord {
    CheckRecord {
        id: id.to_string(),
        description,
        measured,
        limit,
        pass: measured.map(|m| m <= limit),
        source: source.to_string(),
    }
}

/// A fitted rate that must lie in `rate ± tolerance`: measured is |slope − rate|, the limit
/// the tolerance; not evaluated without a slope.
pub fn check_rate(
    id: &str,
    what: &str,
    slope: Option<f64>,
    rate: f64,
    tolerance: f64,
    source: &str,
) -> CheckRecord {
    check_at_most(
        id,
        format!(
            "{what}: fitted slope {} within {rate} ± {tolerance} (measured: abs(slope − {rate}))",
            slope.map_or("—".to_string(), |s| format!("{s:.3}"))
        ),
        slope.map(|s| (s - rate).abs()),
        tolerance,
        source,
    )
}

/// (passed, failed, not evaluated).
pub fn check_counts(checks: &[CheckRecord]) -> (usize, usize, usize) {
    let mut n = (0, 0, 0);
    for c in checks {
        match c.pass {
            Some(true) => n.0 += 1,
            Some(false) => n.1 += 1,
            None => n.2 += 1,
        }
    }
    n
}

/// Least-squares slope of log(error) against log(h) ([`crate::norms::fitted_rate`]) over
/// the last `finest` of the (h, error) pairs given coarse to fine; `None` with fewer than two
/// pairs. Returns the slope and how many pairs it used.
pub fn fitted_rate_finest(h: &[f64], error: &[f64], finest: Option<usize>) -> (Option<f64>, usize) {
    let n = finest.map_or(h.len(), |n| n.min(h.len()));
    let (h, e) = (&h[h.len() - n..], &error[error.len() - n..]);
    (crate::norms::fitted_rate(h, e), n)
}

/// (max − min)/|min| of at least two values, the spread of a sensitivity check.
pub fn relative_spread(u: &[f64]) -> Option<f64> {
    if u.len() < 2 {
        return None;
    }
    let (lo, hi) = u
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
    Some((hi - lo) / lo.abs())
}

/// Richardson extrapolation of three values on meshes refined by a constant ratio r
/// (coarse to fine): (limit, observed order). `None` if the differences do not shrink.
pub fn richardson(values: [f64; 3], ratio: f64) -> Option<(f64, f64)> {
    let (d1, d2) = (values[1] - values[0], values[2] - values[1]);
    if d1 == 0.0 || d2 == 0.0 || d1.signum() != d2.signum() || d2.abs() >= d1.abs() {
        return None;
    }
    let p = (d1 / d2).ln() / ratio.ln();
    Some((values[2] + d2 / (ratio.powf(p) - 1.0), p))
}

/// The largest growth from one value to the next of a sequence ordered coarse to fine (a
/// distance to a reference that must not grow under refinement); `None` with fewer than two.
pub fn largest_growth(values: &[f64]) -> Option<f64> {
    values.windows(2).map(|w| w[1] - w[0]).reduce(f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn richardson_recovers_a_known_limit_and_order() {
        // u(h) = 2 + 3 h^2 at h = 1, 1/2, 1/4.
        let (limit, p) = richardson([5.0, 2.75, 2.1875], 2.0).unwrap();
        assert!((limit - 2.0).abs() < 1e-12 && (p - 2.0).abs() < 1e-12);
        assert!(richardson([1.0, 2.0, 1.5], 2.0).is_none());
    }

    #[test]
    fn rate_checks_pass_inside_the_band_only() {
        assert_eq!(check_rate("r", "x", Some(1.9), 2.0, 0.2, "s").pass, Some(true));
        assert_eq!(check_rate("r", "x", Some(1.7), 2.0, 0.2, "s").pass, Some(false));
        assert_eq!(check_rate("r", "x", None, 2.0, 0.2, "s").pass, None);
        let (s, n) = fitted_rate_finest(&[1.0, 0.5, 0.25], &[9.0, 1.0, 0.25], Some(2));
        assert_eq!(n, 2);
        assert!((s.unwrap() - 2.0).abs() < 1e-12);
    }

    #[test]
    fn growth_and_spread() {
        assert!((largest_growth(&[0.3, 0.1, 0.15]).unwrap() - 0.05).abs() < 1e-15);
        assert_eq!(largest_growth(&[0.3]), None);
        assert!((relative_spread(&[1.1, 1.0]).unwrap() - 0.1).abs() < 1e-15);
        assert_eq!(relative_spread(&[1.0]), None);
    }
}
