//! Rendering of the manufactured-solution study: the report (errors per level, pairwise and
//! fitted rates with their bands), the log-log convergence figures and the domain figures,
//! from `results.json` and `domains.json` only.

use super::{checks_markdown, failures_markdown, IndexEntry};
use crate::study::checks::check_counts;
use crate::study::manufactured::records::{CasePoints, ManufacturedRecord};
use crate::study::manufactured::{ErrorMeasure, Field, FigureKind, FigureSpec, ManufacturedResults};
use crate::study::render::plot::{convergence_svg_along, ConvergenceSeries};
use crate::study::render::plot2d::{domains_svg, Domain, DomainLayer};
use crate::study::results::{read_json, read_results};
use crate::study::StudyError;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

type Results = ManufacturedResults;

fn e3(x: Option<f64>) -> String {
    x.map_or("—".into(), |v| format!("{v:.3e}"))
}

fn r2(x: Option<f64>) -> String {
    x.map_or("—".into(), |v| format!("{v:.2}"))
}

/// log2(e_coarse / e_fine) / log2(n_fine / n_coarse) between consecutive levels.
fn pairwise(cases: &[&ManufacturedRecord], m: ErrorMeasure) -> Vec<Option<f64>> {
    (0..cases.len())
        .map(|i| {
            let (a, b) = (cases.get(i.wrapping_sub(1))?, cases[i]);
            let r = (a.error(m)? / b.error(m)?).log2() / (b.cells as f64 / a.cells as f64).log2();
            r.is_finite().then_some(r)
        })
        .collect()
}

pub fn report_markdown(results: &Results, not_drawn: &[super::NotDrawn]) -> String {
    let study = &results.study;
    let (pass, fail, none) = check_counts(&results.checks);
    let mut s = format!(
        "# {}: {}\n\n{}\n\nChecks: {pass} passed, {fail} failed, {none} not evaluated.\n\n",
        super::md_text(&study.name),
        super::md_text(&study.summary),
        results.provenance.line()
    );
    let dim = study.dimension as usize;
    let (body, boundary) = if dim == 3 {
        ("cube", "face")
    } else {
        ("square", "edge")
    };
    let _ = writeln!(
        s,
        "Hencky elasticity E = {}, ν = {}; the unit {body} filled by material and grid; rollers on every {boundary}; the manufactured body force ramped over {} load steps. Errors at the material (Gauss) points: displacement ‖x_p − x(X_p)‖ / ‖u(X_p)‖, stress Σ‖σ_p − σ(X_p)‖ v_p0 / (σ_max |Ω₀|). Rates are slopes of log(error) against log(h); pairwise rates in brackets.\n",
        study.material.parameter("young_modulus"),
        study.material.parameter("poisson_ratio"),
        study.load_steps
    );
    for sw in &study.sweeps {
        let Some(ids) = results.sweep_cases.get(&sw.id) else {
            continue;
        };
        let mut cells: Vec<usize> = ids
            .iter()
            .filter_map(|i| results.case(i))
            .map(|c| c.cells)
            .collect();
        cells.sort_unstable();
        cells.dedup();
        let amplitude = match sw.field {
            Field::AxisAligned => study.amplitude.axis_aligned,
            Field::Vortex => study.amplitude.vortex,
        };
        let _ = writeln!(
            s,
            "## {}\n\n{} (amplitude {amplitude}).\n",
            super::md_text(&sw.id),
            super::md_text(&sw.title)
        );
        for m in ErrorMeasure::ALL {
            let _ = write!(s, "### {}\n\n| series |", m.label());
            for n in &cells {
                let _ = write!(s, " h = 1/{n} |");
            }
            s.push_str(" fitted rate |\n|---|");
            for _ in &cells {
                s.push_str("---:|");
            }
            s.push_str("---:|\n");
            for ser in results.sweep_series(&sw.id) {
                let cs = results.series_cases(&sw.id, &ser);
                let pr = pairwise(&cs, m);
                let _ = write!(s, "| {} |", ser.label(dim));
                for n in &cells {
                    match cs.iter().position(|c| c.cells == *n) {
                        Some(i) => {
                            let _ = write!(
                                s,
                                " {}{} |",
                                e3(cs[i].error(m)),
                                pr[i].map_or(String::new(), |r| format!(" ({r:.2})"))
                            );
                        }
                        None => s.push_str(" |"),
                    }
                }
                let rate = results
                    .measures
                    .rates
                    .iter()
                    .find(|r| r.sweep == sw.id && r.series == ser && r.measure == m);
                let _ = writeln!(s, " {} |", r2(rate.and_then(|r| r.slope)));
            }
            s.push('\n');
        }
    }
    s.push_str("## Expected rates\n\n| sweep | series | measure | fitted over cells | slope | band | source |\n|---|---|---|---|---:|---|---|\n");
    for r in results.measures.rates.iter().filter(|r| r.expected.is_some()) {
        let e = r.expected.as_ref().expect("filtered");
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:?} | {} | {} ± {} | {} |",
            r.sweep,
            r.series.label(dim),
            r.measure.name(),
            r.cells_used,
            r2(r.slope),
            e.rate,
            e.tolerance,
            e.source.replace('|', "\\|")
        );
    }
    s.push('\n');
    s.push_str(&checks_markdown(&results.checks));
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

