//! Rendering of the compaction study (§5.2): the report, Tables 2–3 and Figures 15–18 from
//! `results.json` and `domains.json` only.

use crate::basis::method::Method;
use crate::study::compaction::*;
use crate::study::render::plot2d::{
    domains_svg, xy_svg, Domain, DomainLayer, LegendCorner, XyAxes, XySeries,
};
use crate::study::vocabulary::{number, points_grid, GhostFaces, ResidualNorm};
type Results = CompactionResults;
use super::{checks_markdown, failures_markdown, IndexEntry};
use crate::study::checks::check_counts;
use crate::study::results::{read_json, read_results, CaseStatus};
use crate::study::StudyError;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::Path;

fn e3(x: Option<f64>) -> String {
    x.map_or("—".into(), |v| format!("{v:.3e}"))
}

fn ppc_label(results: &CompactionResults, p: usize) -> String {
    format!(
        "{} points/cell",
        points_grid(p, results.study.block.dimension as usize)
    )
}

/// Table 2 / Table 3: this code's residuals beside the paper's, per step and iteration.
pub fn residual_table(results: &CompactionResults, p: &PaperResiduals) -> String {
    let mut s = format!(
        "# {}: {}\n\n{}\n\n",
        super::md_text(&p.table),
        super::md_text(&p.title),
        results.provenance.line()
    );
    let case = results.igimp_case(&p.sweep, p.element_size, p.points_per_cell as usize);
    let measure = match results.study.newton.residual_norm {
        ResidualNorm::External => "‖f_int − f_ext‖ / ‖f_ext‖ over the free dofs (`external`)",
        ResidualNorm::Total => {
            "‖f_int − f_ext‖ over the free dofs / ‖f_ext + f_reaction‖ over all dofs, exact reactions (`total`)"
        }
        ResidualNorm::Linearised => {
            "‖f^ob‖ / ‖f_ext + f_rct‖ over all dofs, the reactions updated by their linearised increment as the paper's group computes them (`linearised`, reference/README.md item 18)"
        }
    };
    let _ = writeln!(
        s,
        "Normalised out-of-balance force {measure} after each Newton iteration \
         (iteration k is the residual after the k-th solve), case `{}`. \"code\" is this code, \
         \"paper\" the printed value.\n",
        case.map_or("(not run in this tier)", |c| c.id.as_str())
    );
    let Some(case) = case else { return s };
    if case.yield_stress.is_some() {
        // Measured with the points numbered cell by cell instead of row by row (a change of
        // summation order only): every answer of this 2D study equal to 5e-11, each step's
        // first residual to 6e-9, the later ones moved at the first or second digit
        // (reference/README.md item 55).
        s.push_str(
            "The iterates after a plastic step's first are sensitive to round-off: points whose \
             trial state lies within round-off of the yield surface may take either branch of \
             the return mapping, and so either tangent. Changing only the order of the \
             tangent's sums (the points numbered cell by cell) moved these residuals at the \
             first or second digit while every answer stayed equal to 5e-11 and each step's \
             first residual to 6e-9 (reference/README.md item 55). Compare the pattern with \
             the paper's (iterations per step, the final quadratic drops), not the digits.\n\n",
        );
    }
    if case.solve.status != CaseStatus::Converged {
        let _ = writeln!(
            s,
            "The case did not converge: {}.\n",
            case.solve
                .failure
                .as_ref()
                .map_or(String::new(), |f| format!("step {}: {}", f.step, f.reason))
        );
    }
    let rows = p.residuals.iter().map(Vec::len).max().unwrap_or(0).max(
        p.steps
            .iter()
            .filter_map(|&st| case.solve.steps.iter().find(|r| r.step == st as usize))
            .map(|r| r.residuals.len().saturating_sub(1))
            .max()
            .unwrap_or(0),
    );
    let _ = write!(s, "| iteration |");
    for st in &p.steps {
        let _ = write!(s, " step {st} code | step {st} paper |");
    }
    let _ = write!(s, "\n|---:|");
    for _ in &p.steps {
        let _ = write!(s, "---:|---:|");
    }
    s.push('\n');
    for k in 1..=rows {
        let _ = write!(s, "| {k} |");
        for (j, &st) in p.steps.iter().enumerate() {
            let code = case
                .solve
                .steps
                .iter()
                .find(|r| r.step == st as usize)
                .and_then(|r| r.residuals.get(k).copied());
            let _ = write!(s, " {} | {} |", e3(code), e3(p.residuals[j].get(k - 1).copied()));
        }
        s.push('\n');
    }
    s.push('\n');
    s
}

