//! SVG figures of the plane-strain studies (§5.2–5.3): material point domains coloured by a
//! field with a colour bar (Figures 15, 18–20), Newton residual histories on a log axis
//! (Figure 16) and x–y series (Figures 17 and 21).
//!
//! Same conventions as [`crate::study::render::plot`] (whose style constants and marker helper are reused):
//! SVG text in the generic `sans-serif` family, explicit font sizes, and output that is a pure
//! function of the data so that `study --render-only` is byte-identical.

use crate::study::render::plot::{
    at_fraction, axes_chart, color, dashed, draw_legend, draw_markers, err, fraction, legend_label,
    legend_place, padded, plot_size, svg_text, titled, titled_at, Corner, Marker, PlotResult, TickedAxis,
    FONT, SIZE, TICK_PT,
};
use plotters::prelude::*;

/// An axis-aligned material point domain: centre and half-lengths.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Domain {
    pub centre: [f64; 2],
    pub half: [f64; 2],
}

impl Domain {
    fn corners(&self) -> [(f64, f64); 2] {
        [
            (self.centre[0] - self.half[0], self.centre[1] - self.half[1]),
            (self.centre[0] + self.half[0], self.centre[1] + self.half[1]),
        ]
    }
}

/// A set of domains drawn in one style: filled by a field value (colour bar), or outlined in
/// a series colour with a legend entry.
#[derive(Debug, Clone, PartialEq)]
pub struct DomainLayer {
    pub label: String,
    pub domains: Vec<Domain>,
    /// One value per domain: fill from the colour map. `None`: outline only.
    pub values: Option<Vec<f64>>,
    /// Outline colour index into the palette; `None` draws light grey (initial domains).
    pub colour: Option<usize>,
}

/// Labelled points drawn on top of the domains (e.g. the loaded points).
#[derive(Debug, Clone, PartialEq)]
pub struct PointMarks {
    pub label: String,
    pub points: Vec<(f64, f64)>,
}

