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

/// Newton converges quadratically: once a normalised residual is at most `small`, the next one
/// above `floor` is at most `constant` times its square, and where three successive residuals
/// qualify the observed order is at least 1.5 ([`crate::solver::newton::check_quadratic`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuadraticExpectation {
    pub small: f64,
    pub floor: f64,
    pub constant: f64,
    pub source: String,
}

/// The check `id` of `q` over `steps` (case id, step, its residual history; `what` and
/// `scope` word its description): measured is the
/// largest r_(k+1)/r_k² among the residuals it applies to; it fails on any violation, named
/// with its case and step, and is not evaluated where no step reached `small` twice.
pub fn check_newton_quadratic<'a>(
    id: &str,
    what: &str,
    scope: &str,
    steps: impl Iterator<Item = (&'a str, usize, &'a [f64])>,
    q: &QuadraticExpectation,
) -> CheckRecord {
    let mut worst: Option<f64> = None;
    let mut failure = None;
    for (case, step, residuals) in steps {
        match crate::solver::newton::check_quadratic(residuals, q.small, q.floor, q.constant, 1.5) {
            Ok(k) if k.ratio_checks > 0 => worst = Some(worst.unwrap_or(0.0).max(k.max_ratio)),
            Ok(_) => {}
            Err(m) => failure = failure.or(Some(format!("{case} step {step}: {m}"))),
        }
    }
    let mut rec = check_at_most(
        id,
        format!(
            "{what}: once r_k ≤ {:e}, r_(k+1) ≤ {} r_k² above {:e} and the observed order ≥ 1.5, every step of {scope} (measured: the largest r_(k+1)/r_k²{})",
            q.small,
            q.constant,
            q.floor,
            failure.as_ref().map_or(String::new(), |f| format!("; violated at {f}"))
        ),
        worst,
        q.constant,
        &q.source,
    );
    if failure.is_some() {
        rec.pass = Some(false);
    }
    rec
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

/// Least-squares slope of log(error) against log(h) ([`crate::problems::norms::fitted_rate`]) over
/// the last `finest` of the (h, error) pairs given coarse to fine; `None` with fewer than two
/// pairs. Returns the slope and how many pairs it used.
pub fn fitted_rate_finest(h: &[f64], error: &[f64], finest: Option<usize>) -> (Option<f64>, usize) {
    let n = finest.map_or(h.len(), |n| n.min(h.len()));
    let (h, e) = (&h[h.len() - n..], &error[error.len() - n..]);
    (crate::problems::norms::fitted_rate(h, e), n)
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

/// The grid convergence index of Celik et al. (2008, *J. Fluids Eng.* 130:078001) over three
/// levels: the observed order, the extrapolated value, the approximate and extrapolated
/// relative errors of the finest level, GCI_fine, and the asymptotic-range ratio.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Gci {
    /// Element sizes fine, medium, coarse (h1 < h2 < h3).
    pub h: [f64; 3],
    /// The solution on each (φ1, φ2, φ3).
    pub values: [f64; 3],
    /// Observed order p (the fixed point of Celik's eq 3 when the ratios differ).
    pub order: f64,
    /// φ_ext^21 = (r21^p φ1 − φ2) / (r21^p − 1).
    pub extrapolated: f64,
    /// e_a^21 = |(φ1 − φ2) / φ1|.
    pub approximate_error: f64,
    /// e_ext^21 = |(φ_ext − φ1) / φ_ext|.
    pub extrapolated_error: f64,
    /// GCI_fine^21 = 1.25 e_a^21 / (r21^p − 1).
    pub gci_fine: f64,
    /// GCI^32 / (r21^p GCI^21): 1 in the asymptotic range.
    pub asymptotic_ratio: f64,
    /// ε32/ε21 < 0: the solution oscillates with refinement (p is then an estimate at best).
    pub oscillatory: bool,
}

impl Gci {
    /// Within 10 % of the asymptotic range (|ratio − 1| <= 0.1) and not oscillatory.
    pub fn in_asymptotic_range(&self) -> bool {
        !self.oscillatory && (self.asymptotic_ratio - 1.0).abs() <= 0.1
    }
}

/// [`Gci`] of three (h, φ) levels in any order; `None` unless the sizes differ, the
/// differences are non-zero and an order can be found.
pub fn gci(levels: [(f64, f64); 3]) -> Option<Gci> {
    let mut l = levels;
    l.sort_by(|a, b| a.0.total_cmp(&b.0));
    let ([h1, h2, h3], [f1, f2, f3]) = ([l[0].0, l[1].0, l[2].0], [l[0].1, l[1].1, l[2].1]);
    let (r21, r32) = (h2 / h1, h3 / h2);
    let (e21, e32) = (f2 - f1, f3 - f2);
    if !(r21 > 1.0 && r32 > 1.0) || e21 == 0.0 || e32 == 0.0 || f1 == 0.0 || f2 == 0.0 {
        return None;
    }
    let s = (e32 / e21).signum();
    let mut p = (e32 / e21).abs().ln() / r21.ln();
    for _ in 0..100 {
        let q = ((r21.powf(p) - s) / (r32.powf(p) - s)).ln();
        let next = ((e32 / e21).abs().ln() + q).abs() / r21.ln();
        if !next.is_finite() {
            return None;
        }
        let done = (next - p).abs() <= 1e-12 * next.abs().max(1.0);
        p = next;
        if done {
            break;
        }
    }
    if !(p.is_finite() && p > 0.0) {
        return None;
    }
    let (a21, a32) = (r21.powf(p), r32.powf(p));
    let extrapolated = (a21 * f1 - f2) / (a21 - 1.0);
    let approximate_error = ((f1 - f2) / f1).abs();
    let gci_fine = 1.25 * approximate_error / (a21 - 1.0);
    let gci_32 = 1.25 * ((f2 - f3) / f2).abs() / (a32 - 1.0);
    Some(Gci {
        h: [h1, h2, h3],
        values: [f1, f2, f3],
        order: p,
        extrapolated,
        approximate_error,
        extrapolated_error: ((extrapolated - f1) / extrapolated).abs(),
        gci_fine,
        asymptotic_ratio: gci_32 / (a21 * gci_fine),
        oscillatory: s < 0.0,
    })
}

/// The GCI of one series of a study, as `results.json` records it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GciRecord {
    pub sweep: String,
    /// The series (method, points per cell, …) in words.
    pub series: String,
    /// The measure, e.g. "max horizontal displacement".
    pub measure: String,
    /// `None` with fewer than three converged levels or no observable order.
    pub gci: Option<Gci>,
    /// Why there is no GCI, or what the levels say (e.g. outside the asymptotic range).
    pub note: String,
}

