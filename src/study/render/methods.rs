//! The cross-method report (`<out>/methods/`): the table of fitted rates per method, problem
//! and measure, every method's end values against each study's reference, and the overlay
//! figures, from `methods.json` only ([`crate::study::methods`] gathers it).

use crate::basis::method::Method;
use crate::basis::Basis;
use crate::study::external::StudyMethod;
use crate::study::methods::{MethodsResults, RateRow};
use crate::study::render::plot2d::{xy_svg, LegendCorner, XyAxes, XySeries};
use crate::study::results::read_json;
use crate::study::StudyError;
use std::fmt::Write as _;
use std::path::Path;

/// The report's file name in the methods folder.
pub const REPORT: &str = "report.md";
/// The gathered results' file name.
pub const RESULTS: &str = "methods.json";

/// Column order of the tables: the paper's method (iGIMP) first, then the other material point
/// families in their declaration order ([`Basis::ALL`]), then the finite elements by name — so
/// a new family takes its column without a line here.
fn order(m: &StudyMethod) -> (usize, String) {
    let rank = match m.own() {
        Some(Method::IGIMP) => 0,
        Some(Method::MaterialPoint(b)) => 1 + Basis::ALL.iter().position(|x| *x == b).unwrap_or(0),
        Some(Method::Fem(_)) => 1 + Basis::ALL.len(),
        // Other codes after igimp's methods.
        None => 2 + Basis::ALL.len(),
    };
    (rank, m.name())
}

fn rate_cell(rows: &[&RateRow]) -> String {
    let mut cells: Vec<String> = vec![];
    for r in rows {
        let mut c = r.slope.map_or("—".into(), |s| format!("{s:.2}"));
        if let Some((rate, tol)) = r.expected {
            let mark = match r.pass {
                Some(true) => "✓",
                Some(false) => "✗",
                None => "?",
            };
            let _ = write!(c, " ({rate} ± {tol} {mark})");
        }
        if !cells.contains(&c) {
            cells.push(c);
        }
    }
    cells.join(" / ")
}

/// An identifier of the gathered results in words, for axis labels, titles and headings
/// (`steps_per_period` is the case field a sweep refines, not a label).
fn in_words(text: &str) -> String {
    text.replace("stress_error error", "stress error")
        .replace("f_error error", "deformation gradient error")
        .replace("steps_per_period", "time steps per period")
        .replace("stress_error", "stress error")
        .replace("f_error", "deformation gradient error")
}

/// The axis label of a group's x axis: what is counted, in words.
fn x_words(x_desc: &str) -> String {
    match x_desc {
        "cells" => "cells per side".into(),
        "elements" => "number of elements".into(),
        other => in_words(other),
    }
}

/// The report file of each source study, as its `results.json` names it (`report_file`,
/// else `report.md`), relative to the methods folder; `None` where that file is not there
/// (nothing links a missing file).
fn report_links(dir: &Path, r: &MethodsResults) -> Vec<Option<String>> {
    r.sources
        .iter()
        .map(|x| {
            let study_dir = dir.join("..").join(&x.study);
            let file = read_json::<serde_json::Value>(&study_dir.join("results.json"))
                .ok()
                .and_then(|v| v["study"]["report_file"].as_str().map(str::to_string))
                .unwrap_or_else(|| "report.md".into());
            let safe = !file.contains("..") && !file.starts_with('/');
            (safe && study_dir.join(&file).is_file()).then(|| format!("../{}/{file}", x.study))
        })
        .collect()
}

