//! The column study's Markdown tables, figures and index entry, rendered from its
//! `results.json` (and, for stress profiles, the point files written beside it) and nothing
//! else, so that `study --render-only` reproduces them byte for byte.

mod figures;
mod report;

pub use figures::render_figure;
pub use report::report_markdown;

use super::IndexEntry;
use crate::basis::method::Method;
use crate::study::column::kind::{points_file, read_points_csv};
use crate::study::column::rates::{case_error, pairwise_rates, series};
use crate::study::column::records::{AnalyticalRecord, ColumnRecord, ColumnResults};
use crate::study::column::{FigureKind, FigureSpec, Measure};
use crate::study::results::{read_results, CaseStatus};
use crate::study::vocabulary::weight_label;
use crate::study::StudyError;
use std::fmt::Write as _;
use std::path::Path;

pub(super) fn series_label(m: Method, ppc: Option<usize>) -> String {
    match ppc {
        Some(p) => format!("{}, {p} point{}/cell", m.label(), if p == 1 { "" } else { "s" }),
        None => m.label().to_string(),
    }
}

pub(super) fn e3(x: Option<f64>) -> String {
    x.map_or("—".into(), |v| format!("{v:.3e}"))
}

pub(super) fn rate(x: Option<f64>) -> String {
    x.map_or("—".into(), |v| format!("{v:.2}"))
}

pub(super) fn status_word(c: &ColumnRecord) -> &'static str {
    c.solve.status.word()
}

/// The case ids of a sweep as the run recorded them.
pub(super) fn of_sweep<'a>(results: &'a ColumnResults, sweep: &str) -> &'a [String] {
    results.sweep_cases.get(sweep).map_or(&[], |v| v.as_slice())
}

/// The analytical column at `load` as the run recorded it.
pub(super) fn analytical_at(results: &ColumnResults, load: f64) -> Result<&AnalyticalRecord, StudyError> {
    results.analytical_at(load).ok_or_else(|| StudyError::Parse {
        file: "results.json".into(),
        message: format!(
            "no analytical record for W = {load} (results written by an older igimp: solve again)"
        ),
    })
}

/// The (method, points per cell) series of a sweep at one load, in plan order.
pub(super) fn sweep_series(
    results: &ColumnResults,
    sweep_id: &str,
    load: f64,
) -> Vec<(Method, Option<usize>)> {
    let spec = &results.study;
    let Some(plan) = spec
        .sweep(sweep_id)
        .and_then(|s| spec.plan(s, results.provenance.tier))
    else {
        return vec![];
    };
    if !plan.weights.contains(&load) {
        return vec![];
    }
    let mut out = vec![];
    for &m in &plan.methods {
        if m.uses_material_points() {
            out.extend(plan.points_per_cell.iter().map(|&p| (m, Some(p))));
        } else {
            out.push((m, None));
        }
    }
    out
}

pub(super) fn fitted(
    results: &ColumnResults,
    sweep: &str,
    m: Method,
    load: f64,
    ppc: Option<usize>,
    measure: Measure,
) -> Option<f64> {
    results
        .measures
        .rates
        .iter()
        .find(|r| {
            r.sweep == sweep
                && r.method == m
                && r.load == load
                && r.points_per_cell == ppc
                && r.measure == measure
        })
        .and_then(|r| r.slope)
}

pub(super) fn pass_word(p: Option<bool>) -> &'static str {
    match p {
        Some(true) => "pass",
        Some(false) => "FAIL",
        None => "not run",
    }
}

/// Render the report and every figure of the column study in `dir` from its `results.json`.
/// Returns the files written.
pub fn render(dir: &Path) -> Result<super::Rendered, StudyError> {
    let results: ColumnResults = read_results(dir)?;
    let mut files = super::Files::new(dir);
    for f in &results.study.figures {
        let reason = "no positive error of a converged case to plot on log-log axes";
        files.figure(&f.id, render_figure(&results, dir, f)?, reason)?;
    }
    let report = report_markdown(&results, &files.not_drawn);
    files.report(&results.study.report_file, &report)?;
    Ok(files.done())
}

/// The column study's section of `reports/index.md`: the report, the results and point
/// files, the ParaView files if written, and every figure inline.
pub fn index_entry(dir: &Path) -> Result<IndexEntry, StudyError> {
    let results: ColumnResults = read_results(dir)?;
    let name = &results.study.name;
    let counts = results.check_counts();
    let mut s = super::index_header(name, &results.study.summary, results.provenance.tier, counts);
    let _ = writeln!(s, "- [tables]({name}/{})", results.study.report_file);
    let _ = writeln!(
        s,
        "- [results.json]({name}/results.json) and per-case point files in `{name}/points/`"
    );
    if dir.join("vtk").is_dir() {
        let _ = writeln!(
            s,
            "- ParaView files (`study {name} --vtk`): `{name}/vtk/<case>.pvd`"
        );
    }
    s.push('\n');
    for f in &results.study.figures {
        if dir.join(format!("{}.svg", f.id)).is_file() {
            let _ = writeln!(
                s,
                "### {}\n\n![{}]({name}/{}.svg)\n",
                super::md_text(&f.title),
                super::md_link_text(&f.title),
                f.id
            );
        } else {
            let _ = writeln!(
                s,
                "### {}\n\nNot drawn (no data): see the report.\n",
                super::md_text(&f.title)
            );
        }
    }
    Ok(IndexEntry {
        name: name.to_string(),
        markdown: s,
        checks: counts,
    })
}