impl GciRecord {
    /// The GCI of the three finest of `levels` (h, value), with the note that says whether
    /// they are in the asymptotic range.
    pub fn of(sweep: &str, series: String, measure: &str, mut levels: Vec<(f64, f64)>) -> Self {
        levels.sort_by(|a, b| a.0.total_cmp(&b.0));
        let g = (levels.len() >= 3)
            .then(|| gci([levels[0], levels[1], levels[2]]))
            .flatten();
        let note = match (&g, levels.len()) {
            (_, n) if n < 3 => format!("{n} converged level(s): a GCI needs three"),
            (None, _) => "no observable order (a difference vanishes or grows)".to_string(),
            (Some(g), _) if g.oscillatory => {
                "oscillatory convergence: outside the asymptotic range".to_string()
            }
            (Some(g), _) if !g.in_asymptotic_range() => format!(
                "outside the asymptotic range (GCI32 / (r^p GCI21) = {:.3}, not within 10 % of 1)",
                g.asymptotic_ratio
            ),
            _ => "in the asymptotic range".to_string(),
        };
        GciRecord {
            sweep: sweep.to_string(),
            series,
            measure: measure.to_string(),
            gci: g,
            note,
        }
    }
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

    /// Celik et al. (2008), Table 1, φ1 (reattachment length x_r/H): N = 18000, 8000, 4500
    /// cells in 2D, so h ∝ N^(-1/2): φ = 6.063, 5.972, 5.863 give p = 1.53, φ_ext = 6.1685,
    /// e_a = 1.5 %, e_ext = 1.7 %, GCI_fine = 2.2 % as printed.
    #[test]
    fn gci_reproduces_celik_table_1() {
        let h = |n: f64| n.powf(-0.5);
        let g = gci([(h(18000.0), 6.063), (h(8000.0), 5.972), (h(4500.0), 5.863)]).unwrap();
        assert!((g.order - 1.53).abs() < 0.005, "{g:?}");
        assert!((g.extrapolated - 6.1685).abs() < 5e-4, "{g:?}");
        assert!((100.0 * g.approximate_error - 1.5).abs() < 0.05, "{g:?}");
        assert!((100.0 * g.extrapolated_error - 1.7).abs() < 0.05, "{g:?}");
        assert!((100.0 * g.gci_fine - 2.2).abs() < 0.05, "{g:?}");
        assert!(!g.oscillatory);
    }

    /// An exact p = 2 sequence u = 1 + 10⁻³ h² extrapolates exactly and is in the asymptotic
    /// range (the ratio is φ1/φ2, 1 to within 10⁻³); an oscillating one is flagged.
    #[test]
    fn gci_of_a_second_order_sequence() {
        let u = |h: f64| 1.0 + 1e-3 * h * h;
        let g = gci([(0.25, u(0.25)), (0.5, u(0.5)), (1.0, u(1.0))]).unwrap();
        assert!(
            (g.order - 2.0).abs() < 1e-8 && (g.extrapolated - 1.0).abs() < 1e-12,
            "{g:?}"
        );
        assert!(
            (g.asymptotic_ratio - 1.0).abs() < 1e-3 && g.in_asymptotic_range(),
            "{g:?}"
        );
        let o = gci([(0.25, 1.0), (0.5, 1.1), (1.0, 0.7)]).unwrap();
        assert!(o.oscillatory && !o.in_asymptotic_range());
        assert!(gci([(0.25, 1.0), (0.5, 1.0), (1.0, 2.0)]).is_none());
    }

    #[test]
    fn growth_and_spread() {
        assert!((largest_growth(&[0.3, 0.1, 0.15]).unwrap() - 0.05).abs() < 1e-15);
        assert_eq!(largest_growth(&[0.3]), None);
        assert!((relative_spread(&[1.1, 1.0]).unwrap() - 0.1).abs() < 1e-15);
        assert_eq!(relative_spread(&[1.0]), None);
    }
}
