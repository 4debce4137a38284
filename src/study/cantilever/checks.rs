//! The cantilever's checks (completion, elastica, agreement, collapse, the depth study) and
//! the depth study's rows.

use super::records::{CantileverRecord, CantileverResults, DepthRow};
use super::CantileverStudy;
use crate::study::checks::{check_at_most, CheckRecord, GciRecord};
use crate::study::results::CaseStatus;

fn largest_difference(du: Option<f64>, dv: Option<f64>) -> Option<f64> {
    Some(du?.abs().max(dv?.abs()))
}

pub(super) fn compute_checks(results: &CantileverResults) -> Vec<CheckRecord> {
    let study = &results.study;
    let mut out = vec![];
    for e in &study.expect_completes {
        let c = results.case(&e.case);
        out.push(check_at_most(
            &format!("{}-completes", e.case),
            format!(
                "load steps not completed by `{}` (status {})",
                e.case,
                c.map_or("not run", |c| c.status.word())
            ),
            c.map(|c| (c.load_steps - c.end.len()) as f64),
            0.0,
            &e.source,
        ));
    }
    for e in &study.expect_elastica {
        let c = results.case(&e.case);
        out.push(check_at_most(
            &format!("{}-vs-elastica", e.case),
            format!(
                "largest abs(Δ)/abs(elastica) of the final u/L, v/L of `{}` against the {}",
                e.case,
                if results.study.beam.dimension == 3 {
                    "3D elastica (EI = E d⁴/12)"
                } else {
                    "plane-strain elastica"
                }
            ),
            c.and_then(|c| largest_difference(c.difference_u, c.difference_v)),
            e.tolerance,
            &e.source,
        ));
    }
    for e in &study.expect_agreement {
        let diff = (|| {
            let (a, b) = (results.case(&e.case)?, results.case(&e.reference)?);
            let du = (a.u_over_l? - b.u_over_l?) / b.u_over_l?.abs();
            let dv = (a.v_over_l? - b.v_over_l?) / b.v_over_l?.abs();
            Some(du.abs().max(dv.abs()))
        })();
        let rstatus = results.case(&e.reference).map_or("not run".to_string(), |c| {
            format!(
                "{}{}",
                c.status.word(),
                c.failure
                    .as_ref()
                    .map_or(String::new(), |f| format!(": {}", f.reason))
            )
        });
        out.push(check_at_most(
            &format!("{}-vs-{}", e.case, e.reference),
            format!(
                "largest abs(Δ)/abs(reference) of the final u/L, v/L of `{}` against `{}` ({rstatus})",
                e.case, e.reference
            ),
            diff,
            e.tolerance,
            &e.source,
        ));
    }
    for e in &study.expect_collapse {
        let c = results.case(&e.case);
        let (measured, pass, what) = match c {
            None => (None, None, "not run".to_string()),
            Some(c) => {
                // The failing step's residuals are empty when the failure comes before its
                // first Newton solve (a collapsed domain cannot be evaluated); the converged
                // steps' histories are in `steps`.
                let failed_part_way = c.status == CaseStatus::Failed
                    && c.failure
                        .as_ref()
                        .is_some_and(|f| f.step > 1 && f.step <= c.load_steps && !f.reason.is_empty());
                let m = &c.min_half_length;
                let w = (e.window as usize).min(m.len());
                let shrinking = w >= 2 && m[m.len() - w..].windows(2).all(|p| p[1] <= p[0]);
                let ratio = m.last().map(|&x| x / c.initial_half_length);
                (
                    ratio,
                    ratio.map(|r| failed_part_way && shrinking && r < e.fraction),
                    format!(
                        "failed part-way with step and reason recorded: {failed_part_way} (step {}, {} residuals of the failing step); smallest half-length non-increasing over the last {w} converged steps: {shrinking}",
                        c.failure.as_ref().map_or(0, |f| f.step),
                        c.failure.as_ref().map_or(0, |f| f.residuals.len())
                    ),
                )
            }
        };
        out.push(CheckRecord {
            id: format!("{}-collapses", e.case),
            description: format!(
                "`{}`: smallest domain half-length at the last converged step over its initial value; {what}",
                e.case
            ),
            measured,
            limit: e.fraction,
            pass,
            source: e.source.clone(),
        });
    }
    if let Some(d) = &study.depth_study {
        let mut growth: Option<f64> = None;
        let mut series = 0;
        for &n in &d.elements_through_depth {
            let diffs: Vec<f64> = results
                .measures
                .depth_study
                .iter()
                .filter(|r| r.elements_through_depth == n)
                .filter_map(|r| largest_difference(r.difference_u, r.difference_v))
                .collect();
            if diffs.len() >= 2 {
                series += 1;
                for w in diffs.windows(2) {
                    growth = Some(growth.map_or(w[1] - w[0], |g: f64| g.max(w[1] - w[0])));
                }
            }
        }
        out.push(check_at_most(
            "depth-study-shrinks",
            format!(
                "largest growth of the continuum − elastica difference (largest of abs(Δu), abs(Δv)) from one depth to the next smaller at fixed PL²/EI, over {series} series of fixed elements through the depth"
            ),
            growth,
            0.0,
            &d.source,
        ));
    }
    out
}

pub(super) fn depth_rows(study: &CantileverStudy, records: &[CantileverRecord]) -> Vec<DepthRow> {
    let Some(d) = &study.depth_study else {
        return vec![];
    };
    let mut rows: Vec<DepthRow> = records
        .iter()
        .filter(|r| r.id == d.case || r.id.starts_with(&format!("{}-depth", d.case)))
        .map(|r| DepthRow {
            case: r.id.clone(),
            elements_through_depth: (r.depth / r.element_size).round() as i64,
            depth: r.depth,
            load: r.load,
            element_size: r.element_size,
            u_over_l: r.u_over_l,
            v_over_l: r.v_over_l,
            difference_u: r.difference_u,
            difference_v: r.difference_v,
        })
        .collect();
    rows.sort_by(|a, b| {
        a.elements_through_depth
            .cmp(&b.elements_through_depth)
            .then(b.depth.total_cmp(&a.depth))
    });
    rows
}

/// The GCI of the final u/L and v/L at each depth of the depth study, over its element sizes
/// (h = depth / elements through the depth).
pub(super) fn gci_records(study: &CantileverStudy, rows: &[DepthRow]) -> Vec<GciRecord> {
    let Some(d) = &study.depth_study else {
        return vec![];
    };
    let mut depths: Vec<f64> = rows.iter().map(|r| r.depth).collect();
    depths.sort_by(|a, b| b.total_cmp(a));
    depths.dedup();
    let mut out = vec![];
    for depth in depths {
        for (measure, value) in [
            (
                "final u/L",
                (|r: &DepthRow| r.u_over_l) as fn(&DepthRow) -> Option<f64>,
            ),
            ("final v/L", |r: &DepthRow| r.v_over_l),
        ] {
            let levels: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.depth == depth)
                .filter_map(|r| Some((r.element_size, value(r)?)))
                .collect();
            out.push(GciRecord::of(
                "depth-study",
                format!("`{}` at depth {depth}", d.case),
                measure,
                levels,
            ));
        }
    }
    out
}
