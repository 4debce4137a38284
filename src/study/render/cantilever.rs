//! Rendering of the cantilever study (§5.3): the report and Figures 19–21 from `results.json`
//! and `domains.json` only.

use crate::study::cantilever::*;
use crate::study::render::plot2d::{
    domains_svg, xy_svg, Domain, DomainLayer, LegendCorner, PointMarks, XyAxes, XySeries,
};
type Results = CantileverResults;
use super::{checks_markdown, failures_markdown, IndexEntry};
use crate::study::checks::check_counts;
use crate::study::results::{read_json, read_results, CaseStatus};
use crate::study::StudyError;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

fn f5(x: Option<f64>) -> String {
    x.map_or("—".into(), |v| format!("{v:.5}"))
}

fn pct(x: Option<f64>) -> String {
    x.map_or("—".into(), |v| format!("{:+.2} %", 100.0 * v))
}

fn case_label(study: &CantileverStudy, r: &CantileverRecord) -> String {
    study
        .cases
        .iter()
        .find(|c| c.id == r.id)
        .map_or_else(|| super::md_cell(&r.id), |c| super::md_cell(&c.title))
}

/// The main report.
pub fn report_markdown(results: &CantileverResults, not_drawn: &[super::NotDrawn]) -> String {
    let study = &results.study;
    let (pass, fail, none) = check_counts(&results.checks);
    let mut s = format!(
        "# {}: {}\n\n{}\n\nChecks: {pass} passed, {fail} failed, {none} not evaluated.\n\n",
        super::md_text(&study.name),
        super::md_text(&study.summary),
        results.provenance.line()
    );
    let _ = write!(
        s,
        "## End displacement at the full load\n\nMean of the loaded points (iGIMP; FEM: the loaded node{}); Δ = (continuum − elastica)/|elastica| against the elastica of the same beam ({}).\n\n",
        if results.study.beam.dimension == 3 {
            " in the middle of the loaded edge"
        } else {
            ""
        },
        elastica_label(results, results.study.beam.dimension == 2)
    );
    s.push_str("| case | method | domain / volume update | status | steps | u/L | v/L | elastica u/L | elastica v/L | Δu | Δv |\n|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
    for r in &results.cases {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {}/{} | {} | {} | {} | {} | {} | {} |",
            r.id,
            r.method.label(),
            match (r.domain_update, r.volume_update) {
                (Some(d), Some(v)) => format!("{d:?} / {v:?}"),
                _ => "—".into(),
            },
            r.solve.status.word(),
            r.end.len(),
            r.load_steps,
            f5(r.u_over_l),
            f5(r.v_over_l),
            f5(r.elastica.map(|e| e.u_over_l)),
            f5(r.elastica.map(|e| e.v_over_l)),
            pct(r.difference_u),
            pct(r.difference_v)
        );
    }
    s.push('\n');
    for p in &results.measures.elastica {
        let _ = writeln!(
            s,
            "Elastica, {}: EI = {:.6e} N·m, α = PL²/EI = {:.4} at the full load.\n",
            elastica_label(results, p.plane_strain),
            p.bending_stiffness,
            p.points.last().map_or(f64::NAN, |e| e.alpha)
        );
    }
    if !results.measures.depth_study.is_empty() {
        s.push_str("## Depth study\n\nThe same PL²/EI (P ∝ depth³) and a fixed number of elements through the depth (h ∝ depth); the elastica is the same for every row.\n\n| case | elements through depth | depth | P | h | u/L | v/L | Δu | Δv |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
        for r in &results.measures.depth_study {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                r.case,
                r.elements_through_depth,
                r.depth,
                r.load,
                r.element_size,
                f5(r.u_over_l),
                f5(r.v_over_l),
                pct(r.difference_u),
                pct(r.difference_v)
            );
        }
        s.push('\n');
    }
    for r in &study.refinement {
        let reference = refinement_reference(results, r);
        let _ = write!(
            s,
            "## {}\n\nEvery method on the beam's base case at each element size (h = {}); Δ = u/u_ref − 1 (v likewise) against {} at the same h; the last column against the reference's u/L ({}). {}{}\n\n| method | h | status | u/L | v/L | Δu | Δv | u/L over the reference |\n|---|---:|---|---:|---:|---:|---:|---:|\n",
            super::md_text(&r.title),
            r.element_sizes.iter().map(|h| h.to_string()).collect::<Vec<_>>().join(", "),
            r.reference.label(),
            reference.as_ref().map_or("none".into(), |(u, what)| format!("{u:.6}: {what}")),
            if r.element_sizes.len() > r.quick_element_sizes.as_ref().map_or(usize::MAX, |q| q.len())
                && results.provenance.tier == crate::study::Tier::Quick
            {
                "The quick tier runs the coarser sizes only, so no GCI extrapolation is checked. "
            } else {
                ""
            },
            r.note
        );
        for x in results
            .measures
            .refinement
            .iter()
            .filter(|x| x.refinement == r.id)
        {
            let status = results.case(&x.case).map_or("not run", |c| c.solve.status.word());
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} | {} | {} |",
                x.method.label(),
                x.element_size,
                status,
                f5(x.u_over_l),
                f5(x.v_over_l),
                pct(x.difference_u),
                pct(x.difference_v),
                match (x.u_over_l, &reference) {
                    (Some(u), Some((r, _))) => format!("{:.4}", u / r),
                    _ => "—".into(),
                }
            );
        }
        s.push('\n');
    }
    s.push_str(&checks_markdown(&results.checks));
    // Load path every 5 steps (Figure 21's data).
    let shown: Vec<&CantileverRecord> = results
        .cases
        .iter()
        .filter(|r| !r.end.is_empty() && study.cases.iter().any(|c| c.id == r.id))
        .collect();
    if let Some(el) = results.measures.elastica.first() {
        s.push_str("## Load path (every 5th step)\n\n| step | P (kN) | elastica u/L | elastica v/L |");
        for r in &shown {
            let _ = write!(s, " {0} u/L | {0} v/L |", r.id);
        }
        s.push_str("\n|---:|---:|---:|---:|");
        for _ in &shown {
            s.push_str("---:|---:|");
        }
        s.push('\n');
        for (i, e) in el.points.iter().enumerate().filter(|(i, _)| (i + 1) % 5 == 0) {
            let _ = write!(
                s,
                "| {} | {:.1} | {:.5} | {:.5} |",
                i + 1,
                e.load / 1e3,
                e.u_over_l,
                e.v_over_l
            );
            for r in &shown {
                let d = r.end.iter().find(|d| d.step == i + 1);
                let _ = write!(
                    s,
                    " {} | {} |",
                    f5(d.map(|d| d.u_over_l)),
                    f5(d.map(|d| d.v_over_l))
                );
            }
            s.push('\n');
        }
        s.push('\n');
    }
    s.push_str(&super::gci_markdown(&results.measures.gci));
    s.push_str(&super::performance_markdown(&results.cases, &results.timing));
    s.push_str(&failures_markdown(
        results
            .cases
            .iter()
            .map(|c| (c.id.as_str(), c.solve.status, c.solve.failure.as_ref())),
    ));
    s.push_str(&super::figures_markdown(
        study.figures.iter().map(|f| (f.title.as_str(), f.id.as_str())),
        not_drawn,
    ));
    s
}