fn figure17_table(results: &CompactionResults) -> String {
    let sweep_id = &results.study.reference.igimp_sweep;
    let cases = results.sweep(sweep_id);
    let mut hs: Vec<f64> = cases.iter().map(|c| c.h).collect();
    hs.sort_by(|a, b| b.total_cmp(a));
    hs.dedup();
    let ppcs: BTreeSet<usize> = cases.iter().filter_map(|c| c.points_per_cell).collect();
    let fems: BTreeSet<Method> = cases.iter().map(|c| c.method).filter(|m| m.is_fem()).collect();
    let reference = results.measures.reference.as_ref();
    let mut s = format!(
        "## Figure 17: maximum horizontal displacement\n\nBottom-right material point's horizontal displacement plus half the growth of its domain \
         (FEM: bottom-right node). Normalised by u_ref = {} ({}). Each cell: u, then u/u_ref.\n\n| h |",
        reference.map_or("—".into(), |r| format!("{:.6}", r.value)),
        reference.map_or("no converged case", |r| r.description.as_str())
    );
    for p in &ppcs {
        let _ = write!(s, " iGIMP {} |", ppc_label(results, *p));
    }
    for m in &fems {
        let _ = write!(s, " {} |", m.label());
    }
    let _ = write!(s, "\n|---:|");
    for _ in 0..ppcs.len() + fems.len() {
        s.push_str("---:|");
    }
    s.push('\n');
    let cell = |c: Option<&&CompactionRecord>| -> String {
        match c {
            None => "—".into(),
            Some(c) => match (c.solve.status, c.max_horizontal_displacement) {
                (CaseStatus::Converged, Some(u)) => match reference {
                    Some(r) => format!("{u:.5} ({:.4})", u / r.value),
                    None => format!("{u:.5}"),
                },
                (CaseStatus::Failed, _) => {
                    format!(
                        "failed at step {}",
                        c.solve.failure.as_ref().map_or(0, |f| f.step)
                    )
                }
                _ => "rejected".into(),
            },
        }
    };
    for h in hs {
        let _ = write!(s, "| {h} |");
        for p in &ppcs {
            let c = cases
                .iter()
                .find(|c| c.h == h && c.points_per_cell == Some(*p) && results.is_default(c));
            let _ = write!(s, " {} |", cell(c));
        }
        for m in &fems {
            let _ = write!(
                s,
                " {} |",
                cell(cases.iter().find(|c| c.h == h && c.method == *m))
            );
        }
        s.push('\n');
    }
    s.push('\n');
    s
}

fn cases_table(results: &CompactionResults) -> String {
    let mut s = String::from(
        "## All cases\n\n| case | method | h | points/cell | ρ_y | weak-node tol. | ghost γ | status | max horizontal u | weak nodes treated | steps cut (attempts failed) | Newton its/step |\n|---|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|\n",
    );
    for c in &results.cases {
        let u = c
            .max_horizontal_displacement
            .map(|u| format!("{u:.6}"))
            .or_else(|| {
                c.last_converged_displacement
                    .map(|u| format!("({u:.4} at last converged step)"))
            })
            .unwrap_or("—".into());
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            c.id,
            c.method.label(),
            c.h,
            c.points_per_cell.map_or("—".into(), |p| points_grid(
                p,
                results.study.block.dimension as usize
            )),
            c.yield_stress.map_or("elastic".into(), number),
            c.weak_node_tolerance,
            if c.method.is_fem() {
                "—".into()
            } else if c.ghost_gamma > 0.0 && c.ghost_faces == GhostFaces::All {
                format!("{} (all faces)", number(c.ghost_gamma))
            } else {
                number(c.ghost_gamma)
            },
            c.solve.status.word(),
            u,
            c.weak_nodes_treated,
            if c.steps_cut == 0 {
                "0".into()
            } else {
                format!("{} ({})", c.steps_cut, c.cutbacks)
            },
            if c.solve.steps.is_empty() {
                "—".into()
            } else {
                format!(
                    "{:.2}",
                    c.solve.newton_iterations as f64 / c.solve.steps.len() as f64
                )
            }
        );
    }
    s.push('\n');
    s
}

