//! Figures and reports a reader can use (issue 45): every committed SVG is well-formed XML
//! with no tick label twice on an axis and no text past the canvas, every relative link of
//! every committed report resolves, and text from a study file (titles, summary) is escaped
//! for SVG and Markdown. Plus one test per figure defect, on synthetic data through the
//! public plotting functions.

use igimp::study::render::plot::{convergence_svg_along, profile_svg, ConvergenceSeries, ProfileSeries};
use igimp::study::render::plot2d::{xy_svg, LegendCorner, XyAxes, XySeries};
use std::path::{Path, PathBuf};

fn reports() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("reports")
}

/// Every file under `dir` whose name ends with `ext`, sorted.
fn files(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut out = vec![];
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().path()) {
            if e.is_dir() {
                stack.push(e);
            } else if e.to_string_lossy().ends_with(ext) {
                out.push(e);
            }
        }
    }
    out.sort();
    out
}

/// One `<text>` of a figure: its anchor point, alignment, size, rotation and content.
#[derive(Debug, Clone)]
struct Label {
    x: f64,
    y: f64,
    anchor: String,
    dy: String,
    size: f64,
    rotate: Option<f64>,
    text: String,
}

impl Label {
    /// Its extent (x0, y0, x1, y1) in canvas pixels, estimated as the renderer lays text out:
    /// 0.6 em per character (src/study/render/plot/layout.rs), one em high.
    fn extent(&self) -> (f64, f64, f64, f64) {
        let w = 0.6 * self.size * self.text.chars().count() as f64;
        let (a, b) = match self.anchor.as_str() {
            "middle" => (-0.5 * w, 0.5 * w),
            "end" => (-w, 0.0),
            _ => (0.0, w),
        };
        let (c, d) = match self.dy.as_str() {
            "0.76em" => (0.0, self.size),
            "-0.5ex" => (-self.size, 0.0),
            _ => (-0.5 * self.size, 0.5 * self.size),
        };
        match self.rotate.map(|r| r.rem_euclid(360.0).round() as i32) {
            // rotate(270): (dx, dy) → (dy, −dx); rotate(90): (dx, dy) → (−dy, dx).
            Some(270) => (self.x + c, self.y - b, self.x + d, self.y - a),
            Some(90) => (self.x - d, self.y + a, self.x - c, self.y + b),
            _ => (self.x + a, self.y + c, self.x + b, self.y + d),
        }
    }
}

/// The canvas size and every text of an SVG, or why it is not XML.
fn parse(svg: &str) -> Result<((f64, f64), Vec<Label>), String> {
    let doc = roxmltree::Document::parse(svg).map_err(|e| e.to_string())?;
    let root = doc.root_element();
    let num = |n: roxmltree::Node, a: &str| n.attribute(a).and_then(|v| v.parse::<f64>().ok());
    let size = (
        num(root, "width").unwrap_or(0.0),
        num(root, "height").unwrap_or(0.0),
    );
    let labels = doc
        .descendants()
        .filter(|n| n.has_tag_name("text"))
        .map(|n| Label {
            x: num(n, "x").unwrap_or(f64::NAN),
            y: num(n, "y").unwrap_or(f64::NAN),
            anchor: n.attribute("text-anchor").unwrap_or("start").to_string(),
            dy: n.attribute("dy").unwrap_or("").to_string(),
            size: num(n, "font-size").unwrap_or(f64::NAN),
            rotate: n
                .attribute("transform")
                .and_then(|t| t.strip_prefix("rotate(")?.split(',').next()?.trim().parse().ok()),
            text: n.text().unwrap_or("").trim().to_string(),
        })
        .filter(|l| !l.text.is_empty())
        .collect();
    Ok((size, labels))
}

/// What is wrong with a figure: not XML, a tick label twice on one axis (x ticks share a
/// baseline under the plot, y ticks their right edge), text past the canvas, or a raw
/// identifier as text.
fn problems(svg: &str) -> Vec<String> {
    let ((w, h), labels) = match parse(svg) {
        Ok(p) => p,
        Err(e) => return vec![format!("not XML: {e}")],
    };
    let mut out = vec![];
    let ticks = |l: &&Label| l.rotate.is_none() && l.anchor != "start";
    for (i, a) in labels.iter().enumerate().filter(|(_, l)| ticks(l)) {
        let twin = labels[..i].iter().filter(ticks).find(|b| {
            b.text == a.text
                && b.anchor == a.anchor
                && b.dy == a.dy
                && if a.anchor == "end" { b.x == a.x } else { b.y == a.y }
        });
        if let Some(b) = twin {
            out.push(format!(
                "tick `{}` twice on one axis, at ({}, {}) and ({}, {})",
                a.text, b.x, b.y, a.x, a.y
            ));
        }
    }
    for l in &labels {
        let (x0, y0, x1, y1) = l.extent();
        if x0 < -0.5 || y0 < -0.5 || x1 > w + 0.5 || y1 > h + 0.5 {
            out.push(format!(
                "`{}` reaches ({x0:.0}, {y0:.0})–({x1:.0}, {y1:.0}), past the {w}×{h} canvas",
                l.text
            ));
        }
        for raw in ["steps_per_period", "f_error", "stress_error"] {
            if l.text.contains(raw) {
                out.push(format!("`{}` shows the identifier `{raw}`", l.text));
            }
        }
    }
    out
}