fn render_figure(
    results: &CantileverResults,
    snapshots: &BTreeMap<String, Vec<DomainSnapshot>>,
    dir: &Path,
    f: &CantileverFigure,
) -> Result<Option<String>, StudyError> {
    let path = dir.join(format!("{}.svg", f.id)).display().to_string();
    let fail = |message| StudyError::Io {
        path: path.clone(),
        message,
    };
    match f.kind {
        CantileverFigureKind::Domains => {
            let id = &f.cases[0];
            let (Some(rec), Some(snaps)) = (results.case(id), snapshots.get(id)) else {
                return Ok(None);
            };
            let wanted: Vec<&DomainSnapshot> = match &f.steps {
                Some(steps) => snaps
                    .iter()
                    .filter(|s| steps.contains(&(s.step as i64)))
                    .collect(),
                None => snaps.iter().collect(),
            };
            let domains = |s: &DomainSnapshot| -> Vec<Domain> {
                s.domains
                    .iter()
                    .map(|d| Domain {
                        centre: [d[0], d[1]],
                        half: [d[2], d[3]],
                    })
                    .collect()
            };
            let last = wanted.len().saturating_sub(1);
            let layers: Vec<DomainLayer> = wanted
                .iter()
                .enumerate()
                .map(|(i, s)| DomainLayer {
                    label: if s.step == 0 {
                        "initial".into()
                    } else {
                        format!("load step {}", s.step)
                    },
                    domains: domains(s),
                    values: None,
                    colour: (s.step != 0).then_some(if wanted.len() <= 2 { 0 } else { i.min(last) }),
                })
                .collect();
            let marks: Vec<PointMarks> = match (f.mark_loads, &rec.loaded_points) {
                (true, Some(lp)) => vec![PointMarks {
                    label: "loaded points".into(),
                    points: wanted
                        .iter()
                        .flat_map(|s| {
                            lp.iter()
                                .filter_map(move |&p| s.domains.get(p).map(|d| (d[0], d[1])))
                        })
                        .collect(),
                }],
                _ => vec![],
            };
            let title = match (&rec.solve.failure, rec.solve.status) {
                (Some(fl), CaseStatus::Failed) => format!("{} (failed at step {})", f.title, fl.step),
                _ => f.title.clone(),
            };
            domains_svg(&title, "", ("x", "y"), &layers, &marks)
                .map(Some)
                .map_err(fail)
        }
        CantileverFigureKind::EndDisplacement => {
            let mut series = vec![];
            for p in &results.measures.elastica {
                let plane = elastica_label(results, p.plane_strain);
                for (name, pick) in [("u/L", 0), ("v/L", 1)] {
                    series.push(XySeries {
                        label: format!("elastica ({plane}) {name}"),
                        points: p
                            .points
                            .iter()
                            .map(|e| (e.load / 1e3, if pick == 0 { e.u_over_l } else { e.v_over_l }))
                            .collect(),
                        line: true,
                        markers: false,
                    });
                }
            }
            for id in &f.cases {
                let Some(r) = results.case(id) else { continue };
                if r.end.is_empty() {
                    continue;
                }
                let label = case_label(&results.study, r);
                for (name, pick) in [("u/L", 0), ("v/L", 1)] {
                    series.push(XySeries {
                        label: format!("{label} {name}"),
                        points: r
                            .end
                            .iter()
                            .map(|d| (d.load / 1e3, if pick == 0 { d.u_over_l } else { d.v_over_l }))
                            .collect(),
                        line: false,
                        markers: true,
                    });
                }
            }
            let axes = XyAxes {
                x_desc: "end load P (kN)".into(),
                y_desc: "end displacement / L".into(),
                log_x: false,
                log_y: false,
                y_lines: vec![],
                legend: LegendCorner::UpperRight,
            };
            xy_svg(&f.title, &axes, &series).map(Some).map_err(fail)
        }
        CantileverFigureKind::Refinement => {
            let Some(r) = results
                .study
                .refinement
                .iter()
                .find(|r| Some(&r.id) == f.refinement.as_ref())
            else {
                return Ok(None);
            };
            let Some((u_ref, what)) = refinement_reference(results, r) else {
                return Ok(None);
            };
            let series: Vec<XySeries> = r
                .methods
                .iter()
                .map(|&m| XySeries {
                    label: m.label().to_string(),
                    points: results
                        .measures
                        .refinement
                        .iter()
                        .filter(|x| x.refinement == r.id && x.method == m)
                        .filter_map(|x| Some((x.element_size, x.u_over_l? / u_ref)))
                        .collect(),
                    line: true,
                    markers: true,
                })
                .filter(|s| !s.points.is_empty())
                .collect();
            let axes = XyAxes {
                x_desc: "element size h".into(),
                y_desc: "final u/L over the reference".into(),
                log_x: true,
                log_y: false,
                y_lines: vec![(0.99, "−1 %".into()), (1.01, "+1 %".into())],
                legend: LegendCorner::LowerLeft,
            };
            let title = format!("{} (reference: {what})", f.title);
            xy_svg(&title, &axes, &series).map(Some).map_err(fail)
        }
    }
}