/// The main report.
pub fn report_markdown(results: &CompactionResults, not_drawn: &[super::NotDrawn]) -> String {
    let spec = &results.study;
    let (pass, fail, none) = check_counts(&results.checks);
    let count = |st| results.cases.iter().filter(|c| c.solve.status == st).count();
    let mut s = format!(
        "# {}: {}\n\n{}\n\nChecks: {pass} passed, {fail} failed, {none} not evaluated. Cases: {} converged, {} failed, {} rejected.\n\n",
        super::md_text(&spec.name),
        super::md_text(&spec.summary),
        results.provenance.line(),
        count(CaseStatus::Converged),
        count(CaseStatus::Failed),
        count(CaseStatus::Rejected)
    );
    s.push_str(&figure17_table(results));
    s.push_str(&super::gci_markdown(&results.measures.gci));
    s.push_str(&checks_markdown(&results.checks));
    for p in &spec.paper_residuals {
        let _ = writeln!(
            s,
            "- {}: [{}]({})",
            super::md_text(&p.table),
            super::md_link_text(&p.title),
            p.file
        );
    }
    s.push('\n');
    s.push_str(&cases_table(results));
    s.push_str(&super::performance_markdown(&results.cases, &results.timing));
    s.push_str(&failures_markdown(
        results
            .cases
            .iter()
            .map(|c| (c.id.as_str(), c.solve.status, c.solve.failure.as_ref())),
    ));
    s.push_str(&super::figures_markdown(
        super::figures_in_tier(
            &results.study.figures,
            &results.study.sweeps,
            results.provenance.tier,
        )
        .map(|f| (f.title.as_str(), f.id.as_str())),
        not_drawn,
    ));
    s
}

fn figure_error(dir: &Path, id: &str) -> impl Fn(String) -> StudyError {
    let path = dir.join(format!("{id}.svg")).display().to_string();
    move |message| StudyError::Io {
        path: path.clone(),
        message,
    }
}

