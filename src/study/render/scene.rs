//! Rendering of a scene study from `results.json` alone: the report (every measure of every
//! case beside its reference, the fitted rates, the checks) and, per sweep, a log-log figure of
//! each referenced measure's error against h and a load curve of each history measure.

use super::{checks_markdown, failures_markdown, IndexEntry};
use crate::study::checks::check_counts;
use crate::study::render::plot::{convergence_svg_along, ConvergenceSeries};
use crate::study::render::plot2d::{xy_svg, LegendCorner, XyAxes, XySeries};
use crate::study::results::read_results;
use crate::study::scene::SceneResults;
use crate::study::StudyError;
use std::fmt::Write as _;
use std::path::Path;

/// (title, id) of every figure the results can draw, in order.
fn figures(r: &SceneResults) -> Vec<(String, String, Figure)> {
    let mut out = vec![];
    for s in &r.study.sweeps {
        for m in &r.study.measures {
            if r.measures.references.contains_key(&m.name) {
                out.push((
                    format!("{}: error of {} against h", s.title, m.name),
                    format!("{}-{}-error", s.id, m.name),
                    Figure::Error(s.id.clone(), m.name.clone()),
                ));
            }
            if r.cases.iter().any(|c| c.profiles.contains_key(&m.name)) {
                out.push((
                    format!(
                        "{}: {} along its line, finest case of each method",
                        s.title, m.name
                    ),
                    format!("{}-{}-profile", s.id, m.name),
                    Figure::Profile(s.id.clone(), m.name.clone()),
                ));
            }
            if m.history {
                let over = if r.study.strength_reduction.is_some() {
                    "against the strength reduction factor"
                } else {
                    "over the load steps"
                };
                out.push((
                    format!("{}: {} {over}, finest case of each method", s.title, m.name),
                    format!("{}-{}-history", s.id, m.name),
                    Figure::History(s.id.clone(), m.name.clone()),
                ));
            }
        }
    }
    out
}

enum Figure {
    Error(String, String),
    History(String, String),
    Profile(String, String),
}

/// The finest case of each method and points per cell of `sweep` that has `has`: a legend
/// of every case would not fit beside the curves.
fn finest_cases<'a>(
    r: &'a SceneResults,
    sweep: &str,
    has: impl Fn(&crate::study::scene::SceneRecord) -> bool,
) -> Vec<&'a crate::study::scene::SceneRecord> {
    let mut finest: Vec<&crate::study::scene::SceneRecord> = vec![];
    for c in r.sweep(sweep) {
        if !has(c) {
            continue;
        }
        match finest
            .iter_mut()
            .find(|f| f.method == c.method && f.points_per_cell == c.points_per_cell)
        {
            Some(f) if c.h < f.h => *f = c,
            Some(_) => {}
            None => finest.push(c),
        }
    }
    finest
}

/// Curves of a measure on linear axes, the legend in the lower left.
fn lines(title: &str, x_desc: &str, measure: &str, series: &[XySeries]) -> Result<Option<String>, String> {
    let axes = XyAxes {
        x_desc: x_desc.into(),
        y_desc: measure.into(),
        log_x: false,
        log_y: false,
        y_lines: vec![],
        legend: LegendCorner::LowerLeft,
    };
    xy_svg(title, &axes, series).map(Some)
}

