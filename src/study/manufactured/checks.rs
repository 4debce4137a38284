//! Fitted rates of every series and the `[[expect_rate]]` checks.

use super::rate_check_id;
use super::records::{ExpectedBand, ManufacturedResults, RateRecord, Series};
use super::ErrorMeasure;
use crate::mpm::DomainUpdate;
use crate::study::checks::{check_rate, fitted_rate_finest, CheckRecord};

pub(super) fn rates(results: &ManufacturedResults) -> Vec<RateRecord> {
    let study = &results.study;
    let mut out = vec![];
    for sw in &study.sweeps {
        for s in results.sweep_series(&sw.id) {
            for measure in ErrorMeasure::ALL {
                let pts: Vec<(usize, f64)> = results
                    .series_cases(&sw.id, &s)
                    .into_iter()
                    .filter_map(|c| Some((c.cells, c.error(measure)?)))
                    .collect();
                let h: Vec<f64> = pts.iter().map(|p| 1.0 / p.0 as f64).collect();
                let e: Vec<f64> = pts.iter().map(|p| p.1).collect();
                let (slope, n) = fitted_rate_finest(&h, &e, sw.fit_points.map(|n| n as usize));
                let expected = study
                    .expect_rate
                    .iter()
                    .find(|x| {
                        x.tier.is_none_or(|t| t == results.provenance.tier)
                            && x.sweep == sw.id
                            && x.method == s.method
                            && x.measure == measure
                            && x.points_per_cell.map(|p| p as usize) == s.points_per_cell
                            && (!s.method.uses_domain_update()
                                || Some(x.domain_update.unwrap_or(DomainUpdate::Stretch)) == s.domain_update)
                    })
                    .map(|x| ExpectedBand {
                        rate: x.rate,
                        tolerance: x.tolerance,
                        source: x.source.clone(),
                    });
                out.push(RateRecord {
                    sweep: sw.id.clone(),
                    series: s,
                    measure,
                    slope,
                    cells_used: pts[pts.len() - n..].iter().map(|p| p.0).collect(),
                    expected,
                });
            }
        }
    }
    out
}

/// One check per expected rate; an expectation whose series the tier did not run is not
/// evaluated.
pub(super) fn checks(results: &ManufacturedResults) -> Vec<CheckRecord> {
    let rates = &results.measures.rates;
    results
        .study
        .expect_rate
        .iter()
        .filter(|x| results.sweep_cases.contains_key(&x.sweep))
        .filter(|x| x.tier.is_none_or(|t| t == results.provenance.tier))
        .map(|x| {
            let s = Series {
                method: x.method,
                domain_update: x
                    .method
                    .uses_domain_update()
                    .then(|| x.domain_update.unwrap_or_default()),
                points_per_cell: x.points_per_cell.map(|p| p as usize),
            };
            let r = rates
                .iter()
                .find(|r| r.sweep == x.sweep && r.series == s && r.measure == x.measure);
            let id = rate_check_id(
                &x.sweep,
                x.method,
                s.domain_update,
                s.points_per_cell,
                x.measure.name(),
            );
            let what = format!(
                "{} of {} in sweep `{}`, fitted over cells {:?}",
                x.measure.label(),
                s.label(results.study.dimension as usize),
                x.sweep,
                r.map_or(vec![], |r| r.cells_used.clone())
            );
            check_rate(
                &id,
                &what,
                r.and_then(|r| r.slope),
                x.rate,
                x.tolerance,
                &x.source,
            )
        })
        .collect()
}