/// Viridis, sampled at five anchors and interpolated linearly (perceptually ordered, readable
/// in grey scale).
fn colour_map(t: f64) -> RGBColor {
    const ANCHORS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    let x = t * (ANCHORS.len() - 1) as f64;
    let i = (x.floor() as usize).min(ANCHORS.len() - 2);
    let f = x - i as f64;
    let (a, b) = (ANCHORS[i], ANCHORS[i + 1]);
    let mix = |p: f64, q: f64| (p + f * (q - p)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

fn range_of(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    lo.is_finite().then_some((lo, hi))
}

/// Domains on equal x and y scales, with a vertical colour bar for the filled layers.
pub fn domains_svg(
    title: &str,
    colour_label: &str,
    axes: (&str, &str),
    layers: &[DomainLayer],
    marks: &[PointMarks],
) -> PlotResult<String> {
    let corners: Vec<(f64, f64)> = layers
        .iter()
        .flat_map(|l| l.domains.iter().flat_map(|d| d.corners()))
        .chain(marks.iter().flat_map(|m| m.points.iter().copied()))
        .collect();
    let (x0, x1) = range_of(corners.iter().map(|c| c.0)).ok_or("domain figure without data")?;
    let (y0, y1) = range_of(corners.iter().map(|c| c.1)).ok_or("domain figure without data")?;
    let value_range = range_of(layers.iter().flat_map(|l| l.values.iter().flatten().copied()));
    let bar_width = if value_range.is_some() { 150 } else { 0 };
    let y_area = 70;
    let (x0, x1) = padded(x0, x1, 0.03);
    let (y0, y1) = padded(y0, y1, 0.03);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let area = titled(&root, title)?;
        let (left, right) = area.split_horizontally(SIZE.0 - bar_width);
        // Pad the shorter data range so that one unit is the same length along x and y.
        let (w, h) = plot_size(&left, y_area);
        let scale = ((x1 - x0) / w).max((y1 - y0) / h);
        let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
        let (mut x0, mut x1) = (cx - 0.5 * scale * w, cx + 0.5 * scale * w);
        let (mut y0, mut y1) = (cy - 0.5 * scale * h, cy + 0.5 * scale * h);
        // The legend (outlined layers and marks) goes in a corner clear of every domain, or
        // in a band the ranges are stretched by, equally along x and y.
        let labels: Vec<String> = layers
            .iter()
            .filter(|l| l.values.is_none() && !l.label.is_empty())
            .map(|l| svg_text(&l.label))
            .chain(marks.iter().map(|m| svg_text(&m.label)))
            .collect();
        let frac = |p: (f64, f64)| (fraction(p.0, x0, x1, false), fraction(p.1, y0, y1, false));
        let outlines: Vec<Vec<(f64, f64)>> = layers
            .iter()
            .flat_map(|l| l.domains.iter())
            .map(|d| {
                let [a, b] = d.corners();
                [a, (b.0, a.1), b, (a.0, b.1), a].map(frac).to_vec()
            })
            .collect();
        let points: Vec<(f64, f64)> = marks
            .iter()
            .flat_map(|m| m.points.iter().copied())
            .chain(
                layers
                    .iter()
                    .flat_map(|l| l.domains.iter().map(|d| (d.centre[0], d.centre[1]))),
            )
            .map(frac)
            .collect();
        let (at, (f0, f1)) = legend_place(&labels, &points, &outlines, (w, h), Corner::UpperRight);
        if (f0, f1) != (0.0, 1.0) {
            let s = f1 - f0;
            (y0, y1) = (at_fraction(f0, y0, y1, false), at_fraction(f1, y0, y1, false));
            (x0, x1) = (cx - 0.5 * s * (x1 - x0), cx + 0.5 * s * (x1 - x0));
        }
        let xt = TickedAxis::new(x0, x1, false, w, true);
        let yt = TickedAxis::new(y0, y1, false, h, false);
        let mut chart = axes_chart(&left, y_area, (xt, yt), (axes.0, axes.1))?;
        let (v0, v1) = value_range.unwrap_or((0.0, 1.0));
        let span = if v1 > v0 { v1 - v0 } else { 1.0 };
        let mut legend = false;
        for layer in layers {
            let outline = match layer.colour {
                Some(i) => color(i),
                None => RGBColor(170, 170, 170),
            };
            match &layer.values {
                Some(values) => {
                    chart
                        .draw_series(
                            layer.domains.iter().zip(values).map(|(d, &v)| {
                                Rectangle::new(d.corners(), colour_map((v - v0) / span).filled())
                            }),
                        )
                        .map_err(err)?;
                    chart
                        .draw_series(
                            layer
                                .domains
                                .iter()
                                .map(|d| Rectangle::new(d.corners(), BLACK.mix(0.6).stroke_width(1))),
                        )
                        .map_err(err)?;
                }
                None => {
                    let fill = if layer.colour.is_none() {
                        RGBColor(225, 225, 225).filled()
                    } else {
                        outline.mix(0.12).filled()
                    };
                    chart
                        .draw_series(layer.domains.iter().map(|d| Rectangle::new(d.corners(), fill)))
                        .map_err(err)?;
                    let anno = chart
                        .draw_series(
                            layer
                                .domains
                                .iter()
                                .map(|d| Rectangle::new(d.corners(), outline.stroke_width(1))),
                        )
                        .map_err(err)?;
                    if !layer.label.is_empty() {
                        legend = true;
                        anno.label(svg_text(&layer.label)).legend(move |(x, y)| {
                            Rectangle::new([(x, y - 6), (x + 18, y + 6)], outline.stroke_width(2))
                        });
                    }
                }
            }
        }
        for (i, m) in marks.iter().enumerate() {
            legend = true;
            draw_markers(
                &mut chart,
                &m.points,
                Marker::Triangle,
                color(1 + i),
                Some(&m.label),
                false,
            )?;
        }
        if legend {
            draw_legend(&mut chart, at)?;
        }
        if value_range.is_some() {
            let right = titled_at(&right.margin(20, 0, 0, 0), colour_label, TICK_PT)?;
            let bar_h = right.dim_in_pixel().1.saturating_sub(80) as f64;
            let vt = TickedAxis::new(v0, v0 + span, false, bar_h, false);
            let vl = vt.ticks.clone();
            let mut bar = ChartBuilder::on(&right)
                .margin_bottom(80)
                .margin_right(10)
                .y_label_area_size(80)
                .build_cartesian_2d(0.0..1.0, vt)
                .map_err(err)?;
            bar.configure_mesh()
                .disable_x_mesh()
                .disable_x_axis()
                .label_style((FONT, TICK_PT))
                .y_label_formatter(&|v| vl.label(*v))
                .light_line_style(WHITE.mix(0.0))
                .draw()
                .map_err(err)?;
            let n = 64;
            bar.draw_series((0..n).map(|k| {
                let (a, b) = (k as f64 / n as f64, (k + 1) as f64 / n as f64);
                Rectangle::new(
                    [(0.0, v0 + a * span), (1.0, v0 + b * span)],
                    colour_map(0.5 * (a + b)).filled(),
                )
            }))
            .map_err(err)?;
        }
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// One x–y series: markers, optionally joined by a line.
#[derive(Debug, Clone, PartialEq)]
pub struct XySeries {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// Join the points with a line.
    pub line: bool,
    /// Draw markers (a reference curve sampled densely has none).
    pub markers: bool,
}

/// Axis settings of [`xy_svg`].
#[derive(Debug, Clone, PartialEq)]
pub struct XyAxes {
    pub x_desc: String,
    pub y_desc: String,
    pub log_x: bool,
    pub log_y: bool,
    /// Horizontal reference lines (value, label), e.g. ±1 % bands.
    pub y_lines: Vec<(f64, String)>,
    pub legend: LegendCorner,
}

/// Where the legend box goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LegendCorner {
    UpperLeft,
    UpperRight,
    LowerLeft,
    LowerRight,
}

impl LegendCorner {
    fn corner(self) -> Corner {
        match self {
            LegendCorner::UpperLeft => Corner::UpperLeft,
            LegendCorner::UpperRight => Corner::UpperRight,
            LegendCorner::LowerLeft => Corner::LowerLeft,
            LegendCorner::LowerRight => Corner::LowerRight,
        }
    }
}

/// Series on linear or logarithmic axes, each in its own colour and marker.
pub fn xy_svg(title: &str, axes: &XyAxes, series: &[XySeries]) -> PlotResult<String> {
    let keep = |p: &(f64, f64)| {
        p.0.is_finite() && p.1.is_finite() && (!axes.log_x || p.0 > 0.0) && (!axes.log_y || p.1 > 0.0)
    };
    let pts: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .filter(keep)
        .chain(axes.y_lines.iter().map(|l| (f64::NAN, l.0)))
        .collect();
    let (x0, x1) = range_of(pts.iter().map(|p| p.0)).ok_or("x-y figure without data")?;
    let (y0, y1) = range_of(pts.iter().map(|p| p.1)).ok_or("x-y figure without data")?;
    let widen = |lo: f64, hi: f64, log: bool| {
        if log {
            (lo / 1.4, hi * 1.4)
        } else {
            padded(lo, hi, 0.06)
        }
    };
    let (x0, x1) = widen(x0, x1, axes.log_x);
    let (y0, y1) = widen(y0, y1, axes.log_y);
    let y_area = 100;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let area = titled(&root, title)?;
        let (w, h) = plot_size(&area, y_area);
        // The legend goes where it covers no series (the study's corner first), or in a band
        // the y range is stretched by.
        let frac = |p: &(f64, f64)| {
            (
                fraction(p.0, x0, x1, axes.log_x),
                fraction(p.1, y0, y1, axes.log_y),
            )
        };
        let labels: Vec<String> = series
            .iter()
            .enumerate()
            .filter_map(|(i, s)| legend_label(i, series.len(), &s.label))
            .collect();
        let kept: Vec<Vec<(f64, f64)>> = series
            .iter()
            .map(|s| s.points.iter().copied().filter(keep).collect())
            .collect();
        let points: Vec<(f64, f64)> = series
            .iter()
            .zip(&kept)
            .filter(|(s, _)| s.markers)
            .flat_map(|(_, p)| p.iter().map(frac))
            .collect();
        let lines: Vec<Vec<(f64, f64)>> = series
            .iter()
            .zip(&kept)
            .filter(|(s, _)| s.line || !s.markers)
            .map(|(_, p)| p.iter().map(frac).collect())
            .collect();
        let (at, (f0, f1)) = legend_place(&labels, &points, &lines, (w, h), axes.legend.corner());
        let (y0, y1) = (
            at_fraction(f0, y0, y1, axes.log_y),
            at_fraction(f1, y0, y1, axes.log_y),
        );
        let xt = TickedAxis::new(x0, x1, axes.log_x, w, true);
        let yt = TickedAxis::new(y0, y1, axes.log_y, h, false);
        let mut chart = axes_chart(&area, y_area, (xt, yt), (&axes.x_desc, &axes.y_desc))?;
        for (value, label) in &axes.y_lines {
            chart
                .draw_series(DashedLineSeries::new(
                    [(x0, *value), (x1, *value)],
                    6,
                    4,
                    BLACK.mix(0.5).stroke_width(1),
                ))
                .map_err(err)?;
            chart
                .draw_series(std::iter::once(Text::new(
                    svg_text(label),
                    (x0, *value),
                    (FONT, TICK_PT).into_font().color(&BLACK.mix(0.7)),
                )))
                .map_err(err)?;
        }
        for (i, (s, p)) in series.iter().zip(&kept).enumerate() {
            let label = legend_label(i, series.len(), &s.label);
            if s.markers {
                draw_markers(&mut chart, p, Marker::nth(i), color(i), label.as_deref(), s.line)?;
                continue;
            }
            let style = color(i).stroke_width(2);
            let anno = if dashed(i) {
                chart
                    .draw_series(DashedLineSeries::new(p.iter().copied(), 8, 5, style))
                    .map_err(err)?
            } else {
                chart
                    .draw_series(LineSeries::new(p.iter().copied(), style))
                    .map_err(err)?
            };
            if let Some(label) = label {
                // A dashed series' legend line has a gap.
                let gap = if dashed(i) { 8 } else { 14 };
                anno.label(label).legend(move |(x, y)| {
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (gap, 0)], style)
                        + PathElement::new(vec![(14, 0), (24, 0)], style)
                });
            }
        }
        draw_legend(&mut chart, at)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}