fn draw(r: &SceneResults, title: &str, f: &Figure) -> Result<Option<String>, String> {
    match f {
        Figure::Error(sweep, measure) => {
            let series: Vec<ConvergenceSeries> = r
                .measures
                .rates
                .iter()
                .filter(|x| &x.sweep == sweep && &x.measure == measure && x.errors.len() >= 2)
                .map(|x| ConvergenceSeries {
                    label: match x.points_per_cell {
                        Some(p) => format!("{} {p}ppc", x.method.name()),
                        None => x.method.name().to_string(),
                    },
                    // Exact answers (round-off) plot at the floor of the axis, not at 0.
                    points: x.errors.iter().map(|&(h, e)| (1.0 / h, e.max(1e-17))).collect(),
                    slope: x.slope,
                })
                .collect();
            if series.is_empty() {
                return Ok(None);
            }
            convergence_svg_along(title, "1 / h", "relative error", &series, true).map(Some)
        }
        Figure::Profile(sweep, measure) => {
            let series: Vec<XySeries> = finest_cases(r, sweep, |c| c.profiles.contains_key(measure))
                .iter()
                .map(|c| {
                    let p = &c.profiles[measure];
                    let n = (p.len().max(2) - 1) as f64;
                    XySeries {
                        label: c.id.clone(),
                        points: p.iter().enumerate().map(|(k, &v)| (k as f64 / n, v)).collect(),
                        line: true,
                        markers: false,
                    }
                })
                .collect();
            if series.is_empty() {
                return Ok(None);
            }
            lines(title, "position along the line (fraction)", measure, &series)
        }
        Figure::History(sweep, measure) => {
            let steps = r
                .study
                .sweeps
                .iter()
                .find(|s| &s.id == sweep)
                .and_then(|s| s.load_steps)
                .unwrap_or(r.study.load_steps)
                .max(1) as f64;
            let finest = finest_cases(r, sweep, |c| c.histories.contains_key(measure));
            // Under a strength reduction the curve runs against its factor F (the steps
            // before F rises stack at its start value): the F–displacement curve whose
            // take-off marks the failure.
            let reduction = r.study.strength_reduction.as_ref().map(|s| &s.ramp);
            // Else, under one displacement load on a tabled ramp (a footing settled slowly
            // first), against that load's factor: the curve stays a pressure–settlement one.
            let moved: Vec<_> = r
                .study
                .loads
                .iter()
                .filter(|l| l.displacement.is_some())
                .collect();
            let driver = match moved[..] {
                [l] if reduction.is_none() && !l.ramp.is_linear() => Some(l),
                _ => None,
            };
            let ramp = reduction.or(driver.map(|l| &l.ramp));
            // After step k of the sweep's load steps (a failed case stops early).
            let along = |h: &[f64]| -> Vec<(f64, f64)> {
                h.iter()
                    .enumerate()
                    .map(|(k, &v)| {
                        let t = (k + 1) as f64 / steps;
                        (ramp.map_or(t, |ramp| ramp.factor(t)), v)
                    })
                    .collect()
            };
            let mut series: Vec<XySeries> = finest
                .iter()
                .map(|c| XySeries {
                    label: c.id.clone(),
                    points: along(&c.histories[measure]),
                    line: true,
                    markers: true,
                })
                .collect();
            if let Some(reference) = r
                .measures
                .references
                .get(measure)
                .filter(|x| !x.history.is_empty())
            {
                series.push(XySeries {
                    label: "reference".into(),
                    points: along(&reference.history),
                    line: true,
                    markers: false,
                });
            }
            if series.is_empty() {
                return Ok(None);
            }
            let x = match (reduction, driver) {
                (Some(_), _) => "strength reduction factor F".to_string(),
                (None, Some(l)) => format!(
                    "{}: fraction of its full displacement",
                    l.name.as_deref().unwrap_or("load")
                ),
                (None, None) => "load fraction".to_string(),
            };
            lines(title, &x, measure, &series)
        }
    }
}

fn e3(x: Option<f64>) -> String {
    x.map_or("—".into(), |v| format!("{v:.3e}"))
}

