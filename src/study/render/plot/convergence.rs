//! Log-log convergence figures: error against resolution per series, with a slope triangle
//! under each series' finest segment where the fitted slope is positive.

use super::layout::{self, at_fraction, fraction};
use super::{
    axes_chart, color, draw_legend, draw_markers, err, legend_label, legend_place, plot_size, titled,
    ConvergenceSeries, Corner, Marker, PlotResult, TickedAxis, FONT, SIZE, TICK_PT,
};
use plotters::prelude::*;

/// Error against element count on log-log axes, one series each, optionally with a slope
/// triangle under the finest segment of each series.
pub fn convergence_svg(
    title: &str,
    y_desc: &str,
    series: &[ConvergenceSeries],
    slope_triangles: bool,
) -> PlotResult<String> {
    convergence_svg_along(title, "number of elements", y_desc, series, slope_triangles)
}

/// A slope label to place: its text, and its triangle in plot pixels (left, right, bottom).
#[derive(Debug, Clone, PartialEq)]
struct SlopeLabel {
    text: String,
    left: f64,
    right: f64,
    bottom: f64,
}

/// Where each slope label goes, in plot pixels (left and top of its text): under its
/// triangle, moved down past any label it would overlap (triangles of several series share
/// the finest segment). A label with the text of an earlier one on the same triangle (two
/// series with one finest segment and slope) is dropped: one label serves both.
fn slope_label_positions(labels: &[Option<SlopeLabel>], pt: u32) -> Vec<Option<(f64, f64)>> {
    let h = layout::em(pt) + 3.0;
    let mut placed: Vec<(f64, f64, f64)> = vec![];
    let mut out = vec![];
    for (i, l) in labels.iter().enumerate() {
        let Some(l) = l else {
            out.push(None);
            continue;
        };
        let same = |m: &Option<SlopeLabel>| {
            m.as_ref().is_some_and(|m| {
                m.text == l.text
                    && (m.left - l.left).abs() < 2.0
                    && (m.right - l.right).abs() < 2.0
                    && (m.bottom - l.bottom).abs() < 2.0
            })
        };
        if labels[..i].iter().any(same) {
            out.push(None);
            continue;
        }
        let w = layout::text_width(&l.text, pt);
        let x = 0.5 * (l.left + l.right) - 0.5 * w;
        let mut y = l.bottom + 4.0;
        while let Some(&(_, _, below)) = placed
            .iter()
            .find(|&&(px, py, _)| x < px + w + 6.0 && px < x + w + 6.0 && y < py + h && py < y + h)
        {
            y = below;
        }
        placed.push((x, y, y + h));
        out.push(Some((x, y)));
    }
    out
}

