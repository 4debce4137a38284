//! SVG figures (plotters, SVG backend only).
//!
//! plotters is built without its `ttf` feature, so no system font is loaded: text is written
//! as SVG `<text>` in the generic `sans-serif` family and the viewer picks the face. Every font
//! size is explicit, and the layout (`layout`: ticks, titles, legend place) estimates text
//! extents from character counts, the way tests/studies/figures.rs checks them. Text from a
//! study file is made XML-safe (`svg_text`) before plotters escapes it. The output is a pure
//! function of the input data, which is what makes `study --render-only` byte-identical.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

mod convergence;
mod layout;
pub use convergence::{convergence_svg, convergence_svg_along};
pub(crate) use layout::{at_fraction, fraction, place_legend, svg_text, ticks, title_layout, Corner};

/// A linear or logarithmic axis from `lo` to `hi` marked at the ticks [`layout::ticks`] chose
/// (plotters' own log axis puts a key point at every integer multiple, each decade twice, and
/// none inside a range under a decade; its `with_key_points` loses the f64 label formatter).
/// One type for both scales, so that a chart's drawing code does not depend on them.
pub(crate) struct TickedAxis {
    lo: f64,
    hi: f64,
    log: bool,
    pub ticks: layout::Ticks,
}

impl TickedAxis {
    /// The axis over `pixels`, its labels side by side (`horizontal`) or stacked.
    pub fn new(lo: f64, hi: f64, log: bool, pixels: f64, horizontal: bool) -> Self {
        TickedAxis {
            lo,
            hi,
            log,
            ticks: ticks(lo, hi, log, pixels, horizontal, TICK_PT),
        }
    }
}

impl Ranged for TickedAxis {
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        // As plotters maps a linear axis, in the axis's fraction; off-scale values (a log
        // axis's zero) go to the nearer end.
        let f = fraction(*value, self.lo, self.hi, self.log);
        let f = if f.is_finite() { f.clamp(-10.0, 10.0) } else { 0.0 };
        let length = limit.1 - limit.0;
        if length >= 0 {
            limit.0 + (length as f64 * f + 1e-3).floor() as i32
        } else {
            limit.0 + (length as f64 * f - 1e-3).ceil() as i32
        }
    }

    fn key_points<Hint: plotters::coord::ranged1d::KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            vec![]
        } else {
            self.ticks.values.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

/// Figure size in pixels.
pub(crate) const SIZE: (u32, u32) = (900, 640);
pub(crate) const FONT: &str = "sans-serif";
pub(crate) const CAPTION_PT: u32 = 24;
pub(crate) const AXIS_DESC_PT: u32 = 20;
pub(crate) const TICK_PT: u32 = 16;
pub(crate) const LEGEND_PT: u32 = 16;
/// Margin around a chart, and the heights of the x tick-and-description area.
pub(crate) const MARGIN: u32 = 20;
pub(crate) const X_LABEL_AREA: u32 = 60;
/// The most series a figure tells apart: every colour with every marker (7 × 4, the pairs
/// `(i mod 7, i mod 4)` differ for i below 28). Further series are drawn in grey under one
/// legend entry.
pub(crate) const MAX_SERIES: usize = 28;
/// The colour of the series beyond [`MAX_SERIES`].
pub(crate) const GREY: RGBColor = RGBColor(150, 150, 150);

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
    if i >= MAX_SERIES {
        return GREY;
    }
    PALETTE[i % PALETTE.len()]
}

/// Whether series `i` of lines without markers is dashed: the second seven lines repeat the
/// colours of the first seven, dashed, so that no two look alike.
pub(crate) fn dashed(i: usize) -> bool {
    (i / PALETTE.len()) % 2 == 1
}

/// Label of series `i` of `n` in the legend: its own below [`MAX_SERIES`]; the first grey
/// series stands for all of them; the rest have none.
pub(crate) fn legend_label(i: usize, n: usize, label: &str) -> Option<String> {
    match i.cmp(&MAX_SERIES) {
        std::cmp::Ordering::Less => Some(svg_text(label)),
        std::cmp::Ordering::Equal => Some(format!("{} more series (grey)", n - MAX_SERIES)),
        std::cmp::Ordering::Greater => None,
    }
}

/// Draw `title` (XML-safe, fitted to the width: [`title_layout`]) centred at the top of
/// `root` and return the area below it.
pub(crate) fn titled<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
) -> PlotResult<DrawingArea<DB, Shift>> {
    titled_at(root, title, CAPTION_PT)
}

/// [`titled`] at `pt` (the colour bar's caption).
pub(crate) fn titled_at<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    pt: u32,
) -> PlotResult<DrawingArea<DB, Shift>> {
    let (w, _) = root.dim_in_pixel();
    let t = title_layout(title, pt, w as f64 - 20.0);
    for (i, line) in t.lines.iter().enumerate() {
        let style = TextStyle::from((FONT, t.pt).into_font()).pos(Pos::new(HPos::Center, VPos::Top));
        let y = 10 + (i as f64 * 1.25 * t.pt as f64).round() as i32;
        root.draw(&Text::new(line.clone(), (w as i32 / 2, y), style))
            .map_err(err)?;
    }
    Ok(root.split_vertically(t.height()).1)
}