/// Every committed figure is XML, labels each tick of an axis once and keeps its text on
/// the canvas.
#[test]
fn every_committed_figure_reads_well() {
    let mut bad = vec![];
    let svgs = files(&reports(), ".svg");
    assert!(svgs.len() > 50, "{} figures under reports/", svgs.len());
    for f in &svgs {
        let text = std::fs::read_to_string(f).unwrap();
        for p in problems(&text) {
            bad.push(format!("{}: {p}", f.strip_prefix(reports()).unwrap().display()));
        }
    }
    assert!(bad.is_empty(), "{} problems:\n{}", bad.len(), bad.join("\n"));
}

/// The relative link targets of a Markdown text (`[text](target)` and images), without
/// fragments; web and mail links and in-page anchors are left out. Link texts are taken to
/// hold no unescaped `]`, which the renderer guarantees.
fn links(md: &str) -> Vec<String> {
    let mut out = vec![];
    let mut rest = md;
    while let Some(i) = rest.find("](") {
        // An escaped bracket (`\](`) ends no link text.
        let escaped = rest[..i].ends_with('\\');
        rest = &rest[i + 2..];
        if escaped {
            continue;
        }
        let Some(j) = rest.find(')') else { break };
        let target = rest[..j].split_whitespace().next().unwrap_or("");
        let target = target.split('#').next().unwrap_or("");
        if !(target.is_empty() || target.contains("://") || target.starts_with("mailto:")) {
            out.push(target.to_string());
        }
    }
    out
}

/// Every relative link of every committed report resolves to a file or folder.
#[test]
fn every_report_link_resolves() {
    let mut bad = vec![];
    let mds = files(&reports(), ".md");
    assert!(mds.len() > 10, "{} reports", mds.len());
    for f in &mds {
        let text = std::fs::read_to_string(f).unwrap();
        for l in links(&text) {
            if !f.parent().unwrap().join(&l).exists() {
                bad.push(format!("{}: {l}", f.strip_prefix(reports()).unwrap().display()));
            }
        }
    }
    assert!(
        bad.is_empty(),
        "{} dangling links:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

/// The reports index says what generated it: `study`, over the studies it lists, not a
/// command nobody may have run.
#[test]
fn the_index_names_its_studies_not_a_command() {
    let index = std::fs::read_to_string(reports().join("index.md")).unwrap();
    let head: String = index.lines().take(4).collect::<Vec<_>>().join("\n");
    assert!(!head.contains("-- all"), "{head}");
    assert!(
        head.contains("`study`") && head.contains("vibrating-bar"),
        "{head}"
    );
}

/// A control character, markup and a newline in the study's title and summary (D6): every
/// figure is still XML, the summary starts no heading in index.md, a `|` breaks no table
/// cell, and each figure title is one heading line.
#[test]
fn study_text_is_escaped_for_svg_and_markdown() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("vibrating-bar");
    std::fs::create_dir_all(&dir).unwrap();
    let src = reports().join("vibrating-bar");
    std::fs::copy(src.join("histories.json"), dir.join("histories.json")).unwrap();
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(src.join("results.json")).unwrap()).unwrap();
    v["study"]["summary"] = "bar\n# injected heading\n| a | b |".into();
    for f in v["study"]["figures"].as_array_mut().unwrap() {
        let t = f["title"].as_str().unwrap().to_string();
        f["title"] = format!("a\u{7}b <i>&</i> [x](y) | c\n## d {t}").into();
    }
    std::fs::write(dir.join("results.json"), serde_json::to_string(&v).unwrap()).unwrap();
    let rendered = igimp::study::kinds::render_dir(&dir).unwrap();
    let index = igimp::study::kinds::render_index(tmp.path()).unwrap();
    let svgs: Vec<&PathBuf> = rendered
        .files
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "svg"))
        .collect();
    assert!(!svgs.is_empty());
    for f in svgs {
        let svg = std::fs::read_to_string(f).unwrap();
        let (_, labels) = parse(&svg).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        assert!(
            labels.iter().any(|l| l.text.contains("<i>&</i>")),
            "{}",
            f.display()
        );
    }
    let index = std::fs::read_to_string(index).unwrap();
    let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
    for (name, md) in [("index.md", &index), ("report.md", &report)] {
        for line in md.lines() {
            assert!(
                !line.starts_with("# injected") && !line.starts_with("| a |"),
                "{name}: {line}"
            );
            assert!(
                !line.starts_with("## d "),
                "{name}: a title's newline started a heading: {line}"
            );
        }
        assert!(!md.contains('\u{7}'), "{name}");
    }
    for l in links(&index) {
        assert!(tmp.path().join(&l).exists(), "index.md: {l}");
    }
}