fn report(r: &MethodsResults, links: &[Option<String>], drawn: &[(String, String)]) -> String {
    let mut s = format!(
        "# methods: every method side by side\n\nGathered from the studies' `results.json` in this output folder by `study` ({}); regenerate, do not edit. Nothing here is solved: each number is its study's, whose report says how it was obtained and checked.\n\nSources: {}.\n\n",
        r.software.label(),
        r.sources
            .iter()
            .zip(links)
            .map(|(x, link)| {
                let name = super::md_link_text(&x.study);
                let at = format!("({} tier, {})", super::md_text(&x.tier), super::md_text(&x.software));
                match link {
                    Some(l) => format!("[{name}]({l}) {at}"),
                    None => format!("{name} {at}"),
                }
            })
            .collect::<Vec<_>>()
            .join(", ")
    );
    let mut methods: Vec<StudyMethod> = r.rates.iter().map(|x| x.method.clone()).collect();
    methods.sort_by_key(order);
    methods.dedup();
    s.push_str("## Fitted rates\n\nLog-log slope of each error against the resolution (elements or cells per side) over the levels its study fits; in brackets the band its study asserts and whether it held. Several values in a cell: the method's sweeps in that group.\n\n| study | measure | group |");
    for m in &methods {
        let _ = write!(s, " {} |", m.label());
    }
    s.push_str("\n|---|---|---|");
    for _ in &methods {
        s.push_str("---|");
    }
    s.push('\n');
    let mut keys: Vec<(&str, &str, &str)> = vec![];
    for x in &r.rates {
        let k = (x.study.as_str(), x.measure.as_str(), x.group.as_str());
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    for (study, measure, group) in keys {
        let _ = write!(
            s,
            "| {} | {} | {} |",
            super::md_cell(study),
            super::md_cell(&in_words(measure)),
            super::md_cell(group)
        );
        for m in &methods {
            let rows: Vec<&RateRow> = r
                .rates
                .iter()
                .filter(|x| {
                    (x.study.as_str(), x.measure.as_str(), x.group.as_str()) == (study, measure, group)
                })
                .filter(|x| x.method == *m)
                .collect();
            let _ = write!(s, " {} |", rate_cell(&rows));
        }
        s.push('\n');
    }
    s.push('\n');
    if !r.references.is_empty() {
        s.push_str("## Against each study's reference\n\nThe end value over the study's reference at each element size h (as value/reference − 1), and the GCI extrapolation of the three finest sizes (Celik et al. 2008) where they are in the asymptotic range.\n\n| study | sweep | measure | method | h: deviation | extrapolated | observed order | GCI note | reference |\n|---|---|---|---|---|---:|---:|---|---|\n");
        for x in &r.references {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                super::md_cell(&x.study),
                super::md_cell(&x.sweep),
                super::md_cell(&in_words(&x.measure)),
                x.method.label(),
                x.ratios
                    .iter()
                    .map(|(h, q)| format!("{h}: {:+.2} %", 100.0 * (q - 1.0)))
                    .collect::<Vec<_>>()
                    .join(", "),
                x.extrapolated_ratio
                    .map_or("—".into(), |q| format!("{:+.3} %", 100.0 * (q - 1.0))),
                x.observed_order.map_or("—".into(), |p| format!("{p:.2}")),
                super::md_cell(&x.gci_note),
                super::md_cell(&x.reference)
            );
        }
        s.push('\n');
    }
    if !drawn.is_empty() {
        s.push_str("## Figures\n\n");
        for (title, id) in drawn {
            let _ = writeln!(
                s,
                "### {}\n\n![{}]({id}.svg)\n",
                super::md_text(title),
                super::md_link_text(id)
            );
        }
    }
    s
}

/// Render `dir/methods.json` into the report and one figure per group. Returns the files
/// written.
pub fn render(dir: &Path) -> Result<super::Rendered, StudyError> {
    let r: MethodsResults = read_json(&dir.join(RESULTS))?;
    let links = report_links(dir, &r);
    let mut files = super::Files::new(dir);
    let mut drawn = vec![];
    for g in &r.groups {
        let series: Vec<XySeries> = g
            .series
            .iter()
            .map(|(m, pts)| XySeries {
                label: m.label().to_string(),
                points: pts.clone(),
                line: true,
                markers: true,
            })
            .collect();
        let axes = XyAxes {
            x_desc: x_words(&g.x_desc),
            y_desc: in_words(&g.y_desc),
            log_x: true,
            log_y: g.log_y,
            y_lines: if g.log_y {
                vec![]
            } else {
                vec![(0.99, "−1 %".into()), (1.01, "+1 %".into())]
            },
            legend: LegendCorner::LowerLeft,
        };
        let title = in_words(&g.title);
        let svg = xy_svg(&title, &axes, &series).ok();
        if svg.is_some() {
            drawn.push((title, g.id.clone()));
        }
        files.figure(&g.id, svg, "no data")?;
    }
    files.report(REPORT, &report(&r, &links, &drawn))?;
    Ok(files.done())
}