fn render_figure(
    results: &CompactionResults,
    domains: &BTreeMap<String, Vec<DomainRecord>>,
    dir: &Path,
    f: &CompactionFigure,
) -> Result<Option<String>, StudyError> {
    let fail = figure_error(dir, &f.id);
    let case = match (f.element_size, f.points_per_cell) {
        (Some(h), Some(p)) => results.igimp_case(&f.sweep, h, p as usize),
        _ => None,
    };
    match f.kind {
        CompactionFigureKind::Domains => {
            let Some(points) = case.and_then(|c| domains.get(&c.id)) else {
                return Ok(None);
            };
            let c = case.expect("checked above");
            let initial = points
                .iter()
                .map(|d| Domain {
                    centre: d.x0,
                    half: d.half0,
                })
                .collect();
            let current = points
                .iter()
                .map(|d| Domain {
                    centre: d.x,
                    half: d.half,
                })
                .collect();
            let title = match c.solve.status {
                CaseStatus::Converged => f.title.clone(),
                _ => format!("{} (last converged step)", f.title),
            };
            // The 3D study's domains are the slice next to y = 0, vertical axis z.
            let (vertical, axis) = if results.study.block.dimension == 3 {
                ("σzz", "z")
            } else {
                ("σyy", "y")
            };
            domains_svg(
                &title,
                vertical,
                ("x", axis),
                &[
                    DomainLayer {
                        label: "initial".into(),
                        domains: initial,
                        values: None,
                        colour: None,
                    },
                    DomainLayer {
                        label: String::new(),
                        domains: current,
                        values: Some(points.iter().map(|d| d.sigma_yy).collect()),
                        colour: Some(0),
                    },
                ],
                &[],
            )
            .map(Some)
            .map_err(fail)
        }
        CompactionFigureKind::Residuals => {
            let step = f.step.unwrap_or(1) as usize;
            let Some(rec) = case.and_then(|c| c.solve.steps.iter().find(|r| r.step == step)) else {
                return Ok(None);
            };
            let code: Vec<(f64, f64)> = rec
                .residuals
                .iter()
                .enumerate()
                .skip(1)
                .map(|(k, &r)| (k as f64, r))
                .collect();
            let mut series = vec![XySeries {
                label: format!("this code, load step {step}"),
                points: code,
                line: true,
                markers: true,
            }];
            for p in results.study.paper_residuals.iter().filter(|p| {
                p.sweep == f.sweep
                    && Some(p.element_size) == f.element_size
                    && Some(p.points_per_cell) == f.points_per_cell
            }) {
                if let Some(j) = p.steps.iter().position(|&s| s as usize == step) {
                    series.push(XySeries {
                        label: format!("paper {}, load step {step}", p.table),
                        points: p.residuals[j]
                            .iter()
                            .enumerate()
                            .map(|(k, &r)| ((k + 1) as f64, r))
                            .collect(),
                        line: true,
                        markers: true,
                    });
                }
            }
            let axes = XyAxes {
                x_desc: "Newton iteration".into(),
                y_desc: "normalised out-of-balance force".into(),
                log_x: false,
                log_y: true,
                y_lines: vec![],
                legend: LegendCorner::UpperRight,
            };
            xy_svg(&f.title, &axes, &series).map(Some).map_err(fail)
        }
        CompactionFigureKind::DisplacementConvergence => {
            let Some(reference) = &results.measures.reference else {
                return Ok(None);
            };
            let cases = results.sweep(&f.sweep);
            let mut groups: BTreeMap<SeriesKey, Vec<(f64, f64)>> = BTreeMap::new();
            for c in cases.iter().filter(|c| results.is_default(c)) {
                if let Some(u) = c.max_horizontal_displacement {
                    groups
                        .entry((c.method, c.points_per_cell))
                        .or_default()
                        .push((c.h, u / reference.value));
                }
            }
            let series: Vec<XySeries> = groups
                .into_iter()
                .map(|((m, p), pts)| XySeries {
                    label: match p {
                        Some(p) => format!("{}, {}", m.label(), ppc_label(results, p)),
                        None => m.label().to_string(),
                    },
                    points: pts,
                    line: true,
                    markers: true,
                })
                .collect();
            let axes = XyAxes {
                x_desc: "element size h".into(),
                y_desc: "u_max / u_ref".into(),
                log_x: true,
                log_y: false,
                y_lines: vec![(0.99, "−1 %".into()), (1.01, "+1 %".into())],
                legend: LegendCorner::LowerLeft,
            };
            // The full description is in the report; the title only names the reference.
            let short = match (reference.method, reference.observed_order) {
                (Method::IGIMP, _) => "finest iGIMP (no FEM)".to_string(),
                (m, Some(_)) => format!("{}, extrapolated", m.label()),
                (m, None) => format!("finest {}", m.label()),
            };
            let title = format!("{} (u_ref: {short})", f.title);
            xy_svg(&title, &axes, &series).map(Some).map_err(fail)
        }
    }
}

/// A Figure 17 series: method and points per cell.
type SeriesKey = (Method, Option<usize>);

/// Render the report, the residual tables and the figures from `dir`'s `results.json` and
/// `domains.json`. Returns the files written.
pub fn render(dir: &Path) -> Result<super::Rendered, StudyError> {
    let results: Results = read_results(dir)?;
    let domains: BTreeMap<String, Vec<DomainRecord>> = read_json(&dir.join("domains.json"))?;
    let mut files = super::Files::new(dir);
    for p in &results.study.paper_residuals {
        files.text(&p.file, &residual_table(&results, p))?;
    }
    for f in super::figures_in_tier(
        &results.study.figures,
        &results.study.sweeps,
        results.provenance.tier,
    ) {
        files.figure(
            &f.id,
            render_figure(&results, &domains, dir, f)?,
            "no data (no converged case among those it shows)",
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
        r.study
            .paper_residuals
            .iter()
            .map(|p| (format!("{}: {}", p.table, p.title), p.file.clone())),
        super::drawn(
            dir,
            r.study.figures.iter().map(|f| (f.title.clone(), f.id.clone())),
        ),
    ))
}