fn labels_of(svg: &str) -> Vec<Label> {
    parse(svg).unwrap().1
}

/// A log axis spanning under a decade (0.9 to 1.6) has at least two labelled ticks, each
/// once.
#[test]
fn a_log_axis_under_a_decade_has_two_labels() {
    let axes = XyAxes {
        x_desc: "element size h".into(),
        y_desc: "error".into(),
        log_x: true,
        log_y: true,
        y_lines: vec![],
        legend: LegendCorner::LowerRight,
    };
    let series = [XySeries {
        label: "a".into(),
        points: vec![(0.9, 0.2), (1.2, 0.25), (1.6, 0.3)],
        line: true,
        markers: true,
    }];
    let svg = xy_svg("short log axes", &axes, &series).unwrap();
    assert!(problems(&svg).is_empty(), "{:?}", problems(&svg));
    let labels = labels_of(&svg);
    let x_ticks = labels
        .iter()
        .filter(|l| l.anchor == "middle" && l.dy == "0.76em" && l.y > 500.0);
    let y_ticks = labels.iter().filter(|l| l.anchor == "end");
    assert!(x_ticks.count() >= 2 && y_ticks.count() >= 2, "{labels:?}");
}

/// A history that fills the upper left corner (the cantilever's first 1.2 s): no marker
/// falls inside the legend box.
#[test]
fn the_legend_hides_no_data() {
    let series: Vec<ProfileSeries> = (0..4)
        .map(|k| ProfileSeries {
            label: format!("a long series label number {k} (8 el. through the depth, 64/T₁)"),
            points: (0..80)
                .map(|i| {
                    let t = i as f64 * 0.1;
                    (t, -50.0 * (1.0 - (t + 0.05 * k as f64).cos()) / 2.0)
                })
                .collect(),
        })
        .collect();
    let svg = profile_svg("history", "t (s)", "tip deflection (%)", &series, &[]).unwrap();
    let doc = roxmltree::Document::parse(&svg).unwrap();
    let num = |n: &roxmltree::Node, a: &str| n.attribute(a).unwrap().parse::<f64>().unwrap();
    // The legend box: the black-bordered rectangle without fill drawn over the plot.
    let legend = doc
        .descendants()
        .filter(|n| n.has_tag_name("rect") && n.attribute("stroke") == Some("#000000"))
        .map(|n| (num(&n, "x"), num(&n, "y"), num(&n, "width"), num(&n, "height")))
        .next_back()
        .expect("a legend box");
    let covered: Vec<(f64, f64)> = doc
        .descendants()
        .filter(|n| n.has_tag_name("circle"))
        .map(|n| (num(&n, "cx"), num(&n, "cy")))
        .filter(|&(x, y)| {
            x > legend.0 + 30.0 && x < legend.0 + legend.2 && y > legend.1 && y < legend.1 + legend.3
        })
        .collect();
    assert!(
        covered.is_empty(),
        "legend {legend:?} covers markers at {covered:?}"
    );
}

/// Slope triangles only for a positive fitted slope, and one label where two series share
/// a finest segment and slope (two "0.61" labels stacked before).
#[test]
fn slope_triangles_only_for_positive_slopes_without_stacked_labels() {
    let line = |c: f64, k: f64| -> Vec<(f64, f64)> {
        [4.0f64, 8.0, 16.0, 32.0, 64.0]
            .iter()
            .map(|&n| (n, c * n.powf(-k)))
            .collect()
    };
    let series = vec![
        ConvergenceSeries {
            label: "U".into(),
            points: line(0.1, 0.61),
            slope: Some(0.61),
        },
        ConvergenceSeries {
            label: "F".into(),
            points: line(0.1, 0.61),
            slope: Some(0.61),
        },
        ConvergenceSeries {
            label: "fixed".into(),
            points: line(0.01, -0.09),
            slope: Some(-0.09),
        },
        ConvergenceSeries {
            label: "Q8".into(),
            points: line(0.02, 2.0),
            slope: Some(2.0),
        },
    ];
    let svg = convergence_svg_along("rates", "cells per side", "stress error", &series, true).unwrap();
    assert!(problems(&svg).is_empty(), "{:?}", problems(&svg));
    let labels = labels_of(&svg);
    let count = |t: &str| labels.iter().filter(|l| l.text == t).count();
    assert_eq!(count("-0.09"), 0, "a triangle for a negative slope");
    assert_eq!(count("0.61"), 1, "stacked labels");
    assert_eq!(count("2.00"), 1);
    // Three triangles (closed four-point paths) drawn, not four.
    let triangles = svg
        .lines()
        .filter(|l| l.starts_with("<polyline") && l.contains("stroke-width=\"1\""))
        .filter(|l| {
            let pts = l.split("points=\"").nth(1).unwrap_or("");
            let p: Vec<&str> = pts.split_whitespace().filter(|s| s.contains(',')).collect();
            p.len() == 4 && p[0] == p[3]
        })
        .count();
    assert_eq!(triangles, 3, "{svg}");
}
