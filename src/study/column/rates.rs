//! Convergence rates of the sweeps and the checks declared in the study file.
//!
//! A rate is the least-squares slope of log(error) against log(h), h = L0 / elements
//! ([`crate::problems::norms::fitted_rate`]), over the finest `fit_points` converged element counts of
//! one series (method, weight, points per cell). Pairwise log2 rates per refinement are
//! computed by [`pairwise_rates`] for the tables.

use super::records::ColumnRecord;
pub use super::records::{ComparisonRecord, ExpectedBand, RateRecord};
use super::{ColumnStudy, Measure};
use crate::basis::method::Method;
use crate::study::checks::fitted_rate_finest;
use crate::study::results::{CaseStatus, SweepIndex};
use crate::study::Tier;

/// The error of a case under a measure (converged cases only).
pub fn case_error(case: &ColumnRecord, measure: Measure) -> Option<f64> {
    if case.solve.status != CaseStatus::Converged {
        return None;
    }
    let e = match measure {
        Measure::StressError => case.stress_error,
        Measure::FError => case.f_error,
        Measure::SigmaXxError => case.sigma_xx_error,
        Measure::YieldHeightError => case.yield_height_error,
    }?;
    (e.is_finite() && e > 0.0).then_some(e)
}

/// The converged cases of one series, sorted by element count.
pub fn series<'a>(
    cases: &'a [ColumnRecord],
    ids: &[String],
    method: Method,
    load: f64,
    ppc: Option<usize>,
) -> Vec<&'a ColumnRecord> {
    let mut v: Vec<&ColumnRecord> = cases
        .iter()
        .filter(|c| ids.contains(&c.id))
        .filter(|c| c.method == method && c.load == load && c.points_per_cell == ppc)
        .collect();
    v.sort_by_key(|c| c.elements);
    v
}

/// log2(e_coarse / e_fine) / log2(n_fine / n_coarse) between consecutive entries.
pub fn pairwise_rates(elements: &[usize], errors: &[Option<f64>]) -> Vec<Option<f64>> {
    (0..elements.len())
        .map(|i| {
            if i == 0 {
                return None;
            }
            let (a, b) = (errors[i - 1]?, errors[i]?);
            let r = (a / b).log2() / (elements[i] as f64 / elements[i - 1] as f64).log2();
            r.is_finite().then_some(r)
        })
        .collect()
}

/// Fit every series of every sweep with two or more element counts, then attach the
/// expectations of the study file.
pub fn compute_rates(
    spec: &ColumnStudy,
    tier: Tier,
    cases: &[ColumnRecord],
    case_ids: &SweepIndex,
) -> Vec<RateRecord> {
    let mut out = Vec::new();
    for sweep in &spec.sweeps {
        let Some(plan) = spec.plan(sweep, tier) else {
            continue;
        };
        if plan.elements.len() < 2 {
            continue;
        }
        let ids = case_ids.get(&sweep.id).map_or(&[][..], |v| v.as_slice());
        for &method in &plan.methods {
            let ppcs: Vec<Option<usize>> = if method.uses_material_points() {
                plan.points_per_cell.iter().map(|&p| Some(p)).collect()
            } else {
                vec![None]
            };
            for &load in &plan.weights {
                for &ppc in &ppcs {
                    let s = series(cases, ids, method, load, ppc);
                    for &measure in Measure::all(spec.plastic()) {
                        let pts: Vec<(usize, f64)> = s
                            .iter()
                            .filter_map(|c| case_error(c, measure).map(|e| (c.elements, e)))
                            .collect();
                        let h: Vec<f64> = pts.iter().map(|p| spec.column.length / p.0 as f64).collect();
                        let e: Vec<f64> = pts.iter().map(|p| p.1).collect();
                        let (slope, n) = fitted_rate_finest(&h, &e, sweep.fit_points.map(|n| n as usize));
                        let used = &pts[pts.len() - n..];
                        out.push(RateRecord {
                            sweep: sweep.id.clone(),
                            method,
                            load,
                            points_per_cell: ppc,
                            measure,
                            slope,
                            elements_used: used.iter().map(|p| p.0).collect(),
                            expected: None,
                            pass: None,
                        });
                    }
                }
            }
        }
    }
    for e in &spec.expect {
        // An expectation on a sweep that this tier leaves out is not listed.
        let sweep = spec.sweep(&e.sweep).expect("validated");
        if spec.plan(sweep, tier).is_none() {
            continue;
        }
        let ppc = e.points_per_cell.map(|p| p as usize);
        let band = ExpectedBand {
            rate: e.rate,
            tolerance: e.tolerance,
            source: e.source.clone(),
        };
        let found = out.iter_mut().find(|r| {
            r.sweep == e.sweep
                && r.method == e.method
                && r.load == e.weight
                && r.points_per_cell == ppc
                && r.measure == e.measure
        });
        match found {
            Some(r) => {
                r.pass = Some(r.slope.is_some_and(|s| (s - e.rate).abs() <= e.tolerance));
                r.expected = Some(band);
            }
            None => out.push(RateRecord {
                sweep: e.sweep.clone(),
                method: e.method,
                load: e.weight,
                points_per_cell: ppc,
                measure: e.measure,
                slope: None,
                elements_used: vec![],
                expected: Some(band),
                pass: None,
            }),
        }
    }
    out
}

/// Evaluate the `[[compare]]` checks.
pub fn compute_comparisons(
    spec: &ColumnStudy,
    tier: Tier,
    cases: &[ColumnRecord],
    case_ids: &SweepIndex,
) -> Vec<ComparisonRecord> {
    spec.compare
        .iter()
        .filter(|cmp| spec.sweep(&cmp.sweep).and_then(|s| spec.plan(s, tier)).is_some())
        .map(|cmp| {
            let sweep = spec.sweep(&cmp.sweep).expect("validated");
            let mut elements_checked = vec![];
            let mut ratios = vec![];
            if let Some(plan) = spec.plan(sweep, tier) {
                let ids = case_ids.get(&sweep.id).map_or(&[][..], |v| v.as_slice());
                let pick = |m: Method| -> Vec<&ColumnRecord> {
                    let ppcs: Vec<Option<usize>> = if m.uses_material_points() {
                        plan.points_per_cell.iter().map(|&p| Some(p)).collect()
                    } else {
                        vec![None]
                    };
                    ppcs.into_iter()
                        .flat_map(|p| series(cases, ids, m, cmp.weight, p))
                        .collect()
                };
                let (lo, hi) = (pick(cmp.lower), pick(cmp.higher));
                for &n in &plan.elements {
                    let e_hi = hi
                        .iter()
                        .find(|c| c.elements == n)
                        .and_then(|c| case_error(c, cmp.measure));
                    let Some(e_hi) = e_hi else { continue };
                    for c in lo.iter().filter(|c| c.elements == n) {
                        if let Some(e_lo) = case_error(c, cmp.measure) {
                            elements_checked.push(n);
                            ratios.push(e_lo / e_hi);
                        }
                    }
                }
            }
            ComparisonRecord {
                sweep: cmp.sweep.clone(),
                load: cmp.weight,
                measure: cmp.measure,
                lower: cmp.lower,
                higher: cmp.higher,
                pass: (!ratios.is_empty()).then(|| ratios.iter().all(|&r| r < 1.0)),
                elements_checked,
                ratios,
                source: cmp.source.clone(),
            }
        })
        .collect()
}
