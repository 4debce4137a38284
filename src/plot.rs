//! SVG figures (plotters, SVG backend only).
//!
//! plotters is built without its `ttf` feature, so no system font is loaded: text is written
//! as SVG `<text>` in the generic `sans-serif` family and the viewer picks the face. Layout uses
//! plotters' naive text-size estimate, so every font size here is explicit and generous
//! margins leave room for labels. The output is a pure function of the input data, which is
//! what makes `study --render-only` byte-identical.

use plotters::prelude::*;

/// Figure size in pixels.
pub(crate) const SIZE: (u32, u32) = (900, 640);
pub(crate) const FONT: &str = "sans-serif";
pub(crate) const CAPTION_PT: u32 = 24;
pub(crate) const AXIS_DESC_PT: u32 = 20;
pub(crate) const TICK_PT: u32 = 16;
pub(crate) const LEGEND_PT: u32 = 16;

/// Series colours (colour-blind safe, Okabe–Ito).
const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
];

/// Marker shape of a scatter series.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    Circle,
    Triangle,
    Cross,
    Square,
}

impl Marker {
    pub fn nth(i: usize) -> Self {
        [Marker::Circle, Marker::Triangle, Marker::Square, Marker::Cross][i % 4]
    }
}

/// Scatter series of a profile plot: (σ_zz, z) pairs.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileSeries {
    pub label: String,
    pub points: Vec<(f64, f64)>,
}

/// One series of a convergence plot: (element count, error) pairs, ascending.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvergenceSeries {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// Fitted slope, drawn as a triangle when asked for.
    pub slope: Option<f64>,
}

pub(crate) type PlotResult<T> = Result<T, String>;

pub(crate) fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

pub(crate) fn color(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

pub(crate) fn draw_markers<
    'a,
    DB: DrawingBackend + 'a,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    points: &[(f64, f64)],
    marker: Marker,
    col: RGBColor,
    label: &str,
    line: bool,
) -> PlotResult<()> {
    let size = 5;
    if line {
        chart
            .draw_series(LineSeries::new(points.iter().copied(), col.stroke_width(2)))
            .map_err(err)?;
    }
    let style = col.filled();
    let anno = match marker {
        Marker::Circle => chart
            .draw_series(points.iter().map(|&p| Circle::new(p, size, style)))
            .map_err(err)?,
        Marker::Triangle => chart
            .draw_series(points.iter().map(|&p| TriangleMarker::new(p, size + 1, style)))
            .map_err(err)?,
        Marker::Square => chart
            .draw_series(
                points
                    .iter()
                    .map(|&p| EmptyElement::at(p) + Rectangle::new([(-4, -4), (4, 4)], style)),
            )
            .map_err(err)?,
        Marker::Cross => chart
            .draw_series(points.iter().map(|&p| Cross::new(p, size, col.stroke_width(2))))
            .map_err(err)?,
    };
    // Legend entry: a short line (for line series) and the marker, offsets relative to the
    // entry's anchor.
    let seg = if line {
        vec![(0, 0), (24, 0)]
    } else {
        vec![(12, 0), (12, 0)]
    };
    let line_style = col.stroke_width(2);
    let anno = anno.label(label);
    match marker {
        Marker::Circle => anno.legend(move |(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(seg.clone(), line_style)
                + Circle::new((12, 0), size, style)
        }),
        Marker::Triangle => anno.legend(move |(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(seg.clone(), line_style)
                + TriangleMarker::new((12, 0), size + 1, style)
        }),
        Marker::Square => anno.legend(move |(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(seg.clone(), line_style)
                + Rectangle::new([(8, -4), (16, 4)], style)
        }),
        Marker::Cross => anno.legend(move |(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(seg.clone(), line_style)
                + Cross::new((12, 0), size, line_style)
        }),
    };
    Ok(())
}

