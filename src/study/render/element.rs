//! Rendering of an element study from `results.json` alone: the report (each test's final
//! state, each closed form beside its measure, the checks) and two figures: the stress paths
//! in the (p, q) plane and q against the driven strain.

use super::{checks_markdown, failures_markdown, IndexEntry};
use crate::study::checks::check_counts;
use crate::study::element::ElementResults;
use crate::study::render::plot2d::{xy_svg, LegendCorner, XyAxes, XySeries};
use crate::study::results::read_results;
use crate::study::StudyError;
use std::fmt::Write as _;
use std::path::Path;

/// (title, id, material, x measure, y measure) of the figures: per material (their stress
/// scales differ by orders), the stress paths in the (p, q) plane and q against the driven
/// strain.
fn figures(r: &ElementResults) -> Vec<(String, String, String, &'static str, &'static str)> {
    let mut out = vec![];
    for name in r.study.materials.keys() {
        if !r.study.tests.iter().any(|t| &t.material == name) {
            continue;
        }
        out.push((
            format!("{name}: stress paths, q against p (compression positive)"),
            format!("{name}-stress-paths"),
            name.clone(),
            "p",
            "q",
        ));
        out.push((
            format!("{name}: q against the driven strain"),
            format!("{name}-stress-strain"),
            name.clone(),
            "strain",
            "q",
        ));
    }
    out
}

fn draw(r: &ElementResults, title: &str, material: &str, x: &str, y: &str) -> Result<Option<String>, String> {
    let series: Vec<XySeries> = r
        .study
        .tests
        .iter()
        .filter(|t| t.material == material)
        .filter_map(|t| {
            let c = r.case(&t.id)?;
            let (xs, ys) = (c.histories.get(x)?, c.histories.get(y)?);
            let mut points: Vec<(f64, f64)> = xs.iter().copied().zip(ys.iter().copied()).collect();
            // The path from its start (after the confinement).
            if x == "p" {
                points.insert(0, (c.start.get("p").copied()?, c.start.get("q").copied()?));
            } else {
                points.insert(0, (0.0, c.start.get("q").copied()?));
            }
            Some(XySeries {
                label: c.id.clone(),
                points,
                line: true,
                markers: false,
            })
        })
        .collect();
    if series.is_empty() {
        return Ok(None);
    }
    let axes = XyAxes {
        x_desc: x.into(),
        y_desc: y.into(),
        log_x: false,
        log_y: false,
        y_lines: vec![],
        legend: LegendCorner::UpperLeft,
    };
    xy_svg(title, &axes, &series).map(Some)
}

fn e(v: Option<f64>, digits: usize) -> String {
    v.map_or("—".into(), |v| format!("{v:.digits$e}"))
}

pub fn report_markdown(r: &ElementResults, not_drawn: &[super::NotDrawn]) -> String {
    let study = &r.study;
    let (pass, fail, none) = check_counts(&r.checks);
    let mut s = format!(
        "# {}: {}\n\n{}\n\nChecks: {pass} passed, {fail} failed, {none} not evaluated.\n\n",
        super::md_text(&study.name),
        super::md_text(&study.summary),
        r.provenance.line()
    );
    s.push_str("One material point per test under a prescribed path, no grid (y axial; stresses compression positive, Kirchhoff).\n\n");
    s.push_str("## Materials\n\n| name | model | parameters |\n|---|---|---|\n");
    for (name, t) in &study.materials {
        let params: Vec<String> = t.parameters.iter().map(|(k, v)| format!("{k} = {v}")).collect();
        let _ = writeln!(s, "| {name} | {} | {} |", t.model, params.join(", "));
    }
    s.push_str("\n## Tests\n\n| test | material | path | confining | strain | steps | status | Newton | p | q | axial stress | lateral stress |\n|---|---|---|---:|---:|---:|---|---:|---:|---:|---:|---:|\n");
    for t in &study.tests {
        let Some(c) = r.case(&t.id) else { continue };
        let m = |k: &str| e(c.measures.get(k).copied(), 6);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            t.id,
            t.material,
            t.path.name(),
            t.confining,
            t.strain,
            t.steps,
            c.solve.status.word(),
            c.solve.newton_iterations,
            m("p"),
            m("q"),
            m("axial_stress"),
            m("lateral_stress")
        );
    }
    s.push('\n');
    if !r.measures.closed_forms.is_empty() {
        s.push_str("## Closed forms\n\n| test | closed form | measure | closed-form value | measured | relative error | source |\n|---|---|---|---:|---:|---:|---|\n");
        for x in &r.measures.closed_forms {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} | {} |",
                x.test,
                x.closed_form.name(),
                x.measure,
                e(x.value, 12),
                e(x.measured, 12),
                e(x.error, 2),
                super::md_text(&x.source)
            );
        }
        s.push('\n');
    }
    s.push_str(&checks_markdown(&r.checks));
    s.push_str(&super::performance_markdown(&r.cases, &r.timing));
    s.push_str(&failures_markdown(
        r.cases
            .iter()
            .map(|c| (c.id.as_str(), c.solve.status, c.solve.failure.as_ref())),
    ));
    let figs = figures(r);
    s.push_str(&super::figures_markdown(
        figs.iter().map(|(t, id, ..)| (t.as_str(), id.as_str())),
        not_drawn,
    ));
    s
}

/// Render the report and figures from `dir`'s `results.json`.
pub fn render(dir: &Path) -> Result<super::Rendered, StudyError> {
    let results: ElementResults = read_results(dir)?;
    let mut files = super::Files::new(dir);
    for (title, id, material, x, y) in figures(&results) {
        let svg = draw(&results, &title, &material, x, y)
            .map_err(|e| StudyError::io(&dir.join(format!("{id}.svg")), e))?;
        files.figure(&id, svg, "no converged test")?;
    }
    let report = report_markdown(&results, &files.not_drawn);
    files.report(&results.study.report_file, &report)?;
    Ok(files.done())
}

pub fn index_entry(dir: &Path) -> Result<IndexEntry, StudyError> {
    let r: ElementResults = read_results(dir)?;
    let figs: Vec<(String, String)> = figures(&r).into_iter().map(|(t, id, ..)| (t, id)).collect();
    Ok(super::plane_index_entry(
        (&r.study.name, &r.study.summary, r.provenance.tier),
        ("every test's measures and histories", "results.json"),
        &r.checks,
        &r.study.report_file,
        std::iter::empty(),
        super::drawn(dir, figs),
    ))
}