fn render_figure(
    results: &Results,
    domains: &BTreeMap<String, CasePoints>,
    dir: &Path,
    f: &FigureSpec,
) -> Result<Option<String>, StudyError> {
    let err = |e: String| StudyError::io(&dir.join(format!("{}.svg", f.id)), e);
    match f.kind {
        FigureKind::Convergence => {
            let m = f.measure.unwrap_or(ErrorMeasure::Displacement);
            let series: Vec<ConvergenceSeries> = results
                .sweep_series(&f.sweep)
                .into_iter()
                .filter_map(|ser| {
                    let points: Vec<(f64, f64)> = results
                        .series_cases(&f.sweep, &ser)
                        .into_iter()
                        .filter_map(|c| Some((c.cells as f64, c.error(m)?)))
                        .collect();
                    let slope = results
                        .measures
                        .rates
                        .iter()
                        .find(|r| r.sweep == f.sweep && r.series == ser && r.measure == m)
                        .and_then(|r| r.slope);
                    (points.len() >= 2).then(|| ConvergenceSeries {
                        label: ser.label(results.study.dimension as usize),
                        points,
                        slope,
                    })
                })
                .collect();
            if series.is_empty() {
                return Ok(None);
            }
            convergence_svg_along(&f.title, "cells per side (h = 1/n)", m.label(), &series, true)
                .map(Some)
                .map_err(err)
        }
        FigureKind::Domains => {
            let id = results.study.drawn_cases();
            let Some(p) = id.iter().find_map(|id| {
                let c = results.case(id)?;
                (Some(c.cells as i64) == f.cells
                    && c.points_per_cell.map(|p| p as i64) == f.points_per_cell
                    && c.domain_update == Some(f.domain_update.unwrap_or_default()))
                .then(|| domains.get(id))
                .flatten()
            }) else {
                return Ok(None);
            };
            let layer = DomainLayer {
                label: "final domains".into(),
                domains: p
                    .points
                    .iter()
                    .map(|q| Domain {
                        centre: q.x,
                        half: q.half,
                    })
                    .collect(),
                values: Some(p.stress_error.clone()),
                colour: None,
            };
            domains_svg(&f.title, "‖σ_p − σ(X_p)‖ / σ_max", ("x", "y"), &[layer], &[])
                .map(Some)
                .map_err(err)
        }
    }
}

/// Render the report and figures from `dir`'s `results.json` and `domains.json`.
pub fn render(dir: &Path) -> Result<super::Rendered, StudyError> {
    let results: Results = read_results(dir)?;
    let domains: BTreeMap<String, CasePoints> = read_json(&dir.join("domains.json"))?;
    let mut files = super::Files::new(dir);
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
        std::iter::empty(),
        super::drawn(
            dir,
            r.study.figures.iter().map(|f| (f.title.clone(), f.id.clone())),
        ),
    ))
}