/// The plot area's size in pixels of a chart drawn on `area` with the figures' margin, x label
/// area and a y label area of `y_area` pixels.
pub(crate) fn plot_size<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, y_area: u32) -> (f64, f64) {
    let (w, h) = area.dim_in_pixel();
    (
        w.saturating_sub(2 * MARGIN + y_area) as f64,
        h.saturating_sub(2 * MARGIN + X_LABEL_AREA) as f64,
    )
}

/// The chart builder of every figure: margins and label areas, no caption ([`titled`]).
pub(crate) fn chart_on<'a, 'b, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    y_area: u32,
) -> ChartBuilder<'a, 'b, DB> {
    let mut b = ChartBuilder::on(area);
    b.margin(MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(y_area);
    b
}

/// The chart of an x–y figure on `area`: both axes with their own ticks ([`TickedAxis`]) and
/// descriptions, no grid lines.
pub(crate) fn axes_chart<'a, DB: DrawingBackend + 'a>(
    area: &'a DrawingArea<DB, Shift>,
    y_area: u32,
    (xt, yt): (TickedAxis, TickedAxis),
    (x_desc, y_desc): (&str, &str),
) -> Result<ChartContext<'a, DB, Cartesian2d<TickedAxis, TickedAxis>>, String> {
    let (xl, yl) = (xt.ticks.clone(), yt.ticks.clone());
    let mut chart = chart_on(area, y_area).build_cartesian_2d(xt, yt).map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(svg_text(x_desc))
        .y_desc(svg_text(y_desc))
        .axis_desc_style((FONT, AXIS_DESC_PT))
        .label_style((FONT, TICK_PT))
        .x_label_formatter(&|v| xl.label(*v))
        .y_label_formatter(&|v| yl.label(*v))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(err)?;
    Ok(chart)
}

/// Where the legend of `labels` goes on a plot of `size` pixels, given the data in plot
/// fractions (see [`place_legend`]): its position and the y range's new fractions.
pub(crate) fn legend_place(
    labels: &[String],
    points: &[(f64, f64)],
    lines: &[Vec<(f64, f64)>],
    size: (f64, f64),
    preferred: Corner,
) -> (SeriesLabelPosition, (f64, f64)) {
    let legend = layout::legend_size(labels, LEGEND_PT);
    let (c, range) = place_legend(points, lines, legend, size, preferred);
    let at = match c {
        Corner::UpperLeft => SeriesLabelPosition::UpperLeft,
        Corner::UpperRight => SeriesLabelPosition::UpperRight,
        Corner::LowerLeft => SeriesLabelPosition::LowerLeft,
        Corner::LowerRight => SeriesLabelPosition::LowerRight,
    };
    (at, range)
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
    label: Option<&str>,
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
    let Some(label) = label else {
        return Ok(());
    };
    // Legend entry: a short line (for line series) and the marker, offsets relative to the
    // entry's anchor.
    let seg = if line {
        vec![(0, 0), (24, 0)]
    } else {
        vec![(12, 0), (12, 0)]
    };
    let line_style = col.stroke_width(2);
    let anno = anno.label(svg_text(label));
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
    for &(x, y) in all.filter(|p| p.0.is_finite() && p.1.is_finite()) {
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
    let y_area = 90;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let area = titled(&root, title)?;
        let size = plot_size(&area, y_area);
        let frac = |p: &(f64, f64)| (fraction(p.0, x0, x1, false), fraction(p.1, y0, y1, false));
        let labels: Vec<String> = analytical
            .iter()
            .map(|c| svg_text(&c.label))
            .chain(
                series
                    .iter()
                    .enumerate()
                    .filter_map(|(i, s)| legend_label(i, series.len(), &s.label)),
            )
            .collect();
        let points: Vec<(f64, f64)> = series.iter().flat_map(|s| s.points.iter().map(frac)).collect();
        let lines: Vec<Vec<(f64, f64)>> = analytical
            .iter()
            .map(|c| c.points.iter().map(frac).collect())
            .collect();
        let (at, (f0, f1)) = legend_place(&labels, &points, &lines, size, Corner::UpperLeft);
        let (y0, y1) = (at_fraction(f0, y0, y1, false), at_fraction(f1, y0, y1, false));
        let xt = TickedAxis::new(x0, x1, false, size.0, true);
        let yt = TickedAxis::new(y0, y1, false, size.1, false);
        let mut chart = axes_chart(&area, y_area, (xt, yt), (x_desc, y_desc))?;
        for (i, curve) in analytical.iter().enumerate() {
            let style = if i == 0 {
                BLACK.stroke_width(2)
            } else {
                RGBColor(110, 110, 110).stroke_width(2)
            };
            chart
                .draw_series(LineSeries::new(curve.points.iter().copied(), style))
                .map_err(err)?
                .label(svg_text(&curve.label))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
        }
        for (i, s) in series.iter().enumerate() {
            let label = legend_label(i, series.len(), &s.label);
            draw_markers(
                &mut chart,
                &s.points,
                Marker::nth(i),
                color(i),
                label.as_deref(),
                false,
            )?;
        }
        draw_legend(&mut chart, at)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}
