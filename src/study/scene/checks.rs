//! The scene's checks: each `[[expect_…]]` table of the study file turned into a
//! [`CheckRecord`] from the cases' records and the fitted measures.

use super::{ReferenceValue, SceneRecord, SceneResults, SceneStudy};
use crate::study::checks::{check_at_most, check_newton_quadratic, check_rate, CheckRecord};
use crate::study::external::StudyMethod;
use std::collections::BTreeSet;

/// The largest relative error of `case`'s measure `name` against `r`, at the end and after
/// every step of a history (whose steps are the study's load steps).
fn largest_error(case: &SceneRecord, name: &str, r: &ReferenceValue) -> Option<f64> {
    let scale = if r.value == 0.0 { 1.0 } else { r.value.abs() };
    let mut worst = r.error(*case.measures.get(name)?);
    if let Some(h) = case.histories.get(name) {
        if h.len() == r.history.len() {
            for (v, e) in h.iter().zip(&r.history) {
                worst = worst.max((v - e).abs() / scale);
            }
        }
    }
    Some(worst)
}

pub(super) fn checks(results: &SceneResults) -> Vec<CheckRecord> {
    let study = &results.study;
    let mut out = vec![];
    for e in &study.expect_reference {
        if e.tier.is_some_and(|t| t != results.provenance.tier) {
            continue;
        }
        let r = results.measures.references.get(&e.measure);
        let mut cases: Vec<&SceneRecord> = results
            .sweep(&e.sweep)
            .into_iter()
            .filter(|c| e.methods.is_empty() || e.methods.contains(&c.method))
            .collect();
        if e.finest {
            let finest = |m: &StudyMethod| {
                cases
                    .iter()
                    .filter(|c| &c.method == m)
                    .map(|c| c.h)
                    .fold(f64::INFINITY, f64::min)
            };
            cases = cases
                .iter()
                .copied()
                .filter(|c| c.h == finest(&c.method))
                .collect();
        }
        if cases.is_empty() {
            // The tier does not run the sweep (a full-tier sweep in the quick tier).
            continue;
        }
        let failed = cases.iter().any(|c| !c.solve.status.solved());
        let worst = r.and_then(|r| {
            let errors: Option<Vec<f64>> = cases.iter().map(|c| largest_error(c, &e.measure, r)).collect();
            errors
                .filter(|v| !v.is_empty() && !failed)
                .map(|v| v.into_iter().fold(0.0, f64::max))
        });
        let who = if e.methods.is_empty() {
            "every method".to_string()
        } else {
            e.methods.iter().map(|m| m.name()).collect::<Vec<_>>().join(", ")
        };
        out.push(check_at_most(
            &format!("{}-{}-reference", e.sweep, e.measure),
            format!(
                "{} of {who} in sweep {}{} within {:e} of its reference (measured: the largest relative error over {} cases{})",
                e.measure,
                e.sweep,
                if e.finest { " at its finest h" } else { "" },
                e.tolerance,
                cases.len(),
                if failed { "; a case did not converge" } else { "" }
            ),
            worst,
            e.tolerance,
            &e.source,
        ));
    }
    for e in &study.expect_extrapolation {
        let cases: Vec<&SceneRecord> = results
            .sweep(&e.sweep)
            .into_iter()
            .filter(|c| c.method == e.method)
            .collect();
        let sizes = cases.iter().map(|c| c.h.to_bits()).collect::<BTreeSet<_>>().len();
        if sizes < 3 {
            continue; // the tier runs the method at fewer than three sizes
        }
        let reference = results.measures.references.get(&e.measure);
        let names: BTreeSet<String> = cases
            .iter()
            .map(|c| series_name(&c.method.name(), c.points_per_cell))
            .collect();
        let records: Vec<_> = results
            .measures
            .gci
            .iter()
            .filter(|g| g.sweep == e.sweep && g.measure == e.measure && names.contains(&g.series))
            .collect();
        // Worst over the method's points-per-cell series; a series without a GCI in the
        // asymptotic range (fewer than three converged sizes among them) cannot be compared
        // and fails, as the compaction's check does.
        let measured = records
            .iter()
            .map(|g| match (&g.gci, reference) {
                (Some(x), Some(r)) if x.in_asymptotic_range() => r.error(x.extrapolated),
                _ => f64::INFINITY,
            })
            .reduce(f64::max);
        let what = records
            .iter()
            .map(|g| match &g.gci {
                Some(x) => format!(
                    "{}: {:.6} from h = {}, {}, {}, order {:.2}, {}",
                    g.series, x.extrapolated, x.h[0], x.h[1], x.h[2], x.order, g.note
                ),
                None => format!("{}: {}", g.series, g.note),
            })
            .collect::<Vec<_>>()
            .join("; ");
        out.push(check_at_most(
            &format!("{}-{}-{}-extrapolated", e.sweep, e.measure, e.method.name()),
            format!(
                "{} of {} in sweep {} extrapolated to h = 0 (GCI over the three finest converged sizes) within {:e} of its reference (measured: the relative error of the extrapolation; {what}; a series outside the asymptotic range fails)",
                e.measure,
                e.method.name(),
                e.sweep,
                e.tolerance
            ),
            measured,
            e.tolerance,
            &e.source,
        ));
    }
    for e in &study.expect_quadratic {
        let cases = results.sweep(&e.sweep);
        if cases.is_empty() {
            continue; // not run in this tier
        }
        let steps = cases.into_iter().flat_map(|c| c.solve.newton_histories(&c.id));
        out.push(check_newton_quadratic(
            &format!("{}-newton-quadratic", e.sweep),
            &format!("Newton in sweep {}", e.sweep),
            "every case (a failed case's last attempt included)",
            steps,
            &e.terms(),
        ));
    }
    let extent = scene_extent(study);
    for e in &study.expect_agreement {
        let cases = results.sweep(&e.sweep);
        let of = |m: &StudyMethod| -> Vec<&SceneRecord> {
            cases.iter().copied().filter(|c| &c.method == m).collect()
        };
        let (a, b) = (of(&e.methods[0]), of(&e.methods[1]));
        if a.is_empty() && b.is_empty() {
            continue;
        }
        // Every pair at one h and points per cell whose cases both converged (a failed case
        // is listed among the failures, and --check refuses it unless the study expects it);
        // a converged pair without positions leaves the check not evaluated.
        let mut worst: Option<f64> = Some(0.0);
        let (mut pairs, mut skipped) = (0, 0);
        for x in &a {
            let Some(y) = b
                .iter()
                .find(|y| y.h == x.h && y.points_per_cell == x.points_per_cell)
            else {
                continue;
            };
            if !x.solve.status.solved() || !y.solve.status.solved() {
                skipped += 1;
                continue;
            }
            pairs += 1;
            let ok = x.positions.len() == y.positions.len() && !x.positions.is_empty();
            worst = worst.filter(|_| ok).map(|w| {
                x.positions
                    .iter()
                    .zip(&y.positions)
                    .flat_map(|(p, q)| p.iter().zip(q).map(|(u, v)| (u - v).abs()))
                    .fold(w, f64::max)
            });
        }
        if pairs == 0 {
            worst = None;
        }
        out.push(check_at_most(
            &format!("{}-{}-{}-agreement", e.sweep, e.methods[0].slug(), e.methods[1].slug()),
            format!(
                "final point positions of {} and {} in sweep {} agree to {:e} of the scene's largest body extent {extent} (measured: the largest difference over {pairs} pairs of converged cases, over {extent}{})",
                e.methods[0],
                e.methods[1],
                e.sweep,
                e.tolerance,
                if skipped > 0 {
                    format!("; {skipped} pair(s) with a failed case left out")
                } else {
                    String::new()
                }
            ),
            worst.map(|w| w / extent),
            e.tolerance,
            &e.source,
        ));
    }
    for e in &study.expect_rate {
        for r in results
            .measures
            .rates
            .iter()
            .filter(|r| r.sweep == e.sweep && r.measure == e.measure && r.method == e.method)
        {
            let ppc = r
                .points_per_cell
                .map_or(String::new(), |p| format!(", {p} points per cell"));
            out.push(check_rate(
                &format!(
                    "{}-{}-{}-rate{}",
                    e.sweep,
                    e.measure,
                    e.method.name(),
                    r.points_per_cell.map_or(String::new(), |p| format!("-ppc{p}"))
                ),
                &format!(
                    "error of {} by {}{ppc} in sweep {}",
                    e.measure,
                    e.method.name(),
                    e.sweep
                ),
                r.slope,
                e.rate,
                e.tolerance,
                &e.source,
            ));
        }
    }
    out
}

/// The largest side of the bodies' bounding boxes.
fn scene_extent(study: &SceneStudy) -> f64 {
    study
        .bodies
        .iter()
        .flat_map(|b| {
            let bx = b.bounding_box();
            (0..bx.min.len())
                .map(move |a| bx.max[a] - bx.min[a])
                .collect::<Vec<f64>>()
        })
        .fold(0.0, f64::max)
}

/// A series' name in the GCI records: the method, and its points per cell.
pub(super) fn series_name(method: &str, points_per_cell: Option<usize>) -> String {
    match points_per_cell {
        Some(p) => format!("{method} {p}ppc"),
        None => method.to_string(),
    }
}