pub fn report_markdown(r: &SceneResults, not_drawn: &[super::NotDrawn]) -> String {
    let study = &r.study;
    let (pass, fail, none) = check_counts(&r.checks);
    let mut s = format!(
        "# {}: {}\n\n{}\n\nChecks: {pass} passed, {fail} failed, {none} not evaluated.\n\n",
        super::md_text(&study.name),
        super::md_text(&study.summary),
        r.provenance.line()
    );
    let _ = writeln!(
        s,
        "A scene in {}D: {} bod{} ({}), {} support(s), {} load(s), {} load steps. Errors are relative to the reference's magnitude (absolute where the reference is 0).\n",
        study.dimension,
        study.bodies.len(),
        if study.bodies.len() == 1 { "y" } else { "ies" },
        study.bodies.iter().map(|b| format!("{} of {}", b.name, b.material)).collect::<Vec<_>>().join(", "),
        study.supports.len(),
        study.loads.len(),
        study.load_steps
    );
    // A study whose measures have no reference (a load curve) gets no empty table.
    if !r.measures.references.is_empty() {
        s.push_str("## References\n\n| measure | value | source |\n|---|---:|---|\n");
        for (name, v) in &r.measures.references {
            let _ = writeln!(s, "| {name} | {:.10e} | {} |", v.value, super::md_text(&v.source));
        }
        s.push('\n');
    }
    if !r.measures.gci.is_empty() {
        s.push_str(&super::gci_markdown(&r.measures.gci));
    }
    for sw in &study.sweeps {
        let cases = r.sweep(&sw.id);
        if cases.is_empty() {
            continue;
        }
        let _ = writeln!(
            s,
            "## {}\n\n{}\n",
            super::md_text(&sw.id),
            super::md_text(&sw.title)
        );
        // Older records carry no cut-backs: the column shows only where some were recorded,
        // so that their absence is not read as none (reference/README.md item 76).
        let cut = |c: &crate::study::scene::SceneRecord| -> (usize, usize) {
            c.solve
                .steps
                .iter()
                .fold((0, 0), |(n, i), st| (n + st.cutbacks, i + st.earlier_iterations))
        };
        let show_cuts = cases.iter().any(|c| cut(c).0 > 0);
        s.push_str("| case | status | Newton |");
        if show_cuts {
            s.push_str(" cut-backs (their Newton) |");
        }
        for m in &study.measures {
            let _ = write!(s, " {} |", m.name);
            if r.measures.references.contains_key(&m.name) {
                let _ = write!(s, " error |");
            }
        }
        s.push_str("\n|---|---|---:|");
        if show_cuts {
            s.push_str("---:|");
        }
        for m in &study.measures {
            s.push_str("---:|");
            if r.measures.references.contains_key(&m.name) {
                s.push_str("---:|");
            }
        }
        s.push('\n');
        for c in cases {
            let _ = write!(
                s,
                "| {} | {} | {} |",
                c.id,
                c.solve.status.word(),
                c.solve.newton_iterations
            );
            if show_cuts {
                let (n, i) = cut(c);
                let _ = write!(s, " {n} ({i}) |");
            }
            for m in &study.measures {
                let v = c.measures.get(&m.name).copied();
                let _ = write!(s, " {} |", v.map_or("—".into(), |v| format!("{v:.6e}")));
                if let Some(reference) = r.measures.references.get(&m.name) {
                    let e = v.filter(|_| c.solve.status.solved()).map(|v| reference.error(v));
                    let _ = write!(s, " {} |", e3(e));
                }
            }
            s.push('\n');
        }
        s.push('\n');
    }
    let fitted: Vec<_> = r.measures.rates.iter().filter(|x| x.slope.is_some()).collect();
    if !fitted.is_empty() {
        s.push_str("## Fitted rates\n\nSlope of log(error) against log(h) over every converged h of the series (none where an error is at round-off, below 1e-13).\n\n| sweep | measure | series | slope |\n|---|---|---|---:|\n");
        for x in fitted {
            let ppc = x.points_per_cell.map_or(String::new(), |p| format!(" {p}ppc"));
            let _ = writeln!(
                s,
                "| {} | {} | {}{ppc} | {:.2} |",
                x.sweep,
                x.measure,
                x.method.name(),
                x.slope.unwrap_or(f64::NAN)
            );
        }
        s.push('\n');
    }
    s.push_str(&checks_markdown(&r.checks));
    s.push_str(&super::external::external_markdown(r));
    s.push_str(&super::performance_markdown(&r.cases, &r.timing));
    s.push_str(&failures_markdown(
        r.cases
            .iter()
            .map(|c| (c.id.as_str(), c.solve.status, c.solve.failure.as_ref())),
    ));
    let figs = figures(r);
    s.push_str(&super::figures_markdown(
        figs.iter().map(|(t, id, _)| (t.as_str(), id.as_str())),
        not_drawn,
    ));
    s
}

/// Render the report and figures from `dir`'s `results.json`.
pub fn render(dir: &Path) -> Result<super::Rendered, StudyError> {
    let results: SceneResults = read_results(dir)?;
    let mut files = super::Files::new(dir);
    for (title, id, f) in figures(&results) {
        let svg =
            draw(&results, &title, &f).map_err(|e| StudyError::io(&dir.join(format!("{id}.svg")), e))?;
        files.figure(
            &id,
            svg,
            "no data (fewer than two converged cases, or no history)",
        )?;
    }
    let report = report_markdown(&results, &files.not_drawn);
    files.report(&results.study.report_file, &report)?;
    Ok(files.done())
}

pub fn index_entry(dir: &Path) -> Result<IndexEntry, StudyError> {
    let r: SceneResults = read_results(dir)?;
    let figs: Vec<(String, String)> = figures(&r).into_iter().map(|(t, id, _)| (t, id)).collect();
    Ok(super::plane_index_entry(
        (&r.study.name, &r.study.summary, r.provenance.tier),
        ("every case's measures", "results.json"),
        &r.checks,
        &r.study.report_file,
        std::iter::empty(),
        super::drawn(dir, figs),
    ))
}