/// The legend every igimp figure draws: boxed, white-backed, at `position`.
pub(crate) fn draw_legend<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
) -> PlotResult<()> {
    chart
        .configure_series_labels()
        .position(position)
        .label_font((FONT, LEGEND_PT))
        .margin(12)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()
        .map_err(err)
}

pub(crate) fn padded(lo: f64, hi: f64, frac: f64) -> (f64, f64) {
    let span = (hi - lo).abs().max(1e-12 * hi.abs().max(1.0));
    (lo - frac * span, hi + frac * span)
}

/// Stress against height: numerical points and the analytical curve (σ, z).
pub fn profile_svg(
    title: &str,
    x_desc: &str,
    y_desc: &str,
    series: &[ProfileSeries],
    analytical: &[ProfileSeries],
) -> PlotResult<String> {
    let all = series.iter().chain(analytical).flat_map(|s| s.points.iter());
    let (mut x0, mut x1, mut y0, mut y1) =
        (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for &(x, y) in all {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if !(x0.is_finite() && y0.is_finite()) {
        return Err("profile figure without data".into());
    }
    let (x0, x1) = padded(x0, x1, 0.04);
    let (y0, y1) = padded(y0, y1, 0.04);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, (FONT, CAPTION_PT))
            .margin(20)
            .x_label_area_size(60)
            .y_label_area_size(90)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .axis_desc_style((FONT, AXIS_DESC_PT))
            .label_style((FONT, TICK_PT))
            .x_labels(8)
            .y_labels(8)
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| format!("{v:.0}"))
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(err)?;
        for (i, curve) in analytical.iter().enumerate() {
            let style = if i == 0 {
                BLACK.stroke_width(2)
            } else {
                RGBColor(110, 110, 110).stroke_width(2)
            };
            chart
                .draw_series(LineSeries::new(curve.points.iter().copied(), style))
                .map_err(err)?
                .label(curve.label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
        }
        for (i, s) in series.iter().enumerate() {
            draw_markers(&mut chart, &s.points, Marker::nth(i), color(i), &s.label, false)?;
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

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

/// A log axis's tick label only at 1, 2 and 5 times a power of ten: plotters puts a key point
/// at every integer multiple, whose labels run together near each decade ("90100").
fn log_tick(v: f64, label: String) -> String {
    if !(v > 0.0 && v.is_finite()) {
        return label;
    }
    let mantissa = v / 10f64.powf(v.log10().floor());
    if [1.0, 2.0, 5.0, 10.0].iter().any(|m| (mantissa - m).abs() < 1e-6) {
        label
    } else {
        String::new()
    }
}

/// Where each slope triangle's label goes: under its triangle, moved down past any earlier
/// label it would overlap (triangles of several series share the finest segment, so their
/// labels fell on one another).
fn slope_label_positions(triangles: &[Option<[(f64, f64); 3]>]) -> Vec<Option<(f64, f64)>> {
    // A label is about 1/30 of the plot's height; in log units of y the triangles' own
    // spacing is the scale, so two labels closer than a factor 1.6 in y (and 1.3 in x)
    // are taken to overlap, and a label moves down by a factor 1.8 at a time.
    let mut out: Vec<Option<(f64, f64)>> = vec![];
    for t in triangles {
        let Some(t) = t else {
            out.push(None);
            continue;
        };
        let mut p = ((t[0].0 * t[1].0).sqrt(), t[2].1 / 1.25);
        let overlaps = |p: (f64, f64), q: (f64, f64)| {
            (p.0 / q.0).ln().abs() < 1.3f64.ln() && (p.1 / q.1).ln().abs() < 1.6f64.ln()
        };
        for _ in 0..triangles.len() {
            if !out.iter().flatten().any(|&q| overlaps(p, q)) {
                break;
            }
            p.1 /= 1.8;
        }
        out.push(Some(p));
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
    // is at the bottom left, the top vertex at 0.45× the error of the second-finest point.
    let triangles: Vec<Option<[(f64, f64); 3]>> = series
        .iter()
        .map(|s| {
            let n = s.points.len();
            let slope = s.slope?;
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
    let labels = slope_label_positions(&triangles);
    let all = series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .chain(triangles.iter().flatten().flat_map(|t| t.iter().copied()))
        .chain(triangles.iter().flatten().map(|t| (t[0].0, t[2].1 / 2.0)))
        .chain(labels.iter().flatten().map(|&(x, y)| (x, y / 1.6)));
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
    for (x, y) in all {
        if x > 0.0 && y > 0.0 {
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
    let (y0, y1) = (y0 / 2.5, y1 * 2.5);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, (FONT, CAPTION_PT))
            .margin(20)
            .x_label_area_size(60)
            .y_label_area_size(100)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .axis_desc_style((FONT, AXIS_DESC_PT))
            .label_style((FONT, TICK_PT))
            .x_label_formatter(&|v| log_tick(*v, format!("{v:.0}")))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(err)?;
        for (i, s) in series.iter().enumerate() {
            let pts: Vec<(f64, f64)> = s
                .points
                .iter()
                .copied()
                .filter(|p| p.0 > 0.0 && p.1 > 0.0)
                .collect();
            let label = match s.slope {
                Some(k) => format!("{} (slope {k:.2})", s.label),
                None => s.label.clone(),
            };
            draw_markers(&mut chart, &pts, Marker::nth(i), color(i), &label, true)?;
            if let (Some(t), Some(k)) = (triangles[i], s.slope) {
                let col = color(i);
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![t[0], t[1], t[2], t[0]],
                        col.stroke_width(1),
                    )))
                    .map_err(err)?;
                let mid = labels[i].unwrap_or(((t[0].0 * t[1].0).sqrt(), t[2].1 / 1.25));
                chart
                    .draw_series(std::iter::once(Text::new(
                        format!("{k:.2}"),
                        mid,
                        (FONT, TICK_PT).into_font().color(&col),
                    )))
                    .map_err(err)?;
            }
        }
        draw_legend(&mut chart, SeriesLabelPosition::LowerLeft)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three series whose finest segments coincide (the manufactured vortex: slopes 1.41, 1.41
    /// and 1.20 drawn at one spot before, 2026-12-03): every pair of labels ends at least a
    /// factor 1.6 apart in y, and a lone label stays under its own triangle.
    #[test]
    fn slope_labels_do_not_overlap() {
        let t = |top: f64, slope: f64| {
            let bottom = top * (32.0f64 / 64.0).powf(slope);
            Some([(32.0, top), (64.0, bottom), (32.0, bottom)])
        };
        let tri = vec![t(0.01, 1.41), t(0.01, 1.41), t(0.0105, 1.20), None];
        let p = slope_label_positions(&tri);
        assert!(p[3].is_none());
        let ys: Vec<f64> = p.iter().flatten().map(|q| q.1).collect();
        for i in 0..ys.len() {
            for j in 0..i {
                assert!((ys[i] / ys[j]).ln().abs() >= 1.6f64.ln() - 1e-12, "{ys:?}");
            }
        }
        let lone = slope_label_positions(&[t(0.01, 2.0)]);
        let want = t(0.01, 2.0).unwrap()[2].1 / 1.25;
        assert_eq!(lone[0].unwrap().1, want);
    }

    /// Log-axis ticks are labelled at 1, 2 and 5 per decade only.
    #[test]
    fn log_ticks_at_one_two_five() {
        let shown: Vec<f64> = [10.0, 20.0, 30.0, 50.0, 90.0, 100.0, 200.0, 400.0]
            .into_iter()
            .filter(|&v| !log_tick(v, format!("{v:.0}")).is_empty())
            .collect();
        assert_eq!(shown, [10.0, 20.0, 50.0, 100.0, 200.0]);
    }
}
