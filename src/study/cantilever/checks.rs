//! The cantilever's checks (completion, elastica, agreement, collapse, the depth study) and
//! the depth study's rows.

use super::records::{CantileverRecord, CantileverResults, DepthRow, RefinementRow};
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
                c.map_or("not run", |c| c.solve.status.word())
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
                c.solve.status.word(),
                c.solve
                    .failure
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
                let failed_part_way = c.solve.status == CaseStatus::Failed
                    && c.solve
                        .failure
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
                        c.solve.failure.as_ref().map_or(0, |f| f.step),
                        c.solve.failure.as_ref().map_or(0, |f| f.residuals.len())
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
    for e in &study.expect_refined {
        let rows: Vec<&RefinementRow> = results
            .measures
            .refinement
            .iter()
            .filter(|r| r.refinement == e.refinement && e.methods.contains(&r.method))
            .filter(|r| r.element_size <= e.max_element_size)
            .collect();
        // A case that did not complete (or whose reference did not) fails the check.
        let measured = rows
            .iter()
            .map(|r| largest_difference(r.difference_u, r.difference_v).unwrap_or(f64::INFINITY))
            .reduce(f64::max);
        let reference = study
            .refinement
            .iter()
            .find(|r| r.id == e.refinement)
            .map_or("the reference", |r| r.reference.label());
        out.push(check_at_most(
            &format!(
                "{}{}-vs-reference-h{}",
                e.refinement,
                e.methods.iter().map(|m| format!("-{}", m.name())).collect::<String>(),
                e.max_element_size
            ),
            format!(
                "largest abs(Δ)/abs(reference) of the final u/L, v/L of {} against {reference} at the same element size, over the {} cases with h ≤ {} (one not completed fails)",
                e.methods.iter().map(|m| m.label()).collect::<Vec<_>>().join(", "),
                rows.len(),
                e.max_element_size
            ),
            measured,
            e.tolerance,
            &e.source,
        ));
    }
    for e in &study.expect_extrapolated {
        let Some(r) = study.refinement.iter().find(|r| r.id == e.refinement) else {
            continue;
        };
        let sizes = |m| {
            results
                .measures
                .refinement
                .iter()
                .filter(|x| x.refinement == r.id && x.method == m)
                .count()
        };
        if sizes(e.method) < 3 || sizes(r.reference) < 3 {
            continue;
        }
        let ext = |m| {
            let g = gci_of(&results.measures.refinement, &r.id, m, "final u/L", |x| {
                x.u_over_l
            });
            let x = g.gci.as_ref()?;
            x.in_asymptotic_range().then_some(x.extrapolated)
        };
        let measured = match (ext(e.method), ext(r.reference)) {
            (Some(a), Some(b)) => Some(((a - b) / b).abs()),
            _ => Some(f64::INFINITY),
        };
        out.push(check_at_most(
            &format!("{}-{}-extrapolated-vs-reference", r.id, e.method.name()),
            format!(
                "abs(Δ)/abs(reference) of the GCI-extrapolated final u/L of {} against {}'s, each over its three finest element sizes (outside the asymptotic range or not completed: fails)",
                e.method.label(),
                r.reference.label()
            ),
            measured,
            e.tolerance,
            &e.source,
        ));
    }
    // The depth study's cases beyond the base case are full-tier only: no check without them.
    let depth_cases = results.measures.depth_study.len();
    if let Some(d) = study.depth_study.as_ref().filter(|_| depth_cases > 1) {
        // The continuum at each depth, free of discretisation error: the GCI extrapolation
        // over the depth's element sizes (fixed elements through the depth, so a fixed element
        // shape) where in the asymptotic range, else the finest size.
        let continuum = depth_continuum(study, results);
        let mut growth: Option<f64> = None;
        let mut used = vec![];
        for w in continuum.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            growth = Some(growth.map_or(b.difference - a.difference, |g: f64| {
                g.max(b.difference - a.difference)
            }));
        }
        for c in &continuum {
            used.push(format!(
                "depth {}: {:.2} % ({})",
                c.depth,
                100.0 * c.difference,
                c.source
            ));
        }
        out.push(check_at_most(
            "depth-study-shrinks",
            format!(
                "largest growth, from one depth to the next smaller at fixed PL²/EI, of the continuum − elastica difference (largest of abs(u/u_e − 1), abs(v/v_e − 1)) of the beam's continuum at each depth: {}",
                if used.is_empty() { "no depth solved".to_string() } else { used.join("; ") }
            ),
            (continuum.len() >= 2).then_some(growth).flatten(),
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

/// Every refinement case against the reference method's case at the same element size.
pub(super) fn refinement_rows(study: &CantileverStudy, records: &[CantileverRecord]) -> Vec<RefinementRow> {
    let mut out = vec![];
    for r in &study.refinement {
        for &m in &r.methods {
            for &h in &r.element_sizes {
                let Some(c) = records
                    .iter()
                    .find(|c| c.id == CantileverStudy::refinement_case_id(&r.id, m, h))
                else {
                    continue;
                };
                let reference = records
                    .iter()
                    .find(|c| c.id == CantileverStudy::refinement_case_id(&r.id, r.reference, h));
                let diff = |a: Option<f64>, b: Option<f64>| Some(a? / b? - 1.0);
                out.push(RefinementRow {
                    refinement: r.id.clone(),
                    case: c.id.clone(),
                    method: m,
                    element_size: h,
                    u_over_l: c.u_over_l,
                    v_over_l: c.v_over_l,
                    difference_u: diff(c.u_over_l, reference.and_then(|x| x.u_over_l)),
                    difference_v: diff(c.v_over_l, reference.and_then(|x| x.v_over_l)),
                });
            }
        }
    }
    out
}

/// The GCI of one method's measure over a refinement's element sizes.
fn gci_of(
    rows: &[RefinementRow],
    refinement: &str,
    method: crate::basis::method::Method,
    measure: &str,
    value: fn(&RefinementRow) -> Option<f64>,
) -> GciRecord {
    let levels: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.refinement == refinement && r.method == method)
        .filter_map(|r| Some((r.element_size, value(r)?)))
        .collect();
    GciRecord::of(refinement, method.label().to_string(), measure, levels)
}

/// The GCI of the final u/L and v/L of every method of every refinement.
pub(super) fn refinement_gci(study: &CantileverStudy, rows: &[RefinementRow]) -> Vec<GciRecord> {
    let mut out = vec![];
    for r in &study.refinement {
        for &m in &r.methods {
            out.push(gci_of(rows, &r.id, m, "final u/L", |x| x.u_over_l));
            out.push(gci_of(rows, &r.id, m, "final v/L", |x| x.v_over_l));
        }
    }
    out
}

/// The continuum beam at one depth of the depth study.
pub(super) struct DepthContinuum {
    pub depth: f64,
    /// Largest of |u/u_e − 1| and |v/v_e − 1| against the elastica.
    pub difference: f64,
    /// What the continuum value is ("GCI" or "finest h = …").
    pub source: String,
}

/// Per depth (largest first): u/L and v/L by their GCI extrapolation over the depth's element
/// sizes where in the asymptotic range, else the finest size's; against the elastica.
pub(super) fn depth_continuum(study: &CantileverStudy, results: &CantileverResults) -> Vec<DepthContinuum> {
    let Some(d) = &study.depth_study else {
        return vec![];
    };
    let Some(elastica) = results
        .cases
        .iter()
        .find(|c| c.id == d.case)
        .and_then(|c| c.elastica)
    else {
        return vec![];
    };
    let rows = &results.measures.depth_study;
    let mut depths: Vec<f64> = rows.iter().map(|r| r.depth).collect();
    depths.sort_by(|a, b| b.total_cmp(a));
    depths.dedup();
    let mut out = vec![];
    for depth in depths {
        let series = format!("`{}` at depth {depth}", d.case);
        let mut diffs = vec![];
        let mut sources = vec![];
        for (measure, pick, exact) in [
            ("final u/L", 0, elastica.u_over_l),
            ("final v/L", 1, elastica.v_over_l),
        ] {
            let gci = results
                .measures
                .gci
                .iter()
                .find(|g| g.sweep == "depth-study" && g.series == series && g.measure == measure)
                .and_then(|g| g.gci.as_ref())
                .filter(|g| g.in_asymptotic_range());
            let value = match gci {
                Some(g) => {
                    sources.push(format!("{measure} GCI"));
                    Some(g.extrapolated)
                }
                None => rows
                    .iter()
                    .filter(|r| r.depth == depth)
                    .filter_map(|r| Some((r.element_size, if pick == 0 { r.u_over_l? } else { r.v_over_l? })))
                    .min_by(|a, b| a.0.total_cmp(&b.0))
                    .map(|(h, v)| {
                        sources.push(format!("{measure} finest h = {h}"));
                        v
                    }),
            };
            if let Some(v) = value {
                diffs.push((v / exact - 1.0).abs());
            }
        }
        if diffs.len() == 2 {
            out.push(DepthContinuum {
                depth,
                difference: diffs[0].max(diffs[1]),
                source: sources.join(", "),
            });
        }
    }
    out
}