/// The refinement's reference u/L: the reference method's GCI extrapolation in the asymptotic
/// range, else its finest converged case; with what it is in words.
fn refinement_reference(results: &CantileverResults, r: &RefinementSection) -> Option<(f64, String)> {
    let gci = results
        .measures
        .gci
        .iter()
        .find(|g| g.sweep == r.id && g.series == r.reference.label() && g.measure == "final u/L");
    if let Some(x) = gci
        .and_then(|g| g.gci.as_ref())
        .filter(|x| x.in_asymptotic_range())
    {
        return Some((x.extrapolated, format!("{}, extrapolated", r.reference.label())));
    }
    results
        .measures
        .refinement
        .iter()
        .filter(|x| x.refinement == r.id && x.method == r.reference)
        .filter_map(|x| Some((x.element_size, x.u_over_l?)))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(h, u)| (u, format!("finest {}, h = {h}", r.reference.label())))
}

/// Render the report and figures from `dir`'s `results.json` and `domains.json`.
pub fn render(dir: &Path) -> Result<super::Rendered, StudyError> {
    let results: Results = read_results(dir)?;
    let snapshots: BTreeMap<String, Vec<DomainSnapshot>> = read_json(&dir.join("domains.json"))?;
    let mut files = super::Files::new(dir);
    for f in &results.study.figures {
        files.figure(
            &f.id,
            render_figure(&results, &snapshots, dir, f)?,
            "no data (a domains figure of a case without domain snapshots, or no converged case to plot)",
        )?;
    }
    let report = report_markdown(&results, &files.not_drawn);
    files.report(&results.study.report_file, &report)?;
    Ok(files.done())
}

pub fn index_entry(dir: &Path) -> Result<IndexEntry, StudyError> {
    let r: Results = read_results(dir)?;
    Ok(super::plane_index_entry(
        (&r.study.name, &r.study.summary, r.provenance.tier),
        ("the drawn domains", "domains.json"),
        &r.checks,
        &r.study.report_file,
        std::iter::empty(),
        super::drawn(
            dir,
            r.study.figures.iter().map(|f| (f.title.clone(), f.id.clone())),
        ),
    ))
}

/// What an elastica path stands for: plane strain or stress in 2D, the square section in 3D.
fn elastica_label(results: &CantileverResults, plane_strain: bool) -> &'static str {
    match (results.study.beam.dimension, plane_strain) {
        (3, _) => "3D, EI = E d⁴/12",
        (_, true) => "plane strain",
        (_, false) => "plane stress",
    }
}