/// [`convergence_svg`] with the x axis described by `x_desc` (e.g. elements per side).
pub fn convergence_svg_along(
    title: &str,
    x_desc: &str,
    y_desc: &str,
    series: &[ConvergenceSeries],
    slope_triangles: bool,
) -> PlotResult<String> {
    // Triangles under the finest segment: the hypotenuse has the fitted slope, the right angle
    // is at the bottom left, the top vertex at 0.45× the error of the second-finest point. An
    // error that grows or stays (slope at or under zero) has no order to show: no triangle.
    let triangles: Vec<Option<[(f64, f64); 3]>> = series
        .iter()
        .map(|s| {
            let n = s.points.len();
            let slope = s.slope.filter(|k| *k > 0.0)?;
            if !slope_triangles || n < 2 {
                return None;
            }
            let (na, ea) = s.points[n - 2];
            let (nb, _) = s.points[n - 1];
            let top = 0.45 * ea;
            let bottom = top * (na / nb).powf(slope);
            Some([(na, top), (nb, bottom), (na, bottom)])
        })
        .collect();
    let all = series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .chain(triangles.iter().flatten().flat_map(|t| t.iter().copied()));
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
    for (x, y) in all {
        if x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite() {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    if !(x0.is_finite() && y0.is_finite()) {
        return Err("convergence figure without positive data".into());
    }
    let (x0, x1) = (x0 / 1.5, x1 * 1.5);
    let (mut y0, mut y1) = (y0 / 2.5, y1 * 2.5);
    let pts: Vec<Vec<(f64, f64)>> = series
        .iter()
        .map(|s| {
            s.points
                .iter()
                .copied()
                .filter(|p| p.0 > 0.0 && p.1 > 0.0 && p.0.is_finite() && p.1.is_finite())
                .collect()
        })
        .collect();
    let labels: Vec<String> = series
        .iter()
        .enumerate()
        .filter_map(|(i, s)| {
            let label = match s.slope {
                Some(k) => format!("{} (slope {k:.2})", s.label),
                None => s.label.clone(),
            };
            legend_label(i, series.len(), &label)
        })
        .collect();
    let y_area = 100;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let area = titled(&root, title)?;
        let (w, h) = plot_size(&area, y_area);
        let em = layout::em(TICK_PT);
        // Slope labels and the legend both need room: the labels extend the range downwards
        // until the lowest fits, the legend then takes a free corner or a band of its own,
        // and the labels are placed again on the new range.
        let place = |y0: f64, y1: f64| {
            let fx = |x: f64| fraction(x, x0, x1, true) * w;
            let fy = |y: f64| (1.0 - fraction(y, y0, y1, true)) * h;
            let slope_labels: Vec<Option<SlopeLabel>> = triangles
                .iter()
                .zip(series)
                .map(|(t, s)| {
                    let t = t.as_ref()?;
                    Some(SlopeLabel {
                        text: format!("{:.2}", s.slope?),
                        left: fx(t[0].0),
                        right: fx(t[1].0),
                        bottom: fy(t[2].1),
                    })
                })
                .collect();
            let positions = slope_label_positions(&slope_labels, TICK_PT);
            // Label boxes' corners in plot fractions, for the legend to avoid.
            let boxes: Vec<(f64, f64)> = positions
                .iter()
                .zip(&slope_labels)
                .filter_map(|(p, l)| {
                    let (p, l) = (p.as_ref()?, l.as_ref()?);
                    let tw = layout::text_width(&l.text, TICK_PT);
                    Some([(p.0, p.1), (p.0 + tw, p.1), (p.0, p.1 + em), (p.0 + tw, p.1 + em)])
                })
                .flatten()
                .map(|(x, y)| (x / w, 1.0 - y / h))
                .collect();
            (positions, boxes)
        };
        let data_lines = |y0: f64, y1: f64| {
            let frac = |p: &(f64, f64)| (fraction(p.0, x0, x1, true), fraction(p.1, y0, y1, true));
            let mut lines: Vec<Vec<(f64, f64)>> = pts.iter().map(|p| p.iter().map(frac).collect()).collect();
            lines.extend(
                triangles
                    .iter()
                    .flatten()
                    .map(|t| [t[0], t[1], t[2], t[0]].iter().map(frac).collect::<Vec<_>>()),
            );
            lines
        };
        for _ in 0..4 {
            let (positions, boxes) = place(y0, y1);
            let lowest = positions
                .iter()
                .flatten()
                .fold(0.0f64, |m, p| m.max(p.1 + em + 4.0));
            if lowest > h {
                y0 = at_fraction(-(lowest - h) / h * 1.1, y0, y1, true);
                continue;
            }
            let lines = data_lines(y0, y1);
            let (_, (f0, f1)) = legend_place(&labels, &boxes, &lines, (w, h), Corner::LowerLeft);
            if (f0, f1) == (0.0, 1.0) {
                break;
            }
            (y0, y1) = (at_fraction(f0, y0, y1, true), at_fraction(f1, y0, y1, true));
        }
        let (positions, boxes) = place(y0, y1);
        let (at, _) = legend_place(&labels, &boxes, &data_lines(y0, y1), (w, h), Corner::LowerLeft);
        let xt = TickedAxis::new(x0, x1, true, w, true);
        let yt = TickedAxis::new(y0, y1, true, h, false);
        let mut chart = axes_chart(&area, y_area, (xt, yt), (x_desc, y_desc))?;
        for (i, s) in series.iter().enumerate() {
            let label = match s.slope {
                Some(k) => format!("{} (slope {k:.2})", s.label),
                None => s.label.clone(),
            };
            let label = legend_label(i, series.len(), &label);
            draw_markers(
                &mut chart,
                &pts[i],
                Marker::nth(i),
                color(i),
                label.as_deref(),
                true,
            )?;
            if let (Some(t), Some(k)) = (triangles[i], s.slope) {
                let col = color(i);
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![t[0], t[1], t[2], t[0]],
                        col.stroke_width(1),
                    )))
                    .map_err(err)?;
                if let Some((px, py)) = positions[i] {
                    // Plot pixels back to data: the label's top left corner.
                    let at = (
                        at_fraction(px / w, x0, x1, true),
                        at_fraction(1.0 - py / h, y0, y1, true),
                    );
                    chart
                        .draw_series(std::iter::once(Text::new(
                            format!("{k:.2}"),
                            at,
                            (FONT, TICK_PT).into_font().color(&col),
                        )))
                        .map_err(err)?;
                }
            }
        }
        draw_legend(&mut chart, at)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::render::plot::MAX_SERIES;

    /// No two of the first [`MAX_SERIES`] series share colour and marker (a profile of 15
    /// series repeated colours before); the rest are grey under one legend entry.
    #[test]
    fn series_styles_are_distinct_up_to_the_cap() {
        let styles: Vec<((u8, u8, u8), Marker)> = (0..MAX_SERIES)
            .map(|i| {
                let c = color(i);
                ((c.0, c.1, c.2), Marker::nth(i))
            })
            .collect();
        for i in 0..styles.len() {
            assert!(!styles[..i].contains(&styles[i]), "series {i}: {:?}", styles[i]);
        }
        assert_eq!(color(MAX_SERIES), crate::study::render::plot::GREY);
        assert_eq!(
            legend_label(MAX_SERIES, 31, "x").as_deref(),
            Some("3 more series (grey)")
        );
        assert_eq!(legend_label(MAX_SERIES + 1, 31, "x"), None);
    }

    /// Three triangles on one finest segment (the manufactured axis-aligned field: two series
    /// of slope 0.61 on one segment, their labels stacked before) and one elsewhere: the
    /// repeated label is drawn once, and no two label boxes overlap.
    #[test]
    fn slope_labels_do_not_overlap() {
        let t = |text: &str, bottom: f64| {
            Some(SlopeLabel {
                text: text.into(),
                left: 600.0,
                right: 700.0,
                bottom,
            })
        };
        let labels = vec![
            t("0.61", 300.0),
            t("0.61", 300.0),
            t("1.00", 302.0),
            None,
            t("2.00", 100.0),
        ];
        let p = slope_label_positions(&labels, TICK_PT);
        assert!(p[1].is_none() && p[3].is_none(), "{p:?}");
        let h = layout::em(TICK_PT);
        let boxes: Vec<(f64, f64)> = p.iter().flatten().copied().collect();
        for i in 0..boxes.len() {
            for j in 0..i {
                let (a, b) = (boxes[i], boxes[j]);
                let apart = (a.1 - b.1).abs() >= h || (a.0 - b.0).abs() >= 40.0;
                assert!(apart, "{boxes:?}");
            }
        }
        assert_eq!(p[4].unwrap().1, 104.0);
    }
}
